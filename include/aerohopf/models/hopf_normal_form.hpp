#pragma once
// The Hopf normal form with extra stable dimensions in a skewed basis: the closed-form test
// problem of the Hopf and centre-manifold code (spec 04).
//
// Why this shape: the plain 2-D normal form has B = 0, p and q known by inspection and a flat
// centre manifold, so it cannot catch errors in the projection, the adjoint normalisation or
// the k20/k11 solves. Here, in coordinates u = (x1, x2, y_1..y_m),
//
//     x1'  = mu x1 - x2 - sigma x1 (x1^2 + x2^2)
//     x2'  = x1 + mu x2 - sigma x2 (x1^2 + x2^2)
//     y_k' = -d_k y_k + a_k x1^2 + b_k x1 x2 + c_k x2^2
//
// the x-equations do not see y, so the dynamics on the (curved, y = O(|x|^2)) centre manifold
// are exactly the normal form z' = (mu + i) z - sigma z |z|^2 with z = x1 + i x2, while B != 0
// and k20, k11 != 0 in the full space. The state is w = T u with a fixed, seeded,
// non-orthogonal but well-conditioned T, and f(w) = T g(T^{-1} w), so nothing is aligned with
// the axes.
//
// Normalisation: the reduction uses <p, p> = 1 in w. T's first two columns are scaled to norm
// sqrt(2), so p = T (1, -i, 0..)/2 has <p, p> = 1 and is exactly the eigenvector for which
// z = x1 + i x2. With sigma = s this gives c1 = -s, l1 = -s, and for s = +1 a stable cycle of
// radius |z| = sqrt(mu) (x1^2 + x2^2 = mu) for mu > 0; s = -1 is subcritical.
// Equilibrium w = 0 for every mu; Hopf point mu* = 0, omega = 1; eigenvalues mu +- i, -d_k.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <string>

#include "../bifurcation/hopf_point.hpp"
#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../scalar/traits.hpp"

namespace aerohopf {

class hopf_normal_form {
 public:
  using jacobian_type = Eigen::MatrixXd;

  /// s = +1 supercritical, -1 subcritical; n_extra stable dimensions; seed fixes T, d, a, b, c.
  explicit hopf_normal_form(double s = 1.0, int n_extra = 3, unsigned seed = 1) : s_(s), m_(n_extra) {
    require(std::isfinite(s) && s != 0, "hopf_normal_form: s must be finite and non-zero (got ", s, ")");
    require(n_extra >= 0, "hopf_normal_form: n_extra must be >= 0 (got ", n_extra, ")");
    const int n = 2 + m_;
    // splitmix64: the same numbers on every platform (std:: distributions are not portable).
    std::uint64_t state = 0x9e3779b97f4a7c15ULL * (seed + 1ULL);
    auto unit = [&state]() {
      std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      z ^= z >> 31;
      return 2.0 * (static_cast<double>(z >> 11) * 0x1.0p-53) - 1.0;  // uniform in [-1, 1)
    };
    // I + E with ||E||_2 about 0.8 at most (entries scaled with 1/sqrt(n)): cond(T) stays small.
    const double skew = std::min(0.35, 0.8 / std::sqrt(double(n)));
    t_ = Eigen::MatrixXd::Identity(n, n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) t_(i, j) += skew * unit();
    t_.col(0) *= std::sqrt(2.0) / t_.col(0).norm();
    t_.col(1) *= std::sqrt(2.0) / t_.col(1).norm();
    t_inv_ = t_.inverse();
    d_.resize(m_);
    a_.resize(m_);
    b_.resize(m_);
    c_.resize(m_);
    for (int k = 0; k < m_; ++k) {
      d_[k] = 2.0 + unit();  // in [1, 3]: well separated from the centre pair
      a_[k] = unit();
      b_[k] = unit();
      c_[k] = unit();
    }
  }

  Eigen::Index size() const { return 2 + m_; }
  double s() const { return s_; }
  int n_extra() const { return m_; }
  const Eigen::MatrixXd& basis() const { return t_; }          ///< T (w = T u)
  const Eigen::MatrixXd& basis_inverse() const { return t_inv_; }  ///< T^{-1} as used by f
  const Eigen::VectorXd& decay_rates() const { return d_; }    ///< d_k (eigenvalues -d_k)
  /// (a_k, b_k, c_k) of y_k' = -d_k y_k + a_k x1^2 + b_k x1 x2 + c_k x2^2.
  Eigen::Vector3d y_forcing(int k) const {
    require(k >= 0 && k < m_, "hopf_normal_form::y_forcing: index ", k, " out of range [0, ", m_, ")");
    return {a_[k], b_[k], c_[k]};
  }

