// The Euler residual on MPI ranks (distributed/mpi_euler.hpp), run by CTest under mpirun on 2
// and 3 ranks (tests/CMakeLists.txt): every rank's residual rows equal the serial residual's
// bitwise, and its Jacobian rows times a distributed vector the serial product, on the NACA
// 0012 C-grid (2D), a row of three boxes and the AGARD C-H grid cut for the ranks (3D); local
// parts and the gathered state round-trip; GMRES with block-Jacobi BILU on the ranks solves a
// shifted Jacobian as the sparse LU of the whole does; a bad local size or a non-physical cell
// on one rank makes every rank throw (collective errors), and the ranks go on working
// afterwards.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <Eigen/SparseLU>
#include <complex>
#include <iostream>

#include <string>
#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/partition_grids.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;
using aerohopf::test::contains;

namespace {

template <int Dim>
void check_residual(const flow::euler_model<Dim>& m) {
  distributed_euler<Dim> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  const vec<double> w = test::perturbed_free_stream(m, 3u);  // the same on every rank (same seed)
  const vec<double> local = d.local_part(w);
  EXPECT_EQ(local.size(), d.local_size());
  EXPECT_EQ(d.all_gather(local), w);
  const vec<double> r = d.residual(local);
  const vec<double> serial = m.residual(w);
  EXPECT_EQ(r, d.local_part(serial)) << "rank " << d.rank();
  EXPECT_EQ(d.all_gather(r), serial);
  // a second evaluation at another state reuses the buffers
  const vec<double> w2 = test::perturbed_free_stream(m, 4u);
  EXPECT_EQ(d.residual(d.local_part(w2)), d.local_part(m.residual(w2)));
  // Jacobian rows and products: A x on the ranks = the serial A x, to rounding (the row sums
  // are in another column order), for both Jacobians
  for (const auto kind : {flow::jacobian_kind::exact, flow::jacobian_kind::modified_order}) {
    constexpr int nv = Dim + 2;
    block_sparse_matrix<double, nv> whole, part;
    flow::assemble_jacobian<Dim>(m, w, kind, whole);
    d.jacobian(local, kind, part);
    EXPECT_EQ(part.block_rows(), d.numbering().rows);
    EXPECT_EQ(part.block_cols(), d.numbering().cols);
    const vec<double> x = test::perturbed_free_stream(m, 9u) - m.free_stream_vector();
    vec<double> ax(m.size());
    whole.multiply(x, ax);
    const vec<double> y = d.multiply(part, d.local_part(x));
    EXPECT_LT((y - d.local_part(ax)).cwiseAbs().maxCoeff(), 1e-13 * ax.cwiseAbs().maxCoeff()) << "rank " << d.rank();
    EXPECT_LT((d.all_gather(y) - ax).cwiseAbs().maxCoeff(), 1e-13 * ax.cwiseAbs().maxCoeff());
  }
}

}  // namespace

TEST(mpi_euler, residual_and_jacobian_rows_equal_the_serial_ones_2d) {
  check_residual(flow::euler_model<2>(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02}));
}

TEST(mpi_euler, residual_and_jacobian_rows_equal_the_serial_ones_3d) {
  check_residual(flow::euler_model<3>(test::box_row_3d(), {.mach = 0.8, .alpha_rad = 0.05, .beta_rad = 0.02}));
}

// A shifted modified-order Jacobian (s I - J, the steady solver's kind of matrix) solved on the
// ranks by GMRES with block-Jacobi BILU(0) (couplings across ranks dropped) against Eigen's
// sparse LU of the whole matrix; every rank runs the same iterations.
TEST(mpi_euler, gmres_with_block_jacobi_bilu_solves_the_distributed_system) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  const vec<double> w = test::perturbed_free_stream(m, 6u);
  const double shift = 20.0;
  block_sparse_matrix<double, 4> whole, part;
  flow::assemble_jacobian<2>(m, w, flow::jacobian_kind::modified_order, whole);
  for (auto& v : whole.values()) v = -v;
  for (Eigen::Index i = 0; i < whole.block_rows(); ++i) whole.block(i, i).diagonal().array() += shift;
  d.jacobian(d.local_part(w), flow::jacobian_kind::modified_order, part);
  for (auto& v : part.values()) v = -v;
  for (Eigen::Index i = 0; i < part.block_rows(); ++i) part.block(i, i).diagonal().array() += shift;
  const vec<double> b = test::perturbed_free_stream(m, 8u);
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(whole.to_sparse());
  const vec<double> x_ref = lu.solve(b);

  block_ilu<double, 4> ilu;
  ilu.compute(owned_part(part));
  const distributed_matrix_operator<2> op(d, part, MPI_COMM_WORLD);
  krylov_options o;
  o.relative_tolerance = 1e-11;
  o.max_iterations = 500;
  vec<double> x;
  const auto rep = gmres(op, ilu, d.local_part(b), x, o);
  EXPECT_TRUE(rep.converged) << rep.reason;
  EXPECT_LT((d.all_gather(x) - x_ref).norm(), 1e-9 * x_ref.norm());
  int its[2] = {rep.iterations, -rep.iterations}, all[2];
  MPI_Allreduce(its, all, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(all[0], -all[1]) << "ranks ran different iteration counts";
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: GMRES + block-Jacobi BILU(0) " << rep.iterations
              << " iterations, relative residual " << rep.relative_residual << "\n";
}

