#pragma once
// PETSc as the distributed linear algebra beside our own (optional component aerohopf::petsc:
// MPI plus PETSc by pkg-config, Debian's libpetsc-real3.18-dev; the caller runs
// PetscInitialize after MPI_Init and PetscFinalize before MPI_Finalize).
//
//  - petsc_block_numbering: the global PETSc block index of every column of a rank's rows in
//    distributed_euler's local numbering (rank r owns the contiguous block rows after those of
//    ranks 0 .. r-1, in its local order; the received cells' indices come by one halo exchange).
//  - to_petsc(d, a, columns): one rank's block rows as a BAIJ matrix (MPIBAIJ, SeqBAIJ on one
//    rank) of block size Dim + 2 with exact preallocation from our pattern: the blocks in the
//    rank's own columns go to the diagonal part, those in received columns to the
//    off-diagonal part, so the assembly never allocates.
//  - petsc_solve: KSP GMRES(restart) with block Jacobi across the ranks and, per rank, either
//    PETSc's ILU(k) of the BAIJ diagonal part (block ILU for block size > 1) or our BILU(k)
//    (linalg/block_ilu.hpp) of the same square part through a shell preconditioner: the
//    original's preconditioner "method 3" (couplings across partitions dropped), by either
//    library, on the same matrix. Right preconditioning and the unpreconditioned residual norm,
//    as our GMRES, so the iteration counts compare.
// Errors: a PETSc call that fails throws std::runtime_error naming the call and PETSc's text; a
// KSP that does not converge is reported (converged = false, reason), not thrown.

#include <mpi.h>
#include <petscksp.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace aerohopf::distributed {

