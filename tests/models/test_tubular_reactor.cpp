// The tubular reactor model: analytic Jacobian, f_mu, A_mu and A_w v against independent
// derivatives (taylor jets through the templated residual, central differences), all three
// inflow closures, and input validation.
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear/system.hpp>
#include <aerohopf/scalar/qd.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace aerohopf;

namespace {
vec<double> perturbed_state(const tubular_reactor& r) {
  vec<double> w = r.rest_state();
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] += 0.05 * std::sin(0.7 * double(i)) + (i % 2 ? 0.1 : -0.2);
  return w;
}
}  // namespace

class reactor_variants : public ::testing::TestWithParam<reactor_inflow> {};

TEST_P(reactor_variants, JacobianEqualsTaylorDirectionalDerivative) {
  tubular_reactor r(16, GetParam());
  static_assert(dynamical_system<tubular_reactor>);
  static_assert(system_over<tubular_reactor, taylor<double, 1>>);
  static_assert(system_over<tubular_reactor, dd_real>);
  const vec<double> w = perturbed_state(r);
  for (int trial = 0; trial < 3; ++trial) {
    const vec<double> v = vec<double>::Random(r.size());
    const vec<double> av = r.jacobian(w, 0.17) * v;
    const vec<double> exact = jacobian_product(r, w, 0.17, v);
    EXPECT_LT((av - exact).norm(), 1e-12 * exact.norm());
  }
}

TEST_P(reactor_variants, ParameterDerivativesAgainstTaylorAndDifferences) {
  tubular_reactor r(12, GetParam());
  const vec<double> w = perturbed_state(r);
  const double mu = 0.16;
  // f_mu by a jet in mu (the generic default, independent of the analytic member).
  using J = taylor<double, 1>;
  const vec<J> fj = r.residual(vec<J>(w.cast<J>()), J::variable(mu));
  vec<double> fmu(fj.size());
  for (Eigen::Index i = 0; i < fj.size(); ++i) fmu[i] = fj[i][1];
  EXPECT_LT((r.d_mu(w, mu) - fmu).norm(), 1e-13 * fmu.norm());
  // A_mu: the Jacobian is linear in mu, so a central difference is exact up to rounding.
  const Eigen::MatrixXd amu = (Eigen::MatrixXd(r.jacobian(w, mu + 1e-3)) - Eigen::MatrixXd(r.jacobian(w, mu - 1e-3))) / 2e-3;
  EXPECT_LT((Eigen::MatrixXd(r.jacobian_d_mu(w, mu)) - amu).norm(), 1e-9 * amu.norm());
  // A_w v against second-order jets: (A_w v) u = B(v, u) = coefficient of t*s... use polarisation
  // B(v, u) = [B(v+u, v+u) - B(v-u, v-u)] / 4 with B(x, x) = 2 * (t^2 coefficient of f(w + t x)).
  using J2 = taylor<double, 2>;
  auto bxx = [&](const vec<double>& x) {
    vec<J2> wj(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) wj[i] = J2::variable(w[i], x[i]);
    const vec<J2> f = r.residual(wj, J2(mu));
    vec<double> b(f.size());
    for (Eigen::Index i = 0; i < f.size(); ++i) b[i] = 2.0 * f[i][2];
    return b;
  };
  const vec<double> v = vec<double>::Random(r.size()), u = vec<double>::Random(r.size());
  const vec<double> buv = (bxx(v + u) - bxx(v - u)) / 4.0;
  const vec<double> mine = r.jacobian_directional(w, mu, v) * u;
  EXPECT_LT((mine - buv).norm(), 1e-11 * buv.norm());
}

INSTANTIATE_TEST_SUITE_P(all_inflow_closures, reactor_variants,
                         ::testing::Values(reactor_inflow::first_order, reactor_inflow::second_order,
                                           reactor_inflow::second_order_upwind));

TEST(tubular_reactor, RestStateIsEquilibriumWithoutReaction) {
  for (auto v : {reactor_inflow::first_order, reactor_inflow::second_order, reactor_inflow::second_order_upwind}) {
    tubular_reactor r(10, v);
    EXPECT_LT(r.residual(r.rest_state(), 0.0).norm(), 1e-12);
  }
}

TEST(tubular_reactor, ResidualInQuadDoubleMatchesDouble) {
  tubular_reactor r(10);
  const vec<double> w = perturbed_state(r);
  const vec<qd_real> fq = r.residual(vec<qd_real>(w.cast<qd_real>()), qd_real(0.15));
  const vec<double> fd = r.residual(w, 0.15);
  for (Eigen::Index i = 0; i < fd.size(); ++i) EXPECT_NEAR(to_double(fq[i]), fd[i], 1e-11 * (1 + std::abs(fd[i])));
}

TEST(tubular_reactor, RejectsBadInput) {
  EXPECT_THROW(tubular_reactor(2), input_error);
  tubular_reactor r(8);
  EXPECT_THROW(r.residual(vec<double>(vec<double>::Ones(5)), 0.1), input_error);
  EXPECT_THROW(r.jacobian(vec<double>::Ones(3), 0.1), input_error);
}

TEST(tubular_reactor, RefusesNonFiniteStatesParametersAndShortStatesEverywhere) {
  const tubular_reactor r(8);
  vec<double> w = r.rest_state();
  EXPECT_EQ(r.jacobian(w, 0.1).rows(), 16);  // valid
  w[5] = std::nan("");
  // a NaN state or mu used to come back as a NaN matrix or vector without a word
  EXPECT_THROW(r.jacobian(w, 0.1), input_error);
  EXPECT_THROW(r.d_mu(w, 0.1), input_error);
  EXPECT_THROW(r.jacobian_d_mu(w, 0.1), input_error);
  const vec<double> ok = r.rest_state();
  EXPECT_THROW(r.jacobian(ok, std::nan("")), input_error);
  EXPECT_THROW(r.jacobian_directional(ok, 0.1, w), input_error);
  EXPECT_THROW(r.jacobian_directional(ok, 0.1, vec<double>::Ones(3).eval()), input_error);
  // outlet_theta read w[2N - 1] of any vector
  EXPECT_THROW(r.outlet_theta(vec<double>(vec<double>::Ones(4))), input_error);
  tubular_reactor_parameters p;
  p.gamma = std::nan("");
  EXPECT_THROW(tubular_reactor(8, reactor_inflow::second_order, p), input_error);
  p = {};
  p.pe_h = INFINITY;
  EXPECT_THROW(tubular_reactor(8, reactor_inflow::second_order, p), input_error);
}