  /// Exact right eigenvector at the Hopf point, A p = i p, <p, p> = 1, z = x1 + i x2.
  vec<std::complex<double>> exact_p() const {
    using C = std::complex<double>;
    return (t_.col(0).cast<C>() * 0.5 - C(0, 0.5) * t_.col(1).cast<C>()).eval();
  }
  /// The Hopf point (w = 0, mu = 0, omega = 1, p exact).
  hopf_point exact_hopf_point() const { return hopf_point{vec<double>::Zero(size()), 0.0, 1.0, exact_p()}; }
  /// l1 = -s exactly (with <p, p> = 1, <q, p> = 1).
  double exact_l1() const { return -s_; }
  /// x1, x2 of the state w (the normal-form coordinates; |z|^2 = x1^2 + x2^2).
  Eigen::Vector2d centre_coordinates(const vec<double>& w) const {
    require_size(w.size(), size(), "hopf_normal_form::centre_coordinates", "state");
    return (t_inv_.topRows(2) * w).eval();
  }
  /// The manifold coordinates u = T^{-1} w.
  vec<double> coordinates(const vec<double>& w) const {
    require_size(w.size(), size(), "hopf_normal_form::coordinates", "state");
    return t_inv_ * w;
  }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    require_size(w.size(), size(), "hopf_normal_form::residual", "state");
    const Eigen::Index n = size();
    const vec<T> u = multiply(t_inv_, w);
    const T& x1 = u[0];
    const T& x2 = u[1];
    const T r2 = x1 * x1 + x2 * x2;
    const T sig = make_constant<T>(s_);
    vec<T> g(n);
    g[0] = mu * x1 - x2 - sig * x1 * r2;
    g[1] = x1 + mu * x2 - sig * x2 * r2;
    for (int k = 0; k < m_; ++k)
      g[2 + k] = -make_constant<T>(d_[k]) * u[2 + k] + make_constant<T>(a_[k]) * x1 * x1 +
                 make_constant<T>(b_[k]) * x1 * x2 + make_constant<T>(c_[k]) * x2 * x2;
    return multiply(t_, g);
  }

  /// Exact A = T Dg(u) T^{-1}.
  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    check(w, mu, "jacobian");
    const vec<double> u = t_inv_ * w;
    const double x1 = u[0], x2 = u[1];
    Eigen::MatrixXd dg = Eigen::MatrixXd::Zero(size(), size());
    dg(0, 0) = mu - s_ * (3 * x1 * x1 + x2 * x2);
    dg(0, 1) = -1 - 2 * s_ * x1 * x2;
    dg(1, 0) = 1 - 2 * s_ * x1 * x2;
    dg(1, 1) = mu - s_ * (x1 * x1 + 3 * x2 * x2);
    for (int k = 0; k < m_; ++k) {
      dg(2 + k, 0) = 2 * a_[k] * x1 + b_[k] * x2;
      dg(2 + k, 1) = b_[k] * x1 + 2 * c_[k] * x2;
      dg(2 + k, 2 + k) = -d_[k];
    }
    return t_ * dg * t_inv_;
  }

  /// f_mu = T (x1, x2, 0, ...).
  vec<double> d_mu(const vec<double>& w, double mu) const {
    check(w, mu, "d_mu");
    vec<double> gmu = vec<double>::Zero(size());
    gmu.head(2) = t_inv_.topRows(2) * w;
    return t_ * gmu;
  }

  /// A_mu = T diag(1, 1, 0, ...) T^{-1}.
  Eigen::MatrixXd jacobian_d_mu(const vec<double>& w, double mu) const {
    check(w, mu, "jacobian_d_mu");
    return t_.leftCols(2) * t_inv_.topRows(2);
  }

  /// A_w v = d/dt A(w + t v) at t = 0 (so (A_w v) x = B(v, x)), exact.
  Eigen::MatrixXd jacobian_directional(const vec<double>& w, double mu, const vec<double>& v) const {
    check(w, mu, "jacobian_directional");
    require_size(v.size(), size(), "hopf_normal_form::jacobian_directional", "direction");
    require_finite(v, "hopf_normal_form::jacobian_directional", "direction");
    const vec<double> u = t_inv_ * w, du = t_inv_ * v;
    const double x1 = u[0], x2 = u[1], v1 = du[0], v2 = du[1];
    Eigen::MatrixXd dg = Eigen::MatrixXd::Zero(size(), size());
    dg(0, 0) = -s_ * (6 * x1 * v1 + 2 * x2 * v2);
    dg(0, 1) = -2 * s_ * (v1 * x2 + x1 * v2);
    dg(1, 0) = dg(0, 1);
    dg(1, 1) = -s_ * (2 * x1 * v1 + 6 * x2 * v2);
    for (int k = 0; k < m_; ++k) {
      dg(2 + k, 0) = 2 * a_[k] * v1 + b_[k] * v2;
      dg(2 + k, 1) = b_[k] * v1 + 2 * c_[k] * v2;
    }
    return t_ * dg * t_inv_;
  }

 private:
  /// The entry check of every double-valued evaluation: state of the system's size, finite,
  /// finite mu (the products with T^{-1} would otherwise read past a short state).
  void check(const vec<double>& w, double mu, const char* who) const {
    const std::string where = std::string("hopf_normal_form::") + who;
    require_size(w.size(), size(), where, "state");
    require_finite(w, where, "state");
    require(std::isfinite(mu), where, ": parameter mu is not finite (", mu, ")");
  }
  /// M x in scalar T with the double entries of M converted exactly.
  template <class T>
  static vec<T> multiply(const Eigen::MatrixXd& m, const vec<T>& x) {
    vec<T> r(m.rows());
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      T acc = make_constant<T>(0.0);
      for (Eigen::Index j = 0; j < m.cols(); ++j) acc += make_constant<T>(m(i, j)) * x[j];
      r[i] = acc;
    }
    return r;
  }

  double s_;
  int m_;
  Eigen::MatrixXd t_, t_inv_;
  Eigen::VectorXd d_, a_, b_, c_;
};

}  // namespace aerohopf
