// Harmonic balance, its continuation in amplitude and Hill's Floquet exponents against closed
// forms (the polar normal form of support/lco_test_systems.hpp: super- and subcritical circles,
// the quintic fold and its change of stability), against published values for the Van der Pol
// cycle, and against BDF2 time marching of the tubular reactor.
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear/newton.hpp>
#include <aerohopf/periodic/harmonic_balance.hpp>
#include <aerohopf/time/bdf2.hpp>
#include <aerohopf/time/history.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/aerofoil_cases.hpp"
#include "support/error_messages.hpp"
#include "support/lco_test_systems.hpp"

using namespace aerohopf;
using aerohopf::test_support::polar_normal_form;

namespace {

hopf_point origin_hopf(const polar_normal_form& s) {
  hopf_point hp;
  hp.w = vec<double>::Zero(s.size());
  hp.mu = 0;
  hp.omega = 1;
  vec<std::complex<double>> u = vec<std::complex<double>>::Zero(s.size());
  u[0] = 1;
  u[1] = std::complex<double>(0, -1);
  hp.p = s.basis().cast<std::complex<double>>() * u;
  return hp;
}

/// The reactor's first Hopf point (16 cells) from the equilibrium at mu = 0.16.
hopf_point reactor_hopf(const tubular_reactor& r) {
  vec<double> w = r.rest_state();
  for (int k = 1; k <= 8; ++k) w = newton(r, w, 0.16 * k / 8).x;
  return solve_hopf(r, hopf_start(r, w, 0.16, 0.4)).point;
}

/// Van der Pol, x'' - mu (1 - x^2) x' + x = 0 as a first-order system (x, x').
struct van_der_pol {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 2; }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    vec<T> f(2);
    f[0] = w[1];
    f[1] = mu * (T(1.0) - w[0] * w[0]) * w[1] - w[0];
    return f;
  }
  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(2, 2);
    a << 0, 1, -2 * mu * w[0] * w[1] - 1, mu * (1 - w[0] * w[0]);
    return a;
  }
};

/// A system viewed with an Eigen sparse Jacobian (the Krylov path's bordered form of B = 2).
template <class S>
struct sparse_view {
  using jacobian_type = Eigen::SparseMatrix<double>;
  const S& s;
  Eigen::Index size() const { return s.size(); }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    return s.residual(w, mu);
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s.jacobian(w, mu).sparseView(); }
};

/// sparse_view with an approximate (preconditioning) Jacobian that drops the entries below 0.3 in
/// magnitude: its pattern changes along a cycle (the mean over the instances takes the union).
template <class S>
struct pruned_preconditioner_view : sparse_view<S> {
  Eigen::SparseMatrix<double> approximate_jacobian(const vec<double>& w, double mu) const {
    return Eigen::MatrixXd(this->s.jacobian(w, mu)).sparseView(1.0, 0.3);
  }
};

/// Every exponent of the Krylov result is one of the dense result's, and every dense exponent
/// within the Krylov radius of its shift is found.
void expect_krylov_matches_dense(const floquet_result& k, const floquet_result& d, double tol) {
  EXPECT_FALSE(k.complete);
  EXPECT_TRUE(d.complete);
  ASSERT_FALSE(k.exponents.empty());
  for (const auto& x : k.exponents) {
    double best = INFINITY;
    for (const auto& y : d.exponents) best = std::min(best, std::abs(x - y));
    EXPECT_LT(best, tol) << "Krylov exponent " << x << " is not a dense one";
  }
  for (const auto& y : d.exponents) {
    if (std::abs(y - k.shift) > 0.999 * k.radius) continue;
    double best = INFINITY;
    for (const auto& x : k.exponents) best = std::min(best, std::abs(x - y));
    EXPECT_LT(best, tol) << "dense exponent " << y << " within the radius " << k.radius << " missed";
  }
  EXPECT_NEAR(k.trivial.real(), d.trivial.real(), tol);
  EXPECT_NEAR(k.max_real, d.max_real, tol);
  EXPECT_EQ(k.stable, d.stable);
}

}  // namespace

