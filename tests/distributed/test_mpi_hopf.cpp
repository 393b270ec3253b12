// The Hopf (flutter) point of the pitch-plunge NACA 0012 on MPI ranks (distributed/mpi_hopf.hpp),
// run by CTest under mpirun on 2 and 3 ranks, against the serial Krylov Hopf solver
// (solve_hopf_krylov) on the same very coarse grid (light case, M = 0.5):
//  * fixed equilibrium (zero incidence): from the serial start's parts, and from a start found on
//    the ranks (inverse power of the distributed Jacobian at Ubar = 1.75, shift 0.6i), Ubar* and
//    omega* equal the serial ones to 1e-9 relative and p* is the serial eigenvector (up to the
//    complex scale of the normalisation); the convergence is quadratic;
//  * full formulation (mean incidence 1 deg: the static pitch deflection moves with Ubar): from
//    the static equilibrium at Ubar = 1.7, Ubar*, omega* and the moving equilibrium w* equal the
//    serial full Krylov solve's; the fixed-equilibrium formulation refuses that equilibrium;
//  * the start refinement (an eigenvector 30 % off: one inverse iteration) is kept as in the
//    serial solve, lowers the start's ||F|| and reaches the serial point;
//  * bad input is refused on every rank and a Newton limit reached (iterations, contraction) is
//    a convergence_error on every rank, or a result not converged holding the last iterate.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/mpi_aerofoil.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <cmath>
#include <complex>
#include <iostream>
#include <numbers>
#include <string>

#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/partition_grids.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;
using cd = std::complex<double>;

namespace {

models::aerofoil_family family(double alpha_deg) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return models::aerofoil_family(flow::naca_cgrid(), p, {}, alpha_deg * std::numbers::pi / 180);
}

/// This rank's part of a complex vector, and the whole from the parts.
vec<cd> local_part(distributed_aerofoil& d, const vec<cd>& g) { return d.local_part(g); }
vec<cd> gather(distributed_aerofoil& d, const vec<cd>& local) { return d.all_gather(local); }
/// ||p - c q|| / ||p|| with c the best complex scale: the same eigenvector up to normalisation.
double eigenvector_distance(const vec<cd>& p, const vec<cd>& q) {
  const cd c = q.dot(p) / q.squaredNorm();
  return (p - c * q).norm() / p.norm();
}

distributed_hopf_point local_guess(distributed_aerofoil& d, const hopf_point& g) {
  return {d.local_part(g.w), g.mu, g.omega, local_part(d, g.p)};
}

void expect_quadratic(const newton_report& r) {
  const auto& h = r.residual_history;
  ASSERT_GE(h.size(), 3u);
  // the last step squares (or beats) the error of the one before, up to a constant
  EXPECT_LT(h.back(), 10 * h[h.size() - 2] * h[h.size() - 2] + 1e-11) << "not quadratic";
}

}  // namespace

