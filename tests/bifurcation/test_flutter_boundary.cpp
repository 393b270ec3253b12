// trace_flutter_boundary (bifurcation/flutter_boundary.hpp) on the pitch-plunge NACA 0012
// (models/aerofoil_family.hpp), against the boundaries the aerofoil example computed with its own
// copy of the algorithm before it moved into the library (tests/data/aerofoil_boundaries), the
// coarser-level bridge against the tracer's landing, the coarse-increment predictor against
// natural continuation without it, the crossing check, the
// cost figures as a pure function of the points, and bad input.
#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil_family.hpp>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::models::aerofoil_family;

namespace {

static_assert(flutter_family<aerofoil_family>);

struct reference_point {
  double mach, ubar, omega;
};

std::vector<reference_point> read_reference(const std::string& name) {
  const auto path = std::filesystem::path(__FILE__).parent_path().parent_path() / "data" / "aerofoil_boundaries" / name;
  std::ifstream f(path);
  EXPECT_TRUE(f.good()) << path;
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "mach,ubar,omega");
  std::vector<reference_point> r;
  while (std::getline(f, line)) {
    std::istringstream is(line);
    reference_point p{};
    char c1 = 0, c2 = 0;
    is >> p.mach >> c1 >> p.ubar >> c2 >> p.omega;
    EXPECT_TRUE(is && c1 == ',' && c2 == ',') << line;
    r.push_back(p);
  }
  return r;
}

/// The listed Mach numbers of spec 05: 0.50 .. 0.80 step 0.05, 0.81 .. 0.95 step 0.01.
std::vector<double> listed_machs(double from = 0.5) {
  std::vector<double> m;
  for (int k = 0; k <= 6; ++k) m.push_back(std::round((0.5 + 0.05 * k) * 1e4) / 1e4);
  for (int k = 1; k <= 15; ++k) m.push_back(std::round((0.80 + 0.01 * k) * 1e4) / 1e4);
  std::vector<double> r;
  for (double x : m)
    if (x >= from - 1e-9) r.push_back(x);
  return r;
}

aerofoil_family family(double mu_s) {
  structure::pitch_plunge_parameters p;
  p.mu_s = mu_s;
  return aerofoil_family(flow::naca_cgrid(), p);
}

/// The family's driver options (aerofoil_family::boundary_options, as the example passes them)
/// with the case's start, silent, without the crossing checks unless asked.
flutter_boundary_options options_for(const aerofoil_family& f, double ubar_guess, double omega_guess,
                                     const std::string& label) {
  flutter_boundary_options o = f.boundary_options();
  o.start_mu = ubar_guess;
  o.start_omega = omega_guess;
  o.label = label;
  o.log = nullptr;
  o.check_crossings = false;
  return o;
}

/// Every reference point has a boundary point at the same Mach number with Ubar*, omega* within
/// 3e-5 relative (the Newton tolerance fixes Ubar* to ~2e-5 on the heavy boundaries), and the
/// same number of points.
void expect_matches(const flutter_boundary& b, const std::vector<reference_point>& ref) {
  ASSERT_EQ(b.points.size(), ref.size()) << b.label;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const auto& p = b.points[k];
    EXPECT_NEAR(p.mach, ref[k].mach, 1e-6) << b.label << " point " << k;
    EXPECT_NEAR(p.mu / ref[k].ubar, 1.0, 3e-5) << b.label << " M = " << p.mach;
    EXPECT_NEAR(p.omega / ref[k].omega, 1.0, 3e-5) << b.label << " M = " << p.mach;
  }
}

