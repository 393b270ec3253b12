#pragma once
// SLEPc as the reference eigensolver of the distributed flow Jacobian (optional component
// aerohopf::petsc, which brings SLEPc by pkg-config, Debian's libslepc-real3.18-dev; the caller
// runs SlepcInitialize after MPI_Init and SlepcFinalize before MPI_Finalize).
//
// slepc_nearest: the eigenvalues of A nearest a target by Krylov-Schur on the shift-and-invert
// transformation (A - sigma I)^{-1}, the shifted systems solved by MUMPS (parallel sparse LU):
// an independent method and an independent linear solver for the eigenvalues that our
// inverse power (distributed/mpi_eigen.hpp) finds. The real PETSc build takes a real target;
// complex eigenvalues come as conjugate pairs all the same, so a pair is found from a real
// target near it (nev large enough to reach it).

#include <mpi.h>
#include <slepceps.h>

#include <aerohopf/distributed/petsc.hpp>

#include <algorithm>
#include <complex>
#include <vector>

namespace aerohopf::distributed {

struct slepc_eigen_options {
  int count = 1;            ///< nev: eigenvalues wanted (the nearest to the target)
  double tolerance = 1e-12;  ///< SLEPc's relative convergence tolerance
  int max_iterations = 1000;
};

struct slepc_eigen_result {
  std::vector<std::complex<double>> values;  ///< nearest the target first
  std::vector<double> errors;                ///< SLEPc's relative error estimate of each (EPSComputeError)
  int iterations = 0;                        ///< Krylov-Schur restarts
};

/// The `count` eigenvalues of A nearest `target` (file comment): `a` this rank's rows in d's
/// numbering (distributed_euler::jacobian). Collective. std::runtime_error if SLEPc fails or
/// fewer than `count` eigenvalues converge.
template <int Dim>
slepc_eigen_result slepc_nearest(distributed_euler<Dim>& d, const block_sparse_matrix<double, Dim + 2>& a,
                                 double target, const slepc_eigen_options& o = {}) {
  distributed::internal::collective(d.communicator(), "slepc_nearest", [&] {
    require(std::isfinite(target), "slepc_nearest: target ", target, " is not finite");
    require(o.count >= 1 && o.tolerance > 0 && o.max_iterations >= 1,
            "slepc_nearest: need count >= 1, tolerance > 0, max_iterations >= 1");
  });
  const petsc_mat m = to_petsc(d, a, petsc_block_numbering(d));
  internal::petsc_handle<EPS, EPSDestroy> eps;
  using internal::check_petsc;
  check_petsc(EPSCreate(d.communicator(), eps.out()), "EPSCreate");
  check_petsc(EPSSetOperators(eps.get(), m.get(), nullptr), "EPSSetOperators");
  check_petsc(EPSSetProblemType(eps.get(), EPS_NHEP), "EPSSetProblemType");
  check_petsc(EPSSetType(eps.get(), EPSKRYLOVSCHUR), "EPSSetType");
  check_petsc(EPSSetDimensions(eps.get(), o.count, PETSC_DEFAULT, PETSC_DEFAULT), "EPSSetDimensions");
  check_petsc(EPSSetTolerances(eps.get(), o.tolerance, o.max_iterations), "EPSSetTolerances");
  check_petsc(EPSSetTarget(eps.get(), target), "EPSSetTarget");
  check_petsc(EPSSetWhichEigenpairs(eps.get(), EPS_TARGET_MAGNITUDE), "EPSSetWhichEigenpairs");
  ST st = nullptr;
  KSP ksp = nullptr;
  PC pc = nullptr;
  check_petsc(EPSGetST(eps.get(), &st), "EPSGetST");
  check_petsc(STSetType(st, STSINVERT), "STSetType");
  check_petsc(STGetKSP(st, &ksp), "STGetKSP");
  check_petsc(KSPSetType(ksp, KSPPREONLY), "KSPSetType");
  check_petsc(KSPGetPC(ksp, &pc), "KSPGetPC");
  check_petsc(PCSetType(pc, PCLU), "PCSetType");
  check_petsc(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
  check_petsc(EPSSolve(eps.get()), "EPSSolve");
  PetscInt nconv = 0, its = 0;
  check_petsc(EPSGetConverged(eps.get(), &nconv), "EPSGetConverged");
  check_petsc(EPSGetIterationNumber(eps.get(), &its), "EPSGetIterationNumber");
  if (nconv < o.count)
    throw std::runtime_error(aerohopf::internal::concat("slepc_nearest: ", nconv, " of ", o.count,
                                                        " eigenvalues converged near ", target));
  slepc_eigen_result r;
  r.iterations = static_cast<int>(its);
  for (PetscInt k = 0; k < nconv; ++k) {
    PetscScalar kr = 0, ki = 0;
    PetscReal err = 0;
    check_petsc(EPSGetEigenvalue(eps.get(), k, &kr, &ki), "EPSGetEigenvalue");
    check_petsc(EPSComputeError(eps.get(), k, EPS_ERROR_RELATIVE, &err), "EPSComputeError");
    r.values.emplace_back(kr, ki);
    r.errors.push_back(err);
  }
  return r;
}

}  // namespace aerohopf::distributed
