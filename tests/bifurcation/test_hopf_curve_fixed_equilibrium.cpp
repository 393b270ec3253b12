// The Krylov tracer of the fixed-equilibrium Hopf curve with nested steady solves, and with the joint
// corrector (hopf_curve_fixed_equilibrium.hpp), checked against independent references:
//  * a synthetic family whose equilibrium w*(nu) depends on nu but not on mu and whose Hopf
//    curve is the unit circle mu^2 + nu^2 = 1 (omega = 1 + 0.3 mu), so it turns in nu at nu = 1
//    (dnu/ds = 0, where the fixed-nu Hopf Jacobian is singular): closed form, the dense spectrum
//    at every point, and trace_hopf_curve (the full (3n+3) system with w as unknowns and a
//    sparse LU: independent linear algebra) at the same landed points;
//  * the heavy-case aerofoil (spec 05, mu_s = 100) on the very coarse grid from M = 0.78: the
//    point landed on M = 0.79 against solve_hopf_krylov at M = 0.79 from an independent steady
//    solve (solve_steady, pseudo-transient) and against the full-system tracer's value there;
//  * bad input and a family that cannot be built past some nu (step failure reported).
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include <gtest/gtest.h>

#include "support/aerofoil_cases.hpp"
#include "support/hopf_test_systems.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <chrono>
#include <cmath>
#include <complex>
#include <iomanip>
#include <iostream>
#include <limits>

using namespace aerohopf;

namespace {

/// dw/dt = T g(T^{-1} (w - w*(nu))) with g(0) = 0, g'(0) = block diag(B(mu, nu), -1, -2, ...),
/// B = [[a, -b], [b, a]], a = 1 - mu^2 - nu^2, b = 1 + 0.3 mu: equilibrium w*(nu) for every mu,
/// Hopf points on the unit circle in (mu, nu) with omega = b. Sparse Jacobian (the Krylov tracer
/// needs one) and an approximate Jacobian A - 0.5 I (as the modified-order one of the aerofoil:
/// L - i omega I stays regular at the Hopf point, the preconditioner is not exact).
class circle_family_system {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int n = 8;

  /// kink > 0: a = 1 - mu^2 - nu^2 + kink max(0, nu - 0.7), continuous but not differentiable
  /// in nu at 0.7 (a C1 discretisation's switch crossed by the equilibrium); the curve
  /// mu^2 = 1 - nu^2 + kink max(0, nu - 0.7) turns there by more than 90 degrees for kink = 5.
  explicit circle_family_system(double nu, double kink = 0.0) : nu_(nu), kink_(kink) {
    t_.setZero(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (std::abs(i - j) <= 2) t_(i, j) = (i == j ? 2.0 : 0.0) + 0.3 * std::sin(1.0 + i + 2.0 * j);
    ti_ = t_.inverse();
  }
  Eigen::Index size() const { return n; }

  vec<double> equilibrium() const {
    vec<double> w(n);
    for (int i = 0; i < n; ++i) w[i] = 0.5 * std::sin(nu_ + 0.3 * i) + std::cos(nu_ * (1.0 - 0.2 * i)) + 0.1 * i;
    return w;
  }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    const vec<double> we = equilibrium();
    vec<T> z(n);
    for (int i = 0; i < n; ++i) {
      z[i] = T(0.0);
      for (int j = 0; j < n; ++j) z[i] += T(ti_(i, j)) * (w[j] - T(we[j]));
    }
    const T a = T(1.0) - mu * mu - T(nu_ * nu_ - kink_ * std::max(0.0, nu_ - 0.7)), b = T(1.0) + T(0.3) * mu;
    vec<T> g(n);
    g[0] = a * z[0] - b * z[1] + T(0.5) * z[0] * z[0] - z[1] * z[2];
    g[1] = b * z[0] + a * z[1] + z[0] * z[1] + T(0.3) * z[2] * z[2];
    for (int j = 2; j < n; ++j) g[j] = -T(double(j - 1)) * z[j] + z[0] * z[0] - T(0.5) * z[0] * z[1];
    vec<T> f(n);
    for (int i = 0; i < n; ++i) {
      f[i] = T(0.0);
      for (int j = 0; j < n; ++j) f[i] += T(t_(i, j)) * g[j];
    }
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(n, n);
    for (int j = 0; j < n; ++j) a.col(j) = jacobian_product(*this, w, mu, vec<double>(vec<double>::Unit(n, j)));
    return a.sparseView();
  }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a = Eigen::MatrixXd(jacobian(w, mu)) - 0.5 * Eigen::MatrixXd::Identity(n, n);
    return a.sparseView();
  }

