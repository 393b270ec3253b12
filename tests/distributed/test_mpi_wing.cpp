// The modal AGARD 445.6 wing on MPI ranks (distributed/mpi_wing.hpp, and the solvers of
// distributed/mpi_bordered.hpp on it), run by CTest under mpirun on 2 and 3 ranks. Reference: the
// serial wing_system on the same tiny C-H grid (16 x 4 x 6 cells, four plate modes) cut into as
// many blocks as ranks (models::split_wing_system). Checked:
//  - at a perturbed flow with the wing deflected and moving (the grid moved, with grid speeds)
//    and at rest: the gathered residual equals the serial one, and the bordered Jacobian rows,
//    exact and modified-order, applied to a vector equal the serial bordered Jacobian's product
//    (to rounding: the generalised forces are summed in another order);
//  - the eigenvalue of the first bending mode by inverse power on the ranks equals the serial
//    sparse-LU inverse power's;
//  - the static aeroelastic equilibrium at 1 deg incidence by Newton-GMRES on the ranks equals
//    the serial Newton-Krylov one (solve_equilibrium_krylov);
//  - the flutter point by the distributed Hopf Newton equals the serial Krylov one: the
//    fixed-equilibrium formulation at zero incidence, the full one at 1 deg (the static
//    deflection moving with mu);
//  - a NaN mu or a short local state is refused on every rank.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/equilibrium_krylov.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/distributed/mpi_hopf.hpp>
#include <aerohopf/distributed/mpi_wing.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/models/wing.hpp>

#include <complex>
#include <iostream>
#include <numbers>
#include <random>
#include <string>

#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/wing_cases.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;

namespace {

/// The tiny wing at M = 0.5, U = 170 m/s, 2 % damping, incidence alpha_deg, cut for the ranks.
models::wing_system cut_wing(double alpha_deg) {
  using test_support::agard;
  const flow::multiblock_grid<3> g = flow::wing_cgrid(agard(), test_support::tiny_wing_options());
  coupling::wing_motion_options o;
  o.length_scale = agard().planform.root_chord;
  o.grid = test_support::tiny_wing_options();
  const auto& modes = test_support::agard_plate_modes();
  const models::wing_system whole(
      flow::euler_model<3>(g, {.mach = 0.5, .alpha_rad = alpha_deg * std::numbers::pi / 180}, {.force_tag = "wing"}),
      coupling::wing_modal_motion(g, modes, o),
      structure::modal_structure::from_physical(modes.omega, Eigen::VectorXd::Constant(modes.modes(), 0.02),
                                                agard().planform.root_chord, 170.0));
  return models::split_wing_system(whole, split_for_ranks(g, world_size()));
}

/// The same random vector on every rank.
vec<double> random_vector(Eigen::Index n, unsigned seed, double scale) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  vec<double> x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = scale * g(rng);
  return x;
}

/// The serial Newton-Krylov equilibrium with full steps to ||f|| <= 1e-10 (the static tests).
equilibrium_krylov_options full_steps() {
  equilibrium_krylov_options eo;
  eo.newton.abs_tolerance = 1e-10;
  eo.newton.line_search = false;
  return eo;
}

double relative_gap(const vec<double>& a, const vec<double>& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

void check_at(const models::wing_system& sys, distributed_wing& d, const vec<double>& ws, double mu) {
  const Eigen::Index nf = sys.flow_size(), ns = sys.structure_size();
  vec<double> w(sys.size());
  w.head(nf) = sys.flow().free_stream_vector();
  w.head(nf) += random_vector(nf, 3u, 1e-3).cwiseProduct(w.head(nf));
  w.tail(ns) = ws;
  const vec<double> local = d.local_part(w);
  EXPECT_EQ(d.all_gather(local), w);

  const vec<double> r_serial = sys.residual<double>(w, mu);
  const vec<double> r = d.all_gather(d.residual(local, mu));
  EXPECT_LT(relative_gap(r.head(nf), r_serial.head(nf)), 1e-14) << "flow rows";
  EXPECT_LT(relative_gap(r.tail(ns), r_serial.tail(ns)), 1e-12) << "structural rows";

  const vec<double> x = random_vector(sys.size(), 9u, 1.0);
  const auto pair = sys.bordered_jacobians(w, mu);
  for (const auto kind : {flow::jacobian_kind::exact, flow::jacobian_kind::modified_order}) {
    const auto& serial = kind == flow::jacobian_kind::exact ? pair.exact : pair.preconditioning;
    vec<double> ref(sys.size());
    serial.apply(x, ref);
    distributed_wing::jacobian_rows j;
    d.jacobian(local, mu, kind, j);
    const vec<double> y = d.all_gather(d.multiply(j, d.local_part(x)));
    EXPECT_LT(relative_gap(y.head(nf), ref.head(nf)), 1e-13) << "flow rows";
    EXPECT_LT(relative_gap(y.tail(ns), ref.tail(ns)), 1e-12) << "structural rows";
  }
  // both kinds at once (the border computed once) equal the single-kind assemblies
  distributed_wing::jacobian_rows e1, p1, p2;
  d.jacobians(local, mu, e1, p1);
  d.jacobian(local, mu, flow::jacobian_kind::modified_order, p2);
  EXPECT_EQ(p1.flow.values(), p2.flow.values());
  EXPECT_EQ(p1.flow_structure, p2.flow_structure);
  EXPECT_EQ(p1.structure_flow, p2.structure_flow);
  EXPECT_EQ(p1.structure, p2.structure);
}

}  // namespace

