// Strong scaling of the distributed Euler kernels on the AGARD 445.6 wing grid (distributed/):
// run as  mpirun -np N mpi_scaling [stride [cfl]]  (stride 4: coarse, 2: medium; default 2; CFL
// of the pseudo-time matrix, default 100).
// The one-block C-H grid is cut for N ranks (split_for_ranks); each rank owns its blocks. Printed
// (rank 0; times are the slowest rank's, best of the repeats): cells per rank, received (ghost)
// cells, halo bytes per exchange, the residual, the modified-order Jacobian rows, a product A x,
// and one GMRES(60) solve of the pseudo-time matrix D - J (local time steps at that CFL) with
// block-Jacobi BILU(0) to 1e-2 (the steady solver's linear solve), with its iterations.
#include <mpi.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>

using namespace aerohopf;

namespace {

double seconds_max(MPI_Comm comm, double t) {
  double m = 0;
  MPI_Allreduce(&t, &m, 1, MPI_DOUBLE, MPI_MAX, comm);
  return m;
}

/// Best of `repeats` (each the slowest rank's wall time).
double best(MPI_Comm comm, int repeats, const std::function<void()>& f) {
  double b = 1e300;
  for (int k = 0; k < repeats; ++k) {
    MPI_Barrier(comm);
    const auto t0 = std::chrono::steady_clock::now();
    f();
    b = std::min(b, seconds_max(comm, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int stride = argc > 1 ? std::atoi(argv[1]) : 2;
  const double cfl = argc > 2 ? std::atof(argv[2]) : 100.0;
  if ((stride != 1 && stride != 2 && stride != 4 && stride != 8) || !(cfl > 0.0)) {
    if (rank == 0) std::fprintf(stderr, "mpi_scaling: stride must be 1, 2, 4 or 8 and cfl positive\n");
    MPI_Finalize();
    return 2;
  }
  {
    const auto s = distributed::split_for_ranks(flow::coarsen(flow::wing_cgrid(flow::agard445_6()), stride), size);
    const flow::euler_model<3> m(s.grid, {.mach = 0.96, .alpha_rad = 0.0});
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
    if (rank == 0) {
      std::printf("ranks,stride,cfl,cells,blocks,cells_per_rank_max,imbalance,ghost_cells_max,halo_bytes,residual_s,"
                  "jacobian_s,product_s,bilu_s,gmres_s,gmres_iterations\n");
      std::printf("%d,%d,%g,%zu,%zu,%lld,%.3f,%lld,%lld,%.4f,%.4f,%.5f,%.4f,%.4f,%d\n", size, stride, cfl, m.n_cells(),
                  s.grid.topology.cells.size(), own_max, part.imbalance(), ghost_max, bytes, t_res, t_jac, t_mv, t_ilu,
                  t_gmres, rep.iterations);
    }
  }
  MPI_Finalize();
  return 0;
}
