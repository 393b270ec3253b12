#pragma once
// Steady Euler solutions on a grid partitioned over MPI ranks: flow::solve_steady (the one
// pseudo-transient Newton-Krylov algorithm, flow/steady_solver.hpp) run on every rank with
// this discretisation. Each rank holds its cells' part of the state; residuals, Jacobian rows,
// time steps and wall forces are its own (distributed_euler, bitwise the serial rows); norms
// and inner products are summed over the ranks; GMRES is preconditioned by block-Jacobi
// BILU(k), the factorisation of each rank's square part (couplings across ranks dropped, the
// original's preconditioner "method 3"). Every decision of the solver (accept a step, the CFL,
// convergence) is taken on sums every rank has, so all ranks take the same steps; a rejected
// step or a failure names the cell and is the same text on every rank.
//
// Compared with the serial solve only the preconditioner differs (block Jacobi across the
// ranks), so the linear iterations per step and hence the nonlinear path differ slightly; both
// converge to the same steady state to the accuracy of the stopping test.
//
//   flow::euler_model<2> m(grid, conditions);                 // the same on every rank
//   distributed::distributed_euler<2> d(m, distributed::partition_blocks(m, ranks), MPI_COMM_WORLD);
//   distributed::distributed_euler_discretisation<2> disc(m, d);
//   vec<double> w = d.local_part(m.free_stream_vector());
//   const auto report = flow::solve_steady(disc, w, options);  // w: this rank's converged part

#include <mpi.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <climits>
#include <string>
#include <utility>
#include <vector>

namespace aerohopf::distributed {

/// One rank's part of a partitioned Euler model as a flow::steady_discretisation. `m` is the
/// model `d` was built on (checked); it is non-const because the vortex far field's circulation
/// is a parameter of it, set to the same value on every rank. Both must outlive this object.
template <int Dim>
class distributed_euler_discretisation {
 public:
  static constexpr int block_size = Dim + 2;
  using matrix = block_sparse_matrix<double, block_size>;

  distributed_euler_discretisation(flow::euler_model<Dim>& m, distributed_euler<Dim>& d)
      : m_(m), d_(d), comm_(d.communicator()) {
    require(&d.model() == &m, "distributed_euler_discretisation: the distributed evaluation is of another model");
    vol_ = d_.volumes();
  }

  Eigen::Index size() const { return d_.local_size(); }
  vec<double> residual(const vec<double>& w) { return d_.residual(w); }
  vec<double> spectral_radius(const vec<double>& w) { return d_.spectral_radius(w); }
  const std::vector<double>& volumes() const { return vol_; }
  void jacobian(const vec<double>& w, flow::jacobian_kind kind, matrix& a) { d_.jacobian(w, kind, a); }

  /// The square part of this rank's rows in its own cells: block Jacobi (its pattern is the
  /// same at every call, so BILU's symbolic analysis is reused).
  const matrix& preconditioning_part(const matrix& a) {
    own_ = owned_part(a);
    return own_;
  }

  template <class Pc>
  krylov_report gmres(const matrix& a, const Pc& pc, const vec<double>& b, vec<double>& x, const krylov_options& ko) {
    const distributed_matrix_operator<Dim, double> op(d_, a, comm_);
    return aerohopf::gmres<double>(op, pc, b, x, ko);
  }

  void global_sum(double* p, int n) const { internal::sum_over_ranks(comm_, p, n); }

  /// The text of the lowest rank whose text is not empty ("" if none), with its rank, on every
  /// rank.
  std::string agree(const std::string& text) const {
    int first = text.empty() ? INT_MAX : d_.rank();
    internal::check_mpi(MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm_), "MPI_Allreduce");
    if (first == INT_MAX) return {};
    long long n = static_cast<long long>(text.size());
    internal::check_mpi(MPI_Bcast(&n, 1, MPI_LONG_LONG, first, comm_), "MPI_Bcast");
    std::string out = first == d_.rank() ? text : std::string(static_cast<std::size_t>(n), ' ');
    internal::check_mpi(MPI_Bcast(out.data(), static_cast<int>(n), MPI_CHAR, first, comm_), "MPI_Bcast");
    return aerohopf::internal::concat(out, " [rank ", first, "]");
  }

