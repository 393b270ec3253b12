// Strong scaling of the distributed Euler kernels on the AGARD 445.6 wing grid (distributed/):
// run as  mpirun -np N mpi_scaling [stride [cfl [mach [steady]]]]  (stride 4: coarse, 2: medium;
// default 2; CFL of the pseudo-time matrix, default 100; Mach number, default 0.96; steady = 1
// also runs a whole steady solve from the free stream).
// The one-block C-H grid is cut for N ranks (split_for_ranks); each rank owns its blocks. Printed
// (rank 0; times are the slowest rank's, best of the repeats): cells per rank, received (ghost)
// cells, halo bytes per exchange, the residual, the modified-order Jacobian rows, a product A x,
// and one GMRES(60) solve of the pseudo-time matrix D - J (local time steps at that CFL) with
// block-Jacobi BILU(0) to 1e-2 (the steady solver's linear solve), with its iterations; the
// largest resident memory of a rank (VmHWM). Where PETSc was found (aerohopf::petsc), the same
// matrix is solved by PETSc's KSP GMRES(60) with block Jacobi and ILU(0) to the same tolerance
// (setup: the BAIJ assembly and the factorisation; solve: KSPSolve). With steady = 1, the
// distributed steady solve (flow::solve_steady, default options): steps, GMRES iterations,
// seconds, residual drop.
#include <mpi.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#ifdef AEROHOPF_HAVE_PETSC
#include <aerohopf/distributed/petsc.hpp>
#endif
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include "mpi_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace aerohopf;

