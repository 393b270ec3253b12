#pragma once
// The coupled aeroelastic system of spec 05: 2D Euler flow around a rigid aerofoil in pitch
// and plunge, as one dynamical_system dw/dt = f(w, Ubar) for the Hopf and reduction code.
//
// State w = [w_f (4 per flow cell, euler_model ordering), w_s = (h, h', alpha, alpha')],
// parameter mu = Ubar. Residual
//     f_f = R_f(w_f; grid(w_s), grid speeds(w_s))       (rigid_motion.hpp moves the whole grid)
//     f_s = M^{-1} (f_a(C_l, C_m) - K(Ubar) w_s)         (pitch_plunge.hpp)
// Time scaling: the flow is non-dimensionalised by chord, rho_inf and U_inf, so its time unit
// is c / U_inf, which is exactly the time unit of the structural equations of spec 05
// (h/c, alpha, ' = d/d(t U_inf / c)); grid speeds are therefore d/dt of the moved points in
// that unit, and both halves of f share one clock with no conversion factor. Ubar enters only
// through K.
// Loads: C_l (normal to the free stream) and C_m (nose-up, about the MOVED elastic axis
// (x_ea, y_ea + h)) are integrated from the same wall pressure that the slip-wall flux uses,
// p_w = (3 p_0 - p_1)/2, on the moved wall faces; so the loads are linear in the wall
// pressures (A_sf exact) and consistent with the flow residual.
// The residual is templated on the scalar: with taylor<> or jet<> scalars in w_s the moved grid, metrics
// and Euler residual carry exact derivatives. Jacobian (Eigen sparse, exact):
//   A_ff: flow::assemble_jacobian (exact or modified order) on the grid moved to w_s,
//   [A_fs; A_ss]: one pass of the coupled residual in jet<double, 4> (one direction per
//          structural unknown; exact, includes the dependence of the loads on the moved geometry),
//   A_sf: derivative of the wall-pressure integrals by a local jet per wall cell.
// d_mu and jacobian_d_mu are analytic: -M^{-1} dK/dUbar w_s and the 4x4 block -M^{-1} dK/dUbar.
// Concepts met: bordered_system (block_size 4: bordered_jacobians() gives the exact and the
// modified-order matrices as 4 x 4 flow blocks + the dense border of the 4 structural unknowns,
// the form the Krylov path works in), block_system (jacobians(): the same matrices with the
// structure padded into the last 4 x 4 block, for the callers that take one block matrix) and
// aeroelastic_system (flow part first, the 4 structural unknowns last). The Mach number (free stream) is set in
// place by set_mach / set_free_stream: the grid, metrics, halos and wall faces are kept.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "../coupling/rigid_motion.hpp"
#include "../error.hpp"
#include "../flow/euler_model.hpp"
#include "../flow/jacobian.hpp"
#include "../flow/metrics.hpp"
#include "../flow/steady_solver.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "../linalg/direct.hpp"
#include "../nonlinear/aeroelastic_system.hpp"
#include "../nonlinear/block_system.hpp"
#include "../nonlinear/system.hpp"
#include "../scalar/jet.hpp"
#include "../scalar/taylor.hpp"
#include "../structure/pitch_plunge.hpp"

namespace aerohopf::models {

class aerofoil_system {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int n_structure = 4;
  static constexpr int nv = 4;
  static constexpr int block_size = nv;  // block_system: one flow cell per block, the structure one block

