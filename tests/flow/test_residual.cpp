// Euler residual: free-stream preservation on deformed, moving multi-block grids (2D C-grid
// topology with wake cut, 3D two-block box); uniform flow along a moving slip wall; a block
// split with a reversed interface gives the same residual as the single block; double, dd_real
// and taylor<> evaluations agree; set_free_stream gives the bits of a model built with that free
// stream (residuals, Jacobians) without rebuilding grid, metrics or halos, and refuses bad input.
#include <gtest/gtest.h>

#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/flow/jacobian.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/scalar.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;
using namespace aerohopf::flow;

namespace {

template <int Dim>
grid_block<double, Dim> box_block(index_d<Dim> cells, std::mt19937& rng, double amp, std::array<double, Dim> x0) {
  std::uniform_real_distribution<double> u(-amp, amp);
  grid_block<double, Dim> b;
  for (int d = 0; d < Dim; ++d) b.points[d] = cells[d] + 1;
  b.x.resize(b.n_points());
  for (std::size_t k = 0; k < b.x.size(); ++k) {
    const auto i = unravel<Dim>(k, b.points);
    for (int d = 0; d < Dim; ++d) b.x[k][d] = x0[d] + 0.2 * i[d] + 0.02 * i[(d + 1) % Dim] + u(rng);
  }
  return b;
}

template <int Dim>
multiblock_points<double, Dim> random_velocities(const multiblock_points<double, Dim>& g, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  auto v = g;
  for (auto& b : v.blocks)
    for (auto& x : b.x)
      for (auto& c : x) c = 0.3 * n01(rng);
  return v;
}

template <int Dim>
double max_abs(const vec<double>& r) {
  return r.cwiseAbs().maxCoeff();
}

}  // namespace

// The real C-grid topology (3 blocks, trailing-edge interfaces, reversed wake cut) with the wall
// replaced by a far field, random grid deformation speeds and a pitching/plunging motion.
TEST(euler_residual, free_stream_preserved_on_moving_c_grid) {
  auto g = coarsen(naca_cgrid(), 4);
  for (auto& p : g.topology.patches)
    if (p.kind == boundary_kind::wall) p.kind = boundary_kind::far_field;
  std::mt19937 rng(1);
  euler_model<2> model(g, {.mach = 0.7, .alpha_rad = 0.05});
  const auto vel = random_velocities<2>(g.points, rng);
  model.set_grid_motion(g.points, &vel);
  const auto w = model.free_stream_vector();
  const auto r = model.residual(w);
  EXPECT_LT(max_abs<2>(r), 1e-11);
  // a residual that is not identically zero when the state is not uniform
  auto w2 = w;
  w2[17] *= 1.01;
  EXPECT_GT(max_abs<2>(model.residual(w2)), 1e-4);
}

TEST(euler_residual, free_stream_preserved_on_moving_3d_two_block_grid) {
  std::mt19937 rng(2);
  multiblock_grid<3> g;
  g.points.blocks.push_back(box_block<3>({4, 3, 3}, rng, 0.0, {0, 0, 0}));
  g.points.blocks.push_back(box_block<3>({3, 3, 3}, rng, 0.0, {0.8, 0.06, 0}));
  // perturb interior points only, then make the interface points coincide
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (auto& b : g.points.blocks)
    for (std::size_t k = 0; k < b.x.size(); ++k) {
      const auto i = unravel<3>(k, b.points);
      for (int d = 0; d < 3; ++d) b.x[k][d] += u(rng) * (i[0] > 0 && i[0] < b.points[0] - 1);
    }
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) g.points.blocks[1].at({0, j, k}) = g.points.blocks[0].at({4, j, k});
  g.topology.cells = {g.points.blocks[0].cells(), g.points.blocks[1].cells()};
  auto& pt = g.topology.patches;
  for (int b = 0; b < 2; ++b)
    for (int f = 0; f < 6; ++f) {
      if ((b == 0 && f == 1) || (b == 1 && f == 0)) continue;
      pt.push_back(whole_face<3>(b, f, g.topology.cells[b], boundary_kind::far_field));
    }
  for (int b = 0; b < 2; ++b) {
    auto p = whole_face<3>(b, b == 0 ? 1 : 0, g.topology.cells[b], boundary_kind::interface);
    p.donor_block = 1 - b;
    p.donor_face = b == 0 ? 0 : 1;
    p.donor_end = g.topology.cells[1 - b];
    p.transform = {0, 2, 3};
    pt.push_back(p);
  }
  euler_model<3> model(g, {.mach = 0.8, .alpha_rad = 0.1, .beta_rad = 0.05});
  const auto vel = random_velocities<3>(g.points, rng);
  model.set_grid_motion(g.points, &vel);
  EXPECT_LT(max_abs<3>(model.residual(model.free_stream_vector())), 1e-11);
}

