// The flutter point of the pitch-plunge NACA 0012 on N ranks, and what it costs against a steady
// solve on the same ranks: run as  mpirun -np N mpi_aerofoil_hopf [stride [mach]]  (stride 4:
// coarse, 2: medium, 1: fine C-grid; default 2; Mach number default 0.5; light case mu_s = 10,
// zero incidence, so the fixed-equilibrium formulation).
// The C-grid is cut for N ranks (split_for_ranks). Steps, each timed as the slowest rank's wall
// time: the steady flow from the free stream (flow::solve_steady on the ranks); the Hopf start,
// inverse power of the coupled Jacobian at Ubar = 1.66, shift 0.75i (the aerofoil
// example's light-case guess) (distributed::inverse_power,
// tolerance 1e-8); the Hopf point (distributed::solve_hopf, fixed equilibrium, Newton to 1e-10).
// Printed by rank 0: one CSV line with cells, Ubar*, omega*, iterations, seconds, the ratio
// (start + Hopf) / steady and the largest resident memory of a rank (VmHWM).
#include <mpi.h>

#include <aerohopf/distributed/mpi_aerofoil.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>

#include "mpi_bench.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace aerohopf;

namespace {

double slowest(double t) { return bench::seconds_max(MPI_COMM_WORLD, t); }
double since(std::chrono::steady_clock::time_point t0) { return bench::seconds_since(MPI_COMM_WORLD, t0); }

int run(int argc, char** argv, int rank, int size) {
  const int stride = argc > 1 ? std::atoi(argv[1]) : 2;
  const double mach = argc > 2 ? std::atof(argv[2]) : 0.5;
  if ((stride != 1 && stride != 2 && stride != 4 && stride != 8) || !(mach > 0.0 && mach < 0.9)) {
    if (rank == 0) std::fprintf(stderr, "mpi_aerofoil_hopf: stride must be 1, 2, 4 or 8, mach in (0, 0.9)\n");
    return 2;
  }
  const auto split = distributed::split_for_ranks(flow::coarsen(flow::naca_cgrid(), stride), size);
  structure::pitch_plunge_parameters pp;
  pp.mu_s = 10;
  const models::aerofoil_system sys(flow::euler_model<2>(split.grid, {.mach = mach, .alpha_rad = 0.0}),
                                    structure::pitch_plunge(pp));
  const auto part = distributed::partition_blocks(sys.flow(), size);
  distributed::distributed_aerofoil d(sys, part, MPI_COMM_WORLD);

  // the steady flow, the section at rest
  flow::euler_model<2> fm = sys.flow();
  distributed::distributed_euler<2> de(fm, part, MPI_COMM_WORLD);
  distributed::distributed_euler_discretisation<2> disc(fm, de);
  vec<double> wf = de.local_part(fm.free_stream_vector());
  MPI_Barrier(MPI_COMM_WORLD);
  auto t0 = std::chrono::steady_clock::now();
  const auto sr = flow::solve_steady(disc, wf, {});
  const double t_steady = since(t0);
  if (!sr.converged) {
    if (rank == 0) std::fprintf(stderr, "mpi_aerofoil_hopf: steady solve: %s\n", sr.reason.c_str());
    return 1;
  }
  vec<double> w = vec<double>::Zero(d.local_size());
  w.head(d.flow_size()) = wf;

  // the start: inverse power at the example's light-case guess
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = std::chrono::steady_clock::now();
  distributed::distributed_aerofoil::jacobian_rows a, p;
  const double ubar0 = 1.66;
  d.jacobians(w, ubar0, a, p);
  distributed::distributed_inverse_power_options io;
  io.power.tolerance = 1e-8;
  const eigen_pair ep = distributed::inverse_power(d, a, &p, {0.0, 0.75}, io);
  const double t_start = since(t0);
  distributed::distributed_hopf_point g{w, ubar0, std::abs(ep.lambda.imag()), ep.vector};
  if (ep.lambda.imag() < 0) g.p = g.p.conjugate().eval();

  distributed::distributed_hopf_options ho;
  ho.hopf.fixed_equilibrium = true;
  ho.hopf.verbose = true;
  ho.hopf.label = "hopf on " + std::to_string(size) + " rank(s)";
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = std::chrono::steady_clock::now();
  const auto h = distributed::solve_hopf(d, g, ho);
  const double t_hopf = since(t0);

  // collectives: every rank takes part, rank 0 prints
  const double mem_max = bench::peak_resident_mb_max(MPI_COMM_WORLD);
  const double t_setup = slowest(h.setup_seconds), t_linear = slowest(h.linear_seconds);
  if (rank == 0) {
    std::printf("ranks,stride,mach,cells,blocks,ubar_star,omega_star,steady_steps,steady_gmres,steady_s,start_iterations,"
                "start_gmres,start_s,hopf_newton,hopf_gmres,hopf_s,hopf_setup_s,hopf_linear_s,hopf_over_steady,start_plus_hopf_over_steady,"
                "peak_rss_mb_max\n");
    std::printf("%d,%d,%g,%zu,%zu,%.12f,%.12f,%d,%d,%.3f,%d,%ld,%.3f,%d,%ld,%.3f,%.3f,%.3f,%.2f,%.2f,%.0f\n", size, stride,
                mach, sys.flow().n_cells(), split.grid.topology.cells.size(), h.point.mu, h.point.omega, sr.steps,
                sr.linear_iterations, t_steady, ep.iterations, ep.linear_iterations, t_start, h.report.iterations,
                h.linear_iterations, t_hopf, t_setup, t_linear,
                t_hopf / t_steady, (t_start + t_hopf) / t_steady, mem_max);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1, rc = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  try {
    rc = run(argc, argv, rank, size);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpi_aerofoil_hopf (rank %d): %s\n", rank, e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
