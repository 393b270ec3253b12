#pragma once
// The pitch-plunge aerofoil's flutter_family (models/aerofoil_family.hpp) with its heavy solves
// on the ranks of an MPI communicator, so that trace_flutter_boundary (run alike on every rank)
// computes the serial boundary with the work split:
//  * equilibrium: the steady flow about the section at rest by flow::solve_steady on the ranks
//    (distributed_euler_discretisation, block-Jacobi BILU), gathered, its loads checked as
//    aerofoil_system::steady_equilibrium does;
//  * hopf_start: distributed::inverse_power at (w, Ubar), shift i omega (the driver's
//    hopf_start_krylov options: BILU fill, GMRES restart and tolerance, eigen-residual target);
//  * solve_hopf: distributed::solve_hopf (fixed equilibrium) with the driver's Newton options,
//    BILU fill, GMRES restart and forcing bound.
// Vectors cross this interface whole: each rank's part of a result is all-gathered, so the
// driver's predictions, mode test, tracer hand-over and crossing check run on every rank on the
// same numbers and every rank takes the same decisions (the reductions are MPI_Allreduce: the
// same bits everywhere). The grid and the systems are replicated (about 0.55 kB a cell: fine for
// the aerofoil; a wing wants a per-rank grid).
// Each level's C-grid is partitioned by whole blocks (partition_blocks: 3 blocks, so 1 to 3
// ranks), the same cells as the serial numbering, so the boundary equals the serial one to the
// solvers' tolerances; only the preconditioner (block Jacobi across the ranks) and hence the
// linear iterations differ; the serial solve_hopf_krylov's start refinement
// (hopf_krylov_options::start_iterations, threshold and tolerance) is done on the ranks alike.
// Zero incidence only: the static aeroelastic equilibrium of a mean incidence (the full
// formulation's moving equilibrium) is not yet solved on the ranks, so such a family is refused.
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/mpi_aerofoil.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <utility>

namespace aerohopf::distributed {

class aerofoil_family {
 public:
  using system_type = models::aerofoil_system;
  static constexpr int block_size = models::aerofoil_family::block_size;