// A translating grid (velocity (0, vy)) with a flat wall y = 0 and flow (U cos a, vy): the
// uniform flow is tangent to the moving wall in the wall frame, hence an exact solution.
TEST(euler_residual, uniform_flow_along_moving_wall) {
  std::mt19937 rng(4);
  multiblock_grid<2> g;
  auto b = box_block<2>({6, 5}, rng, 0.0, {0, 0});
  for (auto& x : b.x) x[1] = std::abs(x[1] - 0.02 * (x[0] / 0.2)) + 0.0;  // y = 0 along j = 0
  for (int i = 0; i <= 6; ++i) b.at({i, 0})[1] = 0.0;
  g.points.blocks.push_back(b);
  g.topology.cells = {b.cells()};
  for (int f = 0; f < 4; ++f)
    g.topology.patches.push_back(whole_face<2>(0, f, b.cells(), f == 2 ? boundary_kind::wall : boundary_kind::far_field));
  const double alpha = 0.2;
  euler_model<2> model(g, {.mach = 0.6, .alpha_rad = alpha});
  auto vel = g.points;
  for (auto& x : vel.blocks[0].x) x = {0.3, std::sin(alpha)};  // tangential slip + normal motion
  model.set_grid_motion(g.points, &vel);
  EXPECT_LT(max_abs<2>(model.residual(model.free_stream_vector())), 1e-12);
  // the same flow is NOT a solution if the wall does not move with it
  euler_model<2> fixed(g, {.mach = 0.6, .alpha_rad = alpha});
  EXPECT_GT(max_abs<2>(fixed.residual(fixed.free_stream_vector())), 1e-2);
}

