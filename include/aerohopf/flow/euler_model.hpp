#pragma once
// Cell-centred finite-volume Euler residual on moving structured multi-block grids, one
// dimension-generic implementation for 2D (4 unknowns per cell) and 3D (5).
//
// Equations. For a cell of volume V with faces f (outward area vectors S_f, face volume fluxes
// q_f = integral of x_g . dS), the ALE equations d(V w)/dt = -sum_f F_f with
// F_f = w (u.S_f - q_f) + p (0, S_f, u.S_f), together with the geometric conservation law
// dV/dt = sum_f q_f (exact for our metrics, see metrics.hpp), give
//     dw/dt = R(w) = -(1/V) sum_f (F_f + w_cell q_f).
// This is the residual computed here (sign: R is the ODE right-hand side). Written this way
// a uniform flow is preserved EXACTLY on any closed grid with any motion: F_f(w_inf) sums to
// F(w_inf) . sum_f S_f - w_inf sum_f q_f, cancelled by w_inf sum_f q_f. On rigid motion
// (pitch/plunge) sum_f q_f = 0 and it reduces to the conservative form.
// Non-dimensionalisation: see gas.hpp (chord, rho_inf, U_inf; p_inf = 1/(gamma M^2)).
//
// Discretisation: Osher flux (osher_flux.hpp) between MUSCL/van Albada states of the
// primitive variables (muscl.hpp), dimension by dimension, so each face flux depends on the 4
// cells along its grid line and each cell row of the exact Jacobian has 4 Dim + 1 blocks.
// Boundaries use 2 layers of halo cells; every halo cell is a function of at most two interior
// cells (its donors): a copy across block interfaces (incl. the C-grid wake cut), a mirror
// image for a moving slip wall (velocity reflected relative to the wall's normal speed,
// pressure extrapolated from the two wall cells), and the Riemann-invariant far-field state
// built from the adjacent interior cell. The slip-wall face itself carries the pure pressure
// flux with p_w = (3 p_0 - p_1)/2. The Jacobians (jacobian.hpp) add the chain-rule terms
// dF/dw_halo * dw_halo/dw_donor.
//
// Scalars: residual() is a template, so double, dd_real, qd_real and taylor<> states AND
// grids (metrics computed from taylor<> points, e.g. a grid moved by a structural state) flow
// through the same code.
#include <Eigen/Core>

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../scalar/traits.hpp"
#include "gas.hpp"
#include "metrics.hpp"
#include "muscl.hpp"
#include "osher_flux.hpp"
#include "structured_grid.hpp"

namespace aerohopf::flow {

namespace internal {
template <class S, int Dim>
std::array<double, Dim> face_centre(const grid_block<S, Dim>& g, int d, const index_d<Dim>& p) {
  const auto c = face_corners<Dim>(d, p);
  std::array<double, Dim> m{};
  for (const auto& ci : c)
    for (int e = 0; e < Dim; ++e) m[e] += to_double(g.at(ci)[e]) / double(c.size());
  return m;
}
}  // namespace internal

struct euler_options {
  int order = 2;                   // 1: piecewise-constant states, 2: MUSCL / van Albada
  double limiter_eps = 1e-3;       // eps of the van Albada limiter (variables are O(1))
  /// delta of the smoothed contact switches (0: exact switches): the Osher flux's choice of
  /// intermediate state by the sign of the contact speed (osher_flux.hpp) and the far field's
  /// upwinding of entropy and tangential velocity by the sign of the normal velocity. Set it
  /// (e.g. 0.05) for centre-manifold reductions at a symmetric equilibrium: its wake cut and
  /// the C-grid's outer boundary parallel to the free stream sit exactly on the switches, and
  /// the residual is otherwise not twice differentiable there.
  double contact_smoothing = 0.0;
  std::array<double, 3> moment_centre{0.25, 0.0, 0.0};  // reference point of the moment
  std::string force_tag;           // walls whose forces are integrated ("" = all walls)
  /// Slip-wall flux. extrapolated: pure pressure flux (0, p_w S, p_w q) with the wall pressure
  /// extrapolated linearly from the two adjacent cells, p_w = (3 p_0 - p_1)/2 (zero mass flux
  /// exactly; keeps the normal pressure gradient that wall curvature requires, which the
  /// mirror image cannot: far less spurious entropy at a leading edge resolved by only 0.01 c
  /// cells). riemann: Osher flux between the cell and its mirror image.
  enum class wall_flux { extrapolated, riemann } wall = wall_flux::extrapolated;
  /// Wall ghost cells: mirror (same pressure and density) or extrapolated_pressure (see
  /// euler_model::halo_state).
  enum class wall_ghost_kind { mirror, extrapolated_pressure } wall_ghost = wall_ghost_kind::extrapolated_pressure;
  /// 2D only: far-field state = free stream plus the compressible point vortex of the current
  /// circulation (set_circulation), centred at moment_centre (Thomas & Salas, AIAA J. 24(7),
  /// 1986). Removes most of the lift error of a near far field (15 chords). The circulation is
  /// a PARAMETER of the residual (the Jacobians do not differentiate it); solve_steady updates
  /// it to CL/2 every step, so at convergence it is consistent.
  bool vortex_far_field = false;
};

/// Force and moment coefficients (reference length 1, reference area 1 (2D: per unit span),
/// dynamic pressure 1/2): CL normal to the free stream, CD along it, CM nose-up about the
/// moment centre (2D: about the z axis; 3D: the three components of the moment).
struct force_coefficients {
  double cl = 0.0, cd = 0.0, cm = 0.0;
  std::array<double, 3> force{};   // body-axis force coefficients
  std::array<double, 3> moment{};  // moment coefficients about moment_centre
};

template <int Dim>
class euler_model {
 public:
  static constexpr int nv = Dim + 2;
  static constexpr int halo_width = 2;

  /// One halo cell: padded index in its block, the interior donor and how it is derived.
  struct halo_cell {
    int block;
    std::size_t padded;
    int donor_block;
    std::size_t donor;  // interior linear index in donor_block
    std::size_t donor2; // second donor (same block): the other of the two wall cells; = donor otherwise
    std::size_t patch_face;  // index into the far-field face centres
    boundary_kind kind;
    int dir;            // normal axis of the boundary face
    std::size_t face;   // index among the faces normal to dir (wall / far field)
    int sign;           // +1 if +dir points out of the block
    int patch;
  };

