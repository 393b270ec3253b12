#pragma once
// Exact second-order and modified-order Jacobians of the Euler residual (spec 05), assembled
// into block_sparse_matrix<double, Dim + 2>.
//
// Exact: each face flux F(w_{-2}, w_{-1}, w_{+1}, w_{+2}) depends on the 4 cells along its grid
// line through MUSCL, so a cell row has 4 Dim + 1 blocks (9 in 2D, 13 in 3D). The 4 blocks
// dF/dw_k are obtained by local forward-mode AD of the SAME templated face function that the
// residual uses (jet<double, 4 (Dim+2)>: one pass gives all stencil derivatives): exact to rounding
// and never out of sync with the residual.
// Modified order: MUSCL dependence dropped, dF/dw_{-1} = dF/dw_l and dF/dw_{+1} = dF/dw_r at
// the MUSCL states (2 Dim + 1 blocks). With order 1 both coincide with the exact Jacobian of
// the first-order scheme.
// Halo cells are functions of one interior donor cell each, w_h = g(w_donor), so a derivative
// with respect to a halo cell is added to the donor's column times dg/dw_donor (identity across
// block interfaces; AD of the wall mirror and of the far-field state otherwise).
// Also the ALE term w_cell q_f contributes q_f / V to the diagonal.
#include <Eigen/Core>

#include <utility>
#include <vector>

#include "../linalg/block_sparse_matrix.hpp"
#include "../scalar/taylor.hpp"
#include "../scalar/jet.hpp"
#include "euler_model.hpp"

namespace aerohopf::flow {

enum class jacobian_kind { exact, modified_order };

/// The rows and columns of a Jacobian restricted to some blocks (one rank's part of a
/// partitioned grid, distributed/mpi_euler.hpp): the rows are the cells of the selected blocks,
/// in global order, and these cells are also columns 0 .. rows - 1 in that order; local[c] is the
/// column of global cell c (the others read: rows .. cols - 1; -1: c is no column here). Without
/// a numbering, the Jacobian is the whole square one in global numbering.
struct jacobian_numbering {
  std::vector<char> blocks;          // one entry per block: rows of this block are assembled
  std::vector<Eigen::Index> local;   // n_cells() entries
  Eigen::Index rows = 0, cols = 0;   // block rows and block columns
};

namespace internal {

/// Calls fn(b, d, k, f, cm, c0) for every face of every block (of the selected blocks only if
/// `blocks` is given): k = face index among the faces normal to d, f = its position along d,
/// cm/c0 the padded cells on its -/+ side.
template <int Dim, class Fn>
void for_each_face(const euler_model<Dim>& m, Fn&& fn, const std::vector<char>* blocks = nullptr) {
  const auto& met = m.metrics();
  for (int b = 0; b < static_cast<int>(met.blocks.size()); ++b) {
    if (blocks && !(*blocks)[b]) continue;
    const auto& mb = met.blocks[b];
    for (int d = 0; d < Dim; ++d) {
      const auto fd = mb.face_dims(d);
      const std::size_t nf = product<Dim>(fd), stride = m.stride(b, d);
      for (std::size_t k = 0; k < nf; ++k) {
        auto p = unravel<Dim>(k, fd);
        const int f = p[d];
        for (int e = 0; e < Dim; ++e) p[e] += euler_model<Dim>::halo_width;
        const std::size_t c0 = linear_index<Dim>(p, m.padded_dims(b));
        fn(b, d, k, f, c0 - stride, c0);
      }
    }
  }
}

/// Global column of a padded cell (its donor's if it is a halo cell).
template <int Dim>
Eigen::Index column_of(const euler_model<Dim>& m, int b, std::size_t padded) {
  const long long o = m.padded_owner(b, padded);
  require(o != euler_model<Dim>::unused_cell, "jacobian: stencil reaches an unused corner halo cell");
  if (o >= 0) return static_cast<Eigen::Index>(o);
  const auto& h = m.halos()[static_cast<std::size_t>(-1 - o)];
  return static_cast<Eigen::Index>(m.cell_offset(h.donor_block) + h.donor);
}

/// All global columns a padded cell depends on (one, or two for a wall ghost).
template <int Dim>
std::vector<Eigen::Index> columns_of(const euler_model<Dim>& m, int b, std::size_t padded) {
  const long long o = m.padded_owner(b, padded);
  if (o >= 0) return {static_cast<Eigen::Index>(o)};
  require(o != euler_model<Dim>::unused_cell, "jacobian: stencil reaches an unused corner halo cell");
  const auto& h = m.halos()[static_cast<std::size_t>(-1 - o)];
  const auto base = static_cast<Eigen::Index>(m.cell_offset(h.donor_block));
  return {base + static_cast<Eigen::Index>(h.donor), base + static_cast<Eigen::Index>(h.donor2)};
}

}  // namespace internal

/// Block pattern (cell row, cell column) of the chosen Jacobian.
template <int Dim>
std::vector<std::pair<Eigen::Index, Eigen::Index>> jacobian_pattern(const euler_model<Dim>& m, jacobian_kind kind,
                                                                    const jacobian_numbering* num = nullptr) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pairs;
  const bool wide = kind == jacobian_kind::exact && m.options().order == 2;
  const auto to = [&](Eigen::Index c) { return num ? num->local[static_cast<std::size_t>(c)] : c; };
  for (std::size_t b = 0; b < m.grid().topology.cells.size(); ++b) {
    if (num && !num->blocks[b]) continue;
    for (std::size_t c = m.cell_offset(static_cast<int>(b)); c < m.cell_offset(static_cast<int>(b) + 1); ++c)
      pairs.emplace_back(to(static_cast<Eigen::Index>(c)), to(static_cast<Eigen::Index>(c)));
  }
  internal::for_each_face<Dim>(
      m,
      [&](int b, int d, std::size_t, int f, std::size_t cm, std::size_t c0) {
        const std::size_t s = m.stride(b, d);
        std::vector<std::size_t> sten{cm, c0};
        if (wide) sten = {cm - s, cm, c0, c0 + s};
        const int n = m.metrics().blocks[b].cells[d];
        for (std::size_t q : sten) {
          for (const auto col : internal::columns_of<Dim>(m, b, q)) {
            if (f > 0) pairs.emplace_back(to(internal::column_of<Dim>(m, b, cm)), to(col));
            if (f < n) pairs.emplace_back(to(internal::column_of<Dim>(m, b, c0)), to(col));
          }
        }
      },
      num ? &num->blocks : nullptr);
  return pairs;
}