// One block against the same cells split into two blocks, the second stored with both index
// axes reversed (interface transform -1, like the wake cut): identical residuals.
TEST(euler_residual, split_block_with_reversed_interface_matches_single_block) {
  std::mt19937 rng(6);
  const index_d<2> n{8, 5};
  auto whole = box_block<2>(n, rng, 0.03, {0, 0});
  for (int i = 0; i <= 8; ++i) whole.at({i, 0})[1] = 0.005 * i * (8 - i);  // curved wall
  multiblock_grid<2> g1;
  g1.points.blocks.push_back(whole);
  g1.topology.cells = {n};
  for (int f = 0; f < 4; ++f)
    g1.topology.patches.push_back(whole_face<2>(0, f, n, f == 2 ? boundary_kind::wall : boundary_kind::far_field));

  multiblock_grid<2> g2;
  grid_block<double, 2> a, b;
  a.points = {4, 6};  // cells i = 0..2
  b.points = {6, 6};  // cells i = 3..7 stored reversed in i and j
  a.x.resize(a.n_points());
  b.x.resize(b.n_points());
  for (int j = 0; j <= 5; ++j) {
    for (int i = 0; i <= 3; ++i) a.at({i, j}) = whole.at({i, j});
    for (int i = 0; i <= 5; ++i) b.at({i, j}) = whole.at({8 - i, 5 - j});
  }
  // b is mirrored in both axes: still right-handed.
  g2.points.blocks = {a, b};
  g2.topology.cells = {a.cells(), b.cells()};
  auto& pt = g2.topology.patches;
  pt.push_back(whole_face<2>(0, 0, a.cells(), boundary_kind::far_field));
  pt.push_back(whole_face<2>(0, 2, a.cells(), boundary_kind::wall));
  pt.push_back(whole_face<2>(0, 3, a.cells(), boundary_kind::far_field));
  pt.push_back(whole_face<2>(1, 0, b.cells(), boundary_kind::far_field));  // original i-max
  pt.push_back(whole_face<2>(1, 3, b.cells(), boundary_kind::wall));       // original j = 0
  pt.push_back(whole_face<2>(1, 2, b.cells(), boundary_kind::far_field));
  auto ia = whole_face<2>(0, 1, a.cells(), boundary_kind::interface);
  ia.donor_block = 1;
  ia.donor_face = 1;
  ia.donor_end = b.cells();
  ia.transform = {0, -2};
  pt.push_back(ia);
  auto ib = whole_face<2>(1, 1, b.cells(), boundary_kind::interface);
  ib.donor_block = 0;
  ib.donor_face = 1;
  ib.donor_end = a.cells();
  ib.transform = {0, -2};
  pt.push_back(ib);

  const free_stream fs{.mach = 0.75, .alpha_rad = 0.03};
  euler_model<2> m1(g1, fs), m2(g2, fs);
  // smooth non-uniform state, mapped between the two cell orderings
  vec<double> w1(m1.size()), w2(m2.size());
  const auto winf = fs.conservative_state<double, 2>();
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 8; ++i) {
      const std::size_t c1 = linear_index<2>({i, j}, n);
      const std::size_t c2 = i < 3 ? linear_index<2>({i, j}, a.cells())
                                   : m2.cell_offset(1) + linear_index<2>({8 - 1 - i - 0, 5 - 1 - j}, b.cells());
      for (int v = 0; v < 4; ++v) {
        const double val = winf[v] * (1.0 + 0.05 * std::sin(0.7 * i + 0.3 * v) * std::cos(0.9 * j));
        w1[static_cast<Eigen::Index>(c1 * 4 + v)] = val;
        w2[static_cast<Eigen::Index>(c2 * 4 + v)] = val;
      }
    }
  const auto r1 = m1.residual(w1), r2 = m2.residual(w2);
  double scale = r1.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1e-3);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 8; ++i) {
      const std::size_t c1 = linear_index<2>({i, j}, n);
      const std::size_t c2 = i < 3 ? linear_index<2>({i, j}, a.cells())
                                   : m2.cell_offset(1) + linear_index<2>({7 - i, 4 - j}, b.cells());
      for (int v = 0; v < 4; ++v)
        EXPECT_NEAR(r1[static_cast<Eigen::Index>(c1 * 4 + v)], r2[static_cast<Eigen::Index>(c2 * 4 + v)], 1e-12 * scale)
            << "cell " << i << "," << j << " var " << v;
    }
}

TEST(euler_residual, double_dd_and_taylor_agree) {
  const auto g = coarsen(naca_cgrid(), 8);
  euler_model<2> model(g, {.mach = 0.8, .alpha_rad = 0.02});
  auto w = model.free_stream_vector();
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  const auto r = model.residual(w);
  vec<dd_real> wd(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) wd[k] = dd_real(w[k]);
  const auto rd = model.residual(wd);
  using jet = taylor<double, 2>;
  vec<jet> wj(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) wj[k] = jet::variable(w[k], 0.0);
  const auto rj = model.residual(wj);
  const double scale = r.cwiseAbs().maxCoeff();
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    EXPECT_NEAR(to_double(rd[k]), r[k], 1e-12 * scale);
    EXPECT_EQ(rj[k][0], r[k]);
    EXPECT_EQ(rj[k][1], 0.0);
  }
}

