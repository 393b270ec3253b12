#pragma once
// The coupled aeroelastic wing of spec 06: 3D Euler flow about a flexible wing whose motion is
// m structural modes, as one dynamical_system dw/dt = f(w, mu) for the Hopf and reduction code.
//
// State w = [w_f (5 per flow cell, euler_model ordering), w_s = (a_1 .. a_m, a_1' .. a_m')],
// the modal coordinates a_hat = a / c of structure/modal_structure.hpp; parameter mu = rho_inf c^3
// (the density parameter, kg). Residual
//     f_f = R_f(w_f; grid(a), grid speeds(a'))        (coupling/mesh_deformation.hpp moves the grid)
//     f_s = [a';  mu g(w) - K a - D a']               (structure/modal_structure.hpp)
// with the generalised forces g_i = sum over the wing's wall faces of
//     (p_w - p_inf) S_f . Psi_i(f),     Psi_i(f) = the mean of mode i's grid displacement Psi_i
// over the face's four corners. This is the virtual work of the face's pressure force, shared
// equally by its corners, along the splined mode: f_s = S^T f_a by virtual work, with
// S phi_i = Psi_i on the wing. p_w = (3 p_0 - p_1)/2 is the wall pressure of the slip-wall flux
// (the same one the flow residual applies), S_f the face's area vector on the MOVED grid,
// outward from the fluid. So g is linear in the wall pressures (A_sf exact) and the rotation of
// the surface normals under the modes enters A_ss. Only the faces tagged euler_options::force_tag
// (the wing; not the symmetry plane, which is also a slip wall) carry loads.
// Time and scale: lengths in root chords c, pressure by rho U^2, time tau = c / U; the shapes keep
// their kg^-1/2, so the grid displacement of a mode in root chords is Psi a_hat (mesh_deformation).
// At a fixed Mach number and speed U the reduced frequencies k_i = omega_i c / U are fixed and
// the density parameter mu is the bifurcation parameter (the original work's density ratio).
//
// The residual is templated on the scalar: jets or Taylor numbers in w_s move the grid, its
// metrics (GCL-exact, flow/metrics.hpp) and the Euler residual with exact derivatives.
// Jacobian (exact): A_ff by flow::assemble_jacobian on the grid moved to a, [A_fs; A_ss] by one
// pass of the coupled residual in jet<double, 8> per 8 structural unknowns (all columns at once:
// through the spline, the grid motion, the metrics and the flux), A_sf from the wall cells (local
// jets of the wall pressure). d_mu = [0; 0; g] and jacobian_d_mu = d/dw of it are analytic.
// Concepts met: bordered_system (block 5: flow blocks + the dense border of the 2m structural
// unknowns, the form of the Krylov path) and aeroelastic_system. The free stream is set in place
// by set_mach / set_free_stream, the structure (reduced frequencies: a new speed) by set_structure.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "../coupling/mesh_deformation.hpp"
#include "../error.hpp"
#include "../flow/euler_model.hpp"
#include "../flow/jacobian.hpp"
#include "../flow/metrics.hpp"
#include "../flow/steady_solver.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "../nonlinear/aeroelastic_system.hpp"
#include "../nonlinear/block_system.hpp"
#include "../nonlinear/system.hpp"
#include "../scalar/jet.hpp"
#include "../structure/modal_structure.hpp"

namespace aerohopf::models {

class wing_system {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int nv = 5;
  static constexpr int block_size = nv;
  /// Structural unknowns per jet pass of the coupling columns (all of four modes in one pass).
  static constexpr int jet_width = 8;