namespace internal {

inline void check_petsc(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(aerohopf::internal::concat("PETSc: ", call, " failed (error ", static_cast<int>(code), ": ",
                                                      text ? text : "no text", ")"));
}

/// Owner of one PETSc object (Mat, Vec, KSP): destroyed with the owner, movable, not copyable.
template <class T, PetscErrorCode (*Destroy)(T*)>
class petsc_handle {
 public:
  petsc_handle() = default;
  explicit petsc_handle(T h) : h_(h) {}
  petsc_handle(petsc_handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  petsc_handle& operator=(petsc_handle&& o) noexcept {
    std::swap(h_, o.h_);
    return *this;
  }
  petsc_handle(const petsc_handle&) = delete;
  petsc_handle& operator=(const petsc_handle&) = delete;
  ~petsc_handle() {
    if (h_) Destroy(&h_);
  }
  T get() const { return h_; }
  T* out() { return &h_; }

 private:
  T h_ = nullptr;
};

}  // namespace internal

using petsc_mat = internal::petsc_handle<Mat, MatDestroy>;
using petsc_vec = internal::petsc_handle<Vec, VecDestroy>;
using petsc_ksp = internal::petsc_handle<KSP, KSPDestroy>;

/// The global PETSc block index of each column (block) of this rank's local numbering
/// (d.numbering().cols entries; collective).
template <int Dim>
std::vector<PetscInt> petsc_block_numbering(distributed_euler<Dim>& d) {
  constexpr int nv = Dim + 2;
  long long rows = d.numbering().rows, first = 0;
  distributed::internal::check_mpi(MPI_Exscan(&rows, &first, 1, MPI_LONG_LONG, MPI_SUM, d.communicator()),
                                   "MPI_Exscan");
  if (d.rank() == 0) first = 0;  // MPI_Exscan leaves rank 0's result undefined
  vec<double> idx(d.local_size());
  for (Eigen::Index i = 0; i < d.numbering().rows; ++i)
    idx.segment(i * nv, nv).setConstant(static_cast<double>(first + i));  // exact below 2^53 blocks
  const vec<double> ext = d.with_ghosts(idx);
  std::vector<PetscInt> cols(static_cast<std::size_t>(d.numbering().cols));
  for (std::size_t c = 0; c < cols.size(); ++c) cols[c] = static_cast<PetscInt>(ext[static_cast<Eigen::Index>(c) * nv]);
  return cols;
}

/// This rank's block rows `a` (d.jacobian's numbering) as a PETSc BAIJ matrix over d's
/// communicator, columns numbered by `columns` (petsc_block_numbering). Collective.
template <int Dim>
petsc_mat to_petsc(distributed_euler<Dim>& d, const block_sparse_matrix<double, Dim + 2>& a,
                   const std::vector<PetscInt>& columns) {
  constexpr int nv = Dim + 2;
  const Eigen::Index nb = a.block_rows();
  distributed::internal::collective(d.communicator(), "to_petsc", [&] {
    require(nb == d.numbering().rows && a.block_cols() == d.numbering().cols, "to_petsc: the matrix has ", nb, " x ",
            a.block_cols(), " blocks, this rank's numbering ", d.numbering().rows, " x ", d.numbering().cols);
    require(static_cast<Eigen::Index>(columns.size()) == a.block_cols(), "to_petsc: ", columns.size(),
            " column indices for ", a.block_cols(), " block columns");
  });
  std::vector<PetscInt> d_nnz(static_cast<std::size_t>(nb), 0), o_nnz(static_cast<std::size_t>(nb), 0);
  for (Eigen::Index i = 0; i < nb; ++i)
    for (auto p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) ++(a.col_index()[p] < nb ? d_nnz : o_nnz)[i];
  petsc_mat m;
  const PetscInt n = static_cast<PetscInt>(nb * nv);
  internal::check_petsc(MatCreateBAIJ(d.communicator(), nv, n, n, PETSC_DETERMINE, PETSC_DETERMINE, 0, d_nnz.data(), 0,
                                      o_nnz.data(), m.out()),
                        "MatCreateBAIJ");
  internal::check_petsc(MatSetOption(m.get(), MAT_ROW_ORIENTED, PETSC_FALSE), "MatSetOption");  // column-major blocks
  internal::check_petsc(MatSetOption(m.get(), MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  PetscInt first = 0;
  internal::check_petsc(MatGetOwnershipRange(m.get(), &first, nullptr), "MatGetOwnershipRange");
  first /= nv;
  std::vector<PetscInt> cols;
  for (Eigen::Index i = 0; i < nb; ++i) {
    const PetscInt row = first + static_cast<PetscInt>(i);
    cols.clear();
    for (auto p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) cols.push_back(columns[a.col_index()[p]]);
    internal::check_petsc(MatSetValuesBlocked(m.get(), 1, &row, static_cast<PetscInt>(cols.size()), cols.data(),
                                              a.values().data() + static_cast<std::size_t>(a.row_ptr()[i]) * nv * nv,
                                              INSERT_VALUES),
                          "MatSetValuesBlocked");
  }
  internal::check_petsc(MatAssemblyBegin(m.get(), MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  internal::check_petsc(MatAssemblyEnd(m.get(), MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  return m;
}

/// A PETSc vector over comm holding this rank's part `local`.
inline petsc_vec to_petsc(const vec<double>& local, MPI_Comm comm) {
  petsc_vec v;
  internal::check_petsc(VecCreateMPI(comm, static_cast<PetscInt>(local.size()), PETSC_DETERMINE, v.out()),
                        "VecCreateMPI");
  PetscScalar* p = nullptr;
  internal::check_petsc(VecGetArray(v.get(), &p), "VecGetArray");
  std::copy(local.data(), local.data() + local.size(), p);
  internal::check_petsc(VecRestoreArray(v.get(), &p), "VecRestoreArray");
  return v;
}

/// This rank's part of a PETSc vector.
inline vec<double> from_petsc(const petsc_vec& v) {
  PetscInt n = 0;
  internal::check_petsc(VecGetLocalSize(v.get(), &n), "VecGetLocalSize");
  const PetscScalar* p = nullptr;
  internal::check_petsc(VecGetArrayRead(v.get(), &p), "VecGetArrayRead");
  vec<double> out = Eigen::Map<const vec<double>>(p, n);
  internal::check_petsc(VecRestoreArrayRead(v.get(), &p), "VecRestoreArrayRead");
  return out;
}

enum class petsc_subdomain_solver {
  petsc_ilu,      ///< PETSc's ILU(k) of each rank's BAIJ diagonal part
  aerohopf_bilu,  ///< our BILU(k) of the same part, as a PCSHELL
};

struct petsc_solve_options {
  double relative_tolerance = 1e-8;  ///< on the unpreconditioned residual, relative to ||b||
  int max_iterations = 500;
  int restart = 60;
  int fill_level = 0;
  petsc_subdomain_solver subdomain = petsc_subdomain_solver::petsc_ilu;
};

struct petsc_solve_report {
  bool converged = false;
  int iterations = 0;
  double relative_residual = 0;  ///< ||b - A x|| / ||b||, recomputed
  std::string reason;             ///< PETSc's KSPConvergedReason
  double setup_seconds = 0;  ///< BAIJ assembly and the factorisation of the subdomain matrices
  double solve_seconds = 0;  ///< KSPSolve
};

namespace internal {
template <int B>
struct shell_bilu {
  block_ilu<double, B> ilu;
  vec<double> in, out;
};

/// z = (LU)^{-1} r on this rank's part; no exception crosses PETSc's C frames (an error code
/// instead, which KSPSolve reports).
template <int B>
PetscErrorCode apply_shell_bilu(PC pc, Vec r, Vec z) {
  void* ctx = nullptr;
  if (PetscErrorCode e = PCShellGetContext(pc, &ctx)) return e;
  auto* s = static_cast<shell_bilu<B>*>(ctx);
  PetscInt n = 0;
  const PetscScalar* pr = nullptr;
  PetscScalar* pz = nullptr;
  if (PetscErrorCode e = VecGetLocalSize(r, &n)) return e;
  if (PetscErrorCode e = VecGetArrayRead(r, &pr)) return e;
  s->in = Eigen::Map<const vec<double>>(pr, n);
  if (PetscErrorCode e = VecRestoreArrayRead(r, &pr)) return e;
  s->out.resize(n);
  try {
    s->ilu.apply(s->in, s->out);
  } catch (...) {
    return PETSC_ERR_LIB;
  }
  if (PetscErrorCode e = VecGetArray(z, &pz)) return e;
  std::copy(s->out.data(), s->out.data() + n, pz);
  return VecRestoreArray(z, &pz);
}
}  // namespace internal

/// Solves A x = b by KSP GMRES with block-Jacobi preconditioning (file comment): `a` this
/// rank's rows (d.jacobian's numbering), b and x this rank's parts (x: the solution, started
/// from zero). Collective.
template <int Dim>
petsc_solve_report petsc_solve(distributed_euler<Dim>& d, const block_sparse_matrix<double, Dim + 2>& a,
                               const vec<double>& b, vec<double>& x, const petsc_solve_options& o = {}) {
  constexpr int nv = Dim + 2;
  const MPI_Comm comm = d.communicator();
  distributed::internal::collective(comm, "petsc_solve", [&] {
    require_size(b.size(), d.local_size(), "petsc_solve", "right-hand side (this rank's part)");
    require(o.relative_tolerance > 0 && o.relative_tolerance < 1 && o.max_iterations >= 1 && o.restart >= 1 &&
                o.fill_level >= 0 && o.fill_level <= 8,
            "petsc_solve: need relative_tolerance in (0, 1), max_iterations >= 1, restart >= 1, fill_level in [0, 8]");
  });
  petsc_solve_report rep;
  const double t0 = MPI_Wtime();
  const petsc_mat m = to_petsc(d, a, petsc_block_numbering(d));
  const petsc_vec pb = to_petsc(b, comm);
  petsc_vec px;
  internal::check_petsc(VecDuplicate(pb.get(), px.out()), "VecDuplicate");
  internal::check_petsc(VecSet(px.get(), 0.0), "VecSet");
  petsc_ksp ksp;
  internal::check_petsc(KSPCreate(comm, ksp.out()), "KSPCreate");
  internal::check_petsc(KSPSetOperators(ksp.get(), m.get(), m.get()), "KSPSetOperators");
  internal::check_petsc(KSPSetType(ksp.get(), KSPGMRES), "KSPSetType");
  internal::check_petsc(KSPGMRESSetRestart(ksp.get(), o.restart), "KSPGMRESSetRestart");
  internal::check_petsc(KSPSetPCSide(ksp.get(), PC_RIGHT), "KSPSetPCSide");
  internal::check_petsc(KSPSetNormType(ksp.get(), KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  internal::check_petsc(KSPSetTolerances(ksp.get(), o.relative_tolerance, 0.0, PETSC_DEFAULT, o.max_iterations),
                        "KSPSetTolerances");
  PC pc = nullptr;
  internal::check_petsc(KSPGetPC(ksp.get(), &pc), "KSPGetPC");
  internal::shell_bilu<nv> shell;
  if (o.subdomain == petsc_subdomain_solver::petsc_ilu) {
    internal::check_petsc(PCSetType(pc, PCBJACOBI), "PCSetType");
    internal::check_petsc(KSPSetUp(ksp.get()), "KSPSetUp");
    PetscInt nlocal = 0;
    KSP* sub = nullptr;
    internal::check_petsc(PCBJacobiGetSubKSP(pc, &nlocal, nullptr, &sub), "PCBJacobiGetSubKSP");
    for (PetscInt k = 0; k < nlocal; ++k) {
      PC spc = nullptr;
      internal::check_petsc(KSPSetType(sub[k], KSPPREONLY), "KSPSetType");
      internal::check_petsc(KSPGetPC(sub[k], &spc), "KSPGetPC");
      internal::check_petsc(PCSetType(spc, PCILU), "PCSetType");
      internal::check_petsc(PCFactorSetLevels(spc, o.fill_level), "PCFactorSetLevels");
    }
  } else {
    block_ilu_options io;
    io.fill_level = o.fill_level;
    io.context = "petsc_solve: BILU of this rank's part (PCSHELL)";
    shell.ilu = block_ilu<double, nv>(io);
    distributed::internal::collective(comm, "petsc_solve: BILU", [&] { shell.ilu.compute(owned_part(a)); });
    internal::check_petsc(PCSetType(pc, PCSHELL), "PCSetType");
    internal::check_petsc(PCShellSetContext(pc, &shell), "PCShellSetContext");
    internal::check_petsc(PCShellSetApply(pc, internal::apply_shell_bilu<nv>), "PCShellSetApply");
  }
  internal::check_petsc(KSPSetUp(ksp.get()), "KSPSetUp");
  internal::check_petsc(KSPSetUpOnBlocks(ksp.get()), "KSPSetUpOnBlocks");  // the per-rank ILU, else lazily in the solve
  const double t1 = MPI_Wtime();
  internal::check_petsc(KSPSolve(ksp.get(), pb.get(), px.get()), "KSPSolve");
  const double t2 = MPI_Wtime();
  PetscInt its = 0;
  KSPConvergedReason why;
  internal::check_petsc(KSPGetIterationNumber(ksp.get(), &its), "KSPGetIterationNumber");
  internal::check_petsc(KSPGetConvergedReason(ksp.get(), &why), "KSPGetConvergedReason");
  rep.iterations = static_cast<int>(its);
  rep.converged = why > 0;
  rep.reason = KSPConvergedReasons[why];
  rep.setup_seconds = t1 - t0;
  rep.solve_seconds = t2 - t1;
  x = from_petsc(px);
  // the true residual, by our own distributed product
  const vec<double> r = b - d.multiply(a, x);
  double s[2] = {r.squaredNorm(), b.squaredNorm()};
  distributed::internal::sum_over_ranks(comm, s, 2);
  rep.relative_residual = s[1] > 0 ? std::sqrt(s[0] / s[1]) : std::sqrt(s[0]);
  return rep;
}

}  // namespace aerohopf::distributed
