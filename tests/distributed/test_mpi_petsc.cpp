// PETSc as the distributed linear algebra (distributed/petsc.hpp), run by CTest under mpirun on 2
// and 3 ranks where PETSc is found. References: our distributed product (the PETSc matrix's
// MatMult equals it to rounding: numbering and preallocation), Eigen's sparse LU of the whole
// system (the KSP solutions), and our own distributed GMRES with block-Jacobi BILU(0) (the
// iteration counts: the same preconditioner by PETSc's ILU(0) of the BAIJ diagonal parts and by
// our BILU(0) through PCSHELL). Cases: the shifted modified-order Jacobian of the NACA 0012
// C-grid (block size 4) and of the tiny AGARD grid cut for the ranks (block size 5).
#include <gtest/gtest.h>
#include <mpi.h>
#include <petscsys.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/distributed/petsc.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <Eigen/SparseLU>
#include <cstdlib>
#include <iostream>

#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/partition_grids.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;

namespace {

/// shift I - J (modified order) at a perturbed free stream: whole (serial) and this rank's rows.
template <int Dim>
void shifted_system(const flow::euler_model<Dim>& m, distributed_euler<Dim>& d, double shift,
                    block_sparse_matrix<double, Dim + 2>& whole, block_sparse_matrix<double, Dim + 2>& part) {
  const vec<double> w = test::perturbed_free_stream(m, 6u);
  flow::assemble_jacobian<Dim>(m, w, flow::jacobian_kind::modified_order, whole);
  d.jacobian(d.local_part(w), flow::jacobian_kind::modified_order, part);
  for (auto* a : {&whole, &part}) {
    for (auto& v : a->values()) v = -v;
    for (Eigen::Index i = 0; i < a->block_rows(); ++i) a->block(i, i).diagonal().array() += shift;
  }
}

template <int Dim>
void check_solvers(const flow::euler_model<Dim>& m, double shift) {
  distributed_euler<Dim> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  block_sparse_matrix<double, Dim + 2> whole, part;
  shifted_system(m, d, shift, whole, part);
  const vec<double> b = test::perturbed_free_stream(m, 8u);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(whole.to_sparse());
  const vec<double> x_ref = lu.solve(b);
  const vec<double> b_local = d.local_part(b);

  // the PETSc matrix is our matrix: MatMult = our distributed product
  {
    const petsc_mat pm = to_petsc(d, part, petsc_block_numbering(d));
    const petsc_vec px = to_petsc(b_local, MPI_COMM_WORLD);
    petsc_vec py;
    ASSERT_EQ(VecDuplicate(px.get(), py.out()), 0);
    ASSERT_EQ(MatMult(pm.get(), px.get(), py.get()), 0);
    const vec<double> ours = d.multiply(part, b_local);
    EXPECT_LT((from_petsc(py) - ours).cwiseAbs().maxCoeff(), 1e-14 * ours.cwiseAbs().maxCoeff());
  }

  // our GMRES with block-Jacobi BILU(0)
  block_ilu<double, Dim + 2> ilu;
  ilu.compute(owned_part(part));
  const distributed_matrix_operator<Dim> op(d, part, MPI_COMM_WORLD);
  krylov_options ko;
  ko.relative_tolerance = 1e-10;
  ko.max_iterations = 500;
  ko.restart = 60;
  vec<double> x_ours;
  const auto ours = gmres(op, ilu, b_local, x_ours, ko);
  ASSERT_TRUE(ours.converged) << ours.reason;

  for (const auto sub : {petsc_subdomain_solver::petsc_ilu, petsc_subdomain_solver::aerohopf_bilu}) {
    petsc_solve_options po;
    po.relative_tolerance = 1e-10;
    po.subdomain = sub;
    vec<double> x;
    const auto rep = petsc_solve(d, part, b_local, x, po);
    EXPECT_TRUE(rep.converged) << rep.reason;
    EXPECT_LT(rep.relative_residual, 2e-10);
    EXPECT_LT((d.all_gather(x) - x_ref).norm(), 1e-8 * x_ref.norm());
    // the same preconditioner and the same (right-preconditioned) GMRES: the same iterations, up
    // to one (PETSc orthogonalises by classical Gram-Schmidt, we by modified)
    EXPECT_NEAR(rep.iterations, ours.iterations, 1);
    if (d.rank() == 0)
      std::cout << world_size() << " ranks, block size " << Dim + 2 << ": PETSc KSP GMRES + block Jacobi "
                << (sub == petsc_subdomain_solver::petsc_ilu ? "PETSc ILU(0)" : "our BILU(0) (PCSHELL)") << ": "
                << rep.iterations << " iterations, " << rep.reason << "; ours " << ours.iterations << "\n";
  }
}

}  // namespace

TEST(mpi_petsc, ksp_block_jacobi_solves_the_aerofoil_system_as_ours_does) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02});
  check_solvers(m, 20.0);
}

TEST(mpi_petsc, ksp_block_jacobi_solves_the_wing_system_as_ours_does) {
  const auto s = split_for_ranks(flow::wing_cgrid(test_support::agard(), test_support::tiny_wing_options()),
                                 world_size());
  const flow::euler_model<3> m(s.grid, {.mach = 0.9, .alpha_rad = 0.02});
  check_solvers(m, 20.0);
}

TEST(mpi_petsc, bad_input_is_refused_on_every_rank) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  block_sparse_matrix<double, 4> whole, part;
  shifted_system(m, d, 20.0, whole, part);
  const vec<double> b = d.local_part(m.free_stream_vector());
  vec<double> x;
  // a right-hand side of the wrong size on the last rank
  const int last = world_size() - 1;
  const vec<double> bad = d.rank() == last ? vec<double>(b.head(b.size() - 1)) : b;
  const std::string msg = test::input_error_of([&] { (void)petsc_solve(d, part, bad, x); });
  EXPECT_TRUE(test::contains(msg, d.rank() == last ? "right-hand side" : "refused on rank")) << msg;
  // the serial whole matrix is not this rank's rows
  EXPECT_THROW((void)to_petsc(d, whole, petsc_block_numbering(d)), input_error);
  petsc_solve_options po;
  po.restart = 0;
  EXPECT_THROW((void)petsc_solve(d, part, b, x, po), input_error);
}

int main(int argc, char** argv) {
  return aerohopf::test::run_tests_on_ranks(
      argc, argv, [](int& c, char**& v) { PetscInitialize(&c, &v, nullptr, nullptr); }, [] { PetscFinalize(); });
}
