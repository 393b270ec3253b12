#pragma once
// Small systems for the hostile-input tests of the Hopf solvers and tracers (not a test itself:
// tests/CMakeLists.txt builds only tests/<layer>/test_*.cpp).
//
//  * moving_equilibrium_system: dw/dt = T g(T^{-1} (w - c mu)) with the equilibrium w*(mu) = c mu
//    (c = 0: the equilibrium 0 for every mu, the setting of the fixed-equilibrium formulation),
//    g'(0) = diag(mu, [[mu - 1, -2], [2, mu - 1]], -1.5): a real eigenvalue mu (crossing zero at
//    mu = 0, a fold/divergence) and the pair mu - 1 +- 2i (Hopf point mu* = 1, omega* = 2,
//    w* = c). Quadratic terms make A depend on w. Jacobian dense or sparse.
//  * faulty_system<S>: S whose residual (every scalar type, so the matrix-free products count
//    too) returns NaN at the calls fault_at, fault_at + 1, ..., fault_at + fault_count - 1
//    (counted from 1; a shared counter, so copies count together, and the members of a
//    family can share one). Its Jacobians are S's (not counted).
//  * mu_shifted_system<S>: S with its equilibrium moved along c with mu, w*(mu) = w*_S + c mu.
#include <aerohopf/error.hpp>
#include <aerohopf/nonlinear/system.hpp>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <limits>
#include <memory>

namespace aerohopf::test_support {

/// The equilibrium slope c (w*(mu) = c mu) the Hopf tests give moving_equilibrium_system.
inline const Eigen::Vector4d moving_c{1.0, 0.5, -0.3, 0.2};

template <class Jacobian = Eigen::MatrixXd>
class moving_equilibrium_system {
 public:
  using jacobian_type = Jacobian;
  static constexpr int n = 4;

  explicit moving_equilibrium_system(Eigen::Vector4d c = Eigen::Vector4d::Zero()) : c_(c) {
    t_.resize(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) t_(i, j) = (i == j ? 2.0 : 0.0) + 0.3 * std::sin(1.0 + i + 2.0 * j);
    ti_ = t_.inverse();
  }
  Eigen::Index size() const { return n; }
  /// The equilibrium w*(mu) = c mu.
  vec<double> equilibrium(double mu) const { return vec<double>(c_ * mu); }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    vec<T> u(n);
    for (int i = 0; i < n; ++i) {
      u[i] = T(0.0);
      for (int j = 0; j < n; ++j) u[i] += T(ti_(i, j)) * (w[j] - T(c_[j]) * mu);
    }
    vec<T> g(n);
    g[0] = mu * u[0] + T(0.3) * u[1] * u[1];
    g[1] = (mu - T(1.0)) * u[1] - T(2.0) * u[2] + T(0.2) * u[0] * u[1];
    g[2] = T(2.0) * u[1] + (mu - T(1.0)) * u[2] - T(0.1) * u[0] * u[2];
    g[3] = T(-1.5) * u[3] + u[0] * u[0];
    vec<T> f(n);
    for (int i = 0; i < n; ++i) {
      f[i] = T(0.0);
      for (int j = 0; j < n; ++j) f[i] += T(t_(i, j)) * g[j];
    }
    return f;
  }
  /// Exact Jacobian, one taylor pass per column.
  jacobian_type jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(n, n);
    for (int j = 0; j < n; ++j) a.col(j) = jacobian_product(*this, w, mu, vec<double>(vec<double>::Unit(n, j)));
    if constexpr (is_sparse_matrix_v<jacobian_type>) return a.sparseView();
    else return a;
  }

 private:
  Eigen::Vector4d c_;
  Eigen::MatrixXd t_, ti_;
};

template <class S>
class faulty_system {
 public:
  using jacobian_type = typename S::jacobian_type;

  faulty_system(S s, long fault_at, long fault_count = 1)
      : s_(std::move(s)), calls_(std::make_shared<long>(0)), at_(fault_at), count_(fault_count) {}
  /// With a counter shared by several systems (a family: family(nu) builds one per nu).
  faulty_system(S s, std::shared_ptr<long> counter, long fault_at, long fault_count = 1)
      : s_(std::move(s)), calls_(std::move(counter)), at_(fault_at), count_(fault_count) {}
  Eigen::Index size() const { return s_.size(); }
  long calls() const { return *calls_; }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    const long k = ++*calls_;
    vec<T> f = s_.residual(w, mu);
    if (k >= at_ && k < at_ + count_)  // NaN in every Taylor coefficient too
      for (Eigen::Index i = 0; i < f.size(); ++i) f[i] = f[i] * T(std::numeric_limits<double>::quiet_NaN());
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s_.jacobian(w, mu); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const
    requires has_approximate_jacobian<S>
  {
    return s_.approximate_jacobian(w, mu);
  }

 private:
  S s_;
  std::shared_ptr<long> calls_;
  long at_, count_;
};

template <class S>
class mu_shifted_system {
 public:
  using jacobian_type = typename S::jacobian_type;
  mu_shifted_system(S s, vec<double> c) : s_(std::move(s)), c_(std::move(c)) {}
  Eigen::Index size() const { return s_.size(); }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    vec<T> ws(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) ws[i] = w[i] - T(c_[i]) * mu;
    return s_.residual(ws, mu);
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s_.jacobian(vec<double>(w - c_ * mu), mu); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const
    requires has_approximate_jacobian<S>
  {
    return s_.approximate_jacobian(vec<double>(w - c_ * mu), mu);
  }

 private:
  S s_;
  vec<double> c_;
};

}  // namespace aerohopf::test_support
