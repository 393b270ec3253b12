// The wing as a flutter_family (models/wing_family.hpp): the speed-of-sound schedule, the flutter
// numbers against the AGARD 445.6 experiment table of spec 06 (mass ratio and flutter speed
// index from density and speed), the levels and their transfers on a tiny C-H grid, refusals,
// and the library's flutter-boundary driver over three Mach numbers, its first point the Hopf
// point of a direct solve, its last the lowest imaginary-axis crossing (axis_crossings.hpp).
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/models/wing_family.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include "support/wing_cases.hpp"

#include <cmath>
#include <iostream>

using namespace aerohopf;
using models::wing_family;

namespace {
using test_support::agard;
using test_support::agard_plate_modes;
using test_support::tiny_wing_options;
/// Spec 06: M, density, speed, mass ratio, FSI, omega_f / omega_alpha.
constexpr double table[4][6] = {{0.499, 0.4278, 172.46, 33.465, 0.4459, 0.5353},
                                {0.678, 0.2082, 231.37, 68.753, 0.4174, 0.4722},
                                {0.901, 0.0995, 296.69, 143.920, 0.3700, 0.4225},
                                {0.960, 0.0634, 310.96, 225.820, 0.3095, 0.3673}};
models::speed_of_sound_schedule tunnel() {
  models::speed_of_sound_schedule s;
  for (const auto& r : table) {
    s.mach.push_back(r[0]);
    s.speed_of_sound.push_back(r[2] / r[0]);
  }
  return s;
}
}  // namespace

static_assert(flutter_family<wing_family>);

TEST(wing_family, speed_of_sound_schedule_interpolates_and_refuses_bad_points) {
  const auto s = tunnel();
  EXPECT_NO_THROW(s.validate("test"));
  for (const auto& r : table) EXPECT_NEAR(s.speed(r[0]), r[2], 1e-12 * r[2]);
  const double mid = 0.5 * (table[1][0] + table[2][0]);
  EXPECT_NEAR(s.at(mid), 0.5 * (table[1][2] / table[1][0] + table[2][2] / table[2][0]), 1e-12);
  EXPECT_EQ(s.at(0.3), table[0][2] / table[0][0]);  // constant beyond the ends
  EXPECT_EQ(s.at(1.2), table[3][2] / table[3][0]);
  auto bad = s;
  bad.mach[2] = bad.mach[1];
  EXPECT_THROW(bad.validate("test"), input_error);
  bad = s;
  bad.speed_of_sound.pop_back();
  EXPECT_THROW(bad.validate("test"), input_error);
  bad = s;
  bad.speed_of_sound[0] = NAN;
  EXPECT_THROW(bad.validate("test"), input_error);
}

TEST(wing_family, flutter_numbers_reproduce_the_experiment_table) {
  // the wing mass implied by the first row (mass ratio x density x frustum volume), then every
  // row's mass ratio, FSI and frequency ratio from its density and speed alone
  models::flutter_reference ref;
  ref.frustum_volume = models::flutter_reference::frustum_of(agard().planform);
  EXPECT_NEAR(ref.frustum_volume, 0.13035, 1e-4);
  ref.wing_mass = table[0][3] * table[0][1] * ref.frustum_volume;
  ref.semichord = 0.2794;
  ref.omega_alpha = 239.3;
  const double c = agard().planform.root_chord;
  for (const auto& r : table) {
    const double mu = r[1] * c * c * c;
    const double omega = r[5] * ref.omega_alpha * c / r[2];  // omega_f c / U
    const auto n = models::flutter_numbers::of(mu, omega, r[2], c, ref);
    EXPECT_NEAR(n.density, r[1], 1e-12);
    EXPECT_NEAR(n.mass_ratio, r[3], 2e-3 * r[3]) << "M = " << r[0];  // the table's 4-5 digits
    EXPECT_NEAR(n.fsi, r[4], 1.5e-3 * r[4]) << "M = " << r[0];
    EXPECT_NEAR(n.frequency_ratio, r[5], 1e-12);
    EXPECT_NEAR(n.dynamic_pressure, 0.5 * r[1] * r[2] * r[2], 1e-9);
  }
  EXPECT_THROW(models::flutter_numbers::of(-1e-3, 0.2, 300, c, ref), input_error);
}

