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