TEST(mpi_wing, residual_and_bordered_jacobian_equal_the_serial_ones) {
  const models::wing_system sys = cut_wing(0.0);
  distributed_wing d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  EXPECT_EQ(d.structure_size(), 8);
  vec<double> ws(8);
  ws << 0.003, -0.002, 0.001, 0.0005, 0.01, -0.02, 0.005, 0.002;
  check_at(sys, d, ws, 0.075);                       // deflected and moving
  check_at(sys, d, vec<double>::Zero(8), 0.075);     // at rest: the rest grid
  check_at(sys, d, vec<double>(-0.5 * ws), 0.05);    // moved again
  if (d.rank() == 0) std::cout << world_size() << " ranks: wing residual and Jacobian rows checked\n";
}

// The eigenvalue nearest 0.4i at mu = 0.075 on the steady flow (the flutter mode, which crosses
// the axis at mu* = 0.0799, omega* = 0.4998), by inverse power on the ranks (GMRES, block-Jacobi
// BILU with the border eliminated) against the serial inverse power with the sparse LU of the
// whole Jacobian.
TEST(mpi_wing, inverse_power_equals_the_serial_sparse_lu_iteration) {
  using cd = std::complex<double>;
  const models::wing_system sys = cut_wing(0.0);
  const vec<double> w0 = sys.steady_equilibrium();
  const double mu = 0.075;
  const cd shift(0.0, 0.4);
  inverse_power_options po;
  po.tolerance = 1e-10;
  const eigen_pair ref = aerohopf::inverse_power(sys.jacobian(w0, mu), shift, po);

  distributed_wing d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  distributed_wing::jacobian_rows a, p;
  d.jacobians(d.local_part(w0), mu, a, p);
  distributed_inverse_power_options o;
  o.power = po;
  const eigen_pair ep = distributed::inverse_power(d, a, &p, shift, o);
  EXPECT_LT(std::abs(ep.lambda - ref.lambda), 1e-9 * std::abs(ref.lambda)) << ep.lambda << " vs " << ref.lambda;
  EXPECT_LT(ep.lambda.real(), 0.0);  // below the flutter point: damped
  const vec<cd> x = d.all_gather(ep.vector);
  EXPECT_LT((x - ref.vector).norm(), 1e-6);
  EXPECT_GT(x.tail(8).norm(), 1e-3);  // the structure takes part (the unit vector is mostly flow)
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: wing lambda " << ep.lambda << " in " << ep.iterations << " iterations, "
              << ep.linear_iterations << " GMRES iterations (serial sparse LU: " << ref.lambda << ")\n";
}

