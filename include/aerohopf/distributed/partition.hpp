#pragma once
// Partition of a multi-block grid over ranks, and each rank's halo plan: which cells it owns and
// which cells of other ranks its residual (and Jacobian rows) read. Plain data, no MPI: every
// rank computes every plan from the replicated grid, so the send lists need no communication,
// and the plans are tested serially (tests/distributed/test_partition.cpp).
//
// Ownership is by whole blocks; split_for_ranks cuts large blocks (a wing grid is one block) so
// that whole blocks balance. A rank's residual in its cells reads, besides its own cells, only
// the donors of its blocks' halo cells (euler_model::halo_cell: interface halos copy cells of the
// neighbouring block, wall and far-field halos are functions of the rank's own cells), so the
// cells to receive are exactly the donors of those halos that lie in other ranks' blocks. The
// same set is the off-rank columns of the rank's Jacobian rows (flow/jacobian.hpp chains the
// halo derivatives into their donors).

#include <aerohopf/error.hpp>
#include <aerohopf/flow/euler_model.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

namespace aerohopf::distributed {

/// Blocks assigned to ranks.
struct block_partition {
  int ranks = 1;
  std::vector<int> owner;          // rank of each block
  std::vector<std::size_t> cells;  // cells owned by each rank

  std::vector<int> blocks_of(int rank) const {
    std::vector<int> b;
    for (std::size_t k = 0; k < owner.size(); ++k)
      if (owner[k] == rank) b.push_back(static_cast<int>(k));
    return b;
  }
  /// The largest rank's cell count over the mean (1 = balanced): the parallel efficiency bound.
  double imbalance() const {
    const std::size_t total = std::accumulate(cells.begin(), cells.end(), std::size_t{0});
    const std::size_t largest = cells.empty() ? 0 : *std::max_element(cells.begin(), cells.end());
    return total == 0 ? 1.0 : static_cast<double>(largest) * ranks / static_cast<double>(total);
  }
};

/// Whole blocks to `ranks` ranks by the longest-processing-time rule: blocks by decreasing cell
/// count, each to the rank with the fewest cells so far (ties: the lower block index first, the
/// lower rank), which is within 4/3 of the best balance. Every rank gets at least one block;
/// more ranks than blocks is refused (splitting a block along an index direction is not done
/// here).
inline block_partition partition_blocks(const std::vector<std::size_t>& block_cells, int ranks) {
  require(ranks >= 1, "partition_blocks: ", ranks, " ranks (at least 1)");
  require(!block_cells.empty(), "partition_blocks: no blocks");
  require(static_cast<std::size_t>(ranks) <= block_cells.size(), "partition_blocks: ", ranks, " ranks for ",
          block_cells.size(), " blocks: a rank would own no block (whole blocks are distributed; cut the grid's "
          "blocks first: split_for_ranks)");
  for (std::size_t b = 0; b < block_cells.size(); ++b)
    require(block_cells[b] > 0, "partition_blocks: block ", b, " has no cells");
  std::vector<int> order(block_cells.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return block_cells[a] > block_cells[b]; });
  block_partition p;
  p.ranks = ranks;
  p.owner.assign(block_cells.size(), -1);
  p.cells.assign(ranks, 0);
  for (const int b : order) {
    const int r = static_cast<int>(std::min_element(p.cells.begin(), p.cells.end()) - p.cells.begin());
    p.owner[b] = r;
    p.cells[r] += block_cells[b];
  }
  return p;
}

template <int Dim>
block_partition partition_blocks(const flow::euler_model<Dim>& m, int ranks) {
  std::vector<std::size_t> c(m.grid().topology.cells.size());
  for (std::size_t b = 0; b < c.size(); ++b) c[b] = m.cell_offset(static_cast<int>(b) + 1) - m.cell_offset(static_cast<int>(b));
  return partition_blocks(c, ranks);
}

