// The curve stepper (curve_stepper.hpp) piece by piece on small analytic curves, against closed
// forms: the step-size sequence (halving, growth, clamping, underflow), the tangent and secant
// predictors on the unit circle (angles in closed form), landing on listed values and bounds,
// the natural predictor and the turning point of the fold x^2 + mu = 0, the kink step on a
// curve that turns by 113 degrees, the retrace and sheet-jump guards, the input checks, and
// the joint corrector of the fixed-equilibrium Hopf tracer on a family whose Hopf curve is the
// unit circle mu^2 + nu^2 = 1 with omega = 1 + 0.3 mu.
#include <aerohopf/bifurcation.hpp>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <array>
#include <functional>
#include <optional>
#include <tuple>
#include <numbers>
#include <string>
#include <vector>

using namespace aerohopf;

namespace {

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }
vec<double> v2(double a, double b) {
  vec<double> v(2);
  v << a, b;
  return v;
}

/// A planar curve g(x) = 0, x = (x_0, x_1), corrected by Newton on [g; c.x - value].
struct planar_curve {
  std::function<double(const vec<double>&)> g;
  std::function<vec<double>(const vec<double>&)> dg;  ///< gradient of g
  int max_iterations = 20;
  double tolerance = 1e-13;
  int calls = 0;

  std::optional<curve_corrected> correct(const curve_request& q, std::string& why) {
    ++calls;
    vec<double> x = q.x0;
    for (int it = 1; it <= max_iterations; ++it) {
      Eigen::MatrixXd j(2, 2);
      j.row(0) = dg(x).transpose();
      j.row(1) = q.c.transpose();
      const vec<double> dx = j.fullPivLu().solve(v2(g(x), q.c.dot(x) - q.value));
      if (!dx.allFinite()) break;
      x -= dx;
      if (std::abs(g(x)) < tolerance && std::abs(q.c.dot(x) - q.value) < tolerance * (1 + std::abs(q.value)))
        return curve_corrected{x, it};
    }
    why = "no convergence";
    return std::nullopt;
  }
  vec<double> tangent(const vec<double>& x, const vec<double>& c) {
    Eigen::MatrixXd j(2, 2);
    j.row(0) = dg(x).transpose();
    j.row(1) = c.transpose();
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
    if (!lu.isInvertible()) throw singular_matrix_error("planar_curve: singular bordered matrix");
    return lu.solve(v2(0, 1));
  }
};

planar_curve unit_circle() {
  return {[](const vec<double>& x) { return x.squaredNorm() - 1; },
          [](const vec<double>& x) { return v2(2 * x[0], 2 * x[1]); }};
}

/// Records the emitted points (the pointers of their info are only valid during emit: the
/// tangent is copied); stops when asked to after `stop_at` points.
struct recorder {
  std::vector<vec<double>> x, tangent;
  std::vector<curve_point_info> info;
  int stop_at = -1;
  bool emit(const vec<double>& p, const curve_point_info& i) {
    x.push_back(p);
    tangent.push_back(i.tangent ? *i.tangent : vec<double>());
    info.push_back(i);
    info.back().tangent = info.back().from = info.back().direction = nullptr;
    return int(x.size()) == stop_at;
  }
};

/// A planar problem with a recorder and a script over the step correctors: fail[k] = true makes
/// the k-th step request fail; iterations[k] overrides its iteration count.
struct scripted_circle {
  planar_curve curve = unit_circle();
  recorder rec;
  std::vector<bool> fail;
  std::vector<int> iterations;
  std::vector<double> steps;  // ds of every step request
  std::optional<curve_corrected> correct(const curve_request& q, std::string& why) {
    if (q.kind != curve_attempt::step) return curve.correct(q, why);
    const std::size_t k = steps.size();
    steps.push_back(q.step);
    if (k < fail.size() && fail[k]) {
      why = "scripted failure";
      return std::nullopt;
    }
    auto r = curve.correct(q, why);
    if (r && k < iterations.size()) r->iterations = iterations[k];
    return r;
  }
  vec<double> tangent(const vec<double>& x, const vec<double>& c) { return curve.tangent(x, c); }
  bool emit(const vec<double>& x, const curve_point_info& i) { return rec.emit(x, i); }
};

