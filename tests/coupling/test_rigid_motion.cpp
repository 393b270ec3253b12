// Rigid pitch-plunge grid motion (spec 05): the grid speeds equal the time derivative of the
// moved positions (taylor<> jet in time through a prescribed motion, and a central difference),
// the sign conventions (h up, alpha nose-up: trailing edge goes down), and free-stream
// preservation of the Euler residual on the moving NACA 0012 C-grid (wall replaced by far field
// so the uniform flow is an exact solution).
#include <gtest/gtest.h>

#include <aerohopf/coupling/rigid_motion.hpp>
#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/scalar.hpp>

#include <cmath>

using namespace aerohopf;
using namespace aerohopf::flow;
using namespace aerohopf::coupling;

namespace {
const std::array<double, 2> ea{0.4, 0.0};

// A prescribed motion h(t), alpha(t) as jets in t.
template <class S>
rigid_pose<S> motion(const S& t) {
  using std::cos;
  using std::sin;
  rigid_pose<S> q;
  q.h = S(0.05) * sin(S(0.7) * t);
  q.h_dot = S(0.05 * 0.7) * cos(S(0.7) * t);
  q.alpha = S(0.1) * cos(S(1.3) * t) + S(0.02);
  q.alpha_dot = S(-0.1 * 1.3) * sin(S(1.3) * t);
  return q;
}
}  // namespace

TEST(rigid_motion, grid_speed_is_time_derivative_of_position) {
  const auto g = coarsen(naca_cgrid(), 8);
  using jet = taylor<double, 1>;
  const double t0 = 0.37;
  multiblock_points<jet, 2> pj, vj;
  rigid_grid_motion<jet>(g.points, motion<jet>(jet::variable(t0, 1.0)), ea, pj, &vj);
  multiblock_points<double, 2> pp, pm2, p0, v;
  const double h = 1e-5;
  rigid_grid_motion<double>(g.points, motion<double>(t0 + h), ea, pp);
  rigid_grid_motion<double>(g.points, motion<double>(t0 - h), ea, pm2);
  rigid_grid_motion<double>(g.points, motion<double>(t0), ea, p0, &v);
  double worst_jet = 0, worst_fd = 0, scale = 0;
  for (std::size_t b = 0; b < g.points.blocks.size(); ++b)
    for (std::size_t k = 0; k < g.points.blocks[b].x.size(); ++k)
      for (int d = 0; d < 2; ++d) {
        const double vs = v.blocks[b].x[k][d];
        scale = std::max(scale, std::abs(vs));
        worst_jet = std::max(worst_jet, std::abs(pj.blocks[b].x[k][d][1] - vs));
        EXPECT_NEAR(vj.blocks[b].x[k][d][0], vs, 1e-14 * (1 + std::abs(vs)));
        EXPECT_NEAR(p0.blocks[b].x[k][d], pj.blocks[b].x[k][d][0], 1e-14 * 20);
      }
  for (std::size_t b = 0; b < g.points.blocks.size(); ++b)
    for (std::size_t k = 0; k < g.points.blocks[b].x.size(); ++k)
      for (int d = 0; d < 2; ++d)
        worst_fd = std::max(worst_fd, std::abs((pp.blocks[b].x[k][d] - pm2.blocks[b].x[k][d]) / (2 * h) -
                                               v.blocks[b].x[k][d]));
  ASSERT_GT(scale, 1.0);  // far-field points move fast under pitch
  EXPECT_LT(worst_jet, 1e-13 * scale);
  EXPECT_LT(worst_fd, 1e-8 * scale);
}