  euler_model(multiblock_grid<Dim> grid, free_stream fs, euler_options opt = {})
      : grid_(std::move(grid)), fs_(fs), opt_(opt) {
    require(opt_.order == 1 || opt_.order == 2, "euler_model: order ", opt_.order, " must be 1 or 2");
    check_free_stream(fs_, "euler_model");
    require(grid_.topology.cells.size() == grid_.points.blocks.size(), "euler_model: topology has ",
            grid_.topology.cells.size(), " blocks, grid has ", grid_.points.blocks.size());
    for (std::size_t b = 0; b < grid_.points.blocks.size(); ++b)
      require(grid_.topology.cells[b] == grid_.points.blocks[b].cells(), "euler_model: block ", b,
              " cell counts differ between topology and points");
    metrics_ = compute_metrics<double, Dim>(grid_.points);
    build_layout();
    build_halos();
  }

  const multiblock_grid<Dim>& grid() const { return grid_; }
  const free_stream& conditions() const { return fs_; }
  const euler_options& options() const { return opt_; }
  const grid_metrics<double, Dim>& metrics() const { return metrics_; }
  std::size_t n_cells() const { return offset_.back(); }
  Eigen::Index size() const { return static_cast<Eigen::Index>(n_cells() * nv); }
  std::size_t cell_offset(int block) const { return offset_[block]; }
  /// "block b cell (i,j[,k])" of state cell `global` (< n_cells()), for messages.
  std::string cell_name(std::size_t global) const {
    require(global < n_cells(), "euler_model::cell_name: cell ", global, " of ", n_cells());
    std::size_t b = 0;
    while (global >= offset_[b + 1]) ++b;
    const auto c = unravel<Dim>(global - offset_[b], grid_.topology.cells[b]);
    std::string s = aerohopf::internal::concat("block ", b, " cell (");
    for (int e = 0; e < Dim; ++e) s += aerohopf::internal::concat(e ? "," : "", c[e]);
    return s + ")";
  }
  const std::vector<halo_cell>& halos() const { return halos_; }

  /// Moves the grid: new points and point velocities (the model's block count and shapes; see
  /// compute_metrics for the velocities). Validated (shapes, positive volumes) before anything
  /// is changed.
  void set_grid_motion(const multiblock_points<double, Dim>& points, const multiblock_points<double, Dim>* velocities) {
    require_size(points.blocks.size(), grid_.points.blocks.size(), "euler_model::set_grid_motion",
                 "the block list of the points (blocks)");
    for (std::size_t b = 0; b < points.blocks.size(); ++b)
      require(points.blocks[b].points == grid_.points.blocks[b].points, "euler_model::set_grid_motion: block ", b,
              " has a different shape from the model's");
    auto m = compute_metrics<double, Dim>(points, velocities);
    grid_.points = points;
    metrics_ = std::move(m);
    for (const auto& h : halos_) {
      const auto p = unravel<Dim>(h.face, metrics_.blocks[h.block].face_dims(h.dir));
      far_centre_[h.patch_face] = internal::face_centre<double, Dim>(grid_.points.blocks[h.block], h.dir, p);
    }
  }

  /// Sets the free stream (Mach number, angles) in place: grid, metrics, halos and layout do not
  /// depend on it and are kept (a family of models over Mach shares them; rebuilding costs more
  /// than a residual on the NACA 0012 grids). Nothing derived from the free stream is cached:
  /// free-stream states, far-field states and p_inf are computed from conditions() where used,
  /// so the model is then the same, bit for bit, as one constructed with fs. The circulation of
  /// the far-field vortex (set_circulation) is a separate parameter and is kept. Validated like
  /// the constructor (Mach positive and finite, angles finite); on refusal the model is unchanged.
  void set_free_stream(const free_stream& fs) {
    check_free_stream(fs, "euler_model::set_free_stream");
    fs_ = fs;
  }

  /// Circulation of the far-field point vortex (used with options().vortex_far_field).
  void set_circulation(double gamma) {
    require(std::isfinite(gamma), "euler_model::set_circulation: circulation ", gamma, " is not finite");
    circulation_ = gamma;
  }
  double circulation() const { return circulation_; }

  /// Free stream plus the compressible point vortex (2D): isentropic, same total enthalpy.
  primitive<double, Dim> vortex_free_stream(const std::array<double, Dim>& x) const {
    const double m = fs_.mach, a = fs_.alpha_rad, beta = std::sqrt(1.0 - m * m);
    const double dx = x[0] - opt_.moment_centre[0], dy = x[1] - opt_.moment_centre[1];
    const double r = std::hypot(dx, dy), th = std::atan2(dy, dx);
    const double s = std::sin(th - a);
    const double k = circulation_ * beta / (2.0 * std::numbers::pi * r * (1.0 - m * m * s * s));
    primitive<double, Dim> q{};
    q.u[0] = std::cos(a) + k * std::sin(th);
    q.u[1] = std::sin(a) - k * std::cos(th);
    const double cinf2 = 1.0 / (m * m);
    const double c2 = cinf2 + 0.5 * (gamma_gas - 1.0) * (1.0 - q.u[0] * q.u[0] - q.u[1] * q.u[1]);
    q.rho = std::pow(c2 / cinf2, 1.0 / (gamma_gas - 1.0));
    q.p = fs_.pressure() * std::pow(c2 / cinf2, gamma_gas / (gamma_gas - 1.0));
    return q;
  }

  /// Uniform free-stream state vector.
  template <class S = double>
  vec<S> free_stream_vector() const {
    const auto w = fs_.conservative_state<S, Dim>();
    vec<S> v(size());
    for (std::size_t c = 0; c < n_cells(); ++c)
      for (int k = 0; k < nv; ++k) v[static_cast<Eigen::Index>(c * nv + k)] = w[k];
    return v;
  }

  /// Every entry point that takes a state (residuals, Jacobians, spectral radius, forces)
  /// checks its size (require_size; Eigen's assertions are off in Release builds) and refuses
  /// a cell whose density or pressure is not positive and finite (require_physical): such a
  /// state has a NaN sound speed that turns every wave-sign test of the Osher flux false, which
  /// gives finite garbage and no error. The physical check is one pass over the state, under 1%
  /// of a residual evaluation (double or taylor<>), so it is never skipped.
  ///
  /// An interior cell whose density or pressure is not positive and finite.
  struct state_defect {
    int block;
    index_d<Dim> cell;   // (i, j[, k]) within the block
    std::size_t global;  // cell number in the state vector (values global * nv ...)
    double density, pressure;
  };

