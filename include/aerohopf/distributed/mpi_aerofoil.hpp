#pragma once
// The pitch-plunge aerofoil (models/aerofoil.hpp) on MPI ranks: the flow grid partitioned as in
// mpi_euler.hpp, the four structural unknowns (h, h', alpha, alpha') on one rank, the root, in
// the bordered form of mpi_bordered.hpp (local vectors, Jacobian rows, products, and the
// preconditioner, inverse power, static equilibrium and root locus written there).
//
// Evaluations, each collective and each equal to the serial system's (tests on 2 and 3 ranks):
//  - residual: the flow rows of the rank's cells on the grid moved to the structural state
//    (aerofoil_system::moved_metrics and the rest model's residual_of_blocks, bitwise the serial
//    rows) and the structural rates from the loads, whose parts (the wall faces of each rank's
//    blocks) are summed over the ranks;
//  - jacobian: A_ff (distributed_euler's numbering, on the moved grid as the serial assembly),
//    A_fs (its rows) and A_ss from one jet<double, 4> pass of the rank's residual and loads (the
//    loads' derivatives summed over the ranks), A_sf (its wall cells' columns).
// Memory: as distributed_euler (the grid replicated), plus a moved copy of the flow model and,
// during the jet pass, a whole-grid jet state (five doubles per value).

#include <mpi.h>

#include <aerohopf/distributed/mpi_bordered.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/scalar/jet.hpp>

#include <array>
#include <cmath>
#include <complex>

namespace aerohopf::distributed {

class distributed_aerofoil : public distributed_bordered<2> {
 public:
  static constexpr int ns = models::aerofoil_system::n_structure;

  /// `sys` (the same on every rank) must outlive this object; `part` assigns its flow grid's
  /// blocks to the ranks of `comm`. Collective.
  distributed_aerofoil(const models::aerofoil_system& sys, const block_partition& part, MPI_Comm comm)
      : distributed_bordered<2>(ns, comm, "Ubar"), sys_(sys), moved_(sys.flow()), d_(moved_, part, comm) {
    attach(d_);
  }

  /// f(w, Ubar) in this rank's part (collective).
  vec<double> residual(const vec<double>& local, double ubar) {
    check_state(local, ubar, "distributed_aerofoil::residual");
    const Eigen::Vector4d ws = structure_of(local);
    const coupling::rigid_pose<double> q{ws[0], ws[1], ws[2], ws[3]};
    const auto m = sys_.moved_metrics<double>(q);
    vec<double> r(local_size());
    const vec<double>& full = d_.state_with_halo(local.head(flow_size()));
    residual_.resize(full.size());
    internal::collective(comm_, "distributed_aerofoil::residual", [&] {
      sys_.flow().residual_of_blocks<double>(m, full.data(), residual_.data(), d_.owned_blocks());
    });
    r.head(flow_size()) = d_.local_part(residual_);
    auto [cl, cm] = sys_.loads_of_blocks<double>(m, coupling::rigid_rotation<double>(ws[2]), full.data(),
                                                 &d_.owned_blocks());
    std::array<double, 2> loads{cl, cm};
    sum(loads.data(), 2);
    const auto rs = sys_.structure().rate<double>(ws, loads[0], loads[1], ubar);
    // element by element: GCC 12 with AVX-512 warns falsely on a fixed-to-dynamic copy
    for (int i = 0; i < ns; ++i) r[flow_size() + i] = d_.rank() == root ? rs[i] : 0.0;
    return r;
  }