 private:
  double nu_, kink_ = 0;
  Eigen::MatrixXd t_, ti_;
};

double spectrum_distance(const circle_family_system& sys, const vec<double>& w, double mu, double omega) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(sys.jacobian(w, mu)), false);
  double best = 1e300;
  for (const auto& l : es.eigenvalues()) best = std::min(best, std::abs(l - std::complex<double>(0, omega)));
  return best;
}

/// Start near (mu, nu0) on the circle: perturbed equilibrium, inverse-power eigenvector.
hopf_point circle_start(double nu0, double mu_guess, double omega_guess) {
  const circle_family_system sys(nu0);
  vec<double> w = sys.equilibrium();
  hopf_point h = hopf_start(sys, w, mu_guess, omega_guess);
  h.w.array() += 1e-4;  // the nested steady Newton has to polish it
  return h;
}

hopf_curve_options circle_options() {
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.nu_targets = {0.8};
  o.mu_min = -0.9;
  o.verbose = true;
  return o;
}

/// Worst closed-form errors over the points of a traced circle (mu^2 + nu^2 = 1, omega = 1 + 0.3 mu,
/// w = w*(nu), i omega in the dense spectrum), and its landed points in order.
struct circle_errors {
  double circle = 0, omega = 0, w = 0, ev = 0;
  std::vector<const hopf_curve_point*> landed;
};
circle_errors check_circle(const std::vector<hopf_curve_point>& points) {
  circle_errors e;
  for (const auto& pt : points) {
    const circle_family_system sys(pt.nu);
    e.circle = std::max(e.circle, std::abs(pt.mu * pt.mu + pt.nu * pt.nu - 1));
    e.omega = std::max(e.omega, std::abs(pt.omega - (1 + 0.3 * pt.mu)));
    e.w = std::max(e.w, (pt.w - sys.equilibrium()).lpNorm<Eigen::Infinity>());
    e.ev = std::max(e.ev, spectrum_distance(sys, pt.w, pt.mu, pt.omega));
    if (pt.landed) e.landed.push_back(&pt);
  }
  return e;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

TEST(hopf_curve_fixed_equilibrium, circle_through_the_turning_point_in_nu) {
  auto family = [](double nu) { return circle_family_system(nu); };
  const double nu0 = 0.6;
  const auto t0 = std::chrono::steady_clock::now();
  const fixed_equilibrium_hopf_curve_result r =
      trace_fixed_equilibrium_hopf_curve<2>(family, nu0, circle_start(nu0, 0.78, 1.2), circle_options(), +1);
  std::cout << "symmetric circle: " << r.points.size() << " points, " << r.failed_correctors << " failed correctors, "
            << r.linear_iterations << " GMRES iterations, " << r.steady_solves << " steady solves, "
            << seconds_since(t0) << " s; " << r.stop_reason << "\n";
  EXPECT_EQ(r.stop, hopf_curve_stop::mu_bounds);
  ASSERT_GE(r.points.size(), 10u);
  ASSERT_EQ(r.stats.size(), r.points.size());
  double nu_hi = -9;
  for (const auto& pt : r.points) nu_hi = std::max(nu_hi, pt.nu);
  const circle_errors err = check_circle(r.points);
  const auto& landed = err.landed;
  std::cout << "symmetric circle: max |mu^2+nu^2-1| " << err.circle << ", max |omega error| " << err.omega
            << ", max |w - w*| " << err.w << ", max dist(i omega, spectrum) " << err.ev << "\n";
  EXPECT_LT(err.circle, 1e-9);
  EXPECT_LT(err.omega, 1e-9);
  EXPECT_LT(err.w, 1e-10);
  EXPECT_LT(err.ev, 1e-8);
  EXPECT_GT(nu_hi, 0.99);  // through the turning point nu = 1 (mu = 0)
  // nu = 0.8 crossed before the turn (mu = 0.6) and after it (mu = -0.6); then the bound mu = -0.9
  ASSERT_EQ(landed.size(), 3u);
  EXPECT_NEAR(landed[0]->nu, 0.8, 1e-13);
  EXPECT_NEAR(landed[0]->mu, 0.6, 1e-9);
  EXPECT_NEAR(landed[1]->nu, 0.8, 1e-13);
  EXPECT_NEAR(landed[1]->mu, -0.6, 1e-9);
  EXPECT_NEAR(landed[2]->mu, -0.9, 1e-13);
  EXPECT_NEAR(landed[2]->nu, std::sqrt(1 - 0.81), 1e-9);
  EXPECT_TRUE(r.missed_targets.empty());

  // The same curve by the full-system tracer (w unknown, sparse LU): the same landed points.
  const hopf_curve_result full = trace_hopf_curve(family, nu0, circle_start(nu0, 0.78, 1.2), circle_options(), +1);
  std::vector<const hopf_curve_point*> full_landed;
  for (const auto& pt : full.points)
    if (pt.landed) full_landed.push_back(&pt);
  ASSERT_EQ(full_landed.size(), landed.size());
  for (std::size_t k = 0; k < landed.size(); ++k) {
    EXPECT_NEAR(landed[k]->nu, full_landed[k]->nu, 1e-10) << "landed point " << k;
    EXPECT_NEAR(landed[k]->mu, full_landed[k]->mu, 1e-10) << "landed point " << k;
    EXPECT_NEAR(landed[k]->omega, full_landed[k]->omega, 1e-10) << "landed point " << k;
    EXPECT_LT((landed[k]->w - full_landed[k]->w).lpNorm<Eigen::Infinity>(), 1e-10) << "landed point " << k;
  }
}

// The joint corrector (w an unknown of the corrector, one flow Newton step per iteration) on the
// same circle: the same closed-form checks, the nested tracer's landed points, no nested steady
// solve after the start, and fewer flow Newton steps than the nested solves took.
TEST(hopf_curve_fixed_equilibrium, joint_corrector_traces_the_same_circle_without_nested_steady_solves) {
  auto family = [](double nu) { return circle_family_system(nu); };
  const double nu0 = 0.6;
  fixed_equilibrium_hopf_curve_options joint;
  joint.joint_equilibrium = true;
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, nu0, circle_start(nu0, 0.78, 1.2), circle_options(), +1, joint);
  const auto nested = trace_fixed_equilibrium_hopf_curve<2>(family, nu0, circle_start(nu0, 0.78, 1.2), circle_options(), +1);
  auto flow_steps = [](const fixed_equilibrium_hopf_curve_result& q) {
    int newton = 0;
    for (const auto& pt : q.points) newton += pt.newton_iterations;
    return std::pair{q.steady_iterations, newton};
  };
  const auto [jk, jn] = flow_steps(r);
  const auto [nk, nn] = flow_steps(nested);
  std::cout << "joint circle: " << r.points.size() << " points, " << r.failed_correctors << " failed correctors, "
            << r.steady_solves << " steady solves, " << jk << " flow Newton steps, " << jn
            << " corrector iterations; nested: " << nested.points.size() << " points, " << nested.steady_solves
            << " steady solves, " << nk << " flow Newton steps, " << nn << " corrector iterations\n";
  EXPECT_EQ(r.stop, hopf_curve_stop::mu_bounds);
  EXPECT_EQ(r.steady_solves, 1);  // the start's equilibrium only
  EXPECT_LT(jk, nk);
  EXPECT_LE(jn, nn + static_cast<int>(nested.points.size()));  // about as many corrector iterations
  const circle_errors err = check_circle(r.points);
  const auto& landed = err.landed;
  std::vector<const hopf_curve_point*> nested_landed;
  for (const auto& pt : nested.points)
    if (pt.landed) nested_landed.push_back(&pt);
  std::cout << "joint circle: max |mu^2+nu^2-1| " << err.circle << ", max |omega error| " << err.omega
            << ", max |w - w*| " << err.w << ", max dist(i omega, spectrum) " << err.ev << "\n";
  EXPECT_LT(err.circle, 1e-9);
  EXPECT_LT(err.omega, 1e-9);
  EXPECT_LT(err.w, 1e-10);
  EXPECT_LT(err.ev, 1e-8);
  ASSERT_EQ(landed.size(), 3u);
  ASSERT_EQ(nested_landed.size(), 3u);
  for (std::size_t k = 0; k < landed.size(); ++k) {
    EXPECT_NEAR(landed[k]->nu, nested_landed[k]->nu, 1e-10) << "landed point " << k;
    EXPECT_NEAR(landed[k]->mu, nested_landed[k]->mu, 1e-10) << "landed point " << k;
    EXPECT_NEAR(landed[k]->omega, nested_landed[k]->omega, 1e-10) << "landed point " << k;
    EXPECT_LT((landed[k]->w - nested_landed[k]->w).lpNorm<Eigen::Infinity>(), 1e-10) << "landed point " << k;
  }
  // the kink of the C1 family crossed the same way (fixed-nu fallback through the joint corrector)
  auto kinked = [](double nu) { return circle_family_system(nu, 5.0); };
  hopf_curve_options o = circle_options();
  o.nu_targets = {0.75};
  o.mu_min = -std::numeric_limits<double>::infinity();
  o.nu_max = 0.8;
  o.min_step = 1e-4;
  o.verbose = false;
  const auto k = trace_fixed_equilibrium_hopf_curve<2>(kinked, 0.6, circle_start(0.6, 0.78, 1.2), o, 1, joint);
  EXPECT_EQ(k.stop, hopf_curve_stop::nu_bounds);
  const hopf_curve_point* at = nullptr;
  for (const auto& pt : k.points)
    if (pt.landed && std::abs(pt.nu - 0.75) < 1e-12) at = &pt;
  ASSERT_NE(at, nullptr);
  EXPECT_NEAR(at->mu, std::sqrt(1 - 0.5625 + 0.25), 1e-9);
}