TEST(mpi_hopf, fixed_equilibrium_equals_the_serial_krylov_solve) {
  const auto f = family(0.0);
  const models::aerofoil_system sys = f.system(8, 0.5);
  const vec<double> w = sys.steady_equilibrium();
  const hopf_point start = hopf_start(sys, w, 1.75, 0.6);
  hopf_options opt;
  opt.fixed_equilibrium = true;
  const hopf_result ref = solve_hopf_krylov<4>(sys, start, opt);
  ASSERT_TRUE(ref.report.converged);

  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  distributed_hopf_options o;
  o.hopf = opt;
  o.hopf.label = "distributed hopf";
  o.hopf.verbose = true;
  const distributed_hopf_result r = distributed::solve_hopf(d, local_guess(d, start), o);
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  EXPECT_LT(std::abs(r.point.mu - ref.point.mu), 1e-9 * ref.point.mu) << r.point.mu << " vs " << ref.point.mu;
  EXPECT_LT(std::abs(r.point.omega - ref.point.omega), 1e-9 * ref.point.omega);
  EXPECT_GT(r.point.omega, 0.0);
  EXPECT_LT(eigenvector_distance(gather(d, r.point.p), ref.point.p), 1e-8);
  EXPECT_EQ(d.all_gather(r.point.w), w);  // the equilibrium is not an unknown
  EXPECT_GT(r.linear_iterations, 0);
  expect_quadratic(r.report);
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: Ubar* " << std::setprecision(15) << r.point.mu << " omega* " << r.point.omega
              << " (serial " << ref.point.mu << ", " << ref.point.omega << "), " << r.report.iterations << " Newton / "
              << r.linear_iterations << " GMRES iterations (serial " << ref.report.iterations << " / "
              << ref.linear_iterations << ")\n";

  // the whole pipeline on the ranks: the start by inverse power of the distributed Jacobian
  distributed_aerofoil::jacobian_rows a, p;
  const vec<double> wl = d.local_part(w);
  d.jacobians(wl, 1.75, a, p);
  distributed_inverse_power_options io;
  io.power.tolerance = 1e-8;  // a start: Newton converges the pair
  const eigen_pair ep = distributed::inverse_power(d, a, &p, cd(0.0, 0.6), io);
  distributed_hopf_point g{wl, 1.75, std::abs(ep.lambda.imag()), ep.vector};
  if (ep.lambda.imag() < 0) g.p = g.p.conjugate().eval();
  o.hopf.verbose = false;
  const distributed_hopf_result r2 = distributed::solve_hopf(d, g, o);
  ASSERT_TRUE(r2.report.converged) << r2.report.reason;
  EXPECT_LT(std::abs(r2.point.mu - ref.point.mu), 1e-9 * ref.point.mu);
  EXPECT_LT(std::abs(r2.point.omega - ref.point.omega), 1e-9 * ref.point.omega);
}

TEST(mpi_hopf, full_formulation_equals_the_serial_full_krylov_solve) {
  const auto f = family(1.0);
  const models::aerofoil_system sys = f.system(8, 0.5);
  const vec<double> w17 = f.static_equilibrium(sys, 1.7, 2, 1e-10);
  const hopf_point start = hopf_start(sys, w17, 1.7, 0.6);
  hopf_options opt;
  opt.fixed_equilibrium = false;
  hopf_krylov_options ko;
  ko.full_system = true;
  const hopf_result ref = solve_hopf_krylov<4>(sys, start, opt, ko);
  ASSERT_TRUE(ref.report.converged);

  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  distributed_hopf_options o;
  o.hopf = opt;
  o.hopf.label = "distributed hopf (full)";
  o.hopf.verbose = true;
  const distributed_hopf_result r = distributed::solve_hopf(d, local_guess(d, start), o);
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  EXPECT_LT(std::abs(r.point.mu - ref.point.mu), 1e-9 * ref.point.mu) << r.point.mu << " vs " << ref.point.mu;
  EXPECT_LT(std::abs(r.point.omega - ref.point.omega), 1e-9 * ref.point.omega);
  const vec<double> wg = d.all_gather(r.point.w);
  EXPECT_LT((wg - ref.point.w).norm(), 1e-8 * ref.point.w.norm());
  EXPECT_GT(wg[wg.size() - 2], w17[w17.size() - 2]);  // the static pitch deflection moved with Ubar
  EXPECT_LT(eigenvector_distance(gather(d, r.point.p), ref.point.p), 1e-7);
  if (d.rank() == 0)
    std::cout << world_size() << " ranks (full): Ubar* " << std::setprecision(15) << r.point.mu << " omega* "
              << r.point.omega << " pitch " << wg[wg.size() - 2] << " (serial " << ref.point.mu << ", "
              << ref.point.omega << "), " << r.report.iterations << " Newton / " << r.linear_iterations
              << " GMRES iterations (serial " << ref.report.iterations << " / " << ref.linear_iterations << ")\n";

  // the fixed-equilibrium formulation refuses an equilibrium that moves with Ubar, on every rank
  distributed_hopf_options fo = o;
  fo.hopf.fixed_equilibrium = true;
  fo.hopf.verbose = false;
  const std::string msg = test::error_of<convergence_error>([&] { (void)distributed::solve_hopf(d, local_guess(d, start), fo); });
  EXPECT_TRUE(test::contains(msg, "equilibrium does not hold")) << msg;
}

