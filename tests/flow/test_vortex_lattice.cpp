// Vortex-lattice lift slope against two independent references: the elliptic lifting-line value
// 2 pi A / (A + 2) at large aspect ratio and the DATCOM (Helmbold-Diederich) formula for the
// swept, tapered AGARD 445.6 planform, with panel refinement converging and the Prandtl-Glauert
// factor recovered on a slender wing; the span loading integrates to CL; refusals.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/flow/vortex_lattice.hpp>

#include <cmath>
#include <numbers>

using namespace aerohopf;
using namespace aerohopf::flow;

TEST(VortexLattice, HighAspectRatioApproachesLiftingLine) {
  wing_planform p;
  p.root_chord = p.tip_chord = 1;
  p.semi_span = 50;  // A = 100
  const double a = p.aspect_ratio();
  EXPECT_NEAR(vortex_lattice_lift_slope(p, 0.0, 4, 100).lift_slope / (2 * std::numbers::pi * a / (a + 2)), 1.0, 0.03);
}

TEST(VortexLattice, Agard445LiftSlopeAgreesWithDatcomAndConverges) {
  const wing_planform p = agard445_6().planform;
  const double s1 = vortex_lattice_lift_slope(p, 0.5, 4, 12).lift_slope;
  const double s2 = vortex_lattice_lift_slope(p, 0.5, 8, 24).lift_slope;
  const double s3 = vortex_lattice_lift_slope(p, 0.5, 16, 48).lift_slope;
  EXPECT_LT(std::abs(s3 - s2), 0.7 * std::abs(s2 - s1));  // converging under refinement
  EXPECT_NEAR(s3 / datcom_lift_slope(p, 0.5), 1.0, 0.02);
  EXPECT_NEAR(datcom_lift_slope(p, 0.5), 3.107, 0.002);  // per radian: A = 3.29, mid-chord sweep 43.2 deg
}

TEST(VortexLattice, CompressibilityFactorOnASlenderUnsweptWing) {
  // at high aspect ratio and no sweep the Goethert rule reduces to about 1/beta on the section
  wing_planform p;
  p.root_chord = p.tip_chord = 1;
  p.semi_span = 50;
  const double r = vortex_lattice_lift_slope(p, 0.6, 4, 100).lift_slope / vortex_lattice_lift_slope(p, 0.0, 4, 100).lift_slope;
  EXPECT_NEAR(r, 1 / std::sqrt(1 - 0.36), 0.03);
  EXPECT_GT(r, 1.0);
}

TEST(VortexLattice, SpanLoadingIntegratesToTheLift) {
  const wing_planform p = agard445_6().planform;
  const vortex_lattice_result r = vortex_lattice_lift_slope(p, 0.5, 8, 40);
  // cosine stations: integrate c c_l / (c_mean CL) over y/b by the midpoint rule on the panels
  double integral = 0;
  for (int j = 0; j < 40; ++j) {
    const double y0 = 0.5 * (1 - std::cos(std::numbers::pi * j / 40)), y1 = 0.5 * (1 - std::cos(std::numbers::pi * (j + 1) / 40));
    integral += r.span_loading[j] * (y1 - y0);
  }
  EXPECT_NEAR(integral, 1.0, 1e-12);
  EXPECT_GT(r.span_loading[0], r.span_loading[39]);  // loading falls to the tip
}

TEST(VortexLattice, RefusesBadInput) {
  const wing_planform p = agard445_6().planform;
  EXPECT_THROW(vortex_lattice_lift_slope(p, 1.0), input_error);
  EXPECT_THROW(vortex_lattice_lift_slope(p, 0.5, 0, 10), input_error);
  EXPECT_THROW(datcom_lift_slope(p, -0.1), input_error);
  wing_planform bad = p;
  bad.semi_span = 0;
  EXPECT_THROW(vortex_lattice_lift_slope(bad, 0.5), input_error);
}