TEST(hopf_curve_fixed_equilibrium, decreasing_direction_lands_on_the_lower_bound) {
  auto family = [](double nu) { return circle_family_system(nu); };
  hopf_curve_options o = circle_options();
  o.nu_min = 0.3;
  o.nu_targets = {};
  o.mu_min = -std::numeric_limits<double>::infinity();
  o.verbose = false;
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, circle_start(0.6, 0.78, 1.2), o, -1);
  EXPECT_EQ(r.stop, hopf_curve_stop::nu_bounds);
  ASSERT_GE(r.points.size(), 3u);
  EXPECT_NEAR(r.points.back().nu, 0.3, 1e-13);
  EXPECT_NEAR(r.points.back().mu, std::sqrt(1 - 0.09), 1e-9);
  for (std::size_t k = 1; k < r.points.size(); ++k) EXPECT_LT(r.points[k].nu, r.points[k - 1].nu);
}

// stop_after ends the trace at the first accepted point it returns true for: here the first
// point past the turning point nu = 1 of the circle (nu decreasing again), i.e. where a caller
// that needs a boundary single-valued in nu hands over. Both tracers.
TEST(hopf_curve_fixed_equilibrium, stop_after_ends_the_trace_where_the_caller_asks) {
  auto family = [](double nu) { return circle_family_system(nu); };
  hopf_curve_options o = circle_options();
  o.verbose = false;
  double nu_hi = -9;
  int calls = 0;
  o.stop_after = [&](const hopf_curve_point& p) {
    ++calls;
    nu_hi = std::max(nu_hi, p.nu);
    return p.nu < nu_hi - 1e-3;
  };
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, circle_start(0.6, 0.78, 1.2), o, +1);
  EXPECT_EQ(r.stop, hopf_curve_stop::requested);
  ASSERT_GE(r.points.size(), 3u);
  EXPECT_EQ(calls, static_cast<int>(r.points.size()));  // every accepted point, the stopping one last
  EXPECT_GT(nu_hi, 0.99);
  EXPECT_LT(r.points.back().nu, nu_hi - 1e-3);
  EXPECT_LT(r.points.back().mu, 0);  // just past the turn (mu = 0 there)
  for (std::size_t k = 0; k + 1 < r.points.size(); ++k) EXPECT_GE(r.points[k].mu, -0.2) << k;
  // the full-system tracer honours it the same way
  nu_hi = -9;
  calls = 0;
  const auto full = trace_hopf_curve(family, 0.6, circle_start(0.6, 0.78, 1.2), o, +1);
  EXPECT_EQ(full.stop, hopf_curve_stop::requested);
  EXPECT_EQ(calls, static_cast<int>(full.points.size()));
  EXPECT_LT(full.points.back().nu, nu_hi - 1e-3);
  EXPECT_LT(full.points.back().mu, 0);
}

