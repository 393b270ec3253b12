#pragma once
// The modal aeroelastic wing (models/wing.hpp) on MPI ranks: the flow grid partitioned as in
// mpi_euler.hpp (a wing grid is one block: cut it first, split_for_ranks, and build the system on
// the cut grid, models::split_wing_system), the 2m structural unknowns (a, a') on one rank, the
// root, in the bordered form of mpi_bordered.hpp (local vectors, Jacobian rows, products, and
// the preconditioner, inverse power, static equilibrium and root locus written there).
//
// Evaluations, each collective and each equal to the serial system's (tests on 2 and 3 ranks):
//  - residual: the flow rows of the rank's cells on the grid moved to the modal state
//    (wing_system::moved_metrics_of, the whole grid's metrics on every rank, and the rest model's
//    residual_of_blocks: the serial rows) and the structural rates f_s = [a'; mu g - K a - D a']
//    from the generalised forces g, whose parts (the loaded faces of each rank's blocks) are
//    summed over the ranks;
//  - jacobian: A_ff (distributed_euler's numbering, on the moved grid as the serial assembly),
//    A_fs (its rows) and A_ss from passes of the rank's residual and forces in jet<double, 8> (8
//    structural unknowns per pass: one pass for four modes; the forces' derivatives summed over
//    the ranks), A_sf = mu dg/dw_f (its wall cells' columns).
// Memory: as distributed_euler (the grid and its metrics replicated), plus a moved copy of the
// flow model and, during a jet pass, a whole-grid jet state and moved metrics (nine doubles per
// value).

#include <mpi.h>

#include <aerohopf/distributed/mpi_bordered.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/models/wing.hpp>
#include <aerohopf/scalar/jet.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aerohopf::distributed {

class distributed_wing : public distributed_bordered<3> {
 public:
  /// Structural unknowns per jet pass of the coupling columns.
  static constexpr int jet_width = models::wing_system::jet_width;

  /// `sys` (the same on every rank, on a grid of at least as many blocks as ranks) must outlive
  /// this object; `part` assigns its flow grid's blocks to the ranks of `comm`. Collective.
  distributed_wing(const models::wing_system& sys, const block_partition& part, MPI_Comm comm)
      : distributed_bordered<3>(sys.structure_size(), comm, "mu"), sys_(sys), moved_(sys.flow()), d_(moved_, part, comm) {
    attach(d_);
  }

  const models::wing_system& sys() const { return sys_; }
  Eigen::Index modes() const { return sys_.modes(); }

  /// f(w, mu) in this rank's part (collective).
  vec<double> residual(const vec<double>& local, double mu) {
    check_state(local, mu, "distributed_wing::residual");
    const vec<double> ws = structure_of(local);
    const vec<double>& full = d_.state_with_halo(local.head(flow_size()));
    residual_.resize(full.size());
    vec<double> r(local_size()), g;
    with_metrics(ws, [&](const flow::grid_metrics<double, 3>& m) {
      internal::collective(communicator(), "distributed_wing::residual", [&] {
        sys_.flow().residual_of_blocks<double>(m, full.data(), residual_.data(), d_.owned_blocks());
      });
      g = sys_.forces_of_blocks<double>(m, full.data(), &d_.owned_blocks());
    });
    r.head(flow_size()) = d_.local_part(residual_);
    sum(g.data(), static_cast<int>(g.size()));
    const vec<double> rs = sys_.structure().residual<double>(ws, g, mu);
    if (rank() == root) r.tail(ns_) = rs;
    else r.tail(ns_).setZero();
    return r;
  }

