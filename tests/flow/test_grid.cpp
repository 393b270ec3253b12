// Grids and metrics: the NACA C-grid generator (sizes, geometry, wall orthogonality, positive
// volumes on all four levels), closed control volumes, total volume of a perturbed box against
// its exact volume, and the geometric conservation law (sum of face speeds = dV/dt computed
// independently by a central difference of volumes and by a taylor<> pass); split_block against
// the residual of the uncut grid.
#include <gtest/gtest.h>

#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/flow/metrics.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/scalar/taylor.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>
#include "support/error_messages.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using namespace aerohopf::flow;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;

namespace {

template <int Dim>
multiblock_points<double, Dim> perturbed_box(std::mt19937& rng, index_d<Dim> n, double amp) {
  std::uniform_real_distribution<double> u(-amp, amp);
  multiblock_points<double, Dim> g;
  grid_block<double, Dim> b;
  b.points = n;
  b.x.resize(b.n_points());
  for (std::size_t k = 0; k < b.x.size(); ++k) {
    const auto i = unravel<Dim>(k, n);
    bool boundary = false;
    for (int d = 0; d < Dim; ++d) boundary |= (i[d] == 0 || i[d] == n[d] - 1);
    for (int d = 0; d < Dim; ++d) b.x[k][d] = double(i[d]) / (n[d] - 1) * (1.0 + d) + (boundary ? 0.0 : u(rng));
  }
  g.blocks.push_back(b);
  return g;
}

template <class S, int Dim>
double max_closure_error(const grid_metrics<S, Dim>& m) {
  double worst = 0.0;
  for (const auto& b : m.blocks) {
    for (std::size_t k = 0; k < b.volume.size(); ++k) {
      const auto c = unravel<Dim>(k, b.cells);
      double scale = 0.0;
      std::array<double, Dim> sum{};
      for (int d = 0; d < Dim; ++d)
        for (int side = 0; side < 2; ++side) {
          auto p = c;
          p[d] += side;
          const auto& s = b.normal[d][linear_index<Dim>(p, b.face_dims(d))];
          for (int e = 0; e < Dim; ++e) {
            sum[e] += (side ? 1.0 : -1.0) * to_double(s[e]);
            scale = std::max(scale, std::abs(to_double(s[e])));
          }
        }
      for (int e = 0; e < Dim; ++e) worst = std::max(worst, std::abs(sum[e]) / scale);
    }
  }
  return worst;
}

}  // namespace

TEST(naca_cgrid, fine_grid_sizes_geometry_and_levels) {
  const auto fine = naca_cgrid();
  ASSERT_EQ(fine.points.blocks.size(), 3u);
  EXPECT_EQ(fine.topology.cells[0], (index_d<2>{32, 64}));
  EXPECT_EQ(fine.topology.cells[1], (index_d<2>{192, 64}));
  EXPECT_EQ(fine.topology.cells[2], (index_d<2>{32, 64}));
  int around = 1;
  for (const auto& c : fine.topology.cells) around += c[0];
  EXPECT_EQ(around, 257);

  const auto& af = fine.points.blocks[1];
  // Trailing edge at (1, 0) on both ends of the aerofoil block; wall points on the NACA 0012
  // thickness distribution (closed trailing edge coefficient).
  EXPECT_NEAR(af.at({0, 0})[0], 1.0, 1e-14);
  EXPECT_NEAR(af.at({0, 0})[1], 0.0, 1e-14);
  EXPECT_NEAR(af.at({192, 0})[0], 1.0, 1e-14);
  for (int i = 1; i < 192; ++i) {
    const double x = af.at({i, 0})[0], y = af.at({i, 0})[1];
    const double yt = 0.6 * (0.2969 * std::sqrt(x) - 0.126 * x - 0.3516 * x * x + 0.2843 * x * x * x -
                             0.1036 * x * x * x * x);
    EXPECT_NEAR(std::abs(y), yt, 1e-6) << "wall point " << i;
    EXPECT_EQ(y < 0, i < 96) << "lower surface first, wall point " << i;
  }
  // First cell height 0.01 and orthogonality at the wall away from the trailing edge.
  for (int i = 8; i <= 184; ++i) {
    const auto& a = af.at({i - 1, 0});
    const auto& b = af.at({i + 1, 0});
    const auto& p = af.at({i, 0});
    const auto& q = af.at({i, 1});
    const double tx = b[0] - a[0], ty = b[1] - a[1], nx = q[0] - p[0], ny = q[1] - p[1];
    EXPECT_NEAR(std::hypot(nx, ny), 0.01, 1e-4);
    const double cosang = (tx * nx + ty * ny) / std::hypot(tx, ty) / std::hypot(nx, ny);
    EXPECT_LT(std::abs(cosang), std::cos(80.0 * M_PI / 180.0)) << "wall point " << i;
  }
  // Far field about 15 chords away; outflow plane at x = 16.
  double rmin = 1e9;
  for (const auto& b : fine.points.blocks)
    for (int i = 0; i < b.points[0]; ++i) {
      const auto& x = b.at({i, b.points[1] - 1});
      rmin = std::min(rmin, std::hypot(x[0] - 0.5, x[1]));
    }
  EXPECT_GT(rmin, 14.0);
  EXPECT_NEAR(fine.points.blocks[0].at({0, 0})[0], 16.0, 1e-12);
  // Wake cut: lower wake point i coincides with upper wake point (n - i).
  const auto& lw = fine.points.blocks[0];
  const auto& uw = fine.points.blocks[2];
  for (int i = 0; i <= 32; ++i) {
    EXPECT_EQ(lw.at({i, 0})[0], uw.at({32 - i, 0})[0]);
    EXPECT_EQ(lw.at({i, 0})[1], uw.at({32 - i, 0})[1]);
  }
  // Block faces at the trailing edge are point-matched.
  for (int j = 0; j <= 64; ++j) {
    EXPECT_EQ(lw.at({32, j}), af.at({0, j}));
    EXPECT_EQ(af.at({192, j}), uw.at({0, j}));
  }

  for (int m : {1, 2, 4, 8}) {
    const auto g = coarsen(fine, m);
    EXPECT_EQ(g.points.blocks[1].points[0], 192 / m + 1);
    EXPECT_EQ(g.points.blocks[1].points[1], 64 / m + 1);
    const auto met = compute_metrics<double, 2>(g.points);  // throws on a non-positive volume
    double vmin = 1e300;
    for (const auto& b : met.blocks)
      for (double v : b.volume) vmin = std::min(vmin, v);
    EXPECT_GT(vmin, 0.0) << "level " << m;
    EXPECT_LT(max_closure_error(met), 1e-13) << "level " << m;
  }
  EXPECT_THROW(coarsen(fine, 3), input_error);
}