TEST(mpi_hopf, start_refinement_as_the_serial_one) {
  const auto f = family(0.0);
  const models::aerofoil_system sys = f.system(8, 0.5);
  const vec<double> w = sys.steady_equilibrium();
  hopf_point start = hopf_start(sys, w, 1.75, 0.6);
  // an eigenvector far off (a smooth perturbation of 30 % of its size), as a continued guess
  // across a shock's motion is
  const double scale = 0.3 * start.p.norm() / std::sqrt(static_cast<double>(start.p.size()));
  for (Eigen::Index i = 0; i < start.p.size(); ++i)
    start.p[i] += scale * cd(std::sin(0.37 * static_cast<double>(i)), std::cos(0.11 * static_cast<double>(i)));
  hopf_options opt;
  opt.fixed_equilibrium = true;
  hopf_krylov_options ko;
  ko.start_iterations = 1;
  const hopf_result ref = solve_hopf_krylov<4>(sys, start, opt, ko);
  ASSERT_TRUE(ref.report.converged);
  EXPECT_TRUE(ref.start_refined);

  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  distributed_hopf_options o;
  o.hopf = opt;
  o.start_iterations = 1;
  const distributed_hopf_result r = distributed::solve_hopf(d, local_guess(d, start), o);
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  EXPECT_TRUE(r.start_refined);
  // the refined start is nearer: ||F|| of the start below the unrefined one's
  o.start_iterations = 0;
  const distributed_hopf_result u = distributed::solve_hopf(d, local_guess(d, start), o);
  ASSERT_TRUE(u.report.converged) << u.report.reason;
  EXPECT_FALSE(u.start_refined);
  EXPECT_LT(r.report.residual_history.front(), u.report.residual_history.front());
  EXPECT_LT(std::abs(r.point.mu - ref.point.mu), 1e-9 * ref.point.mu) << r.point.mu << " vs " << ref.point.mu;
  EXPECT_LT(std::abs(r.point.omega - ref.point.omega), 1e-9 * ref.point.omega);
  // a threshold above the start's ||F||: no refinement
  o.start_iterations = 1;
  o.start_residual_threshold = 1e6;
  EXPECT_FALSE(distributed::solve_hopf(d, local_guess(d, start), o).start_refined);
}

// A distributed solve runs the GMRES of its serial twin: the serial options' restart, deflation,
// iteration limit and Gram-Schmidt passes carry over (the tolerance is the caller's forcing); a
// GMRES-DR(300, 20) against a plain GMRES(300) is another solver on a hard correction.
TEST(mpi_hopf, serial_gmres_settings_carry_over_to_the_distributed_options) {
  hopf_krylov_options ko;
  ko.krylov.restart = 300;
  ko.krylov.deflation = 0;
  ko.krylov.max_iterations = 1234;
  ko.krylov.reorthogonalize = true;
  ko.krylov.reorthogonalization_threshold = 0.5;
  const distributed_hopf_options o = distributed::internal::hopf_options_from(hopf_options{}, ko);
  EXPECT_EQ(o.krylov.restart, 300);
  EXPECT_EQ(o.krylov.deflation, 0);
  EXPECT_EQ(o.krylov.max_iterations, 1234);
  EXPECT_TRUE(o.krylov.reorthogonalize);
  EXPECT_EQ(o.krylov.reorthogonalization_threshold, 0.5);
  EXPECT_EQ(distributed::internal::hopf_options_from(hopf_options{}, hopf_krylov_options{}).krylov.deflation,
            hopf_krylov_options{}.krylov.deflation);
  hopf_start_krylov_options so;
  so.krylov.restart = 50;
  so.krylov.deflation = 12;
  const distributed_inverse_power_options io = distributed::internal::inverse_power_options_from(so);
  EXPECT_EQ(io.krylov.restart, 50);
  EXPECT_EQ(io.krylov.deflation, 12);
  EXPECT_EQ(io.krylov.relative_tolerance, so.krylov.relative_tolerance);
  EXPECT_EQ(io.fill_level, so.fill_level);
}