TEST(FlutterBoundary, LightCoarseEqualsTheExamplesBoundary) {
  const auto f = family(10.0);
  const auto machs = listed_machs();
  const flutter_boundary b = trace_flutter_boundary(f, 4, machs, nullptr, options_for(f, 1.66, 0.75, "light coarse"));
  EXPECT_TRUE(b.complete) << b.stop_reason;
  expect_matches(b, read_reference("boundary_light_coarse.csv"));
  // attempts: every accepted point has its record, the first is the inverse-power start
  ASSERT_FALSE(b.attempts.empty());
  EXPECT_EQ(b.attempts.front().kind, "first");
  const auto accepted = std::count_if(b.attempts.begin(), b.attempts.end(),
                                      [](const flutter_attempt& a) { return a.outcome == "accepted"; });
  EXPECT_EQ(static_cast<std::size_t>(accepted), b.points.size());
  const flutter_boundary_costs c = boundary_costs(b, machs);
  EXPECT_EQ(c.listed, machs.size() - 1);
  EXPECT_GT(c.hopf_per_steady_listed, 0.0);
}

// The heavy case jumps to the other mode near M = 0.90 and hands over to the Hopf-curve tracer
// over the steep stretch near M = 0.827 (spec 05): the driver's whole repertoire.
TEST(FlutterBoundary, HeavyCoarseEqualsTheExamplesBoundary) {
  const auto f = family(100.0);
  flutter_boundary_options o = options_for(f, 4.6, 0.22, "heavy coarse");
  o.check_crossings = true;
  const flutter_boundary b = trace_flutter_boundary(f, 4, listed_machs(), nullptr, o);
  EXPECT_TRUE(b.complete) << b.stop_reason;
  expect_matches(b, read_reference("boundary_heavy_coarse.csv"));
  EXPECT_TRUE(std::any_of(b.points.begin(), b.points.end(), [](const flutter_boundary_point& p) { return p.jump; }));
  EXPECT_TRUE(std::any_of(b.points.begin(), b.points.end(), [](const flutter_boundary_point& p) { return !p.own_steady; }));
  EXPECT_TRUE(std::any_of(b.attempts.begin(), b.attempts.end(), [](const flutter_attempt& a) { return a.kind == "arclength"; }));
  // before the hand-over, the bridge on the very coarse grid is tried and fails: there the branch
  // ends near M = 0.824 (the boundary jumps to the other mode), so the sub-trace has no point of
  // this mode at the stretch's start M = 0.82625; the tracer then takes over on this level
  const auto bridge = std::find_if(b.attempts.begin(), b.attempts.end(),
                                   [](const flutter_attempt& a) { return a.kind == std::string("coarser-level bridge"); });
  ASSERT_NE(bridge, b.attempts.end());
  EXPECT_EQ(bridge->outcome.rfind("failed: ", 0), 0u) << bridge->outcome;
  EXPECT_LT(bridge - b.attempts.begin(),
            std::find_if(b.attempts.begin(), b.attempts.end(), [](const flutter_attempt& a) { return a.kind == "arclength"; }) -
                b.attempts.begin());
  // the crossing check: the jump and the last point are the lowest crossings of the imaginary axis
  ASSERT_EQ(b.checks.size(), 2u);
  EXPECT_EQ(b.checks.front().what, "jump");
  EXPECT_EQ(b.checks.back().what, "last point");
  EXPECT_TRUE(b.checks_passed());
  for (const auto& c : b.checks) EXPECT_NEAR(c.lowest_mu / c.mu, 1.0, 1e-5) << "M = " << c.mach;
}

