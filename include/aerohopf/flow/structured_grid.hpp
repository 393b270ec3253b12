#pragma once
// Structured multi-block grids and their connectivity, templated on dimension and scalar.
//
// Why this layout: every block stores its points contiguously (index 0 fastest), so metrics and
// residual kernels stream through memory, and the dimension is a template parameter so the 2D
// aerofoil and the 3D wings share one implementation. Points are templated on the scalar so a
// grid moved by a structural state can itself carry taylor<> jets (exact A_fs products).
//
// Connectivity is a list of boundary patches, each covering a rectangle of cell faces on one
// block face: a slip wall, a far field, or a point-matched interface with another block (or
// the same block, e.g. a C-grid wake cut) with a signed axis transform as in CGNS.
// Faces are numbered face = 2 * axis + side (side 0: index-min face, side 1: index-max face).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdlib>
#include <utility>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../error.hpp"

namespace aerohopf::flow {

template <int Dim>
using index_d = std::array<int, Dim>;

/// Row-major-like linear index with index 0 fastest.
template <int Dim>
std::size_t linear_index(const index_d<Dim>& i, const index_d<Dim>& n) {
  std::size_t r = static_cast<std::size_t>(i[Dim - 1]);
  for (int d = Dim - 2; d >= 0; --d) r = r * static_cast<std::size_t>(n[d]) + static_cast<std::size_t>(i[d]);
  return r;
}
template <int Dim>
std::size_t product(const index_d<Dim>& n) {
  std::size_t r = 1;
  for (int d = 0; d < Dim; ++d) r *= static_cast<std::size_t>(n[d]);
  return r;
}
/// Inverse of linear_index.
template <int Dim>
index_d<Dim> unravel(std::size_t k, const index_d<Dim>& n) {
  index_d<Dim> i{};
  for (int d = 0; d < Dim; ++d) {
    i[d] = static_cast<int>(k % static_cast<std::size_t>(n[d]));
    k /= static_cast<std::size_t>(n[d]);
  }
  return i;
}

/// One block: points[d] in each direction, coordinates x[linear point index][axis].
template <class S, int Dim>
struct grid_block {
  index_d<Dim> points{};
  std::vector<std::array<S, Dim>> x;

  index_d<Dim> cells() const {
    index_d<Dim> c{};
    for (int d = 0; d < Dim; ++d) c[d] = points[d] - 1;
    return c;
  }
  std::size_t n_points() const { return product<Dim>(points); }
  std::size_t n_cells() const { return product<Dim>(cells()); }
  std::array<S, Dim>& at(const index_d<Dim>& i) { return x[linear_index<Dim>(i, points)]; }
  const std::array<S, Dim>& at(const index_d<Dim>& i) const { return x[linear_index<Dim>(i, points)]; }
};

/// The name of the level a grid family makes by coarsening its finest grid by `stride`:
/// 8 very_coarse, 4 coarse, 2 medium, 1 fine, else "stride<s>".
inline std::string level_name(int stride) {
  switch (stride) {
    case 8: return "very_coarse";
    case 4: return "coarse";
    case 2: return "medium";
    case 1: return "fine";
    default: return "stride" + std::to_string(stride);
  }
}

template <class S, int Dim>
struct multiblock_points {
  std::vector<grid_block<S, Dim>> blocks;
  std::size_t n_cells() const {
    std::size_t n = 0;
    for (const auto& b : blocks) n += b.n_cells();
    return n;
  }
};

/// Converts the coordinates to another scalar (e.g. double -> taylor<double, 1>).
template <class T, class S, int Dim>
multiblock_points<T, Dim> convert_points(const multiblock_points<S, Dim>& g) {
  multiblock_points<T, Dim> r;
  r.blocks.resize(g.blocks.size());
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    r.blocks[b].points = g.blocks[b].points;
    r.blocks[b].x.resize(g.blocks[b].x.size());
    for (std::size_t k = 0; k < g.blocks[b].x.size(); ++k)
      for (int d = 0; d < Dim; ++d) r.blocks[b].x[k][d] = T(g.blocks[b].x[k][d]);
  }
  return r;
}

enum class boundary_kind { wall, far_field, interface };

inline const char* to_string(boundary_kind k) {
  switch (k) {
    case boundary_kind::wall: return "wall";
    case boundary_kind::far_field: return "far_field";
    default: return "interface";
  }
}

