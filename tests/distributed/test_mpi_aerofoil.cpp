// The pitch-plunge aerofoil on MPI ranks (distributed/mpi_aerofoil.hpp), run by CTest under mpirun
// on 2 and 3 ranks. Reference: the serial aerofoil_system on the same coarse C-grid. Checked at a
// perturbed flow with the section displaced and moving (the grid moved and with grid speeds):
// the gathered residual equals the serial one (flow rows bitwise, the structural rates to
// rounding: their loads are summed in another order); the bordered Jacobian in the ranks' rows,
// exact and modified-order, applied to a vector equals the serial bordered Jacobian's product;
// the structural part counts once in a sum over the ranks; also at the section at rest (the
// rest grid); the eigenvalue of a structural mode by inverse power on the ranks equals the serial
// sparse-LU inverse power's, and its root locus over Ubar the serial root_locus's; a bad local
// size, a NaN entry or a NaN Ubar is refused on every rank; the static aeroelastic equilibrium at
// a mean incidence by Newton-GMRES on the ranks equals the serial one.
#include <gtest/gtest.h>
#include <mpi.h>

#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/distributed/mpi_aerofoil.hpp>
#include <aerohopf/distributed/mpi_steady.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <complex>
#include <functional>
#include <numbers>
#include <vector>

#include <iostream>
#include <string>

#include "support/error_messages.hpp"
#include "support/mpi_test.hpp"
#include "support/partition_grids.hpp"

using namespace aerohopf;
using namespace aerohopf::distributed;
using aerohopf::test::world_size;

