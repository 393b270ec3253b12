// The flexible wing's flutter family with its solves on MPI ranks
// (distributed/mpi_wing_family.hpp), run by CTest under mpirun on 2 and 3 ranks, against the
// serial family (models::wing_family) on the tiny AGARD 445.6 C-H grid (16 x 4 x 6 cells, four
// plate modes, no structural damping):
//  * the vectors cross to the cut grid and back unchanged (wing_on_ranks);
//  * the equilibrium (the steady flow on the ranks of the cut grid, gathered in the serial
//    order) is the serial steady equilibrium to the stopping test's accuracy;
//  * the inverse-power start at mu = 0.075, shift 0.4i is the serial hopf_start_krylov's
//    eigenvalue to 1e-8;
//  * the flutter boundary by trace_flutter_boundary at M = 0.5, 0.55, 0.6 (Newton to ||F|| <=
//    1e-10) has the serial boundary's mu* and omega* to 1e-8 relative at every Mach number, the
//    same on every rank.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/mpi_wing_family.hpp>
#include <aerohopf/models/wing_family.hpp>

#include <cmath>
#include <complex>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "support/mpi_boundary.hpp"
#include "support/mpi_test.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using aerohopf::test::world_size;

namespace {

/// The tiny wing's family, the test schedule's speed of sound (spec 06).
models::wing_family serial_wing_family() {
  models::speed_of_sound_schedule s;
  s.mach = {0.499, 0.678, 0.901, 0.960};
  s.speed_of_sound = {172.46 / 0.499, 231.37 / 0.678, 296.69 / 0.901, 310.96 / 0.960};
  return models::wing_family(test_support::agard(), test_support::tiny_wing_options(), {1},
                             test_support::agard_plate_modes(), Eigen::VectorXd::Zero(1), s);
}

using test::expect_serial_boundary;
using test::same_on_every_rank;
using test::world_rank;

}  // namespace

TEST(mpi_wing_family, equilibrium_and_start_equal_the_serial_ones) {
  const auto serial = serial_wing_family();
  const distributed::wing_family dist(serial, MPI_COMM_WORLD);
  const models::wing_system s = serial.system(1, 0.5);
  {  // whole vectors to the ranks and back
    distributed::wing_on_ranks r(s, MPI_COMM_WORLD);
    vec<std::complex<double>> x(s.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = {std::sin(0.1 * double(i)), std::cos(0.3 * double(i))};
    EXPECT_EQ(r.whole(r.local(x)), x);
  }
  const vec<double> ws = serial.equilibrium(s, 0.075);
  const vec<double> wd = dist.equilibrium(s, 0.075);
  ASSERT_EQ(wd.size(), ws.size());
  EXPECT_LT((wd - ws).norm(), 1e-8 * ws.norm());  // the same stopping test; only the preconditioner differs
  const double fd = s.residual<double>(wd, 0.075).norm(), fs = s.residual<double>(ws, 0.075).norm();
  EXPECT_LT(fd, 10 * fs + 1e-12);  // the same stopping test (a drop relative to the first residual) as the serial
  if (world_rank() == 0) std::cout << "||f|| of the equilibrium on the ranks " << fd << ", serial " << fs << "\n";
  EXPECT_TRUE(same_on_every_rank(wd.sum()));

  hopf_start_krylov_options so;
  so.fill_level = 1;
  so.inverse_power.tolerance = 1e-10;
  eigen_pair es, ed;
  const hopf_point hs = hopf_start_krylov<5>(s, ws, 0.075, 0.4, so, &es);
  const hopf_point hd = dist.hopf_start(s, ws, 0.075, 0.4, so, &ed);
  EXPECT_LT(std::abs(ed.lambda - es.lambda), 1e-8 * std::abs(es.lambda)) << ed.lambda << " vs " << es.lambda;
  EXPECT_LT(std::abs(hd.omega - hs.omega), 1e-8 * hs.omega);
  ASSERT_EQ(hd.p.size(), s.size());
  const std::complex<double> c = hs.p.dot(hd.p) / hs.p.squaredNorm();  // the same vector up to its scale
  EXPECT_LT((hd.p - c * hs.p).norm(), 1e-7 * hd.p.norm());
}

TEST(mpi_wing_family, flutter_boundary_equals_the_serial_one) {
  const auto serial = serial_wing_family();
  const distributed::wing_family dist(serial, MPI_COMM_WORLD);
  const std::vector<double> machs{0.5, 0.55, 0.6};
  flutter_boundary_options o = serial.boundary_options();
  o.start_mu = 0.075;
  o.start_omega = 0.4;
  expect_serial_boundary(serial, dist, 1, machs, o, "tiny wing");
}

AEROHOPF_MPI_TEST_MAIN();
