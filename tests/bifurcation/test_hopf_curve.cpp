// Two-parameter continuation of Hopf points (hopf_curve.hpp), checked against independent
// references:
//  * a synthetic family whose Hopf curve is known in closed form and turns in both parameters
//    (the unit circle mu^2 + nu^2 = 1, omega = 1 + 0.3 mu), hidden behind a parameter-dependent
//    equilibrium and a change of variables so that no block of the method is trivial;
//  * a synthetic family whose Hopf curve ends at a Bogdanov-Takens point (omega = sqrt(-nu));
//  * the tubular reactor with nu = beta: traced points against the dense-spectrum crossing
//    (bisection on max Re lambda along the equilibrium branch) at the same beta and against
//    solve_hopf at fixed beta; the landed point at beta = 2.5 against the known mu* = 0.165042718.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/models/tubular_reactor.hpp>

#include "support/hopf_test_systems.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <chrono>
#include <cmath>
#include <complex>
#include <iostream>

using namespace aerohopf;

namespace {

/// dw/dt = T g(T^{-1} (w - w*(mu, nu))) with g(0) = 0 and g'(0) = block diag(B(mu, nu), -1, -2, ...):
/// the equilibrium is w*(mu, nu), its spectrum that of B plus -1, -2, ... (slaved stable
/// modes). B = [[a, -b], [b, a]] (circle: a = 1 - mu^2 - nu^2, b = 1 + 0.3 mu) or
/// B = [[a, 1], [nu, a]] (Bogdanov-Takens: a = mu - 0.5 nu - 0.2 nu^2, eigenvalues a +- sqrt(nu)).
class synthetic_system {
 public:
  using jacobian_type = Eigen::MatrixXd;
  enum kind { circle, bogdanov_takens };

  synthetic_system(kind k, double nu, int slaved = 6) : k_(k), nu_(nu), n_(2 + slaved) {
    t_.resize(n_, n_);
    for (int i = 0; i < n_; ++i)
      for (int j = 0; j < n_; ++j) t_(i, j) = (i == j ? 2.0 : 0.0) + 0.3 * std::sin(1.0 + i + 2.0 * j);
    ti_ = t_.inverse();
  }
  Eigen::Index size() const { return n_; }

  template <class T>
  vec<T> equilibrium(const T& mu) const {
    using std::cos;
    using std::sin;
    vec<T> w(n_);
    for (int i = 0; i < n_; ++i) w[i] = sin(T(nu_ + 0.3 * i)) * 0.5 + mu * T(0.1 * (i + 1)) + cos(mu * T(nu_ - 0.2 * i));
    return w;
  }
  vec<double> equilibrium_d(double mu) const { return equilibrium<double>(mu); }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    const vec<T> we = equilibrium<T>(mu);
    vec<T> z(n_);
    for (int i = 0; i < n_; ++i) {
      z[i] = T(0.0);
      for (int j = 0; j < n_; ++j) z[i] += T(ti_(i, j)) * (w[j] - we[j]);
    }
    vec<T> g(n_);
    if (k_ == circle) {
      const T a = T(1.0) - mu * mu - T(nu_ * nu_), b = T(1.0) + T(0.3) * mu;
      g[0] = a * z[0] - b * z[1] + T(0.5) * z[0] * z[0] - z[1] * z[2];
      g[1] = b * z[0] + a * z[1] + z[0] * z[1] + T(0.3) * z[2] * z[2];
    } else {
      const T a = mu - T(0.5 * nu_ + 0.2 * nu_ * nu_);
      g[0] = a * z[0] + z[1] + T(0.5) * z[0] * z[0] - z[1] * z[2];
      g[1] = T(nu_) * z[0] + a * z[1] + z[0] * z[1] + T(0.3) * z[2] * z[2];
    }
    for (int j = 2; j < n_; ++j) g[j] = -T(double(j - 1)) * z[j] + z[0] * z[0] - T(0.5) * z[0] * z[1];
    vec<T> f(n_);
    for (int i = 0; i < n_; ++i) {
      f[i] = T(0.0);
      for (int j = 0; j < n_; ++j) f[i] += T(t_(i, j)) * g[j];
    }
    return f;
  }
  /// Exact Jacobian: one forward-mode (taylor) pass per column.
  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(n_, n_);
    for (int j = 0; j < n_; ++j) a.col(j) = jacobian_product(*this, w, mu, vec<double>(vec<double>::Unit(n_, j)));
    return a;
  }

 private:
  kind k_;
  double nu_;
  int n_;
  Eigen::MatrixXd t_, ti_;
};

