// Downstream use of the installed MPI component: the NACA 0012 C-grid's residual by
// distributed_euler on the processes of MPI_COMM_WORLD (one, unless run under mpirun) against
// the serial residual.
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>

#include <cmath>
#include <iostream>

int main(int argc, char** argv) {
  using namespace aerohopf;
  MPI_Init(&argc, &argv);
  int size = 0, rank = 0, bad = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  {
    const flow::euler_model<2> m(flow::coarsen(flow::naca_cgrid(), 8), {.mach = 0.8, .alpha_rad = 0.02});
    vec<double> w = m.free_stream_vector();
    for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + 0.01 * std::sin(0.37 * static_cast<double>(k));
    distributed::distributed_euler<2> d(m, distributed::partition_blocks(m, size), MPI_COMM_WORLD);
    const vec<double> r = d.all_gather(d.residual(d.local_part(w)));
    bad = r == m.residual(w) ? 0 : 1;
    if (rank == 0)
      std::cout << "consumer_mpi: distributed residual on " << size << " process(es) "
                << (bad ? "DIFFERS from" : "equals") << " the serial one, ||R|| = " << r.norm() << "\n";
  }
  MPI_Finalize();
  return bad;
}