TEST(wing_family, levels_systems_and_transfers) {
  const wing_family f(agard(), tiny_wing_options(), {2, 1}, agard_plate_modes(), Eigen::VectorXd::Constant(1, 0.005), tunnel());
  const models::wing_system fine = f.system(1, 0.9), coarse = f.system(2, 0.9);
  EXPECT_EQ(fine.flow_size(), 5 * 16 * 4 * 6);
  EXPECT_EQ(coarse.flow_size(), 5 * 8 * 2 * 3);
  EXPECT_EQ(fine.structure_size(), 8);
  const double u = f.sound().speed(0.9), c = agard().planform.root_chord;
  for (Eigen::Index i = 0; i < 4; ++i) {
    EXPECT_NEAR(fine.structure().reduced_frequency()[i], agard_plate_modes().omega[i] * c / u, 1e-12);
    EXPECT_EQ(fine.structure().damping_ratio()[i], 0.005);
  }
  EXPECT_TRUE(f.refines(2, 1));
  EXPECT_FALSE(f.refines(4, 2));
  EXPECT_EQ(f.coarser_level(1), std::optional<int>(2));
  EXPECT_FALSE(f.coarser_level(2).has_value());
  EXPECT_EQ(wing_family::level_name(4), "coarse");
  // a coarse eigenvector prolongs with its structural part kept
  vec<std::complex<double>> p = vec<std::complex<double>>::Random(coarse.size());
  const vec<std::complex<double>> q = f.prolong(fine, coarse, p);
  ASSERT_EQ(q.size(), fine.size());
  EXPECT_EQ((f.structure_part(q) - f.structure_part(p)).norm(), 0.0);
  EXPECT_EQ(f.stiffness_factor(0.03), 0.03);
  EXPECT_EQ(f.parameter_of_factor(0.03), 0.03);
  // refusals
  EXPECT_THROW(f.system(4, 0.9), input_error);  // no such level
  EXPECT_THROW(f.system(1, -0.9), input_error);
  EXPECT_THROW(wing_family(agard(), tiny_wing_options(), {3}, agard_plate_modes(), Eigen::VectorXd::Zero(1), tunnel()),
               input_error);
  EXPECT_THROW(wing_family(agard(), tiny_wing_options(), {1}, agard_plate_modes(), Eigen::VectorXd::Zero(3), tunnel()),
               input_error);
  EXPECT_THROW(wing_family(agard(), tiny_wing_options(), {1}, agard_plate_modes(), Eigen::VectorXd::Zero(1), {}), input_error);
}

TEST(wing_family, flutter_boundary_driver_runs_on_the_wing) {
  const wing_family f(agard(), tiny_wing_options(), {1}, agard_plate_modes(), Eigen::VectorXd::Zero(1), tunnel());
  flutter_boundary_options o = f.boundary_options();
  o.start_mu = 0.075;
  o.start_omega = 0.4;
  o.log = nullptr;
  o.check_crossings = true;  // affordable on this grid (sparse LUs of the flow block)
  const flutter_boundary b = trace_flutter_boundary(f, 1, {0.5, 0.55, 0.6}, nullptr, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_EQ(b.points.size(), 3u);
  // the last point is the lowest imaginary-axis crossing of A0 + mu B, B with flow columns
  ASSERT_FALSE(b.checks.empty());
  for (const auto& c : b.checks) {
    std::cout << "crossing check M = " << c.mach << " (" << c.what << "): " << c.crossings << " crossings, lowest mu "
              << c.lowest_mu << " omega " << c.lowest_omega << "\n";
    EXPECT_TRUE(c.pass) << c.what;
  }
  for (const auto& p : b.points)
    std::cout << "M = " << p.mach << ": mu* = " << p.mu << ", omega* = " << p.omega << " (" << p.newton_iterations
              << " Newton iterations)\n";
  // the first point is the direct (sparse LU) Hopf point of that Mach number's system
  const models::wing_system s = f.system(1, 0.5);
  const vec<double> w = f.equilibrium(s, 0.0);
  hopf_options ho;
  ho.fixed_equilibrium = true;
  const hopf_result h = solve_hopf(s, hopf_start(s, w, 0.075, 0.4), ho);
  ASSERT_TRUE(h.report.converged);
  EXPECT_NEAR(b.points[0].mu, h.point.mu, 1e-6 * h.point.mu);
  EXPECT_NEAR(b.points[0].omega, h.point.omega, 1e-6);
  // one mode all along (the structural parts continue each other)
  for (std::size_t k = 1; k < b.points.size(); ++k) EXPECT_GT(b.points[k].cosine, 0.9);
}

TEST(wing_family, log_secant_predicts_a_falling_boundary_without_crossing_zero) {
  // the density parameter falls steeply with Mach number: with the secant in log mu
  // (positive_parameter, the family's default) every listed Mach number is reached from the
  // previous point in one attempt; the linear secant's prediction at the last one is below the
  // log one's (here: the tiny grid's points, 0.5 -> 0.9)
  const wing_family f(agard(), tiny_wing_options(), {1}, agard_plate_modes(), Eigen::VectorXd::Zero(1), tunnel());
  flutter_boundary_options o = f.boundary_options();
  ASSERT_TRUE(o.positive_parameter);
  ASSERT_EQ(o.mu_min, 1e-4);
  o.start_mu = 0.075;
  o.start_omega = 0.4;
  o.log = nullptr;
  const flutter_boundary b = trace_flutter_boundary(f, 1, {0.5, 0.7, 0.9}, nullptr, o);
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_EQ(b.points.size(), 3u);
  for (const auto& a : b.attempts) EXPECT_EQ(a.outcome, "accepted") << "M = " << a.mach << ": " << a.outcome;
  EXPECT_EQ(b.attempts.size(), 3u);
  const auto& p = b.points;
  const double t = (p[2].mach - p[1].mach) / (p[1].mach - p[0].mach);
  const double linear = p[1].mu + t * (p[1].mu - p[0].mu), logarithmic = p[1].mu * std::pow(p[1].mu / p[0].mu, t);
  std::cout << "mu*: " << p[0].mu << ", " << p[1].mu << ", " << p[2].mu << "; predicted at M = 0.9: linear " << linear
            << ", log " << logarithmic << "\n";
  EXPECT_LT(std::abs(logarithmic - p[2].mu), std::abs(linear - p[2].mu));
}
