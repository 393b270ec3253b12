// Steady Euler solutions on MPI ranks (distributed/mpi_steady.hpp: flow::solve_steady with the
// partitioned discretisation), run by CTest under mpirun on 2 and 3 ranks. Reference: the
// serial solve_steady of the same model. Checked: the distributed solve converges ten orders
// with every rank taking the same steps, the gathered state equals the serial steady state
// to the accuracy of the stopping test, lift and moment equal the serial ones, on the
// transonic lifting NACA 0012 (2D, with and without the vortex far field) and the tiny AGARD
// 445.6 C-H grid cut for the ranks (3D); a bad initial state on one rank and a run out of
// steps fail on every rank with the same error.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/flow/steady_solver.hpp>

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

/// Serial and distributed solves of m from the free stream; the states agree to `tol` relative
/// (max norm), cl and cm to `tol` absolute.
template <int Dim>
void check_steady(flow::euler_model<Dim>& serial_model, flow::euler_model<Dim>& m, double tol) {
  flow::steady_options opt;
  vec<double> ws = serial_model.free_stream_vector();
  const auto srep = flow::solve_steady<Dim>(serial_model, ws, opt);
  ASSERT_TRUE(srep.converged) << srep.reason;

  distributed_euler<Dim> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  distributed_euler_discretisation<Dim> disc(m, d);
  vec<double> w = d.local_part(m.free_stream_vector());
  const auto rep = flow::solve_steady(disc, w, opt);
  ASSERT_TRUE(rep.converged) << rep.reason;
  EXPECT_LE(rep.final_residual, opt.residual_drop * rep.initial_residual);
  // the same residual, its squares summed in another order
  EXPECT_NEAR(rep.initial_residual, srep.initial_residual, 1e-14 * srep.initial_residual);

  // every rank took the same steps
  int steps[2] = {rep.steps, -rep.steps}, all[2];
  MPI_Allreduce(steps, all, 2, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_EQ(all[0], -all[1]) << "ranks took different numbers of steps";

  const vec<double> wg = d.all_gather(w);
  const double scale = ws.cwiseAbs().maxCoeff();
  EXPECT_LT((wg - ws).cwiseAbs().maxCoeff(), tol * scale);
  const auto fs = serial_model.forces(ws), fd = d.forces(w);
  EXPECT_NEAR(fd.cl, fs.cl, tol);
  EXPECT_NEAR(fd.cm, fs.cm, tol);
  EXPECT_NEAR(rep.history.back().cl, fs.cl, tol);
  if (d.rank() == 0)
    std::cout << world_size() << " ranks, " << Dim << "D: " << rep.steps << " steps, " << rep.linear_iterations
              << " GMRES iterations (serial " << srep.steps << ", " << srep.linear_iterations
              << "); max |w - w_serial| / max |w| = " << (wg - ws).cwiseAbs().maxCoeff() / scale << ", CL " << fd.cl
              << " (serial " << fs.cl << ")\n";
}

}  // namespace

TEST(mpi_steady, transonic_lifting_aerofoil_equals_the_serial_solution) {
  const flow::free_stream fs{.mach = 0.8, .alpha_rad = 1.25 * M_PI / 180.0};
  flow::euler_model<2> serial(test::partition_cgrid(), fs), m(test::partition_cgrid(), fs);
  check_steady(serial, m, 1e-9);
}

TEST(mpi_steady, vortex_far_field_circulation_equals_the_serial_one) {
  const flow::free_stream fs{.mach = 0.7, .alpha_rad = 2.0 * M_PI / 180.0};
  flow::euler_options eo;
  eo.vortex_far_field = true;
  flow::euler_model<2> serial(test::partition_cgrid(), fs, eo), m(test::partition_cgrid(), fs, eo);
  check_steady(serial, m, 1e-9);
  EXPECT_NEAR(m.circulation(), serial.circulation(), 1e-9);
  EXPECT_NE(m.circulation(), 0.0);
}

TEST(mpi_steady, wing_cut_for_the_ranks_equals_the_serial_solution) {
  const auto s = split_for_ranks(flow::wing_cgrid(test_support::agard(), test_support::tiny_wing_options()),
                                 world_size());
  const flow::free_stream fs{.mach = 0.9, .alpha_rad = 0.02};
  flow::euler_model<3> serial(s.grid, fs), m(s.grid, fs);
  check_steady(serial, m, 1e-9);
}

TEST(mpi_steady, failures_are_the_same_on_every_rank) {
  flow::euler_model<2> m(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.02});
  distributed_euler<2> d(m, partition_blocks(m, world_size()), MPI_COMM_WORLD);
  distributed_euler_discretisation<2> disc(m, d);
  const vec<double> w0 = d.local_part(m.free_stream_vector());

  // a negative density on the last rank: every rank refuses the initial state, w untouched
  vec<double> bad = w0;
  const int last = world_size() - 1;
  if (d.rank() == last) bad[0] = -1.0;
  const vec<double> bad_before = bad;
  const std::string msg = test::input_error_of([&] { (void)flow::solve_steady(disc, bad, {}); });
  EXPECT_TRUE(contains(msg, "solve_steady")) << msg;
  // the last rank and those that read its cell name the cell, the others the rank
  EXPECT_TRUE(contains(msg, "non-positive density or pressure in block") ||
              (d.rank() != last && contains(msg, "refused on rank " + std::to_string(last))))
      << msg;
  EXPECT_EQ(bad, bad_before);

  // two steps are not enough: the same report on every rank, w the last accepted state
  flow::steady_options opt;
  opt.max_steps = 2;
  opt.throw_on_failure = false;
  vec<double> w = w0;
  const auto rep = flow::solve_steady(disc, w, opt);
  EXPECT_FALSE(rep.converged);
  EXPECT_TRUE(contains(rep.reason, "after 2 accepted steps")) << rep.reason;
  // rank 0's text is every rank's
  long long n = static_cast<long long>(rep.reason.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string first(static_cast<std::size_t>(n), ' ');
  if (d.rank() == 0) first = rep.reason;
  MPI_Bcast(first.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  EXPECT_EQ(rep.reason, first);
  EXPECT_EQ(d.residual(w).size(), w.size());  // a physical state the ranks can evaluate

  opt.throw_on_failure = true;
  w = w0;
  EXPECT_THROW((void)flow::solve_steady(disc, w, opt), convergence_error);
  // the ranks carry on: the full solve converges
  w = w0;
  EXPECT_TRUE(flow::solve_steady(disc, w, flow::steady_options{}).converged);
}

AEROHOPF_MPI_TEST_MAIN();