// A kink of the curve at nu = 0.7 where it turns by ~117 degrees in the metric: the arclength
// corrector cannot cross it at any step size; the fixed-nu fallback does.
TEST(hopf_curve_fixed_equilibrium, crosses_a_kink_at_fixed_nu) {
  auto family = [](double nu) { return circle_family_system(nu, 5.0); };
  hopf_curve_options o = circle_options();
  o.nu_targets = {0.75};
  o.mu_min = -std::numeric_limits<double>::infinity();
  o.nu_max = 0.8;
  o.min_step = 1e-4;
  o.verbose = false;
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, circle_start(0.6, 0.78, 1.2), o);
  std::cout << "kink: " << r.points.size() << " points, " << r.kink_steps << " fixed-parameter steps, "
            << r.failed_correctors << " failed correctors; " << r.stop_reason << "\n";
  EXPECT_EQ(r.stop, hopf_curve_stop::nu_bounds);
  EXPECT_GE(r.kink_steps, 1);
  double worst = 0;
  for (const auto& pt : r.points)
    worst = std::max(worst, std::abs(pt.mu * pt.mu - (1 - pt.nu * pt.nu + 5.0 * std::max(0.0, pt.nu - 0.7))));
  EXPECT_LT(worst, 1e-9);
  const hopf_curve_point* at = nullptr;
  for (const auto& pt : r.points)
    if (pt.landed && std::abs(pt.nu - 0.75) < 1e-12) at = &pt;
  ASSERT_NE(at, nullptr);
  EXPECT_NEAR(at->mu, std::sqrt(1 - 0.5625 + 0.25), 1e-9);
  EXPECT_NEAR(at->omega, 1 + 0.3 * at->mu, 1e-9);
  // without the fallback the trace stops at the kink
  fixed_equilibrium_hopf_curve_options so;
  so.kink_fallback = false;
  o.throw_on_failure = false;
  const auto stuck = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, circle_start(0.6, 0.78, 1.2), o, 1, so);
  EXPECT_EQ(stuck.stop, hopf_curve_stop::step_failure);
  EXPECT_LT(stuck.points.back().nu, 0.7 + 1e-3);
}

