#pragma once
// The flexible wing's flutter_family (models/wing_family.hpp) with its heavy solves on the ranks
// of an MPI communicator, so that trace_flutter_boundary (run alike on every rank) computes the
// serial boundary with the work split, as distributed::aerofoil_family does for the aerofoil:
//  * each solve cuts the level's one-block grid for the ranks (split_for_ranks along the
//    wall-normal direction: as many blocks as ranks where it divides so) and builds the wing
//    system on the cut grid
//    (models::split_wing_system, distributed_wing): the same cells in another order;
//  * equilibrium: the steady flow about the wing at rest by flow::solve_steady on the ranks
//    (distributed_euler_discretisation, block-Jacobi BILU), gathered, its generalised forces
//    checked as wing_system::steady_equilibrium does;
//  * hopf_start: distributed::inverse_power at (w, mu), shift i omega (the driver's
//    hopf_start_krylov options);
//  * solve_hopf: distributed::solve_hopf (fixed equilibrium: the wing family's only formulation)
//    with the driver's Newton options, BILU fill, GMRES restart, forcing bound and start
//    refinement.
// Vectors cross this interface whole and in the serial system's cell order (to_split_order and
// back), all-gathered, so the driver runs on every rank on the same numbers and takes the same
// decisions. The grid, its metrics and the systems are replicated on every rank (the memory
// note of mpi_euler.hpp); the cut system is rebuilt per call (its metrics: a small part of a
// Hopf solve).
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/mpi_family.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/distributed/mpi_wing.hpp>
#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/models/wing_family.hpp>

#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <utility>

namespace aerohopf::distributed {

/// A wing system cut for the ranks of comm, and its distributed evaluation; vectors to and from
/// the serial system's order. Collective construction; `s` must outlive it.
class wing_on_ranks {
 public:
  static constexpr int nv = models::wing_system::nv;
  /// cut_axis: the index direction the grid is cut along (split_for_ranks; -1: its longest).
  /// wing_cgrid's wall-normal direction j by default: the wall and the near field stay on one
  /// rank, so block Jacobi drops only weak far-field couplings (AGARD coarse grid, 2 ranks, M =
  /// 0.499: 425 GMRES iterations for the Hopf point against 543 cut along the span and 607 around
  /// the section, the longest axis; 368 serially).
  static constexpr int normal_axis = 1;
  wing_on_ranks(const models::wing_system& s, MPI_Comm comm, int cut_axis = normal_axis)
      : cut_(split_for_ranks(s.flow().grid(), internal::comm_size(comm), 1.1, cut_axis)),
        sys_(models::split_wing_system(s, cut_)),
        d_(sys_, partition_blocks(sys_.flow(), internal::comm_size(comm)), comm) {}

  distributed_wing& d() { return d_; }
  const flow::split_grid<3>& cut() const { return cut_; }
  const models::wing_system& system() const { return sys_; }
  /// This rank's part of a whole vector of the serial system (real or complex).
  template <class S>
  vec<S> local(const vec<S>& whole) const {
    return d_.local_part(flow::to_split_order(cut_, whole, nv));
  }
  /// The whole vector, in the serial system's order, from every rank's part (collective).
  template <class S>
  vec<S> whole(const vec<S>& local) {
    return flow::from_split_order(cut_, d_.all_gather(local), nv);
  }

 private:
  flow::split_grid<3> cut_;
  models::wing_system sys_;
  distributed_wing d_;
};

class wing_family : public distributed_family_base<models::wing_family> {
 public:
  /// serial: the family (the same on every rank); comm: its ranks; cut_axis: as wing_on_ranks's.
  /// Collective: every rank must construct it.
  wing_family(models::wing_family serial, MPI_Comm comm, int cut_axis = wing_on_ranks::normal_axis)
      : distributed_family_base(std::move(serial), comm), cut_axis_(cut_axis) {}

  /// The steady flow about the wing at rest on the ranks, whole on every rank (the same for every
  /// mu); convergence_error (every rank) if it does not converge or does work on the modes at
  /// rest (largest generalised force above max_load), as wing_system::steady_equilibrium.
  vec<double> equilibrium(const system_type& s, double /*mu*/) const {
    const flow::split_grid<3> cut = split_for_ranks(s.flow().grid(), ranks_, 1.1, cut_axis_);
    const flow::euler_model<3> m(cut.grid, s.flow().conditions(), s.flow().options());
    vec<double> w = s.free_stream_state();
    w.head(s.flow_size()) = steady_flow_on_ranks(m, comm_, serial_.steady_options(), "distributed::wing_family");
    w = flow::from_split_order(cut, w, wing_on_ranks::nv);
    const double mach = s.flow().conditions().mach;
    const double g = s.generalised_forces<double>(w).cwiseAbs().maxCoeff();
    if (!(g <= max_load))
      throw convergence_error(aerohopf::internal::concat(
          "distributed::wing_family: the steady flow at M = ", mach, " does work on the modes at rest (largest "
          "generalised force ", g, ", limit ", max_load, "): not an equilibrium of the coupled system"));
    return w;
  }
  vec<double> equilibrium_from(const system_type& s, const vec<double>& w0, double mu0, double mu) const {
    return serial_.equilibrium_from(s, w0, mu0, mu);
  }

  /// The eigenpair of J(w, mu) nearest i omega by inverse power on the ranks, as a Hopf start
  /// (as hopf_start_krylov: omega > 0, the vector's phase normalised; info: the eigenpair with
  /// its iteration and GMRES counts, the vector whole).
  hopf_point hopf_start(const system_type& s, const vec<double>& w, double mu, double omega,
                        const hopf_start_krylov_options& so, eigen_pair* info) const {
    wing_on_ranks r(s, comm_, cut_axis_);
    distributed_wing::jacobian_rows a, p;
    r.d().jacobians(r.local(w), mu, a, p);
    const distributed_inverse_power_options io = internal::inverse_power_options_from(so);
    eigen_pair ep = inverse_power(r.d(), a, so.precondition_exact ? nullptr : &p, {0.0, omega}, io);
    ep.vector = r.whole(ep.vector);
    aerohopf::internal::normalise_phase(ep.vector);
    if (info) *info = ep;
    return aerohopf::internal::hopf_point_from(w, mu, ep);
  }

  /// The Hopf point from `guess` on the ranks (fixed equilibrium), whole on every rank; failures
  /// as distributed::solve_hopf (convergence_error on every rank).
  hopf_result solve_hopf(const system_type& s, const hopf_point& guess, const hopf_options& ho,
                         const hopf_krylov_options& ko) const {
    wing_on_ranks r(s, comm_, cut_axis_);
    const distributed_hopf_point g{r.local(guess.w), guess.mu, guess.omega, r.local(guess.p)};
    const distributed_hopf_result res = distributed::solve_hopf(r.d(), g, internal::hopf_options_from(ho, ko));
    vec<std::complex<double>> p = r.whole(res.point.p);  // collective calls in one order
    vec<double> w = ho.fixed_equilibrium ? guess.w : r.whole(res.point.w);  // fixed: w unchanged
    return internal::hopf_result_from(res, std::move(w), std::move(p));
  }

  /// Largest generalised force of the steady flow about the wing at rest for an equilibrium (as
  /// wing_system::steady_equilibrium's default).
  static constexpr double max_load = 1e-8;

 private:
  int cut_axis_;
};

static_assert(flutter_family<wing_family>);

}  // namespace aerohopf::distributed
