// The coupled aeroelastic wing (models/wing.hpp) on a tiny AGARD 445.6 C-H grid (16 x 4 x 6
// cells) with four plate modes: every Jacobian against exact directional derivatives
// (check_jacobian) at rest and on a moved grid; A_mu against differences of A in mu; the
// generalised forces of a heave and a pitch "mode" against the flow model's own force and
// moment integration; a uniform flow on the moving grid is kept off the wall and loads no mode;
// bad input refused; and the flutter point: the Krylov Hopf solver and the direct one agree, and
// the dense spectrum of the coupled Jacobian crosses the imaginary axis there, all other
// eigenvalues stable.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/models/wing.hpp>
#include <aerohopf/nonlinear/check_jacobian.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include "support/dense_spectrum.hpp"
#include "support/tiny_wing_system.hpp"
#include "support/wing_cases.hpp"

#include <cmath>
#include <complex>
#include <iostream>
#include <numbers>
#include <random>

using namespace aerohopf;
using models::wing_system;

namespace {
using test_support::agard;
using test_support::agard_plate_modes;
using test_support::tiny_wing;
using test_support::tiny_wing_grid;
using test_support::tiny_wing_motion;
using test_support::tiny_wing_options;
const vec<double>& rest_equilibrium() {
  static const vec<double> w = tiny_wing().steady_equilibrium();
  return w;
}
/// Two synthetic modes at the plate nodes: heave t3 = 1 and pitch t3 = -(x - x0) (nose up).
structure::modal_data heave_and_pitch(double x0) {
  const structure::modal_data& p = agard_plate_modes();
  structure::modal_data d;
  d.point_ids = p.point_ids;
  d.points = p.points;
  d.omega.resize(2);
  d.omega << 60, 240;
  d.generalised_mass = Eigen::VectorXd::Ones(2);
  for (int k = 0; k < 2; ++k) {
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d.size()), 6);
    for (std::size_t i = 0; i < d.size(); ++i) s(static_cast<Eigen::Index>(i), 2) = k == 0 ? 1.0 : -(d.points[i].x() - x0);
    d.shapes.push_back(s);
  }
  return d;
}
}  // namespace

static_assert(aeroelastic_system<wing_system>);
static_assert(bordered_system<wing_system> && has_exact_bordered_jacobian<wing_system>);
static_assert(block_system_of<wing_system, 5>);

TEST(wing_system, jacobians_are_the_derivatives_of_the_residual_at_rest_and_on_a_moved_grid) {
  const wing_system s = tiny_wing(0.0, 0.02);
  const double mu = 0.075;
  vec<double> moved = rest_equilibrium();
  for (Eigen::Index i = 0; i < s.structure_size(); ++i) moved[s.flow_size() + i] = 0.002 * double(i % 3 - 1) + 0.001;
  for (const vec<double>* w : {&rest_equilibrium(), static_cast<const vec<double>*>(&moved)}) {
    const jacobian_check_report r = check_jacobian(s, *w, mu);
    std::cout << r;
    for (const auto* e : {&r.exact, &r.bordered_exact}) {
      ASSERT_TRUE(e->present) << e->name;
      EXPECT_LT(e->componentwise_error, 1e-11) << e->name;
      EXPECT_LT(e->relative_error, 1e-13) << e->name;
    }
    for (const auto* e : {&r.approximate, &r.bordered_approximate}) {
      ASSERT_TRUE(e->present) << e->name;
      EXPECT_GT(e->componentwise_error, 1e-3) << e->name;  // modified order: a different matrix
    }
    ASSERT_TRUE(r.d_mu.present);
    EXPECT_LT(r.d_mu.componentwise_error, 1e-13);
    // A is affine in mu, so central differences of it are exact up to rounding
    const Eigen::SparseMatrix<double> amu = s.jacobian_d_mu(*w, mu);
    const Eigen::SparseMatrix<double> fd = (s.jacobian(*w, mu + 0.01) - s.jacobian(*w, mu - 0.01)) / 0.02;
    EXPECT_LT((amu - fd).norm(), 1e-10 * fd.norm());
    EXPECT_GT(fd.norm(), 0.0);
  }
  // the flow does no work on the modes at rest (symmetric section, zero incidence)
  EXPECT_LT(s.generalised_forces<double>(rest_equilibrium()).cwiseAbs().maxCoeff(), 1e-10);
}