  /// serial: the family (the same on every rank, zero incidence); comm: its ranks (1 to 3, the
  /// C-grid's blocks). Collective: every rank must construct it.
  aerofoil_family(models::aerofoil_family serial, MPI_Comm comm) : serial_(std::move(serial)), comm_(comm) {
    internal::check_mpi(MPI_Comm_size(comm_, &ranks_), "MPI_Comm_size");
    internal::check_mpi(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    require(serial_.alpha() == 0.0, "distributed::aerofoil_family: angle of attack ", serial_.alpha(),
            " rad: the static aeroelastic equilibrium of a mean incidence is not solved on the ranks (zero incidence "
            "only)");
  }

  system_type system(int stride, double mach) const { return serial_.system(stride, mach); }
  static std::string level_name(int stride) { return models::aerofoil_family::level_name(stride); }
  bool fixed_equilibrium() const { return true; }

  /// The steady flow of s about the section at rest on the ranks (the same for every Ubar),
  /// whole on every rank; convergence_error as aerofoil_system::steady_equilibrium (no
  /// convergence, or loads on the section at rest).
  vec<double> equilibrium(const system_type& s, double /*ubar*/) const {
    flow::euler_model<2> m = s.flow();
    distributed_euler<2> d(m, partition_blocks(m, ranks_), comm_);
    distributed_euler_discretisation<2> disc(m, d);
    vec<double> wf = d.local_part(m.free_stream_vector());
    const auto r = flow::solve_steady(disc, wf, serial_.steady_options());
    const double mach = s.flow().conditions().mach;
    if (!r.converged)
      throw convergence_error(aerohopf::internal::concat(
          "distributed::aerofoil_family::equilibrium: the steady flow at M = ", mach, " on ", ranks_,
          " ranks did not converge (", r.steps, " steps, residual ", r.final_residual, ": ", r.reason, ")"));
    vec<double> w = s.free_stream_state();
    w.head(s.flow_size()) = d.all_gather(wf);
    const auto [cl, cm] = s.load_coefficients<double>(w);
    if (!(std::abs(cl) <= max_load && std::abs(cm) <= max_load))
      throw convergence_error(aerohopf::internal::concat(
          "distributed::aerofoil_family::equilibrium: the steady flow at M = ", mach, " loads the section at rest (C_l = ",
          cl, ", C_m = ", cm, ", limit ", max_load, "): not an equilibrium of the coupled system"));
    return w;
  }

  /// w0 itself: at zero incidence the equilibrium does not depend on Ubar.
  vec<double> equilibrium_from(const system_type& s, const vec<double>& w0, double u0, double ubar) const {
    return serial_.equilibrium_from(s, w0, u0, ubar);
  }

  /// The eigenpair of J(w, Ubar) nearest i omega by inverse power on the ranks, as a Hopf start
  /// (as hopf_start_krylov: omega > 0, the vector's phase normalised; info: the eigenpair with
  /// its iteration and GMRES counts, the vector whole).
  hopf_point hopf_start(const system_type& s, const vec<double>& w, double ubar, double omega,
                        const hopf_start_krylov_options& so, eigen_pair* info) const {
    distributed_aerofoil d(s, partition_blocks(s.flow(), ranks_), comm_);
    distributed_aerofoil::jacobian_rows a, p;
    d.jacobians(d.local_part(w), ubar, a, p);
    distributed_inverse_power_options io;
    io.power = so.inverse_power;
    io.fill_level = so.fill_level;
    io.linear.relative_tolerance = so.krylov.relative_tolerance;
    io.linear.restart = so.krylov.restart;
    io.linear.max_iterations = so.krylov.max_iterations;
    eigen_pair ep = inverse_power(d, a, so.precondition_exact ? nullptr : &p, {0.0, omega}, io);
    ep.vector = d.all_gather(ep.vector);
    aerohopf::internal::normalise_phase(ep.vector);
    if (info) *info = ep;
    return aerohopf::internal::hopf_point_from(w, ubar, ep);
  }

  /// The Hopf point from `guess` on the ranks (fixed-equilibrium formulation), whole on every
  /// rank; failures as distributed::solve_hopf (convergence_error on every rank).
  hopf_result solve_hopf(const system_type& s, const hopf_point& guess, const hopf_options& ho,
                         const hopf_krylov_options& ko) const {
    require(ho.fixed_equilibrium && !ko.full_system,
            "distributed::aerofoil_family::solve_hopf: the fixed-equilibrium formulation only (zero incidence)");
    distributed_aerofoil d(s, partition_blocks(s.flow(), ranks_), comm_);
    distributed_hopf_options o;
    o.hopf = ho;
    o.fill_level = ko.fill_level;
    o.krylov.restart = ko.krylov.restart;
    o.krylov.max_iterations = ko.krylov.max_iterations;
    o.eta_max = ko.eta_max;
    o.start_iterations = ko.start_iterations;
    o.start_tolerance = ko.start_tolerance;
    o.start_max_iterations = ko.start_max_iterations;
    o.start_residual_threshold = ko.start_residual_threshold;
    distributed_hopf_point g{d.local_part(guess.w), guess.mu, guess.omega, d.local_part(guess.p)};
    const distributed_hopf_result r = distributed::solve_hopf(d, g, o);
    hopf_result h;
    h.point.w = guess.w;  // the fixed equilibrium, unchanged
    h.point.mu = r.point.mu;
    h.point.omega = r.point.omega;
    h.point.p = d.all_gather(r.point.p);
    // the normalisation e_k: p_k = i at the largest component
    Eigen::Index k = 0;
    h.point.p.cwiseAbs().maxCoeff(&k);
    h.s = vec<double>::Zero(h.point.p.size());
    h.s[k] = 1.0;
    h.report = r.report;
    h.linear_iterations = r.linear_iterations;
    h.setup_seconds = r.setup_seconds;
    h.linear_seconds = r.linear_seconds;
    h.residual_seconds = r.residual_seconds;
    h.start_refined = r.start_refined;
    return h;
  }

  flutter_boundary_options boundary_options() const { return serial_.boundary_options(); }
  bool refines(int coarse_stride, int fine_stride) const { return serial_.refines(coarse_stride, fine_stride); }
  std::optional<int> coarser_level(int stride) const { return serial_.coarser_level(stride); }
  vec<std::complex<double>> prolong(const system_type& fine, const system_type& coarse,
                                    const vec<std::complex<double>>& p) const {
    return serial_.prolong(fine, coarse, p);
  }
  vec<std::complex<double>> structure_part(const vec<std::complex<double>>& p) const {
    return serial_.structure_part(p);
  }
  static double stiffness_factor(double ubar) { return models::aerofoil_family::stiffness_factor(ubar); }
  static double parameter_of_factor(double q) { return models::aerofoil_family::parameter_of_factor(q); }

  const models::aerofoil_family& serial() const { return serial_; }
  MPI_Comm communicator() const { return comm_; }
  int ranks() const { return ranks_; }
  int rank() const { return rank_; }

  /// |C_l|, |C_m| above which the steady flow about the section at rest is no equilibrium (as
  /// aerofoil_system::steady_equilibrium's default).
  static constexpr double max_load = 1e-6;

 private:
  models::aerofoil_family serial_;
  MPI_Comm comm_;
  int ranks_ = 1, rank_ = 0;
};

static_assert(flutter_family<aerofoil_family>);

}  // namespace aerohopf::distributed