namespace {

models::aerofoil_system make_system() {
  return models::aerofoil_system(flow::euler_model<2>(test::partition_cgrid(), {.mach = 0.8, .alpha_rad = 0.0}),
                                 structure::pitch_plunge{});
}

void check_at(const models::aerofoil_system& sys, distributed_aerofoil& d, const Eigen::Vector4d& ws, double ubar) {
  vec<double> w(sys.size());
  w.head(sys.flow_size()) = test::perturbed_free_stream(sys.flow(), 3u);
  w.tail(4) = ws;
  const vec<double> local = d.local_part(w);
  EXPECT_EQ(d.all_gather(local), w);

  const vec<double> r_serial = sys.residual(w, ubar);
  const vec<double> r = d.all_gather(d.residual(local, ubar));
  EXPECT_EQ(r.head(sys.flow_size()), r_serial.head(sys.flow_size())) << "flow rows";
  EXPECT_LT((r.tail(4) - r_serial.tail(4)).cwiseAbs().maxCoeff(), 1e-13 * r_serial.tail(4).cwiseAbs().maxCoeff());

  vec<double> x(sys.size());
  x.head(sys.flow_size()) = test::perturbed_free_stream(sys.flow(), 9u) - sys.flow().free_stream_vector();
  x.tail(4) << 0.3, -0.2, 0.5, 0.1;
  const auto pair = sys.bordered_jacobians(w, ubar);
  for (const auto kind : {flow::jacobian_kind::exact, flow::jacobian_kind::modified_order}) {
    const auto& serial = kind == flow::jacobian_kind::exact ? pair.exact : pair.preconditioning;
    vec<double> ref(sys.size());
    serial.apply(x, ref);
    distributed_aerofoil::jacobian_rows j;
    d.jacobian(local, ubar, kind, j);
    const vec<double> y = d.all_gather(d.multiply(j, d.local_part(x)));
    const double scale = ref.cwiseAbs().maxCoeff();
    EXPECT_LT((y.head(sys.flow_size()) - ref.head(sys.flow_size())).cwiseAbs().maxCoeff(), 1e-13 * scale);
    EXPECT_LT((y.tail(4) - ref.tail(4)).cwiseAbs().maxCoeff(), 1e-13 * ref.tail(4).cwiseAbs().maxCoeff())
        << "structural rows";
    EXPECT_EQ(j.structure, serial.structure());
  }
  // both kinds at once (the border computed once) equal the single-kind assemblies
  distributed_aerofoil::jacobian_rows e1, p1, p2;
  d.jacobians(local, ubar, e1, p1);
  d.jacobian(local, ubar, flow::jacobian_kind::modified_order, p2);
  EXPECT_EQ(p1.flow.values(), p2.flow.values());
  EXPECT_EQ(p1.flow_structure, p2.flow_structure);
  EXPECT_EQ(p1.structure_flow, p2.structure_flow);
  EXPECT_EQ(p1.structure, p2.structure);
  // the structure counts once in a sum over the ranks
  const vec<double> lx = d.local_part(x);
  double s = lx.squaredNorm();
  MPI_Allreduce(MPI_IN_PLACE, &s, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_NEAR(s, x.squaredNorm(), 1e-13 * x.squaredNorm());
}

}  // namespace

TEST(mpi_aerofoil, residual_and_bordered_jacobian_equal_the_serial_ones) {
  const models::aerofoil_system sys = make_system();
  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  check_at(sys, d, Eigen::Vector4d(0.01, 0.02, 0.03, -0.01), 4.5);  // displaced and moving
  check_at(sys, d, Eigen::Vector4d::Zero(), 4.5);                    // at rest: the rest grid
  check_at(sys, d, Eigen::Vector4d(-0.02, 0.0, -0.01, 0.005), 3.0);  // moved again
  if (d.rank() == 0) std::cout << world_size() << " ranks: aeroelastic residual and Jacobian rows checked\n";
}

// The aeroelastic eigenvalue near 0.13 + 0.35i at Ubar = 3 (a structural mode, |x_s| = 0.13 of
// the unit eigenvector, on this very coarse grid) by inverse power on the ranks (GMRES with the
// block-Jacobi BILU and the border eliminated) against the serial inverse power with the sparse
// LU of the whole Jacobian.
TEST(mpi_aerofoil, inverse_power_equals_the_serial_sparse_lu_iteration) {
  using cd = std::complex<double>;
  const models::aerofoil_system sys = make_system();
  const vec<double> w0 = sys.steady_equilibrium();
  const double ubar = 3.0;
  const cd shift(0.13, 0.35);
  inverse_power_options po;
  po.tolerance = 1e-10;
  const eigen_pair ref = aerohopf::inverse_power(sys.jacobian(w0, ubar), shift, po);

  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  const vec<double> local = d.local_part(w0);
  distributed_aerofoil::jacobian_rows a, p;
  d.jacobians(local, ubar, a, p);
  distributed_inverse_power_options o;
  o.power = po;
  const eigen_pair ep = distributed::inverse_power(d, a, &p, shift, o);
  EXPECT_LT(std::abs(ep.lambda - ref.lambda), 1e-10 * std::abs(ref.lambda)) << ep.lambda << " vs " << ref.lambda;
  const vec<double> xr = d.all_gather(vec<double>(ep.vector.real())), xi = d.all_gather(vec<double>(ep.vector.imag()));
  vec<cd> x(xr.size());
  x.real() = xr;
  x.imag() = xi;
  EXPECT_LT((x - ref.vector).norm(), 1e-7);
  EXPECT_GT(x.tail(4).norm(), 0.1);  // a structural mode
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: aeroelastic lambda " << ep.lambda << " in " << ep.iterations << " iterations, "
              << ep.linear_iterations << " GMRES iterations (serial sparse LU: " << ref.lambda << ", " << ref.iterations
              << " iterations)\n";
}

// The root locus of that mode from Ubar = 3 down to 2.7 on the ranks, its equilibrium (the
// steady flow with the section at rest) by the steady solve on the ranks, against the serial
// root_locus (sparse LU) on the serial equilibrium.
TEST(mpi_aerofoil, root_locus_equals_the_serial_one) {
  using cd = std::complex<double>;
  const models::aerofoil_system sys = make_system();
  const vec<double> w0 = sys.steady_equilibrium();
  const std::vector<double> ubars{3.0, 2.9, 2.8, 2.7};
  inverse_power_options po;
  po.tolerance = 1e-10;
  const auto ref = aerohopf::root_locus(sys, std::function<vec<double>(double)>([&](double) { return w0; }), ubars,
                                        cd(0.13, 0.35), po);
  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  // the equilibrium by the steady solve on the ranks (the flow with the section at rest; the
  // same partition, so the same local order as d's flow part)
  flow::euler_model<2> fm = sys.flow();
  distributed_euler<2> de(fm, partition_blocks(fm, world_size()), MPI_COMM_WORLD);
  distributed_euler_discretisation<2> disc(fm, de);
  vec<double> wf = de.local_part(fm.free_stream_vector());
  ASSERT_TRUE(flow::solve_steady(disc, wf, {}).converged);
  vec<double> local = vec<double>::Zero(d.local_size());
  local.head(d.flow_size()) = wf;
  EXPECT_LT((d.all_gather(local) - w0).cwiseAbs().maxCoeff(), 1e-9 * w0.cwiseAbs().maxCoeff());
  distributed_inverse_power_options o;
  o.power = po;
  const auto locus = distributed::root_locus(d, [&](double) { return local; }, ubars, cd(0.13, 0.35), o);
  ASSERT_EQ(locus.size(), ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    EXPECT_EQ(locus[k].mu, ref[k].mu);
    EXPECT_LT(std::abs(locus[k].lambda - ref[k].lambda), 1e-8 * std::abs(ref[k].lambda))
        << "Ubar " << ref[k].mu << ": " << locus[k].lambda << " vs " << ref[k].lambda;
    if (d.rank() == 0)
      std::cout << world_size() << " ranks: Ubar " << ref[k].mu << "  lambda " << locus[k].lambda << " (serial "
                << ref[k].lambda << "), " << locus[k].iterations << " iterations\n";
  }
  // a NaN Ubar is refused before any point is computed, on every rank
  EXPECT_THROW(distributed::root_locus(d, [&](double) { return local; }, {3.0, NAN}, cd(0.13, 0.35), o), input_error);
}

// The static aeroelastic equilibrium at a mean incidence of 1 deg (very coarse NACA 0012, M = 0.5,
// light case, Ubar = 1.7) by Newton-GMRES on the ranks from the loaded steady flow about the
// section at rest, against the serial family's static_equilibrium (solve_equilibrium_krylov);
// too few iterations: a result not converged with the reason on every rank.
TEST(mpi_aerofoil, static_equilibrium_equals_the_serial_one) {
  structure::pitch_plunge_parameters pp;
  pp.mu_s = 10;
  const models::aerofoil_family f(flow::naca_cgrid(), pp, {}, std::numbers::pi / 180);
  const models::aerofoil_system sys = f.system(8, 0.5);
  const vec<double> ref = f.static_equilibrium(sys, 1.7);
  const vec<double> rest = sys.steady_equilibrium({}, INFINITY);  // the flow loads the section
  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  const distributed_equilibrium_result r = solve_equilibrium(d, d.local_part(rest), 1.7);
  ASSERT_TRUE(r.converged) << r.reason;
  EXPECT_LE(r.residual, 1e-10);
  const vec<double> w = d.all_gather(r.w);
  EXPECT_LT((w - ref).norm(), 1e-8 * ref.norm());
  const double pitch = w[w.size() - 2];
  EXPECT_GT(pitch, 1e-4);  // a nose-up static deflection
  EXPECT_NEAR(pitch, ref[ref.size() - 2], 1e-9);
  EXPECT_GT(r.linear_iterations, 0);
  if (d.rank() == 0)
    std::cout << world_size() << " ranks: static pitch " << pitch << " rad (serial " << ref[ref.size() - 2] << "), "
              << r.iterations << " Newton, " << r.linear_iterations << " GMRES\n";
  distributed_equilibrium_options one;
  one.max_iterations = 1;
  const distributed_equilibrium_result q = solve_equilibrium(d, d.local_part(rest), 1.7, one);
  EXPECT_FALSE(q.converged);
  EXPECT_TRUE(test::contains(q.reason, "no convergence in 1 Newton iterations")) << q.reason;
  EXPECT_EQ(q.iterations, 1);
  one.fill_level = -1;
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)solve_equilibrium(d, d.local_part(rest), 1.7, one); }),
                             "fill_level"));
}

TEST(mpi_aerofoil, bad_input_is_refused_on_every_rank) {
  const models::aerofoil_system sys = make_system();
  distributed_aerofoil d(sys, partition_blocks(sys.flow(), world_size()), MPI_COMM_WORLD);
  const vec<double> local = d.local_part(sys.free_stream_state());
  const int last = world_size() - 1;
  const vec<double> bad = d.rank() == last ? vec<double>(local.head(local.size() - 1)) : local;
  const std::string msg = test::input_error_of([&] { (void)d.residual(bad, 4.0); });
  EXPECT_TRUE(test::contains(msg, d.rank() == last ? "this rank's flow values" : "refused on rank")) << msg;
  // a NaN Ubar, and a NaN state entry on rank 0 only
  EXPECT_THROW((void)d.residual(local, NAN), input_error);
  vec<double> nan_state = local;
  if (d.rank() == 0) nan_state[1] = NAN;
  EXPECT_THROW((void)d.residual(nan_state, 4.0), input_error);
  EXPECT_EQ(d.residual(local, 4.0).size(), local.size());  // and the ranks carry on
}

AEROHOPF_MPI_TEST_MAIN();
