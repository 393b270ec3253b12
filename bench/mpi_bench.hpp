#pragma once
// What the MPI benchmark programs (mpi_scaling, mpi_aerofoil_hopf) measure the same way: times
// as the slowest rank's wall time, and the largest resident memory of a rank.
#include <mpi.h>

#include <aerohopf/distributed/mpi_euler.hpp>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <string>

namespace aerohopf::bench {

/// The largest t over the ranks (collective).
inline double seconds_max(MPI_Comm comm, double t) { return distributed::internal::max_over_ranks(comm, t); }

/// Wall time since t0, the slowest rank's (collective).
inline double seconds_since(MPI_Comm comm, std::chrono::steady_clock::time_point t0) {
  return seconds_max(comm, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

/// Best of `repeats` (each the slowest rank's wall time, the ranks started together).
inline double best(MPI_Comm comm, int repeats, const std::function<void()>& f) {
  double b = 1e300;
  for (int k = 0; k < repeats; ++k) {
    MPI_Barrier(comm);
    const auto t0 = std::chrono::steady_clock::now();
    f();
    b = std::min(b, seconds_since(comm, t0));
  }
  return b;
}

/// The largest resident set of this process so far (VmHWM of /proc/self/status), in MB; 0 where
/// the file is not there.
inline double peak_resident_mb() {
  std::ifstream f("/proc/self/status");
  std::string key;
  double kb = 0;
  while (f >> key) {
    if (key == "VmHWM:") {
      f >> kb;
      break;
    }
    f.ignore(1 << 12, '\n');
  }
  return kb / 1024.0;
}

/// peak_resident_mb of the rank with the most (collective).
inline double peak_resident_mb_max(MPI_Comm comm) {
  return distributed::internal::max_over_ranks(comm, peak_resident_mb());
}

}  // namespace aerohopf::bench