  /// The exact (kind exact) or modified-order Jacobian in this rank's rows at (w, mu)
  /// (collective). The border is the same for both kinds.
  void jacobian(const vec<double>& local, double mu, flow::jacobian_kind kind, jacobian_rows& j) {
    check_state(local, mu, "distributed_wing::jacobian");
    const vec<double> ws = structure_of(local);
    const vec<double> wf = local.head(flow_size());
    move_flow_to(ws);
    d_.jacobian(wf, kind, j.flow);

    // [A_fs; A_ss]: passes of this rank's residual and of its part of the forces with jets along
    // the structural unknowns j0 .. j0 + width - 1
    using sjet = jet<double, jet_width>;
    const Eigen::Index m = sys_.modes();
    const vec<double>& full = d_.state_with_halo(wf);
    j.flow_structure.resize(flow_size(), ns_);
    j.structure.resize(ns_, ns_);
    vec<sjet> rj(full.size());
    j.structure_d_mu.setZero(ns_, ns_);
    for (Eigen::Index j0 = 0; j0 < ns_; j0 += jet_width) {
      const Eigen::Index width = std::min<Eigen::Index>(jet_width, ns_ - j0);
      const vec<sjet> wj = full.cast<sjet>();
      vec<sjet> wsj = ws.cast<sjet>();
      for (Eigen::Index k = 0; k < width; ++k) wsj[j0 + k] = sjet::variable(ws[j0 + k], static_cast<int>(k));
      const auto mj = sys_.moved_metrics_of<sjet>(wsj);
      internal::collective(communicator(), "distributed_wing::jacobian", [&] {
        sys_.flow().residual_of_blocks<sjet>(mj, wj.data(), rj.data(), d_.owned_blocks());
      });
      vec<sjet> g = sys_.forces_of_blocks<sjet>(mj, wj.data(), &d_.owned_blocks());
      sum_jets(g);
      const vec<sjet> rs = sys_.structure().residual<sjet>(wsj, g, sjet(mu));
      store_coupling_columns(rj, rs, j0, width, j);
      for (Eigen::Index k = 0; k < width && j0 + k < m; ++k)  // dg/da: the a' rows of dA_ss/dmu
        for (Eigen::Index i = 0; i < m; ++i) j.structure_d_mu(m + i, j0 + k) = g[i].derivative(static_cast<int>(k));
    }

    // A_sf = mu dg/dw_f: this rank's wall cells
    const auto& num = d_.numbering();
    j.structure_flow_d_mu.setZero(ns_, flow_size());
    with_metrics(ws, [&](const flow::grid_metrics<double, 3>& mt) {
      sys_.force_pressure_entries(mt, full.data(), &d_.owned_blocks(),
                                  [&](Eigen::Index i, Eigen::Index cell, int v, double x) {
                                    j.structure_flow_d_mu(m + i, num.local[static_cast<std::size_t>(cell)] * nv + v) += x;
                                  });
    });
    j.structure_flow = mu * j.structure_flow_d_mu;
    j.mu = mu;
  }

  /// The exact and the modified-order Jacobian rows at (w, mu) together: the border (the jet
  /// passes) and the moved grid computed once (collective).
  void jacobians(const vec<double>& local, double mu, jacobian_rows& exact, jacobian_rows& preconditioning) {
    jacobian(local, mu, flow::jacobian_kind::exact, exact);
    // moved_ is at w's modal state now
    d_.jacobian(local.head(flow_size()), flow::jacobian_kind::modified_order, preconditioning.flow);
    preconditioning.flow_structure = exact.flow_structure;
    preconditioning.structure_flow = exact.structure_flow;
    preconditioning.structure = exact.structure;
    preconditioning.mu = exact.mu;
    preconditioning.structure_flow_d_mu = exact.structure_flow_d_mu;
    preconditioning.structure_d_mu = exact.structure_d_mu;
  }

  /// Moves Jacobian rows to another mu without re-assembly: mu scales the generalised forces
  /// only, so A_sf and A_ss are affine in it (their d/dmu kept in the rows).
  void set_parameter(jacobian_rows& j, double mu) const {
    require(std::isfinite(mu) && std::isfinite(j.mu) && j.structure_d_mu.rows() == ns_ &&
                j.structure_flow_d_mu.cols() == flow_size(),
            "distributed_wing::set_parameter: mu ", mu, " (rows assembled at ", j.mu,
            ") must be finite, the rows this rank's assembly");
    if (mu == j.mu) return;
    j.structure_flow += (mu - j.mu) * j.structure_flow_d_mu;
    j.structure += (mu - j.mu) * j.structure_d_mu;
    j.mu = mu;
  }