double angle(const vec<double>& x) { return std::atan2(x[1], x[0]); }

/// The scripted circle with `tamper(result, step requests so far)` applied to every corrected
/// point (a corrector that jumps).
template <class Tamper>
auto tampered(scripted_circle& p, Tamper tamper) {
  return curve_problem{[&p, tamper](const curve_request& r, std::string& why) -> std::optional<curve_corrected> {
                         auto c = p.correct(r, why);
                         if (c) tamper(*c, p.steps.size());
                         return c;
                       },
                       [&p](const vec<double>& x, const vec<double>& c) { return p.tangent(x, c); },
                       [&p](const vec<double>& x, const curve_point_info& i) { return p.emit(x, i); }};
}
const curve_metric euclid(vec<double>::Ones(2));
const vec<double> east = v2(1, 0), north = v2(0, 1);

}  // namespace

// Growth after fast steps, halving after failures, the clamp to max_step: the step of every
// request follows from the script alone.
TEST(curve_stepper, step_sizes_halve_on_failure_and_grow_after_fast_steps) {
  scripted_circle p;
  //            step 1   step 2: two failures, then a slow success   step 3   step 4   step 5
  p.fail = {false, true, true, false, false, false, false};
  p.iterations = {1, 0, 0, 9, 1, 1, 1};
  curve_stepper_options o;
  o.step = 0.1;
  o.min_step = 1e-3;
  o.max_step = 0.3;
  o.growth = 2;
  o.fast_iterations = 2;
  o.retry_exact_tangent = false;
  o.max_points = 6;
  const curve_outcome out = trace_curve(p, east, north, euclid, o);
  EXPECT_EQ(out.stop, curve_stop::max_points);
  EXPECT_EQ(out.failed_correctors, 2);
  const std::vector<double> expected = {0.1, 0.2, 0.1, 0.05, 0.05, 0.1, 0.2};
  ASSERT_EQ(p.steps.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_DOUBLE_EQ(p.steps[k], expected[k]) << k;
  ASSERT_EQ(p.rec.info.size(), 6u);
  EXPECT_EQ(p.rec.info[2].attempts, 3);  // the step after two failures
  // growth stops at max_step
  scripted_circle q;
  q.iterations.assign(20, 1);
  o.max_points = 8;
  o.step = 0.1;
  o.growth = 1.5;
  const curve_outcome out2 = trace_curve(q, east, north, euclid, o);
  EXPECT_EQ(out2.stop, curve_stop::max_points);
  for (double s : q.steps) EXPECT_LE(s, o.max_step);
  EXPECT_DOUBLE_EQ(q.steps.back(), o.max_step);
}

// A corrector that always fails: the step halves from 0.1 until it falls below min_step; the
// stop names the last point, the attempted step and the failure.
TEST(curve_stepper, step_underflow_stops_with_the_reason) {
  scripted_circle p;
  p.fail.assign(100, true);
  curve_stepper_options o;
  o.step = 0.1;
  o.min_step = 0.01;
  o.retry_exact_tangent = false;
  o.label = "circle";
  const curve_outcome out = trace_curve(p, east, north, euclid, o);
  EXPECT_EQ(out.stop, curve_stop::step_underflow);
  // 0.1, 0.05, 0.025, 0.0125: four attempts, then 0.00625 < min_step
  EXPECT_EQ(p.steps.size(), 4u);
  EXPECT_EQ(out.failed_correctors, 4);
  EXPECT_DOUBLE_EQ(out.last_step, 0.0125);
  EXPECT_EQ(out.last_failure, "scripted failure");
  EXPECT_TRUE(has(out.reason, "circle: step fell below min_step = 0.01")) << out.reason;
  EXPECT_TRUE(has(out.reason, "scripted failure")) << out.reason;
  EXPECT_EQ(p.rec.x.size(), 1u);  // only the start
}

// Tangent predictor on the unit circle: the hyperplane orthogonal to the tangent at angle
// theta, at distance ds, meets the circle at theta + asin(ds). Secant predictor: the chord of
// the last step (angle delta) is the tangent at the midpoint, so the next point is at
// theta - delta/2 + asin(sin(delta/2) + ds).
TEST(curve_stepper, tangent_and_secant_predictors_follow_the_circle_in_closed_form) {
  curve_stepper_options o;
  o.step = 0.2;
  o.max_step = 0.2;
  o.max_points = 12;
  for (curve_predictor pred : {curve_predictor::tangent, curve_predictor::secant}) {
    scripted_circle p;
    o.predictor = pred;
    const curve_outcome out = trace_curve(p, east, north, euclid, o);
    EXPECT_EQ(out.stop, curve_stop::max_points);
    ASSERT_EQ(p.rec.x.size(), 12u);
    double theta = 0, delta = 0;
    for (std::size_t k = 1; k < p.rec.x.size(); ++k) {
      const double next = pred == curve_predictor::tangent || k == 1
                              ? theta + std::asin(0.2)
                              : theta - delta / 2 + std::asin(std::sin(delta / 2) + 0.2);
      delta = next - theta;
      theta = next;
      EXPECT_NEAR(std::remainder(angle(p.rec.x[k]) - theta, 2 * std::numbers::pi), 0.0, 1e-12) << k;
      if (pred == curve_predictor::tangent) {
        ASSERT_EQ(p.rec.tangent[k].size(), 2);
        EXPECT_NEAR((p.rec.tangent[k] - v2(-std::sin(theta), std::cos(theta))).norm(), 0.0, 1e-12);
      }
    }
  }
}

// Landings: every crossing of a listed x_0 value is landed on exactly, in curve order, before
// the step's own point; a bound on x_1 ends the trace on it. Closed form: the circle.
TEST(curve_stepper, lands_exactly_on_listed_values_and_stops_on_a_bound) {
  scripted_circle p;
  curve_stepper_options o;
  o.step = 0.3;
  o.max_step = 0.3;
  o.targets.push_back({0, {0.5, 0.0, -0.5}, "x0"});
  o.bounds.push_back({1, -0.5, "x1"});
  const curve_outcome out = trace_curve(p, east, north, euclid, o);
  EXPECT_EQ(out.stop, curve_stop::bound);
  EXPECT_TRUE(out.bound_landed);
  EXPECT_EQ(out.bound_index, 1);
  EXPECT_EQ(out.reason, "reached x1 = -0.5");
  EXPECT_TRUE(out.missed.empty());
  std::vector<vec<double>> landed;
  for (std::size_t k = 0; k < p.rec.x.size(); ++k)
    if (p.rec.info[k].landed) landed.push_back(p.rec.x[k]);
  // counter-clockwise from (1, 0): x0 = 0.5, 0, -0.5 on the upper half, then x1 = -0.5 on the left
  ASSERT_EQ(landed.size(), 4u);
  const double r3 = std::sqrt(0.75);
  const vec<double> expected[4] = {v2(0.5, r3), v2(0.0, 1.0), v2(-0.5, r3), v2(-r3, -0.5)};
  for (int k = 0; k < 4; ++k) EXPECT_LT((landed[k] - expected[k]).norm(), 1e-12) << k;
  EXPECT_EQ(landed.back(), p.rec.x.back());  // the bound's point is the last one
  // angles increase along the emitted points: landings come in curve order
  for (std::size_t k = 1; k < p.rec.x.size(); ++k) {
    double a = angle(p.rec.x[k]), b = angle(p.rec.x[k - 1]);
    if (a < 0) a += 2 * std::numbers::pi;
    if (b < 0) b += 2 * std::numbers::pi;
    EXPECT_GT(a, b) << k;
  }
}

// Natural predictor on the fold x^2 + mu = 0 (unknowns (x, mu)): mu_k = -1 + 0.3 k exactly,
// x = -sqrt(-mu); past the turning point mu = 0 there is no solution: the trace stops with
// the corrector's failure. A limit on mu stops before a value outside it is solved.
TEST(curve_stepper, natural_steps_are_exact_and_stop_at_the_turning_point) {
  planar_curve fold{[](const vec<double>& x) { return x[0] * x[0] + x[1]; },
                    [](const vec<double>& x) { return v2(2 * x[0], 1.0); }};
  recorder rec;
  curve_problem p{[&](const curve_request& q, std::string& why) { return fold.correct(q, why); }, nullptr,
                  [&](const vec<double>& x, const curve_point_info& i) { return rec.emit(x, i); }};
  curve_stepper_options o;
  o.predictor = curve_predictor::natural;
  o.natural_index = 1;
  o.step = 0.3;
  const vec<double> x0 = v2(-1.0, -1.0);
  const curve_outcome out = trace_curve(p, x0, vec<double>(), euclid, o);
  EXPECT_EQ(out.stop, curve_stop::corrector_failure);
  ASSERT_EQ(rec.x.size(), 4u);  // mu = -1, -0.7, -0.4, -0.1
  for (std::size_t k = 0; k < rec.x.size(); ++k) {
    const double mu = -1 + 0.3 * double(k);
    EXPECT_EQ(rec.x[k][1], mu) << k;
    EXPECT_NEAR(rec.x[k][0], -std::sqrt(-mu), 1e-12) << k;
  }
  rec = {};
  o.limits.push_back({1, -1.0, -0.3});
  const curve_outcome lim = trace_curve(p, x0, vec<double>(), euclid, o);
  EXPECT_EQ(lim.stop, curve_stop::limit);
  EXPECT_EQ(rec.x.size(), 3u);  // -1, -0.7, -0.4; -0.1 is outside and never solved
}

// The same fold by the tangent predictor passes the turning point (mu rises to 0 and falls
// again, every point on x^2 + mu = 0). At the turning point the tangent along e_mu does not
// exist: the bordered matrix is singular and curve_unit_tangent says so.
TEST(curve_stepper, tangent_predictor_passes_the_turning_point_of_the_fold) {
  planar_curve fold{[](const vec<double>& x) { return x[0] * x[0] + x[1]; },
                    [](const vec<double>& x) { return v2(2 * x[0], 1.0); }};
  recorder rec;
  curve_problem p{[&](const curve_request& q, std::string& why) { return fold.correct(q, why); },
                  [&](const vec<double>& x, const vec<double>& c) { return fold.tangent(x, c); },
                  [&](const vec<double>& x, const curve_point_info& i) { return rec.emit(x, i); }};
  const vec<double> x0 = v2(-1.0, -1.0);
  const vec<double> e_mu = v2(0.0, 1.0);
  const vec<double> t0 = curve_unit_tangent(p, euclid, x0, e_mu, e_mu, "fold");
  EXPECT_LT((t0 - vec<double>(v2(1 / std::sqrt(5.0), 2 / std::sqrt(5.0)))).norm(), 1e-14);  // (dx, dmu) ~ (1, -2x)
  curve_stepper_options o;
  o.predictor = curve_predictor::tangent;
  o.step = 0.1;
  o.max_step = 0.2;
  o.limits.push_back({0, -2.0, 1.0});  // stop once x > 1
  const curve_outcome out = trace_curve(p, x0, t0, euclid, o);
  EXPECT_EQ(out.stop, curve_stop::limit);
  double mu_max = -9;
  for (const auto& x : rec.x) {
    EXPECT_NEAR(x[0] * x[0] + x[1], 0.0, 1e-12);
    mu_max = std::max(mu_max, x[1]);
  }
  EXPECT_GT(rec.x.back()[0], 1.0);
  EXPECT_LT(rec.x.back()[1], -1.0);  // past the turn, mu falls again
  EXPECT_GT(mu_max, -0.05);
  for (std::size_t k = 1; k < rec.x.size(); ++k) EXPECT_GT(rec.x[k][0], rec.x[k - 1][0]);  // never turns back in x
  const vec<double> top = v2(0.0, 0.0);
  EXPECT_THROW(curve_unit_tangent(p, euclid, top, e_mu, e_mu, "fold"), singular_matrix_error);
  const vec<double> e_x = v2(1.0, 0.0);
  EXPECT_LT((curve_unit_tangent(p, euclid, top, e_x, e_x, "fold") - e_x).norm(), 1e-14);
}

// Sheet-jump guard: a corrector that lands behind the last point (as at a fold of a curve,
// onto the other sheet) is rejected and the step retried; without the guard it is taken.
TEST(curve_stepper, sheet_jump_guard_rejects_a_point_behind_the_last_one) {
  auto run = [](bool guard) {
    scripted_circle p;
    // the third step request lands on the mirror image of its prediction
    auto q = tampered(p, [](curve_corrected& c, std::size_t steps) {
      if (steps == 3) c.x[1] = -c.x[1];
    });
    curve_stepper_options o;
    o.step = 0.2;
    o.max_step = 0.2;
    o.max_points = 5;
    o.sheet_guard = guard;
    const int failed = trace_curve(q, east, north, euclid, o).failed_correctors;
    int below = 0;
    for (const auto& x : p.rec.x) below += x[1] < 0;
    return std::pair{failed, below};
  };
  const auto [failed, below] = run(true);
  EXPECT_EQ(failed, 1);
  EXPECT_EQ(below, 0);
  const auto [failed_off, below_off] = run(false);
  EXPECT_EQ(failed_off, 0);
  EXPECT_GE(below_off, 1);
}

// Retrace test: the polyline distance in closed form (a square path), and in the stepper a
// corrector that lands on a stretch traced before is rejected.
TEST(curve_stepper, retrace_test) {
  std::vector<vec<double>> path;
  for (const auto& [a, b] : std::vector<std::pair<double, double>>{{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 2}})
    path.push_back(v2(a, b));
  const vec<double> near_first = v2(0.5, 0.1), near_second = v2(0.95, 0.5);
  EXPECT_TRUE(curve_near_polyline(path, 0, 4, near_first, 0.11));
  EXPECT_FALSE(curve_near_polyline(path, 0, 4, near_first, 0.09));
  EXPECT_FALSE(curve_near_polyline(path, 1, 4, near_first, 0.11));  // the first segment left out
  EXPECT_TRUE(curve_near_polyline(path, 1, 4, near_second, 0.06));
  EXPECT_FALSE(curve_near_polyline(path, 0, 1, near_second, 0.06));  // only segment 0 -> 1

  // On the circle with steps of 0.25: the 9th step request returns the 2nd point (angle ~0.25).
  auto run = [](bool guard) {
    scripted_circle p;
    auto q = tampered(p, [&p](curve_corrected& c, std::size_t steps) {
      if (steps == 9) c.x = p.rec.x[1] + v2(0.01, 0.0);
    });
    curve_stepper_options o;
    o.step = 0.25;
    o.max_step = 0.25;
    o.max_points = 12;
    o.retrace_guard = guard;
    const curve_outcome out = trace_curve(q, east, north, euclid, o);
    return std::pair{out.failed_correctors, p.rec.x};
  };
  const auto [failed, points] = run(true);
  EXPECT_EQ(failed, 1);
  ASSERT_EQ(points.size(), 12u);
  for (const auto& x : points) EXPECT_NEAR(x.norm(), 1.0, 1e-12);
  for (std::size_t k = 2; k < points.size(); ++k) EXPECT_GT(std::abs(angle(points[k]) - angle(points[1])), 0.2) << k;
  const auto [failed_off, points_off] = run(false);
  bool went_back = false;  // without the guard the point is taken: the trace runs back
  for (std::size_t k = 3; k < points_off.size(); ++k) went_back |= std::abs(angle(points_off[k]) - angle(points_off[1])) < 0.02;
  EXPECT_TRUE(went_back);
}

// The kink step on mu^2 = 1 - nu^2 + 5 max(0, nu - 0.7) (unknowns (nu, mu), upper branch): the
// curve turns by about 113 degrees at nu = 0.7, where the arclength hyperplane ahead of the
// last point does not meet its next piece. Steps at fixed nu cross it; the landing on nu = 0.75
// is the closed form mu = sqrt(1 - 0.5625 + 0.25). Without the kink step the trace stops there.
TEST(curve_stepper, kink_step_crosses_a_sharp_turn_at_fixed_nu) {
  auto g = [](const vec<double>& x) { return x[1] * x[1] - (1 - x[0] * x[0] + 5 * std::max(0.0, x[0] - 0.7)); };
  auto dg = [](const vec<double>& x) {
    return v2(2 * x[0] - (x[0] > 0.7 ? 5.0 : 0.0), 2 * x[1]);
  };
  auto run = [&](bool kink) {
    planar_curve kinked{g, dg};
    recorder rec;
    curve_problem p{[&](const curve_request& q, std::string& why) { return kinked.correct(q, why); },
                    [&](const vec<double>& x, const vec<double>& c) { return kinked.tangent(x, c); },
                    [&](const vec<double>& x, const curve_point_info& i) { return rec.emit(x, i); }};
    const vec<double> x0 = v2(0.6, 0.8);
    const vec<double> e_nu = v2(1.0, 0.0);
    const vec<double> t0 = curve_unit_tangent(p, euclid, x0, e_nu, e_nu, "kink");
    curve_stepper_options o;
    o.step = 0.05;
    o.max_step = 0.2;
    o.min_step = 1e-4;
    o.sheet_guard = true;
    o.retrace_guard = true;
    o.kink_step = kink;
    o.kink_primary = 0;
    o.kink_secondary = 1;
    o.targets.push_back({0, {0.75}, "nu"});
    o.bounds.push_back({0, 0.8, "nu"});
    const curve_outcome out = trace_curve(p, x0, t0, euclid, o);
    return std::pair{out, rec};
  };
  const auto [out, rec] = run(true);
  EXPECT_EQ(out.stop, curve_stop::bound);
  EXPECT_GE(out.kink_steps, 1);
  for (const auto& x : rec.x) EXPECT_NEAR(g(x), 0.0, 1e-12);
  int kinks = 0, landed = 0;
  for (std::size_t k = 0; k < rec.x.size(); ++k) {
    kinks += rec.info[k].kink;
    if (rec.info[k].landed && std::abs(rec.x[k][0] - 0.75) < 1e-14) {
      ++landed;
      EXPECT_NEAR(rec.x[k][1], std::sqrt(1 - 0.5625 + 0.25), 1e-12);
    }
  }
  EXPECT_EQ(kinks, out.kink_steps);
  EXPECT_EQ(landed, 1);
  const auto [stuck, stuck_rec] = run(false);
  EXPECT_EQ(stuck.stop, curve_stop::step_underflow);
  EXPECT_LT(stuck_rec.x.back()[0], 0.7 + 1e-3);
}

// Bad input is refused by name before anything is evaluated.
TEST(curve_stepper, refuses_bad_input_naming_it) {
  auto refused = [](const curve_stepper_options& o, const vec<double>& x0, const std::string& part) {
    scripted_circle p;
    try {
      trace_curve(p, x0, north, euclid, o);
      ADD_FAILURE() << "expected input_error: " << part;
    } catch (const input_error& e) {
      EXPECT_TRUE(has(e.what(), part)) << e.what();
    }
    EXPECT_EQ(p.curve.calls, 0);
    EXPECT_TRUE(p.rec.x.empty());
  };
  curve_stepper_options o;
  o.label = "test curve";
  refused(o, v2(NAN, 0.0), "test curve: start entry 0");
  curve_stepper_options bad = o;
  bad.step = 0;
  refused(bad, east, "step must be finite and > 0");
  bad = o;
  bad.step = -0.1;
  refused(bad, east, "step must be finite and > 0");
  bad = o;
  bad.min_step = 0;
  refused(bad, east, "min_step");
  bad = o;
  bad.targets.push_back({0, {}, "nu"});
  refused(bad, east, "listed nu values are empty");
  bad = o;
  bad.targets.push_back({0, {0.1, 0.3, 0.2}, "nu"});
  refused(bad, east, "listed nu values must be strictly monotone (entries 1 and 2");
  bad = o;
  bad.targets.push_back({0, {0.1, 0.1}, "nu"});
  refused(bad, east, "strictly monotone");
  bad = o;
  bad.targets.push_back({0, {0.1, NAN}, "nu"});
  refused(bad, east, "listed nu value 1 is not finite");
  bad = o;
  bad.bounds.push_back({5, 0.0, "nu"});
  refused(bad, east, "outside [0, 2)");
  EXPECT_THROW(curve_metric(vec<double>::Zero(2)), input_error);
  EXPECT_THROW(curve_metric(v2(1.0, -1.0)), input_error);
  // a decreasing list is monotone too
  scripted_circle p;
  o.targets.push_back({0, {0.5, 0.0}, "x0"});
  o.max_points = 10;
  EXPECT_NO_THROW(trace_curve(p, east, north, euclid, o));
}

// ---- the joint corrector of the fixed-equilibrium Hopf tracer ----
namespace {
/// w' = f(w - w*(nu)) with z = w - w*(nu): z0' = a z0 - b z1 + z0 z1, z1' = b z0 + a z1 + z0^2 / 2,
/// z2' = -z2 + z0^2, z3' = -2 z3 + z1 z2; a = 1 - mu^2 - nu^2, b = 1 + 0.3 mu. The equilibrium
/// w*(nu) does not depend on mu; the Hopf points are the unit circle in (mu, nu), omega = b.
class circle_hopf_family {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;
  explicit circle_hopf_family(double nu) : nu_(nu) {}
  Eigen::Index size() const { return 4; }
  vec<double> equilibrium() const {
    return (vec<double>(4) << std::sin(nu_), std::cos(2 * nu_), 0.5 * nu_, nu_ * nu_).finished();
  }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    const vec<double> we = equilibrium();
    vec<T> z(4);
    for (int i = 0; i < 4; ++i) z[i] = w[i] - T(we[i]);
    const T a = T(1.0) - mu * mu - T(nu_ * nu_), b = T(1.0) + T(0.3) * mu;
    vec<T> f(4);
    f[0] = a * z[0] - b * z[1] + z[0] * z[1];
    f[1] = b * z[0] + a * z[1] + T(0.5) * z[0] * z[0];
    f[2] = -z[2] + z[0] * z[0];
    f[3] = T(-2.0) * z[3] + z[1] * z[2];
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const {
    Eigen::MatrixXd a(4, 4);
    for (int j = 0; j < 4; ++j) a.col(j) = jacobian_product(*this, w, mu, vec<double>(vec<double>::Unit(4, j)));
    return a.sparseView();
  }
  /// A - 0.5 I: L - i omega I stays regular at the Hopf point (a preconditioner, not exact).
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    return (Eigen::MatrixXd(jacobian(w, mu)) - 0.5 * Eigen::MatrixXd::Identity(4, 4)).sparseView();
  }

 private:
  double nu_;
};
}  // namespace