// The coarser-level bridge (flutter_boundary_options::coarser_level_bridge) on the heavy medium
// grid, M = 0.82 -> 0.83, no coarse boundary given: natural continuation stops at M = 0.825 (the
// Hopf curve folds back in M near 0.826 and its mode turns, omega* 0.20 -> 0.40), the stretch is
// traced on the coarse grid and the medium grid restarted at M = 0.83 from it. The point equals
// the one the medium-grid tracer lands on (tests/data/aerofoil_boundaries, the example's
// boundary before the driver moved into the library) to the Newton tolerance. About 6 s.
TEST(FlutterBoundary, CoarserLevelBridgeLandsWhereTheTracerDoes) {
  const auto f = family(100.0);
  flutter_boundary_options o = options_for(f, 4.18, 0.211, "heavy medium bridge");
  ASSERT_TRUE(o.coarser_level_bridge);
  const flutter_boundary b = trace_flutter_boundary(f, 2, {0.82, 0.83}, nullptr, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_GE(b.points.size(), 2u);
  const auto bridge = std::find_if(b.attempts.begin(), b.attempts.end(),
                                   [](const flutter_attempt& a) { return a.kind == "coarser-level bridge"; });
  ASSERT_NE(bridge, b.attempts.end());
  EXPECT_EQ(bridge->outcome.rfind("accepted", 0), 0u) << bridge->outcome;
  EXPECT_TRUE(std::none_of(b.attempts.begin(), b.attempts.end(),
                           [](const flutter_attempt& a) { return a.kind == std::string("arclength"); }));
  const flutter_boundary_point& p = b.points.back();
  EXPECT_NEAR(p.mach, 0.83, 1e-12);
  // boundary_heavy_medium.csv at M = 0.83 (the tracer's landing)
  EXPECT_NEAR(p.mu / 4.5785485659128335, 1.0, 3e-5);
  EXPECT_NEAR(p.omega / 0.39513228340412276, 1.0, 3e-5);
  // the restart is the branch's continuation through the turned mode, not a jump
  EXPECT_FALSE(p.jump);
  EXPECT_LT(p.cosine, o.same_mode_cosine);
}

// Grid sequencing (very coarse -> coarse) and the coarse-increment predictor change the starts
// only, never the points: the light coarse boundary M = 0.75 .. 0.95 with and without them lists
// the same Mach numbers with the same Ubar*, omega* to the Newton tolerance.
TEST(FlutterBoundary, CoarsePredictorChangesStartsNotPoints) {
  const auto f = family(10.0);
  const auto machs = listed_machs(0.75);
  const flutter_boundary_options o = options_for(f, 1.66, 0.75, "light");
  const flutter_boundary vc = trace_flutter_boundary(f, 8, machs, nullptr, o);
  ASSERT_TRUE(vc.complete) << vc.stop_reason;
  flutter_boundary_options with = o, without = o;
  std::ostringstream log;
  with.log = &log;
  with.verbose = true;
  without.predictor = coarse_predictor::off;
  without.coarse_guided_restart = false;
  const flutter_boundary a = trace_flutter_boundary(f, 4, machs, &vc, with);
  const flutter_boundary b = trace_flutter_boundary(f, 4, machs, &vc, without);
  std::size_t used = 0;
  for (std::size_t at = log.str().find("predictor ||F||"); at != std::string::npos;
       at = log.str().find("predictor ||F||", at + 1))
    ++used;
  EXPECT_GE(used, 10u);  // one per continued coarse point
  std::size_t n = 0;
  for (const auto& p : a.points) {
    if (!internal::flutter_listed(machs, p.mach)) continue;
    const auto q = std::find_if(b.points.begin(), b.points.end(),
                                [&](const flutter_boundary_point& x) { return std::abs(x.mach - p.mach) < 1e-9; });
    ASSERT_NE(q, b.points.end()) << "M = " << p.mach;
    EXPECT_NEAR(p.mu / q->mu, 1.0, 1e-4) << "M = " << p.mach;
    EXPECT_NEAR(p.omega / q->omega, 1.0, 1e-4) << "M = " << p.mach;
    ++n;
  }
  EXPECT_EQ(n, machs.size());
}

// Continuation in a structural parameter: the mass ratio 12 boundary's first coarse point by
// Newton from the mass ratio 10 coarse point (start_point, although a coarser boundary is given)
// is the point grid sequencing gives, the coarser boundary still serves the next Mach number, and
// a start point of another level's size or with a bad frequency is refused.
TEST(FlutterBoundary, StartPointContinuesInAStructuralParameter) {
  const auto f10 = family(10.0), f12 = family(12.0);
  const flutter_boundary a = trace_flutter_boundary(f10, 4, {0.5}, nullptr, options_for(f10, 1.66, 0.75, "mu_s 10"));
  ASSERT_EQ(a.points.size(), 1u);
  const flutter_boundary_options o12 = options_for(f12, 1.66, 0.75, "mu_s 12");
  const flutter_boundary vc = trace_flutter_boundary(f12, 8, {0.5, 0.55}, nullptr, o12);
  ASSERT_TRUE(vc.complete) << vc.stop_reason;
  const flutter_boundary ref = trace_flutter_boundary(f12, 4, {0.5, 0.55}, &vc, o12);
  ASSERT_TRUE(ref.complete) << ref.stop_reason;
  EXPECT_GT(ref.points[0].mu / a.points[0].mu, 1.05);  // a different problem, not the same point again

  flutter_boundary_options o = o12;
  o.label = "mu_s 12 from 10";
  o.start_point = a.points[0].point;
  std::ostringstream log;
  o.log = &log;
  o.verbose = true;
  const flutter_boundary b = trace_flutter_boundary(f12, 4, {0.5, 0.55}, &vc, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_EQ(b.points.size(), ref.points.size());
  for (std::size_t k = 0; k < b.points.size(); ++k) {
    EXPECT_NEAR(b.points[k].mu / ref.points[k].mu, 1.0, 1e-6) << k;
    EXPECT_NEAR(b.points[k].omega / ref.points[k].omega, 1.0, 1e-6) << k;
  }
  ASSERT_FALSE(b.attempts.empty());
  EXPECT_EQ(b.attempts.front().kind, "start point");
  EXPECT_EQ(log.str().find("inverse power"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("predictor ||F||"), std::string::npos) << log.str();  // the coarser boundary at M = 0.55

  o.log = nullptr;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f12, 8, {0.5}, nullptr, o); }),
                             "start_point.p has size"));
  o.start_point->omega = NAN;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f12, 4, {0.5}, nullptr, o); }),
                             "start_point.omega"));
}

