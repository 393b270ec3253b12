// Exact and modified-order Jacobians: products with random vectors against the taylor<>
// directional derivative of the residual (independent: one jet pass through the whole
// residual, halos and all) on a moving C-grid (wall, far field, wake cut, block interfaces) and
// a 3D two-block grid; block counts per row (9/5 in 2D, 13/7 in 3D); modified order = exact
// Jacobian of the first-order scheme; the rows of selected blocks in a local numbering (one
// rank's part) against the whole Jacobian.
#include <gtest/gtest.h>

#include <aerohopf/flow/jacobian.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>
#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;
using namespace aerohopf::flow;

namespace {

template <int Dim>
vec<double> perturbed_state(const euler_model<Dim>& m, std::mt19937& rng, double amp) {
  auto w = m.free_stream_vector();
  std::uniform_real_distribution<double> u(-amp, amp);
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  return w;
}

template <int Dim>
vec<double> jet_derivative(const euler_model<Dim>& m, const vec<double>& w, const vec<double>& v) {
  using jet = taylor<double, 1>;
  vec<jet> wj(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) wj[k] = jet::variable(w[k], v[k]);
  const auto r = m.residual(wj);
  vec<double> d(w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) d[k] = r[k][1];
  return d;
}

template <int Dim>
void check_products(const euler_model<Dim>& m, const vec<double>& w, jacobian_kind kind, std::mt19937& rng) {
  block_sparse_matrix<double, Dim + 2> a;
  assemble_jacobian<Dim>(m, w, kind, a);
  std::normal_distribution<double> n01;
  for (int t = 0; t < 3; ++t) {
    vec<double> v(w.size());
    for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = n01(rng);
    vec<double> jv(w.size());
    a.apply(v, jv);
    const auto ref = jet_derivative<Dim>(m, w, v);
    const double rel = (jv - ref).norm() / ref.norm();
    EXPECT_LT(rel, 1e-10) << "trial " << t;
    EXPECT_LT((jv - ref).cwiseAbs().maxCoeff(), 1e-10 * ref.cwiseAbs().maxCoeff()) << "trial " << t;
  }
}

template <int Dim>
std::vector<int> blocks_per_row(const block_sparse_matrix<double, Dim + 2>& a) {
  std::vector<int> n(a.block_rows());
  for (Eigen::Index i = 0; i < a.block_rows(); ++i) n[i] = a.row_ptr()[i + 1] - a.row_ptr()[i];
  return n;
}

euler_model<2> moving_cgrid_model(int order) {
  const auto g = coarsen(naca_cgrid(), 4);
  euler_options opt;
  opt.order = order;
  euler_model<2> m(g, {.mach = 0.8, .alpha_rad = 0.03}, opt);
  // pitching about the quarter chord plus plunging: the wall and far field move
  auto vel = g.points;
  for (std::size_t b = 0; b < vel.blocks.size(); ++b)
    for (std::size_t k = 0; k < vel.blocks[b].x.size(); ++k) {
      const auto& x = g.points.blocks[b].x[k];
      vel.blocks[b].x[k] = {0.2 * x[1], -0.2 * (x[0] - 0.25) + 0.1};
    }
  m.set_grid_motion(g.points, &vel);
  return m;
}

}  // namespace

TEST(jacobian, exact_second_order_product_matches_jet_derivative_2d) {
  std::mt19937 rng(1);
  const auto m = moving_cgrid_model(2);
  const auto w = perturbed_state<2>(m, rng, 0.05);
  check_products<2>(m, w, jacobian_kind::exact, rng);
  block_sparse_matrix<double, 4> a;
  assemble_jacobian<2>(m, w, jacobian_kind::exact, a);
  const auto n = blocks_per_row<2>(a);
  EXPECT_EQ(*std::max_element(n.begin(), n.end()), 9);
  // a cell two cells away from every block boundary: exactly 9 blocks
  const std::size_t interior = m.cell_offset(1) + linear_index<2>({20, 8}, m.grid().topology.cells[1]);
  EXPECT_EQ(n[interior], 9);
  block_sparse_matrix<double, 4> b;
  assemble_jacobian<2>(m, w, jacobian_kind::modified_order, b);
  EXPECT_EQ(blocks_per_row<2>(b)[interior], 5);
}

