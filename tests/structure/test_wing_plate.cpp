// A wing's plate model: the mesh over the planform (corners, section thickness, zero at the edges,
// root clamped), and the AGARD 445.6 weakened model 3 in mahogany against Yates' calculated
// frequencies, with the bending / torsion character of the first two modes at the tip.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <cmath>

using namespace aerohopf;
using namespace aerohopf::structure;

TEST(WingPlate, MeshFollowsPlanformAndSection) {
  const flow::wing_geometry w = flow::agard445_6();
  const int ni = 10, nj = 6;
  const plate_mesh m = wing_plate_mesh(w, ni, nj);
  ASSERT_EQ(m.nodes.size(), static_cast<std::size_t>((ni + 1) * (nj + 1)));
  const auto node = [&](int i, int j) { return static_cast<std::size_t>(i + (ni + 1) * j); };
  EXPECT_NEAR(m.nodes[node(0, 0)].norm(), 0.0, 1e-15);                                 // root leading edge
  EXPECT_NEAR(m.nodes[node(ni, 0)].x(), w.planform.root_chord, 1e-15);                 // root trailing edge
  EXPECT_NEAR(m.nodes[node(0, nj)].x(), w.planform.x_leading_edge(w.planform.semi_span), 1e-15);  // tip LE
  EXPECT_NEAR(m.nodes[node(0, nj)].y(), w.planform.semi_span, 1e-15);
  EXPECT_EQ(m.thickness[node(0, 3)], 0.0);  // edges thin to zero
  EXPECT_EQ(m.thickness[node(ni, 3)], 0.0);
  EXPECT_NEAR(m.thickness[node(5, 0)], 2 * w.section.half_thickness(0.5) * w.planform.root_chord, 1e-15);
  const plate_constraints c = clamped_root(m, ni);
  int fixed = 0;
  for (const auto& f : c.fixed) fixed += f[0] + f[1] + f[2];
  EXPECT_EQ(fixed, 3 * (ni + 1));
  EXPECT_THROW(wing_plate_mesh(w, 1, 4), input_error);
  EXPECT_THROW(clamped_root(m, 1000), input_error);
  const orthotropic_material mat = agard445_6_mahogany(w.planform);
  EXPECT_NEAR(mat.fibre_angle * 180 / 3.141592653589793, 45.0, 0.05);  // the quarter-chord line
}

TEST(WingPlate, Agard445WeakenedModel3FrequenciesNearYates) {
  // spec 06: fibre along the 45 deg quarter-chord line, thickness of the NACA 65A004 section,
  // clamped root; Yates' calculated frequencies 9.60, 38.17, 48.35, 91.54 Hz
  const flow::wing_geometry w = flow::agard445_6();
  const int ni = 20, nj = 20;
  const plate_mesh m = wing_plate_mesh(w, ni, nj);
  const plate_matrices km = assemble_plate(m, agard445_6_mahogany(w.planform));
  const plate_modes md = plate_modes_of(km, clamped_root(m, ni), {.count = 4});
  const double yates[4] = {9.60, 38.17, 48.35, 91.54};
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(md.frequency_hz(k) / yates[k], 1.0, 0.07) << "mode " << k + 1;
  EXPECT_NEAR(plate_mass(km), 1.72, 0.03);  // kg
  // mode character at the tip: bending (leading and trailing edge in phase) and torsion (opposite)
  const std::size_t tip_le = static_cast<std::size_t>(nj * (ni + 1)), tip_te = tip_le + static_cast<std::size_t>(ni);
  auto le_te = [&](int k) { return md.deflection(k)[static_cast<Eigen::Index>(tip_le)] * md.deflection(k)[static_cast<Eigen::Index>(tip_te)]; };
  EXPECT_GT(le_te(0), 0.0);  // first bending
  EXPECT_LT(le_te(1), 0.0);  // first torsion
}