// The residual on a grid that is itself a taylor<> jet (points and point speeds moved by a
// structural-like parameter t): the t-derivative equals a central difference of residuals on
// displaced grids, and qd_real runs through the same code.
TEST(euler_residual, jet_grid_motion_matches_finite_differences) {
  const auto g = coarsen(naca_cgrid(), 8);
  euler_model<2> m(g, {.mach = 0.75, .alpha_rad = 0.02});
  auto w = m.free_stream_vector();
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  // pitch about the quarter chord: displacement direction dx and a pitch-rate change dv
  auto dx = g.points, dv = g.points;
  for (std::size_t b = 0; b < g.points.blocks.size(); ++b)
    for (std::size_t k = 0; k < g.points.blocks[b].x.size(); ++k) {
      const auto& x = g.points.blocks[b].x[k];
      dx.blocks[b].x[k] = {x[1], -(x[0] - 0.25)};
      dv.blocks[b].x[k] = {0.3 * x[1], -0.3 * (x[0] - 0.25) + 0.1};
    }
  auto moved = [&](double t) {
    auto p = g.points, v = g.points;
    for (std::size_t b = 0; b < p.blocks.size(); ++b)
      for (std::size_t k = 0; k < p.blocks[b].x.size(); ++k)
        for (int d = 0; d < 2; ++d) {
          p.blocks[b].x[k][d] += t * dx.blocks[b].x[k][d];
          v.blocks[b].x[k][d] = t * dv.blocks[b].x[k][d];
        }
    euler_model<2> mt = m;
    mt.set_grid_motion(p, &v);
    return mt.residual(w);
  };
  using jet = taylor<double, 1>;
  auto pj = convert_points<jet>(g.points), vj = convert_points<jet>(g.points);
  for (std::size_t b = 0; b < pj.blocks.size(); ++b)
    for (std::size_t k = 0; k < pj.blocks[b].x.size(); ++k)
      for (int d = 0; d < 2; ++d) {
        pj.blocks[b].x[k][d] = jet::variable(g.points.blocks[b].x[k][d], dx.blocks[b].x[k][d]);
        vj.blocks[b].x[k][d] = jet::variable(0.0, dv.blocks[b].x[k][d]);
      }
  vec<jet> wj(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) wj[k] = jet(w[k]);
  const auto rj = m.residual(compute_metrics<jet, 2>(pj, &vj), wj);
  const double h = 1e-5;
  const vec<double> fd = (moved(h) - moved(-h)) / (2 * h);
  vec<double> dj(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) dj[k] = rj[k][1];
  ASSERT_GT(fd.norm(), 1e-3);
  EXPECT_LT((dj - fd).norm(), 1e-7 * fd.norm());

  vec<qd_real> wq(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) wq[k] = qd_real(w[k]);
  const auto rq = m.residual(wq);
  const auto r = m.residual(w);
  for (Eigen::Index k = 0; k < w.size(); ++k) EXPECT_NEAR(to_double(rq[k]), r[k], 1e-12 * r.cwiseAbs().maxCoeff());
}

// ---- hostile input: every public entry point that takes a state checks it -----------------

namespace {

euler_model<2> small_cgrid_model() { return euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.8, .alpha_rad = 0.02}); }

template <class T>
vec<T> converted(const vec<double>& w) {
  vec<T> r(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) r[k] = T(w[k]);
  return r;
}


}  // namespace

// One cell short (the old code read past the end of w), one cell long (silently ignored) and
// empty (null data): refused by every overload and entry point, in every scalar, with a
// message giving both sizes.
TEST(euler_residual, wrong_size_state_is_refused_by_every_entry_point) {
  const auto m = small_cgrid_model();
  const vec<double> w = m.free_stream_vector();
  const vec<double> shorter = w.head(w.size() - 4);
  vec<double> longer(w.size() + 4);
  longer << w, w.head(4);
  const vec<double> empty;
  const std::string expected = "expected " + std::to_string(m.size());
  for (const vec<double>* bad : std::initializer_list<const vec<double>*>{&shorter, &longer, &empty}) {
    SCOPED_TRACE(bad->size());
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(*bad); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(m.metrics(), *bad); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(converted<dd_real>(*bad)); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(converted<qd_real>(*bad)); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(converted<taylor<double, 1>>(*bad)); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.spectral_radius(*bad); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.forces(*bad); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.wall_faces(*bad); }), expected));
    EXPECT_TRUE(contains(input_error_of([&] { (void)m.is_physical(*bad); }), expected));
  }
}