// The system on the tiny grid cut into 3 blocks (as for 3 ranks) is the whole grid's system with
// its cells reordered: residual, both Jacobians (products with a random vector) and the loads,
// on a moved grid.
TEST(wing_system, on_a_cut_grid_is_the_whole_grid_system_reordered) {
  const wing_system s = tiny_wing(0.0, 0.02);
  const auto cut = distributed::split_for_ranks(tiny_wing_grid(), 3);
  ASSERT_GE(cut.grid.points.blocks.size(), 3u);
  const wing_system c = models::split_wing_system(s, cut);
  ASSERT_EQ(c.size(), s.size());
  const double mu = 0.075;
  vec<double> w = rest_equilibrium();
  for (Eigen::Index i = 0; i < s.structure_size(); ++i) w[s.flow_size() + i] = 0.002 * double(i % 3 - 1) + 0.001;
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  for (Eigen::Index i = 0; i < s.flow_size(); ++i) w[i] *= 1.0 + 1e-3 * g(rng);  // the flow loads the wing
  vec<double> x(s.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = g(rng);
  // whole-grid vector -> the cut system's order
  const auto to_cut = [&](const vec<double>& v) { return flow::to_split_order(cut, v, 5); };
  EXPECT_EQ(flow::from_split_order(cut, to_cut(x), 5), x);
  EXPECT_EQ(to_cut(x).tail(s.structure_size()), x.tail(s.structure_size()));
  const auto expect_near = [](const vec<double>& a, const vec<double>& b, const char* what) {
    EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-12 * b.cwiseAbs().maxCoeff()) << what;
  };
  expect_near(c.residual<double>(to_cut(w), mu), to_cut(s.residual<double>(w, mu)), "residual");
  expect_near(c.generalised_forces<double>(to_cut(w)), s.generalised_forces<double>(w), "generalised forces");
  const auto js = s.bordered_jacobians(w, mu), jc = c.bordered_jacobians(to_cut(w), mu);
  vec<double> ys(s.size()), yc(s.size());
  js.exact.apply(x, ys);
  jc.exact.apply(to_cut(x), yc);
  expect_near(yc, to_cut(ys), "exact Jacobian");
  js.preconditioning.apply(x, ys);
  jc.preconditioning.apply(to_cut(x), yc);
  expect_near(yc, to_cut(ys), "modified-order Jacobian");
  // a cut that is not this grid's is refused
  auto bad = cut;
  bad.origin[1].offset[0] += 1;
  EXPECT_THROW(models::split_wing_system(s, bad), input_error);
  EXPECT_THROW(models::split_wing_system(c, cut), input_error);  // cut already
}

TEST(wing_system, generalised_forces_of_heave_and_pitch_are_the_lift_and_the_moment) {
  // At 2 degrees incidence. The shapes are splined to the wing exactly (the spline reproduces
  // linear fields) and hold root chords per unit coordinate (mesh_deformation.hpp): heave t3 = 1
  // does the work of the vertical force, the flow model's force integration (coefficients by
  // rho U^2 c^2 / 2); pitch t3 = -(x - x0) (x in metres: c times the grid's x) that of the
  // vertical forces' nose-up moment about x0, summed here from the model's wall faces (its wall
  // pressures, areas and face centres).
  const double c = agard().planform.root_chord, x0 = 0.25 * c;
  const wing_system s = tiny_wing(2.0, 0.0, heave_and_pitch(x0));
  flow::euler_model<3> f = s.flow();
  vec<double> wf = f.free_stream_vector();
  ASSERT_TRUE(flow::solve_steady<3>(f, wf, {}).converged);
  vec<double> w = s.free_stream_state();
  w.head(s.flow_size()) = wf;
  const vec<double> g = s.generalised_forces<double>(w);
  const flow::force_coefficients k = s.flow().forces(wf);
  const double pinf = s.flow().conditions().pressure();
  double moment = 0;
  for (const auto& face : s.flow().wall_faces(wf))
    moment += (face.pressure - pinf) * face.area_out[2] * -(c * face.centre[0] - x0);
  std::cout << "heave work " << g[0] << " vs F_z " << 0.5 * k.force[2] << "; pitch work " << g[1]
            << " vs moment of F_z " << moment << "\n";
  EXPECT_GT(k.force[2], 0.01);
  EXPECT_NEAR(g[0], 0.5 * k.force[2], 1e-12 * std::abs(k.force[2]));
  EXPECT_NEAR(g[1], moment, 1e-12 * std::abs(k.force[2]) * c);
  EXPECT_GT(std::abs(moment), 1e-4);
}

TEST(wing_system, uniform_flow_on_the_moving_grid_loads_no_mode) {
  const wing_system s = tiny_wing(0.0, 0.01);
  vec<double> w = s.free_stream_state();
  const Eigen::Index nf = s.flow_size(), m = s.modes();
  for (Eigen::Index i = 0; i < 2 * m; ++i) w[nf + i] = 0.003 * double(i + 1) * (i % 2 ? -1 : 1);
  const vec<double> r = s.residual(w, 0.1);
  // GCL: the moving grid keeps the uniform flow in every cell whose stencil does not reach the
  // wall's halo (j >= 2; the slip wall turns the flow, the far field keeps it)
  const auto cells = tiny_wing_grid().points.blocks[0].cells();
  double off_wall = 0, at_wall = 0;
  for (Eigen::Index c = 0; c < nf / wing_system::nv; ++c) {
    const double rc = r.segment(c * wing_system::nv, wing_system::nv).cwiseAbs().maxCoeff();
    if (flow::unravel<3>(static_cast<std::size_t>(c), cells)[1] >= 2) off_wall = std::max(off_wall, rc);
    else at_wall = std::max(at_wall, rc);
  }
  EXPECT_LT(off_wall, 1e-12);
  EXPECT_GT(at_wall, 1e-3);
  const auto& k = s.structure().reduced_frequency();
  const auto& z = s.structure().damping_ratio();
  for (Eigen::Index i = 0; i < m; ++i) {
    EXPECT_EQ(r[nf + i], w[nf + m + i]);
    EXPECT_NEAR(r[nf + m + i], -k[i] * k[i] * w[nf + i] - 2 * z[i] * k[i] * w[nf + m + i], 1e-12);
  }
}

