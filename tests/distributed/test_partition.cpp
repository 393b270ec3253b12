// Block partitions and halo plans (distributed/partition.hpp), serially: the longest-processing-
// time assignment and its refusals; send and receive lists that mirror each other; and, the
// plan's real test, every rank's residual from its owned cells and received cells alone (all
// other cells NaN) equals the serial residual bitwise (euler_model::residual_of_blocks), on the
// NACA 0012 C-grid (2D, three blocks), a row of three boxes (3D) and the tiny AGARD C-H grid (one
// block, split_for_ranks), for 1, 2 and 3 ranks.
#include <gtest/gtest.h>

#include <aerohopf/distributed/partition.hpp>

#include <algorithm>
#include <limits>
#include <vector>
#include "support/error_messages.hpp"
#include "support/partition_grids.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;

TEST(partition, longest_processing_time_balances_whole_blocks) {
  const auto p = partition_blocks({10, 7, 5, 4, 3}, 2);
  // 10 -> rank 0; 7 -> 1; 5 -> 1 (12); 4 -> 0 (14); 3 -> 1 (15)
  EXPECT_EQ(p.owner, (std::vector<int>{0, 1, 1, 0, 1}));
  EXPECT_EQ(p.cells, (std::vector<std::size_t>{14, 15}));
  EXPECT_NEAR(p.imbalance(), 15.0 * 2 / 29.0, 1e-15);
  EXPECT_EQ(p.blocks_of(1), (std::vector<int>{1, 2, 4}));
  const auto one = partition_blocks({10, 7}, 1);
  EXPECT_EQ(one.owner, (std::vector<int>{0, 0}));
  EXPECT_DOUBLE_EQ(one.imbalance(), 1.0);
}

TEST(partition, bad_requests_are_refused) {
  EXPECT_TRUE(contains(input_error_of([] { partition_blocks({4, 4}, 0); }), "0 ranks"));
  EXPECT_TRUE(contains(input_error_of([] { partition_blocks({4, 4}, 3); }), "3 ranks for 2 blocks"));
  EXPECT_TRUE(contains(input_error_of([] { partition_blocks({4, 0}, 1); }), "block 1 has no cells"));
  EXPECT_TRUE(contains(input_error_of([] { partition_blocks({}, 1); }), "no blocks"));
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8});
  block_partition p = partition_blocks(m, 2);
  EXPECT_TRUE(contains(input_error_of([&] { make_halo_plan(m, p, 2); }), "rank 2 of 2"));
  p.owner[1] = 5;
  EXPECT_TRUE(contains(input_error_of([&] { make_halo_plan(m, p, 0); }), "block 1 has owner 5"));
  p.owner.pop_back();
  EXPECT_TRUE(contains(input_error_of([&] { make_halo_plan(m, p, 0); }), "block owners"));
}

namespace {

template <int Dim>
void check_plans(const flow::euler_model<Dim>& m, int ranks) {
  SCOPED_TRACE(testing::Message() << Dim << "D, " << ranks << " ranks");
  constexpr int nv = flow::euler_model<Dim>::nv;
  const auto part = partition_blocks(m, ranks);
  std::vector<halo_plan> plans;
  for (int r = 0; r < ranks; ++r) plans.push_back(make_halo_plan(m, part, r));
  const vec<double> w = test::perturbed_free_stream(m, 11u + ranks);
  const vec<double> serial = m.residual(w);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<int> owned_by(m.n_cells(), -1);
  for (int r = 0; r < ranks; ++r) {
    EXPECT_EQ(plans[r].owned_cells(), part.cells[r]);
    for (const auto& [a, b] : plans[r].owned)
      for (std::size_t c = a; c < b; ++c) {
        EXPECT_EQ(owned_by[c], -1) << "cell " << c << " owned twice";
        owned_by[c] = r;
      }
  }
  for (int r = 0; r < ranks; ++r) {
    const auto& h = plans[r];
    EXPECT_TRUE(h.recv[r].empty() && h.send[r].empty());
    for (int q = 0; q < ranks; ++q) {
      EXPECT_EQ(h.send[q], plans[q].recv[r]) << "rank " << r << " -> " << q;
      for (const std::size_t c : h.recv[q]) EXPECT_EQ(owned_by[c], q) << "rank " << r << " receives cell " << c;
    }
    // this rank's view: its cells and the received cells, NaN everywhere else
    vec<double> view = vec<double>::Constant(m.size(), nan);
    for (const auto& [a, b] : h.owned)
      view.segment(static_cast<Eigen::Index>(a * nv), static_cast<Eigen::Index>((b - a) * nv)) =
          w.segment(static_cast<Eigen::Index>(a * nv), static_cast<Eigen::Index>((b - a) * nv));
    for (int q = 0; q < ranks; ++q)
      for (const std::size_t c : h.recv[q])
        view.segment(static_cast<Eigen::Index>(c * nv), nv) = w.segment(static_cast<Eigen::Index>(c * nv), nv);
    vec<double> r_view = vec<double>::Constant(m.size(), -7.0);
    m.template residual_of_blocks<double>(m.metrics(), view.data(), r_view.data(), h.owned_blocks);
    for (std::size_t c = 0; c < m.n_cells(); ++c)
      for (int v = 0; v < nv; ++v) {
        const auto k = static_cast<Eigen::Index>(c * nv + v);
        if (owned_by[c] == r) {
          ASSERT_EQ(r_view[k], serial[k]) << "rank " << r << " " << m.cell_name(c) << " value " << v;
        } else {
          ASSERT_EQ(r_view[k], -7.0) << "rank " << r << " wrote " << m.cell_name(c) << ", not its cell";
        }
      }
    if (ranks > 1) {
      EXPECT_GT(h.ghost_cells(), 0u) << "rank " << r;
    }
  }
  for (std::size_t c = 0; c < m.n_cells(); ++c) EXPECT_GE(owned_by[c], 0) << "cell " << c << " owned by no rank";
  if (ranks == 1) {
    EXPECT_EQ(plans[0].ghost_cells(), 0u);
  }
}

}  // namespace