TEST(rigid_motion, sign_conventions_and_rigidity) {
  rigid_pose<double> q{0.1, 0.0, 0.2, 0.0};
  // trailing edge (1, 0) goes DOWN for nose-up alpha, leading edge up; plunge h lifts both
  const auto te = rigid_position<double>({1.0, 0.0}, q, ea), le = rigid_position<double>({0.0, 0.0}, q, ea);
  EXPECT_NEAR(te[1], 0.1 - 0.6 * std::sin(0.2), 1e-15);
  EXPECT_NEAR(le[1], 0.1 + 0.4 * std::sin(0.2), 1e-15);
  EXPECT_NEAR(std::hypot(te[0] - le[0], te[1] - le[1]), 1.0, 1e-15);
  const auto e = rigid_position<double>(ea, q, ea);
  EXPECT_NEAR(e[0], 0.4, 1e-15);
  EXPECT_NEAR(e[1], 0.1, 1e-15);
  // pitch rate alone: the trailing edge moves down, the elastic axis does not move
  q.alpha_dot = 1.0;
  EXPECT_LT(rigid_speed<double>(te, q, ea)[1], 0.0);
  EXPECT_NEAR(rigid_speed<double>(e, q, ea)[1], 0.0, 1e-15);
  q.alpha_dot = 0.0;
  q.h_dot = 0.3;
  EXPECT_EQ(rigid_speed<double>(te, q, ea)[1], 0.3);
}

TEST(rigid_motion, free_stream_preserved_on_pitching_plunging_grid) {
  auto g = coarsen(naca_cgrid(), 4);
  for (auto& p : g.topology.patches)
    if (p.kind == boundary_kind::wall) p.kind = boundary_kind::far_field;
  euler_model<2> model(g, {.mach = 0.6, .alpha_rad = 0.03});
  multiblock_points<double, 2> pts, spd;
  rigid_grid_motion<double>(g.points, rigid_pose<double>{0.05, -0.3, 0.15, 0.8}, ea, pts, &spd);
  model.set_grid_motion(pts, &spd);
  const auto r = model.residual(model.free_stream_vector());
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-11);
  // not a test that cannot fail: on the real aerofoil (slip wall) the motion changes the residual
  euler_model<2> wall_model(coarsen(naca_cgrid(), 4), {.mach = 0.6, .alpha_rad = 0.0});
  const auto r0 = wall_model.residual(wall_model.free_stream_vector());
  wall_model.set_grid_motion(pts, &spd);
  const auto r1 = wall_model.residual(wall_model.free_stream_vector());
  EXPECT_GT((r1 - r0).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(rigid_motion, refuses_non_finite_pose_axis_and_inconsistent_rest_grid_before_writing) {
  const auto rest = coarsen(naca_cgrid(), 8).points;
  rigid_pose<double> q;
  q.alpha = 0.1;
  multiblock_points<double, 2> pts, spd;
  rigid_grid_motion<double>(rest, q, ea, pts, &spd);  // valid
  EXPECT_EQ(pts.blocks.size(), rest.blocks.size());
  // a NaN pose used to give a NaN grid without a word; nothing is written before the check
  multiblock_points<double, 2> out;
  q.alpha = std::nan("");
  EXPECT_THROW(rigid_grid_motion<double>(rest, q, ea, out, &spd), input_error);
  EXPECT_TRUE(out.blocks.empty());
  q.alpha = 0.1;
  q.h_dot = INFINITY;
  EXPECT_THROW(rigid_grid_motion<double>(rest, q, ea, out), input_error);
  q.h_dot = 0;
  EXPECT_THROW(rigid_grid_motion<double>(rest, q, {std::nan(""), 0.0}, out), input_error);
  // a jet pose: its value is checked
  using J = taylor<double, 1>;
  rigid_pose<J> qj;
  qj.alpha = J::variable(std::nan(""), 1.0);
  multiblock_points<J, 2> outj;
  EXPECT_THROW(rigid_grid_motion<J>(rest, qj, ea, outj), input_error);
  // a rest block whose point list does not match its dimensions
  auto broken = rest;
  broken.blocks[0].x.pop_back();
  EXPECT_THROW(rigid_grid_motion<double>(broken, q, ea, out), input_error);
  EXPECT_TRUE(out.blocks.empty());
}