TEST(jacobian, modified_order_is_exact_jacobian_of_first_order_scheme) {
  std::mt19937 rng(2);
  const auto m1 = moving_cgrid_model(1);
  const auto w = perturbed_state<2>(m1, rng, 0.05);
  check_products<2>(m1, w, jacobian_kind::modified_order, rng);
  // at first order the modified-order and exact assemblies are the same matrix
  block_sparse_matrix<double, 4> a, b;
  assemble_jacobian<2>(m1, w, jacobian_kind::modified_order, a);
  assemble_jacobian<2>(m1, w, jacobian_kind::exact, b);
  ASSERT_EQ(a.nonzero_blocks(), b.nonzero_blocks());
  double diff = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < a.values().size(); ++k) {
    diff = std::max(diff, std::abs(a.values()[k] - b.values()[k]));
    scale = std::max(scale, std::abs(b.values()[k]));
  }
  EXPECT_LT(diff, 1e-14 * scale);
  // the second-order model's modified-order Jacobian is NOT its exact Jacobian
  const auto m2 = moving_cgrid_model(2);
  block_sparse_matrix<double, 4> c;
  assemble_jacobian<2>(m2, w, jacobian_kind::modified_order, c);
  vec<double> v = vec<double>::Ones(w.size()), cv(w.size());
  c.apply(v, cv);
  EXPECT_GT((cv - jet_derivative<2>(m2, w, v)).norm(), 1e-3 * cv.norm());
}

TEST(jacobian, exact_product_matches_jet_derivative_3d) {
  std::mt19937 rng(3);
  multiblock_grid<3> g;
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (int b = 0; b < 2; ++b) {
    grid_block<double, 3> blk;
    blk.points = {7, 6, 6};
    blk.x.resize(blk.n_points());
    for (std::size_t k = 0; k < blk.x.size(); ++k) {
      const auto i = unravel<3>(k, blk.points);
      const int gi = i[0] + 6 * b;  // global i: the interface points coincide
      blk.x[k] = {0.2 * gi, 0.2 * i[1] + 0.01 * gi, 0.25 * i[2]};
      if (i[0] > 0 && i[0] < 6)
        for (auto& c : blk.x[k]) c += u(rng);
    }
    g.points.blocks.push_back(blk);
    g.topology.cells.push_back(blk.cells());
  }
  for (int b = 0; b < 2; ++b) {
    for (int f = 0; f < 6; ++f) {
      if ((b == 0 && f == 1) || (b == 1 && f == 0)) continue;
      g.topology.patches.push_back(whole_face<3>(b, f, g.topology.cells[b], f == 4 ? boundary_kind::wall : boundary_kind::far_field));
    }
    auto p = whole_face<3>(b, b == 0 ? 1 : 0, g.topology.cells[b], boundary_kind::interface);
    p.donor_block = 1 - b;
    p.donor_face = b == 0 ? 0 : 1;
    p.donor_end = g.topology.cells[1 - b];
    p.transform = {0, 2, 3};
    g.topology.patches.push_back(p);
  }
  euler_model<3> m(g, {.mach = 0.7, .alpha_rad = 0.05});
  auto vel = g.points;
  for (auto& b : vel.blocks)
    for (auto& x : b.x) x = {0.1 * x[2], 0.0, -0.1 * x[0] + 0.05};
  m.set_grid_motion(g.points, &vel);
  const auto w = perturbed_state<3>(m, rng, 0.05);
  check_products<3>(m, w, jacobian_kind::exact, rng);
  block_sparse_matrix<double, 5> a;
  assemble_jacobian<3>(m, w, jacobian_kind::exact, a);
  const auto n = blocks_per_row<3>(a);
  EXPECT_EQ(*std::max_element(n.begin(), n.end()), 13);
  block_sparse_matrix<double, 5> b;
  assemble_jacobian<3>(m, w, jacobian_kind::modified_order, b);
  const auto nb = blocks_per_row<3>(b);
  EXPECT_EQ(*std::max_element(nb.begin(), nb.end()), 7);
}