TEST(HarmonicBalance, DifferentiationMatrixIsExactOnTrigonometricPolynomials) {
  for (int h : {1, 2, 5}) {
    const int n = 2 * h + 1;
    const Eigen::MatrixXd d = fourier_differentiation_matrix(n);
    vec<double> f(n), df(n);
    for (int j = 0; j < n; ++j) {
      const double t = 2 * std::numbers::pi * j / n;
      f[j] = 0.3 + std::sin(h * t + 0.2) - 0.7 * std::cos(t);
      df[j] = h * std::cos(h * t + 0.2) + 0.7 * std::sin(t);
    }
    EXPECT_LT((d * f - df).norm(), 1e-12 * df.norm()) << "H = " << h;
  }
  EXPECT_THROW(fourier_differentiation_matrix(4), input_error);
  EXPECT_THROW(fourier_differentiation_matrix(0), input_error);
}

TEST(HarmonicBalance, SupercriticalCircleFrequencyAndFloquetExponentsAreExact) {
  const polar_normal_form s(-1.0, 0.0, 0.3);
  const vec<double> e = s.probe_x1();
  const hopf_point hp = origin_hopf(s);
  for (int h : {1, 2, 4}) {
    const lco_solution g = lco_guess_from_hopf(hp, e, 0.1, h);
    const lco_solution c = solve_lco(s, g, e, lco_fix::amplitude, 0.3);
    EXPECT_NEAR(c.mu, 0.09, 1e-12) << "H = " << h;
    EXPECT_NEAR(c.omega, 1 + 0.3 * 0.09, 1e-12);
    EXPECT_NEAR(c.amplitude, 0.3, 1e-14);
    EXPECT_LE(c.residual, 1e-10);
    EXPECT_GE(c.newton_iterations, 2);
    EXPECT_NEAR(probe_peak_amplitude(c, e), 0.3, 1e-12);  // x1 is a pure first harmonic
    if (h == 1) continue;  // the y_k carry harmonic 2: exact from H = 2 on
    const floquet_result f = hill_floquet(s, c);
    ASSERT_EQ(f.exponents.size(), std::size_t(s.size()));
    EXPECT_LT(std::abs(f.trivial), 1e-9);
    // exponents 0, -2 r^2 = -0.18, -d_k
    std::vector<double> expected = {0.0, -0.18};
    for (int k = 0; k < s.extra(); ++k) expected.push_back(-s.decay(k));
    std::sort(expected.rbegin(), expected.rend());
    for (std::size_t k = 0; k < expected.size(); ++k) {
      EXPECT_NEAR(f.exponents[k].real(), expected[k], 1e-9) << "exponent " << k << ", H = " << h;
      EXPECT_NEAR(std::remainder(f.exponents[k].imag(), c.omega), 0.0, 1e-9);
    }
    EXPECT_NEAR(f.max_real, -0.18, 1e-9);
    EXPECT_TRUE(f.stable);
    // the trivial multiplier is 1, the radial one exp(-0.18 T)
    const auto m = f.multipliers();
    EXPECT_NEAR(std::abs(m[0]), 1.0, 1e-8);
    EXPECT_NEAR(std::abs(m[1]), std::exp(-0.18 * c.period()), 1e-8);
  }
}

TEST(HarmonicBalance, SubcriticalCircleIsUnstableAndSolvedAtFixedParameter) {
  const polar_normal_form s(1.0, 0.0, -0.2);
  const vec<double> e = s.probe_x1();
  const lco_solution g = lco_guess_from_hopf(origin_hopf(s), e, 0.2, 3);
  // fixed mu = -0.04: r = 0.2
  const lco_solution c = solve_lco(s, g, e, lco_fix::parameter, -0.04);
  EXPECT_NEAR(c.amplitude, 0.2, 1e-12);
  EXPECT_NEAR(c.omega, 1 - 0.2 * 0.04, 1e-12);
  const floquet_result f = hill_floquet(s, c);
  EXPECT_NEAR(f.max_real, 0.08, 1e-9);  // 2 c3 r^2
  EXPECT_FALSE(f.stable);
}