TEST(metrics, perturbed_box_volume_and_closure_2d_3d) {
  std::mt19937 rng(7);
  {
    const auto g = perturbed_box<2>(rng, {9, 7}, 0.03);
    const auto m = compute_metrics<double, 2>(g);
    double total = 0.0;
    for (double v : m.blocks[0].volume) total += v;
    EXPECT_NEAR(total, 1.0 * 2.0, 1e-14);
    EXPECT_LT(max_closure_error(m), 1e-14);
  }
  {
    const auto g = perturbed_box<3>(rng, {6, 5, 4}, 0.03);
    const auto m = compute_metrics<double, 3>(g);
    double total = 0.0;
    for (double v : m.blocks[0].volume) total += v;
    EXPECT_NEAR(total, 1.0 * 2.0 * 3.0, 1e-13);
    EXPECT_LT(max_closure_error(m), 1e-14);
  }
}

TEST(metrics, negative_volume_names_block_and_cell) {
  std::mt19937 rng(3);
  auto g = perturbed_box<2>(rng, {5, 5}, 0.0);
  g.blocks.push_back(g.blocks[0]);
  std::swap(g.blocks[1].at({2, 2}), g.blocks[1].at({3, 3}));  // folds cells around (2,2)
  try {
    (void)compute_metrics<double, 2>(g);
    FAIL() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("block 1 cell ("), std::string::npos) << e.what();
  }
}