  template <class F>
  void collective(const char* what, F&& f) const {
    internal::collective(comm_, what, std::forward<F>(f));
  }

  /// Size and finite entries of every rank's part, then the physical state of the cells each
  /// rank reads (collective: every rank throws if one part is bad).
  void check_initial(const vec<double>& w, const char* who) {
    collective(who, [&] {
      require_size(w.size(), d_.local_size(), who, "state (this rank's part)");
      require_finite(w, who, "state (this rank's part)");
    });
    const std::string bad = d_.nonphysical(w);
    collective(who, [&] {
      if (!bad.empty()) throw input_error(aerohopf::internal::concat(who, ": initial state: ", bad));
    });
  }

  std::string nonphysical(const vec<double>& w) { return d_.nonphysical(w); }
  flow::force_coefficients forces(const vec<double>& w) { return d_.forces(w); }
  bool vortex() const { return Dim == 2 && m_.options().vortex_far_field; }
  double circulation() const { return m_.circulation(); }
  void set_circulation(double g) { m_.set_circulation(g); }  // the same g on every rank (summed forces)
  std::string conditions_text() const { return flow::conditions_text(m_); }

  /// The cell with the largest residual norm on any rank, named on every rank.
  std::pair<double, std::string> largest_residual(const vec<double>& r) const {
    constexpr int nv = block_size;
    struct {
      double value;
      int rank;
    } best{-1.0, d_.rank()};
    Eigen::Index worst = 0;
    for (Eigen::Index c = 0; c < r.size() / nv; ++c)
      if (const double v = r.segment(c * nv, nv).norm(); v > best.value) {
        best.value = v;
        worst = c;
      }
    long long cell = r.size() > 0 ? static_cast<long long>(d_.global_cell(worst)) : 0;
    internal::check_mpi(MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm_), "MPI_Allreduce");
    internal::check_mpi(MPI_Bcast(&cell, 1, MPI_LONG_LONG, best.rank, comm_), "MPI_Bcast");
    return {best.value, m_.cell_name(static_cast<std::size_t>(cell))};
  }

 private:
  flow::euler_model<Dim>& m_;
  distributed_euler<Dim>& d_;
  MPI_Comm comm_;
  std::vector<double> vol_;
  matrix own_;
};

/// The steady flow of `model` from the free stream on the ranks of comm (its blocks partitioned
/// by partition_blocks: the grid must have at least as many blocks as ranks), whole on every rank
/// in the model's cell order; convergence_error (every rank) naming `who`, the Mach number and
/// the ranks if it does not converge. The distributed flutter families' equilibria. Progress
/// (o.log: a line per step with the global residual) is written by rank 0 only.
template <int Dim>
vec<double> steady_flow_on_ranks(const flow::euler_model<Dim>& model, MPI_Comm comm, const flow::steady_options& o,
                                 const char* who) {
  const int ranks = internal::comm_size(comm);
  flow::euler_model<Dim> m = model;
  distributed_euler<Dim> d(m, partition_blocks(m, ranks), comm);
  distributed_euler_discretisation<Dim> disc(m, d);
  vec<double> wf = d.local_part(m.free_stream_vector());
  flow::steady_options ro = o;
  if (internal::comm_rank(comm) != 0) ro.log = nullptr;
  const auto r = flow::solve_steady(disc, wf, ro);
  if (!r.converged)
    throw convergence_error(aerohopf::internal::concat(who, ": the steady flow at M = ", model.conditions().mach,
                                                       " on ", ranks, " ranks did not converge (", r.steps,
                                                       " steps, residual ", r.final_residual, ": ", r.reason, ")"));
  return d.all_gather(wf);
}

}  // namespace aerohopf::distributed
