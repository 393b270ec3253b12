// Inverse power (right and adjoint), the Cayley-transform rightmost eigenvalues and root-locus
// tracing, all against Eigen's dense eigen-decomposition.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>
#include <aerohopf/models/tubular_reactor.hpp>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <iostream>

using namespace aerohopf;

namespace {
std::complex<double> nearest(const std::vector<std::complex<double>>& ev, std::complex<double> z) {
  return *std::min_element(ev.begin(), ev.end(), [&](auto a, auto b) { return std::abs(a - z) < std::abs(b - z); });
}
vec<double> reactor_state(const tubular_reactor& r, double mu) {
  return newton(r, newton(r, r.rest_state(), 0.1).x, mu).x;
}
}  // namespace

TEST(inverse_power, RightAndAdjointEigenpairsDenseAndSparse) {
  const tubular_reactor r(24);
  const double mu = 0.16;
  const vec<double> w = reactor_state(r, mu);
  const Eigen::SparseMatrix<double> a = r.jacobian(w, mu);
  const Eigen::MatrixXd ad(a);
  const auto ev = dense_spectrum(ad);
  const std::complex<double> shift(0.0, 0.5);
  const auto ref = nearest(ev, shift);
  for (int dense = 0; dense < 2; ++dense) {
    const eigen_pair p = dense ? inverse_power(ad, shift) : inverse_power(a, shift);
    EXPECT_LT(std::abs(p.lambda - ref), 1e-10 * std::abs(ref));
    const Eigen::MatrixXcd ac = ad.cast<std::complex<double>>();
    EXPECT_LT((ac * p.vector - p.lambda * p.vector).norm(), 1e-10);
    const eigen_pair q = dense ? inverse_power_adjoint(ad, shift) : inverse_power_adjoint(a, shift);
    EXPECT_LT(std::abs(q.lambda - std::conj(ref)), 1e-10 * std::abs(ref));
    EXPECT_LT((ac.transpose() * q.vector - q.lambda * q.vector).norm(), 1e-10);
  }
}

// The Krylov route (complex BILU(k) of A - sigma I + GMRES behind the solver interface) gives
// the same eigenpair as the sparse LU, with inexact solves, and the same through hopf_start.
TEST(inverse_power, KrylovSolverMatchesDirectAndDense) {
  const tubular_reactor r(40);
  const double mu = 0.16;
  const vec<double> w = reactor_state(r, mu);
  const Eigen::SparseMatrix<double> a = r.jacobian(w, mu);
  const auto ev = dense_spectrum(Eigen::MatrixXd(a));
  const std::complex<double> shift(0.0, 0.5);
  const auto ref = nearest(ev, shift);
  krylov_solver_options ko;
  ko.fill_level = 1;
  ko.krylov.relative_tolerance = 1e-6;  // inexact on purpose: the outer residual test decides
  krylov_solver<Eigen::SparseMatrix<std::complex<double>>> ks(ko, "inverse power BILU(1)-GMRES");
  const eigen_pair p = inverse_power(a, shift, {}, nullptr, ks);
  const eigen_pair d = inverse_power(a, shift);
  EXPECT_LT(std::abs(p.lambda - ref), 1e-10 * std::abs(ref));
  EXPECT_LT(std::abs(p.lambda - d.lambda), 1e-10 * std::abs(ref));
  EXPECT_LT((p.vector - d.vector).norm(), 1e-8);  // both phase-normalised
  EXPECT_GT(p.linear_iterations, 0);
  EXPECT_EQ(d.linear_iterations, 0);
  std::cout << "Krylov inverse power: " << p.iterations << " outer, " << p.linear_iterations << " GMRES iterations; direct "
            << d.iterations << " outer\n";
  const hopf_point h = hopf_start(r, w, mu, 0.5, {}, ks);
  EXPECT_NEAR(h.omega, std::abs(ref.imag()), 1e-10);
}

TEST(inverse_power, FailsClearlyWhenNotConverging) {
  // Two eigenvalues equidistant from the shift: no convergence, a clear error.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2, 2);
  a(0, 0) = 1.0;
  a(1, 1) = -1.0;
  inverse_power_options o;
  o.max_iterations = 20;
  EXPECT_THROW(inverse_power(a, {0.0, 0.0}, o), convergence_error);
}

TEST(cayley, RightmostEigenvaluesMatchDenseSpectrum) {
  const tubular_reactor r(32);
  for (double mu : {0.12, 0.165, 0.17}) {
    const vec<double> w = reactor_state(r, mu);
    const auto a = r.jacobian(w, mu);
    auto ev = dense_spectrum(a);
    std::sort(ev.begin(), ev.end(), [](auto x, auto y) { return x.real() > y.real(); });
    const auto c = cayley_rightmost(a);
    ASSERT_FALSE(c.empty());
    EXPECT_LT(std::abs(c.front() - nearest(ev, c.front())), 1e-7);
    EXPECT_NEAR(c.front().real(), ev.front().real(), 1e-7) << "mu " << mu;
  }
}

TEST(root_locus, TracksDenseEigenvalueAlongMu) {
  const tubular_reactor r(16);
  std::vector<double> mus;
  for (int k = 0; k <= 10; ++k) mus.push_back(0.15 + 0.002 * k);
  vec<double> w = reactor_state(r, 0.15);
  auto equilibrium = [&](double mu) {
    w = newton(r, w, mu).x;
    return w;
  };
  // start from the rightmost complex eigenvalue at mu = 0.15
  auto ev0 = dense_spectrum(r.jacobian(w, 0.15));
  std::complex<double> start{-1e300, 0};
  for (auto l : ev0)
    if (l.imag() > 1e-6 && l.real() > start.real()) start = l;
  const auto locus = root_locus(r, std::function<vec<double>(double)>(equilibrium), mus, start);
  ASSERT_EQ(locus.size(), mus.size());
  vec<double> w2 = reactor_state(r, 0.15);
  for (const auto& p : locus) {
    w2 = newton(r, w2, p.mu).x;
    const auto ev = dense_spectrum(r.jacobian(w2, p.mu));
    EXPECT_LT(std::abs(p.lambda - nearest(ev, p.lambda)), 1e-9);
  }
  // it crosses the imaginary axis between 0.164 and 0.166 (the first Hopf point)
  EXPECT_LT(locus[7].lambda.real(), 0.0);
  EXPECT_GT(locus[8].lambda.real(), 0.0);
}
