// Downstream use of the installed PETSc component: the NACA 0012 C-grid's modified-order
// Jacobian, shifted, as a PETSc BAIJ matrix (distributed::to_petsc) on the processes of
// MPI_COMM_WORLD, solved by KSP with block Jacobi; the true residual must meet the tolerance.
#include <aerohopf/distributed/petsc.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>

#include <iostream>

int main(int argc, char** argv) {
  using namespace aerohopf;
  MPI_Init(&argc, &argv);
  PetscInitialize(&argc, &argv, nullptr, nullptr);
  int size = 0, rank = 0, bad = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  {
    const flow::euler_model<2> m(flow::coarsen(flow::naca_cgrid(), 8), {.mach = 0.8, .alpha_rad = 0.02});
    distributed::distributed_euler<2> d(m, distributed::partition_blocks(m, size), MPI_COMM_WORLD);
    const vec<double> w = d.local_part(m.free_stream_vector());
    block_sparse_matrix<double, 4> a;
    d.jacobian(w, flow::jacobian_kind::modified_order, a);
    for (auto& v : a.values()) v = -v;
    for (Eigen::Index i = 0; i < a.block_rows(); ++i) a.block(i, i).diagonal().array() += 20.0;
    vec<double> x;
    const auto rep = distributed::petsc_solve(d, a, w, x);
    bad = rep.converged && rep.relative_residual < 1e-7 ? 0 : 1;
    if (rank == 0)
      std::cout << "consumer_petsc: KSP on " << size << " process(es): " << rep.iterations << " iterations, "
                << rep.reason << ", true relative residual " << rep.relative_residual << "\n";
  }
  PetscFinalize();
  MPI_Finalize();
  return bad;
}
