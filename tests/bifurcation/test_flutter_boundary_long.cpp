// trace_flutter_boundary with a moving equilibrium (bifurcation/flutter_boundary.hpp): the
// pitch-plunge NACA 0012 at a mean incidence alpha_0 = 1 deg on the coarse grid, light case.
// From M = 0.65 natural continuation cannot reach M = 0.70 (the branch folds back near M = 0.665),
// (it ends at M = 0.6625), so the driver's V-g scan at M = 0.70 (damping of both structural modes along Ubar with the
// static aeroelastic equilibrium continued) finds the lowest rising zero of g and starts the full
// Hopf solve from it. Checked: the jump point is a Hopf point of the full system whose static
// deflection is that of a separate static aeroelastic solve; it agrees with the scan's zero of g;
// the crossing checks (V-g scans from 0.5 Ubar*) pass. Then the skip of a listed Mach number
// without a flutter point in the scan. Then the crossing direction of a Hopf point where g falls
// through zero (medium grid), which the driver must not take for a flutter onset. Labelled long
// (about four minutes).
#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil_family.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

using namespace aerohopf;
using aerohopf::models::aerofoil_family;

namespace {

/// The static aeroelastic equilibrium of s at Ubar = to, continued from the one solved at `from`
/// in steps of at most `step` (the equilibrium at incidence is not unique: the branch reached by a
/// rising speed).
vec<double> static_equilibrium_continued(const aerofoil_family& f, const models::aerofoil_system& s, double from,
                                         double to, double step) {
  vec<double> w = f.static_equilibrium(s, from);
  for (double u = from; u < to;) {
    const double next = std::min(u + step, to);
    w = f.static_equilibrium_from(s, w, u, next);
    u = next;
  }
  return w;
}

TEST(FlutterBoundaryMoving, BranchEndJumpsByVgScanAtAlphaOneDegree) {
  structure::pitch_plunge_parameters sp;
  sp.mu_s = 10.0;
  const aerofoil_family f(flow::naca_cgrid(), sp, {}, std::numbers::pi / 180);
  flutter_boundary_options o = f.boundary_options();
  ASSERT_TRUE(o.moving_equilibrium);
  o.start_mu = 1.56;
  o.start_omega = 0.71;
  o.label = "alpha1";
  o.log = nullptr;
  const flutter_boundary b = trace_flutter_boundary(f, 4, {0.65, 0.70}, nullptr, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  // M = 0.65, the halved step's 0.6625 (the last point of the branch), and the jump at 0.70 (the
  // example's coarse boundary at alpha_0 = 1 deg)
  ASSERT_EQ(b.points.size(), 3u);
  EXPECT_NEAR(b.points[0].mu, 1.556707, 2e-6);
  EXPECT_NEAR(b.points[1].mach, 0.6625, 1e-12);
  EXPECT_NEAR(b.points[1].mu, 1.556537, 2e-6);
  const auto& p = b.points[2];
  EXPECT_TRUE(p.jump);
  EXPECT_NEAR(p.mach, 0.70, 1e-12);
  // the jump is the scan's zero of g, far above the end of the first branch
  EXPECT_NEAR(p.mu, 2.139307, 2e-5 * 2.14);
  EXPECT_NEAR(p.omega, 0.685104, 2e-5);
  bool scanned = false;
  for (const auto& a : b.attempts) scanned = scanned || (a.kind == "V-g scan");
  EXPECT_TRUE(scanned);
  // a Hopf point of the full system: the residual at the returned point
  const auto s = f.system(4, 0.70);
  hopf_options ho;
  const hopf_problem<models::aerofoil_system> pr(s, p.point, ho, "check");
  EXPECT_LT(pr.residual(pr.start()).norm(), 1e-6);
  // its equilibrium is the static aeroelastic one at Ubar*: a separate solve, continued from the
  // one at Ubar = 1 in steps of 0.05 (the equilibrium is not unique there: Newton from the section
  // at rest straight at Ubar*, or from Ubar = 1 in one step, lands on another branch, alpha =
  // -0.052 rad)
  const vec<double> w = static_equilibrium_continued(f, s, 1.0, p.mu, 0.05);
  const double alpha_static = w[w.size() - 2];
  EXPECT_NEAR(p.point.w[p.point.w.size() - 2], alpha_static, 1e-8);
  EXPECT_GT(alpha_static, 0.1);  // the section deflects by about 8.6 deg at this Ubar
  // the first point (reached by the frozen-flow secant) is a flutter onset: Re(lambda) rises
  // through zero there
  const auto [below, above] = internal::moving_crossing_sides(f, f.system(4, 0.65), b.points[0].point, o);
  EXPECT_LT(below, 0.0);
  EXPECT_GT(above, 0.0);
  // the crossing checks: the jump and the last point (the same) pass
  ASSERT_FALSE(b.checks.empty());
  for (const auto& c : b.checks) EXPECT_TRUE(c.pass) << c.what << " at M = " << c.mach << ": lowest " << c.lowest_mu;
}

// A listed Mach number whose scan finds no rising zero of g is skipped with the reason, and the
// boundary goes on: with the scans capped at 1.25 x the branch's last Ubar (1.9457), M = 0.70
// (its flutter point is at 2.139) is skipped, and the boundary goes on from M = 0.6625 to the
// point of the example's coarse boundary at M = 0.75 (1.849328).
TEST(FlutterBoundaryMoving, MachWithoutFlutterInTheScanIsSkipped) {
  structure::pitch_plunge_parameters sp;
  sp.mu_s = 10.0;
  const aerofoil_family f(flow::naca_cgrid(), sp, {}, std::numbers::pi / 180);
  flutter_boundary_options o = f.boundary_options();
  o.start_mu = 1.56;
  o.start_omega = 0.71;
  o.scan_to = 1.25;
  o.label = "alpha1 skip";
  o.log = nullptr;
  const flutter_boundary b = trace_flutter_boundary(f, 4, {0.65, 0.70, 0.75}, nullptr, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_EQ(b.skipped.size(), 1u);
  EXPECT_NEAR(b.skipped[0].first, 0.70, 1e-12);
  EXPECT_NE(b.skipped[0].second.find("no rising zero of g"), std::string::npos) << b.skipped[0].second;
  EXPECT_NE(b.stop_reason.find("0.7000"), std::string::npos) << b.stop_reason;
  ASSERT_EQ(b.points.size(), 3u);
  const auto& p = b.points.back();
  EXPECT_NEAR(p.mach, 0.75, 1e-12);
  EXPECT_NEAR(p.mu, 1.849328, 2e-5 * 1.85);
  // the point past the skip (here also the last point) is checked as such, and passes
  ASSERT_FALSE(b.checks.empty());
  EXPECT_EQ(b.checks.back().what, "past a skipped Mach number");
  for (const auto& c : b.checks) EXPECT_TRUE(c.pass) << c.what << " at M = " << c.mach << ": lowest " << c.lowest_mu;
}

// A Hopf point of the full system where g FALLS through zero: medium grid, M = 0.65, Ubar =
// 1.5762689 (the frozen-flow secant led there from the point at M = 0.60). A V-g scan of the
// equilibrium continued in steps of 0.01 Ubar from 0.5 Ubar (independent: the damping of the
// tracked mode) has g = +0.0165 at 0.99 Ubar and -0.0068 at 1.01 Ubar, and the onset at 1.5221
// where g rises. moving_crossing_sides must say falling, so the driver rejects such a point.
TEST(FlutterBoundaryMoving, CrossingSidesOfARestabilisingHopfPoint) {
  structure::pitch_plunge_parameters sp;
  sp.mu_s = 10.0;
  const aerofoil_family f(flow::naca_cgrid(), sp, {}, std::numbers::pi / 180);
  flutter_boundary_options o = f.boundary_options();
  o.label = "alpha1 sides";
  const auto s = f.system(2, 0.65);
  hopf_point h;
  h.mu = 1.5762688604590065;
  h.omega = 0.68823681668640457;
  // the static aeroelastic equilibrium reached by a rising speed (pitch 0.0709 rad at Ubar*)
  h.w = static_equilibrium_continued(f, s, 0.5 * h.mu, h.mu, 0.01 * h.mu);
  EXPECT_NEAR(h.w[h.w.size() - 2], 0.07093, 1e-4);
  const auto [below, above] = internal::moving_crossing_sides(f, s, h, o);
  EXPECT_GT(below, 0.0);
  EXPECT_LT(above, 0.0);
}

}  // namespace