  /// The exact (kind exact) or modified-order Jacobian in this rank's rows at (w, Ubar)
  /// (collective). The border is the same for both kinds.
  void jacobian(const vec<double>& local, double ubar, flow::jacobian_kind kind, jacobian_rows& j) {
    check_state(local, ubar, "distributed_aerofoil::jacobian");
    const Eigen::Vector4d ws = structure_of(local);
    const vec<double> wf = local.head(flow_size());
    // A_ff on the grid moved to ws, as the serial assembly (the rest model when ws = 0)
    if (ws.isZero(0.0)) {
      if (moved_is_moved_) {
        moved_ = sys_.flow();  // the rest model itself (its metrics as constructed); d_ keeps its address
        moved_is_moved_ = false;
      }
    } else {
      flow::multiblock_points<double, 2> pts, spd;
      coupling::rigid_grid_motion<double>(sys_.flow().grid().points,
                                          coupling::rigid_pose<double>{ws[0], ws[1], ws[2], ws[3]},
                                          {sys_.structure().parameters().x_ea, sys_.structure().parameters().y_ea}, pts,
                                          &spd);
      moved_.set_grid_motion(pts, &spd);
      moved_is_moved_ = true;
    }
    d_.jacobian(wf, kind, j.flow);

    // [A_fs; A_ss]: one jet pass (direction k = structural unknown k) of this rank's residual
    // and of its part of the loads
    using sjet = jet<double, ns>;
    const vec<double>& full = d_.state_with_halo(wf);
    vec<sjet> wj = full.cast<sjet>();
    coupling::rigid_pose<sjet> qj{sjet::variable(ws[0], 0), sjet::variable(ws[1], 1), sjet::variable(ws[2], 2),
                                  sjet::variable(ws[3], 3)};
    const auto mj = sys_.moved_metrics<sjet>(qj);
    vec<sjet> rj(full.size());
    const auto& model = sys_.flow();
    internal::collective(comm_, "distributed_aerofoil::jacobian", [&] {
      model.residual_of_blocks<sjet>(mj, wj.data(), rj.data(), d_.owned_blocks());
    });
    const auto& num = d_.numbering();
    j.flow_structure.resize(flow_size(), ns);
    j.structure.resize(ns, ns);
    for (const auto& [first, last] : d_.plan().owned)
      for (std::size_t c = first; c < last; ++c)
        for (int v = 0; v < nv; ++v)
          for (int k = 0; k < ns; ++k)
            j.flow_structure(num.local[c] * nv + v, k) = rj[static_cast<Eigen::Index>(c * nv + v)].derivative(k);
    const auto [clj, cmj] = sys_.loads_of_blocks<sjet>(mj, coupling::rigid_rotation<sjet>(qj.alpha), wj.data(),
                                                       &d_.owned_blocks());
    std::array<double, 2 * (ns + 1)> parts{};
    parts[0] = clj.value();
    parts[ns + 1] = cmj.value();
    for (int k = 0; k < ns; ++k) {
      parts[1 + k] = clj.derivative(k);
      parts[ns + 2 + k] = cmj.derivative(k);
    }
    sum(parts.data(), static_cast<int>(parts.size()));
    sjet cl(parts[0]), cm(parts[ns + 1]);
    for (int k = 0; k < ns; ++k) {
      cl.derivative(k) = parts[1 + k];
      cm.derivative(k) = parts[ns + 2 + k];
    }
    Eigen::Matrix<sjet, 4, 1> wsj;
    for (int k = 0; k < ns; ++k) wsj[k] = sjet::variable(ws[k], k);
    const auto rs = sys_.structure().rate<sjet>(wsj, cl, cm, sjet(ubar));
    for (int i = 0; i < ns; ++i)
      for (int k = 0; k < ns; ++k) j.structure(i, k) = rs[i].derivative(k);
    j.mu = ubar;

    // A_sf: this rank's wall cells
    j.structure_flow.setZero(ns, flow_size());
    const auto m = sys_.moved_metrics<double>(coupling::rigid_pose<double>{ws[0], ws[1], ws[2], ws[3]});
    sys_.structure_flow_entries(m, coupling::rigid_rotation<double>(ws[2]), full.data(), &d_.owned_blocks(),
                                [&](int i, Eigen::Index cell, int v, double x) {
                                  j.structure_flow(i, num.local[static_cast<std::size_t>(cell)] * nv + v) += x;
                                });
  }

  /// The exact and the modified-order Jacobian rows at (w, Ubar) together: the border (one jet
  /// pass) and the moved grid computed once, as aerofoil_system::bordered_jacobians (collective).
  void jacobians(const vec<double>& local, double ubar, jacobian_rows& exact, jacobian_rows& preconditioning) {
    jacobian(local, ubar, flow::jacobian_kind::exact, exact);
    // moved_ is at w's pose now
    d_.jacobian(local.head(flow_size()), flow::jacobian_kind::modified_order, preconditioning.flow);
    preconditioning.flow_structure = exact.flow_structure;
    preconditioning.structure_flow = exact.structure_flow;
    preconditioning.structure = exact.structure;
    preconditioning.mu = exact.mu;
  }

  /// Moves Jacobian rows to another Ubar without re-assembly: Ubar enters only the stiffness,
  /// so only A_ss changes, by the in-vacuo part -M^{-1} (K(Ubar) - K(j.mu)).
  void set_parameter(jacobian_rows& j, double ubar) const {
    require(std::isfinite(ubar) && ubar != 0 && std::isfinite(j.mu), "distributed_aerofoil::set_parameter: Ubar ",
            ubar, " (rows assembled at ", j.mu, ") must be finite and non-zero");
    if (ubar == j.mu) return;
    const auto& st = sys_.structure();
    j.structure += st.in_vacuo_matrix(ubar) - st.in_vacuo_matrix(j.mu);
    j.mu = ubar;
  }

  /// dA/dUbar: zero but for the structural block, -M^{-1} dK/dUbar (4 x 4, every rank).
  Eigen::MatrixXd structure_d_ubar(double ubar) const {
    const auto& st = sys_.structure();
    return -st.mass_inverse() * st.stiffness_d_ubar(ubar);
  }

  /// df/dUbar in this rank's part: the structural rows -M^{-1} dK/dUbar w_s on the root, zeros
  /// elsewhere (collective: the root's structure broadcast).
  vec<double> residual_d_parameter(const vec<double>& local, double ubar) const {
    const vec<double> ws = structure_of(local);
    const Eigen::MatrixXd b = structure_d_ubar(ubar);
    vec<double> r = vec<double>::Zero(local_size());
    if (rank() == root) r.tail(ns) = b * ws;
    return r;
  }

  /// (dA/dUbar) x at the rows' Ubar in this rank's part (collective: x's structure broadcast).
  template <class S>
  vec<S> parameter_column(const jacobian_rows& j, const vec<S>& x) const {
    const vec<S> xs = structure_of(x);
    const Eigen::MatrixXd b = structure_d_ubar(j.mu);
    vec<S> r = vec<S>::Zero(local_size());
    if (rank() == root) r.tail(ns) = b * xs;
    return r;
  }

  const models::aerofoil_system& sys() const { return sys_; }

 private:
  const models::aerofoil_system& sys_;
  flow::euler_model<2> moved_;  // the flow model on the grid moved to the last Jacobian's pose
  distributed_euler<2> d_;      // evaluates on moved_ (its metrics: the rest ones or moved)
  vec<double> residual_;        // whole-grid residual buffer (this rank's cells written)
  bool moved_is_moved_ = false;
};

}  // namespace aerohopf::distributed
