#pragma once
// The pitch-plunge aerofoil's flutter_family (models/aerofoil_family.hpp) with its heavy solves
// on the ranks of an MPI communicator, so that trace_flutter_boundary (run alike on every rank)
// computes the serial boundary with the work split:
//  * equilibrium: the steady flow about the section at rest by flow::solve_steady on the ranks
//    (distributed_euler_discretisation, block-Jacobi BILU), gathered; at zero incidence its loads
//    are checked as aerofoil_system::steady_equilibrium does; at a mean incidence the static
//    aeroelastic equilibrium is continued from it in Ubar by distributed::solve_equilibrium
//    (Newton-GMRES on the coupled rows), as the serial family does with solve_equilibrium_krylov;
//  * hopf_start: distributed::inverse_power at (w, Ubar), shift i omega (the driver's
//    hopf_start_krylov options: BILU fill, GMRES restart and tolerance, eigen-residual target);
//  * solve_hopf: distributed::solve_hopf in the driver's formulation (fixed equilibrium, or the
//    full system at an incidence) with its Newton options, BILU fill, GMRES restart, forcing bound
//    and start refinement;
//  * scan_eigen: at an incidence, the inverse powers of the driver's V-g scans (a jump's scan,
//    the crossing check) by distributed::inverse_power, where the system is above the driver's
//    scan_direct_max_unknowns (below, each rank factors A - sigma I by sparse LU as serially).
// Vectors cross this interface whole: each rank's part of a result is all-gathered, so the
// driver's predictions, mode test, tracer hand-over and crossing check run on every rank on the
// same numbers and every rank takes the same decisions
// (the reductions are MPI_Allreduce: the same bits everywhere). The grid and the systems are
// replicated (about 0.55 kB a cell: fine for the aerofoil; a wing wants a per-rank grid).
// Each level's C-grid is partitioned by whole blocks where it has as many blocks as ranks (3:
// lower wake, aerofoil, upper wake), in the serial numbering; on more ranks its blocks are cut
// first (aerofoil_on_ranks: split_for_ranks along the wall-normal direction, the system rebuilt
// on the cut grid, vectors converted to and from the serial order). Either way the boundary
// equals the serial one to the solvers' tolerances; only the preconditioner (block Jacobi
// across the ranks) and hence the linear iterations differ.
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/mpi_aerofoil.hpp>
#include <aerohopf/distributed/mpi_family.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace aerohopf::distributed {

/// An aerofoil system on the ranks of comm: on at most as many ranks as its grid has blocks the
/// system itself, its blocks whole; on more, its grid cut first (split_for_ranks, within 1.1 of
/// balance, along the wall-normal direction j where a block has 4 cells or more there: the wall
/// and its near field stay on one rank, as wing_on_ranks) and the system rebuilt on the cut grid
/// (the same cells in another order; the rigid grid motion moves every point alike). local() and
/// whole() convert vectors from and to the serial system's order. Collective construction; `s`
/// must outlive it.
class aerofoil_on_ranks {
 public:
  static constexpr int nv = distributed_aerofoil::nv;
  static constexpr int normal_axis = 1;
  aerofoil_on_ranks(const models::aerofoil_system& s, MPI_Comm comm)
      : ranks_(internal::comm_size(comm)), cut_(cut_for(s.flow().grid(), ranks_)), own_(rebuilt(s, cut_)),
        d_(own_ ? *own_ : s, partition_blocks((own_ ? *own_ : s).flow(), ranks_), comm) {}

  distributed_aerofoil& d() { return d_; }
  /// The grid is cut (more ranks than the grid's blocks).
  bool cut() const { return cut_.has_value(); }
  /// This rank's part of a whole vector of the serial system (real or complex).
  template <class S>
  vec<S> local(const vec<S>& whole) const {
    return cut_ ? d_.local_part(flow::to_split_order(*cut_, whole, nv)) : d_.local_part(whole);
  }
  /// The whole vector, in the serial system's order, from every rank's part (collective).
  template <class S>
  vec<S> whole(const vec<S>& local) {
    return cut_ ? flow::from_split_order(*cut_, d_.all_gather(local), nv) : d_.all_gather(local);
  }
  /// The grid the ranks share out: cut for more ranks than blocks, else empty (the serial grid).
  static std::optional<flow::split_grid<2>> cut_for(const flow::multiblock_grid<2>& g, int ranks) {
    if (static_cast<std::size_t>(ranks) <= g.topology.cells.size()) return std::nullopt;
    return split_for_ranks(g, ranks, 1.1, normal_axis);
  }