  /// flow: the Euler model on the rest grid (free stream, options; its wall patches with
  /// options().force_tag, or all walls if empty, carry the loads); structure: the section.
  aerofoil_system(flow::euler_model<2> flow, structure::pitch_plunge structure)
      : flow_(std::move(flow)), structure_(std::move(structure)) {
    require(flow_.options().wall == flow::euler_options::wall_flux::extrapolated,
            "aerofoil_system: the loads assume the extrapolated slip-wall flux (euler_options::wall)");
    require(!flow_.options().vortex_far_field,
            "aerofoil_system: vortex_far_field is a residual parameter not differentiated here; switch it off");
    const auto& sp = structure_.parameters();
    ea_ = {sp.x_ea, sp.y_ea};
    nf_ = flow_.size();
    walls_ = flow_.loaded_faces();
    require(!walls_.empty(), "aerofoil_system: the flow grid has no wall faces to integrate loads over");
    // mid-point of every rest face relative to the elastic axis (the moved metrics and the loads)
    const auto& rest = flow_.metrics();
    face_arm_.resize(rest.blocks.size());
    for (std::size_t b = 0; b < rest.blocks.size(); ++b)
      for (int d = 0; d < 2; ++d) {
        auto& arms = face_arm_[b][d];
        arms.resize(rest.blocks[b].normal[d].size());
        const auto& g = flow_.grid().points.blocks[b];
        for (std::size_t k = 0; k < arms.size(); ++k) {
          const auto corners = flow::internal::face_corners<2>(d, flow::unravel<2>(k, rest.blocks[b].face_dims(d)));
          const auto& xa = g.at(corners[0]);
          const auto& xb = g.at(corners[1]);
          arms[k] = {0.5 * (xa[0] + xb[0]) - ea_[0], 0.5 * (xa[1] + xb[1]) - ea_[1]};
        }
      }
  }

  Eigen::Index size() const { return nf_ + n_structure; }
  Eigen::Index flow_size() const { return nf_; }
  Eigen::Index structure_size() const { return n_structure; }
  /// The structural unknowns (h, h', alpha, alpha') of a state or eigenvector (the last 4 entries).
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    require_size(v.size(), size(), "aerofoil_system::structure_part", "vector");
    return v.tail(n_structure);
  }
  const flow::euler_model<2>& flow() const { return flow_; }
  const structure::pitch_plunge& structure() const { return structure_; }

  /// A new free stream (Mach number, incidence) in place: the flow model's grid, metrics and
  /// halos and this system's wall faces do not depend on it and are kept, so the system is then
  /// the same as one constructed with fs, without the set-up (euler_model::set_free_stream).
  /// Refused (input_error) like the constructor's; the system is then unchanged.
  void set_free_stream(const flow::free_stream& fs) { flow_.set_free_stream(fs); }
  /// The same with only the Mach number changed.
  void set_mach(double mach) {
    flow::free_stream fs = flow_.conditions();
    fs.mach = mach;
    set_free_stream(fs);
  }

  /// Uniform free stream with the section at rest (the start of the steady solve).
  vec<double> free_stream_state() const {
    vec<double> w = vec<double>::Zero(size());
    w.head(nf_) = flow_.free_stream_vector();
    return w;
  }

  /// The equilibrium with the section at rest: steady flow (solve_steady from the free stream)
  /// and zero structural state. For a symmetric aerofoil at zero incidence it is the same for
  /// every Ubar. solve_steady throws convergence_error if the steady solve fails.
  /// The section at rest is an equilibrium only if the flow exerts no load on it: if the
  /// converged flow has |C_l| or |C_m| above max_load, it throws convergence_error naming them
  /// rather than return a state that is not an equilibrium. That happens at non-zero incidence,
  /// and also for the symmetric NACA 0012 at zero incidence, where the transonic Euler equations
  /// admit non-symmetric (lifting) steady flows besides the symmetric one: measured on the
  /// medium grid (stride 2) at M = 0.90125, the solve from the free stream converged (||R|| down
  /// 10 orders) to C_l = 6.1e-3, 0.87 in the 2-norm away from the symmetric flow, which Newton
  /// from the neighbouring Mach numbers' flows finds (bifurcation/equilibrium_krylov.hpp); both
  /// are stable steady flows. Round-off leaves |C_l| ~ 1e-11 on the symmetric one.
  vec<double> steady_equilibrium(const flow::steady_options& opt = {}, double max_load = 1e-6) const {
    flow::euler_model<2> f = flow_;
    vec<double> wf = f.free_stream_vector();
    const auto report = flow::solve_steady<2>(f, wf, opt);
    if (!report.converged)
      throw convergence_error(internal::concat("aerofoil_system::steady_equilibrium: the steady flow at M = ",
                                               flow_.conditions().mach, " with the section at rest did not converge (",
                                               report.steps, " steps, residual ", report.final_residual, ": ", report.reason, ")"));
    vec<double> w = free_stream_state();
    w.head(nf_) = wf;
    const auto [cl, cm] = load_coefficients<double>(w);
    if (!(std::abs(cl) <= max_load && std::abs(cm) <= max_load))
      throw convergence_error(internal::concat(
          "aerofoil_system::steady_equilibrium: the steady flow at M = ", flow_.conditions().mach,
          " converged (residual down to ", report.final_residual, " after ", report.steps, " steps) but loads the section at rest (C_l = ", cl, ", C_m = ", cm,
          ", limit ", max_load, "), so it is not an equilibrium of the coupled system: non-zero incidence, or a non-symmetric "
          "transonic solution of a symmetric section (start from a symmetric flow instead, e.g. solve_equilibrium_krylov "
          "from a neighbouring Mach number's equilibrium)"));
    return w;
  }