namespace {

using bench::best;
using bench::seconds_max;

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
#ifdef AEROHOPF_HAVE_PETSC
  PetscInitializeNoArguments();
#endif
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int stride = argc > 1 ? std::atoi(argv[1]) : 2;
  const double cfl = argc > 2 ? std::atof(argv[2]) : 100.0;
  const double mach = argc > 3 ? std::atof(argv[3]) : 0.96;
  const bool steady = argc > 4 && std::atoi(argv[4]) == 1;
  if ((stride != 1 && stride != 2 && stride != 4 && stride != 8) || !(cfl > 0.0) || !(mach > 0.0 && mach < 5.0)) {
    if (rank == 0) std::fprintf(stderr, "mpi_scaling: stride must be 1, 2, 4 or 8, cfl positive, mach in (0, 5)\n");
    MPI_Finalize();
    return 2;
  }
  {
    const auto s = distributed::split_for_ranks(flow::coarsen(flow::wing_cgrid(flow::agard445_6()), stride), size);
    flow::euler_model<3> m(s.grid, {.mach = mach, .alpha_rad = 0.0});
    const auto part = distributed::partition_blocks(m, size);
    distributed::distributed_euler<3> d(m, part, MPI_COMM_WORLD);
    vec<double> w = m.free_stream_vector();
    for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + 0.01 * std::sin(0.001 * static_cast<double>(k));
    const vec<double> local = d.local_part(w);

    long long own = d.plan().owned_cells(), ghost = d.plan().ghost_cells(), sent = 0;
    for (const auto& l : d.plan().send) sent += static_cast<long long>(l.size());
    long long own_max = 0, ghost_max = 0, bytes = 0;
    MPI_Allreduce(&own, &own_max, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(&ghost, &ghost_max, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    sent *= 5 * 8;
    MPI_Allreduce(&sent, &bytes, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);

    vec<double> r;
    const double t_res = best(MPI_COMM_WORLD, 5, [&] { r = d.residual(local); });
    block_sparse_matrix<double, 5> a;
    d.jacobian(local, flow::jacobian_kind::modified_order, a);
    const double t_jac = best(MPI_COMM_WORLD, 3, [&] { d.jacobian(local, flow::jacobian_kind::modified_order, a); });
    vec<double> y;
    const double t_mv = best(MPI_COMM_WORLD, 10, [&] { y = d.multiply(a, local); });
    // pseudo-time matrix D - J, D = rad / (CFL vol), in this rank's rows
    const vec<double> rad = m.spectral_radius(w);
    std::vector<double> vol;
    for (const auto& b : m.metrics().blocks) vol.insert(vol.end(), b.volume.begin(), b.volume.end());
    for (auto& v : a.values()) v = -v;
    {
      Eigen::Index row = 0;
      for (const auto& [first, last] : d.plan().owned)
        for (std::size_t c = first; c < last; ++c, ++row)
          a.block(row, row).diagonal().array() += rad[static_cast<Eigen::Index>(c)] / (cfl * vol[c]);
    }
    block_ilu<double, 5> ilu;
    const double t_ilu = best(MPI_COMM_WORLD, 2, [&] { ilu.compute(distributed::owned_part(a)); });
    const distributed::distributed_matrix_operator<3> op(d, a, MPI_COMM_WORLD);
    krylov_options ko;
    ko.relative_tolerance = 1e-2;
    ko.restart = 60;
    ko.max_iterations = 200;
    krylov_report rep;
    const double t_gmres = best(MPI_COMM_WORLD, 2, [&] {
      vec<double> x;
      rep = gmres(op, ilu, r, x, ko);
    });
    double petsc_setup = NAN, petsc_solve = NAN;
    int petsc_its = -1;
#ifdef AEROHOPF_HAVE_PETSC
    {
      distributed::petsc_solve_options po;
      po.relative_tolerance = ko.relative_tolerance;
      po.restart = ko.restart;
      po.max_iterations = ko.max_iterations;
      for (int k = 0; k < 2; ++k) {  // best of two
        vec<double> x;
        const auto pr = distributed::petsc_solve(d, a, r, x, po);
        const double su = seconds_max(MPI_COMM_WORLD, pr.setup_seconds), so = seconds_max(MPI_COMM_WORLD, pr.solve_seconds);
        if (k == 0 || su + so < petsc_setup + petsc_solve) {
          petsc_setup = su;
          petsc_solve = so;
          petsc_its = pr.iterations;
        }
      }
    }
#endif
    int steps = -1, steady_its = -1;
    double steady_s = NAN, drop = NAN;
    if (steady) {
      distributed::distributed_euler_discretisation<3> disc(m, d);
      vec<double> ws = d.local_part(m.free_stream_vector());
      flow::steady_options so;
      so.throw_on_failure = false;
      MPI_Barrier(MPI_COMM_WORLD);
      const auto sr = flow::solve_steady(disc, ws, so);
      steps = sr.steps;
      steady_its = sr.linear_iterations;
      steady_s = seconds_max(MPI_COMM_WORLD, sr.seconds);
      drop = sr.final_residual / sr.initial_residual;
      if (rank == 0 && !sr.converged) std::fprintf(stderr, "mpi_scaling: steady solve: %s\n", sr.reason.c_str());
    }
    const double mem_max = bench::peak_resident_mb_max(MPI_COMM_WORLD);
    if (rank == 0) {
      std::printf("ranks,stride,cfl,mach,cells,blocks,cells_per_rank_max,imbalance,ghost_cells_max,halo_bytes,residual_s,"
                  "jacobian_s,product_s,bilu_s,gmres_s,gmres_iterations,petsc_setup_s,petsc_solve_s,petsc_iterations,"
                  "steady_steps,steady_gmres_iterations,steady_s,steady_drop,peak_rss_mb_max\n");
      std::printf("%d,%d,%g,%g,%zu,%zu,%lld,%.3f,%lld,%lld,%.4f,%.4f,%.5f,%.4f,%.4f,%d,%.4f,%.4f,%d,%d,%d,%.2f,%.2e,%.0f\n",
                  size, stride, cfl, mach, m.n_cells(), s.grid.topology.cells.size(), own_max, part.imbalance(),
                  ghost_max, bytes, t_res, t_jac, t_mv, t_ilu, t_gmres, rep.iterations, petsc_setup, petsc_solve,
                  petsc_its, steps, steady_its, steady_s, drop, mem_max);
    }
  }
#ifdef AEROHOPF_HAVE_PETSC
  PetscFinalize();
#endif
  MPI_Finalize();
  return 0;
}