// GCL in 2D: sum of face speeds equals dV/dt for an arbitrary deformation. The cell area is
// quadratic in the points, so a central difference of volumes is exact to rounding; a
// taylor<double, 1> evaluation of the volumes gives the same derivative independently.
TEST(metrics, geometric_conservation_law_2d) {
  std::mt19937 rng(11);
  const auto g = perturbed_box<2>(rng, {8, 6}, 0.04);
  auto v = g;
  std::normal_distribution<double> n01;
  for (auto& x : v.blocks[0].x) x = {n01(rng), n01(rng)};
  const double h = 1e-3;
  auto gp = g, gm = g;
  for (std::size_t k = 0; k < g.blocks[0].x.size(); ++k)
    for (int d = 0; d < 2; ++d) {
      gp.blocks[0].x[k][d] += h * v.blocks[0].x[k][d];
      gm.blocks[0].x[k][d] -= h * v.blocks[0].x[k][d];
    }
  const auto m = compute_metrics<double, 2>(g, &v);
  const auto mp = compute_metrics<double, 2>(gp), mm = compute_metrics<double, 2>(gm);
  using jet = taylor<double, 1>;
  auto gj = convert_points<jet>(g);
  for (std::size_t k = 0; k < g.blocks[0].x.size(); ++k)
    for (int d = 0; d < 2; ++d) gj.blocks[0].x[k][d] = jet::variable(g.blocks[0].x[k][d], v.blocks[0].x[k][d]);
  const auto mj = compute_metrics<jet, 2>(gj);
  const auto& b = m.blocks[0];
  for (std::size_t k = 0; k < b.volume.size(); ++k) {
    const auto c = unravel<2>(k, b.cells);
    double sum_q = 0.0;
    for (int d = 0; d < 2; ++d) {
      auto p = c;
      sum_q -= b.speed[d][linear_index<2>(p, b.face_dims(d))];
      p[d] += 1;
      sum_q += b.speed[d][linear_index<2>(p, b.face_dims(d))];
    }
    const double dvdt_fd = (mp.blocks[0].volume[k] - mm.blocks[0].volume[k]) / (2 * h);
    EXPECT_NEAR(sum_q, dvdt_fd, 1e-10) << "cell " << k;
    EXPECT_NEAR(sum_q, mj.blocks[0].volume[k][1], 1e-14) << "cell " << k;
  }
}

// GCL in 3D for a rigid motion (rotation + translation): volumes do not change, so the sum of
// face speeds must vanish in every cell.
TEST(metrics, rigid_motion_face_speeds_sum_to_zero_3d) {
  std::mt19937 rng(5);
  const auto g = perturbed_box<3>(rng, {5, 4, 6}, 0.05);
  auto v = g;
  const std::array<double, 3> omega{0.3, -0.7, 0.5}, vel{0.1, 0.2, -0.4};
  for (std::size_t k = 0; k < g.blocks[0].x.size(); ++k) {
    const auto& x = g.blocks[0].x[k];
    v.blocks[0].x[k] = {vel[0] + omega[1] * x[2] - omega[2] * x[1], vel[1] + omega[2] * x[0] - omega[0] * x[2],
                        vel[2] + omega[0] * x[1] - omega[1] * x[0]};
  }
  const auto m = compute_metrics<double, 3>(g, &v);
  const auto& b = m.blocks[0];
  for (std::size_t k = 0; k < b.volume.size(); ++k) {
    const auto c = unravel<3>(k, b.cells);
    double sum_q = 0.0, scale = 0.0;
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        auto p = c;
        p[d] += side;
        const double q = b.speed[d][linear_index<3>(p, b.face_dims(d))];
        sum_q += side ? q : -q;
        scale = std::max(scale, std::abs(q));
      }
    EXPECT_LT(std::abs(sum_q), 1e-14 * std::max(scale, 1.0)) << "cell " << k;
  }
}

// GCL in 3D for an arbitrary deformation: d/dt of the (trilinear, exact) cell volume, taken
// by a taylor<double, 1> pass through the metrics, equals the sum of the face speeds.
TEST(metrics, geometric_conservation_law_3d_deforming) {
  std::mt19937 rng(9);
  const auto g = perturbed_box<3>(rng, {5, 4, 4}, 0.06);
  auto v = g;
  std::normal_distribution<double> n01;
  for (auto& x : v.blocks[0].x) x = {n01(rng), n01(rng), n01(rng)};
  const auto m = compute_metrics<double, 3>(g, &v);
  using jet = taylor<double, 1>;
  auto gj = convert_points<jet>(g);
  for (std::size_t k = 0; k < g.blocks[0].x.size(); ++k)
    for (int d = 0; d < 3; ++d) gj.blocks[0].x[k][d] = jet::variable(g.blocks[0].x[k][d], v.blocks[0].x[k][d]);
  const auto mj = compute_metrics<jet, 3>(gj);
  const auto& b = m.blocks[0];
  for (std::size_t k = 0; k < b.volume.size(); ++k) {
    const auto c = unravel<3>(k, b.cells);
    double sum_q = 0.0;
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        auto p = c;
        p[d] += side;
        const double q = b.speed[d][linear_index<3>(p, b.face_dims(d))];
        sum_q += side ? q : -q;
      }
    EXPECT_NEAR(sum_q, mj.blocks[0].volume[k][1], 1e-13) << "cell " << k;
    EXPECT_NEAR(b.volume[k], mj.blocks[0].volume[k][0], 1e-15);
  }
}