  /// First interior cell of w (n_cells() * nv values, not checked: internal) whose density or
  /// pressure is not positive and finite, judged on the value part of the scalar (to_double:
  /// the constant term of a taylor<> jet, the leading double of dd_real / qd_real). The one
  /// physical-state test of the flow layer: is_physical() (a solver's acceptance of a step) and
  /// require_physical() (the entry checks) both are this. NaN anywhere in a cell's state fails
  /// it (!(x > 0)).
  template <class S>
  std::optional<state_defect> first_nonphysical_cell(const S* w) const {
    for (std::size_t b = 0; b + 1 < offset_.size(); ++b)
      for (std::size_t c = offset_[b]; c < offset_[b + 1]; ++c)
        if (auto d = cell_defect<S>(w, static_cast<int>(b), c)) return d;
    return std::nullopt;
  }

  /// As first_nonphysical_cell, over the cells a block-restricted residual reads: those of the
  /// selected blocks (blocks[b] != 0), then the donors of their halos in other blocks.
  template <class S>
  std::optional<state_defect> first_nonphysical_cell(const S* w, const std::vector<char>& blocks) const {
    for (std::size_t b = 0; b + 1 < offset_.size(); ++b)
      if (blocks[b])
        for (std::size_t c = offset_[b]; c < offset_[b + 1]; ++c)
          if (auto d = cell_defect<S>(w, static_cast<int>(b), c)) return d;
    for (const auto& h : halos_)
      if (blocks[h.block] && !blocks[h.donor_block])
        for (const std::size_t c : {offset_[h.donor_block] + h.donor, offset_[h.donor_block] + h.donor2})
          if (auto d = cell_defect<S>(w, h.donor_block, c)) return d;
    return std::nullopt;
  }

  /// true if w has the model's size and every cell positive, finite density and pressure.
  template <class S>
  bool is_physical(const vec<S>& w) const {
    require_size(w.size(), size(), "euler_model::is_physical", "state");
    return !first_nonphysical_cell<S>(w.data());
  }

  /// Throws input_error("<where>: block b cell (i,j[,k]) (state cell c): density .., pressure ..
  /// ...") for the first non-physical cell of w (n_cells() * nv values, not checked).
  template <class S>
  void require_physical(const S* w, std::string_view where) const {
    report_defect(first_nonphysical_cell<S>(w), where);
  }

  /// require_physical over the cells a block-restricted residual reads (see residual_of_blocks).
  template <class S>
  void require_physical(const S* w, const std::vector<char>& blocks, std::string_view where) const {
    report_defect(first_nonphysical_cell<S>(w, blocks), where);
  }

 private:
  template <class S>
  std::optional<state_defect> cell_defect(const S* w, int b, std::size_t c) const {
    state<double, Dim> s;
    for (int v = 0; v < nv; ++v) s[v] = to_double(w[c * nv + v]);
    const auto q = to_primitive<double, Dim>(s);
    if (q.rho > 0.0 && q.p > 0.0 && std::isfinite(q.rho) && std::isfinite(q.p)) return std::nullopt;
    return state_defect{b, unravel<Dim>(c - offset_[b], grid_.topology.cells[b]), c, q.rho, q.p};
  }

  void report_defect(const std::optional<state_defect>& d, std::string_view where) const {
    if (!d) return;
    throw input_error(aerohopf::internal::concat(where, ": ", cell_name(d->global), " (state cell ", d->global,
                                                 "): density ", d->density, ", pressure ", d->pressure,
                                                 ": not a physical state (both must be positive and finite)"));
  }

 public:

  /// R(w) with the model's own (double) metrics. Checks the size and the physical state of w.
  template <class S>
  vec<S> residual(const vec<S>& w) const {
    require_size(w.size(), size(), "euler_model::residual", "state");
    vec<S> r(size());
    if constexpr (std::is_same_v<S, double>) {
      residual<S>(metrics_, w.data(), r.data());
    } else {
      residual<S>(convert_metrics<S>(metrics_), w.data(), r.data());
    }
    return r;
  }

  /// R(w) with given metrics (e.g. of a grid moved by a taylor<> structural state). Checks the
  /// metrics' shapes, the size and the physical state of w.
  template <class S>
  vec<S> residual(const grid_metrics<S, Dim>& m, const vec<S>& w) const {
    require_size(w.size(), size(), "euler_model::residual", "state");
    vec<S> r(size());
    residual<S>(m, w.data(), r.data());
    return r;
  }

  /// Internal form: w and r point to at least size() values each (NOT checked; a coupled
  /// system passes the flow part of its longer state this way). The metrics and the physical
  /// state of the size() values read are checked.
  template <class S>
  void residual(const grid_metrics<S, Dim>& m, const S* w, S* r) const {
    check_metrics(m);
    require_physical<S>(w, "euler_model::residual");
    residual_unchecked<S>(m, w, r, nullptr);
  }

  /// R(w) in the cells of the selected blocks only (blocks[b] != 0, one entry per block); the
  /// values of r at other blocks' cells are left as they were. This is the evaluation of one
  /// rank that owns those blocks (distributed/partition.hpp): w must hold the states of the
  /// selected blocks' cells and of the donors of their halos (halo_plan lists those in other
  /// blocks); no other cell of w is read. Each selected cell's value is bitwise the full
  /// residual's. Checks the metrics, the selection's size and the physical state of the cells
  /// read.
  template <class S>
  void residual_of_blocks(const grid_metrics<S, Dim>& m, const S* w, S* r, const std::vector<char>& blocks) const {
    check_metrics(m);
    require_size(blocks.size(), pdims_.size(), "euler_model::residual_of_blocks", "block selection");
    require_physical<S>(w, blocks, "euler_model::residual_of_blocks");
    residual_unchecked<S>(m, w, r, &blocks);
  }

