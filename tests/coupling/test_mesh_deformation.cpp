// Wing grid motion: the j-line weights (1 at the wall, 0 at the outer boundary), a linear
// structural motion reproduced exactly on the wing and carried through the volume, the outer
// boundary fixed and the cuts coincident after the motion, positive volumes at a realistic
// amplitude, jets through the moved points giving the basis, and the geometric conservation law:
// a uniform flow preserved on the moving grid (wing opened) to rounding.
#include <gtest/gtest.h>

#include <aerohopf/coupling/mesh_deformation.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/scalar/jet.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <cmath>

using namespace aerohopf;
using namespace aerohopf::coupling;

namespace {
const flow::wing_geometry& wing() {
  static const flow::wing_geometry w = flow::agard445_6();
  return w;
}
const flow::multiblock_grid<3>& very_coarse() {
  static const flow::multiblock_grid<3> g = flow::coarsen(flow::wing_cgrid(wing()), 8);
  return g;
}
wing_motion_options options() {
  wing_motion_options o;
  o.length_scale = wing().planform.root_chord;
  o.stride = 8;
  return o;
}
/// Modal data with two synthetic "modes" over the planform: a pitch t3 = x - 0.3 and a heave
/// with roll t3 = 0.1 + 0.5 y (metres), at the nodes of a plate mesh.
structure::modal_data linear_modes() {
  const structure::plate_mesh m = structure::wing_plate_mesh(wing(), 6, 6);
  structure::modal_data d;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    d.point_ids.push_back(static_cast<long long>(i) + 1);
    d.points.emplace_back(m.nodes[i].x(), m.nodes[i].y(), 0.0);
  }
  d.omega.resize(2);
  d.omega << 60, 240;
  d.generalised_mass = Eigen::VectorXd::Ones(2);
  for (int k = 0; k < 2; ++k) {
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(m.nodes.size()), 6);
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      s(static_cast<Eigen::Index>(i), 2) = k == 0 ? m.nodes[i].x() - 0.3 : 0.1 + 0.5 * m.nodes[i].y();
    d.shapes.push_back(s);
  }
  return d;
}
}  // namespace

TEST(MeshDeformation, JLineWeightsRunFromOneToZero) {
  const auto& b = very_coarse().points.blocks[0];
  const std::vector<double> psi = j_line_weights(b);
  for (int k = 0; k < b.points[2]; k += 3)
    for (int i = 0; i < b.points[0]; i += 5) {
      EXPECT_EQ(psi[flow::linear_index<3>({i, 0, k}, b.points)], 1.0);
      EXPECT_NEAR(psi[flow::linear_index<3>({i, b.points[1] - 1, k}, b.points)], 0.0, 1e-14);
      for (int j = 1; j < b.points[1]; ++j)
        EXPECT_LT(psi[flow::linear_index<3>({i, j, k}, b.points)], psi[flow::linear_index<3>({i, j - 1, k}, b.points)]);
    }
}

TEST(MeshDeformation, LinearMotionIsExactOnTheWingAndTheOuterBoundaryStays) {
  const wing_modal_motion mo(very_coarse(), linear_modes(), options());
  const auto& b = very_coarse().points.blocks[0];
  const flow::wing_grid_layout l = flow::wing_grid_layout::of(options().grid, 8);
  const int ks = l.tip, ni = b.points[0];
  const double cr = wing().planform.root_chord;
  for (int k = 0; k < ks; ++k)
    for (int i = l.wing_begin; i <= l.wing_end; ++i) {  // on the wing: the spline reproduces the linear field
      const auto& x = b.at({i, 0, k});
      const std::size_t p = flow::linear_index<3>({i, 0, k}, b.points);
      EXPECT_NEAR(mo.basis(0)[p][2], x[0] * cr - 0.3, 1e-10);
      EXPECT_NEAR(mo.basis(1)[p][2], 0.1 + 0.5 * x[1] * cr, 1e-10);
      EXPECT_NEAR(mo.basis(0)[p][0], 0.0, 1e-12);
    }
  for (int k = 0; k < b.points[2]; ++k)
    for (int i = 0; i < ni; ++i) {
      const std::size_t outer = flow::linear_index<3>({i, b.points[1] - 1, k}, b.points);
      for (int m = 0; m < 2; ++m) EXPECT_NEAR(mo.basis(m)[outer][2], 0.0, 1e-12);
      // the cuts stay closed: i and ni - 1 - i coincide on j = 0 off the wing
      if (i <= l.wing_begin || (k >= ks && i <= l.leading_edge)) {
        const std::size_t a = flow::linear_index<3>({i, 0, k}, b.points), c = flow::linear_index<3>({ni - 1 - i, 0, k}, b.points);
        for (int m = 0; m < 2; ++m)
          for (int d = 0; d < 3; ++d) EXPECT_NEAR(mo.basis(m)[a][d], mo.basis(m)[c][d], 1e-12);
      }
    }
}