/// Distance of i omega from the spectrum of the dense Jacobian (an independent eigen-solve).
template <class S>
double spectrum_distance(const S& sys, const vec<double>& w, double mu, double omega) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(sys.jacobian(w, mu)), false);
  double best = 1e300;
  for (const auto& l : es.eigenvalues()) best = std::min(best, std::abs(l - std::complex<double>(0, omega)));
  return best;
}

hopf_point synthetic_start(synthetic_system::kind k, double nu, double mu_guess, double omega_guess) {
  const synthetic_system sys(k, nu);
  vec<double> w = sys.equilibrium_d(mu_guess);
  w.array() += 1e-3;  // not exactly on the equilibrium
  return hopf_start(sys, w, mu_guess, omega_guess);
}

}  // namespace

TEST(hopf_curve, circle_turns_in_both_parameters_and_closes) {
  auto family = [](double nu) { return synthetic_system(synthetic_system::circle, nu); };
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.nu_targets = {0.0, 0.5};
  o.verbose = true;
  const double nu0 = 0.6;
  const auto t0 = std::chrono::steady_clock::now();
  const hopf_curve_result r = trace_hopf_curve(family, nu0, synthetic_start(synthetic_system::circle, nu0, 0.78, 1.2), o);
  std::cout << "circle: " << r.points.size() << " points, " << r.failed_correctors << " failed correctors, "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s; " << r.stop_reason
            << "\n";
  EXPECT_EQ(r.stop, hopf_curve_stop::closed_curve);
  ASSERT_GE(r.points.size(), 20u);
  double nu_hi = -9, nu_lo = 9, mu_hi = -9, mu_lo = 9, worst_circle = 0, worst_omega = 0, worst_w = 0, worst_ev = 0;
  int landed = 0;
  for (const auto& pt : r.points) {
    nu_hi = std::max(nu_hi, pt.nu), nu_lo = std::min(nu_lo, pt.nu);
    mu_hi = std::max(mu_hi, pt.mu), mu_lo = std::min(mu_lo, pt.mu);
    const synthetic_system sys(synthetic_system::circle, pt.nu);
    worst_circle = std::max(worst_circle, std::abs(pt.mu * pt.mu + pt.nu * pt.nu - 1));
    worst_omega = std::max(worst_omega, std::abs(pt.omega - (1 + 0.3 * pt.mu)));
    worst_w = std::max(worst_w, (pt.w - sys.equilibrium_d(pt.mu)).lpNorm<Eigen::Infinity>());
    worst_ev = std::max(worst_ev, spectrum_distance(sys, pt.w, pt.mu, pt.omega));
    if (pt.landed) {
      ++landed;
      const bool on_target = std::abs(pt.nu) < 1e-12 || std::abs(pt.nu - 0.5) < 1e-12;
      EXPECT_TRUE(on_target) << "landed point at nu = " << pt.nu;
    }
  }
  std::cout << "circle: max |mu^2+nu^2-1| " << worst_circle << ", max |omega error| " << worst_omega
            << ", max |w - w*| " << worst_w << ", max dist(i omega, spectrum) " << worst_ev << "\n";
  EXPECT_LT(worst_circle, 1e-8);
  EXPECT_LT(worst_omega, 1e-8);
  EXPECT_LT(worst_w, 1e-8);
  EXPECT_LT(worst_ev, 1e-8);
  // the whole circle: past both turning points in nu (nu = +-1) and both in mu (mu = +-1)
  EXPECT_GT(nu_hi, 0.98);
  EXPECT_LT(nu_lo, -0.98);
  EXPECT_GT(mu_hi, 0.98);
  EXPECT_LT(mu_lo, -0.98);
  EXPECT_EQ(landed, 4);  // nu = 0 and nu = 0.5, each crossed twice
  EXPECT_TRUE(r.missed_targets.empty());

  // Natural continuation in nu fails past the turning point nu = 1: no Hopf point at nu = 1.02
  // (Newton from the traced point nearest the turn diverges or stalls).
  const hopf_curve_point* near_turn = &r.points[0];
  for (const auto& pt : r.points)
    if (pt.nu > near_turn->nu) near_turn = &pt;
  hopf_options ho;
  EXPECT_THROW(solve_hopf(synthetic_system(synthetic_system::circle, 1.02), near_turn->point(), ho), convergence_error);
}