TEST(mpi_euler, residual_and_jacobian_rows_equal_the_serial_ones_on_a_split_wing) {
  // the tiny AGARD C-H grid is one block with interfaces to itself: cut for the ranks
  const auto s = split_for_ranks(flow::wing_cgrid(test_support::agard(), test_support::tiny_wing_options()),
                                 world_size());
  check_residual(flow::euler_model<3>(s.grid, {.mach = 0.9, .alpha_rad = 0.02}));
}

// The complex shifted system (s I - J) - i omega I of the root locus and the Hopf solves: GMRES on
// the ranks (complex vectors, a real matrix) with complex block-Jacobi BILU(0) of each rank's
// shifted own part, against Eigen's sparse LU of the whole shifted matrix.
TEST(mpi_euler, complex_shifted_gmres_solves_the_distributed_system) {
  using cd = std::complex<double>;
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  const vec<double> w = test::perturbed_free_stream(m, 6u);
  const double shift = 20.0;
  const cd sigma(0.0, 1.3);
  block_sparse_matrix<double, 4> whole, part;
  flow::assemble_jacobian<2>(m, w, flow::jacobian_kind::modified_order, whole);
  d.jacobian(d.local_part(w), flow::jacobian_kind::modified_order, part);
  for (auto* a : {&whole, &part}) {
    for (auto& v : a->values()) v = -v;
    for (Eigen::Index i = 0; i < a->block_rows(); ++i) a->block(i, i).diagonal().array() += shift;
  }
  const vec<double> br = test::perturbed_free_stream(m, 8u), bi = test::perturbed_free_stream(m, 10u);
  vec<cd> b(br.size());
  b.real() = br;
  b.imag() = bi;
  Eigen::SparseLU<Eigen::SparseMatrix<cd>> lu(shifted(whole, sigma).to_sparse());
  const vec<cd> x_ref = lu.solve(b);

  block_ilu<cd, 4> ilu;
  ilu.compute(shifted(owned_part(part), sigma));
  const distributed_matrix_operator<2, cd> op(d, part, MPI_COMM_WORLD, sigma);
  krylov_options o;
  o.relative_tolerance = 1e-11;
  o.max_iterations = 500;
  vec<cd> x;
  vec<cd> b_local(d.local_size());
  b_local.real() = d.local_part(br);
  b_local.imag() = d.local_part(bi);
  const auto rep = gmres(op, ilu, b_local, x, o);
  EXPECT_TRUE(rep.converged) << rep.reason;
  const vec<double> xr = d.all_gather(vec<double>(x.real())), xi = d.all_gather(vec<double>(x.imag()));
  EXPECT_LT((xr - x_ref.real()).norm() + (xi - x_ref.imag()).norm(), 1e-9 * x_ref.norm());
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: complex GMRES + block-Jacobi BILU(0) " << rep.iterations << " iterations\n";
}

TEST(mpi_euler, errors_are_collective) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  const vec<double> w = test::perturbed_free_stream(m, 5u);
  vec<double> local = d.local_part(w);
  // the last rank passes a state of the wrong size: every rank throws
  const int last = world_size() - 1;
  const vec<double> bad_size = d.rank() == last ? vec<double>(local.head(local.size() - 1)) : local;
  const std::string msg = test::input_error_of([&] { d.residual(bad_size); });
  if (d.rank() == last)
    EXPECT_TRUE(contains(msg, "distributed_euler::with_ghosts")) << msg;
  else
    EXPECT_TRUE(contains(msg, "refused on rank " + std::to_string(last))) << msg;
  // rank 0 holds a negative density: every rank throws, rank 0 naming the cell
  vec<double> bad = local;
  if (d.rank() == 0) bad[4 * 5] = -1.0;
  const std::string msg2 = test::input_error_of([&] { d.residual(bad); });
  if (d.rank() == 0)
    EXPECT_TRUE(contains(msg2, "not a physical state")) << msg2;
  else
    EXPECT_TRUE(contains(msg2, "refused on rank 0")) << msg2;
  // and the ranks carry on
  EXPECT_EQ(d.residual(local), d.local_part(m.residual(w)));
  // a partition for another number of ranks is refused on every rank
  const auto wrong = partition_blocks(m, world_size() == 3 ? 2 : 3);
  EXPECT_THROW(distributed_euler<2>(m, wrong, MPI_COMM_WORLD), input_error);
}

AEROHOPF_MPI_TEST_MAIN();