  /// flow: the Euler model on the rest grid (its options().force_tag names the loaded walls and
  /// must be set); motion: the modal grid motion of that grid; structure: reduced frequencies and
  /// damping of the same modes. `origins`: for a flow grid cut into blocks (split_wing_system
  /// below), where each block's points lie in the motion's one-block grid; empty: the flow grid
  /// is the motion's grid itself.
  wing_system(flow::euler_model<3> flow, coupling::wing_modal_motion motion, structure::modal_structure structure,
              std::vector<flow::block_origin<3>> origins = {})
      : flow_(std::move(flow)), motion_(std::move(motion)), structure_(std::move(structure)),
        origins_(std::move(origins)) {
    const char* who = "wing_system";
    const auto& opt = flow_.options();
    require(opt.wall == flow::euler_options::wall_flux::extrapolated, who,
            ": the loads assume the extrapolated slip-wall flux (euler_options::wall)");
    require(!opt.force_tag.empty(), who,
            ": euler_options::force_tag must name the wing's wall patches (e.g. \"wing\"); the symmetry plane is a "
            "slip wall too and carries no structural load");
    require(motion_.modes() == structure_.modes(), who, ": the grid motion has ", motion_.modes(),
            " modes, the structure ", structure_.modes());
    const auto& grid = flow_.grid();
    const auto& whole = motion_.rest();
    if (origins_.empty()) {
      require(grid.points.blocks.size() == 1 && grid.points.blocks[0].n_points() == whole.n_points(), who,
              ": the grid motion was not made for this flow grid (", grid.points.blocks.size(), " blocks, ",
              grid.points.blocks[0].n_points(), " points vs ", whole.n_points(), ")");
      origins_.resize(1);
    } else {
      // a cut grid: each block a box of the motion's grid, point for point
      require(origins_.size() == grid.points.blocks.size(), who, ": ", origins_.size(), " block origins for ",
              grid.points.blocks.size(), " blocks");
      for (std::size_t b = 0; b < origins_.size(); ++b) {
        const auto& blk = grid.points.blocks[b];
        const auto& o = origins_[b];
        bool inside = o.block == 0;
        for (int d = 0; d < 3; ++d) inside = inside && o.offset[d] >= 0 && o.offset[d] + blk.points[d] <= whole.points[d];
        require(inside, who, ": block ", b, "'s origin lies outside the grid motion's block");
        for (std::size_t k = 0; k < blk.n_points(); ++k)
          require(blk.x[k] == whole.x[motion_point(b, flow::unravel<3>(k, blk.points))], who, ": block ", b,
                  "'s point ", k, " is not the grid motion's point at its origin");
      }
    }
    nf_ = flow_.size();
    m_ = structure_.modes();
    const auto& rest = flow_.metrics();
    walls_ = flow_.loaded_faces();
    for (const auto& f : walls_) {
      const auto corners =
          flow::internal::face_corners<3>(f.dir, flow::unravel<3>(f.face, rest.blocks[f.block].face_dims(f.dir)));
      for (Eigen::Index i = 0; i < m_; ++i) {
        std::array<double, 3> mean{};
        for (const auto& c : corners) {
          const auto& psi = motion_.basis(i)[motion_point(static_cast<std::size_t>(f.block), c)];
          for (int d = 0; d < 3; ++d) mean[d] += 0.25 * psi[d];
        }
        face_mode_.push_back(mean);
      }
    }
    require(!walls_.empty(), who, ": the flow grid has no wall faces tagged \"", opt.force_tag, "\"");
  }

  Eigen::Index size() const { return nf_ + 2 * m_; }
  Eigen::Index flow_size() const { return nf_; }
  Eigen::Index structure_size() const { return 2 * m_; }
  Eigen::Index modes() const { return m_; }
  /// The structural unknowns (a, a') of a state or eigenvector (the last 2m entries).
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    require_size(v.size(), size(), "wing_system::structure_part", "vector");
    return v.tail(2 * m_);
  }
  const flow::euler_model<3>& flow() const { return flow_; }
  const coupling::wing_modal_motion& motion() const { return motion_; }
  const structure::modal_structure& structure() const { return structure_; }
  std::size_t wall_faces() const { return walls_.size(); }