TEST(mpi_hopf, bad_input_and_failures_are_the_same_on_every_rank) {
  const auto f = family(0.0);
  const models::aerofoil_system sys = f.system(8, 0.5);
  const vec<double> w = sys.steady_equilibrium();
  const hopf_point start = hopf_start(sys, w, 1.75, 0.6);
  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  distributed_hopf_options o;
  o.hopf.fixed_equilibrium = true;
  const distributed_hopf_point g = local_guess(d, start);
  const int last = world_size() - 1;
  // a short eigenvector part on the last rank only
  distributed_hopf_point bad = g;
  if (d.rank() == last) bad.p = bad.p.head(bad.p.size() - 1).eval();
  std::string msg = test::input_error_of([&] { (void)distributed::solve_hopf(d, bad, o); });
  EXPECT_TRUE(test::contains(msg, d.rank() == last ? "guess.p" : "refused on rank")) << msg;
  // NaN in w on rank 0, a zero eigenvector, a NaN Ubar, bad options
  bad = g;
  if (d.rank() == 0) bad.w[0] = NAN;
  EXPECT_THROW((void)distributed::solve_hopf(d, bad, o), input_error);
  bad = g;
  bad.p.setZero();
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)distributed::solve_hopf(d, bad, o); }), "zero"));
  bad = g;
  bad.mu = NAN;
  EXPECT_THROW((void)distributed::solve_hopf(d, bad, o), input_error);
  distributed_hopf_options bo = o;
  bo.fill_level = -1;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)distributed::solve_hopf(d, g, bo); }), "fill_level"));
  bo = o;
  bo.start_tolerance = 1.0;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)distributed::solve_hopf(d, g, bo); }), "start_tolerance"));
  bo = o;
  bo.hopf.fixed_equilibrium = false;
  bo.start_iterations = 1;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)distributed::solve_hopf(d, g, bo); }),
                             "only in the fixed-equilibrium formulation"));
  // one Newton iteration is not enough: a convergence_error naming the iterate on every rank, or
  // with throw_on_failure = false a result that holds the last iterate
  distributed_hopf_options lo = o;
  lo.hopf.newton.max_iterations = 1;
  msg = test::error_of<convergence_error>([&] { (void)distributed::solve_hopf(d, g, lo); });
  EXPECT_TRUE(test::contains(msg, "no convergence in 1 Newton iterations")) << msg;
  EXPECT_TRUE(test::contains(msg, "iterate 1")) << msg;
  lo.hopf.newton.throw_on_failure = false;
  const distributed_hopf_result r = distributed::solve_hopf(d, g, lo);
  EXPECT_FALSE(r.report.converged);
  EXPECT_EQ(r.report.iterations, 1);
  EXPECT_TRUE(std::isfinite(r.point.mu));
  EXPECT_NE(r.point.mu, g.mu);  // the iterate after the one step
  // the contraction test (as newton_options): a step that leaves ||F|| above max_contraction
  // times the one before fails at once, as the serial Newton does (a start outside the basin)
  distributed_hopf_options co = o;
  co.hopf.newton.max_contraction = 1e-12;
  co.hopf.newton.contraction_from = 1;
  msg = test::error_of<convergence_error>([&] { (void)distributed::solve_hopf(d, g, co); });
  EXPECT_TRUE(test::contains(msg, "not contracting at iterate 1")) << msg;
}

AEROHOPF_MPI_TEST_MAIN();