TEST(HarmonicBalance, QuinticBranchPassesTheFoldAndChangesStabilityThere) {
  const polar_normal_form s(1.0, -1.0, 0.1);
  const vec<double> e = s.probe_x1();
  const lco_solution start = solve_lco(s, lco_guess_from_hopf(origin_hopf(s), e, 0.2, 2), e, lco_fix::amplitude);
  lco_branch_options o;
  o.step = 0.05;
  o.max_step = 0.1;
  o.amplitude_max = 1.1;
  o.mu_targets = {-0.2, -0.1};  // crossed twice in opposite directions: only the first sweep lands
  o.max_points = 200;
  o.newton.tolerance = 1e-13;
  const lco_branch b = trace_lco_branch(s, start, e, o);
  ASSERT_GE(b.points.size(), 15u);
  double mu_min = 1, a_at_min = 0;
  int stable_count = 0, unstable_count = 0;
  for (const auto& p : b.points) {
    const double r = p.cycle.amplitude, r2 = r * r;
    EXPECT_NEAR(p.cycle.mu, r2 * r2 - r2, 1e-11) << "a = " << r;
    EXPECT_NEAR(p.cycle.omega, 1 + 0.1 * r2, 1e-11);
    EXPECT_NEAR(p.probe_amplitude, r, 1e-11);
    ASSERT_TRUE(p.floquet.has_value());
    const double radial = 2 * r2 - 4 * r2 * r2;
    if (std::abs(r2 - 0.5) > 0.02) {
      EXPECT_EQ(p.floquet->stable, r2 > 0.5) << "a = " << r;
      EXPECT_NEAR(p.floquet->max_real, std::max(radial, -1.0), 1e-8) << "a = " << r;
      (r2 > 0.5 ? stable_count : unstable_count)++;
    }
    if (p.cycle.mu < mu_min) mu_min = p.cycle.mu, a_at_min = r;
  }
  EXPECT_GE(stable_count, 3);
  EXPECT_GE(unstable_count, 3);
  EXPECT_NEAR(mu_min, -0.25, 2e-3);               // the fold at mu = -1/4
  EXPECT_NEAR(a_at_min * a_at_min, 0.5, 0.1);     // at r^2 = 1/2
  EXPECT_GT(b.points.back().cycle.amplitude, 1.0);  // well past the fold, on the stable sheet
  EXPECT_GT(b.points.back().cycle.mu, 0.0);
  int landed = 0;
  for (const auto& p : b.points)
    if (p.landed) {
      ++landed;
      EXPECT_TRUE(std::abs(p.cycle.mu + 0.2) < 1e-12 || std::abs(p.cycle.mu + 0.1) < 1e-12) << p.cycle.mu;
    }
  EXPECT_GE(landed, 2);
  o.fast_iterations = -1;
  EXPECT_THROW(trace_lco_branch(s, start, e, o), input_error);
}