// ---- hostile input ---------------------------------------------------------------------------

namespace {

/// Unit-spaced 3D box, far field all round.
euler_model<3> box_model_3d(index_d<3> cells) {
  multiblock_grid<3> g;
  grid_block<double, 3> b;
  for (int d = 0; d < 3; ++d) b.points[d] = cells[d] + 1;
  b.x.resize(b.n_points());
  for (std::size_t k = 0; k < b.x.size(); ++k) {
    const auto i = unravel<3>(k, b.points);
    for (int d = 0; d < 3; ++d) b.x[k][d] = 0.25 * i[d] + 0.01 * i[(d + 1) % 3];
  }
  g.points.blocks.push_back(b);
  g.topology.cells = {cells};
  for (int f = 0; f < 6; ++f) g.topology.patches.push_back(whole_face<3>(0, f, cells, boundary_kind::far_field));
  return euler_model<3>(g, {.mach = 0.7, .alpha_rad = 0.05});
}


}  // namespace

// A state of the wrong size or with a non-physical cell is refused by both Jacobians (the
// old code assembled finite garbage from NaN sound speeds), and the matrix passed in is left
// untouched by the refusal.
TEST(jacobian, wrong_size_and_non_physical_states_are_refused) {
  std::mt19937 rng(31);
  const auto m = moving_cgrid_model(2);
  const vec<double> w = perturbed_state<2>(m, rng, 0.02);
  for (auto kind : {jacobian_kind::exact, jacobian_kind::modified_order}) {
    block_sparse_matrix<double, 4> a;
    assemble_jacobian<2>(m, w, kind, a);
    const std::vector<double> before = a.values();
    EXPECT_TRUE(contains(input_error_of([&] { assemble_jacobian<2>(m, vec<double>(w.head(w.size() - 4)), kind, a); }),
                         "expected " + std::to_string(m.size())));
    const int b = 2;
    const index_d<2> ij{1, 4};
    const auto c = static_cast<Eigen::Index>(m.cell_offset(b) + linear_index<2>(ij, m.grid().topology.cells[b]));
    vec<double> bad = w;
    bad[4 * c + 3] = 0.0;  // zero energy: negative pressure
    const std::string msg = input_error_of([&] { assemble_jacobian<2>(m, bad, kind, a); });
    for (const char* part : {"block 2", "cell (1,4)", "density", "pressure"}) EXPECT_TRUE(contains(msg, part)) << msg;
    EXPECT_TRUE(a.values() == before);
  }
}

// 3D: the cell is named by its three indices, in the residual and the Jacobian alike.
TEST(jacobian, non_physical_state_in_3d_names_the_three_cell_indices) {
  const auto m = box_model_3d({3, 4, 2});
  vec<double> w = m.free_stream_vector();
  const auto c = static_cast<Eigen::Index>(linear_index<3>({2, 1, 1}, {3, 4, 2}));
  w[5 * c] = -0.5;
  block_sparse_matrix<double, 5> a;
  for (const std::string& msg : {input_error_of([&] { (void)m.residual(w); }),
                                 input_error_of([&] { assemble_jacobian<3>(m, w, jacobian_kind::exact, a); })}) {
    EXPECT_TRUE(contains(msg, "block 0")) << msg;
    EXPECT_TRUE(contains(msg, "cell (2,1,1)")) << msg;
    EXPECT_TRUE(contains(msg, "density -0.5")) << msg;
  }
}