TEST(FlutterBoundary, CostsArePureFunctionsOfThePoints) {
  flutter_boundary b;
  auto pt = [](double m, double hopf, double st, bool own) {
    flutter_boundary_point p;
    p.mach = m;
    p.hopf_seconds = hopf;
    p.steady_seconds = st;
    p.own_steady = own;
    return p;
  };
  b.points = {pt(0.5, 9.0, 1.0, true), pt(0.55, 1.0, 2.0, true), pt(0.575, 0.5, 1.0, true), pt(0.6, 2.0, 2.0, true),
              pt(0.61, 1.0, 2.0, false)};
  const std::vector<double> listed{0.5, 0.55, 0.6};
  const auto c = boundary_costs(b, listed);
  EXPECT_EQ(c.continued, 4u);
  EXPECT_EQ(c.listed, 2u);
  EXPECT_DOUBLE_EQ(c.hopf_per_steady, (1.0 + 0.5 + 2.0 + 1.0) / (2.0 + 1.0 + 2.0 + 2.0));
  // beyond one steady solve per listed Mach number: the Hopf work and the intermediate steady solve
  EXPECT_DOUBLE_EQ(c.hopf_per_steady_listed, (1.0 + 0.5 + 2.0 + 1.0 + 1.0) / (2.0 + 2.0));
  EXPECT_DOUBLE_EQ(c.beyond_steady_seconds, 1.0 + 0.5 + 2.0 + 1.0 + 1.0);
  EXPECT_DOUBLE_EQ(c.listed_steady_seconds, 2.0 + 2.0);
  EXPECT_DOUBLE_EQ(c.work_seconds, 9 + 1 + 1 + 2 + 0.5 + 1 + 2 + 2 + 1);
  flutter_boundary coarse;
  coarse.points = {pt(0.5, 1.0, 0.5, true), pt(0.55, 0.5, 0.5, false)};
  EXPECT_DOUBLE_EQ(boundary_cost_with_coarser(b, coarse, listed), (1.0 + 0.5 + 2.0 + 1.0 + 1.0 + 2.0) / 4.0);
}

