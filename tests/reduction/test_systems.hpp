#pragma once
// A small generic nonlinear system for the reduction and time tests: transcendental (exp, sqrt)
// so finite differences have truncation error in every order, cyclic coupling so every
// product is dense. Its Jacobian is assembled column by column from taylor<double, 1> jets.
#include <cmath>

#include "aerohopf/nonlinear/system.hpp"
#include "aerohopf/scalar/taylor.hpp"
#include "aerohopf/scalar/traits.hpp"

namespace aerohopf::test_systems {

struct exp_system {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index n = 5;

  Eigen::Index size() const { return n; }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    using std::exp;
    using std::sqrt;
    vec<T> f(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const T& next = w[(i + 1) % n];
      const T& prev = w[(i + n - 1) % n];
      f[i] = -w[i] + make_constant<T>(0.4) * exp(make_constant<T>(0.5) * next - make_constant<T>(0.3) * prev) * w[i] +
             mu * sqrt(make_constant<T>(1.0) + w[i] * w[i]) + make_constant<T>(0.2) * next * next * prev;
    }
    return f;
  }

  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    using J = taylor<double, 1>;
    Eigen::MatrixXd a(n, n);
    for (Eigen::Index j = 0; j < n; ++j) {
      vec<J> wj(n);
      for (Eigen::Index i = 0; i < n; ++i) wj[i] = J::variable(w[i], i == j ? 1.0 : 0.0);
      const vec<J> f = residual(wj, J(mu));
      for (Eigen::Index i = 0; i < n; ++i) a(i, j) = f[i][1];
    }
    return a;
  }
};

}  // namespace aerohopf::test_systems