// Metrics whose arrays do not match their own cell counts (hand-made or truncated) are refused
// before the residual indexes them.
TEST(euler_residual, inconsistent_metrics_are_refused) {
  const auto m = small_cgrid_model();
  const vec<double> w = m.free_stream_vector();
  auto bad = m.metrics();
  bad.blocks[1].volume.pop_back();
  EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(bad, w); }), "block 1"));
  bad = m.metrics();
  bad.blocks[2].normal[1].pop_back();
  EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(bad, w); }), "block 2"));
  bad = m.metrics();
  bad.blocks[0].speed[0].clear();
  EXPECT_TRUE(contains(input_error_of([&] { (void)m.residual(bad, w); }), "block 0"));
}

// Fewer blocks than the model (the old code read the metrics past their end), a block of
// another shape, velocities of another block count or shape: refused, and the model is left
// exactly as it was.
TEST(euler_residual, set_grid_motion_refuses_mismatched_grids_and_keeps_the_model) {
  auto m = small_cgrid_model();
  vec<double> w = m.free_stream_vector();
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + 0.01 * std::sin(0.37 * double(k));
  const vec<double> r0 = m.residual(w);
  const auto full = m.grid().points;

  auto fewer = full;
  fewer.blocks.pop_back();
  EXPECT_TRUE(contains(input_error_of([&] { m.set_grid_motion(fewer, nullptr); }), "blocks"));
  EXPECT_TRUE(contains(input_error_of([&] { m.set_grid_motion(fewer, &fewer); }), "blocks"));
  EXPECT_TRUE(contains(input_error_of([&] { m.set_grid_motion(full, &fewer); }), "blocks"));

  auto reshaped = full;  // block 0 one point row shorter, still a valid grid block
  auto& b0 = reshaped.blocks[0];
  b0.points[1] -= 1;
  b0.x.resize(b0.n_points());
  EXPECT_THROW(m.set_grid_motion(reshaped, nullptr), input_error);
  EXPECT_THROW(m.set_grid_motion(full, &reshaped), input_error);

  EXPECT_EQ(m.grid().points.blocks.size(), full.blocks.size());
  const vec<double> r1 = m.residual(w);
  EXPECT_EQ((r1 - r0).cwiseAbs().maxCoeff(), 0.0);
}