// From the converged start at nu = 0.6 (mu = 0.8), a prediction at nu = 0.7 with the landing row
// nu = 0.7: the joint corrector converges to mu = sqrt(1 - 0.49), omega = 1 + 0.3 mu and
// w = w*(0.7) without any nested steady solve; the nested corrector reaches the same point
// with one. The arclength row (c = W t) is solved likewise.
TEST(curve_stepper, joint_corrector_lands_on_the_circle_without_steady_solves) {
  auto family = [](double nu) { return circle_hopf_family(nu); };
  using F = decltype(family);
  hopf_curve_options opt;
  opt.label = "joint";
  fixed_equilibrium_hopf_curve_options sopt;
  sopt.joint_equilibrium = true;
  const double nu0 = 0.6;
  const circle_hopf_family s0(nu0);
  hopf_point start = hopf_start(s0, s0.equilibrium(), 0.8, 1.24);
  start.w.array() += 1e-5;
  const internal::hopf_curve_layout L(4, false, opt, resolve_normalisation<Eigen::SparseMatrix<double>>(opt.normalisation));
  auto run = [&](bool joint, double mu1, double nu1, const vec<double>* row) {
    fixed_equilibrium_hopf_curve_result res;
    internal::fixed_equilibrium_hopf_corrector<2, F> corr(family, L, opt, sopt, res,
                                                          internal::family_cache<F, circle_hopf_family>(family));
    const hopf_result h0 = corr.converge_start(nu0, start);
    EXPECT_NEAR(h0.point.mu, 0.8, 1e-10);
    vec<double> x(L.N);
    L.set_p(x, h0.point.p);
    x[L.imu] = h0.point.mu;
    x[L.inu] = nu0;
    x[L.iom] = h0.point.omega;
    const vec<double> s = L.refresh_s(x);
    corr.costs() = {};
    vec<double> x0 = x;
    x0[L.imu] = mu1;
    x0[L.inu] = nu1;
    const std::array<double, 3> c = row ? L.row3(*row) : std::array<double, 3>{0, 1, 0};
    const double value = row ? row->dot(x0) : nu1;
    std::string why;
    auto r = joint ? corr.correct_joint(x0, s, c, value, 10.0, why) : corr.correct_nested(x0, s, c, value, 10.0, why);
    EXPECT_TRUE(r.has_value()) << why;
    return std::tuple{r.value_or(internal::hopf_corrected{}), corr.costs(), vec<double>(corr.point_w(r ? r->x : x))};
  };
  for (bool joint : {true, false}) {
    const auto [r, costs, w] = run(joint, 0.8, 0.7, nullptr);
    ASSERT_EQ(r.x.size(), L.N);
    const double mu = r.x[L.imu], nu = r.x[L.inu], om = r.x[L.iom];
    EXPECT_NEAR(nu, 0.7, 1e-14);
    EXPECT_NEAR(mu, std::sqrt(1 - 0.49), 1e-10) << (joint ? "joint" : "nested");
    EXPECT_NEAR(om, 1 + 0.3 * mu, 1e-10);
    EXPECT_LT((w - circle_hopf_family(0.7).equilibrium()).norm(), 1e-10);
    EXPECT_GE(r.iterations, 2);
    EXPECT_LE(r.iterations, 8);
    if (joint) {
      EXPECT_EQ(costs.steady_solves, 0);
      EXPECT_EQ(costs.steady_iterations, r.iterations);  // one flow Newton step per iteration
    } else {
      EXPECT_GE(costs.steady_solves, 1);
    }
  }
  // the arclength row through the prediction (mu, nu) = (0.8, 0.6) + 0.1 (-0.6, 0.8): the point
  // of the circle on that line orthogonal to the tangent: angle asin(0.1) further along
  const vec<double> row = [&] {
    vec<double> c = vec<double>::Zero(L.N);
    c[L.imu] = -0.6;
    c[L.inu] = 0.8;
    return c;
  }();
  const auto [r, costs, w] = run(true, 0.8 - 0.06, 0.6 + 0.08, &row);
  (void)w;
  const double phi = std::atan2(0.6, 0.8) + std::asin(0.1);  // nu = sin(phi), mu = cos(phi)
  EXPECT_NEAR(r.x[L.inu], std::sin(phi), 1e-10);
  EXPECT_NEAR(r.x[L.imu], std::cos(phi), 1e-10);
  EXPECT_EQ(costs.steady_solves, 0);
}