  /// Grid sequencing: a state or eigenvector v of `coarse`, whose flow grid is this system's grid
  /// coarsened by m, transferred to this system (flow by injection, structural part copied).
  template <class T>
  vec<T> prolong_from(const aerofoil_system& coarse, int m, const vec<T>& v) const {
    require(v.size() == coarse.size(), "aerofoil_system::prolong_from: vector has ", v.size(), " entries, coarse system ",
            coarse.size());
    vec<T> out(size());
    out.head(nf_) = flow::prolong_cells<2>(coarse.flow().grid().topology, flow_.grid().topology, m,
                                           vec<T>(v.head(coarse.flow_size())), nv);
    out.tail(n_structure) = v.tail(n_structure);
    return out;
  }

  template <class T>
  coupling::rigid_pose<T> pose(const vec<T>& w) const {
    require_size(w.size(), size(), "aerofoil_system::pose", "state");
    return {w[nf_], w[nf_ + 1], w[nf_ + 2], w[nf_ + 3]};
  }

  /// Metrics of the grid moved rigidly to the pose of w (rigid_motion.hpp), from the rest
  /// metrics: the rotation R(alpha) turns every edge, so the area vectors are R S_0 and the
  /// volumes are the rest ones; the grid speed is affine in x, so a face's swept volume (the
  /// mid-point rule of compute_metrics, exact on straight edges) is x_g(x_mid) . S with the
  /// mid-point moved. Equal to compute_metrics on the moved points up to rounding (test), with
  /// the volumes' derivatives exactly zero, at a small part of its cost (it was about a third of
  /// a residual on the medium grid, measured).
  template <class T>
  flow::grid_metrics<T, 2> moved_metrics(const vec<T>& w) const {
    return moved_metrics<T>(pose<T>(w));
  }

  /// The same for the pose q (h, h', alpha, alpha') itself.
  template <class T>
  flow::grid_metrics<T, 2> moved_metrics(const coupling::rigid_pose<T>& q) const {
    coupling::require_finite_pose(q, "aerofoil_system::moved_metrics");
    const coupling::rigid_rotation<T> rot(q.alpha);
    const auto& rest = flow_.metrics();
    flow::grid_metrics<T, 2> m;
    m.blocks.resize(rest.blocks.size());
    for (std::size_t b = 0; b < rest.blocks.size(); ++b) {
      const auto& rb = rest.blocks[b];
      auto& mb = m.blocks[b];
      mb.cells = rb.cells;
      mb.volume.resize(rb.volume.size());
      for (std::size_t k = 0; k < rb.volume.size(); ++k) mb.volume[k] = T(rb.volume[k]);
      for (int d = 0; d < 2; ++d) {
        const auto& n0 = rb.normal[d];
        const auto& arms = face_arm_[b][d];
        auto& nd = mb.normal[d];
        auto& sd = mb.speed[d];
        nd.resize(n0.size());
        sd.resize(n0.size());
        for (std::size_t k = 0; k < n0.size(); ++k) {
          const auto n = rot.apply(n0[k]);
          const auto r = rot.apply(arms[k]);  // moved mid-point - moved axis
          // x_g = (alpha' r_y, -alpha' r_x + h')
          sd[k] = q.alpha_dot * (r[1] * n[0] - r[0] * n[1]) + q.h_dot * n[1];
          nd[k] = n;
        }
      }
    }
    return m;
  }