// The points checked by the crossing test: a marked jump, a change of mode (structural cosine
// below the threshold), the first point past a skipped Mach number, and the last point, each once.
TEST(FlutterBoundary, CheckPointsAreJumpsModeChangesPointsPastASkipAndTheLast) {
  const auto f = family(10.0);
  using cvec = vec<std::complex<double>>;
  auto pt = [](double m, const cvec& p, bool jump) {
    flutter_boundary_point q;
    q.mach = m;
    q.point.p = p;
    q.jump = jump;
    return q;
  };
  const cvec plunge = (cvec(6) << 0, 0, 1, 0, std::complex<double>(0, 1), 0).finished();
  const cvec pitch = (cvec(6) << 0, 0, 0, 1, 0, std::complex<double>(0, 1)).finished();
  flutter_boundary b;
  b.points = {pt(0.50, plunge, false), pt(0.55, plunge, false), pt(0.60, pitch, false), pt(0.65, pitch, true),
              pt(0.75, pitch, false), pt(0.80, pitch, false), pt(0.85, pitch, false)};
  b.skipped = {{0.70, "no rising zero of g"}};
  const auto at = flutter_check_points(f, b, 0.9);
  ASSERT_EQ(at.size(), 4u);
  EXPECT_EQ(at[0].first, 2u);  // the mode changes
  EXPECT_STREQ(at[0].second, "jump");
  EXPECT_EQ(at[1].first, 3u);  // marked
  EXPECT_STREQ(at[1].second, "jump");
  EXPECT_EQ(at[2].first, 4u);  // continued across M = 0.70
  EXPECT_STREQ(at[2].second, "past a skipped Mach number");
  EXPECT_EQ(at[3].first, 6u);
  EXPECT_STREQ(at[3].second, "last point");
  b.skipped.clear();
  EXPECT_EQ(flutter_check_points(f, b, 0.9).size(), 3u);
}

TEST(FlutterBoundary, BadInputIsRefused) {
  const auto f = family(10.0);
  flutter_boundary_options o = options_for(f, 1.66, 0.75, "bad");
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {}, nullptr, o); }), "no Mach numbers"));
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.6, 0.5}, nullptr, o); }),
                             "must increase"));
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5, NAN}, nullptr, o); }),
                             "Mach number 1"));
  o.start_omega = -1;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5}, nullptr, o); }),
                             "start_omega"));
  o = options_for(f, 1.66, 0.75, "bad");
  o.same_mode_cosine = 1.5;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5}, nullptr, o); }),
                             "same_mode_cosine"));
  o = options_for(f, 1.66, 0.75, "bad");
  o.scan_delta = 0.5;  // wider than half the scan step: the check's last two values would not bracket mu*
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5}, nullptr, o); }),
                             "scan_delta 0.5"));
  o = options_for(f, 1.66, 0.75, "bad");
  o.start_eigen_tolerance = NAN;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5}, nullptr, o); }),
                             "start_eigen_tolerance"));
  o = options_for(f, 1.66, 0.75, "bad");
  o.mu_min = NAN;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { trace_flutter_boundary(f, 8, {0.5}, nullptr, o); }), "mu_min"));
}

TEST(FlutterBoundary, PointsBelowMuMinAreRefused) {
  // the light very coarse boundary's first point lies at Ubar* ~ 1.7: with mu_min above it the
  // converged point is refused, so there is no first point
  const auto f = family(10.0);
  flutter_boundary_options o = options_for(f, 1.66, 0.75, "mu_min");
  o.mu_min = 5.0;
  o.log = nullptr;
  EXPECT_THROW(trace_flutter_boundary(f, 8, {0.5}, nullptr, o), convergence_error);
  o.mu_min = 1.0;
  const flutter_boundary b = trace_flutter_boundary(f, 8, {0.5}, nullptr, o);
  ASSERT_EQ(b.points.size(), 1u);
  EXPECT_GT(b.points[0].mu, 1.0);
}

}  // namespace