TEST(hopf_curve_fixed_equilibrium, refuses_bad_input_and_reports_step_failure) {
  auto family = [](double nu) { return circle_family_system(nu); };
  const hopf_point start = circle_start(0.6, 0.78, 1.2);
  hopf_curve_options o = circle_options();
  o.verbose = false;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 0), input_error);
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, NAN, start, o), input_error);
  hopf_curve_options bad = o;
  bad.step = 0;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, bad), input_error);
  bad = o;
  bad.nu_min = 0.7;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, bad), input_error);
  hopf_point short_p = start;
  short_p.p = short_p.p.head(3).eval();
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, short_p, o), input_error);
  hopf_point short_w = start;
  short_w.w = short_w.w.head(5).eval();
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, short_w, o), input_error);
  fixed_equilibrium_hopf_curve_options so;
  so.fill_level = -1;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so), input_error);
  so = {};
  so.steady.abs_tolerance = 0;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so), input_error);
  so = {};
  so.derivative_tolerance = 1.0;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so), input_error);

  // A family that cannot be built beyond nu = 0.7 (a steady solve failing past some Mach number)
  auto limited = [](double nu) {
    require(nu <= 0.7, "test family: no system beyond nu = 0.7 (asked for ", nu, ")");
    return circle_family_system(nu);
  };
  o.min_step = 1e-3;
  try {
    trace_fixed_equilibrium_hopf_curve<2>(limited, 0.6, start, o);
    ADD_FAILURE() << "no convergence_error";
  } catch (const convergence_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("min_step"), std::string::npos) << m;
    EXPECT_NE(m.find("no system beyond nu = 0.7"), std::string::npos) << m;
  }
  o.throw_on_failure = false;
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(limited, 0.6, start, o);
  EXPECT_EQ(r.stop, hopf_curve_stop::step_failure);
  ASSERT_GE(r.points.size(), 2u);
  EXPECT_LE(r.points.back().nu, 0.7);
  EXPECT_GT(r.points.back().nu, 0.69);
}