/// A grid whose blocks whole-block partitioning can spread over `ranks` ranks within
/// `max_imbalance` (largest rank's cells over the mean): the largest block is cut along its
/// longest axis (or along `axis` while that has 4 cells or more; flow::split_block), one rank's
/// share (total cells / ranks) off it where it holds more than that, else in half, until
/// partition_blocks reaches the bound, or the largest block
/// has fewer than 4 cells along every axis (then the grid so far is returned; check
/// partition_blocks(...).imbalance()). A single-block wing grid becomes `ranks` blocks of equal
/// size where its longest axis divides so (the AGARD medium grid for 3 ranks: 3 blocks; halving
/// alone made 17).
/// original_cell maps the result's cells to g's, origin its blocks' points to g's.
template <int Dim>
flow::split_grid<Dim> split_for_ranks(const flow::multiblock_grid<Dim>& g, int ranks, double max_imbalance = 1.1,
                                      int axis = -1) {
  require(ranks >= 1, "split_for_ranks: ", ranks, " ranks (at least 1)");
  require(max_imbalance >= 1.0, "split_for_ranks: max_imbalance ", max_imbalance, " (at least 1)");
  require(axis >= -1 && axis < Dim, "split_for_ranks: axis ", axis, " (-1: the longest, or 0 .. ", Dim - 1, ")");
  flow::split_grid<Dim> cur{g, {}};
  std::size_t total = 0;
  for (const auto& c : g.topology.cells) total += flow::product<Dim>(c);
  cur.original_cell.resize(total);
  std::iota(cur.original_cell.begin(), cur.original_cell.end(), std::size_t{0});
  cur.origin.resize(g.topology.cells.size());
  for (std::size_t b = 0; b < cur.origin.size(); ++b) cur.origin[b].block = static_cast<int>(b);
  while (true) {
    const auto& cells = cur.grid.topology.cells;
    std::vector<std::size_t> n(cells.size());
    for (std::size_t b = 0; b < n.size(); ++b) n[b] = flow::product<Dim>(cells[b]);
    if (n.size() >= static_cast<std::size_t>(ranks) && partition_blocks(n, ranks).imbalance() <= max_imbalance) break;
    const int big = static_cast<int>(std::max_element(n.begin(), n.end()) - n.begin());
    const int longest = static_cast<int>(std::max_element(cells[big].begin(), cells[big].end()) - cells[big].begin());
    const int cut = axis >= 0 && cells[big][axis] >= 4 ? axis : longest;
    const int len = cells[big][cut];
    if (len < 4) break;
    const double share = static_cast<double>(total) / ranks;
    int at = len / 2;
    if (static_cast<double>(n[big]) > 1.5 * share)
      at = std::clamp(static_cast<int>(std::lround(len * share / static_cast<double>(n[big]))), 2, len - 2);
    auto next = flow::split_block(cur.grid, big, cut, at);
    for (auto& c : next.original_cell) c = cur.original_cell[c];
    next.origin = flow::compose_origins(cur.origin, next.origin);
    cur = std::move(next);
  }
  return cur;
}

/// One rank's view of a partition. Cells are the model's global cell numbers (state values
/// c * nv .. c * nv + nv - 1). The rank's local state is its owned cells in global order (its
/// blocks in increasing index, each block's cells in the model's order).
struct halo_plan {
  int rank = 0;
  int ranks = 1;
  std::vector<char> owned_blocks;                          // one entry per block
  std::vector<std::pair<std::size_t, std::size_t>> owned;  // [first, last) global cell ranges, increasing
  std::vector<std::vector<std::size_t>> recv;              // recv[q]: cells of rank q read here, increasing
  std::vector<std::vector<std::size_t>> send;              // send[q]: cells of this rank read by q, increasing

  std::size_t owned_cells() const {
    std::size_t n = 0;
    for (const auto& [a, b] : owned) n += b - a;
    return n;
  }
  std::size_t ghost_cells() const {
    std::size_t n = 0;
    for (const auto& r : recv) n += r.size();
    return n;
  }
};


/// The halo plan of `rank` in partition p of model m's blocks (p as partition_blocks gives it, or
/// any assignment of the model's blocks to p.ranks ranks: checked).
template <int Dim>
halo_plan make_halo_plan(const flow::euler_model<Dim>& m, const block_partition& p, int rank) {
  const std::size_t nb = m.grid().topology.cells.size();
  require(p.ranks >= 1, "make_halo_plan: ", p.ranks, " ranks");
  require(rank >= 0 && rank < p.ranks, "make_halo_plan: rank ", rank, " of ", p.ranks);
  require_size(p.owner.size(), nb, "make_halo_plan", "the partition's block owners");
  for (std::size_t b = 0; b < nb; ++b)
    require(p.owner[b] >= 0 && p.owner[b] < p.ranks, "make_halo_plan: block ", b, " has owner ", p.owner[b], " of ",
            p.ranks, " ranks");
  halo_plan h;
  h.rank = rank;
  h.ranks = p.ranks;
  h.owned_blocks.assign(nb, 0);
  for (std::size_t b = 0; b < nb; ++b) {
    if (p.owner[b] != rank) continue;
    h.owned_blocks[b] = 1;
    const std::size_t first = m.cell_offset(static_cast<int>(b)), last = m.cell_offset(static_cast<int>(b) + 1);
    if (!h.owned.empty() && h.owned.back().second == first)
      h.owned.back().second = last;
    else
      h.owned.emplace_back(first, last);
  }
  // one pass over the halos: a halo of a block of rank `reader` whose donor block belongs to
  // another rank `holder` puts both donor cells on holder's list for reader
  h.recv.assign(p.ranks, {});
  h.send.assign(p.ranks, {});
  for (const auto& c : m.halos()) {
    const int reader = p.owner[c.block], holder = p.owner[c.donor_block];
    if (reader == holder || (reader != rank && holder != rank)) continue;
    auto& list = reader == rank ? h.recv[holder] : h.send[reader];
    list.push_back(m.cell_offset(c.donor_block) + c.donor);
    list.push_back(m.cell_offset(c.donor_block) + c.donor2);
  }
  for (auto* lists : {&h.recv, &h.send})
    for (auto& l : *lists) {
      std::sort(l.begin(), l.end());
      l.erase(std::unique(l.begin(), l.end()), l.end());
    }
  return h;
}

}  // namespace aerohopf::distributed
