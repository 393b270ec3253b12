#pragma once
// The dense spectrum of a Jacobian near a target (not a test itself): the eigenvalue nearest
// `target` and the largest real part of all the others (its conjugate excluded), the check that
// a Hopf point is the first crossing of the imaginary axis.
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <complex>
#include <utility>

namespace aerohopf::test_support {

template <class Matrix>
std::pair<std::complex<double>, double> eigenvalue_near(const Matrix& a, std::complex<double> target) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(a), false);
  const auto& ev = es.eigenvalues();
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < ev.size(); ++i)
    if (std::abs(ev[i] - target) < std::abs(ev[best] - target)) best = i;
  double other = -1e300;
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (std::abs(ev[i] - ev[best]) > 1e-9 && std::abs(ev[i] - std::conj(ev[best])) > 1e-9)
      other = std::max(other, ev[i].real());
  return {ev[best], other};
}

}  // namespace aerohopf::test_support