  /// f_mu = [0; 0; g(w)] in this rank's part: the generalised forces in the a' rows on the root
  /// (collective).
  vec<double> residual_d_parameter(const vec<double>& local, double mu) {
    check_state(local, mu, "distributed_wing::residual_d_parameter");
    const vec<double> ws = structure_of(local);
    const vec<double>& full = d_.state_with_halo(local.head(flow_size()));
    vec<double> g;
    with_metrics(ws, [&](const flow::grid_metrics<double, 3>& m) {
      g = sys_.forces_of_blocks<double>(m, full.data(), &d_.owned_blocks());
    });
    sum(g.data(), static_cast<int>(g.size()));
    vec<double> r = vec<double>::Zero(local_size());
    if (rank() == root) r.tail(modes()) = g;
    return r;
  }

  /// A_mu x (d/dmu of the rows, kept by jacobian()) in this rank's part, real or complex x
  /// (collective: x's structure broadcast, the border rows summed).
  template <class S>
  vec<S> parameter_column(const jacobian_rows& j, const vec<S>& x) const {
    const vec<S> xs = structure_of(x);
    vec<S> part = j.structure_flow_d_mu * x.head(flow_size());
    sum(part.data(), static_cast<int>(ns_));
    vec<S> r = vec<S>::Zero(local_size());
    if (rank() == root) r.tail(ns_) = part + j.structure_d_mu * xs;
    return r;
  }

 private:
  /// fn(metrics of the grid at the modal state ws): the rest metrics (no copy) at ws = 0, as the
  /// serial system.
  template <class Fn>
  void with_metrics(const vec<double>& ws, Fn&& fn) const {
    if (ws.isZero(0.0)) fn(sys_.flow().metrics());
    else fn(sys_.moved_metrics_of<double>(ws));
  }

  /// moved_ (the model d_ evaluates) on the grid of the modal state ws.
  void move_flow_to(const vec<double>& ws) {
    if (ws.isZero(0.0)) {
      if (moved_is_moved_) {
        moved_ = sys_.flow();  // the rest model itself; d_ keeps its address
        moved_is_moved_ = false;
      }
      return;
    }
    flow::multiblock_points<double, 3> pts, spd;
    sys_.moved_points<double>(ws, pts, spd);
    moved_.set_grid_motion(pts, &spd);
    moved_is_moved_ = true;
  }

  /// Sums jets (values and derivatives) over the ranks in place (collective).
  template <class Jet>
  void sum_jets(vec<Jet>& g) const {
    constexpr int w = Jet::directions;
    std::vector<double> buf(static_cast<std::size_t>(g.size()) * (w + 1));
    for (Eigen::Index i = 0; i < g.size(); ++i) {
      buf[static_cast<std::size_t>(i * (w + 1))] = g[i].value();
      for (int k = 0; k < w; ++k) buf[static_cast<std::size_t>(i * (w + 1) + 1 + k)] = g[i].derivative(k);
    }
    sum(buf.data(), static_cast<int>(buf.size()));
    for (Eigen::Index i = 0; i < g.size(); ++i) {
      g[i] = Jet(buf[static_cast<std::size_t>(i * (w + 1))]);
      for (int k = 0; k < w; ++k) g[i].derivative(k) = buf[static_cast<std::size_t>(i * (w + 1) + 1 + k)];
    }
  }

  const models::wing_system& sys_;
  flow::euler_model<3> moved_;  // the flow model on the grid moved to the last Jacobian's modal state
  distributed_euler<3> d_;      // evaluates on moved_ (its metrics: the rest ones or moved)
  vec<double> residual_;        // whole-grid residual buffer (this rank's cells written)
  bool moved_is_moved_ = false;
};

}  // namespace aerohopf::distributed
