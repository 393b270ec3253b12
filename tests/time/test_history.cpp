// The measures of a sampled oscillation (time/history.hpp) against closed forms.
#include <aerohopf/time/history.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

using namespace aerohopf;

TEST(last_cycles, amplitude_and_period_of_a_settled_cosine) {
  // y = 0.3 + 0.02 cos(omega t + 0.4) + a transient decaying like e^{-t}, 40 samples per period
  const double omega = 0.7, period = 2 * std::numbers::pi / omega, dt = period / 40;
  std::vector<double> t, y;
  for (int k = 0; k <= 40 * 30; ++k) {
    t.push_back(k * dt);
    y.push_back(0.3 + 0.02 * std::cos(omega * k * dt + 0.4) + 0.05 * std::exp(-k * dt) * std::cos(3 * k * dt));
  }
  const cycle_measure m = last_cycles(t, y, 3);
  EXPECT_EQ(m.cycles, 3);
  EXPECT_NEAR(m.amplitude, 0.02, 0.02 * 1e-4);
  EXPECT_NEAR(m.period, period, period * 1e-5);
  // more cycles asked than the signal holds: what there is
  const std::vector<double> ts(t.begin(), t.begin() + 100), ys(y.begin(), y.begin() + 100);
  EXPECT_GE(last_cycles(ts, ys, 50).cycles, 1);
  EXPECT_LE(last_cycles(ts, ys, 50).cycles, 3);
  // too short: NaN, cycles 0
  const cycle_measure none = last_cycles({0.0, 1.0, 2.0}, {0.0, 1.0, 2.0}, 3);
  EXPECT_EQ(none.cycles, 0);
  EXPECT_TRUE(std::isnan(none.amplitude));
  EXPECT_THROW(last_cycles(t, y, 0), input_error);
  EXPECT_THROW(last_cycles({0.0, 1.0}, {1.0}, 1), input_error);
}

TEST(limit_cycle_from_envelopes, landau_cycle_amplitude_and_radial_exponent_from_both_sides) {
  // y = A(t) cos(omega t) with dA/dt = alpha A - beta A^3 (closed form): the stable cycle
  // A* = sqrt(alpha / beta), its radial exponent -2 alpha; runs from 0.9 and 1.1 A*, 10 periods
  const double alpha = 0.02, beta = 50.0, omega = 1.0, as = std::sqrt(alpha / beta), dt = 2 * std::numbers::pi / 80;
  std::vector<std::vector<amplitude_sample>> runs;
  for (double start : {0.9, 1.1}) {
    std::vector<double> t, y;
    const double a0 = start * as;
    for (int k = 0; k <= 80 * 10; ++k) {
      const double tk = k * dt;
      const double a = as / std::sqrt(1 + (as * as / (a0 * a0) - 1) * std::exp(-2 * alpha * tk));
      t.push_back(tk);
      y.push_back(a * std::cos(omega * tk));
    }
    runs.push_back(amplitude_envelope(t, y, 0.0));
  }
  const envelope_cycle c = limit_cycle_from_envelopes(runs);
  EXPECT_NEAR(c.amplitude / as, 1.0, 2e-3);
  EXPECT_NEAR(c.exponent / (-2 * alpha), 1.0, 0.03);
  EXPECT_TRUE(c.bracketed);
  EXPECT_GT(c.samples, 30);
  // an unstable cycle (alpha, beta < 0: runs leave it) has a positive exponent
  for (auto& run : runs)
    for (auto& e : run) e.growth_rate = -e.growth_rate;
  const envelope_cycle u = limit_cycle_from_envelopes(runs);
  EXPECT_NEAR(u.amplitude / as, 1.0, 2e-3);
  EXPECT_GT(u.exponent, 0.0);
  // too little to fit, or nothing that changes
  EXPECT_THROW(limit_cycle_from_envelopes({}), input_error);
  EXPECT_THROW(limit_cycle_from_envelopes({{{0.0, 1.0, 0.1}, {1.0, 1.0, 0.2}, {2.0, 1.0, 0.3}}}), input_error);
  EXPECT_THROW(limit_cycle_from_envelopes({{{0.0, 1.0, 0.1}, {1.0, 2.0, 0.1}, {2.0, 3.0, 0.1}}}), convergence_error);
}