 private:
  template <class S>
  void residual_unchecked(const grid_metrics<S, Dim>& m, const S* w, S* r, const std::vector<char>* selected) const {
    std::vector<std::vector<state<S, Dim>>> padded;
    fill_padded<S>(m, w, padded, selected);
    std::vector<std::vector<primitive<S, Dim>>> prim(padded.size());
    for (std::size_t b = 0; b < padded.size(); ++b) {
      prim[b].resize(padded[b].size());
      for (std::size_t k = 0; k < padded[b].size(); ++k) prim[b][k] = to_primitive<S, Dim>(padded[b][k]);
    }
    for (std::size_t b = 0; b < padded.size(); ++b) {
      if (selected && !(*selected)[b]) continue;
      for (std::size_t k = offset_[b] * nv; k < offset_[b + 1] * nv; ++k) r[k] = S(0.0);
    }
    for (std::size_t b = 0; b < padded.size(); ++b) {
      if (selected && !(*selected)[b]) continue;
      const auto& mb = m.blocks[b];
      const auto& pd = pdims_[b];
      S* rb = r + offset_[b] * nv;
      for (int d = 0; d < Dim; ++d) {
        const std::size_t stride = stride_[b][d];
        const auto fd = mb.face_dims(d);
        const std::size_t nf = product<Dim>(fd);
        for (std::size_t k = 0; k < nf; ++k) {
          auto p = unravel<Dim>(k, fd);
          const int f = p[d];
          for (int e = 0; e < Dim; ++e) p[e] += halo_width;
          const std::size_t c0 = linear_index<Dim>(p, pd);  // cell on the + side of the face
          const std::size_t cm = c0 - stride;               // cell on the - side
          const auto flux = face_flux<S>(prim[b], cm, stride, mb.normal[d][k], mb.speed[d][k], wall_side(b, d, k));
          const S& q = mb.speed[d][k];
          if (f > 0) {
            const std::size_t ic = interior_index(b, cm);
            for (int v = 0; v < nv; ++v) rb[ic * nv + v] -= flux[v] + padded[b][cm][v] * q;
          }
          if (f < mb.cells[d]) {
            const std::size_t ic = interior_index(b, c0);
            for (int v = 0; v < nv; ++v) rb[ic * nv + v] += flux[v] + padded[b][c0][v] * q;
          }
        }
      }
      for (std::size_t c = 0; c < mb.volume.size(); ++c)
        for (int v = 0; v < nv; ++v) rb[c * nv + v] /= mb.volume[c];
    }
  }

 public:

  /// Flux through the face between padded cells cm and cm + stride of one block.
  template <class S>
  state<S, Dim> face_flux(const std::vector<primitive<S, Dim>>& prim, std::size_t cm, std::size_t stride,
                          const std::array<S, Dim>& area, const S& q, int wall = 0) const {
    const std::size_t c0 = cm + stride;
    return face_flux4<S>(prim[cm - stride], prim[cm], prim[c0], prim[c0 + stride], area, q, wall);
  }

  /// 0 for a face that is not a slip wall with the extrapolated wall flux; otherwise +1 (-1) if
  /// the wall lies on the + (-) side of the face, i.e. the fluid is on the - (+) side.
  int wall_side(int b, int d, std::size_t k) const { return wall_flag_.empty() ? 0 : wall_flag_[b][d][k]; }

  /// Wall pressure extrapolated from the two fluid cells next to the wall.
  template <class S>
  static S wall_pressure(const primitive<S, Dim>& first, const primitive<S, Dim>& second) {
    return S(1.5) * first.p - S(0.5) * second.p;
  }

  /// Flux through a face from the 4 cells along the grid line (two on each side).
  template <class S>
  state<S, Dim> face_flux4(const primitive<S, Dim>& qmm, const primitive<S, Dim>& qm, const primitive<S, Dim>& qp,
                           const primitive<S, Dim>& qpp, const std::array<S, Dim>& area, const S& q,
                           int wall = 0, osher_star<S>* star = nullptr) const {
    if (wall != 0) {
      const S pw = wall > 0 ? wall_pressure<S>(qm, qmm) : wall_pressure<S>(qp, qpp);
      if (star) *star = {pw, S(0.0)};
      state<S, Dim> f;
      f[0] = S(0.0);
      for (int d = 0; d < Dim; ++d) f[1 + d] = pw * area[d];
      f[Dim + 1] = pw * q;
      return f;
    }
    if (opt_.order == 1) return osher_flux<S, Dim>(qm, qp, area, q, star, opt_.contact_smoothing);
    const auto ql = muscl_left<S, Dim>(qmm, qm, qp, opt_.limiter_eps);
    const auto qr = muscl_right<S, Dim>(qm, qp, qpp, opt_.limiter_eps);
    return osher_flux<S, Dim>(ql, qr, area, q, star, opt_.contact_smoothing);
  }

  /// Halo state of h from its donors' conservative states (the function whose derivative the
  /// Jacobians chain in). Wall ghosts: the velocity of the mirrored cell reflected about the
  /// moving wall; with wall_ghost::extrapolated_pressure the pressure continues the profile of
  /// the two wall cells geometrically, p_ghost(layer l) = p_0 (p_0 / p_1)^(l+1) (positive, and
  /// it keeps the normal pressure gradient that a curved wall needs in the MUSCL slopes of the
  /// first cells), and the density follows isentropically from the mirrored cell.
  template <class S>
  state<S, Dim> halo_state(const halo_cell& h, const state<S, Dim>& donor, const state<S, Dim>& donor2,
                           const grid_metrics<S, Dim>& m) const {
    if (h.kind == boundary_kind::interface) return donor;
    const auto& s = m.blocks[h.block].normal[h.dir][h.face];
    const S& q = m.blocks[h.block].speed[h.dir][h.face];
    using std::sqrt;
    const S a = sqrt(dot<S, Dim>(s, s));
    vector_d<S, Dim> n;
    for (int d = 0; d < Dim; ++d) n[d] = S(double(h.sign)) * s[d] / a;  // outward unit normal
    const S sn = S(double(h.sign)) * q / a;                            // outward wall speed
    auto qi = to_primitive<S, Dim>(donor);
    if (h.kind == boundary_kind::wall) {
      const S un = dot<S, Dim>(qi.u, n) - sn;
      for (int d = 0; d < Dim; ++d) qi.u[d] -= S(2.0) * un * n[d];
      if (opt_.wall_ghost == euler_options::wall_ghost_kind::extrapolated_pressure) {
        const int layer = padded_layer(h);
        const auto q2 = to_primitive<S, Dim>(donor2);
        const S& p0 = layer == 0 ? qi.p : q2.p;
        const S& p1 = layer == 0 ? q2.p : qi.p;
        const S pg = p0 * internal::power(p0 / p1, double(layer + 1));
        qi.rho *= internal::power(pg / qi.p, 1.0 / gamma_gas);
        qi.p = pg;
      }
      return to_conservative<S, Dim>(qi);
    }
    return to_conservative<S, Dim>(far_field_state<S>(qi, n, sn, &far_centre_[h.patch_face]));
  }

