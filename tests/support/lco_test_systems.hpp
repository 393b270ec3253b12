#pragma once
// A closed-form test system of limit cycles (not a test itself): the polar normal form
//     z' = (mu + i (1 + beta |z|^2)) z + (c3 |z|^2 + c5 |z|^4) z,     z = x1 + i x2,
// with m extra stable directions y_k' = -d_k y_k + a_k x1^2 + b_k x1 x2 + c_k x2^2, in a skewed
// basis w = T u (f(w) = T g(T^{-1} w)), so nothing is aligned with the axes and the cycle's
// harmonics 0 and 2 live in every coordinate. Its cycles are exact circles |z| = r with
//     mu + c3 r^2 + c5 r^4 = 0,   omega = 1 + beta r^2,
// Floquet exponents 0 (phase), 2 c3 r^2 + 4 c5 r^4 (radial) and -d_k; x1 = r cos(omega t) is a
// pure first harmonic (amplitude r), the y_k hold harmonics 0 and 2 only, so harmonic balance
// with H >= 2 is exact. c3 = -1: supercritical (r^2 = mu); c3 = +1: subcritical (r^2 = -mu);
// c3 = +1, c5 = -1: the branch folds at mu = -1/4, r^2 = 1/2 (unstable inside, stable outside).
#include <aerohopf/nonlinear/system.hpp>
#include <aerohopf/scalar/taylor.hpp>

#include <Eigen/Dense>

#include <cmath>

namespace aerohopf::test_support {

class polar_normal_form {
 public:
  using jacobian_type = Eigen::MatrixXd;

  polar_normal_form(double c3, double c5, double beta, int extra = 3) : c3_(c3), c5_(c5), beta_(beta), m_(extra) {
    const int n = 2 + m_;
    t_.resize(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) t_(i, j) = (i == j ? 1.5 : 0.0) + 0.3 * std::sin(0.7 + 1.3 * i + 2.1 * j);
    ti_ = t_.inverse();
    for (int k = 0; k < m_; ++k) {
      d_.push_back(1.0 + 0.5 * k);
      a_.push_back(std::cos(1.0 + k));
      b_.push_back(std::sin(2.0 + k));
      c_.push_back(0.5 * std::cos(3.0 + 2 * k));
    }
  }
  Eigen::Index size() const { return 2 + m_; }
  /// The probe x1 = e^T w (the first row of T^{-1}).
  vec<double> probe_x1() const { return ti_.row(0).transpose(); }
  const Eigen::MatrixXd& basis() const { return t_; }
  int extra() const { return m_; }
  double decay(int k) const { return d_[std::size_t(k)]; }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    const Eigen::Index n = size();
    vec<T> u(n), g(n), f(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      u[i] = T(0.0);
      for (Eigen::Index j = 0; j < n; ++j) u[i] += T(ti_(i, j)) * w[j];
    }
    const T r2 = u[0] * u[0] + u[1] * u[1];
    const T radial = mu + T(c3_) * r2 + T(c5_) * r2 * r2;
    const T om = T(1.0) + T(beta_) * r2;
    g[0] = radial * u[0] - om * u[1];
    g[1] = om * u[0] + radial * u[1];
    for (int k = 0; k < m_; ++k)
      g[2 + k] = -T(d_[k]) * u[2 + k] + T(a_[k]) * u[0] * u[0] + T(b_[k]) * u[0] * u[1] + T(c_[k]) * u[1] * u[1];
    for (Eigen::Index i = 0; i < n; ++i) {
      f[i] = T(0.0);
      for (Eigen::Index j = 0; j < n; ++j) f[i] += T(t_(i, j)) * g[j];
    }
    return f;
  }
  /// Exact Jacobian, column by column from taylor products.
  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(size(), size());
    for (Eigen::Index j = 0; j < size(); ++j)
      a.col(j) = jacobian_product(*this, w, mu, vec<double>::Unit(size(), j));
    return a;
  }

 private:
  double c3_, c5_, beta_;
  int m_;
  Eigen::MatrixXd t_, ti_;
  std::vector<double> d_, a_, b_, c_;
};

}  // namespace aerohopf::test_support