 private:
  static std::unique_ptr<models::aerofoil_system> rebuilt(const models::aerofoil_system& s,
                                                          const std::optional<flow::split_grid<2>>& cut) {
    if (!cut) return nullptr;
    return std::make_unique<models::aerofoil_system>(
        flow::euler_model<2>(cut->grid, s.flow().conditions(), s.flow().options()), s.structure());
  }
  int ranks_;
  std::optional<flow::split_grid<2>> cut_;
  std::unique_ptr<models::aerofoil_system> own_;  // the system on the cut grid (cut_ only)
  distributed_aerofoil d_;
};

class aerofoil_family : public distributed_family_base<models::aerofoil_family> {
 public:
  /// serial: the family (the same on every rank); comm: its ranks (any number: aerofoil_on_ranks).
  /// Collective: every rank must construct it.
  aerofoil_family(models::aerofoil_family serial, MPI_Comm comm) : distributed_family_base(std::move(serial), comm) {}

  /// The equilibrium of s at Ubar on the ranks, whole on every rank: at zero incidence the steady
  /// flow about the section at rest (the same for every Ubar; convergence_error as
  /// aerofoil_system::steady_equilibrium if it does not converge or loads the section); at an
  /// incidence the static aeroelastic equilibrium continued from it (static_equilibrium_from).
  vec<double> equilibrium(const system_type& s, double ubar) const {
    const bool at_rest = serial_.alpha() == 0.0;
    vec<double> w = steady_flow(s, at_rest);
    if (at_rest) return w;
    return static_equilibrium_from(s, w, 0.0, ubar);
  }

  /// The equilibrium at ubar from w0, the one at u0: w0 itself at zero incidence, else
  /// static_equilibrium_from.
  vec<double> equilibrium_from(const system_type& s, const vec<double>& w0, double u0, double ubar) const {
    if (serial_.alpha() == 0.0) return serial_.equilibrium_from(s, w0, u0, ubar);
    return static_equilibrium_from(s, w0, u0, ubar);
  }

  /// The static aeroelastic equilibrium at ubar from w0 (whole; the one at u0, 0: the section at
  /// rest) on the ranks: distributed::solve_equilibrium (BILU(2), ||f|| <= 1e-10, full Newton
  /// steps) in the serial family's continuation in Ubar (models::aerofoil_family::continue_in_ubar:
  /// a failed step halved down to 1/64 of |Ubar|, then convergence_error). Whole on every rank.
  vec<double> static_equilibrium_from(const system_type& s, const vec<double>& w0, double u0, double ubar) const {
    require(std::isfinite(ubar) && ubar != 0.0 && std::isfinite(u0),
            "distributed::aerofoil_family::static_equilibrium_from: Ubar = ", ubar, " from ", u0);
    require_size(w0.size(), s.size(), "distributed::aerofoil_family::static_equilibrium_from", "start state");
    aerofoil_on_ranks r(s, comm_);
    distributed_aerofoil& d = r.d();
    const std::string who = aerohopf::internal::concat("distributed::aerofoil_family::static_equilibrium at M = ",
                                                       s.flow().conditions().mach, ", Ubar = ", ubar, " on ", ranks_,
                                                       " ranks");
    const vec<double> w = models::aerofoil_family::continue_in_ubar(
        r.local(w0), u0, ubar, who,
        [&](const vec<double>& wl, double u, std::string& why) -> std::optional<vec<double>> {
          auto eq = solve_equilibrium(d, wl, u);
          if (eq.converged) return std::move(eq.w);
          why = eq.reason;
          return std::nullopt;
        });
    return r.whole(w);
  }

  /// The steady flow of s about the section at rest on the ranks, whole on every rank, the
  /// structure at rest; check_loads: convergence_error if it loads the section (|C_l| or |C_m| >
  /// max_load: then it is no equilibrium of the coupled system).
  vec<double> steady_flow(const system_type& s, bool check_loads) const {
    vec<double> w = s.free_stream_state();
    if (const auto cut = aerofoil_on_ranks::cut_for(s.flow().grid(), ranks_)) {
      const flow::euler_model<2> m(cut->grid, s.flow().conditions(), s.flow().options());
      w.head(s.flow_size()) = steady_flow_on_ranks(m, comm_, serial_.steady_options(), "distributed::aerofoil_family");
      w = flow::from_split_order(*cut, w, aerofoil_on_ranks::nv);
    } else {
      w.head(s.flow_size()) =
          steady_flow_on_ranks(s.flow(), comm_, serial_.steady_options(), "distributed::aerofoil_family");
    }
    const double mach = s.flow().conditions().mach;
    if (!check_loads) return w;
    const auto [cl, cm] = s.load_coefficients<double>(w);
    if (!(std::abs(cl) <= max_load && std::abs(cm) <= max_load))
      throw convergence_error(aerohopf::internal::concat(
          "distributed::aerofoil_family: the steady flow at M = ", mach, " loads the section at rest (C_l = ", cl,
          ", C_m = ", cm, ", limit ", max_load, "): not an equilibrium of the coupled system"));
    return w;
  }