  /// Characteristic far-field state (1D Riemann invariants normal to the boundary, in the
  /// frame of the moving boundary; entropy and tangential velocity upwinded).
  template <class S>
  primitive<S, Dim> far_field_state(const primitive<S, Dim>& qi, const vector_d<S, Dim>& n, const S& sn,
                                    const std::array<double, Dim>* where = nullptr) const {
    constexpr double gm1 = gamma_gas - 1.0;
    auto qf = fs_.primitive_state<S, Dim>();
    if constexpr (Dim == 2) {
      if (where && opt_.vortex_far_field && circulation_ != 0.0) {
        const auto v = vortex_free_stream(*where);
        qf = {S(v.rho), {S(v.u[0]), S(v.u[1])}, S(v.p)};
      }
    }
    const S ci = sound_speed(qi), cf = sound_speed(qf);
    const S ui = dot<S, Dim>(qi.u, n) - sn, uf = dot<S, Dim>(qf.u, n) - sn;
    if (uf <= -cf) return qf;  // supersonic inflow
    if (ui >= ci) return qi;   // supersonic outflow
    const S rp = ui + S(2.0 / gm1) * ci, rm = uf - S(2.0 / gm1) * cf;
    const S ub = S(0.5) * (rp + rm), cb = S(0.25 * gm1) * (rp - rm);
    // Entropy and tangential velocity from the upwind side of the contact wave (speed ub):
    // weight wf of the free stream = H(-ub), or its logistic smoothing with the contact
    // smoothing delta (as in osher_flux.hpp: the outer boundary of a C-grid runs parallel to
    // the free stream, where ub = 0 and the switch would make the residual non-smooth).
    S wf = ub < S(0.0) ? S(1.0) : S(0.0);
    if (opt_.contact_smoothing > 0.0) {
      using std::exp;
      const S arg = ub / (S(opt_.contact_smoothing) * cb);
      if (arg < S(40.0) && arg > S(-40.0)) wf = S(1.0) / (S(1.0) + exp(S(2.0) * arg));
    }
    const S wi = S(1.0) - wf;
    const S entropy = wf * qf.p / internal::power(qf.rho, gamma_gas) + wi * qi.p / internal::power(qi.rho, gamma_gas);
    primitive<S, Dim> qb;
    qb.rho = internal::power(cb * cb / (S(gamma_gas) * entropy), 1.0 / gm1);
    qb.p = qb.rho * cb * cb / S(gamma_gas);
    for (int d = 0; d < Dim; ++d) qb.u[d] = wf * (qf.u[d] + (ub - uf) * n[d]) + wi * (qi.u[d] + (ub - ui) * n[d]);
    return qb;
  }

  /// A wall face that carries loads (its patch tagged options().force_tag, every wall if that is
  /// empty) with the two cells whose pressures make its wall pressure (3 p_0 - p_1) / 2.
  struct loaded_face {
    int block, dir, sign;     // as the halo's: normal axis, +1 if +dir points out of the block
    std::size_t face;         // index among the block's faces normal to dir
    Eigen::Index cell0, cell1;  // the wall cell and the next one inwards (global cell indices)
  };
  std::vector<loaded_face> loaded_faces() const {
    std::vector<loaded_face> out;
    for (const auto& h : halos_) {
      if (h.kind != boundary_kind::wall || padded_layer(h) != 0 || !tagged(h.patch)) continue;
      out.push_back({h.block, h.dir, h.sign, h.face, static_cast<Eigen::Index>(offset_[h.donor_block] + h.donor),
                     static_cast<Eigen::Index>(offset_[h.donor_block] + h.donor2)});
    }
    return out;
  }

  /// Wall pressures (Osher star pressure at each wall face) and force coefficients.
  struct wall_face {
    int block;
    std::array<double, Dim> centre;
    std::array<double, Dim> area_out;  // outward from the fluid (into the body)
    double pressure;
    double cp;
  };
  /// With `blocks` (one entry per block), the faces of the selected blocks only, reading the
  /// cells residual_of_blocks reads.
  std::vector<wall_face> wall_faces(const vec<double>& w, const std::vector<char>* blocks = nullptr) const {
    check_state_vector(w, "euler_model::wall_faces");
    if (blocks) require_size(blocks->size(), pdims_.size(), "euler_model::wall_faces", "block selection");
    std::vector<std::vector<state<double, Dim>>> padded;
    fill_padded<double>(metrics_, w.data(), padded, blocks);
    std::vector<wall_face> out;
    const double pinf = fs_.pressure();
    for (const auto& h : halos_) {
      if (h.kind != boundary_kind::wall || !tagged(h.patch)) continue;
      if (blocks && !(*blocks)[h.block]) continue;
      if (padded_layer(h) != 0) continue;
      const int b = h.block;
      // Local line of 4 cells across the face (cm - stride .. c0 + stride) in padded indexing.
      const std::size_t stride = stride_[b][h.dir];
      const std::size_t inner = h.sign > 0 ? h.padded - stride : h.padded + stride;
      const std::size_t cm = h.sign > 0 ? inner : h.padded;
      auto prim = [&](std::size_t c) { return to_primitive<double, Dim>(padded[b][c]); };
      osher_star<double> star{};
      (void)face_flux4<double>(prim(cm - stride), prim(cm), prim(cm + stride), prim(cm + 2 * stride),
                               metrics_.blocks[b].normal[h.dir][h.face], metrics_.blocks[b].speed[h.dir][h.face],
                               wall_side(b, h.dir, h.face), &star);
      wall_face f;
      f.block = b;
      f.pressure = star.pressure;
      f.cp = 2.0 * (star.pressure - pinf);
      const auto& s = metrics_.blocks[b].normal[h.dir][h.face];
      for (int d = 0; d < Dim; ++d) f.area_out[d] = h.sign * s[d];
      auto p = unravel<Dim>(h.face, metrics_.blocks[b].face_dims(h.dir));
      f.centre = internal::face_centre<double, Dim>(grid_.points.blocks[b], h.dir, p);
      out.push_back(f);
    }
    return out;
  }