TEST(HarmonicBalance, VanDerPolCycleConvergesSpectrallyToThePublishedPeriod) {
  // mu = 1: period 6.663286859323130 and amplitude 2.00861986087 (high-precision values quoted
  // throughout the literature; an RK4 run with dt = 2e-5 gives 6.6632868616 and 2.0086198609).
  const van_der_pol s;
  const vec<double> e = vec<double>::Unit(2, 0);
  hopf_point hp;
  hp.w = vec<double>::Zero(2);
  hp.mu = 0;
  hp.omega = 1;
  hp.p = vec<std::complex<double>>(2);
  hp.p << 1.0, std::complex<double>(0, 1);
  // from the small cycle near onset (r = 2) up to mu = 1 by the branch, then each H at mu = 1
  lco_solution c = solve_lco(s, lco_guess_from_hopf(hp, e, 2.0, 15, 0.05), e, lco_fix::parameter, 0.05);
  lco_branch_options o;
  o.mu_targets = {1.0};
  o.amplitude_scale = 1;
  o.mu_max = 1.01;
  o.step = 0.1;
  o.mu_direction = +1;  // the first harmonic shrinks slightly as mu grows
  const lco_branch b = trace_lco_branch(s, c, e, o, [](const lco_branch_point& p) { return p.landed; });
  ASSERT_TRUE(b.points.back().landed) << b.stop_reason;
  const lco_solution at1 = b.points.back().cycle;
  EXPECT_NEAR(at1.period(), 6.663286859323130, 1e-6);  // H = 15
  EXPECT_NEAR(probe_peak_amplitude(at1, e), 2.00861986087, 1e-4);
  ASSERT_TRUE(b.points.back().floquet.has_value());
  EXPECT_TRUE(b.points.back().floquet->stable);
  // spectral convergence in H (measured: period errors 1.2, 3.2e-2, 1.3e-3, 7.5e-6, 4.5e-8,
  // 2.7e-10, 1.4e-13, 1.8e-15 for these H)
  double last_period = INFINITY, last_amplitude = INFINITY;
  for (int h : {3, 5, 8, 12, 16, 20, 25, 30}) {
    const lco_solution ch = solve_lco(s, resample(at1, h), e, lco_fix::parameter, 1.0);
    const double ep = std::abs(ch.period() - 6.663286859323130);
    const double ea = std::abs(probe_peak_amplitude(ch, e) - 2.00861986087);
    EXPECT_LT(ep, last_period) << "H = " << h;
    EXPECT_LT(ea, last_amplitude) << "H = " << h;
    last_period = ep;
    last_amplitude = ea;
  }
  EXPECT_LT(last_period, 1e-12);
  EXPECT_LT(last_amplitude, 1e-9);
}

TEST(HarmonicBalance, TubularReactorCycleMatchesBdf2TimeMarching) {
  const tubular_reactor r(16);
  const hopf_point hp = reactor_hopf(r);
  const vec<double> e = vec<double>::Unit(r.size(), r.size() - 1);  // Theta at the outlet
  const double dmu = 1e-3;
  lco_branch_options o;
  o.mu_scale = 1e-3;
  o.amplitude_scale = 0.01;
  o.step = 0.2;
  o.mu_targets = {hp.mu + dmu};
  o.stability = true;
  const lco_solution start =
      solve_lco(r, lco_guess_from_hopf(hp, e, 2e-3, 5), e, lco_fix::amplitude, std::nullopt);
  const lco_branch b = trace_lco_branch(r, start, e, o, [](const lco_branch_point& p) { return p.landed; });
  ASSERT_TRUE(b.points.back().landed) << b.stop_reason;
  const lco_branch_point& p = b.points.back();
  ASSERT_TRUE(p.floquet.has_value());
  EXPECT_TRUE(p.floquet->stable);  // supercritical
  // BDF2 from the cycle's state at tau = 0 displaced by 20 % of its oscillation towards the
  // mean, for 60 periods (the transient decays as exp(2 Re(sigma) t)): peaks of the last 3.
  const vec<double> w0 = p.cycle.mean() + 0.8 * (p.cycle.state(0.0) - p.cycle.mean());
  const double period = p.cycle.period(), dt = period / 400;
  bdf2_options bo;
  bo.dt = dt;
  bo.inner_tolerance = 1e-11;
  std::vector<double> t, y;
  integrate_bdf2(r, p.cycle.mu, w0, 0.0, 60 * period, bo, [&](const bdf2_step_info& si, const vec<double>& ws) {
    t.push_back(si.t);
    y.push_back(ws[r.size() - 1]);
  });
  const cycle_measure last = last_cycles(t, y, 3);
  ASSERT_EQ(last.cycles, 3);
  const double marched_period = last.period, marched_amplitude = last.amplitude;
  const double hb_amplitude = p.probe_amplitude;
  EXPECT_NEAR(marched_amplitude / hb_amplitude, 1.0, 0.01);
  EXPECT_NEAR(marched_period / period, 1.0, 0.005);
}

