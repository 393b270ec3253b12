// Wing geometry: the AGARD 445.6 planform against the figures of spec 06 (area, mean aerodynamic
// chord, taper, sweeps, tip leading edge), the NACA 65A004 section interpolant against its table
// (exact at the stations, no overshoot between them, 4 % thickness, round nose), and refusals.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/flow/wing_geometry.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::flow;

namespace {
double degrees(double tan_value) { return std::atan(tan_value) * 180 / std::numbers::pi; }
}  // namespace

TEST(WingGeometry, Agard445PlanformMatchesTheSpec) {
  const wing_geometry w = agard445_6();
  const wing_planform& p = w.planform;
  EXPECT_NEAR(p.area(), 0.353, 5e-4);                    // half-wing area, m^2
  EXPECT_NEAR(p.mean_aerodynamic_chord(), 0.470, 5e-4);  // m
  EXPECT_NEAR(p.taper_ratio(), 0.659, 5e-4);
  EXPECT_NEAR(degrees(p.sweep_tan(0.25)), 45.0, 0.05);  // quarter chord
  EXPECT_NEAR(degrees(p.sweep_tan(0.0)), 46.7, 0.05);   // leading edge
  EXPECT_NEAR(degrees(p.sweep_tan(1.0)), 39.1, 0.05);   // trailing edge
  EXPECT_NEAR(p.x_leading_edge(p.semi_span) / 0.0254, 31.87, 0.01);  // tip leading edge, inches
  EXPECT_DOUBLE_EQ(p.chord(0), 0.5587);
  EXPECT_DOUBLE_EQ(p.chord(p.semi_span), 0.3682);
  EXPECT_DOUBLE_EQ(p.x_at(1.0, 0.3), p.x_leading_edge(0.3) + p.chord(0.3));
}

TEST(WingGeometry, SectionInterpolantReproducesTheTableWithoutOvershoot) {
  const section_ordinates s = naca65a004();
  const auto& x = s.stations();
  const auto& z = s.ordinates();
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(s.half_thickness(x[i]), z[i], 1e-15) << "x/c = " << x[i];
  // monotone cubic: between two stations the value stays within their ordinates (at the crest
  // too: the slope is zero at a station where the table turns)
  for (std::size_t i = 0; i + 1 < x.size(); ++i)
    for (int k = 1; k < 10; ++k) {
      const double xi = x[i] + (x[i + 1] - x[i]) * k / 10.0, v = s.half_thickness(xi);
      const double lo = std::min(z[i], z[i + 1]), hi = std::max(z[i], z[i + 1]);
      EXPECT_GE(v, lo - 1e-15) << "x/c = " << xi;
      EXPECT_LE(v, hi + 1e-15) << "x/c = " << xi;
    }
  EXPECT_NEAR(s.thickness_ratio(), 0.04, 1e-4);
  // round nose: z ~ sqrt(x/c) below the first station, so z(x/4) = z(x)/2 there
  EXPECT_NEAR(s.half_thickness(0.005 / 4), 0.5 * s.half_thickness(0.005), 2e-4);
  EXPECT_EQ(s.half_thickness(-0.1), 0.0);
  EXPECT_EQ(s.half_thickness(1.5), 0.0);
}

TEST(WingGeometry, ThicknessFollowsSectionAndChord) {
  const wing_geometry w = agard445_6();
  const double y = 0.4, c = w.planform.chord(y), x = w.planform.x_at(0.5, y);
  EXPECT_NEAR(w.thickness(x, y), 2 * 0.01954 * c, 1e-12);
  EXPECT_EQ(w.thickness(w.planform.x_leading_edge(y) - 1e-3, y), 0.0);  // ahead of the leading edge
  EXPECT_NEAR(w.thickness(w.planform.x_at(0.5, 0.0), 0.0), 2 * 0.01954 * 0.5587, 1e-12);
}

TEST(WingGeometry, RefusesMalformedSections) {
  EXPECT_THROW(section_ordinates({0, 0.5, 1}, {0, 0.01}, "short"), input_error);
  EXPECT_THROW(section_ordinates({0, 0.6, 0.5, 1}, {0, 0.01, 0.01, 0}, "unordered"), input_error);
  EXPECT_THROW(section_ordinates({0, 0.5, 1}, {0, -0.01, 0}, "negative"), input_error);
  EXPECT_THROW(section_ordinates({0.1, 0.5, 1}, {0, 0.01, 0}, "no leading edge"), input_error);
  EXPECT_THROW(section_ordinates({0, NAN, 1}, {0, 0.01, 0}, "nan"), input_error);
  wing_planform p;
  p.tip_chord = -1;
  EXPECT_THROW(p.validate("test"), input_error);
}

TEST(WingGeometry, CamberedAndParabolicArcSections) {
  // a cambered section: thickness 2 z_t and camber m(x) = 0.04 x (1 - x)
  std::vector<double> x = {0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9, 1};
  std::vector<double> up(x.size()), lo(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = 0.06 * std::sqrt(x[i]) * (1 - x[i]), m = 0.04 * x[i] * (1 - x[i]);
    up[i] = m + t;
    lo[i] = m - t;
  }
  const section_ordinates s(x, up, lo, "cambered");
  EXPECT_FALSE(s.symmetric());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_NEAR(s.upper(x[i]), up[i], 1e-15);
    EXPECT_NEAR(s.lower(x[i]), lo[i], 1e-15);
    EXPECT_NEAR(s.camber(x[i]), 0.04 * x[i] * (1 - x[i]), 1e-15);
  }
  EXPECT_GT(s.thickness_ratio(), 0.04);
  EXPECT_THROW(section_ordinates({0, 0.5, 1}, {0, 0.01, 0}, {0, 0.02, 0}, "crossed"), input_error);
  EXPECT_THROW(section_ordinates({0, 0.5, 1}, {0.01, 0.02, 0}, {0, -0.02, 0}, "open nose"), input_error);
  const section_ordinates sym = naca65a004();
  EXPECT_TRUE(sym.symmetric());
  EXPECT_EQ(sym.camber(0.3), 0.0);
  EXPECT_EQ(sym.lower(0.3), -sym.upper(0.3));
  // the Goland wing's 4 % parabolic arc
  const section_ordinates arc = parabolic_arc(0.04);
  EXPECT_NEAR(arc.thickness_ratio(), 0.04, 1e-6);
  for (double xi : {0.13, 0.5, 0.77}) EXPECT_NEAR(arc.half_thickness(xi), 0.08 * xi * (1 - xi), 2e-6);
  EXPECT_THROW(parabolic_arc(0.0), input_error);
}