  /// Force and moment coefficients of the tagged walls. With `blocks`, the walls of the
  /// selected blocks only: their force and moment are the parts of a partitioned grid, summed
  /// over the parts and turned into cl, cd, cm by coefficients().
  force_coefficients forces(const vec<double>& w, const std::vector<char>* blocks = nullptr) const {
    check_state_vector(w, "euler_model::forces");
    force_coefficients c;
    const double pinf = fs_.pressure();
    for (const auto& f : wall_faces(w, blocks)) {
      std::array<double, 3> fc{}, r{};
      for (int d = 0; d < Dim; ++d) {
        fc[d] = 2.0 * (f.pressure - pinf) * f.area_out[d];
        r[d] = f.centre[d] - opt_.moment_centre[d];
        c.force[d] += fc[d];
      }
      c.moment[0] += r[1] * fc[2] - r[2] * fc[1];
      c.moment[1] += r[2] * fc[0] - r[0] * fc[2];
      c.moment[2] += r[0] * fc[1] - r[1] * fc[0];
    }
    return coefficients(c.force, c.moment);
  }

  /// cl, cd, cm (wind axes of the free stream) from body-axis force and moment coefficients.
  force_coefficients coefficients(const std::array<double, 3>& force, const std::array<double, 3>& moment) const {
    force_coefficients c;
    c.force = force;
    c.moment = moment;
    const double ca = std::cos(fs_.alpha_rad), sa = std::sin(fs_.alpha_rad);
    if constexpr (Dim == 2) {
      c.cl = -c.force[0] * sa + c.force[1] * ca;
      c.cd = c.force[0] * ca + c.force[1] * sa;
      c.cm = -c.moment[2];  // nose-up positive: clockwise in the x-y plane
    } else {
      c.cl = -c.force[0] * sa + c.force[2] * ca;
      c.cd = c.force[0] * ca + c.force[2] * sa;
      c.cm = c.moment[1];   // about +y (span): nose-up positive for x aft, z up
    }
    return c;
  }

  /// Sum over the faces of a cell of (|u.n - s_n| + c) |S|: the local time step is
  /// CFL * V / this (spectral radius of the flux Jacobian, first-order states).
  /// With `blocks`, the selected blocks' cells only (the others stay 0), reading the cells
  /// residual_of_blocks reads.
  vec<double> spectral_radius(const vec<double>& w, const std::vector<char>* blocks = nullptr) const {
    check_state_vector(w, "euler_model::spectral_radius");
    if (blocks) require_size(blocks->size(), pdims_.size(), "euler_model::spectral_radius", "block selection");
    vec<double> rad = vec<double>::Zero(static_cast<Eigen::Index>(n_cells()));
    std::vector<std::vector<state<double, Dim>>> padded;
    fill_padded<double>(metrics_, w.data(), padded, blocks);
    for (std::size_t b = 0; b < padded.size(); ++b) {
      if (blocks && !(*blocks)[b]) continue;
      const auto& mb = metrics_.blocks[b];
      for (int d = 0; d < Dim; ++d) {
        const auto fd = mb.face_dims(d);
        const std::size_t nf = product<Dim>(fd), stride = stride_[b][d];
        for (std::size_t k = 0; k < nf; ++k) {
          auto p = unravel<Dim>(k, fd);
          const int f = p[d];
          for (int e = 0; e < Dim; ++e) p[e] += halo_width;
          const std::size_t c0 = linear_index<Dim>(p, pdims_[b]), cm = c0 - stride;
          const auto ql = to_primitive<double, Dim>(padded[b][cm]);
          const auto qr = to_primitive<double, Dim>(padded[b][c0]);
          const auto& s = mb.normal[d][k];
          const double a = std::sqrt(dot<double, Dim>(s, s));
          const double un = 0.5 * (dot<double, Dim>(ql.u, s) + dot<double, Dim>(qr.u, s)) - mb.speed[d][k];
          const double lam = std::abs(un) + 0.5 * (sound_speed(ql) + sound_speed(qr)) * a;
          if (f > 0) rad[static_cast<Eigen::Index>(offset_[b] + interior_index(b, cm))] += lam;
          if (f < mb.cells[d]) rad[static_cast<Eigen::Index>(offset_[b] + interior_index(b, c0))] += lam;
        }
      }
    }
    return rad;
  }

  // ---- layout helpers (public for the Jacobian assembly) ----
  const index_d<Dim>& padded_dims(int b) const { return pdims_[b]; }
  std::size_t stride(int b, int d) const { return stride_[b][d]; }
  /// For a padded cell: >= 0 global cell index of an interior cell, -1 - k for halo k, or
  /// unused_cell for corner halos (never referenced by the stencil).
  static constexpr long long unused_cell = -(1LL << 62);
  long long padded_owner(int b, std::size_t padded) const { return owner_[b][padded]; }
  std::size_t interior_index(int b, std::size_t padded) const {
    auto p = unravel<Dim>(padded, pdims_[b]);
    for (int e = 0; e < Dim; ++e) p[e] -= halo_width;
    return linear_index<Dim>(p, grid_.topology.cells[b]);
  }

