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
#include <array>
#include <cstddef>
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