/// A rectangle of cell faces on one block face. begin/end are cell index ranges along the
/// tangential axes (the entry of the normal axis is ignored). For an interface, the donor
/// rectangle on (donor_block, donor_face) is given the same way, and transform[a] = +-(b+1)
/// says that tangential axis a of this block runs along axis b of the donor, forwards (+) or
/// backwards (-). The normal entry of transform is ignored (normals always match outward to
/// inward).
template <int Dim>
struct boundary_patch {
  int block = 0;
  int face = 0;
  index_d<Dim> begin{}, end{};
  boundary_kind kind = boundary_kind::wall;
  int donor_block = -1;
  int donor_face = -1;
  index_d<Dim> donor_begin{}, donor_end{};
  index_d<Dim> transform{};
  /// Optional tag (e.g. "aerofoil") so that forces can be integrated over a group of walls.
  std::string tag;
};

/// Whole block face as a patch (helper for the common case).
template <int Dim>
boundary_patch<Dim> whole_face(int block, int face, const index_d<Dim>& cells, boundary_kind kind) {
  boundary_patch<Dim> p;
  p.block = block;
  p.face = face;
  p.kind = kind;
  for (int d = 0; d < Dim; ++d) p.end[d] = cells[d];
  return p;
}

template <int Dim>
struct grid_topology {
  std::vector<index_d<Dim>> cells;  // interior cells per block
  std::vector<boundary_patch<Dim>> patches;
};

}  // namespace aerohopf::flow

