#pragma once
// Shift-invert inverse power on MPI ranks: the eigenpair of a partitioned flow Jacobian A
// nearest a complex shift sigma (the root locus' and the Hopf start's eigen-solve), by the one
// iteration of bifurcation/inverse_power.hpp with its norms and inner products summed over the
// ranks. Each solve (A - sigma I) y = x is complex GMRES on the ranks (A real, vectors
// complex), preconditioned by block-Jacobi complex BILU(k) of each rank's square part of
// P - sigma I, P the preconditioning matrix (the modified-order Jacobian for an exact A, or A).
// The solves are inexact, to a relative residual tau: the eigen-residual then stagnates at
// about tau |lambda - sigma| (the error of each solve, scaled by the growth 1/|lambda - sigma|
// of the wanted component), so tau need not lie far below the eigen-tolerance when the shift is
// near. Its default, 1e-9, sits above GMRES's attainable floor near such a shift (about
// eps ||A|| / |lambda - sigma|: 2e-10 at |lambda - sigma| = 0.002 on the tests' coarse
// aerofoil). A shift AT an eigenvalue makes A - sigma I singular: GMRES then fails
// (convergence_error on every rank); the root locus' shifts are the previous point's.

#include <mpi.h>

#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <cmath>
#include <complex>
#include <string>

namespace aerohopf::distributed {

/// inverse power's vector operations on vectors distributed over `comm` (each process its
/// part): sums of the local squared norms and inner products; the largest entry of the
/// process holding it, broadcast.
struct distributed_vectors {
  MPI_Comm comm;

  double squared_norm(const vec<std::complex<double>>& v) const {
    double s = v.squaredNorm();
    internal::sum_over_ranks(comm, &s, 1);
    return s;
  }
  std::complex<double> dot(const vec<std::complex<double>>& a, const vec<std::complex<double>>& b) const {
    std::complex<double> s = a.dot(b);
    internal::sum_over_ranks(comm, &s, 1);
    return s;
  }
  std::complex<double> largest_entry(const vec<std::complex<double>>& x) const {
    const int rank = internal::comm_rank(comm);
    struct {
      double value;
      int rank;
    } best{-1.0, rank};
    std::complex<double> mine = 0.0;
    if (x.size() > 0) {
      Eigen::Index i = 0;
      best.value = x.cwiseAbs().maxCoeff(&i);
      mine = x[i];
    }
    internal::check_mpi(MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm), "MPI_Allreduce");
    internal::check_mpi(MPI_Bcast(&mine, 1, MPI_C_DOUBLE_COMPLEX, best.rank, comm), "MPI_Bcast");
    return mine;
  }
};

struct distributed_inverse_power_options {
  inverse_power_options power;  ///< tolerance on ||A x - lambda x|| / max(1, |lambda|), iterations
  /// each shifted solve: relative tolerance 1e-9 (file comment), at most 500 iterations, GMRES(100)
  krylov_options krylov{.relative_tolerance = 1e-9, .max_iterations = 500, .restart = 100, .record_history = false};
  int fill_level = 0;           ///< k of the block-Jacobi BILU(k)
  bool single_precision_factors = false;  ///< block_ilu_options::single_precision_factors
};

namespace internal {

/// The part shared by the distributed inverse powers: the start (`start`, or this rank's part of
/// the serial default start of n_global entries, by local_part), unit-normalised over the ranks,
/// then the one iteration with GMRES on `op` preconditioned by `pc` for each solve. Collective.
template <class LocalPart, class Apply, class Op, class Pc>
eigen_pair run_inverse_power(MPI_Comm comm, const vec<std::complex<double>>* start, Eigen::Index n_global,
                             const LocalPart& local_part, const Apply& apply, const Op& op, const Pc& pc,
                             std::complex<double> shift, double a_norm, const distributed_inverse_power_options& opt,
                             const char* who) {
  using C = std::complex<double>;
  const distributed_vectors space{comm};
  vec<C> x;
  if (start) {
    x = *start;
  } else {  // this rank's part of the serial default start
    const vec<C> g = aerohopf::internal::default_start(n_global);
    const vec<double> re = local_part(vec<double>(g.real())), im = local_part(vec<double>(g.imag()));
    x.resize(re.size());
    x.real() = re;
    x.imag() = im;
  }
  const double nx2 = space.squared_norm(x);
  collective(comm, who, [&] { require(nx2 > 0, who, ": start vector is zero"); });
  x /= std::sqrt(nx2);
  krylov_options ko = opt.krylov;
  ko.throw_on_failure = true;
  const std::string context = ko.context;
  int solve = 0;
  return aerohopf::internal::inverse_power_iteration(
      space, apply,
      [&](const vec<C>& v, long& linear_iterations) {
        vec<C> y = vec<C>::Zero(v.size());
        // a failed solve names itself: which inverse power, its shift and which of its solves
        ko.context = aerohopf::internal::concat(who, " at shift ", shift, ", shifted solve ", ++solve, " (BILU(",
                                                opt.fill_level, ") block Jacobi; ", context, ")");
        linear_iterations += gmres(op, pc, v, y, ko).iterations;
        return y;
      },
      shift, a_norm, std::move(x), opt.power, who);
}

}  // namespace internal

