// Pitch-plunge structure (spec 05): in-vacuo eigenvalues of the 4x4 first-order form against the
// closed-form roots of the 2x2 mass-stiffness problem det(K2 - omega^2 M2) = 0, the analytic
// dK/dUbar against finite differences, the sign conventions (lift raises h, nose-up moment
// raises alpha) and input validation.
#include <gtest/gtest.h>

#include <aerohopf/structure/pitch_plunge.hpp>
#include <aerohopf/error.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::structure;

namespace {
// omega^2 roots of (r^2/2 - x^2/2) s^2 - (a r^2/2 + b) s + a b = 0, a = 4 wR^2/U^2, b = 2 r^2/U^2:
// the determinant of [a - s, -s x/2; -s x, b - s r^2/2].
std::vector<double> closed_form_frequencies(const pitch_plunge_parameters& p, double ubar) {
  const double a = 4 * p.w_r * p.w_r / (ubar * ubar), b = 2 * p.r_a * p.r_a / (ubar * ubar);
  const double qa = 0.5 * (p.r_a * p.r_a - p.x_a * p.x_a), qb = -(a * p.r_a * p.r_a / 2 + b), qc = a * b;
  const double disc = std::sqrt(qb * qb - 4 * qa * qc);
  return {std::sqrt((-qb - disc) / (2 * qa)), std::sqrt((-qb + disc) / (2 * qa))};
}
}  // namespace

TEST(pitch_plunge, in_vacuo_eigenvalues_match_closed_form) {
  for (double mu_s : {10.0, 100.0})
    for (double ubar : {0.5, 2.0, 4.0}) {
      pitch_plunge_parameters p;
      p.mu_s = mu_s;
      const pitch_plunge s(p);
      Eigen::EigenSolver<Eigen::Matrix4d> es(s.in_vacuo_matrix(ubar));
      std::vector<double> im;
      for (int i = 0; i < 4; ++i) {
        EXPECT_NEAR(es.eigenvalues()[i].real(), 0.0, 1e-12);  // no structural damping
        if (es.eigenvalues()[i].imag() > 0) im.push_back(es.eigenvalues()[i].imag());
      }
      ASSERT_EQ(im.size(), 2u);
      std::sort(im.begin(), im.end());
      const auto ref = closed_form_frequencies(p, ubar);
      EXPECT_NEAR(im[0], ref[0], 1e-12 * ref[1]);
      EXPECT_NEAR(im[1], ref[1], 1e-12 * ref[1]);
      // uncoupled limit sanity: omega_alpha = 2/Ubar in units of U/c, so the ratio of the
      // frequencies brackets w_R (coupling separates them)
      EXPECT_LT(im[0] * ubar / 2, p.w_r);
      EXPECT_GT(im[1] * ubar / 2, 1.0);
    }
}

TEST(pitch_plunge, uncoupled_frequencies_without_unbalance) {
  pitch_plunge_parameters p;
  p.x_a = 0.0;
  const pitch_plunge s(p);
  const double ubar = 3.0;
  Eigen::EigenSolver<Eigen::Matrix4d> es(s.in_vacuo_matrix(ubar));
  std::vector<double> im;
  for (int i = 0; i < 4; ++i)
    if (es.eigenvalues()[i].imag() > 0) im.push_back(es.eigenvalues()[i].imag());
  std::sort(im.begin(), im.end());
  // omega_h = w_R omega_a, omega_a = U/b / Ubar = 2/Ubar in units of U/c
  EXPECT_NEAR(im[0], 2 * p.w_r / ubar, 1e-13);
  EXPECT_NEAR(im[1], 2.0 / ubar, 1e-13);
}

TEST(pitch_plunge, stiffness_derivative_matches_finite_difference) {
  const pitch_plunge s;
  const double u = 1.7, h = 1e-5;
  const Eigen::Matrix4d fd = (s.stiffness_matrix<double>(u + h) - s.stiffness_matrix<double>(u - h)) / (2 * h);
  EXPECT_LT((fd - s.stiffness_d_ubar(u)).norm(), 1e-8 * fd.norm());
}

TEST(pitch_plunge, sign_conventions) {
  pitch_plunge_parameters p;
  p.x_a = 0.0;  // decouple inertia so each load drives one coordinate
  const pitch_plunge s(p);
  const Eigen::Vector4d zero = Eigen::Vector4d::Zero();
  const double pi = 3.14159265358979323846;
  // positive lift accelerates h upwards: h'' = 2 Cl / (pi mu_s)
  auto r = s.rate<double>(zero, 1.0, 0.0, 2.0);
  EXPECT_NEAR(r[1], 2.0 / (pi * p.mu_s), 1e-15);
  EXPECT_EQ(r[3], 0.0);
  // positive (nose-up) moment accelerates alpha nose-up: alpha'' = 4 Cm / (pi mu_s) / (r_a^2/2)
  r = s.rate<double>(zero, 0.0, 1.0, 2.0);
  EXPECT_NEAR(r[3], 8.0 / (pi * p.mu_s * p.r_a * p.r_a), 1e-14);
  EXPECT_EQ(r[1], 0.0);
  // kinematics: dh/dt = h', dalpha/dt = alpha'; springs restore (positive h -> negative h'')
  Eigen::Vector4d w(0.1, 0.2, 0.3, 0.4);
  r = s.rate<double>(w, 0.0, 0.0, 2.0);
  EXPECT_EQ(r[0], 0.2);
  EXPECT_EQ(r[2], 0.4);
  EXPECT_LT(r[1], 0.0);
  EXPECT_LT(r[3], 0.0);
  // with the test unbalance (x_a = -0.2: c.g. aft of the elastic axis) a lift pushing the
  // elastic axis up leaves the c.g. behind, so the nose pitches up: row 4 of M gives
  // x_a h'' + r_a^2/2 alpha'' = 0, alpha'' = -2 x_a h'' / r_a^2 > 0
  const pitch_plunge t;
  r = t.rate<double>(zero, 1.0, 0.0, 2.0);
  EXPECT_GT(r[1], 0.0);
  EXPECT_GT(r[3], 0.0);
  EXPECT_NEAR(r[3], -2 * (-0.2) * r[1] / (0.539 * 0.539), 1e-15);
}

TEST(pitch_plunge, rejects_bad_parameters) {
  pitch_plunge_parameters p;
  p.mu_s = -1;
  EXPECT_THROW(pitch_plunge{p}, input_error);
  p = {};
  p.x_a = 0.6;  // r_a^2 < x_a^2: mass matrix indefinite
  EXPECT_THROW(pitch_plunge{p}, input_error);
  EXPECT_THROW(pitch_plunge{}.stiffness_d_ubar(0.0), input_error);
}

TEST(pitch_plunge, refuses_zero_or_non_finite_ubar_in_every_stiffness_entry_point) {
  const pitch_plunge s;
  EXPECT_TRUE(s.in_vacuo_matrix(2.0).allFinite());  // valid
  // K has 1/Ubar^2: Ubar = 0 used to give an infinite matrix without a word
  EXPECT_THROW(s.in_vacuo_matrix(0.0), input_error);
  EXPECT_THROW(s.in_vacuo_matrix(std::nan("")), input_error);
  EXPECT_THROW(s.stiffness_matrix<double>(0.0), input_error);
  EXPECT_THROW(s.stiffness_matrix<double>(INFINITY), input_error);
  const Eigen::Vector4d ws(0.01, 0.0, 0.02, 0.0);
  EXPECT_THROW(s.rate<double>(ws, 0.1, 0.01, 0.0), input_error);
}
