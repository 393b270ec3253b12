// The pitch-plunge aerofoil's flutter family with its solves on MPI ranks
// (distributed/mpi_aerofoil_family.hpp), run by CTest under mpirun on 2, 3 and 4 ranks (4: more
// ranks than the C-grid's three blocks, which are cut first: aerofoil_on_ranks), against the
// serial family (models::aerofoil_family) on the very coarse grid, light case:
//  * aerofoil_on_ranks cuts the grid exactly when there are more ranks than blocks, its local()
//    and whole() are inverse, and its residual is the serial one (reordered) to rounding;
//  * the equilibrium (steady flow on the ranks, gathered) is the serial steady equilibrium to the
//    stopping test's accuracy;
//  * the inverse-power start at Ubar = 1.66, shift 0.75i is the serial hopf_start_krylov's
//    eigenvalue to 1e-8;
//  * the flutter boundary by trace_flutter_boundary at M = 0.5, 0.55, 0.6, 0.65 (first point
//    from inverse power, then natural continuation with the mode test, the crossing check; Newton
//    to ||F|| <= 1e-10) has the serial boundary's Ubar* and omega* to 1e-8 relative at every Mach
//    number, and every rank holds the same boundary;
//  * at a mean incidence of 1 deg (full Hopf systems about the static aeroelastic equilibrium,
//    solved on the ranks) the boundary at M = 0.5, 0.55 has the serial Ubar*, omega* and static
//    pitch deflection to 1e-8, and the last point's crossing check (a V-g scan from below Ubar*,
//    its inverse powers on the ranks: scan_eigen) the serial lowest rising zero of g to 1e-6.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/distributed/mpi_aerofoil_family.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <cmath>
#include <complex>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "support/error_messages.hpp"
#include "support/mpi_boundary.hpp"
#include "support/mpi_test.hpp"

// mpirun ranks: 2 3 4

using namespace aerohopf;
using aerohopf::test::world_size;

namespace {

models::aerofoil_family serial_aerofoil_family(double alpha_rad = 0.0) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return models::aerofoil_family(flow::naca_cgrid(), p, {}, alpha_rad);
}

using test::expect_serial_boundary;
using test::same_on_every_rank;
using test::world_rank;

constexpr int very_coarse = 8;

}  // namespace

TEST(mpi_aerofoil_family, the_grid_is_cut_only_for_more_ranks_than_blocks) {
  const auto serial = serial_aerofoil_family();
  const models::aerofoil_system s = serial.system(very_coarse, 0.6);
  distributed::aerofoil_on_ranks r(s, MPI_COMM_WORLD);
  EXPECT_EQ(r.cut(), world_size() > 3);
  // a state with the structure displaced (the grid moves) and a non-uniform flow
  vec<double> w = s.free_stream_state();
  for (Eigen::Index i = 0; i < s.flow_size(); ++i) w[i] *= 1 + 0.01 * std::sin(0.37 * double(i));
  w.tail(4) << 0.01, -0.02, 0.03, 0.01;
  const vec<double> wl = r.local(w);
  EXPECT_EQ(r.whole(wl), w);
  const vec<double> f = s.residual(w, 1.66);
  const vec<double> fd = r.whole(r.d().residual(wl, 1.66));
  EXPECT_LT((fd - f).norm(), 1e-12 * f.norm()) << "ranks " << world_size();
}

TEST(mpi_aerofoil_family, equilibrium_and_start_equal_the_serial_ones) {
  const auto serial = serial_aerofoil_family();
  const distributed::aerofoil_family dist(serial, MPI_COMM_WORLD);
  const models::aerofoil_system s = serial.system(very_coarse, 0.6);
  const vec<double> ws = serial.equilibrium(s, 1.66);
  const vec<double> wd = dist.equilibrium(s, 1.66);
  ASSERT_EQ(wd.size(), ws.size());
  // both converged by the same stopping test; only the preconditioner differs
  EXPECT_LT((wd - ws).norm(), 1e-8 * ws.norm());
  EXPECT_LT(s.residual(wd, 1.66).norm(), 1e-9);
  EXPECT_TRUE(same_on_every_rank(wd.sum()));

  hopf_start_krylov_options so;
  so.fill_level = 2;
  so.inverse_power.tolerance = 1e-10;
  eigen_pair es, ed;
  const hopf_point hs = hopf_start_krylov<4>(s, ws, 1.66, 0.75, so, &es);
  const hopf_point hd = dist.hopf_start(s, ws, 1.66, 0.75, so, &ed);
  EXPECT_LT(std::abs(ed.lambda - es.lambda), 1e-8 * std::abs(es.lambda)) << ed.lambda << " vs " << es.lambda;
  EXPECT_LT(std::abs(hd.omega - hs.omega), 1e-8 * hs.omega);
  EXPECT_GT(hd.omega, 0.0);
  ASSERT_EQ(hd.p.size(), s.size());
  // the same eigenvector up to its complex scale
  const std::complex<double> c = hs.p.dot(hd.p) / hs.p.squaredNorm();
  EXPECT_LT((hd.p - c * hs.p).norm(), 1e-7 * hd.p.norm());
  EXPECT_EQ(hd.w, ws);
}

TEST(mpi_aerofoil_family, flutter_boundary_equals_the_serial_one) {
  const auto serial = serial_aerofoil_family();
  const distributed::aerofoil_family dist(serial, MPI_COMM_WORLD);
  const std::vector<double> machs{0.5, 0.55, 0.6, 0.65};
  flutter_boundary_options o = serial.boundary_options();
  o.start_mu = 1.66;
  o.start_omega = 0.75;
  expect_serial_boundary(serial, dist, very_coarse, machs, o, "light very coarse");
}

// A mean incidence of 1 deg: every point a full Hopf system about the static aeroelastic
// equilibrium (solved on the ranks), the static pitch deflection moving with Ubar.
TEST(mpi_aerofoil_family, moving_equilibrium_boundary_equals_the_serial_one) {
  const auto serial = serial_aerofoil_family(std::numbers::pi / 180);
  const distributed::aerofoil_family dist(serial, MPI_COMM_WORLD);
  EXPECT_FALSE(dist.fixed_equilibrium());
  const std::vector<double> machs{0.5, 0.55};
  flutter_boundary_options o = serial.boundary_options();
  o.start_mu = 1.66;
  o.start_omega = 0.75;
  // the last point's crossing check: a V-g scan from below Ubar*, its inverse powers on the ranks
  // (serially BILU-GMRES too: the LU a grid this small gets by default is off)
  static_assert(aerohopf::internal::has_scan_eigen<distributed::aerofoil_family>);
  o.scan_direct_max_unknowns = 0;
  expect_serial_boundary(serial, dist, very_coarse, machs, o, "light very coarse alpha 1",
                         [](const flutter_boundary_point& p, const flutter_boundary_point& q) {
                           // the static pitch deflection at the flutter point
                           const double pitch = p.point.w[p.point.w.size() - 2];
                           const double pitch_ref = q.point.w[q.point.w.size() - 2];
                           EXPECT_GT(pitch, 1e-4) << "M = " << p.mach;
                           EXPECT_LT(std::abs(pitch - pitch_ref), 1e-8 * pitch_ref) << "M = " << p.mach;
                         },
                         1e-6);
}

AEROHOPF_MPI_TEST_MAIN();