// iterate_distance: a corrector iterate farther than iterate_distance x step from its prediction
// is abandoned before the equilibrium at its nu is solved. With a radius below the corrector's
// first move every step fails, the trace reports why and the family is never built away from a
// prediction; the default radius leaves the circle's trace unchanged.
TEST(hopf_curve_fixed_equilibrium, abandons_a_corrector_that_leaves_the_trust_radius) {
  std::vector<double> built;
  auto family = [&](double nu) {
    built.push_back(nu);
    return circle_family_system(nu);
  };
  const hopf_point start = circle_start(0.6, 0.78, 1.2);
  hopf_curve_options o = circle_options();
  o.verbose = false;
  o.throw_on_failure = false;
  o.min_step = 0.05;
  fixed_equilibrium_hopf_curve_options so;
  so.iterate_distance = 1e-9;
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so);
  EXPECT_EQ(r.stop, hopf_curve_stop::step_failure);
  EXPECT_EQ(r.points.size(), 1u);
  EXPECT_NE(r.stop_reason.find("from the prediction (more than"), std::string::npos) << r.stop_reason;
  EXPECT_GE(r.failed_correctors, 1);
  // only the start and the predictions were built: each lies within one step of nu0 = 0.6
  for (double nu : built) EXPECT_LE(std::abs(nu - 0.6), o.step * o.nu_scale + 1e-12) << nu;
  built.clear();
  const auto same = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, fixed_equilibrium_hopf_curve_options{});
  so = {};
  so.iterate_distance = std::numeric_limits<double>::infinity();
  const auto off = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so);
  ASSERT_EQ(same.points.size(), off.points.size());
  for (std::size_t k = 0; k < same.points.size(); ++k) EXPECT_EQ(same.points[k].nu, off.points[k].nu) << k;
  so.iterate_distance = 0;
  EXPECT_THROW(trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, o, 1, so), input_error);
}

// Heavy case (mu_s = 100) on the very coarse grid (stride 8, as the example), from M = 0.78 to
// the landed point at M = 0.79.
TEST(hopf_curve_fixed_equilibrium, aerofoil_heavy_very_coarse_matches_fixed_mach_hopf_solve) {
  using models::aerofoil_system;
  const auto make = test_support::heavy_very_coarse_aerofoil;
  const double m0 = 0.78, m1 = 0.79;
  const auto t0 = std::chrono::steady_clock::now();
  const aerofoil_system s0 = make(m0);
  const vec<double> w0 = s0.steady_equilibrium();
  hopf_point guess = hopf_start(s0, w0, 4.6, 0.22);
  guess.mu = 4.6;
  hopf_curve_options o;
  o.mu_scale = 0.5;
  o.nu_scale = 0.05;
  o.omega_scale = 0.05;
  o.step = 0.5;
  o.max_step = 1.0;
  o.min_step = 1e-3;
  o.nu_min = m0 - 1e-9;
  o.nu_targets = {m1};
  o.max_points = 3;
  o.fast_iterations = 4;
  o.verbose = true;
  o.label = "heavy very coarse";
  const auto r = trace_fixed_equilibrium_hopf_curve<4>(make, m0, guess, o);
  std::cout << "aerofoil: " << r.points.size() << " points in " << seconds_since(t0) << " s, stop: " << r.stop_reason
            << "\n";
  const hopf_curve_point* at = nullptr;
  for (const auto& pt : r.points)
    if (pt.landed) at = &pt;
  ASSERT_NE(at, nullptr) << "M = 0.79 not reached";
  EXPECT_NEAR(at->nu, m1, 1e-13);
  // the start against the full-system tracer's start (out/aerofoil_flutter/hopf_curve_heavy_very_coarse.csv)
  EXPECT_NEAR(std::abs(r.points[0].mu), 3.5484449637967996, 1e-7);
  EXPECT_NEAR(r.points[0].omega, 0.23423217154293471, 1e-7);
  // M = 0.79: independent steady solve (pseudo-transient, tight) and the fixed-Mach Hopf solver
  const aerofoil_system s1 = make(m1);
  flow::steady_options so;
  so.residual_drop = 1e-13;
  so.max_steps = 500;
  const vec<double> w1 = s1.steady_equilibrium(so);
  EXPECT_LT((at->w - w1).lpNorm<Eigen::Infinity>(), 1e-8);
  hopf_options ho;
  ho.fixed_equilibrium = true;
  hopf_point g = at->point();
  g.w = w1;
  g.mu *= 1.01;
  g.omega *= 0.99;
  const hopf_result h = solve_hopf_krylov<4>(s1, g, ho);
  std::cout << std::setprecision(12) << "M = 0.79: traced Ubar " << at->mu << ", omega " << at->omega
            << "; fixed-Mach solve " << h.point.mu << ", " << h.point.omega << "\n";
  EXPECT_NEAR(at->mu, h.point.mu, 1e-8);
  EXPECT_NEAR(at->omega, h.point.omega, 1e-8);
  // and the full-system tracer's landed point at M = 0.79
  EXPECT_NEAR(std::abs(at->mu), 3.5379158790270173, 1e-7);
  EXPECT_NEAR(at->omega, 0.23343358002885775, 1e-7);
  // the joint corrector (flow as an unknown of the corrector) lands on the same point
  fixed_equilibrium_hopf_curve_options joint;
  joint.joint_equilibrium = true;
  o.label = "heavy very coarse joint";
  const auto rj = trace_fixed_equilibrium_hopf_curve<4>(make, m0, guess, o, +1, joint);
  const hopf_curve_point* atj = nullptr;
  std::size_t kj = 0;
  for (std::size_t k = 0; k < rj.points.size(); ++k)
    if (rj.points[k].landed) atj = &rj.points[kj = k];
  ASSERT_NE(atj, nullptr) << "joint corrector: M = 0.79 not reached";
  std::cout << "joint: " << rj.points.size() << " points, " << rj.steady_solves << " nested steady solves (nested: "
            << r.steady_solves << "), Ubar " << atj->mu << ", omega " << atj->omega << "\n";
  EXPECT_EQ(rj.stats[kj].steady_solves, 0);  // the landing converged by the joint corrector
  EXPECT_GT(rj.stats[kj].steady_iterations, 0);
  EXPECT_LT(rj.steady_solves, r.steady_solves);
  EXPECT_NEAR(atj->mu, h.point.mu, 1e-8);
  EXPECT_NEAR(atj->omega, h.point.omega, 1e-8);
  EXPECT_LT((atj->w - w1).lpNorm<Eigen::Infinity>(), 1e-8);
}