// set_free_stream changes only the free stream: a model built at M = 0.6 and set to (M = 0.85,
// alpha = 0.02) gives the same bits as one built there (residuals in double and taylor<>,
// both Jacobians, forces, spectral radius), on the rest grid and on a moved one, and its grid,
// metrics and halos are the same objects (their storage is not reallocated: nothing rebuilt).
TEST(euler_residual, set_free_stream_in_place_equals_a_model_built_with_it) {
  const auto grid = coarsen(naca_cgrid(), 8);
  const free_stream target{.mach = 0.85, .alpha_rad = 0.02};
  euler_model<2> changed(grid, {.mach = 0.6, .alpha_rad = 0.0});
  const euler_model<2> built(grid, target);
  const auto* points = changed.grid().points.blocks[0].x.data();
  const auto* volumes = changed.metrics().blocks[1].volume.data();
  const auto* normals = changed.metrics().blocks[2].normal[0].data();
  const auto* halos = changed.halos().data();
  changed.set_free_stream(target);
  EXPECT_EQ(changed.conditions().mach, target.mach);
  EXPECT_EQ(changed.conditions().alpha_rad, target.alpha_rad);
  EXPECT_EQ(changed.grid().points.blocks[0].x.data(), points);
  EXPECT_EQ(changed.metrics().blocks[1].volume.data(), volumes);
  EXPECT_EQ(changed.metrics().blocks[2].normal[0].data(), normals);
  EXPECT_EQ(changed.halos().data(), halos);

  auto same_bits = [](const euler_model<2>& a, const euler_model<2>& b, const char* where) {
    SCOPED_TRACE(where);
    vec<double> w = b.free_stream_vector();
    EXPECT_EQ(a.free_stream_vector(), w);
    for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + 0.02 * std::sin(0.37 * double(k));
    EXPECT_EQ(a.residual(w), b.residual(w));
    using J = taylor<double, 1>;
    vec<J> wj(w.size());
    for (Eigen::Index k = 0; k < w.size(); ++k) wj[k] = J::variable(w[k], std::cos(0.11 * double(k)));
    const vec<J> ra = a.residual(wj), rb = b.residual(wj);
    for (Eigen::Index k = 0; k < w.size(); ++k) {
      ASSERT_EQ(ra[k][0], rb[k][0]) << k;
      ASSERT_EQ(ra[k][1], rb[k][1]) << k;
    }
    for (const auto kind : {jacobian_kind::exact, jacobian_kind::modified_order}) {
      block_sparse_matrix<double, 4> ja, jb;
      assemble_jacobian<2>(a, w, kind, ja);
      assemble_jacobian<2>(b, w, kind, jb);
      EXPECT_EQ(ja.col_index(), jb.col_index());
      EXPECT_EQ(ja.values(), jb.values());
    }
    const auto fa = a.forces(w), fb = b.forces(w);
    EXPECT_EQ(fa.cl, fb.cl);
    EXPECT_EQ(fa.cd, fb.cd);
    EXPECT_EQ(fa.cm, fb.cm);
    EXPECT_EQ(a.spectral_radius(w), b.spectral_radius(w));
  };
  same_bits(changed, built, "rest grid");
  // a moved grid (the aerofoil's Jacobian assembly moves a copy of the model)
  auto moved = grid.points;
  auto speeds = grid.points;
  for (auto& b : moved.blocks)
    for (auto& x : b.x) x = {x[0] * std::cos(0.01) - x[1] * std::sin(0.01), x[0] * std::sin(0.01) + x[1] * std::cos(0.01)};
  for (auto& b : speeds.blocks)
    for (auto& x : b.x) x = {-0.05 * x[1], 0.05 * x[0]};
  euler_model<2> moved_changed(grid, {.mach = 0.5});
  moved_changed.set_grid_motion(moved, &speeds);
  moved_changed.set_free_stream(target);
  euler_model<2> moved_built(grid, target);
  moved_built.set_grid_motion(moved, &speeds);
  same_bits(moved_changed, moved_built, "moved grid");
  // and back: the first free stream again gives the first model's bits
  changed.set_free_stream({.mach = 0.6, .alpha_rad = 0.0});
  same_bits(changed, euler_model<2>(grid, {.mach = 0.6, .alpha_rad = 0.0}), "set back");
}

// A Mach number that is not positive and finite, or a non-finite angle: refused by
// set_free_stream (naming it and the value) and by the constructor; the model keeps its free
// stream and gives the same residual bits.
TEST(euler_residual, set_free_stream_refuses_bad_conditions_and_keeps_the_model) {
  auto m = small_cgrid_model();
  const free_stream before = m.conditions();
  vec<double> w = m.free_stream_vector();
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + 0.01 * std::sin(0.37 * double(k));
  const vec<double> r0 = m.residual(w);
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  for (const double mach : {0.0, -0.5, nan, inf}) {
    SCOPED_TRACE(mach);
    EXPECT_TRUE(contains(input_error_of([&] { m.set_free_stream({.mach = mach}); }),
                         "euler_model::set_free_stream: Mach number"));
    EXPECT_THROW(euler_model<2>(m.grid(), {.mach = mach}), input_error);
  }
  EXPECT_TRUE(contains(input_error_of([&] { m.set_free_stream({.mach = 0.7, .alpha_rad = nan}); }), "angle of attack"));
  EXPECT_TRUE(contains(input_error_of([&] { m.set_free_stream({.mach = 0.7, .alpha_rad = 0.0, .beta_rad = inf}); }),
                       "angle of sideslip"));
  EXPECT_THROW(euler_model<2>(m.grid(), {.mach = 0.7, .alpha_rad = inf}), input_error);
  EXPECT_EQ(m.conditions().mach, before.mach);
  EXPECT_EQ(m.conditions().alpha_rad, before.alpha_rad);
  EXPECT_EQ(m.conditions().beta_rad, before.beta_rad);
  EXPECT_EQ(m.residual(w), r0);
}