TEST(HarmonicBalance, KrylovStrategyEqualsSparseLuOnTheReactor) {
  const tubular_reactor r(16);
  const hopf_point hp = reactor_hopf(r);
  const vec<double> e = vec<double>::Unit(r.size(), r.size() - 1);
  const lco_solution g = lco_guess_from_hopf(hp, e, 0.01, 4);
  harmonic_balance_options ho;
  ho.tolerance = 1e-11;
  const lco_solution direct = solve_lco(r, g, e, lco_fix::amplitude, std::nullopt, ho);
  const lco_solution krylov = solve_lco(r, g, e, lco_fix::amplitude, std::nullopt, ho, hb_krylov<2>{});
  EXPECT_NEAR(krylov.mu, direct.mu, 1e-10 * std::abs(direct.mu));
  EXPECT_NEAR(krylov.omega, direct.omega, 1e-9 * direct.omega);
  EXPECT_LT((krylov.instances - direct.instances).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(krylov.newton_iterations, direct.newton_iterations);
  EXPECT_GT(krylov.linear_iterations, 0);
  EXPECT_EQ(direct.linear_iterations, 0);
  hb_krylov<2> bad;
  bad.fill_level = -1;
  EXPECT_THROW(solve_lco(r, g, e, lco_fix::amplitude, std::nullopt, ho, bad), input_error);
  bad = {};
  bad.accept_tolerance = 1e-9;  // below krylov.relative_tolerance
  EXPECT_THROW(solve_lco(r, g, e, lco_fix::amplitude, std::nullopt, ho, bad), input_error);
  // a GMRES that cannot converge (one iteration, nothing accepted) ends the solve clearly
  bad = {};
  bad.krylov.max_iterations = 1;
  bad.accept_tolerance = bad.krylov.relative_tolerance;
  const std::string msg = test::error_of<convergence_error>(
      [&] { solve_lco(r, g, e, lco_fix::amplitude, std::nullopt, ho, bad); });
  EXPECT_TRUE(test::contains(msg, "GMRES on the harmonic-balance Jacobian")) << msg;
  EXPECT_TRUE(test::contains(msg, "Newton iteration 0")) << msg;
}

TEST(HarmonicBalance, KrylovStrategyEqualsSparseLuOnTheAerofoil) {
  // heavy pitch-plunge NACA 0012, very coarse grid, M = 0.5: the pitch cycle of 0.01 rad
  const auto s = test_support::heavy_very_coarse_aerofoil(0.5);
  const hopf_result h = test_support::heavy_very_coarse_hopf(s);
  ASSERT_TRUE(h.report.converged);
  const vec<double> e = vec<double>::Unit(s.size(), s.flow_size() + 2);  // pitch angle
  const lco_solution g = lco_guess_from_hopf(h.point, e, 0.01, 2);
  harmonic_balance_options ho;
  ho.tolerance = 1e-10;
  const auto t0 = std::chrono::steady_clock::now();
  const lco_solution direct = solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho);
  const auto t1 = std::chrono::steady_clock::now();
  const lco_solution krylov = solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, hb_krylov<4>{});
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("aerofoil (n = %ld, H = 2): Ubar %.10f (Hopf %.10f), omega %.8f; sparse LU %d Newton %.2f s, Krylov %d Newton"
              " %d GMRES %.2f s\n",
              long(s.size()), krylov.mu, h.point.mu, krylov.omega, direct.newton_iterations,
              std::chrono::duration<double>(t1 - t0).count(), krylov.newton_iterations, krylov.linear_iterations,
              std::chrono::duration<double>(t2 - t1).count());
  EXPECT_NEAR(krylov.mu, direct.mu, 1e-8 * std::abs(direct.mu));
  EXPECT_NEAR(krylov.omega, direct.omega, 1e-8 * direct.omega);
  EXPECT_LT((krylov.instances - direct.instances).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_NE(krylov.mu, h.point.mu);  // a finite cycle: off the Hopf point
  // the inexact-Newton forcing against a fixed 1e-6 per solve: the same cycle (the Newton test
  // decides), fewer GMRES iterations
  hb_krylov<4> fixed;
  fixed.adaptive_tolerance = false;
  const lco_solution tight = solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, fixed);
  std::printf("  GMRES iterations: %d with the forcing, %d at 1e-6 (Newton %d, %d)\n", krylov.linear_iterations,
              tight.linear_iterations, krylov.newton_iterations, tight.newton_iterations);
  EXPECT_NEAR(tight.mu, krylov.mu, 1e-8 * std::abs(direct.mu));
  EXPECT_LT(krylov.linear_iterations, tight.linear_iterations);
  EXPECT_LE(krylov.residual, ho.tolerance);
  // single-precision BILU factors per harmonic: the same cycle (the operator stays exact), the
  // GMRES iterations within a few of the double factors'
  hb_krylov<4> single;
  single.single_precision_factors = true;
  const lco_solution sp = solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, single);
  EXPECT_NEAR(sp.mu, direct.mu, 1e-8 * std::abs(direct.mu));
  EXPECT_NEAR(sp.omega, direct.omega, 1e-8 * direct.omega);
  EXPECT_LE(sp.residual, ho.tolerance);
  EXPECT_LE(std::abs(sp.linear_iterations - krylov.linear_iterations), 3)
      << sp.linear_iterations << " vs " << krylov.linear_iterations;
  // short deflated GMRES cycles (GMRES-DR(10, 4)): the same cycle
  hb_krylov<4> deflated;
  deflated.krylov.restart = 10;
  deflated.krylov.deflation = 4;
  const lco_solution dr = solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, deflated);
  EXPECT_NEAR(dr.mu, direct.mu, 1e-8 * std::abs(direct.mu));
  EXPECT_NEAR(dr.omega, direct.omega, 1e-8 * direct.omega);
  hb_krylov<4> bad;
  bad.eta_max = 1;
  EXPECT_THROW(solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, bad), input_error);
  bad = {};
  bad.krylov.deflation = bad.krylov.restart - 1;
  const std::string why =
      test::error_of<input_error>([&] { solve_lco(s, g, e, lco_fix::amplitude, std::nullopt, ho, bad); });
  EXPECT_TRUE(test::contains(why, "hb_krylov::krylov: deflation")) << why;
}