// ---- hostile input ----
namespace {
using test_support::faulty_system;
using test_support::mu_shifted_system;

auto faulty_circle_family(std::shared_ptr<long> counter, long at, long count) {
  return [=](double nu) { return faulty_system<circle_family_system>(circle_family_system(nu), counter, at, count); };
}

hopf_curve_options quiet_circle_options() {
  hopf_curve_options o = circle_options();
  o.verbose = false;
  o.min_step = 1e-3;
  return o;
}

const hopf_curve_point* landed_at(const std::vector<hopf_curve_point>& pts, double nu, double mu_sign) {
  for (const auto& p : pts)
    if (p.landed && std::abs(p.nu - nu) < 1e-12 && p.mu * mu_sign > 0) return &p;
  return nullptr;
}
}  // namespace

TEST(hopf_curve_fixed_equilibrium_hostile, options_are_checked_by_name) {
  auto family = [](double nu) { return circle_family_system(nu); };
  const hopf_point start = circle_start(0.6, 0.78, 1.2);
  auto message = [&](const hopf_curve_options& o, const fixed_equilibrium_hopf_curve_options& so,
                     const hopf_point& s) -> std::string {
    try {
      trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, s, o, 1, so);
    } catch (const input_error& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("wrong exception type: ") + e.what();
    }
    return "no exception";
  };
  const hopf_curve_options good = quiet_circle_options();
  const fixed_equilibrium_hopf_curve_options sgood;
  auto expect = [&](const hopf_curve_options& o, const fixed_equilibrium_hopf_curve_options& so, const hopf_point& s,
                    const char* part) {
    const std::string m = message(o, so, s);
    EXPECT_NE(m.find(part), std::string::npos) << part << " not in: " << m;
  };
  hopf_curve_options o = good;
  o.nu_targets = {NAN};
  expect(o, sgood, start, "nu_targets entry 0");
  o = good;
  o.min_cosine = -2;
  expect(o, sgood, start, "min_cosine");
  o = good;
  o.newton.rel_tolerance = -1;
  expect(o, sgood, start, "newton.rel_tolerance");
  o = good;
  o.start.newton.abs_tolerance = NAN;
  expect(o, sgood, start, "newton.abs_tolerance");
  fixed_equilibrium_hopf_curve_options so = sgood;
  so.kink_distance = 0;
  expect(good, so, start, "kink_distance");
  so = sgood;
  so.steady.relaxation = 2;
  expect(good, so, start, "steady.relaxation");
  hopf_point s = start;
  s.w[1] = NAN;
  expect(good, sgood, s, "start.w (equilibrium at nu0) entry 1");
  s = start;
  s.p = s.p.head(5).eval();
  expect(good, sgood, s, "start.p (eigenvector) has 5 entries");
}

