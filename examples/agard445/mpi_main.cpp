// The AGARD 445.6 flutter boundaries (as agard445's part 4) with the heavy solves on MPI ranks:
// the library driver trace_flutter_boundary over distributed::wing_family
// (distributed/mpi_wing_family.hpp), whose steady flows, inverse-power starts and Hopf points
// are solved on the ranks, each level's one-block C-H grid cut into as many blocks as ranks; the
// driver's decisions are the same on every rank, rank 0 prints and writes. The structure is the
// serial program's: the plate model's first four modes on the same mesh. Built where the
// distributed component exists (MPI found).
//
// Usage: mpirun -np N agard445_mpi [out_dir] [options]
//   --flutter LEVELS  --damping PERCENTS  --fine-damping PERCENTS  --machs LIST  --mesh NI,NJ  --verbose
//                     as agard445's (default: coarse and medium, 0, 0.5 and 2 % on coarse, 0.5 % on
//                     medium, the experiment's four Mach numbers; plate mesh 24 x 24)
// Outputs under out_dir (default out/agard445_mpi): boundary_<level>_zeta<percent>.csv in the
// serial program's format, flutter_mode_*_M0.96_phase<k>.vtk and costs.csv.
// Exit status 1 if a boundary is incomplete.
#include <mpi.h>

#include <aerohopf/distributed/mpi_wing_family.hpp>
#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/structure/modal_data.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "../common/cli.hpp"
#include "flutter.hpp"

using namespace aerohopf;

namespace {

struct options {
  std::filesystem::path out = "out/agard445_mpi";
  int ni = 24, nj = 24;
  agard445_flutter::flutter_options flutter;
};

options parse(int argc, char** argv) {
  options o;
  example_cli::arguments args(argc, argv);
  for (std::string a; args.next(a);) {
    if (agard445_flutter::read_mesh_option(a, args, o.ni, o.nj) ||
        agard445_flutter::read_boundary_option(a, args, o.flutter)) {
      continue;
    } else if (!a.empty() && a[0] != '-') {
      o.out = a;
    } else {
      throw input_error("unknown option " + a);
    }
  }
  require(!o.flutter.strides.empty(), "--flutter: at least one level");
  return o;
}

int run(int argc, char** argv, int rank, int ranks) {
  const options o = parse(argc, argv);
  const auto output = [](auto&& fn) { distributed::on_root(MPI_COMM_WORLD, "agard445_mpi output", fn); };
  output([&] { std::filesystem::create_directories(o.out); });
  const auto t0 = std::chrono::steady_clock::now();
  const flow::wing_geometry w = flow::agard445_6();
  // the serial program's structure: five plate modes on the mesh, their modal data, the first four
  const agard445_flutter::solved plate = agard445_flutter::modes_on(w, o.ni, o.nj, 5);
  const structure::modal_data four =
      agard445_flutter::first_four(structure::modal_data_from_plate(plate.mesh, plate.modes));
  output([&] {
    std::printf("AGARD 445.6 flutter boundaries on %d MPI ranks: plate %dx%d, first four modes", ranks, o.ni, o.nj);
    for (int k = 0; k < 4; ++k) std::printf(" %.2f", plate.modes.frequency_hz(k));
    std::printf(" Hz\n");
  });
  const auto runs = agard445_flutter::boundaries(
      o.flutter, o.out, w, flow::wing_grid_options{}, four,
      [](const models::wing_family& f) { return distributed::wing_family(f, MPI_COMM_WORLD); }, output,
      rank == 0 ? &std::cout : nullptr);
  int incomplete = 0;
  for (const auto& r : runs) incomplete += r.b.complete ? 0 : 1;
  output([&] {
    agard445_flutter::write_costs(o.out / "costs.csv", runs, o.flutter.machs);
    std::printf("\ntotal %.1f s on %d ranks; results in %s\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), ranks,
                o.out.string().c_str());
  });
  return incomplete > 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1, rc = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (rank != 0) std::cout.setstate(std::ios::badbit);  // rank 0 reports
  try {
    rc = run(argc, argv, rank, ranks);
  } catch (const std::exception& e) {
    std::cerr << "agard445_mpi (rank " << rank << "): " << e.what() << "\n";
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