TEST(partition, each_rank_evaluates_its_blocks_from_its_cells_and_its_halo_cells_alone_2d) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02});
  for (const int ranks : {1, 2, 3}) check_plans(m, ranks);
}

TEST(partition, each_rank_evaluates_its_blocks_from_its_cells_and_its_halo_cells_alone_3d) {
  const flow::euler_model<3> m(test::box_row_3d(), {.mach = 0.8, .alpha_rad = 0.05, .beta_rad = 0.02});
  for (const int ranks : {1, 2, 3}) check_plans(m, ranks);
}

TEST(partition, block_residual_checks_the_cells_it_reads) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8});
  constexpr int nv = 4;
  const auto part = partition_blocks(m, 3);
  const auto h = make_halo_plan(m, part, 0);
  const vec<double> w = test::perturbed_free_stream(m, 5u);
  vec<double> r(m.size());
  // a negative density in an owned cell, then in a received cell: refused naming the cell
  const std::size_t own = h.owned.front().first + 3;
  std::size_t ghost = 0;
  for (const auto& l : h.recv)
    if (!l.empty()) ghost = l.front();
  for (const std::size_t c : {own, ghost}) {
    vec<double> bad = w;
    bad[static_cast<Eigen::Index>(c * nv)] = -1.0;
    const auto msg = input_error_of([&] { m.residual_of_blocks<double>(m.metrics(), bad.data(), r.data(), h.owned_blocks); });
    EXPECT_TRUE(contains(msg, "residual_of_blocks")) << msg;
    EXPECT_TRUE(contains(msg, m.cell_name(c))) << msg;
  }
  // a cell it does not read may hold anything
  vec<double> other = w;
  for (std::size_t c = 0; c < m.n_cells(); ++c) {
    bool read = false;
    for (const auto& [a, b] : h.owned) read = read || (c >= a && c < b);
    for (const auto& l : h.recv) read = read || std::binary_search(l.begin(), l.end(), c);
    if (!read) other[static_cast<Eigen::Index>(c * nv)] = -1.0;
  }
  EXPECT_NO_THROW(m.residual_of_blocks<double>(m.metrics(), other.data(), r.data(), h.owned_blocks));
  EXPECT_TRUE(contains(input_error_of([&] {
                         m.residual_of_blocks<double>(m.metrics(), w.data(), r.data(), std::vector<char>(2, 1));
                       }),
                       "block selection"));
}

// The single-block wing grid cut for 2, 3 and 4 ranks: balanced within the bound, the residual on
// the cut grid the original's cell by cell, and every rank's plan complete (check_plans).
TEST(partition, a_single_block_wing_is_split_for_the_ranks) {
  const auto g = flow::wing_cgrid(test_support::agard(), test_support::tiny_wing_options());
  const flow::free_stream fs{.mach = 0.9, .alpha_rad = 0.02};
  const flow::euler_model<3> whole(g, fs);
  const vec<double> w = test::perturbed_free_stream(whole, 21u);
  const vec<double> r = whole.residual(w);
  for (const int ranks : {2, 3, 4}) {
    const auto s = split_for_ranks(g, ranks);
    const flow::euler_model<3> m(s.grid, fs);
    const auto p = partition_blocks(m, ranks);
    EXPECT_LE(p.imbalance(), 1.1) << ranks << " ranks, " << s.grid.topology.cells.size() << " blocks";
    vec<double> ws(w.size()), rs_expected(w.size());
    for (std::size_t c = 0; c < s.original_cell.size(); ++c) {
      ws.segment(static_cast<Eigen::Index>(5 * c), 5) = w.segment(static_cast<Eigen::Index>(5 * s.original_cell[c]), 5);
      rs_expected.segment(static_cast<Eigen::Index>(5 * c), 5) =
          r.segment(static_cast<Eigen::Index>(5 * s.original_cell[c]), 5);
    }
    EXPECT_LE((m.residual(ws) - rs_expected).cwiseAbs().maxCoeff(), 1e-13 * r.cwiseAbs().maxCoeff()) << ranks;
    ASSERT_EQ(s.origin.size(), s.grid.points.blocks.size());
    for (std::size_t b = 0; b < s.origin.size(); ++b) {  // the blocks' points: boxes of the input's
      const auto& blk = s.grid.points.blocks[b];
      EXPECT_EQ(s.origin[b].block, 0);
      for (std::size_t k = 0; k < blk.n_points(); ++k) {
        auto i = flow::unravel<3>(k, blk.points);
        for (int d = 0; d < 3; ++d) i[d] += s.origin[b].offset[d];
        ASSERT_EQ(blk.x[k], g.points.blocks[0].at(i)) << ranks << " ranks, block " << b << " point " << k;
      }
    }
    check_plans(m, ranks);
  }
  EXPECT_TRUE(contains(input_error_of([&] { split_for_ranks(g, 0); }), "0 ranks"));
  EXPECT_TRUE(contains(input_error_of([&] { split_for_ranks(g, 2, 0.5); }), "max_imbalance"));
}