// The rows of some blocks in a local numbering (one rank's part, distributed/mpi_euler.hpp): the
// selected blocks' cells first, the other cells after them in reverse order; every block of every
// row equals the whole Jacobian's bitwise, no more blocks than it has; cells outside the
// selected blocks and their halos' donors are not read (NaN there). A numbering that breaks its
// contract is refused.
TEST(jacobian, rows_of_selected_blocks_in_a_local_numbering_equal_the_whole_jacobians) {
  std::mt19937 rng(41);
  const auto m = moving_cgrid_model(2);
  const vec<double> w = perturbed_state<2>(m, rng, 0.02);
  const std::size_t nb = m.grid().topology.cells.size();
  for (auto kind : {jacobian_kind::exact, jacobian_kind::modified_order})
    for (std::size_t sel = 0; sel < nb; ++sel) {
      SCOPED_TRACE(testing::Message() << "block " << sel << (kind == jacobian_kind::exact ? " exact" : " modified"));
      block_sparse_matrix<double, 4> whole, part;
      assemble_jacobian<2>(m, w, kind, whole);
      jacobian_numbering num;
      num.blocks.assign(nb, 0);
      num.blocks[sel] = 1;
      num.local.assign(m.n_cells(), -1);
      Eigen::Index k = 0;
      for (std::size_t c = m.cell_offset(static_cast<int>(sel)); c < m.cell_offset(static_cast<int>(sel) + 1); ++c)
        num.local[c] = k++;
      num.rows = k;
      std::vector<char> read(m.n_cells(), 0);
      for (const auto& h : m.halos())
        if (static_cast<std::size_t>(h.block) == sel && static_cast<std::size_t>(h.donor_block) != sel)
          read[m.cell_offset(h.donor_block) + h.donor] = read[m.cell_offset(h.donor_block) + h.donor2] = 1;
      vec<double> view = w;
      for (std::size_t c = m.n_cells(); c-- > 0;) {
        if (num.local[c] >= 0) continue;
        if (read[c])
          num.local[c] = k++;
        else
          view.segment(static_cast<Eigen::Index>(4 * c), 4).setConstant(std::nan(""));
      }
      num.cols = k;
      assemble_jacobian<2>(m, view, kind, part, &num);
      ASSERT_EQ(part.block_rows(), num.rows);
      std::vector<Eigen::Index> global_of(num.cols);
      for (std::size_t c = 0; c < m.n_cells(); ++c)
        if (num.local[c] >= 0) global_of[num.local[c]] = static_cast<Eigen::Index>(c);
      for (Eigen::Index r = 0; r < part.block_rows(); ++r) {
        const Eigen::Index g = global_of[r];
        EXPECT_EQ(part.row_ptr()[r + 1] - part.row_ptr()[r], whole.row_ptr()[g + 1] - whole.row_ptr()[g]) << r;
        for (auto p = part.row_ptr()[r]; p < part.row_ptr()[r + 1]; ++p) {
          const Eigen::Index col = global_of[part.col_index()[p]];
          ASSERT_TRUE(whole.contains(g, col)) << r;
          ASSERT_TRUE(Eigen::Matrix4d(part.block_at(p)) == Eigen::Matrix4d(whole.block(g, col)))
              << "row cell " << g << " column cell " << col;
        }
      }
      // contract breaches: a selected cell out of order, a column beyond cols
      auto bad = num;
      std::swap(bad.local[m.cell_offset(static_cast<int>(sel))], bad.local[m.cell_offset(static_cast<int>(sel)) + 1]);
      EXPECT_TRUE(contains(input_error_of([&] { assemble_jacobian<2>(m, view, kind, part, &bad); }), "numbering"));
      bad = num;
      bad.cols = num.rows;
      EXPECT_TRUE(contains(input_error_of([&] { assemble_jacobian<2>(m, view, kind, part, &bad); }), "numbering"));
    }
}