/// The eigenpair of A nearest `shift`: A a matrix of this rank's rows in d's numbering
/// (distributed_euler::jacobian), `pre` the matrix whose block-Jacobi BILU(k) preconditions the
/// shifted solves (nullptr: A itself), `start` this rank's part of the start vector (nullptr:
/// the part of the serial default start, so that 1 and N ranks start alike). The vector of the
/// result is this rank's part. Collective; input_error (on every rank) for a non-finite shift,
/// bad options, a start of the wrong size, zero or not finite, or a non-finite matrix entry;
/// convergence_error (every rank) if a GMRES solve or the iteration does not converge.
template <int Dim>
eigen_pair inverse_power(distributed_euler<Dim>& d, const block_sparse_matrix<double, Dim + 2>& a,
                         const block_sparse_matrix<double, Dim + 2>* pre, std::complex<double> shift,
                         const distributed_inverse_power_options& opt = {},
                         const vec<std::complex<double>>* start = nullptr) {
  using C = std::complex<double>;
  constexpr int nv = Dim + 2;
  const char* who = "distributed inverse power";
  const MPI_Comm comm = d.communicator();
  double a_norm = 0;
  internal::collective(comm, who, [&] {
    require(std::isfinite(shift.real()) && std::isfinite(shift.imag()), who, ": shift ", shift, " is not finite");
    require(opt.power.max_iterations >= 1, who, ": max_iterations must be >= 1 (got ", opt.power.max_iterations, ")");
    require(std::isfinite(opt.power.tolerance) && opt.power.tolerance > 0, who,
            ": tolerance must be finite and > 0 (got ", opt.power.tolerance, ")");
    require(opt.fill_level >= 0 && opt.fill_level <= 8, who, ": fill_level must lie in [0, 8] (got ", opt.fill_level,
            ")");
    for (const auto* m : {&a, pre}) {
      if (!m) continue;
      require(m->block_rows() == d.numbering().rows && m->block_cols() == d.numbering().cols, who, ": a matrix has ",
              m->block_rows(), " x ", m->block_cols(), " blocks, this rank's numbering ", d.numbering().rows, " x ",
              d.numbering().cols);
    }
    if (start) {
      require_size(start->size(), d.local_size(), who, "start vector (this rank's part)");
      require_finite(*start, who, "start vector");
    }
    vec<double> row_sums = vec<double>::Zero(d.local_size());
    for (Eigen::Index i = 0; i < a.block_rows(); ++i)
      for (auto p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) {
        const auto& blk = a.block_at(p);
        require(blk.allFinite(), who, ": a matrix entry in block row ", i, " (this rank's numbering) is not finite");
        row_sums.segment(i * nv, nv) += blk.cwiseAbs().rowwise().sum();
      }
    a_norm = row_sums.size() ? row_sums.maxCoeff() : 0.0;
  });
  a_norm = internal::max_over_ranks(comm, a_norm);
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.single_precision_factors = opt.single_precision_factors;
  io.context = "distributed inverse power: block-Jacobi BILU of P - sigma I";
  block_ilu<C, nv> ilu(io);
  internal::collective(comm, who, [&] { ilu.compute(shifted(owned_part(pre ? *pre : a), shift)); });
  const distributed_matrix_operator<Dim, C> op(d, a, comm, shift);
  return internal::run_inverse_power(
      comm, start, d.model().size(), [&d](const vec<double>& g) { return d.local_part(g); },
      [&](const vec<C>& v) { return d.multiply(a, v); }, op, ilu, shift, a_norm, opt, who);
}

}  // namespace aerohopf::distributed