TEST(hopf_curve, decreasing_direction_and_bounds_land_exactly) {
  auto family = [](double nu) { return synthetic_system(synthetic_system::circle, nu); };
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.nu_min = -0.3;
  const hopf_curve_result r = trace_hopf_curve(family, 0.6, synthetic_start(synthetic_system::circle, 0.6, 0.78, 1.2), o, -1);
  EXPECT_EQ(r.stop, hopf_curve_stop::nu_bounds);
  ASSERT_GE(r.points.size(), 3u);
  for (size_t k = 1; k < r.points.size(); ++k) EXPECT_LT(r.points[k].nu, r.points[k - 1].nu);  // mu > 0 arc: monotone
  const auto& last = r.points.back();
  EXPECT_TRUE(last.landed);
  EXPECT_NEAR(last.nu, -0.3, 1e-12);
  EXPECT_NEAR(last.mu, std::sqrt(1 - 0.09), 1e-9);
}

TEST(hopf_curve, ends_at_bogdanov_takens_point) {
  auto family = [](double nu) { return synthetic_system(synthetic_system::bogdanov_takens, nu); };
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.1;
  o.verbose = true;
  const double nu0 = -1.0;
  hopf_curve_result r;
  ASSERT_NO_THROW(r = trace_hopf_curve(family, nu0, synthetic_start(synthetic_system::bogdanov_takens, nu0, -0.28, 0.9), o));
  std::cout << "Bogdanov-Takens: " << r.points.size() << " points; " << r.stop_reason << "\n";
  EXPECT_EQ(r.stop, hopf_curve_stop::bogdanov_takens);
  double worst = 0;
  for (const auto& pt : r.points) {
    worst = std::max(worst, std::abs(pt.mu - (0.5 * pt.nu + 0.2 * pt.nu * pt.nu)));
    worst = std::max(worst, std::abs(pt.omega * pt.omega + pt.nu));
    const synthetic_system sys(synthetic_system::bogdanov_takens, pt.nu);
    worst = std::max(worst, spectrum_distance(sys, pt.w, pt.mu, pt.omega));
  }
  EXPECT_LT(worst, 1e-8);
  EXPECT_GT(r.points.back().nu, -0.05);  // got close to the end of the curve
  EXPECT_NEAR(r.bogdanov_takens_nu, 0.0, 1e-3);
  EXPECT_NEAR(r.bogdanov_takens_mu, 0.0, 1e-3);
}