// A family whose equilibrium moves with mu: the symmetric tracer's fixed-equilibrium Hopf
// system cannot follow it; the start point is refused (the equilibrium solved at the guess's mu
// does not hold at mu*) instead of tracing a curve of non-equilibria.
TEST(hopf_curve_fixed_equilibrium_hostile, an_equilibrium_that_moves_with_mu_is_refused) {
  const vec<double> c = vec<double>::LinSpaced(circle_family_system::n, 0.2, -0.3);
  auto family = [c](double nu) { return mu_shifted_system<circle_family_system>(circle_family_system(nu), c); };
  hopf_point start = circle_start(0.6, 0.78, 1.2);
  start.w += c * start.mu;
  try {
    const auto r = trace_fixed_equilibrium_hopf_curve<2>(family, 0.6, start, quiet_circle_options());
    ADD_FAILURE() << "traced " << r.points.size() << " points of a moving equilibrium";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("equilibrium does not hold"), std::string::npos) << e.what();
  }
}

// NaN from some call on for good: the trace stops with step_failure keeping the points accepted
// so far, the reason names the tracer, the point and the corrector's last accepted iterate;
// restarted from the last point without the fault, it lands on the same point as the
// uninjected trace. A single NaN is survived (same landed point).
TEST(hopf_curve_fixed_equilibrium_hostile, nan_residual_stops_with_context_and_the_trace_restarts) {
  const hopf_point start = circle_start(0.6, 0.78, 1.2);
  const hopf_point start_copy = start;
  hopf_curve_options o = quiet_circle_options();
  o.label = "injected symmetric curve";
  auto clean = std::make_shared<long>(0);
  long calls_at_point2 = -1;
  int seen = 0;
  hopf_curve_options counting = o;
  counting.observer = [&](const hopf_curve_point&) {
    if (++seen == 3) calls_at_point2 = *clean;
  };
  const auto ref = trace_fixed_equilibrium_hopf_curve<2>(faulty_circle_family(clean, 1L << 40, 0), 0.6, start, counting);
  const hopf_curve_point* ref_land = landed_at(ref.points, 0.8, +1);
  ASSERT_NE(ref_land, nullptr);
  ASSERT_GT(calls_at_point2, 0);
  ASSERT_LT(ref.points[2].nu, 0.8);

  auto once = std::make_shared<long>(0);
  const auto survived = trace_fixed_equilibrium_hopf_curve<2>(faulty_circle_family(once, calls_at_point2 + 3, 1), 0.6, start, o);
  const hopf_curve_point* s_land = landed_at(survived.points, 0.8, +1);
  ASSERT_NE(s_land, nullptr);
  EXPECT_NEAR(s_land->mu, ref_land->mu, 1e-9);
  EXPECT_NEAR(s_land->omega, ref_land->omega, 1e-9);

  o.throw_on_failure = false;
  auto counter = std::make_shared<long>(0);
  const auto r = trace_fixed_equilibrium_hopf_curve<2>(faulty_circle_family(counter, calls_at_point2 + 1, 1L << 40), 0.6, start, o);
  EXPECT_EQ(r.stop, hopf_curve_stop::step_failure);
  ASSERT_EQ(r.points.size(), 3u);
  for (const char* part : {"injected symmetric curve", "point 2", "last accepted iterate", "||F|| = ", "nu = ", "mu = ",
                           "omega = "})
    EXPECT_NE(r.stop_reason.find(part), std::string::npos) << part << " not in: " << r.stop_reason;
  EXPECT_EQ(start.w, start_copy.w);
  EXPECT_EQ(start.p, start_copy.p);
  EXPECT_EQ(start.mu, start_copy.mu);
  o.throw_on_failure = true;
  auto family = [](double nu) { return circle_family_system(nu); };
  const hopf_curve_point& last = r.points.back();
  const auto again = trace_fixed_equilibrium_hopf_curve<2>(family, last.nu, last.point(), o);
  const hopf_curve_point* land = landed_at(again.points, 0.8, +1);
  ASSERT_NE(land, nullptr);
  EXPECT_NEAR(land->mu, ref_land->mu, 1e-9);
  EXPECT_NEAR(land->omega, ref_land->omega, 1e-9);
}