TEST(HarmonicBalance, KrylovHillExponentsEqualTheDenseOnesAndTheClosedForms) {
  {  // supercritical circle with stable extra directions: 0, -2 r^2, -d_k
    const polar_normal_form base(-1.0, 0.0, 0.3);
    const sparse_view<polar_normal_form> s{base};
    const vec<double> e = base.probe_x1();
    const lco_solution c = solve_lco(s, lco_guess_from_hopf(origin_hopf(base), e, 0.1, 3), e, lco_fix::amplitude, 0.3);
    hill_krylov_options ho;
    ho.exponents = 3;  // 0, -0.18 and -1 (after the copies of the first two at +-i omega)
    ho.subspace = 24;
    const floquet_result k = hill_floquet_krylov<2>(s, c, ho);
    expect_krylov_matches_dense(k, hill_floquet(s, c), 1e-8);
    EXPECT_NEAR(k.max_real, -0.18, 1e-9);
    EXPECT_LT(std::abs(k.trivial), 1e-9);
    EXPECT_TRUE(k.stable);
    // a preconditioning matrix whose pattern differs between the instances: the same exponents
    const pruned_preconditioner_view<polar_normal_form> sp{{base}};
    const floquet_result kp = hill_floquet_krylov<2>(sp, c, ho);
    EXPECT_NEAR(kp.max_real, -0.18, 1e-9);
    EXPECT_NE(kp.linear_iterations, k.linear_iterations);  // another preconditioner
  }
  {  // subcritical circle: unstable, the radial exponent 2 c3 r^2 = +0.08
    const polar_normal_form base(1.0, 0.0, -0.2);
    const sparse_view<polar_normal_form> s{base};
    const vec<double> e = base.probe_x1();
    const lco_solution c = solve_lco(s, lco_guess_from_hopf(origin_hopf(base), e, 0.2, 3), e, lco_fix::parameter, -0.04);
    const floquet_result k = hill_floquet_krylov<2>(s, c);
    EXPECT_NEAR(k.max_real, 0.08, 1e-9);
    EXPECT_FALSE(k.stable);
    expect_krylov_matches_dense(k, hill_floquet(s, c), 1e-8);
  }
  {  // the reactor's cycle (16 cells, 4 harmonics, pitch of the Krylov path B = 2)
    const tubular_reactor r(16);
    const hopf_point hp = reactor_hopf(r);
    const vec<double> e = vec<double>::Unit(r.size(), r.size() - 1);
    const lco_solution c = solve_lco(r, lco_guess_from_hopf(hp, e, 0.01, 4), e, lco_fix::amplitude);
    for (auto pre : {hb_preconditioner_state::mean_state, hb_preconditioner_state::mean_jacobian}) {
      hill_krylov_options ho;
      ho.preconditioner = pre;
      const floquet_result k = hill_floquet_krylov<2>(r, c, ho);
      const floquet_result d = hill_floquet(r, c);
      expect_krylov_matches_dense(k, d, 1e-7);
      EXPECT_TRUE(k.stable);
      EXPECT_GE(k.exponents.size(), 2u);
    }
    {  // short deflated GMRES cycles (GMRES-DR(6, 3)): the same exponents
      hill_krylov_options ho;
      ho.krylov.restart = 6;
      ho.krylov.deflation = 3;
      expect_krylov_matches_dense(hill_floquet_krylov<2>(r, c, ho), hill_floquet(r, c), 1e-7);
    }
    // the options are checked
    hill_krylov_options bad;
    bad.subspace = bad.exponents + 2;
    EXPECT_THROW(hill_floquet_krylov<2>(r, c, bad), input_error);
    bad = {};
    bad.krylov.deflation = bad.krylov.restart - 1;
    const std::string why = test::error_of<input_error>([&] { hill_floquet_krylov<2>(r, c, bad); });
    EXPECT_TRUE(test::contains(why, "krylov: deflation")) << why;
    bad = {};
    bad.krylov.max_iterations = 1;
    const std::string msg = test::error_of<convergence_error>([&] { hill_floquet_krylov<2>(r, c, bad); });
    EXPECT_TRUE(test::contains(msg, "GMRES on Hill's matrix")) << msg;
  }
}