namespace {
tubular_reactor reactor_at_beta(int cells, double beta) {
  tubular_reactor_parameters p;
  p.beta = beta;
  return tubular_reactor(cells, reactor_inflow::second_order, p);
}

/// Re of the eigenvalue nearest i omega of the dense Jacobian at the equilibrium at mu (Newton
/// from w, which is updated).
double critical_real_part(const tubular_reactor& r, vec<double>& w, double mu, double omega) {
  newton_options no;
  no.abs_tolerance = 1e-12;
  w = newton(r, w, mu, no).x;
  double best = 1e300, re = NAN;
  for (const auto& l : dense_spectrum(r.jacobian(w, mu))) {
    const double d = std::abs(l - std::complex<double>(0, omega));
    if (d < best) best = d, re = l.real();
  }
  return re;
}

/// Independent Hopf location at fixed beta: bisection on that real part over [mu - d, mu + d].
double dense_spectrum_crossing(const tubular_reactor& r, vec<double> w, double mu, double omega, double d) {
  double lo = mu - d, hi = mu + d;
  vec<double> wl = w, wh = w;
  double glo = critical_real_part(r, wl, lo, omega);
  const double ghi = critical_real_part(r, wh, hi, omega);
  EXPECT_LT(glo * ghi, 0.0) << "no crossing of the critical pair within +-" << d << " of mu = " << mu;
  for (int it = 0; it < 60 && hi - lo > 1e-14; ++it) {
    const double mid = 0.5 * (lo + hi);
    vec<double> wm = wl;
    const double gm = critical_real_part(r, wm, mid, omega);
    if (gm * glo > 0) lo = mid, glo = gm, wl = wm;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

hopf_point reactor_start(const tubular_reactor& r, double mu, double omega) {
  newton_options no;
  no.abs_tolerance = 1e-12;
  const vec<double> w = newton(r, newton(r, r.rest_state(), 0.1, no).x, mu, no).x;
  return hopf_start(r, w, mu, omega);
}
}  // namespace

// The first Hopf curve of the 16-cell reactor in (Da, beta). From beta = 2.55 upwards it turns
// back in beta near 2.6366 and forward again near 2.631 (three Hopf points per beta in
// between); downwards it passes beta = 2.5 (mu* = 0.165042718, the known fixed-beta Hopf point)
// and ends at a Bogdanov-Takens point near beta = 2.4703.
TEST(hopf_curve, tubular_reactor_in_damkohler_and_beta) {
  const int cells = 16;
  auto family = [](double beta) { return reactor_at_beta(16, beta); };
  const double beta0 = 2.55;
  const hopf_point start = reactor_start(reactor_at_beta(cells, beta0), 0.166, 0.6);
  hopf_curve_options o;
  o.step = 0.01;
  o.max_step = 0.05;
  o.nu_min = 2.3;
  o.nu_max = 2.7;
  o.verbose = true;
  o.nu_targets = {2.5, 2.635};
  const auto t0 = std::chrono::steady_clock::now();
  const hopf_curve_result up = trace_hopf_curve(family, beta0, start, o, +1);
  const hopf_curve_result down = trace_hopf_curve(family, beta0, start, o, -1);
  std::cout << "reactor: up " << up.points.size() << " points (" << up.failed_correctors << " failed correctors), "
            << up.stop_reason << "; down " << down.points.size() << " points, " << down.stop_reason << "; "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s\n";

  // upwards: reaches beta_max past a turning point in beta; three landings on beta = 2.635
  EXPECT_EQ(up.stop, hopf_curve_stop::nu_bounds);
  EXPECT_NEAR(up.points.back().nu, 2.7, 1e-12);
  std::vector<const hopf_curve_point*> at2635;
  bool turned = false;
  for (size_t k = 1; k < up.points.size(); ++k) {
    if (up.points[k].nu < up.points[k - 1].nu) turned = true;
    if (up.points[k].landed && std::abs(up.points[k].nu - 2.635) < 1e-12) at2635.push_back(&up.points[k]);
  }
  EXPECT_TRUE(turned) << "the curve should turn back in beta";
  ASSERT_EQ(at2635.size(), 3u);
  EXPECT_LT(at2635[0]->mu, at2635[1]->mu);
  EXPECT_LT(at2635[1]->mu, at2635[2]->mu);

  // downwards: beta = 2.5 landed on the known Hopf point, then the Bogdanov-Takens end
  EXPECT_EQ(down.stop, hopf_curve_stop::bogdanov_takens);
  const hopf_curve_point* at25 = nullptr;
  for (const auto& pt : down.points)
    if (pt.landed && std::abs(pt.nu - 2.5) < 1e-12) at25 = &pt;
  ASSERT_NE(at25, nullptr);
  std::cout << std::setprecision(12) << "reactor: landed at beta = 2.5: mu* = " << at25->mu << ", omega* = " << at25->omega
            << "; Bogdanov-Takens estimate beta = " << down.bogdanov_takens_nu << ", mu = " << down.bogdanov_takens_mu
            << std::setprecision(6) << "\n";
  EXPECT_NEAR(at25->mu, 0.165042718, 6e-10);
  EXPECT_NEAR(down.bogdanov_takens_nu, 2.4703, 2e-3);
  {  // at the Bogdanov-Takens estimate the equilibrium has two eigenvalues near zero
    const tubular_reactor r = reactor_at_beta(cells, down.bogdanov_takens_nu);
    vec<double> w = down.points.back().w;
    newton_options no;  // the point is on the fold of the equilibria: Newton converges only linearly
    no.abs_tolerance = 1e-7;
    w = newton(r, w, down.bogdanov_takens_mu, no).x;
    std::vector<double> mags;
    for (const auto& l : dense_spectrum(r.jacobian(w, down.bogdanov_takens_mu))) mags.push_back(std::abs(l));
    std::sort(mags.begin(), mags.end());
    std::cout << "reactor: |lambda| nearest 0 at the Bogdanov-Takens estimate: " << mags[0] << ", " << mags[1]
              << " (next " << mags[2] << ")\n";
    EXPECT_LT(mags[1], 1e-2);
    EXPECT_GT(mags[2], 0.1);
  }

  // traced points against the independent dense-spectrum crossing and solve_hopf at fixed beta
  std::vector<const hopf_curve_point*> checks(at2635.begin(), at2635.end());
  checks.push_back(at25);
  checks.push_back(&up.points[up.points.size() / 3]);
  checks.push_back(&up.points.back());
  checks.push_back(&down.points[down.points.size() / 2]);
  double worst_crossing = 0, worst_solve = 0;
  for (const hopf_curve_point* pt : checks) {
    const tubular_reactor r = reactor_at_beta(cells, pt->nu);
    const double ref = dense_spectrum_crossing(r, pt->w, pt->mu, pt->omega, 2e-4);
    worst_crossing = std::max(worst_crossing, std::abs(pt->mu - ref));
    EXPECT_NEAR(pt->mu, ref, 1e-8) << "beta = " << pt->nu;
    // solve_hopf at fixed beta from a perturbed start (equilibrium at mu + 1e-4, shift 1.01 omega;
    // near the turn in beta the neighbouring Hopf point at the same beta is only 1.6e-3 away)
    newton_options no;
    no.abs_tolerance = 1e-12;
    const vec<double> w = newton(r, pt->w, pt->mu + 1e-4, no).x;
    const hopf_result h = solve_hopf(r, hopf_start(r, w, pt->mu + 1e-4, 1.01 * pt->omega));
    worst_solve = std::max({worst_solve, std::abs(h.point.mu - pt->mu), std::abs(h.point.omega - pt->omega)});
    EXPECT_NEAR(h.point.mu, pt->mu, 1e-8) << "beta = " << pt->nu;
    EXPECT_NEAR(h.point.omega, pt->omega, 1e-8) << "beta = " << pt->nu;
  }
  std::cout << "reactor: " << checks.size() << " points: max |mu - dense-spectrum crossing| " << worst_crossing
            << ", max |(mu, omega) - solve_hopf| " << worst_solve << "\n";
}

// 32 cells: landing on beta = 2.5 reproduces the known first Hopf point mu* = 0.16504.
TEST(hopf_curve, tubular_reactor_32_cells_lands_on_known_hopf_point) {
  auto family = [](double beta) { return reactor_at_beta(32, beta); };
  const hopf_point start = reactor_start(reactor_at_beta(32, 2.56), 0.166, 0.6);
  hopf_curve_options o;
  o.step = 0.02;
  o.max_step = 0.05;
  o.nu_min = 2.49;
  o.nu_targets = {2.5};
  const hopf_curve_result r = trace_hopf_curve(family, 2.56, start, o, -1);
  EXPECT_EQ(r.stop, hopf_curve_stop::nu_bounds);
  const hopf_curve_point* at25 = nullptr;
  for (const auto& pt : r.points)
    if (pt.landed && std::abs(pt.nu - 2.5) < 1e-12) at25 = &pt;
  ASSERT_NE(at25, nullptr);
  std::cout << std::setprecision(12) << "reactor 32 cells: mu*(beta = 2.5) = " << at25->mu << std::setprecision(6) << "\n";
  EXPECT_NEAR(at25->mu, 0.16504, 5e-6);
}

// A family that cannot be built beyond nu = 0.9 (as a steady solve failing past some Mach
// number): the step control shrinks onto the barrier and then reports where it stopped.
TEST(hopf_curve, step_failure_is_reported_with_the_last_point) {
  auto family = [](double nu) {
    require(nu <= 0.9, "test family: no system beyond nu = 0.9 (asked for ", nu, ")");
    return synthetic_system(synthetic_system::circle, nu);
  };
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.min_step = 1e-4;
  const hopf_point start = synthetic_start(synthetic_system::circle, 0.6, 0.78, 1.2);
  try {
    trace_hopf_curve(family, 0.6, start, o);
    ADD_FAILURE() << "expected a convergence_error";
  } catch (const convergence_error& e) {
    const std::string m = e.what();
    std::cout << "step failure message: " << m << "\n";
    EXPECT_NE(m.find("min_step"), std::string::npos);
    EXPECT_NE(m.find("after the point nu = 0.89"), std::string::npos);
    EXPECT_NE(m.find("no system beyond nu = 0.9"), std::string::npos);
  }
  o.throw_on_failure = false;
  const hopf_curve_result r = trace_hopf_curve(family, 0.6, start, o);
  EXPECT_EQ(r.stop, hopf_curve_stop::step_failure);
  EXPECT_GT(r.points.back().nu, 0.89);
  for (const auto& pt : r.points) {
    EXPECT_LE(pt.nu, 0.9);
    EXPECT_LT(std::abs(pt.mu * pt.mu + pt.nu * pt.nu - 1), 1e-8);
  }
}

// ---- hostile input ----
namespace {
using test_support::faulty_system;
using circle_fault = faulty_system<synthetic_system>;

/// The circle family with a residual that returns NaN from call `at` on (`count` calls), one
/// call counter for all its members.
auto faulty_circle(std::shared_ptr<long> counter, long at, long count) {
  return [=](double nu) { return circle_fault(synthetic_system(synthetic_system::circle, nu), counter, at, count); };
}

hopf_curve_options circle_trace_options() {
  hopf_curve_options o;
  o.step = 0.05;
  o.max_step = 0.2;
  o.min_step = 1e-4;
  o.nu_targets = {0.8};
  o.nu_max = 0.9;
  return o;
}

const hopf_curve_point* landed_at(const hopf_curve_result& r, double nu) {
  for (const auto& p : r.points)
    if (p.landed && std::abs(p.nu - nu) < 1e-12) return &p;
  return nullptr;
}
}  // namespace

TEST(hopf_curve_hostile, options_and_start_are_checked_by_name) {
  auto family = [](double nu) { return synthetic_system(synthetic_system::circle, nu); };
  const hopf_point start = synthetic_start(synthetic_system::circle, 0.6, 0.78, 1.2);
  const hopf_curve_options good = circle_trace_options();
  auto message = [&](const hopf_curve_options& o, const hopf_point& s) -> std::string {
    try {
      trace_hopf_curve(family, 0.6, s, o);
    } catch (const input_error& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("wrong exception type: ") + e.what();
    }
    return "no exception";
  };
  auto expect = [&](const hopf_curve_options& o, const hopf_point& s, const char* part) {
    const std::string m = message(o, s);
    EXPECT_NE(m.find(part), std::string::npos) << part << " not in: " << m;
    EXPECT_NE(m.find(o.label), std::string::npos) << m;
  };
  hopf_curve_options o = good;
  o.nu_targets = {0.7, NAN};
  expect(o, start, "nu_targets entry 1");
  o = good;
  o.max_points = 0;
  expect(o, start, "max_points");
  o = good;
  o.step = INFINITY;
  expect(o, start, "step sizes");
  o = good;
  o.min_cosine = 2;
  expect(o, start, "min_cosine");
  o = good;
  o.omega_min = NAN;
  expect(o, start, "omega_min");
  o = good;
  o.corrector_distance = 0;
  expect(o, start, "corrector_distance");
  o = good;
  o.growth = INFINITY;
  expect(o, start, "growth");
  o = good;
  o.newton.abs_tolerance = NAN;
  expect(o, start, "newton.abs_tolerance");
  o = good;
  o.newton.max_iterations = 0;
  expect(o, start, "newton.max_iterations");
  o = good;
  o.mu_min = 1, o.mu_max = 0;
  expect(o, start, "mu_min <= mu_max");
  hopf_point s = start;
  s.w = s.w.head(3).eval();
  expect(good, s, "start.w (equilibrium at nu0) has 3 entries");
  s = start;
  s.p[2] = std::complex<double>(NAN, 0);
  expect(good, s, "start.p (eigenvector) entry 2");
}

// A residual that returns NaN once during the trace: the corrector that meets it fails, the
// step is retried, and the trace goes on to the same landed point as the uninjected one.
TEST(hopf_curve_hostile, a_transient_nan_is_survived) {
  const hopf_point start = synthetic_start(synthetic_system::circle, 0.6, 0.78, 1.2);
  const hopf_curve_options o = circle_trace_options();
  auto clean_counter = std::make_shared<long>(0);
  const hopf_curve_result ref = trace_hopf_curve(faulty_circle(clean_counter, 1L << 40, 0), 0.6, start, o);
  const hopf_curve_point* ref_land = landed_at(ref, 0.8);
  ASSERT_NE(ref_land, nullptr);
  auto counter = std::make_shared<long>(0);
  const hopf_curve_result r = trace_hopf_curve(faulty_circle(counter, *clean_counter / 2, 1), 0.6, start, o);
  EXPECT_GE(r.failed_correctors, 1);
  const hopf_curve_point* land = landed_at(r, 0.8);
  ASSERT_NE(land, nullptr);
  EXPECT_NEAR(land->mu, ref_land->mu, 1e-9);
  EXPECT_NEAR(land->omega, ref_land->omega, 1e-9);
  EXPECT_NEAR(land->mu, 0.6, 1e-9);  // closed form: mu^2 + nu^2 = 1
}

// From some call on the residual is NaN for good: the trace reports where and why it stopped
// (label, last point, and the corrector's last accepted iterate with ||F||, nu, mu, omega),
// keeps the points accepted so far (throw_on_failure = false) or throws convergence_error with
// the same context; the caller's start and options are untouched; restarting from the last
// accepted point without the fault lands on the same point as the uninjected trace.
TEST(hopf_curve_hostile, a_persistent_nan_stops_the_trace_with_context_and_it_restarts) {
  const hopf_point start = synthetic_start(synthetic_system::circle, 0.6, 0.78, 1.2);
  const hopf_point start_copy = start;
  hopf_curve_options o = circle_trace_options();
  o.label = "injected curve";
  // the call count when point 2 is accepted, from an uninjected run with the same counter
  auto clean_counter = std::make_shared<long>(0);
  long calls_at_point2 = -1;
  hopf_curve_options counting = o;
  int seen = 0;
  counting.observer = [&](const hopf_curve_point&) {
    if (++seen == 3) calls_at_point2 = *clean_counter;
  };
  const hopf_curve_result ref = trace_hopf_curve(faulty_circle(clean_counter, 1L << 40, 0), 0.6, start, counting);
  const hopf_curve_point* ref_land = landed_at(ref, 0.8);
  ASSERT_NE(ref_land, nullptr);
  ASSERT_GT(calls_at_point2, 0);
  ASSERT_LT(ref.points[2].nu, 0.8);

  const long at = calls_at_point2 + 1;
  o.throw_on_failure = false;
  const hopf_curve_options o_copy = o;
  auto counter = std::make_shared<long>(0);
  const hopf_curve_result r = trace_hopf_curve(faulty_circle(counter, at, 1L << 40), 0.6, start, o);
  EXPECT_EQ(r.stop, hopf_curve_stop::step_failure);
  ASSERT_EQ(r.points.size(), 3u);
  for (const auto& pt : r.points) EXPECT_LT(std::abs(pt.mu * pt.mu + pt.nu * pt.nu - 1), 1e-8);
  for (const char* part : {"injected curve", "point 2", "not finite", "last accepted iterate", "||F|| = ", "nu = ",
                           "mu = ", "omega = "})
    EXPECT_NE(r.stop_reason.find(part), std::string::npos) << part << " not in: " << r.stop_reason;
  o.throw_on_failure = true;
  try {
    auto c2 = std::make_shared<long>(0);
    trace_hopf_curve(faulty_circle(c2, at, 1L << 40), 0.6, start, o);
    ADD_FAILURE() << "no exception";
  } catch (const convergence_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("last accepted iterate"), std::string::npos) << m;
    EXPECT_NE(m.find("injected curve"), std::string::npos) << m;
  }
  // inputs untouched
  EXPECT_EQ(start.w, start_copy.w);
  EXPECT_EQ(start.p, start_copy.p);
  EXPECT_EQ(start.mu, start_copy.mu);
  EXPECT_EQ(start.omega, start_copy.omega);
  EXPECT_EQ(o_copy.step, o.step);
  EXPECT_EQ(o_copy.nu_targets, o.nu_targets);
  // restart from the last accepted point, no fault
  o.throw_on_failure = true;
  auto family = [](double nu) { return synthetic_system(synthetic_system::circle, nu); };
  const hopf_curve_point& last = r.points.back();
  const hopf_curve_result again = trace_hopf_curve(family, last.nu, last.point(), o);
  const hopf_curve_point* land = landed_at(again, 0.8);
  ASSERT_NE(land, nullptr);
  EXPECT_NEAR(land->mu, ref_land->mu, 1e-9);
  EXPECT_NEAR(land->omega, ref_land->omega, 1e-9);
}

// A start at the real eigenvalue mu = 0 of a family (tests/support/hopf_test_systems.hpp) with
// omega_min = 0 and tolerances 1e-8: solve_hopf converges to omega ~ 1e-11, which that
// tolerance does not resolve. Refused, instead of tracing the fold line mu = 0 as "Hopf points".
TEST(hopf_curve_hostile, a_start_at_a_real_eigenvalue_is_refused) {
  using test_support::moving_equilibrium_system;
  using cplx = std::complex<double>;
  auto family = [](double nu) { return moving_equilibrium_system<>(Eigen::Vector4d(nu, 0.5 * nu, 0, 0)); };
  const auto s0 = family(0.3);
  hopf_point g = hopf_start(s0, s0.equilibrium(0.2), 0.2, 0.3);
  vec<cplx> q(4);
  q << cplx(0.1, 0.7), cplx(-0.4, 0.2), cplx(0.3, -0.5), cplx(0.6, 0.1);
  g.p += 0.3 * q;
  hopf_curve_options o;
  o.omega_min = 0;
  o.start.newton.abs_tolerance = 1e-8;
  o.newton.abs_tolerance = 1e-8;
  o.max_points = 5;
  o.throw_on_failure = false;
  try {
    const hopf_curve_result r = trace_hopf_curve(family, 0.3, g, o);
    ADD_FAILURE() << "traced " << r.points.size() << " points, the first with omega = " << r.points.front().omega;
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("real eigenvalue"), std::string::npos) << e.what();
  }
}