/// Assembles dR/dw (R = dw/dt) at state w into a (pattern set here if a is empty or has the
/// wrong size, otherwise reused with set_zero()). The size and the physical state of w are
/// checked before a is touched.
///
/// With a numbering `num`, only the rows of the selected blocks are assembled, in its local rows
/// and columns (each entry bitwise the whole Jacobian's); w is then read only at the cells of
/// those blocks and at the donors of their halos (euler_model::residual_of_blocks).
template <int Dim>
void assemble_jacobian(const euler_model<Dim>& m, const vec<double>& w, jacobian_kind kind,
                       block_sparse_matrix<double, Dim + 2>& a, const jacobian_numbering* num = nullptr) {
  constexpr int nv = Dim + 2;
  using block = Eigen::Matrix<double, nv, nv>;
  require_size(w.size(), m.size(), "assemble_jacobian", "state");
  const auto ncell = static_cast<Eigen::Index>(m.n_cells());
  if (num) {
    require_size(num->blocks.size(), m.grid().topology.cells.size(), "assemble_jacobian", "numbering's blocks");
    require_size(num->local.size(), m.n_cells(), "assemble_jacobian", "numbering's columns");
    Eigen::Index row = 0;
    for (std::size_t b = 0; b < num->blocks.size(); ++b)
      for (std::size_t c = m.cell_offset(static_cast<int>(b)); c < m.cell_offset(static_cast<int>(b) + 1); ++c) {
        const Eigen::Index l = num->local[c];
        require(num->blocks[b] ? l == row++ : l < 0 || (l >= num->rows && l < num->cols), "assemble_jacobian: the "
                "numbering gives cell ", c, " column ", l, " (selected blocks' cells: 0 ..", num->rows - 1,
                " in order; others: ", num->rows, " .. ", num->cols - 1, " or -1)");
      }
    require(row == num->rows, "assemble_jacobian: the numbering has ", num->rows, " rows, the selected blocks ", row,
            " cells");
    m.template require_physical<double>(w.data(), num->blocks, "assemble_jacobian");
  } else {
    m.template require_physical<double>(w.data(), "assemble_jacobian");
  }
  const Eigen::Index nrow = num ? num->rows : ncell, ncol = num ? num->cols : ncell;
  if (a.block_rows() != nrow || a.block_cols() != ncol) a.set_pattern(nrow, ncol, jacobian_pattern<Dim>(m, kind, num));
  a.set_zero(false);
  const auto to = [&](Eigen::Index c) { return num ? num->local[static_cast<std::size_t>(c)] : c; };
  const auto& met = m.metrics();
  std::vector<std::vector<state<double, Dim>>> padded;
  m.template fill_padded<double>(met, w.data(), padded, num ? &num->blocks : nullptr);

  // dg/dw_donor of every halo cell (identity across interfaces): one jet pass per donor, the nv
  // directions being the donor's nv unknowns.
  using halo_jet = jet<double, nv>;
  const auto jet_metrics = euler_model<Dim>::template convert_metrics<halo_jet>(met);
  std::vector<block> dhalo(m.halos().size()), dhalo2(m.halos().size());
  for (std::size_t k = 0; k < m.halos().size(); ++k) {
    const auto& h = m.halos()[k];
    if (num && !num->blocks[h.block]) continue;
    if (h.kind == boundary_kind::interface) {
      dhalo[k].setIdentity();
      continue;
    }
    const double* src = w.data() + (m.cell_offset(h.donor_block) + h.donor) * nv;
    const double* src2 = w.data() + (m.cell_offset(h.donor_block) + h.donor2) * nv;
    state<halo_jet, Dim> donor, donor2, c1, c2;
    for (int u = 0; u < nv; ++u) {
      donor[u] = halo_jet::variable(src[u], u);
      c2[u] = halo_jet(src2[u]);
      c1[u] = halo_jet(src[u]);
      donor2[u] = halo_jet::variable(src2[u], u);
    }
    const auto g = m.template halo_state<halo_jet>(h, donor, c2, jet_metrics);
    for (int u = 0; u < nv; ++u)
      for (int v = 0; v < nv; ++v) dhalo[k](u, v) = g[u].derivative(v);
    if (h.donor2 != h.donor) {
      const auto g2 = m.template halo_state<halo_jet>(h, c1, donor2, jet_metrics);
      for (int u = 0; u < nv; ++u)
        for (int v = 0; v < nv; ++v) dhalo2[k](u, v) = g2[u].derivative(v);
    }
  }

  auto add_column = [&](int b, std::size_t padded_cell, Eigen::Index row, const block& d, double scale) {
    const long long o = m.padded_owner(b, padded_cell);
    if (o >= 0) {
      a.block(row, to(static_cast<Eigen::Index>(o))) += scale * d;
    } else {
      const auto hk = static_cast<std::size_t>(-1 - o);
      const auto& h = m.halos()[hk];
      a.block(row, to(static_cast<Eigen::Index>(m.cell_offset(h.donor_block) + h.donor))) += scale * (d * dhalo[hk]);
      if (h.donor2 != h.donor)
        a.block(row, to(static_cast<Eigen::Index>(m.cell_offset(h.donor_block) + h.donor2))) +=
            scale * (d * dhalo2[hk]);
    }
  };
  const bool exact2 = kind == jacobian_kind::exact && m.options().order == 2;
  const bool muscl = m.options().order == 2;
  const double eps = m.options().limiter_eps;

  internal::for_each_face<Dim>(m, [&](int b, int d, std::size_t k, int f, std::size_t cm, std::size_t c0) {
    const auto& mb = met.blocks[b];
    const std::size_t s = m.stride(b, d);
    const auto& pb = padded[b];
    const int n = mb.cells[d];
    const Eigen::Index row_m = f > 0 ? to(internal::column_of<Dim>(m, b, cm)) : -1;
    const Eigen::Index row_p = f < n ? to(internal::column_of<Dim>(m, b, c0)) : -1;
    const double vol_m = f > 0 ? mb.volume[m.interior_index(b, cm)] : 1.0;
    const double vol_p = f < n ? mb.volume[m.interior_index(b, c0)] : 1.0;
    auto scatter = [&](std::size_t cell, const block& dflux) {
      if (row_m >= 0) add_column(b, cell, row_m, dflux, -1.0 / vol_m);
      if (row_p >= 0) add_column(b, cell, row_p, dflux, 1.0 / vol_p);
    };
    const int wall = m.wall_side(b, d, k);
    if (exact2 || wall != 0) {
      // one jet pass: derivatives with respect to the 4 nv unknowns of the stencil
      using D4 = jet<double, 4 * nv>;
      const std::size_t sten[4] = {cm - s, cm, c0, c0 + s};
      std::array<primitive<D4, Dim>, 4> qs;
      for (int p = 0; p < 4; ++p) {
        state<D4, Dim> wd;
        for (int u = 0; u < nv; ++u) wd[u] = D4::variable(pb[sten[p]][u], p * nv + u);
        qs[p] = to_primitive<D4, Dim>(wd);
      }
      std::array<D4, Dim> area_d;
      for (int e = 0; e < Dim; ++e) area_d[e] = D4(mb.normal[d][k][e]);
      const auto fl = m.template face_flux4<D4>(qs[0], qs[1], qs[2], qs[3], area_d, D4(mb.speed[d][k]), wall);
      for (int p = 0; p < 4; ++p) {
        block dflux;
        for (int u = 0; u < nv; ++u)
          for (int v = 0; v < nv; ++v) dflux(u, v) = fl[u].derivative(p * nv + v);
        scatter(sten[p], dflux);
      }
    } else {
      // states on both sides of the face (MUSCL states for the modified-order Jacobian)
      primitive<double, Dim> ql = to_primitive<double, Dim>(pb[cm]), qr = to_primitive<double, Dim>(pb[c0]);
      if (muscl) {
        ql = muscl_left<double, Dim>(to_primitive<double, Dim>(pb[cm - s]), ql, qr, eps);
        qr = muscl_right<double, Dim>(to_primitive<double, Dim>(pb[cm]), qr, to_primitive<double, Dim>(pb[c0 + s]), eps);
      }
      const auto wl = to_conservative<double, Dim>(ql), wr = to_conservative<double, Dim>(qr);
      using D2 = jet<double, 2 * nv>;
      state<D2, Dim> wld, wrd;
      for (int u = 0; u < nv; ++u) {
        wld[u] = D2::variable(wl[u], u);
        wrd[u] = D2::variable(wr[u], nv + u);
      }
      std::array<D2, Dim> area_d;
      for (int e = 0; e < Dim; ++e) area_d[e] = D2(mb.normal[d][k][e]);
      const auto fl = osher_flux<D2, Dim>(to_primitive<D2, Dim>(wld), to_primitive<D2, Dim>(wrd), area_d,
                                          D2(mb.speed[d][k]), nullptr, m.options().contact_smoothing);
      block dl, dr;
      for (int u = 0; u < nv; ++u)
        for (int v = 0; v < nv; ++v) {
          dl(u, v) = fl[u].derivative(v);
          dr(u, v) = fl[u].derivative(nv + v);
        }
      scatter(cm, dl);
      scatter(c0, dr);
    }
    // ALE term: row cm gets -(w_cm q)/V, row c0 gets +(w_c0 q)/V.
    const double qd = mb.speed[d][k];
    if (qd != 0.0) {
      if (row_m >= 0) a.block(row_m, row_m).diagonal().array() -= qd / vol_m;
      if (row_p >= 0) a.block(row_p, row_p).diagonal().array() += qd / vol_p;
    }
  }, num ? &num->blocks : nullptr);
}

}  // namespace aerohopf::flow
