// The flutter boundaries of the pitch-plunge NACA 0012 (as aerofoil_flutter's) with the heavy
// solves on MPI ranks: the library driver trace_flutter_boundary over
// distributed::aerofoil_family (distributed/mpi_aerofoil_family.hpp), whose steady flows,
// inverse-power starts and Hopf points are solved on the ranks (at --incidence the static
// aeroelastic equilibria and full Hopf systems too); the driver's decisions are the same on every
// rank, rank 0 prints and writes. Any number of ranks (on more than the C-grid's three blocks
// they are cut first). Built where the distributed component exists (MPI found).
//
// Usage: mpirun -np N aerofoil_flutter_mpi [out_dir] [options]
//   --case light|heavy|both  --grids coarse,medium  --mach-min M --mach-max M --mach-step d
//   --incidence DEG  --skip-jump-check  --verbose
//                    as aerofoil_flutter's (default: both cases, coarse and medium, zero incidence)
// Outputs under out_dir (default out/aerofoil_flutter_mpi): boundary_<case>_<grid>.csv (at an
// incidence boundary_<case>_<grid>_alpha<DEG>.csv), the serial example's format. Exit status 1
// if a boundary is incomplete or a crossing check fails.
#include <mpi.h>

#include <aerohopf/distributed/mpi_aerofoil_family.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <string>

#include "../common/cli.hpp"
#include "parts.hpp"
#include "setup.hpp"

using namespace aerohopf;
using namespace aerofoil_example;

namespace aerofoil_example {

// the serial example's declaration (parts.hpp); here the boundary on the ranks
flutter_boundary boundary_on(const options& o, const structural_case& c, const grid_level& g,
                             const flutter_boundary* coarser) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const distributed::aerofoil_family family(family_of(c, o.incidence_deg * std::numbers::pi / 180), MPI_COMM_WORLD);
  flutter_boundary_options fo = driver_options(o, c, g, family.serial());
  fo.label += " on " + std::to_string(family.ranks()) + " ranks";
  fo.log = rank == 0 ? &std::cout : nullptr;
  flutter_boundary b = trace_flutter_boundary(family, g.stride, mach_list(o), coarser, fo);
  distributed::on_root(MPI_COMM_WORLD, "aerofoil_flutter_mpi output", [&] { write_boundary(o, c, g, b); });
  return b;
}

}  // namespace aerofoil_example

namespace {

options parse(int argc, char** argv) {
  options o;
  o.out = "out/aerofoil_flutter_mpi";
  example_cli::arguments args(argc, argv);
  for (std::string a; args.next(a);) {
    if (read_boundary_option(a, args, o)) {
      continue;
    } else if (a == "--skip-jump-check") {
      o.crossing_check = false;
    } else {
      throw input_error("unknown option " + a);
    }
  }
  check_mach_range(o);
  return o;
}

int run(int argc, char** argv, int rank) {
  const options o = parse(argc, argv);
  distributed::on_root(MPI_COMM_WORLD, "aerofoil_flutter_mpi output", [&] { std::filesystem::create_directories(o.out); });
  const auto t0 = clk::now();
  int failed = 0;
  for (const auto& c : o.cases) {
    flutter_boundary previous;
    const flutter_boundary* coarser = nullptr;
    for (const auto& g : o.grids) {
      flutter_boundary b = boundary_on(o, c, g, coarser);
      double hopf = 0, steady = 0;
      for (const auto& p : b.points) {
        hopf += p.hopf_seconds;
        steady += p.steady_seconds;
      }
      if (rank == 0) {
        std::printf("  %s: %zu points, Hopf %.1f s + steady %.1f s; Hopf / steady = %.2f%s%s\n", b.label.c_str(),
                    b.points.size(), hopf, steady, hopf / steady, b.complete ? "" : "; incomplete: ",
                    b.complete ? "" : b.stop_reason.c_str());
        for (const auto& x : b.checks)
          if (!x.pass) std::printf("  crossing check FAILED at M = %.4f\n", x.mach);
      }
      failed += (b.complete ? 0 : 1) + (b.checks_passed() ? 0 : 1);
      previous = std::move(b);
      coarser = &previous;
    }
  }
  if (rank == 0) std::cout << "total " << seconds_since(t0) << " s; results in " << o.out << "\n";
  return failed > 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, rc = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) std::cout.setstate(std::ios::badbit);  // rank 0 reports
  try {
    rc = run(argc, argv, rank);
  } catch (const std::exception& e) {
    std::cerr << "aerofoil_flutter_mpi (rank " << rank << "): " << e.what() << "\n";
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
