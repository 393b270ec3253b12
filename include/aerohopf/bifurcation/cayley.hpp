#pragma once
// Rightmost eigenvalues of a large sparse A by the generalised Cayley transform (spec 02):
//
//   C = (A - a1 I)^{-1} (A - a2 I) = I + (a1 - a2)(A - a1 I)^{-1},   a1 > a2 real,
//
// maps lambda to theta = (lambda - a2)/(lambda - a1): eigenvalues right of the line
// Re(lambda) = (a1 + a2)/2 go outside the unit circle, those left of it inside. The
// dominant-magnitude eigenvalues of C (found by Arnoldi with explicit restarts, one sparse LU of
// A - a1 I) therefore are the rightmost eigenvalues of A, mapped back by
// lambda = (a1 theta - a2)/(theta - 1). This is the Hopf test function for systems too large
// for a dense eigen-decomposition.
//
// Choice of a1 = -a2 = a: log|theta| ~ 4 a Re(lambda) / (|lambda|^2 + a^2), so for |lambda| << a
// the ordering by |theta| is the ordering by real part, while eigenvalues far away (the stiff,
// strongly damped ones) are pushed towards |theta| = 1 from below. Take a several times larger
// than the frequencies of interest and smaller than the stiff part of the spectrum; the count
// of |theta| > 1 (eigenvalues right of the line) is correct for any a.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"

namespace aerohopf {

struct cayley_options {
  double a1 = 50.0;      ///< pole (real); must not be an eigenvalue
  double a2 = -50.0;     ///< zero (real), a2 < a1
  int subspace = 30;     ///< Arnoldi basis size
  int restarts = 8;
  int wanted = 6;        ///< number of eigenvalues returned
  double tolerance = 1e-8;  ///< Ritz residual relative to |theta|
};

/// Up to `wanted` rightmost eigenvalues of A (dominant |theta|, converged Ritz values only),
/// sorted by decreasing real part. A must be square and finite; options: finite a1 > a2,
/// subspace >= 1, restarts >= 0, wanted >= 1, finite tolerance > 0 (input_error otherwise).
template <class Matrix>
std::vector<std::complex<double>> cayley_rightmost(const Matrix& a, const cayley_options& opt = {}) {
  using C = std::complex<double>;
  const Eigen::Index n = a.rows();
  const char* who = "cayley_rightmost";
  require(a.rows() == a.cols(), who, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
  require(n >= 1, who, ": matrix is empty");
  require(std::isfinite(opt.a1) && std::isfinite(opt.a2) && opt.a1 > opt.a2, who,
          ": needs finite a1 > a2 (got a1 = ", opt.a1, ", a2 = ", opt.a2, ")");
  require(opt.subspace >= 1, who, ": subspace must be >= 1 (got ", opt.subspace, ")");
  require(opt.restarts >= 0, who, ": restarts must be >= 0 (got ", opt.restarts, ")");
  require(opt.wanted >= 1, who, ": wanted must be >= 1 (got ", opt.wanted, ")");
  require(std::isfinite(opt.tolerance) && opt.tolerance > 0, who, ": tolerance must be finite and > 0 (got ",
          opt.tolerance, ")");
  if constexpr (is_sparse_matrix_v<Matrix>) {
    for (int k = 0; k < a.outerSize(); ++k)
      for (typename Matrix::InnerIterator it(a, k); it; ++it)
        require(std::isfinite(it.value()), who, ": matrix entry (", it.row(), ", ", it.col(), ") is not finite (",
                it.value(), ")");
  } else {
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        require(std::isfinite(a(i, j)), who, ": matrix entry (", i, ", ", j, ") is not finite (", a(i, j), ")");
  }
  const int m = int(std::min<Eigen::Index>(opt.subspace, n));
  direct_solver<std::decay_t<decltype(shifted(a, opt.a1))>> lu("cayley: A - a1 I");
  lu.compute(shifted(a, opt.a1));
  auto apply = [&](const vec<C>& x) { return vec<C>(x + (opt.a1 - opt.a2) * lu.solve(x)); };
  vec<C> v0 = vec<C>::Ones(n);
  for (Eigen::Index i = 0; i < n; ++i) v0[i] += 0.3 * std::sin(0.9 * double(i));
  std::vector<C> result;
  for (int restart = 0; restart <= opt.restarts; ++restart) {
    Eigen::Matrix<C, Eigen::Dynamic, Eigen::Dynamic> v(n, m + 1), h = Eigen::Matrix<C, -1, -1>::Zero(m + 1, m);
    v.col(0) = v0.normalized();
    int k = m;
    for (int j = 0; j < m; ++j) {
      vec<C> w = apply(v.col(j));
      for (int pass = 0; pass < 2; ++pass)  // classical Gram-Schmidt, twice
        for (int i = 0; i <= j; ++i) {
          const C hij = v.col(i).dot(w);
          h(i, j) += hij;
          w -= hij * v.col(i);
        }
      h(j + 1, j) = w.norm();
      if (std::abs(h(j + 1, j)) < 1e-14) {
        k = j + 1;
        break;
      }
      v.col(j + 1) = w / h(j + 1, j);
    }
    Eigen::ComplexEigenSolver<Eigen::Matrix<C, -1, -1>> es(h.topLeftCorner(k, k));
    std::vector<int> idx(k);
    for (int i = 0; i < k; ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](int x, int y) { return std::abs(es.eigenvalues()[x]) > std::abs(es.eigenvalues()[y]); });
    const int want = std::min(opt.wanted, k);
    bool converged = true;
    v0.setZero();
    result.clear();
    for (int r = 0; r < want; ++r) {
      const C theta = es.eigenvalues()[idx[r]];
      const vec<C> y = es.eigenvectors().col(idx[r]);
      const double resid = k == m ? std::abs(h(m, m - 1) * y[m - 1]) : 0.0;  // Arnoldi residual
      if (resid > opt.tolerance * std::abs(theta)) converged = false;
      else result.push_back((opt.a1 * theta - opt.a2) / (theta - 1.0));  // only converged Ritz values
      v0 += v.leftCols(k) * y;
    }
    if (converged) break;
  }
  std::sort(result.begin(), result.end(), [](C x, C y) { return x.real() > y.real(); });
  return result;
}

}  // namespace aerohopf
