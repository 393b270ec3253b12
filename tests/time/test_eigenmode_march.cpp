// march_eigenmode (time/eigenmode_march.hpp): on the Hopf normal form in a skewed basis, whose
// critical pair is mu +- i in closed form, the BDF2 growth rate of a small perturbation along
// the eigenvector (from a dense eigen-decomposition) is mu below and above the Hopf point, and
// exactly BDF2's discrete rate of the mode (closed form) at coarse steps; bad input is refused.
#include <aerohopf/models/hopf_normal_form.hpp>
#include <aerohopf/time/eigenmode_march.hpp>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <complex>
#include <numbers>

#include "support/error_messages.hpp"

using namespace aerohopf;

namespace {

/// The eigenpair of the normal form's Jacobian at w = 0 with Im lambda close to +1 (dense).
eigen_pair critical_pair(const hopf_normal_form& m, double mu) {
  Eigen::ComplexEigenSolver<Eigen::MatrixXcd> es(m.jacobian(vec<double>::Zero(m.size()), mu).cast<std::complex<double>>());
  Eigen::Index k = 0;
  (es.eigenvalues().array() - std::complex<double>(mu, 1.0)).abs().minCoeff(&k);
  eigen_pair ep;
  ep.lambda = es.eigenvalues()[k];
  ep.vector = es.eigenvectors().col(k).normalized();
  return ep;
}

/// The coordinate where the eigenvector is largest.
Eigen::Index largest_component(const eigen_pair& ep) {
  Eigen::Index k = 0;
  ep.vector.cwiseAbs().maxCoeff(&k);
  return k;
}

TEST(EigenmodeMarch, GrowthRateIsTheRealPartBelowAndAboveTheHopfPoint) {
  const hopf_normal_form m(1.0, 3, 5);
  for (double mu : {-0.04, 0.03}) {
    const eigen_pair ep = critical_pair(m, mu);
    ASSERT_NEAR(ep.lambda.real(), mu, 1e-12);
    ASSERT_NEAR(ep.lambda.imag(), 1.0, 1e-12);
    eigenmode_march_options o;
    o.coordinate = largest_component(ep);
    o.amplitude = 1e-4;  // the cubic term changes the rate by ~amplitude^2
    o.cycles = 6;
    const vec<double> w_eq = vec<double>::Zero(m.size());
    const vec<double> w_before = w_eq;
    const auto r = march_eigenmode(m, mu, w_eq, ep, o);
    EXPECT_EQ(w_eq, w_before);
    EXPECT_NEAR(r.dt, 2 * std::numbers::pi / 72, 1e-14);
    EXPECT_EQ(r.steps, 6 * 72);
    EXPECT_EQ(r.t.size(), r.y.size());
    EXPECT_NEAR(r.y.front(), 1e-4, 1e-18);
    EXPECT_GE(r.peaks, 8);
    EXPECT_NEAR(r.growth_rate, r.bdf2_rate, 1.5e-4) << "mu = " << mu;  // the peak fit: 6e-5, 9e-5
    EXPECT_NEAR(r.growth_rate, mu, 5e-4) << "mu = " << mu;  // BDF2 at 72 steps: 1.4e-4, 3.9e-4
    EXPECT_EQ(r.growth_rate > 0, mu > 0);
  }
}

/// BDF2's own rate of the mode e^{lambda t} at step h, Re(log z) / h with z the principal root of
/// (3 - 2 h lambda) z^2 - 4 z + 1 = 0, by the quadratic formula in long double.
double bdf2_rate(std::complex<double> lambda, double h) {
  using cl = std::complex<long double>;
  const cl a = 3.0L - 2.0L * static_cast<long double>(h) * cl(lambda.real(), lambda.imag());
  const cl d = std::sqrt(cl(16.0L) - 4.0L * a);
  const cl z1 = (4.0L + d) / (2.0L * a), z2 = (4.0L - d) / (2.0L * a);
  return static_cast<double>(std::log(std::abs(std::abs(z1) >= std::abs(z2) ? z1 : z2)) / h);
}

// The marched rate is BDF2's discrete rate of the linear mode, not Re(lambda): at 18 and 36
// steps per period BDF2 damps the mode by 6.2e-3 and 6.6e-4 (lambda = -0.02 + i), and the march
// reproduces both to the peak fit's error; the result reports the same discrete rate.
TEST(EigenmodeMarch, RateIsBdf2sDiscreteRateOfTheMode) {
  const hopf_normal_form m(1.0, 2, 3);
  const double mu = -0.02;
  const eigen_pair ep = critical_pair(m, mu);
  eigenmode_march_options o;
  o.coordinate = largest_component(ep);
  o.amplitude = 1e-5;
  o.cycles = 8;
  o.bdf2.inner_residual_drop = 0;  // converged inner iterations: only the time step's error
  o.bdf2.inner_tolerance = 1e-13;
  for (int steps : {18, 36}) {
    o.steps_per_period = steps;
    const auto r = march_eigenmode(m, mu, vec<double>::Zero(m.size()), ep, o);
    const double expected = bdf2_rate(ep.lambda, 2 * std::numbers::pi / steps);
    EXPECT_NEAR(r.bdf2_rate, expected, 1e-12);
    EXPECT_NEAR(r.growth_rate, expected, 5e-5) << steps << " steps per period";
    EXPECT_GT(std::abs(expected - mu), steps == 18 ? 6e-3 : 6e-4);  // the damping is real
  }
}

TEST(EigenmodeMarch, BadInputIsRefused) {
  const hopf_normal_form m(1.0, 2, 3);
  const eigen_pair ep = critical_pair(m, -0.02);
  const vec<double> w = vec<double>::Zero(m.size());
  eigenmode_march_options o;
  o.coordinate = largest_component(ep);
  auto msg = [&](auto f) { return test::input_error_of(f); };
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, vec<double>::Zero(2), ep, o); }), "equilibrium has 2"));
  eigenmode_march_options bad = o;
  bad.coordinate = m.size();
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, ep, bad); }), "coordinate 4 outside"));
  eigen_pair real = ep;
  real.lambda = {-0.5, 0.0};
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, real, o); }), "not a finite complex pair"));
  eigen_pair zero = ep;
  zero.vector[o.coordinate] = 0;
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, zero, o); }), "is zero or not finite"));
  bad = o;
  bad.skip_cycles = bad.cycles;
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, ep, bad); }), "skip_cycles < cycles"));
  bad = o;
  bad.amplitude = -1;
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, ep, bad); }), "amplitude must be positive"));
  bad = o;
  bad.steps_per_period = 4;
  EXPECT_TRUE(test::contains(msg([&] { march_eigenmode(m, -0.02, w, ep, bad); }), "steps_per_period"));
}

}  // namespace