namespace aerohopf::flow {

/// Points plus connectivity: everything a flow solver needs to know about a grid.
template <int Dim>
struct multiblock_grid {
  multiblock_points<double, Dim> points;
  grid_topology<Dim> topology;
};

/// Coarser grid from every m-th point in each direction (m = 2, 4, 8 for medium, coarse,
/// very coarse from a fine grid). Throws input_error if a block or patch does not divide by m.
template <int Dim>
multiblock_grid<Dim> coarsen(const multiblock_grid<Dim>& fine, int m) {
  require(m >= 1, "coarsen: factor ", m, " must be positive");
  multiblock_grid<Dim> g;
  g.topology = fine.topology;
  g.points.blocks.resize(fine.points.blocks.size());
  for (std::size_t b = 0; b < fine.points.blocks.size(); ++b) {
    const auto& fb = fine.points.blocks[b];
    auto& cb = g.points.blocks[b];
    for (int d = 0; d < Dim; ++d) {
      require((fb.points[d] - 1) % m == 0, "coarsen: block ", b, " has ", fb.points[d] - 1,
              " cells along axis ", d, ", not divisible by ", m);
      cb.points[d] = (fb.points[d] - 1) / m + 1;
    }
    cb.x.resize(cb.n_points());
    for (std::size_t k = 0; k < cb.x.size(); ++k) {
      auto i = unravel<Dim>(k, cb.points);
      for (int d = 0; d < Dim; ++d) i[d] *= m;
      cb.x[k] = fb.at(i);
    }
  }
  g.topology.cells.clear();
  for (const auto& cb : g.points.blocks) g.topology.cells.push_back(cb.cells());
  for (std::size_t p = 0; p < g.topology.patches.size(); ++p) {
    auto& pt = g.topology.patches[p];
    for (int d = 0; d < Dim; ++d) {
      for (int* v : {&pt.begin[d], &pt.end[d], &pt.donor_begin[d], &pt.donor_end[d]}) {
        require(*v % m == 0, "coarsen: patch ", p, " (block ", pt.block, ", face ", pt.face,
                ") has a range bound ", *v, " not divisible by ", m);
        *v /= m;
      }
    }
  }
  return g;
}

/// Where a block's points lie in another grid: the box of block `block` from point index
/// `offset`, the block's own point counts wide (index directions kept).
template <int Dim>
struct block_origin {
  int block = 0;
  std::array<int, Dim> offset{};
};

/// A grid with one block cut in two (split_block) and where each of its cells and points came
/// from. `origin` may be empty (a grid made by hand): then it is not known.
template <int Dim>
struct split_grid {
  multiblock_grid<Dim> grid;
  std::vector<std::size_t> original_cell;     // for each cell of `grid` (blocks in order), its cell in the input
  std::vector<block_origin<Dim>> origin = {};  // for each block of `grid`, where its points lie in the input
};

/// Cuts block b of g at cell index `at` along `axis`: cells [0, at) stay block b, cells [at, n)
/// become a new last block, the two joined by a point-matched interface. Every patch is carried
/// over: patches of b split where they straddle the cut (an interface's donor range with them),
/// and interfaces whose donor range in b straddles it split likewise, so each halo cell of the
/// result reads the same donor as before and the residual is the same (to the cell order,
/// original_cell). Both pieces keep at least 2 cells along the axis (the MUSCL stencil and
/// interface halos need 2).
template <int Dim>
split_grid<Dim> split_block(const multiblock_grid<Dim>& g, int b, int axis, int at) {
  const int nb = static_cast<int>(g.topology.cells.size());
  require(b >= 0 && b < nb, "split_block: block ", b, " of ", nb);
  require(axis >= 0 && axis < Dim, "split_block: axis ", axis);
  const auto cells = g.topology.cells[b];
  require(at >= 2 && at <= cells[axis] - 2, "split_block: cut at cell ", at, " of block ", b, "'s ", cells[axis],
          " cells along axis ", axis, " (each piece needs at least 2)");
  const int nu = nb;  // index of the upper piece
  split_grid<Dim> out;
  auto& og = out.grid;
  og.points = g.points;
  og.topology.cells = g.topology.cells;
  // points: lower [0, at], upper [at, n] along the axis (the cut plane in both)
  {
    const auto& src = g.points.blocks[b];
    grid_block<double, Dim> lo, up;
    lo.points = src.points;
    lo.points[axis] = at + 1;
    up.points = src.points;
    up.points[axis] = src.points[axis] - at;
    lo.x.resize(lo.n_points());
    up.x.resize(up.n_points());
    for (std::size_t k = 0; k < lo.x.size(); ++k) lo.x[k] = src.at(unravel<Dim>(k, lo.points));
    for (std::size_t k = 0; k < up.x.size(); ++k) {
      auto i = unravel<Dim>(k, up.points);
      i[axis] += at;
      up.x[k] = src.at(i);
    }
    og.points.blocks[b] = std::move(lo);
    og.points.blocks.push_back(std::move(up));
    og.topology.cells[b] = og.points.blocks[b].cells();
    og.topology.cells.push_back(og.points.blocks[nu].cells());
  }
  // the part of a cell range [lo, hi) along the axis in piece 0 (below the cut) or 1 (above it,
  // in the piece's own indices: shifted by -at), empty if first >= second
  const auto part_of = [at](int piece, int lo, int hi) {
    return piece == 0 ? std::pair{lo, std::min(hi, at)} : std::pair{std::max(lo, at) - at, hi - at};
  };
  // 1. patches ON block b: by the receiver's range along the axis
  std::vector<boundary_patch<Dim>> pass1;
  for (const auto& p : g.topology.patches) {
    if (p.block != b) {
      pass1.push_back(p);
      continue;
    }
    if (p.face / 2 == axis) {
      auto q = p;
      if (p.face % 2 == 1) q.block = nu;
      pass1.push_back(q);
      continue;
    }
    const int lo = p.begin[axis], hi = p.end[axis];
    for (const int piece : {0, 1}) {
      const auto [a, c] = part_of(piece, lo, hi);
      if (a >= c) continue;
      auto q = p;
      q.block = piece == 0 ? b : nu;
      q.begin[axis] = a;
      q.end[axis] = c;
      if (p.kind == boundary_kind::interface) {
        const int tr = p.transform[axis], be = std::abs(tr) - 1;
        const int shift = piece ? at : 0;
        const int d0 = a + shift - lo, d1 = c + shift - lo;  // the part's offsets along the receiver's axis
        if (tr > 0) {
          q.donor_begin[be] = p.donor_begin[be] + d0;
          q.donor_end[be] = p.donor_begin[be] + d1;
        } else {
          q.donor_begin[be] = p.donor_end[be] - d1;
          q.donor_end[be] = p.donor_end[be] - d0;
        }
      }
      pass1.push_back(q);
    }
  }
  // 2. interfaces whose DONOR is block b: by the donor range along the axis
  for (const auto& p : pass1) {
    if (p.kind != boundary_kind::interface || p.donor_block != b) {
      og.topology.patches.push_back(p);
      continue;
    }
    if (p.donor_face / 2 == axis) {
      auto q = p;
      if (p.donor_face % 2 == 1) q.donor_block = nu;
      og.topology.patches.push_back(q);
      continue;
    }
    int e = -1;  // the receiver's axis that runs along the donor's cut axis
    for (int k = 0; k < Dim; ++k)
      if (k != p.face / 2 && std::abs(p.transform[k]) - 1 == axis) e = k;
    require(e >= 0, "split_block: interface patch of block ", p.block, " face ", p.face, " has no axis along the cut");
    const bool forward = p.transform[e] > 0;
    const int dlo = p.donor_begin[axis], dhi = p.donor_end[axis];
    for (const int piece : {0, 1}) {
      const auto [pa, pc] = part_of(piece, dlo, dhi);
      if (pa >= pc) continue;
      auto q = p;
      q.donor_block = piece == 0 ? b : nu;
      q.donor_begin[axis] = pa;
      q.donor_end[axis] = pc;
      // receiver offsets of donor cells [a, c) (uncut indices): forward delta = idx - dlo,
      // reverse delta = dhi - 1 - idx
      const int a = pa + (piece ? at : 0), c = pc + (piece ? at : 0);
      const int r0 = forward ? a - dlo : dhi - c, r1 = forward ? c - dlo : dhi - a;
      q.begin[e] = p.begin[e] + r0;
      q.end[e] = p.begin[e] + r1;
      og.topology.patches.push_back(q);
    }
  }
  // 3. the cut: lower's max face <-> upper's min face, axes aligned
  for (const int piece : {0, 1}) {
    boundary_patch<Dim> q;
    q.block = piece == 0 ? b : nu;
    q.face = 2 * axis + (piece == 0 ? 1 : 0);
    q.kind = boundary_kind::interface;
    q.donor_block = piece == 0 ? nu : b;
    q.donor_face = 2 * axis + (piece == 0 ? 0 : 1);
    const auto& own = og.topology.cells[q.block];
    const auto& don = og.topology.cells[q.donor_block];
    for (int k = 0; k < Dim; ++k) {
      q.end[k] = own[k];
      q.donor_end[k] = don[k];
      q.transform[k] = k + 1;
    }
    og.topology.patches.push_back(q);
  }
  // where each cell came from: blocks before the new one keep their cells (b truncated), the new
  // last block holds b's upper cells
  std::vector<std::size_t> offset(nb + 1, 0);
  for (int k = 0; k < nb; ++k) offset[k + 1] = offset[k] + product<Dim>(g.topology.cells[k]);
  for (int k = 0; k <= nb; ++k) {
    const int src = k == nu ? b : k;
    const auto& oc = og.topology.cells[k];
    for (std::size_t c = 0; c < product<Dim>(oc); ++c) {
      auto i = unravel<Dim>(c, oc);
      if (k == nu) i[axis] += at;
      out.original_cell.push_back(offset[src] + linear_index<Dim>(i, g.topology.cells[src]));
    }
  }
  out.origin.resize(static_cast<std::size_t>(nb) + 1);
  for (int k = 0; k < nb; ++k) out.origin[static_cast<std::size_t>(k)].block = k;
  out.origin[static_cast<std::size_t>(nu)].block = b;
  out.origin[static_cast<std::size_t>(nu)].offset[static_cast<std::size_t>(axis)] = at;
  return out;
}

/// The origins of split_block(s.grid, ...)'s blocks (`next`) in the grid s was cut from.
template <int Dim>
std::vector<block_origin<Dim>> compose_origins(const std::vector<block_origin<Dim>>& s,
                                               const std::vector<block_origin<Dim>>& next) {
  std::vector<block_origin<Dim>> out;
  out.reserve(next.size());
  for (const auto& o : next) {
    require(o.block >= 0 && static_cast<std::size_t>(o.block) < s.size(), "compose_origins: block ", o.block, " of ",
            s.size());
    block_origin<Dim> c = s[static_cast<std::size_t>(o.block)];
    for (int d = 0; d < Dim; ++d) c.offset[static_cast<std::size_t>(d)] += o.offset[static_cast<std::size_t>(d)];
    out.push_back(c);
  }
  return out;
}

/// A field of s's input grid (nv values per cell, in its cell order; any values past the cells,
/// e.g. a structure's, kept in place) in the cut grid's cell order; from_split_order: back.
template <int Dim, class T>
Eigen::Matrix<T, Eigen::Dynamic, 1> to_split_order(const split_grid<Dim>& s, const Eigen::Matrix<T, Eigen::Dynamic, 1>& v,
                                                   int nv) {
  const auto nc = static_cast<Eigen::Index>(s.original_cell.size()) * nv;
  require(nv >= 1 && v.size() >= nc, "to_split_order: a field of ", v.size(), " values for ", s.original_cell.size(),
          " cells x ", nv);
  Eigen::Matrix<T, Eigen::Dynamic, 1> out = v;
  for (std::size_t k = 0; k < s.original_cell.size(); ++k)
    out.segment(static_cast<Eigen::Index>(k) * nv, nv) = v.segment(static_cast<Eigen::Index>(s.original_cell[k]) * nv, nv);
  return out;
}
template <int Dim, class T>
Eigen::Matrix<T, Eigen::Dynamic, 1> from_split_order(const split_grid<Dim>& s,
                                                     const Eigen::Matrix<T, Eigen::Dynamic, 1>& v, int nv) {
  const auto nc = static_cast<Eigen::Index>(s.original_cell.size()) * nv;
  require(nv >= 1 && v.size() >= nc, "from_split_order: a field of ", v.size(), " values for ", s.original_cell.size(),
          " cells x ", nv);
  Eigen::Matrix<T, Eigen::Dynamic, 1> out = v;
  for (std::size_t k = 0; k < s.original_cell.size(); ++k)
    out.segment(static_cast<Eigen::Index>(s.original_cell[k]) * nv, nv) = v.segment(static_cast<Eigen::Index>(k) * nv, nv);
  return out;
}

/// Transfer of a cell-centred field with nv values per cell from a coarse grid to the grid
/// it was coarsened from (coarse = coarsen(fine, m)) by injection: every fine cell takes the
/// value of the coarse cell containing it. Cells are numbered block by block, each block in
/// linear_index order (the euler_model ordering). Used for grid sequencing (a coarse-grid
/// steady state or Hopf eigenvector as the start on the finer grid). T may be complex.
template <int Dim, class T>
Eigen::Matrix<T, Eigen::Dynamic, 1> prolong_cells(const grid_topology<Dim>& coarse, const grid_topology<Dim>& fine,
                                                  int m, const Eigen::Matrix<T, Eigen::Dynamic, 1>& v, int nv) {
  require(m >= 1 && nv >= 1, "prolong_cells: factor ", m, " and values per cell ", nv, " must be positive");
  require(coarse.cells.size() == fine.cells.size(), "prolong_cells: ", coarse.cells.size(), " coarse blocks vs ",
          fine.cells.size(), " fine blocks");
  std::size_t nc = 0, nf = 0;
  for (std::size_t b = 0; b < fine.cells.size(); ++b) {
    for (int d = 0; d < Dim; ++d)
      require(fine.cells[b][d] == m * coarse.cells[b][d], "prolong_cells: block ", b, " axis ", d, " has ",
              fine.cells[b][d], " fine cells, not ", m, " x ", coarse.cells[b][d]);
    nc += product<Dim>(coarse.cells[b]);
    nf += product<Dim>(fine.cells[b]);
  }
  require(v.size() == static_cast<Eigen::Index>(nc) * nv, "prolong_cells: field has ", v.size(), " entries, the coarse grid ",
          nc, " cells x ", nv);
  Eigen::Matrix<T, Eigen::Dynamic, 1> out(static_cast<Eigen::Index>(nf) * nv);
  std::size_t oc = 0, of = 0;
  for (std::size_t b = 0; b < fine.cells.size(); ++b) {
    const std::size_t n_fine = product<Dim>(fine.cells[b]);
    for (std::size_t k = 0; k < n_fine; ++k) {
      auto i = unravel<Dim>(k, fine.cells[b]);
      for (int d = 0; d < Dim; ++d) i[d] /= m;
      const std::size_t kc = linear_index<Dim>(i, coarse.cells[b]);
      out.segment(static_cast<Eigen::Index>((of + k) * nv), nv) = v.segment(static_cast<Eigen::Index>((oc + kc) * nv), nv);
    }
    oc += product<Dim>(coarse.cells[b]);
    of += n_fine;
  }
  return out;
}

}  // namespace aerohopf::flow