  /// A new free stream in place (euler_model::set_free_stream; grid, motion and walls kept).
  void set_free_stream(const flow::free_stream& fs) { flow_.set_free_stream(fs); }
  void set_mach(double mach) {
    flow::free_stream fs = flow_.conditions();
    fs.mach = mach;
    set_free_stream(fs);
  }
  /// New reduced frequencies and damping (a new speed U) for the same number of modes.
  void set_structure(structure::modal_structure s) {
    require(s.modes() == m_, "wing_system::set_structure: ", s.modes(), " modes for a system of ", m_);
    structure_ = std::move(s);
  }

  /// Uniform free stream with the wing at rest (the start of the steady solve).
  vec<double> free_stream_state() const {
    vec<double> w = vec<double>::Zero(size());
    w.head(nf_) = flow_.free_stream_vector();
    return w;
  }

  /// The equilibrium with the wing at rest: the steady flow from the free stream and a = a' = 0,
  /// the same for every mu. It is an equilibrium only if the flow does no work on the modes:
  /// convergence_error if a generalised force exceeds max_load (a lifting flow: incidence or
  /// camber), or if the steady solve fails.
  vec<double> steady_equilibrium(const flow::steady_options& opt = {}, double max_load = 1e-8) const {
    flow::euler_model<3> f = flow_;
    vec<double> wf = f.free_stream_vector();
    const auto report = flow::solve_steady<3>(f, wf, opt);
    if (!report.converged)
      throw convergence_error(internal::concat("wing_system::steady_equilibrium: the steady flow at M = ",
                                               flow_.conditions().mach, " about the wing at rest did not converge (",
                                               report.steps, " steps, residual ", report.final_residual, ": ",
                                               report.reason, ")"));
    vec<double> w = free_stream_state();
    w.head(nf_) = wf;
    const vec<double> g = generalised_forces<double>(w);
    if (!(g.cwiseAbs().maxCoeff() <= max_load))
      throw convergence_error(internal::concat(
          "wing_system::steady_equilibrium: the steady flow at M = ", flow_.conditions().mach,
          " converged but does work on the modes at rest (largest generalised force ", g.cwiseAbs().maxCoeff(),
          ", limit ", max_load, "): the wing at rest is not an equilibrium (incidence or camber: solve the static "
          "aeroelastic equilibrium instead)"));
    return w;
  }

  /// A state or eigenvector of `coarse` (this grid coarsened by m) as one of this system: flow
  /// by injection, structural part copied.
  template <class T>
  vec<T> prolong_from(const wing_system& coarse, int m, const vec<T>& v) const {
    require(v.size() == coarse.size() && coarse.modes() == m_, "wing_system::prolong_from: vector of ", v.size(),
            " entries, coarse system ", coarse.size(), " with ", coarse.modes(), " modes (this: ", m_, ")");
    vec<T> out(size());
    out.head(nf_) = flow::prolong_cells<3>(coarse.flow().grid().topology, flow_.grid().topology, m,
                                           vec<T>(v.head(coarse.flow_size())), nv);
    out.tail(2 * m_) = v.tail(2 * m_);
    return out;
  }

  /// Metrics of the grid moved to the modal state of w (points and speeds).
  template <class T>
  flow::grid_metrics<T, 3> moved_metrics(const vec<T>& w) const {
    require_size(w.size(), size(), "wing_system::moved_metrics", "state");
    return moved_metrics_of<T>(vec<T>(w.tail(2 * m_)));
  }
  /// The same from the structural part w_s = (a, a') alone (the distributed wing's ranks hold
  /// only their flow values).
  template <class T>
  flow::grid_metrics<T, 3> moved_metrics_of(const vec<T>& ws) const {
    flow::multiblock_points<T, 3> pts, spd;
    moved_points<T>(ws, pts, spd);
    return flow::compute_metrics<T, 3>(pts, &spd);
  }