// The static aeroelastic equilibrium at 1 deg incidence, mu = 0.075 (the wing bends and twists
// under its lift), from the steady flow about the wing at rest: Newton-GMRES on the ranks
// against the serial Newton-Krylov solve, both with full steps (the first step raises ||f|| a
// hundredfold, which a monotone line search refuses) to ||f|| <= 1e-10 (the rounding floor of
// this grid's residual is about 2e-11); one Newton step only: not converged, the reason on every
// rank.
TEST(mpi_wing, static_equilibrium_equals_the_serial_one) {
  const models::wing_system sys = cut_wing(1.0);
  const double mu = 0.075;
  const vec<double> rest = sys.steady_equilibrium({}, INFINITY);  // the flow loads the wing
  const auto ref = solve_equilibrium_krylov<5>(sys, mu, rest, full_steps());
  ASSERT_TRUE(ref.report.converged);
  distributed_wing d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  const distributed_equilibrium_result r = solve_equilibrium(d, d.local_part(rest), mu);
  ASSERT_TRUE(r.converged) << r.reason;
  const vec<double> w = d.all_gather(r.w);
  EXPECT_LT((w - ref.w).norm(), 1e-8 * ref.w.norm());
  const vec<double> a = w.segment(sys.flow_size(), 4), a_ref = ref.w.segment(sys.flow_size(), 4);
  EXPECT_GT(a.cwiseAbs().maxCoeff(), 1e-6);  // a static deflection
  EXPECT_LT((a - a_ref).cwiseAbs().maxCoeff(), 1e-8 * a_ref.cwiseAbs().maxCoeff());
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: static modal deflection " << a.transpose() << " (serial " << a_ref.transpose()
              << "), " << r.iterations << " Newton, " << r.linear_iterations << " GMRES\n";
  distributed_equilibrium_options one;
  one.max_iterations = 1;
  const distributed_equilibrium_result q = solve_equilibrium(d, d.local_part(rest), mu, one);
  EXPECT_FALSE(q.converged);
  EXPECT_TRUE(test::contains(q.reason, "no convergence in 1 Newton iterations")) << q.reason;
}

// The flutter point near the experiment's density at M = 0.5 (mu = rho c^3 = 0.075, omega 0.4):
// the distributed Hopf Newton (GMRES, block-Jacobi BILU, the border eliminated) from the serial
// inverse-power start, against the serial Krylov Hopf solve; at 1 deg incidence the full system
// (unknowns w too) from the static equilibrium at the start's mu.
TEST(mpi_wing, flutter_point_equals_the_serial_one_in_both_formulations) {
  for (const bool fixed : {true, false}) {
    SCOPED_TRACE(fixed ? "fixed equilibrium" : "full system");
    const models::wing_system sys = cut_wing(fixed ? 0.0 : 1.0);
    vec<double> w = sys.steady_equilibrium({}, fixed ? 1e-8 : INFINITY);
    if (!fixed) w = solve_equilibrium_krylov<5>(sys, 0.075, w, full_steps()).w;
    const hopf_point start = hopf_start(sys, w, 0.075, 0.4);
    hopf_options ho;
    ho.fixed_equilibrium = fixed;
    ho.newton.abs_tolerance = 1e-10;
    hopf_krylov_options ko;
    ko.full_system = !fixed;
    const hopf_result ref = solve_hopf_krylov<5>(sys, start, ho, ko);
    ASSERT_TRUE(ref.report.converged) << ref.report.reason;

    distributed_wing d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
    distributed_hopf_options o;
    o.hopf = ho;
    const distributed_hopf_point guess{d.local_part(start.w), start.mu, start.omega, d.local_part(start.p)};
    const distributed_hopf_result r = distributed::solve_hopf(d, guess, o);
    ASSERT_TRUE(r.report.converged) << r.report.reason;
    EXPECT_NEAR(r.point.mu, ref.point.mu, 1e-8 * ref.point.mu);
    EXPECT_NEAR(r.point.omega, ref.point.omega, 1e-8 * ref.point.omega);
    if (!fixed) {  // the static deflection at mu*
      const vec<double> wd = d.all_gather(r.point.w);
      EXPECT_LT((wd - ref.point.w).norm(), 1e-7 * ref.point.w.norm());
      EXPECT_GT(wd.segment(sys.flow_size(), 4).cwiseAbs().maxCoeff(), 1e-6);
    }
    if (d.rank() == 0)
      std::cout << world_size() << " ranks, " << (fixed ? "fixed" : "full") << ": mu* " << r.point.mu << " omega* "
                << r.point.omega << " (serial " << ref.point.mu << ", " << ref.point.omega << "), "
                << r.report.iterations << " Newton, " << r.linear_iterations << " GMRES\n";
  }
}

TEST(mpi_wing, bad_input_is_refused_on_every_rank) {
  const models::wing_system sys = cut_wing(0.0);
  distributed_wing d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  const vec<double> local = d.local_part(sys.free_stream_state());
  const int last = world_size() - 1;
  const vec<double> bad = d.rank() == last ? vec<double>(local.head(local.size() - 1)) : local;
  const std::string msg = test::input_error_of([&] { (void)d.residual(bad, 0.075); });
  EXPECT_TRUE(test::contains(msg, d.rank() == last ? "this rank's flow values" : "refused on rank")) << msg;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)d.residual(local, NAN); }), "mu nan is not finite"));
  EXPECT_EQ(d.residual(local, 0.075).size(), local.size());  // and the ranks carry on
}

AEROHOPF_MPI_TEST_MAIN();