// split_block: the residual on the grid with one block cut in two equals the original one cell
// by cell (original_cell) at a random state, for cuts across interfaces, walls and far field:
// the C-grid's aerofoil block along i (its ends are interfaces with the wake blocks) and along
// j, a wake block along i (the wake cut, an interface with the other wake block with i
// reversed, straddles the cut), and the tiny AGARD C-H grid (one block whose wake cut and
// beyond-tip cut are interfaces with itself, i reversed) along i and along k, twice in a row.
namespace {

template <int Dim>
void expect_same_residual(const multiblock_grid<Dim>& g, const split_grid<Dim>& s, const free_stream& fs) {
  constexpr int nv = Dim + 2;
  const euler_model<Dim> whole(g, fs), cut(s.grid, fs);
  ASSERT_EQ(cut.n_cells(), whole.n_cells());
  ASSERT_EQ(s.original_cell.size(), whole.n_cells());
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  vec<double> w = whole.free_stream_vector();
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  vec<double> wc(w.size());
  for (std::size_t c = 0; c < s.original_cell.size(); ++c)
    wc.segment(static_cast<Eigen::Index>(c * nv), nv) = w.segment(static_cast<Eigen::Index>(s.original_cell[c] * nv), nv);
  const vec<double> r = whole.residual(w), rc = cut.residual(wc);
  double worst = 0;
  for (std::size_t c = 0; c < s.original_cell.size(); ++c)
    for (int v = 0; v < nv; ++v)
      worst = std::max(worst, std::abs(rc[static_cast<Eigen::Index>(c * nv + v)] -
                                       r[static_cast<Eigen::Index>(s.original_cell[c] * nv + v)]));
  EXPECT_LE(worst, 1e-13 * r.cwiseAbs().maxCoeff());
  // every block's points are the box of the input's points at its origin
  if (s.origin.empty()) return;
  ASSERT_EQ(s.origin.size(), s.grid.points.blocks.size());
  for (std::size_t b = 0; b < s.origin.size(); ++b) {
    const auto& blk = s.grid.points.blocks[b];
    const auto& src = g.points.blocks.at(static_cast<std::size_t>(s.origin[b].block));
    for (std::size_t k = 0; k < blk.n_points(); ++k) {
      auto i = unravel<Dim>(k, blk.points);
      for (int d = 0; d < Dim; ++d) i[d] += s.origin[b].offset[d];
      ASSERT_EQ(blk.x[k], src.at(i)) << "block " << b << " point " << k;
    }
  }
}

}  // namespace

TEST(split_block, residual_is_unchanged_by_cuts_2d) {
  const auto g = coarsen(naca_cgrid(), 8);
  const free_stream fs{.mach = 0.8, .alpha_rad = 0.03};
  const auto& n = g.topology.cells;
  for (const auto& [b, axis] : std::vector<std::pair<int, int>>{{1, 0}, {1, 1}, {0, 0}, {2, 0}}) {
    SCOPED_TRACE(testing::Message() << "block " << b << " axis " << axis);
    const auto s = split_block(g, b, axis, n[b][axis] / 2);
    EXPECT_EQ(s.grid.topology.cells.size(), 4u);
    expect_same_residual<2>(g, s, fs);
  }
}

TEST(split_block, residual_is_unchanged_by_cuts_of_a_self_connected_wing_block_3d) {
  const auto g = wing_cgrid(test_support::agard(), test_support::tiny_wing_options());
  const free_stream fs{.mach = 0.9, .alpha_rad = 0.02};
  const auto& n = g.topology.cells[0];
  for (const int axis : {0, 2}) {
    SCOPED_TRACE(testing::Message() << "axis " << axis);
    const auto s = split_block(g, 0, axis, n[axis] / 2);
    expect_same_residual<3>(g, s, fs);
    // and the upper piece once more, along the other axis: original_cell composes
    const int other = axis == 0 ? 2 : 0;
    const auto s2 = split_block(s.grid, 1, other, s.grid.topology.cells[1][other] / 2);
    split_grid<3> both{s2.grid, {}, compose_origins(s.origin, s2.origin)};
    for (const std::size_t c : s2.original_cell) both.original_cell.push_back(s.original_cell[c]);
    expect_same_residual<3>(g, both, fs);
  }
}

TEST(split_block, bad_cuts_are_refused) {
  const auto g = coarsen(naca_cgrid(), 8);
  EXPECT_TRUE(contains(input_error_of([&] { split_block(g, 3, 0, 4); }), "block 3 of 3"));
  EXPECT_TRUE(contains(input_error_of([&] { split_block(g, 0, 2, 4); }), "axis 2"));
  EXPECT_TRUE(contains(input_error_of([&] { split_block(g, 0, 0, 1); }), "at least 2"));
  EXPECT_TRUE(contains(input_error_of([&] { split_block(g, 0, 0, g.topology.cells[0][0] - 1); }), "at least 2"));
}