  /// Fills per-block padded arrays (interior copied from w, halos derived from donors,
  /// unused corners set to the free stream). Internal: w must hold size() values (not checked;
  /// every public entry point checks before calling this).
  /// With `selected`, only the selected blocks (and their halos) are filled; the others are left
  /// empty.
  template <class S>
  void fill_padded(const grid_metrics<S, Dim>& m, const S* w, std::vector<std::vector<state<S, Dim>>>& padded,
                   const std::vector<char>* selected = nullptr) const {
    const auto winf = fs_.conservative_state<S, Dim>();
    padded.resize(pdims_.size());
    for (std::size_t b = 0; b < pdims_.size(); ++b) {
      if (selected && !(*selected)[b]) {
        padded[b].clear();
        continue;
      }
      padded[b].assign(product<Dim>(pdims_[b]), winf);
      const auto& cells = grid_.topology.cells[b];
      const std::size_t nc = product<Dim>(cells);
      for (std::size_t c = 0; c < nc; ++c) {
        auto p = unravel<Dim>(c, cells);
        for (int e = 0; e < Dim; ++e) p[e] += halo_width;
        auto& dst = padded[b][linear_index<Dim>(p, pdims_[b])];
        const S* src = w + (offset_[b] + c) * nv;
        for (int v = 0; v < nv; ++v) dst[v] = src[v];
      }
    }
    for (const auto& h : halos_) {
      if (selected && !(*selected)[h.block]) continue;
      state<S, Dim> donor, donor2;
      const S* src = w + (offset_[h.donor_block] + h.donor) * nv;
      const S* src2 = w + (offset_[h.donor_block] + h.donor2) * nv;
      for (int v = 0; v < nv; ++v) {
        donor[v] = src[v];
        donor2[v] = src2[v];
      }
      padded[h.block][h.padded] = halo_state<S>(h, donor, donor2, m);
    }
  }

  template <class S>
  static grid_metrics<S, Dim> convert_metrics(const grid_metrics<double, Dim>& m) {
    grid_metrics<S, Dim> r;
    r.blocks.resize(m.blocks.size());
    for (std::size_t b = 0; b < m.blocks.size(); ++b) {
      const auto& s = m.blocks[b];
      auto& t = r.blocks[b];
      t.cells = s.cells;
      t.volume.assign(s.volume.begin(), s.volume.end());
      for (int d = 0; d < Dim; ++d) {
        t.normal[d].resize(s.normal[d].size());
        for (std::size_t k = 0; k < s.normal[d].size(); ++k)
          for (int e = 0; e < Dim; ++e) t.normal[d][k][e] = S(s.normal[d][k][e]);
        t.speed[d].assign(s.speed[d].begin(), s.speed[d].end());
      }
    }
    return r;
  }

  /// Depth of a halo cell outside its boundary (0 = adjacent to the face).
  int padded_layer(const halo_cell& h) const {
    const auto p = unravel<Dim>(h.padded, pdims_[h.block]);
    const int i = p[h.dir] - halo_width;
    return h.sign > 0 ? i - grid_.topology.cells[h.block][h.dir] : -1 - i;
  }

 private:
  static void check_free_stream(const free_stream& fs, std::string_view who) {
    require(fs.mach > 0.0 && std::isfinite(fs.mach), who, ": Mach number ", fs.mach, " must be positive and finite");
    require(std::isfinite(fs.alpha_rad), who, ": angle of attack ", fs.alpha_rad, " rad is not finite");
    require(std::isfinite(fs.beta_rad), who, ": angle of sideslip ", fs.beta_rad, " rad is not finite");
  }

  bool tagged(int patch) const {
    return opt_.force_tag.empty() || grid_.topology.patches[patch].tag == opt_.force_tag;
  }

  /// Shapes of given metrics: the model's blocks and cells, and arrays of the sizes these imply
  /// (metrics are plain data a caller may have built or edited).
  template <class S>
  void check_metrics(const grid_metrics<S, Dim>& m) const {
    require(m.blocks.size() == pdims_.size(), "euler_model: metrics have ", m.blocks.size(), " blocks, model has ",
            pdims_.size());
    for (std::size_t b = 0; b < pdims_.size(); ++b) {
      const auto& mb = m.blocks[b];
      require(mb.cells == grid_.topology.cells[b], "euler_model: metrics of block ", b, " have a different shape");
      require(mb.volume.size() == product<Dim>(mb.cells), "euler_model: metrics of block ", b, " have ",
              mb.volume.size(), " volumes for ", product<Dim>(mb.cells), " cells");
      for (int d = 0; d < Dim; ++d) {
        const std::size_t nf = product<Dim>(mb.face_dims(d));
        require(mb.normal[d].size() == nf && mb.speed[d].size() == nf, "euler_model: metrics of block ", b, " have ",
                mb.normal[d].size(), " area vectors and ", mb.speed[d].size(), " face speeds normal to axis ", d,
                ", expected ", nf);
      }
    }
  }

  /// Size and physical state of a double state vector.
  void check_state_vector(const vec<double>& w, std::string_view where) const {
    require_size(w.size(), size(), where, "state");
    require_physical<double>(w.data(), where);
  }

  void build_layout() {
    const auto& cells = grid_.topology.cells;
    offset_.assign(cells.size() + 1, 0);
    pdims_.resize(cells.size());
    stride_.resize(cells.size());
    owner_.resize(cells.size());
    for (std::size_t b = 0; b < cells.size(); ++b) {
      for (int d = 0; d < Dim; ++d) {
        require(cells[b][d] >= 2, "euler_model: block ", b, " has ", cells[b][d], " cells along axis ", d,
                " (at least 2 needed for the MUSCL stencil)");
        pdims_[b][d] = cells[b][d] + 2 * halo_width;
      }
      std::size_t s = 1;
      for (int d = 0; d < Dim; ++d) {
        stride_[b][d] = s;
        s *= static_cast<std::size_t>(pdims_[b][d]);
      }
      offset_[b + 1] = offset_[b] + product<Dim>(cells[b]);
      owner_[b].assign(product<Dim>(pdims_[b]), unused_cell);
      for (std::size_t c = 0; c < product<Dim>(cells[b]); ++c) {
        auto p = unravel<Dim>(c, cells[b]);
        for (int e = 0; e < Dim; ++e) p[e] += halo_width;
        owner_[b][linear_index<Dim>(p, pdims_[b])] = static_cast<long long>(offset_[b] + c);
      }
    }
  }