TEST(MeshDeformation, PlateModesKeepCellsPositiveAndJetsGiveTheBasis) {
  const structure::plate_mesh pm = structure::wing_plate_mesh(wing(), 12, 12);
  const structure::plate_modes md = structure::plate_modes_of(
      pm, structure::agard445_6_mahogany(wing().planform), structure::clamped_root(pm, 12), {.count = 2});
  const structure::modal_data d = structure::modal_data_from_plate(pm, md);
  const wing_modal_motion mo(very_coarse(), d, options());
  // amplitude: a tip deflection of 5 % of the root chord in the first mode
  double wmax = 0;
  for (const auto& v : mo.basis(0)) wmax = std::max(wmax, std::abs(v[2]));
  const Eigen::Vector2d a(0.05 / wmax, 0.0);
  flow::multiblock_grid<3> moved = very_coarse();
  moved.points.blocks[0] = mo.points<double>(a);
  const flow::grid_quality q = flow::hexahedron_quality(moved);
  EXPECT_GT(q.min_volume, 0.0);
  // every corner stays positive except at the cut's leading edge beyond the tip, where the rest
  // grid has its collinear (180 deg) corners: those cells may turn slightly non-convex there
  const auto cells = moved.topology.cells[0];
  const flow::wing_grid_layout l = flow::wing_grid_layout::of(options().grid, 8);
  const int le = l.leading_edge, ks = l.tip;
  const flow::grid_quality inboard = flow::hexahedron_quality(moved, 0, {0, 0, 0}, {cells[0], cells[1], ks - 1});
  const flow::grid_quality off_edge = flow::hexahedron_quality(moved, 0, {0, 1, 0}, cells);
  const flow::grid_quality lower = flow::hexahedron_quality(moved, 0, {0, 0, ks - 1}, {le - 1, 1, cells[2]});
  const flow::grid_quality upper = flow::hexahedron_quality(moved, 0, {le + 1, 0, ks - 1}, {cells[0], 1, cells[2]});
  for (const auto* r : {&inboard, &off_edge, &lower, &upper}) EXPECT_GT(r->min_ratio_all, 0.05);
  const flow::grid_quality edge = flow::hexahedron_quality(moved, 0, {le - 1, 0, ks - 1}, {le + 1, 1, cells[2]});
  EXPECT_GT(edge.min_volume, 0.0);
  EXPECT_GT(edge.min_ratio_all, -0.1);
  using J = jet<double, 2>;
  const Eigen::Matrix<J, 2, 1> aj(J::variable(a[0], 0), J::variable(a[1], 1));
  const auto pj = mo.points<J>(aj);
  for (std::size_t p = 0; p < pj.x.size(); p += 97)
    for (int m = 0; m < 2; ++m)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(pj.x[p][static_cast<std::size_t>(c)].derivative(m), mo.basis(m)[p][static_cast<std::size_t>(c)]);
}

TEST(MeshDeformation, UniformFlowIsPreservedOnTheMovingGrid) {
  const wing_modal_motion mo(very_coarse(), linear_modes(), options());
  flow::multiblock_grid<3> g = very_coarse();
  for (auto& p : g.topology.patches)
    if (p.tag == "wing") p.kind = flow::boundary_kind::far_field;
  flow::euler_model<3> m(g, {.mach = 0.6, .alpha_rad = 0.02}, {});
  flow::multiblock_points<double, 3> pts, vel;
  pts.blocks.push_back(mo.points<double>(Eigen::Vector2d(0.03, -0.02)));
  vel.blocks.push_back(mo.velocities<double>(Eigen::Vector2d(0.4, 0.7)));
  m.set_grid_motion(pts, &vel);
  EXPECT_LT(m.residual(m.free_stream_vector()).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(MeshDeformation, RefusesMismatchedInput) {
  wing_motion_options o = options();
  o.stride = 4;  // not the level of the grid
  EXPECT_THROW(wing_modal_motion(very_coarse(), linear_modes(), o), input_error);
  const wing_modal_motion mo(very_coarse(), linear_modes(), options());
  EXPECT_THROW(mo.points<double>(Eigen::Vector3d::Zero()), input_error);
}