TEST(HarmonicBalance, BadInputIsRefusedAndNonConvergenceIsReported) {
  const polar_normal_form s(-1.0, 0.0, 0.0);
  const vec<double> e = s.probe_x1();
  const hopf_point hp = origin_hopf(s);
  EXPECT_THROW(lco_guess_from_hopf(hp, e, -0.1, 2), input_error);
  EXPECT_THROW(lco_guess_from_hopf(hp, e, 0.1, 0), input_error);
  EXPECT_THROW(lco_guess_from_hopf(hp, vec<double>::Zero(s.size()), 0.1, 2), input_error);
  EXPECT_THROW(lco_guess_from_hopf(hp, vec<double>::Ones(3), 0.1, 2), input_error);
  lco_solution g = lco_guess_from_hopf(hp, e, 0.1, 2);
  const lco_solution kept = g;
  EXPECT_THROW(solve_lco(s, g, vec<double>::Ones(2), lco_fix::amplitude), input_error);
  lco_solution bad = g;
  bad.instances(1, 2) = NAN;
  EXPECT_THROW(solve_lco(s, bad, e, lco_fix::amplitude), input_error);
  bad = g;
  bad.omega = -1;
  EXPECT_THROW(solve_lco(s, bad, e, lco_fix::amplitude), input_error);
  bad = g;
  bad.instances.conservativeResize(Eigen::NoChange, 4);
  EXPECT_THROW(solve_lco(s, bad, e, lco_fix::amplitude), input_error);
  harmonic_balance_options ho;
  ho.max_iterations = 1;
  const std::string msg = test::error_of<convergence_error>([&] { solve_lco(s, g, e, lco_fix::amplitude, 0.5, ho); });
  for (const char* part : {"solve_lco", "Newton iteration 1", "not converged", "H = 2"})
    EXPECT_TRUE(test::contains(msg, part)) << msg;
  ho.tolerance = -1;
  EXPECT_THROW(solve_lco(s, g, e, lco_fix::amplitude, 0.5, ho), input_error);
  EXPECT_EQ((g.instances - kept.instances).norm(), 0.0);  // the guess is untouched
  hill_options hl;
  hl.max_size = 10;
  EXPECT_THROW(hill_floquet(s, solve_lco(s, g, e, lco_fix::amplitude), hl), input_error);
}