  /// The moved points and their speeds of every block of the flow grid at w_s = (a, a').
  template <class T>
  void moved_points(const vec<T>& ws, flow::multiblock_points<T, 3>& pts, flow::multiblock_points<T, 3>& spd) const {
    require_size(ws.size(), 2 * m_, "wing_system::moved_points", "structural state");
    auto p = motion_.points<T>(ws.head(m_));
    auto v = motion_.velocities<T>(ws.tail(m_));
    pts.blocks.clear();
    spd.blocks.clear();
    if (flow_.grid().points.blocks.size() == 1) {
      pts.blocks.push_back(std::move(p));
      spd.blocks.push_back(std::move(v));
      return;
    }
    for (std::size_t b = 0; b < origins_.size(); ++b) {
      const auto& n = flow_.grid().points.blocks[b].points;
      flow::grid_block<T, 3> pb, vb;
      pb.points = vb.points = n;
      pb.x.resize(pb.n_points());
      vb.x.resize(vb.n_points());
      for (std::size_t k = 0; k < pb.x.size(); ++k) {
        const std::size_t q = motion_point(b, flow::unravel<3>(k, n));
        pb.x[k] = p.x[q];
        vb.x[k] = v.x[q];
      }
      pts.blocks.push_back(std::move(pb));
      spd.blocks.push_back(std::move(vb));
    }
  }

  /// The flow model on the grid moved to the modal state of w (points and speeds): the
  /// deflected wing's surface for io::write_vtk_wall_surface, the flow part of the Jacobian.
  flow::euler_model<3> moved_flow(const vec<double>& w) const {
    require_size(w.size(), size(), "wing_system::moved_flow", "state");
    flow::multiblock_points<double, 3> pts, spd;
    moved_points<double>(vec<double>(w.tail(2 * m_)), pts, spd);
    flow::euler_model<3> moved = flow_;
    moved.set_grid_motion(pts, &spd);
    return moved;
  }

  /// Where the flow grid's blocks lie in the grid motion's block (one entry, offset 0, when
  /// the flow grid is that block).
  const std::vector<flow::block_origin<3>>& block_origins() const { return origins_; }