// Negative density, negative pressure, NaN and Inf in one cell: refused by the residual in
// every scalar (judged on the value part), by the spectral radius and the forces, with the
// block, the cell (i,j), the density and the pressure in the message. A physical state passes.
TEST(euler_residual, non_physical_state_is_refused_naming_block_and_cell) {
  const auto m = small_cgrid_model();
  const vec<double> w0 = m.free_stream_vector();
  EXPECT_TRUE(m.is_physical(w0));
  const int b = 1;
  const index_d<2> ij{3, 2};
  const auto c = static_cast<Eigen::Index>(m.cell_offset(b) + linear_index<2>(ij, m.grid().topology.cells[b]));
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  struct defect {
    const char* name;
    int var;
    double value;
  };
  const double kinetic = 0.5 * (w0[4 * c + 1] * w0[4 * c + 1] + w0[4 * c + 2] * w0[4 * c + 2]) / w0[4 * c];
  for (const defect& d : {defect{"negative density", 0, -w0[4 * c]}, defect{"negative pressure", 3, 0.5 * kinetic},
                          defect{"NaN momentum", 1, nan}, defect{"NaN density", 0, nan},
                          defect{"infinite energy", 3, inf}}) {
    SCOPED_TRACE(d.name);
    vec<double> w = w0;
    w[4 * c + d.var] = d.value;
    EXPECT_FALSE(m.is_physical(w));
    for (const std::string& msg :
         {input_error_of([&] { (void)m.residual(w); }), input_error_of([&] { (void)m.residual(m.metrics(), w); }),
          input_error_of([&] { (void)m.residual(converted<dd_real>(w)); }),
          input_error_of([&] { (void)m.residual(converted<qd_real>(w)); }),
          input_error_of([&] { (void)m.residual(converted<taylor<double, 2>>(w)); }),
          input_error_of([&] { (void)m.spectral_radius(w); }), input_error_of([&] { (void)m.forces(w); })}) {
      EXPECT_TRUE(contains(msg, "block 1")) << msg;
      EXPECT_TRUE(contains(msg, "cell (3,2)")) << msg;
      EXPECT_TRUE(contains(msg, "density")) << msg;
      EXPECT_TRUE(contains(msg, "pressure")) << msg;
    }
  }
  // a taylor<> state whose derivative part is anything: only the value part is judged
  using jet = taylor<double, 1>;
  vec<jet> wj(w0.size());
  for (Eigen::Index k = 0; k < w0.size(); ++k) wj[k] = jet::variable(w0[k], k % 4 == 0 ? -1e3 : 0.0);
  EXPECT_NO_THROW((void)m.residual(wj));
}

// The raw-pointer residual (internal: the coupled aerofoil system passes its longer state) cannot
// check the size but still checks the physical state of the cells it reads.
TEST(euler_residual, raw_pointer_residual_checks_the_physical_state) {
  const auto m = small_cgrid_model();
  vec<double> w = m.free_stream_vector();
  vec<double> r(m.size());
  EXPECT_NO_THROW(m.residual<double>(m.metrics(), w.data(), r.data()));
  w[4 * 5] = -1.0;
  EXPECT_THROW(m.residual<double>(m.metrics(), w.data(), r.data()), input_error);
}