  void build_halos() {
    const auto& cells = grid_.topology.cells;
    const int nb = static_cast<int>(cells.size());
    // coverage[b][face] counts how often each boundary face cell is claimed by a patch
    std::vector<std::array<std::vector<int>, 2 * Dim>> coverage(nb);
    for (int b = 0; b < nb; ++b)
      for (int f = 0; f < 2 * Dim; ++f) {
        auto fc = cells[b];
        fc[f / 2] = 1;
        coverage[b][f].assign(product<Dim>(fc), 0);
      }
    wall_flag_.assign(nb, {});
    for (int b = 0; b < nb; ++b)
      for (int d = 0; d < Dim; ++d) {
        auto fd = cells[b];
        fd[d] += 1;
        wall_flag_[b][d].assign(product<Dim>(fd), 0);
      }
    const auto& patches = grid_.topology.patches;
    for (int pi = 0; pi < static_cast<int>(patches.size()); ++pi) {
      const auto& pt = patches[pi];
      require(pt.block >= 0 && pt.block < nb && pt.face >= 0 && pt.face < 2 * Dim, "boundary patch ", pi,
              ": bad block ", pt.block, " or face ", pt.face);
      const int b = pt.block, d = pt.face / 2, side = pt.face % 2;
      const auto& n = cells[b];
      index_d<Dim> lo = pt.begin, hi = pt.end;
      lo[d] = 0;
      hi[d] = 1;
      for (int e = 0; e < Dim; ++e)
        require(e == d || (lo[e] >= 0 && hi[e] <= n[e] && lo[e] < hi[e]), "boundary patch ", pi, " (block ", b,
                ", face ", pt.face, "): range [", lo[e], ", ", hi[e], ") outside the ", n[e], " cells of axis ", e);
      int db = -1, dd = -1, dside = 0;
      if (pt.kind == boundary_kind::interface) {
        require(pt.donor_block >= 0 && pt.donor_block < nb && pt.donor_face >= 0 && pt.donor_face < 2 * Dim,
                "boundary patch ", pi, ": bad donor block ", pt.donor_block, " or face ", pt.donor_face);
        db = pt.donor_block;
        dd = pt.donor_face / 2;
        dside = pt.donor_face % 2;
        require(cells[db][dd] >= halo_width, "boundary patch ", pi, ": donor block ", db, " has only ",
                cells[db][dd], " cells normal to its face");
        std::array<bool, Dim> used{};
        for (int e = 0; e < Dim; ++e) {
          if (e == d) continue;
          const int t = pt.transform[e], be = std::abs(t) - 1;
          require(t != 0 && be >= 0 && be < Dim && be != dd && !used[be], "boundary patch ", pi,
                  ": invalid transform entry ", t, " for axis ", e);
          used[be] = true;
          require(pt.donor_end[be] - pt.donor_begin[be] == hi[e] - lo[e] && pt.donor_begin[be] >= 0 &&
                      pt.donor_end[be] <= cells[db][be],
                  "boundary patch ", pi, ": donor range along axis ", be, " does not match ", hi[e] - lo[e],
                  " cells");
        }
      }
      index_d<Dim> span;
      for (int e = 0; e < Dim; ++e) span[e] = hi[e] - lo[e];
      for (std::size_t k = 0; k < product<Dim>(span); ++k) {
        auto t = unravel<Dim>(k, span);
        for (int e = 0; e < Dim; ++e) t[e] += lo[e];
        index_d<Dim> cov = t;
        cov[d] = 0;
        auto fc = n;
        fc[d] = 1;
        coverage[b][pt.face][linear_index<Dim>(cov, fc)] += 1;
        index_d<Dim> c = t;
        c[d] = side ? n[d] - 1 : 0;
        const int out = side ? 1 : -1;
        index_d<Dim> fidx = t;
        fidx[d] = side ? n[d] : 0;
        auto fdims = n;
        fdims[d] += 1;
        for (int layer = 0; layer < halo_width; ++layer) {
          halo_cell h{};
          h.block = b;
          h.kind = pt.kind;
          h.dir = d;
          h.sign = out;
          h.patch = pi;
          h.face = linear_index<Dim>(fidx, fdims);
          index_d<Dim> hp = c;
          hp[d] += out * (layer + 1);
          for (int e = 0; e < Dim; ++e) hp[e] += halo_width;
          h.padded = linear_index<Dim>(hp, pdims_[b]);
          index_d<Dim> donor = c;
          h.donor_block = b;
          if (pt.kind == boundary_kind::wall) {
            donor[d] -= out * layer;
          } else if (pt.kind == boundary_kind::interface) {
            h.donor_block = db;
            for (int e = 0; e < Dim; ++e) {
              if (e == d) continue;
              const int tr = pt.transform[e], be = std::abs(tr) - 1;
              const int delta = t[e] - lo[e];
              donor[be] = tr > 0 ? pt.donor_begin[be] + delta : pt.donor_end[be] - 1 - delta;
            }
            donor[dd] = dside ? cells[db][dd] - 1 - layer : layer;
          }
          h.donor = linear_index<Dim>(donor, cells[h.donor_block]);
          h.donor2 = h.donor;
          if (pt.kind == boundary_kind::wall) {
            index_d<Dim> other = c;
            other[d] -= out * (1 - layer);
            h.donor2 = linear_index<Dim>(other, cells[b]);
          }
          owner_[b][h.padded] = -1 - static_cast<long long>(halos_.size());
          h.patch_face = far_centre_.size();
          far_centre_.push_back(internal::face_centre<double, Dim>(grid_.points.blocks[b], d, fidx));
          halos_.push_back(h);
          if (pt.kind == boundary_kind::wall && opt_.wall == euler_options::wall_flux::extrapolated)
            wall_flag_[b][d][h.face] = static_cast<signed char>(out);
        }
      }
    }
    for (int b = 0; b < nb; ++b)
      for (int f = 0; f < 2 * Dim; ++f)
        for (std::size_t k = 0; k < coverage[b][f].size(); ++k)
          require(coverage[b][f][k] == 1, "grid topology: block ", b, " face ", f, " cell ", k, " is covered by ",
                  coverage[b][f][k], " boundary patches (must be exactly 1)");
  }

  multiblock_grid<Dim> grid_;
  free_stream fs_;
  euler_options opt_;
  double circulation_ = 0.0;
  std::vector<std::array<double, Dim>> far_centre_;  // face centre of each halo's boundary face
  grid_metrics<double, Dim> metrics_;
  std::vector<std::size_t> offset_;
  std::vector<index_d<Dim>> pdims_;
  std::vector<std::array<std::size_t, Dim>> stride_;
  std::vector<std::vector<long long>> owner_;
  std::vector<halo_cell> halos_;
  std::vector<std::array<std::vector<signed char>, Dim>> wall_flag_;
};


}  // namespace aerohopf::flow
