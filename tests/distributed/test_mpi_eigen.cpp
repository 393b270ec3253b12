// Shift-invert inverse power on MPI ranks (distributed/mpi_eigen.hpp), run by CTest under mpirun
// on 2 and 3 ranks. Reference: the serial inverse power with Eigen's sparse LU of the whole
// shifted matrix (itself tested against dense spectra in tests/bifurcation). Checked on the
// exact Jacobian of a transonic lifting NACA 0012 steady state (from the serial steady solve)
// with the modified-order Jacobian as preconditioning matrix: the eigenvalue nearest the shift
// to 1e-10 relative (1e-8 from a start and shift near it, the root locus' step), the gathered eigenvector (phase fixed alike) to 1e-7, every rank ending
// after the same iterations; bad input refused on every rank.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/distributed/mpi_eigen.hpp>
#include <aerohopf/flow/steady_solver.hpp>

#include <complex>
#include <iostream>

#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/partition_grids.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;
using cd = std::complex<double>;

namespace {

struct flow_case {
  flow::euler_model<2> m{test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 1.25 * M_PI / 180.0}};
  vec<double> w;
  flow_case() {
    w = m.free_stream_vector();
    flow::solve_steady<2>(m, w, {});
  }
};

/// -J (the Jacobian negated: its spectrum near the origin, complex pairs) in d's numbering.
void minus_jacobian(distributed_euler<2>& d, const vec<double>& w, flow::jacobian_kind kind,
                    block_sparse_matrix<double, 4>& a) {
  d.jacobian(d.local_part(w), kind, a);
  for (auto& v : a.values()) v = -v;
}

}  // namespace

TEST(mpi_eigen, inverse_power_equals_the_serial_sparse_lu_iteration) {
  const flow_case c;
  block_sparse_matrix<double, 4> whole;
  flow::assemble_jacobian<2>(c.m, c.w, flow::jacobian_kind::exact, whole);
  const Eigen::SparseMatrix<double> a_serial = -whole.to_sparse();
  const cd shift(0.05, 0.08);  // near the pair 0.05246 +- 0.07978i of this grid's -J (dense spectrum)
  inverse_power_options po;
  po.tolerance = 1e-10;
  const eigen_pair ref = inverse_power(a_serial, shift, po);

  distributed_euler<2> d(c.m, partition_blocks(c.m, world_size()), MPI_COMM_WORLD);
  block_sparse_matrix<double, 4> a, p;
  minus_jacobian(d, c.w, flow::jacobian_kind::exact, a);
  minus_jacobian(d, c.w, flow::jacobian_kind::modified_order, p);
  distributed_inverse_power_options o;
  o.power = po;
  o.fill_level = 2;
  const eigen_pair ep = distributed::inverse_power(d, a, &p, shift, o);
  EXPECT_LT(std::abs(ep.lambda - ref.lambda), 1e-10 * std::abs(ref.lambda)) << ep.lambda << " vs " << ref.lambda;
  EXPECT_LE(ep.residual, 1e-10 * std::max(1.0, std::abs(ep.lambda)));
  EXPECT_NEAR(ep.iterations, ref.iterations, 1);
  const vec<double> xr = d.all_gather(vec<double>(ep.vector.real())), xi = d.all_gather(vec<double>(ep.vector.imag()));
  vec<cd> x(xr.size());
  x.real() = xr;
  x.imag() = xi;
  EXPECT_NEAR(x.norm(), 1.0, 1e-14);
  EXPECT_LT((x - ref.vector).norm(), 1e-7);
  int its[2] = {ep.iterations, -ep.iterations}, all[2];
  MPI_Allreduce(its, all, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(all[0], -all[1]) << "ranks ran different iteration counts";
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: lambda " << ep.lambda << " in " << ep.iterations << " iterations, "
              << ep.linear_iterations << " GMRES iterations (serial sparse LU: " << ref.lambda << ", "
              << ref.iterations << " iterations)\n";

  // the eigenvector as the start and a shift near the eigenvalue (the root locus' next point;
  // a shift AT the eigenvalue would make every GMRES solve singular): two iterations
  const eigen_pair again = distributed::inverse_power(d, a, &p, ep.lambda + cd(1e-3, -1e-3), o, &ep.vector);
  EXPECT_LE(again.iterations, 2);
  EXPECT_LT(std::abs(again.lambda - ref.lambda), 1e-8 * std::abs(ref.lambda));  // residual 1e-10: 4e-10 measured
}

TEST(mpi_eigen, bad_input_is_refused_on_every_rank) {
  const flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  block_sparse_matrix<double, 4> a;
  minus_jacobian(d, m.free_stream_vector(), flow::jacobian_kind::exact, a);
  EXPECT_THROW(distributed::inverse_power(d, a, nullptr, cd(NAN, 0.1)), input_error);
  // a start of the wrong size on the last rank only
  const int last = world_size() - 1;
  const vec<cd> start = vec<cd>::Ones(d.local_size() - (d.rank() == last ? 1 : 0));
  const std::string msg = test::input_error_of([&] { distributed::inverse_power(d, a, nullptr, cd(0, 0.1), {}, &start); });
  EXPECT_TRUE(test::contains(msg, d.rank() == last ? "start vector" : "refused on rank")) << msg;
  // a zero start everywhere
  const vec<cd> zero = vec<cd>::Zero(d.local_size());
  EXPECT_THROW(distributed::inverse_power(d, a, nullptr, cd(0, 0.1), {}, &zero), input_error);
  // a NaN matrix entry on rank 0
  block_sparse_matrix<double, 4> bad = a;
  if (d.rank() == 0) bad.values()[3] = NAN;
  EXPECT_THROW(distributed::inverse_power(d, bad, nullptr, cd(0, 0.1)), input_error);
}

AEROHOPF_MPI_TEST_MAIN();