TEST(wing_system, refuses_bad_input) {
  const double c = agard().planform.root_chord;
  const auto st = structure::modal_structure::from_physical(agard_plate_modes().omega, Eigen::VectorXd::Zero(4), c, 170);
  // no force tag: the symmetry plane would be loaded too
  EXPECT_THROW(wing_system(flow::euler_model<3>(tiny_wing_grid(), {.mach = 0.5}), tiny_wing_motion(agard_plate_modes()), st),
               input_error);
  // a tag that names no wall
  EXPECT_THROW(wing_system(flow::euler_model<3>(tiny_wing_grid(), {.mach = 0.5}, {.force_tag = "flap"}),
                           tiny_wing_motion(agard_plate_modes()), st),
               input_error);
  // three structural modes for a motion of four
  Eigen::VectorXd k3(3);
  k3 << 0.2, 0.8, 1.0;
  const auto three = structure::modal_structure(k3, Eigen::VectorXd::Zero(3));
  EXPECT_THROW(wing_system(flow::euler_model<3>(tiny_wing_grid(), {.mach = 0.5}, {.force_tag = "wing"}),
                           tiny_wing_motion(agard_plate_modes()), three),
               input_error);
  const wing_system s = tiny_wing();
  vec<double> w = rest_equilibrium();
  EXPECT_THROW(s.residual(vec<double>(w.head(w.size() - 1)), 0.1), input_error);
  w[s.flow_size() + 2] = NAN;
  try {
    s.residual(w, 0.1);
    ADD_FAILURE() << "a NaN modal coordinate was accepted";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("structural unknown 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(s.residual(rest_equilibrium(), double(NAN)), input_error);
  wing_system t = tiny_wing();
  EXPECT_THROW(t.set_structure(three), input_error);
  // a lifting flow is no equilibrium of the wing at rest
  EXPECT_THROW(tiny_wing(2.0).steady_equilibrium(), convergence_error);
}

TEST(wing_system, flutter_point_is_where_the_dense_spectrum_crosses_the_axis) {
  const wing_system s = tiny_wing();
  const vec<double>& w = rest_equilibrium();
  // start near the experiment's density at M = 0.5 (rho = 0.428 kg/m^3: mu = rho c^3 = 0.0746)
  const hopf_point start = hopf_start(s, w, 0.075, 0.4);
  hopf_options opt;
  opt.fixed_equilibrium = true;
  const hopf_result hk = solve_hopf_krylov<5>(s, start, opt);
  const hopf_result hd = solve_hopf(s, start, opt);
  ASSERT_TRUE(hk.report.converged);
  ASSERT_TRUE(hd.report.converged);
  const double mu = hk.point.mu, omega = hk.point.omega;
  std::cout << "flutter point: mu* = " << mu << " (rho = " << mu / std::pow(agard().planform.root_chord, 3)
            << " kg/m^3), omega* = " << omega << "; Krylov " << hk.report.iterations << " Newton / "
            << hk.linear_iterations << " GMRES iterations, direct " << hd.report.iterations << "\n";
  EXPECT_NEAR(hd.point.mu, mu, 1e-8 * mu);
  EXPECT_NEAR(hd.point.omega, omega, 1e-8);
  EXPECT_LE(hk.report.iterations, 5);
  // A p = i omega p at the point
  const Eigen::SparseMatrix<std::complex<double>> ac = s.jacobian(w, mu).cast<std::complex<double>>();
  const vec<std::complex<double>> p = hk.point.p;
  EXPECT_LT((ac * p - std::complex<double>(0, omega) * p).norm(), 1e-8 * p.norm());
  // the dense spectrum 2 % below and above: the critical pair crosses, everything else is stable
  auto near = [&](double at) { return test_support::eigenvalue_near(s.jacobian(w, at), {0.0, omega}); };
  const auto [below, other_below] = near(0.98 * mu);
  const auto [above, other_above] = near(1.02 * mu);
  std::cout << "critical eigenvalue at 0.98 mu*: " << below << ", at 1.02 mu*: " << above
            << "; largest other real part " << other_below << " / " << other_above << "\n";
  EXPECT_LT(below.real(), 0.0);
  EXPECT_GT(above.real(), 0.0);
  EXPECT_NEAR(below.imag(), omega, 0.02 * omega);
  EXPECT_NEAR(above.imag(), omega, 0.02 * omega);
  EXPECT_LT(other_below, 0.0);  // the first crossing: the wing is stable below it
  EXPECT_LT(other_above, 0.0);
}
