// The main of the MPI tests' bundle (AEROHOPF_TEST_BUNDLES): every test_mpi_*.cpp ends with
// AEROHOPF_MPI_TEST_MAIN(), which in a bundle expands to nothing, and this file defines main once.
#include "support/mpi_test.hpp"

int main(int argc, char** argv) { return aerohopf::test::run_tests_on_ranks(argc, argv); }