  /// The generalised forces g (m entries, non-dimensional: by rho U^2 c^2 times root chords) of state w.
  template <class T>
  vec<T> generalised_forces(const vec<T>& w) const {
    require_size(w.size(), size(), "wing_system::generalised_forces", "state");
    vec<T> g;
    with_metrics<T>(w, [&](const flow::grid_metrics<T, 3>& m) { g = forces_of_blocks<T>(m, w.data(), nullptr); });
    return g;
  }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    check_entry(w, mu, "wing_system::residual");
    vec<T> r(size());
    with_metrics<T>(w, [&](const flow::grid_metrics<T, 3>& m) {
      flow_.template residual<T>(m, w.data(), r.data());
      const vec<T> g = forces_of_blocks<T>(m, w.data(), nullptr);
      r.tail(2 * m_) = structure_.residual<T>(w.tail(2 * m_), g, mu);
    });
    return r;
  }

  jacobian_type jacobian(const vec<double>& w, double mu) const { return bordered_jacobian(w, mu).to_sparse(); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    return assemble_bordered(w, mu, flow::jacobian_kind::modified_order).to_sparse();
  }
  /// bordered_system: the exact and the modified-order Jacobian (the preconditioning matrix);
  /// the coupling blocks are the same in both and computed once.
  bordered_jacobian_pair<block_size> bordered_jacobians(const vec<double>& w, double mu) const {
    constexpr const char* who = "wing_system::jacobians";
    bordered_jacobian_pair<block_size> p;
    p.exact = assemble_bordered(w, mu, flow::jacobian_kind::exact, nullptr, who);
    p.preconditioning = assemble_bordered(w, mu, flow::jacobian_kind::modified_order, &p.exact, who);
    return p;
  }
  bordered_block_matrix<double, nv> bordered_jacobian(const vec<double>& w, double mu) const {
    return assemble_bordered(w, mu, flow::jacobian_kind::exact);
  }

  /// f_mu = [0; 0; g(w)].
  vec<double> d_mu(const vec<double>& w, double mu) const {
    check_state(*this, w, mu, "wing_system::d_mu");
    vec<double> r = vec<double>::Zero(size());
    r.tail(m_) = generalised_forces<double>(w);
    return r;
  }
  /// A_mu = d f_mu / dw: the rows of a' hold dg/dw_f (wall cells) and dg/da (the moved normals).
  jacobian_type jacobian_d_mu(const vec<double>& w, double mu) const {
    check_state(*this, w, mu, "wing_system::jacobian_d_mu");
    const Eigen::MatrixXd ga = force_structure_derivative(w);
    const Eigen::MatrixXd gf = force_pressure_derivative(w);
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index i = 0; i < m_; ++i) {
      for (Eigen::Index j = 0; j < nf_; ++j)
        if (gf(i, j) != 0) t.emplace_back(nf_ + m_ + i, j, gf(i, j));
      for (Eigen::Index j = 0; j < m_; ++j)
        if (ga(i, j) != 0) t.emplace_back(nf_ + m_ + i, nf_ + j, ga(i, j));
    }
    jacobian_type a(size(), size());
    a.setFromTriplets(t.begin(), t.end());
    return a;
  }

  /// The generalised forces g (m entries) on metrics m of the flow state wf (the whole grid's
  /// flow values), from the loaded faces of the blocks selected by `blocks` (one entry per
  /// block; nullptr: all): a sum over faces, so the parts of disjoint selections add up to g.
  template <class T>
  vec<T> forces_of_blocks(const flow::grid_metrics<T, 3>& m, const T* wf, const std::vector<char>* blocks) const {
    const T pinf = T(flow_.conditions().pressure());
    vec<T> g = vec<T>::Constant(m_, T(0.0));
    for (std::size_t f = 0; f < walls_.size(); ++f) {
      const auto& wl = walls_[f];
      if (blocks && !(*blocks)[static_cast<std::size_t>(wl.block)]) continue;
      const T dp = T(1.5) * flow::pressure_at<T, 3>(wf + wl.cell0 * nv) - T(0.5) * flow::pressure_at<T, 3>(wf + wl.cell1 * nv) - pinf;
      for (Eigen::Index i = 0; i < m_; ++i) g[i] += dp * face_work<T>(m, f, i);
    }
    return g;
  }

  /// The entries of dg/dw_f on metrics m at the flow state wf, from the loaded faces of the
  /// selected blocks (nullptr: all): entry(i, cell, v, x) for each contribution x to
  /// dg_i / dw_(cell, v) (a cell may receive several; they add up).
  template <class Entry>
  void force_pressure_entries(const flow::grid_metrics<double, 3>& m, const double* wf,
                              const std::vector<char>* blocks, Entry&& entry) const {
    using cjet = jet<double, nv>;
    for (std::size_t f = 0; f < walls_.size(); ++f) {
      const auto& wl = walls_[f];
      if (blocks && !(*blocks)[static_cast<std::size_t>(wl.block)]) continue;
      for (int which = 0; which < 2; ++which) {
        const Eigen::Index cell = which == 0 ? wl.cell0 : wl.cell1;
        const double weight = which == 0 ? 1.5 : -0.5;
        std::array<cjet, nv> wc;
        for (int u = 0; u < nv; ++u) wc[u] = cjet::variable(wf[cell * nv + u], u);
        const cjet p = flow::pressure_at<cjet, 3>(wc.data());
        for (Eigen::Index i = 0; i < m_; ++i) {
          const double c = weight * face_work<double>(m, f, i);
          for (int v = 0; v < nv; ++v) entry(i, cell, v, c * p.derivative(v));
        }
      }
    }
  }

 private:
  using wall_face = flow::euler_model<3>::loaded_face;
  struct coupling_blocks {
    Eigen::MatrixXd fs, ss;  // [A_fs; A_ss] (nf x 2m, 2m x 2m)
  };

  /// The motion's point index of point i of the flow grid's block b.
  std::size_t motion_point(std::size_t b, flow::index_d<3> i) const {
    for (int d = 0; d < 3; ++d) i[d] += origins_[b].offset[d];
    return flow::linear_index<3>(i, motion_.rest().points);
  }

  /// A double state with the structural part exactly zero: the grid at rest.
  bool at_rest(const vec<double>& w) const { return w.tail(2 * m_).isZero(0.0); }
  /// fn(metrics of the grid of w): the model's rest metrics (no copy) for a double state at
  /// rest, else the moved ones (a jet or Taylor state carries directions through the motion
  /// even at a = 0).
  template <class T, class Fn>
  void with_metrics(const vec<T>& w, Fn&& fn) const {
    if constexpr (std::is_same_v<T, double>) {
      if (at_rest(w)) {
        fn(flow_.metrics());
        return;
      }
    }
    fn(moved_metrics<T>(w));
  }

  template <class T>
  void check_entry(const vec<T>& w, const T& mu, const char* who) const {
    require_finite_aeroelastic_state(w, mu, size(), nf_, nv, who, "mu");
  }

  /// c_fi = S_f . Psi_i(f) of wall face f (outward from the fluid) on metrics m.
  template <class T>
  T face_work(const flow::grid_metrics<T, 3>& m, std::size_t f, Eigen::Index i) const {
    const auto& wf = walls_[f];
    const auto& s = m.blocks[wf.block].normal[wf.dir][wf.face];
    const auto& psi = face_mode_[f * static_cast<std::size_t>(m_) + static_cast<std::size_t>(i)];
    return T(double(wf.sign)) * (s[0] * psi[0] + s[1] * psi[1] + s[2] * psi[2]);
  }

  /// dg/dw_f (m x nf, non-zero in the wall cells' columns) at the grid of w.
  Eigen::MatrixXd force_pressure_derivative(const vec<double>& w) const {
    Eigen::MatrixXd gf = Eigen::MatrixXd::Zero(m_, nf_);
    with_metrics<double>(w, [&](const flow::grid_metrics<double, 3>& m) {
      force_pressure_entries(m, w.data(), nullptr,
                             [&](Eigen::Index i, Eigen::Index cell, int v, double x) { gf(i, cell * nv + v) += x; });
    });
    return gf;
  }

  /// dg/da (m x m): the forces on the grid moved by jets in a (the normals turn with the modes).
  Eigen::MatrixXd force_structure_derivative(const vec<double>& w) const {
    using sjet = jet<double, jet_width>;
    Eigen::MatrixXd ga(m_, m_);
    for (Eigen::Index j0 = 0; j0 < m_; j0 += jet_width) {
      const Eigen::Index width = std::min<Eigen::Index>(jet_width, m_ - j0);
      vec<sjet> wj = w.cast<sjet>();
      for (Eigen::Index j = 0; j < width; ++j) wj[nf_ + j0 + j] = sjet::variable(w[nf_ + j0 + j], static_cast<int>(j));
      const vec<sjet> g = forces_of_blocks<sjet>(moved_metrics<sjet>(wj), wj.data(), nullptr);
      for (Eigen::Index j = 0; j < width; ++j)
        for (Eigen::Index i = 0; i < m_; ++i) ga(i, j0 + j) = g[i].derivative(static_cast<int>(j));
    }
    return ga;
  }

  /// [A_fs; A_ss] by passes of the coupled residual with jets along the structural unknowns.
  coupling_blocks coupling(const vec<double>& w, double mu) const {
    using sjet = jet<double, jet_width>;
    const Eigen::Index ns = 2 * m_;
    coupling_blocks c;
    c.fs.resize(nf_, ns);
    c.ss.resize(ns, ns);
    for (Eigen::Index j0 = 0; j0 < ns; j0 += jet_width) {
      const Eigen::Index width = std::min<Eigen::Index>(jet_width, ns - j0);
      vec<sjet> wj = w.cast<sjet>();
      for (Eigen::Index j = 0; j < width; ++j)
        wj[nf_ + j0 + j] = sjet::variable(w[nf_ + j0 + j], static_cast<int>(j));
      const auto m = moved_metrics<sjet>(wj);
      vec<sjet> r(size());
      flow_.template residual<sjet>(m, wj.data(), r.data());
      const vec<sjet> g = forces_of_blocks<sjet>(m, wj.data(), nullptr);
      r.tail(ns) = structure_.residual<sjet>(wj.tail(ns), g, sjet(mu));
      for (Eigen::Index j = 0; j < width; ++j) {
        const int d = static_cast<int>(j);
        for (Eigen::Index i = 0; i < nf_; ++i) c.fs(i, j0 + j) = r[i].derivative(d);
        for (Eigen::Index i = 0; i < ns; ++i) c.ss(i, j0 + j) = r[nf_ + i].derivative(d);
      }
    }
    return c;
  }

  bordered_block_matrix<double, nv> assemble_bordered(const vec<double>& w, double mu, flow::jacobian_kind kind,
                                                      const bordered_block_matrix<double, nv>* coupling_from = nullptr,
                                                      const char* who = nullptr) const {
    const char* name =
        who ? who : (kind == flow::jacobian_kind::exact ? "wing_system::jacobian" : "wing_system::approximate_jacobian");
    check_state(*this, w, mu, name);
    const vec<double> wf = w.head(nf_);
    block_sparse_matrix<double, nv> aff;
    if (at_rest(w)) {
      flow::assemble_jacobian<3>(flow_, wf, kind, aff);
    } else {
      flow::assemble_jacobian<3>(moved_flow(w), wf, kind, aff);
    }
    if (coupling_from) {
      require(coupling_from->flow_size() == nf_ && coupling_from->structure_size() == 2 * m_,
              "wing_system: coupling blocks from a matrix of another size");
      return {std::move(aff), coupling_from->flow_structure(), coupling_from->structure_flow(),
              coupling_from->structure(), name};
    }
    coupling_blocks c = coupling(w, mu);
    Eigen::MatrixXd sf = Eigen::MatrixXd::Zero(2 * m_, nf_);
    sf.bottomRows(m_) = mu * force_pressure_derivative(w);
    return {std::move(aff), std::move(c.fs), std::move(sf), std::move(c.ss), name};
  }

  flow::euler_model<3> flow_;
  coupling::wing_modal_motion motion_;
  structure::modal_structure structure_;
  Eigen::Index nf_ = 0, m_ = 0;
  std::vector<flow::block_origin<3>> origins_;   // per flow block: its box in the motion's block
  std::vector<wall_face> walls_;
  std::vector<std::array<double, 3>> face_mode_;  // Psi_i(f), face-major
};

/// The wing system `s` on its grid cut into blocks (`cut`: flow::split_block or
/// distributed::split_for_ranks of s.flow().grid(), which record where the blocks' points lie):
/// the same free stream, options, motion and structure. Its state orders the flow cells as
/// cut.original_cell; the residual and Jacobian are s's so permuted (the loads summed in another
/// order: to rounding).
inline wing_system split_wing_system(const wing_system& s, const flow::split_grid<3>& cut) {
  const char* who = "split_wing_system";
  require(s.flow().grid().points.blocks.size() == 1, who, ": the system's grid is cut already (",
          s.flow().grid().points.blocks.size(), " blocks)");
  require(!cut.origin.empty(), who, ": the cut grid does not record where its blocks' points lie (split_grid::origin)");
  require_size(cut.original_cell.size(), static_cast<std::size_t>(s.flow().n_cells()), who, "cut grid's cells");
  return wing_system(flow::euler_model<3>(cut.grid, s.flow().conditions(), s.flow().options()), s.motion(),
                     s.structure(), cut.origin);
}

}  // namespace aerohopf::models