  /// (C_l, C_m about the moved elastic axis) of state w.
  template <class T>
  std::pair<T, T> load_coefficients(const vec<T>& w) const {
    require_size(w.size(), size(), "aerofoil_system::load_coefficients", "state");
    const auto m = moved_metrics<T>(w);
    return loads<T>(m, coupling::rigid_rotation<T>(w[nf_ + 2]), w);
  }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    check_entry(w, mu, "aerofoil_system::residual");
    const auto m = moved_metrics<T>(w);
    vec<T> r(size());
    flow_.template residual<T>(m, w.data(), r.data());
    const auto [cl, cm] = loads<T>(m, coupling::rigid_rotation<T>(w[nf_ + 2]), w);
    Eigen::Matrix<T, 4, 1> ws;
    for (int i = 0; i < 4; ++i) ws[i] = w[nf_ + i];
    const auto rs = structure_.rate<T>(ws, cl, cm, mu);
    for (int i = 0; i < 4; ++i) r[nf_ + i] = rs[i];
    return r;
  }

  jacobian_type jacobian(const vec<double>& w, double mu) const { return assemble(w, mu, flow::jacobian_kind::exact); }
  /// bordered_system: the exact Jacobian and the modified-order one (the preconditioning matrix)
  /// as flow blocks + the dense structural border, what the Krylov path takes directly. The
  /// coupling blocks (A_fs, A_ss, A_sf) are the same in the two and are computed once (one
  /// jet<double, 4> pass of the whole residual: about a seventh of the assembly time on the
  /// medium grid, measured).
  bordered_jacobian_pair<block_size> bordered_jacobians(const vec<double>& w, double mu) const {
    constexpr const char* who = "aerofoil_system::jacobians";
    bordered_jacobian_pair<block_size> p;
    p.exact = assemble_bordered(w, mu, flow::jacobian_kind::exact, nullptr, who);
    p.preconditioning = assemble_bordered(w, mu, flow::jacobian_kind::modified_order, &p.exact, who);
    return p;
  }
  /// The exact Jacobian alone in the bordered form (bordered_jacobians().exact).
  bordered_block_matrix<double, nv> bordered_jacobian(const vec<double>& w, double mu) const {
    return assemble_bordered(w, mu, flow::jacobian_kind::exact);
  }
  /// block_system: the matrices of bordered_jacobians() in 4 x 4 blocks, the structural unknowns
  /// the last block row and column (no padding), saving callers that take one block matrix the
  /// Eigen round trip (triplets, sort, re-blocking: about half the assembly time).
  block_jacobian_pair<block_size> jacobians(const vec<double>& w, double mu) const {
    auto p = bordered_jacobians(w, mu);
    return {padded_form(p.exact), padded_form(p.preconditioning)};
  }
  /// The exact Jacobian alone in blocks (jacobians().exact, without the modified-order one).
  block_sparse_matrix<double, nv> block_jacobian(const vec<double>& w, double mu) const {
    return assemble_blocks(w, mu, flow::jacobian_kind::exact);
  }
  /// The modified-order Jacobian alone in blocks (jacobians().preconditioning).
  block_sparse_matrix<double, nv> approximate_block_jacobian(const vec<double>& w, double mu) const {
    return assemble_blocks(w, mu, flow::jacobian_kind::modified_order);
  }
  /// jacobians() as (exact, approximate).
  std::pair<block_sparse_matrix<double, nv>, block_sparse_matrix<double, nv>> block_jacobians(const vec<double>& w,
                                                                                              double mu) const {
    auto p = jacobians(w, mu);
    return {std::move(p.exact), std::move(p.preconditioning)};
  }
  /// Same with the modified-order flow block (left-hand side of Newton iterations).
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    return assemble(w, mu, flow::jacobian_kind::modified_order);
  }

  vec<double> d_mu(const vec<double>& w, double mu) const {
    check_state(*this, w, mu, "aerofoil_system::d_mu");
    vec<double> r = vec<double>::Zero(size());
    const Eigen::Matrix4d b = -structure_.mass_inverse() * structure_.stiffness_d_ubar(mu);
    const Eigen::Vector4d q = w.tail<4>();
    r.tail<4>() = b * q;  // fixed-size operands (GCC 12 + AVX-512 misreads the dynamic-block product)
    return r;
  }
  jacobian_type jacobian_d_mu(const vec<double>& w, double mu) const {
    check_state(*this, w, mu, "aerofoil_system::jacobian_d_mu");
    const Eigen::Matrix4d b = -structure_.mass_inverse() * structure_.stiffness_d_ubar(mu);
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) t.emplace_back(nf_ + i, nf_ + j, b(i, j));
    jacobian_type a(size(), size());
    a.setFromTriplets(t.begin(), t.end());
    return a;
  }

 private:
  template <class T>
  void check_entry(const vec<T>& w, const T& mu, const char* who) const {
    require_finite_aeroelastic_state(w, mu, size(), nf_, nv, who, "Ubar");
  }
  static const char* who_of(flow::jacobian_kind kind) {
    return kind == flow::jacobian_kind::exact ? "aerofoil_system::jacobian" : "aerofoil_system::approximate_jacobian";
  }

  using wall_face = flow::euler_model<2>::loaded_face;

  /// Load of one wall face: (dC_l, dC_m) per unit (p_w - p_inf) and the face's lever arm.
  template <class T>
  std::pair<T, T> face_load_per_pressure(const flow::grid_metrics<T, 2>& m, const coupling::rigid_rotation<T>& rot,
                                         const wall_face& f) const {
    const auto& s = m.blocks[f.block].normal[f.dir][f.face];
    const T fx = T(2.0 * f.sign) * s[0], fy = T(2.0 * f.sign) * s[1];  // area outward from the fluid
    // moved mid-point - moved axis (x_ea, y_ea + h)
    const auto [rx, ry] = rot.apply(face_arm_[f.block][f.dir][f.face]);
    const double a = flow_.conditions().alpha_rad;
    const T cl = fy * T(std::cos(a)) - fx * T(std::sin(a));
    const T cm = -(rx * fy - ry * fx);  // nose-up = clockwise
    return {cl, cm};
  }

  template <class T>
  std::pair<T, T> loads(const flow::grid_metrics<T, 2>& m, const coupling::rigid_rotation<T>& rot,
                        const vec<T>& w) const {
    return loads_of_blocks<T>(m, rot, w.data(), nullptr);
  }

 public:
  /// The part of (C_l, C_m) carried by the wall faces of the selected blocks (blocks[b] != 0;
  /// all blocks with nullptr) at the flow state wf (flow_size() values; only the selected
  /// blocks' wall cells are read), on metrics m moved by the rotation rot: the loads of a grid
  /// partitioned over processes are the sum of its parts (distributed/mpi_aerofoil.hpp).
  template <class T>
  std::pair<T, T> loads_of_blocks(const flow::grid_metrics<T, 2>& m, const coupling::rigid_rotation<T>& rot, const T* wf,
                                  const std::vector<char>* blocks) const {
    const T pinf = T(flow_.conditions().pressure());
    T cl = T(0.0), cm = T(0.0);
    for (const auto& f : walls_) {
      if (blocks && !(*blocks)[static_cast<std::size_t>(f.block)]) continue;
      const T p0 = flow::pressure_at<T, 2>(wf + f.cell0 * nv), p1 = flow::pressure_at<T, 2>(wf + f.cell1 * nv);
      const T dp = T(1.5) * p0 - T(0.5) * p1 - pinf;
      const auto [l, c] = face_load_per_pressure<T>(m, rot, f);
      cl += l * dp;
      cm += c * dp;
    }
    return {cl, cm};
  }

  /// The entries of A_sf = d(structural rates)/d(flow unknowns) from the wall faces of the
  /// selected blocks (all with nullptr): fn(i, cell, v, value) adds `value` to row i (structural
  /// unknown) and column cell * nv + v; w is the whole state (its flow part read only at those
  /// blocks' wall cells, its structural part for the pose). The loads are linear in the wall
  /// pressures, p_w = 1.5 p_0 - 0.5 p_1, so these are all of A_sf; dp/dw by a local jet per cell.
  template <class Fn>
  void structure_flow_entries(const flow::grid_metrics<double, 2>& m, const coupling::rigid_rotation<double>& rot,
                              const double* wf, const std::vector<char>* blocks, Fn&& fn) const {
    using cjet = jet<double, nv>;
    const auto& minv = structure_.mass_inverse();
    const double pi = std::numbers::pi, mus = structure_.parameters().mu_s;
    const double kl = 2.0 / (pi * mus), km = 4.0 / (pi * mus);
    for (const auto& f : walls_) {
      if (blocks && !(*blocks)[static_cast<std::size_t>(f.block)]) continue;
      const auto [l, c] = face_load_per_pressure<double>(m, rot, f);
      for (int which = 0; which < 2; ++which) {
        const Eigen::Index cell = which == 0 ? f.cell0 : f.cell1;
        const double weight = which == 0 ? 1.5 : -0.5;
        std::array<cjet, nv> wc;
        for (int u = 0; u < nv; ++u) wc[u] = cjet::variable(wf[cell * nv + u], u);
        const cjet p = flow::pressure_at<cjet, 2>(wc.data());
        for (int v = 0; v < nv; ++v) {
          const double dp = weight * p.derivative(v);
          for (int i = 0; i < 4; ++i) fn(i, cell, v, (minv(i, 1) * kl * l + minv(i, 3) * km * c) * dp);
        }
      }
    }
  }

 private:
  jacobian_type assemble(const vec<double>& w, double mu, flow::jacobian_kind kind) const {
    return assemble_blocks(w, mu, kind).to_sparse();
  }
  block_sparse_matrix<double, nv> assemble_blocks(const vec<double>& w, double mu, flow::jacobian_kind kind) const {
    return padded_form(assemble_bordered(w, mu, kind));
  }

  /// The coupled Jacobian as flow blocks A_ff (the cells, flow::assemble_jacobian on the grid
  /// moved to w_s) and the structural border: A_fs and A_ss exact from one jet pass, A_sf from
  /// the wall cells (the loads depend on no other flow unknowns). With coupling_from (a matrix
  /// assembled by this function at the same (w, mu)), the border is copied from it.
  bordered_block_matrix<double, nv> assemble_bordered(const vec<double>& w, double mu, flow::jacobian_kind kind,
                                                      const bordered_block_matrix<double, nv>* coupling_from = nullptr,
                                                      const char* who = nullptr) const {
    const char* name = who ? who : who_of(kind);
    check_state(*this, w, mu, name);
    const vec<double> wf = w.head(nf_);
    block_sparse_matrix<double, nv> aff;
    if (w.tail(4).isZero(0.0)) {
      flow::assemble_jacobian<2>(flow_, wf, kind, aff);
    } else {
      flow::multiblock_points<double, 2> pts, spd;
      coupling::rigid_grid_motion<double>(flow_.grid().points, pose<double>(w), ea_, pts, &spd);
      flow::euler_model<2> moved = flow_;
      moved.set_grid_motion(pts, &spd);
      flow::assemble_jacobian<2>(moved, wf, kind, aff);
    }
    if (coupling_from) {
      require(coupling_from->flow_size() == nf_ && coupling_from->structure_size() == n_structure,
              "aerofoil_system: coupling blocks from a matrix of another size");
      return {std::move(aff), coupling_from->flow_structure(), coupling_from->structure_flow(),
              coupling_from->structure(), name};
    }
    // [A_fs; A_ss]: one pass of the coupled residual with a 4-direction jet (direction j =
    // structural unknown j) gives all 4 columns exactly: the values (moved grid, metrics, Osher
    // fluxes) are computed once, not once per column.
    using sjet = jet<double, n_structure>;
    vec<sjet> wj = w.cast<sjet>();
    for (int j = 0; j < n_structure; ++j) wj[nf_ + j] = sjet::variable(w[nf_ + j], j);
    const vec<sjet> rj = residual<sjet>(wj, sjet(mu));
    Eigen::MatrixXd fs(nf_, n_structure), ss(n_structure, n_structure);
    Eigen::MatrixXd sf = Eigen::MatrixXd::Zero(n_structure, nf_);
    for (Eigen::Index i = 0; i < nf_ + n_structure; ++i)
      for (int j = 0; j < n_structure; ++j) {
        if (i < nf_) fs(i, j) = rj[i].derivative(j);
        else ss(i - nf_, j) = rj[i].derivative(j);
      }
    // A_sf: loads are linear in the wall pressures (structure_flow_entries)
    const auto m = moved_metrics<double>(w);
    const coupling::rigid_rotation<double> rot(w[nf_ + 2]);
    structure_flow_entries(m, rot, w.data(), nullptr,
                           [&sf](int i, Eigen::Index cell, int v, double x) { sf(i, cell * nv + v) += x; });
    return {std::move(aff), std::move(fs), std::move(sf), std::move(ss), name};
  }

  /// The bordered Jacobian in blocks of nv: block rows/columns 0..nc-1 the flow cells, block nc
  /// the 4 structural unknowns. Pattern: the flow part's, plus the structural column in every
  /// row (the rigid motion moves every cell) and, in the structural row, the wall cells (the
  /// only flow unknowns the loads depend on) and the diagonal.
  block_sparse_matrix<double, nv> padded_form(const bordered_block_matrix<double, nv>& j) const {
    using sidx = block_sparse_matrix<double, nv>::storage_index;
    const auto& aff = j.flow();
    const auto nc = static_cast<sidx>(nf_ / nv);
    std::vector<sidx> wall_cells;
    for (const auto& f : walls_) {
      wall_cells.push_back(static_cast<sidx>(f.cell0));
      wall_cells.push_back(static_cast<sidx>(f.cell1));
    }
    std::sort(wall_cells.begin(), wall_cells.end());
    wall_cells.erase(std::unique(wall_cells.begin(), wall_cells.end()), wall_cells.end());
    const auto& frp = aff.row_ptr();
    const auto& fci = aff.col_index();
    std::vector<sidx> rp(static_cast<std::size_t>(nc) + 2), ci;
    ci.reserve(fci.size() + static_cast<std::size_t>(nc) + wall_cells.size() + 1);
    for (sidx i = 0; i < nc; ++i) {  // flow row: its flow blocks (sorted), then the structural column nc
      rp[i] = static_cast<sidx>(ci.size());
      ci.insert(ci.end(), fci.begin() + frp[i], fci.begin() + frp[i + 1]);
      ci.push_back(nc);
    }
    rp[nc] = static_cast<sidx>(ci.size());
    ci.insert(ci.end(), wall_cells.begin(), wall_cells.end());
    ci.push_back(nc);
    rp[nc + 1] = static_cast<sidx>(ci.size());
    block_sparse_matrix<double, nv> a;
    a.set_pattern_csr(nc + 1, nc + 1, rp, ci);
    constexpr std::ptrdiff_t bb = nv * nv;
    for (sidx i = 0; i < nc; ++i) {
      std::copy(aff.values().begin() + frp[i] * bb, aff.values().begin() + frp[i + 1] * bb, a.values().begin() + rp[i] * bb);
      a.block_at(rp[i + 1] - 1) = j.flow_structure().middleRows(Eigen::Index(i) * nv, nv);
    }
    for (std::size_t k = 0; k < wall_cells.size(); ++k)
      a.block_at(rp[nc] + static_cast<sidx>(k)) = j.structure_flow().middleCols(Eigen::Index(wall_cells[k]) * nv, nv);
    a.block_at(rp[nc + 1] - 1) = j.structure();
    return a;
  }

  flow::euler_model<2> flow_;
  structure::pitch_plunge structure_;
  std::array<double, 2> ea_{};
  Eigen::Index nf_ = 0;
  std::vector<wall_face> walls_;
  std::vector<std::array<std::vector<std::array<double, 2>>, 2>> face_arm_;  // rest face mid-point - axis, by block, axis
};

}  // namespace aerohopf::models