  /// The eigenpair of J(w, Ubar) nearest i omega by inverse power on the ranks, as a Hopf start
  /// (as hopf_start_krylov: omega > 0, the vector's phase normalised; info: the eigenpair with
  /// its iteration and GMRES counts, the vector whole).
  hopf_point hopf_start(const system_type& s, const vec<double>& w, double ubar, double omega,
                        const hopf_start_krylov_options& so, eigen_pair* info) const {
    aerofoil_on_ranks r(s, comm_);
    distributed_aerofoil::jacobian_rows a, p;
    r.d().jacobians(r.local(w), ubar, a, p);
    const distributed_inverse_power_options io = internal::inverse_power_options_from(so);
    eigen_pair ep = inverse_power(r.d(), a, so.precondition_exact ? nullptr : &p, {0.0, omega}, io);
    ep.vector = r.whole(ep.vector);
    aerohopf::internal::normalise_phase(ep.vector);
    if (info) *info = ep;
    return aerohopf::internal::hopf_point_from(w, ubar, ep);
  }

  /// The Hopf point from `guess` on the ranks in the formulation of ho.fixed_equilibrium, whole
  /// on every rank; failures as distributed::solve_hopf (convergence_error on every rank).
  hopf_result solve_hopf(const system_type& s, const hopf_point& guess, const hopf_options& ho,
                         const hopf_krylov_options& ko) const {
    aerofoil_on_ranks r(s, comm_);
    const distributed_hopf_point g{r.local(guess.w), guess.mu, guess.omega, r.local(guess.p)};
    const distributed_hopf_result res = distributed::solve_hopf(r.d(), g, internal::hopf_options_from(ho, ko));
    vec<std::complex<double>> p = r.whole(res.point.p);  // collective calls in one order
    vec<double> w = ho.fixed_equilibrium ? guess.w : r.whole(res.point.w);  // fixed: w unchanged
    return internal::hopf_result_from(res, std::move(w), std::move(p));
  }

  /// The inverse powers of the driver's V-g scans (moving equilibrium: the jump's scan and the
  /// crossing check) on the ranks: eig(w, Ubar, shift, start, power) is the eigenpair of J(w,
  /// Ubar) nearest `shift` from the whole vector `start` (nullptr: the default start) by
  /// distributed::inverse_power, GMRES (ko.krylov's tolerance and limit, a restart of at least
  /// scan_min_restart) preconditioned by the block-Jacobi BILU(ko.fill_level) of the
  /// modified-order rows, as vg_krylov_solvers does serially; the vector whole on every rank. The
  /// partition and the rows at (w, Ubar) are made once per Ubar (the scan calls it for every mode
  /// there). Collective.
  auto scan_eigen(const system_type& s, const vg_krylov_options& ko) const {
    struct rows_at {
      double ubar = NAN;
      std::unique_ptr<aerofoil_on_ranks> r;
      distributed_aerofoil::jacobian_rows a, p;
    };
    return [this, &s, ko, cache = std::make_shared<rows_at>()](
               const vec<double>& w, double ubar, std::complex<double> shift, const vec<std::complex<double>>* start,
               const inverse_power_options& power) {
      if (!cache->r) cache->r = std::make_unique<aerofoil_on_ranks>(s, comm_);
      aerofoil_on_ranks& r = *cache->r;
      distributed_aerofoil& d = r.d();
      if (!(ubar == cache->ubar)) {  // the equilibrium is a function of Ubar
        d.jacobians(r.local(w), ubar, cache->a, cache->p);
        cache->ubar = ubar;
      }
      distributed_inverse_power_options io = internal::inverse_power_options_from(ko, power);
      io.krylov.restart = std::max(io.krylov.restart, scan_min_restart);
      vec<std::complex<double>> x0;
      if (start) x0 = r.local(*start);
      eigen_pair ep = inverse_power(d, cache->a, &cache->p, shift, io, start ? &x0 : nullptr);
      ep.vector = r.whole(ep.vector);
      return ep;
    };
  }

  /// The smallest GMRES restart of scan_eigen: block Jacobi across the ranks drops couplings the
  /// serial BILU keeps (3 ranks, very coarse C-grid, alpha 1 deg, M = 0.55: GMRES(50) stalls at a
  /// relative residual of 0.54 for the damped mode near -0.277 + 0.5i; GMRES(100) converges).
  static constexpr int scan_min_restart = 100;

  /// |C_l|, |C_m| above which the steady flow about the section at rest is no equilibrium (as
  /// aerofoil_system::steady_equilibrium's default).
  static constexpr double max_load = 1e-6;
};

static_assert(flutter_family<aerofoil_family>);

}  // namespace aerohopf::distributed
