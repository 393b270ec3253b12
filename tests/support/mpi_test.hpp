#pragma once
// The MPI tests' shared pieces (tests/distributed/test_mpi_*.cpp, run under mpirun on 2 and 3
// ranks): the number of ranks, and the main that runs GoogleTest on every rank and fails the
// process on every rank if a test failed on any.
#include <gtest/gtest.h>
#include <mpi.h>

namespace aerohopf::test {

inline int world_size() {
  int n = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

/// Whether x is the same on every rank (bitwise).
inline bool same_on_every_rank(double x) {
  double lo = 0, hi = 0;
  MPI_Allreduce(&x, &lo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&x, &hi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return lo == hi;
}

/// MPI_Init, then init() (e.g. PetscInitialize), the tests, fini(), MPI_Finalize; returns
/// nonzero on every rank if any rank had a failure.
template <class Init, class Fini>
int run_tests_on_ranks(int argc, char** argv, Init init, Fini fini) {
  MPI_Init(&argc, &argv);
  init(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  const int failed = RUN_ALL_TESTS();
  int any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  fini();
  MPI_Finalize();
  return any;
}

inline int run_tests_on_ranks(int argc, char** argv) {
  return run_tests_on_ranks(argc, argv, [](int, char**) {}, [] {});
}

}  // namespace aerohopf::test

// The main of an MPI test file: its own, or none in a bundle of several files
// (AEROHOPF_TEST_BUNDLE; support/mpi_bundle_main.cpp defines the bundle's).
#ifdef AEROHOPF_TEST_BUNDLE
#define AEROHOPF_MPI_TEST_MAIN() static_assert(true)
#else
#define AEROHOPF_MPI_TEST_MAIN() \
  int main(int argc, char** argv) { return aerohopf::test::run_tests_on_ranks(argc, argv); } \
  static_assert(true)
#endif
