// Fixed-step RK4: fourth order (error ratio ~16 on halving dt) on closed-form ODEs (real
// vector, complex scalar, complex vector), step rounding onto t_end, histories, observer and
// the error paths.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "aerohopf/models/hopf_normal_form.hpp"
#include "aerohopf/time.hpp"

using namespace aerohopf;
using C = std::complex<double>;

TEST(RungeKutta, FourthOrderOnRealLinearOscillatorWithForcing) {
  // y1' = y2, y2' = -4 y1 + cos t: y1 = cos(2t)(1 - 1/3) + cos(t)/3 with y(0) = (1, 0).
  auto f = [](double t, const vec<double>& y) {
    vec<double> d(2);
    d << y[1], -4 * y[0] + std::cos(t);
    return d;
  };
  auto exact = [](double t) { return (2.0 / 3.0) * std::cos(2 * t) + std::cos(t) / 3.0; };
  vec<double> y0(2);
  y0 << 1, 0;
  double prev = 0;
  for (double dt : {0.02, 0.01, 0.005}) {
    const vec<double> y = integrate_rk4(f, y0, 0.0, 3.0, dt);
    const double err = std::abs(y[0] - exact(3.0));
    if (prev > 0) {
      EXPECT_NEAR(prev / err, 16.0, 1.0) << "dt = " << dt;
    }
    prev = err;
  }
  EXPECT_LT(prev, 1e-9);
}

TEST(RungeKutta, FourthOrderOnComplexScalarAndVector) {
  // z' = (-0.2 + 1.5 i) z + z^2 / (1 + |z|^2) is not closed form; use the Bernoulli equation
  // z' = a z - b z^2, z = a z0 e^{a t} / (a + b z0 (e^{a t} - 1)).
  const C a(-0.3, 2.0), b(0.5, 0.25), z0(0.4, 0.1);
  auto f = [&](double, const C& z) { return a * z - b * z * z; };
  auto exact = [&](double t) { const C e = std::exp(a * t); return a * z0 * e / (a + b * z0 * (e - 1.0)); };
  double e1 = std::abs(integrate_rk4(f, z0, 0.0, 2.0, 0.04) - exact(2.0));
  double e2 = std::abs(integrate_rk4(f, z0, 0.0, 2.0, 0.02) - exact(2.0));
  EXPECT_NEAR(e1 / e2, 16.0, 2.0);
  // Complex vector: decoupled copies of the same equation.
  auto fv = [&](double, const vec<C>& z) { return vec<C>(a * z - b * z.cwiseProduct(z)); };
  vec<C> zv = vec<C>::Constant(3, z0);
  const vec<C> r = integrate_rk4(fv, zv, 0.0, 2.0, 0.01);
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(r[i] - exact(2.0)), 1e-8);
}

TEST(RungeKutta, HistoryObserverAndStepRounding) {
  auto f = [](double, const double& y) { return -y; };
  // dt = 0.3 does not divide 1: 4 steps of 0.25 end exactly on t_end.
  const auto h = rk4_history(f, 1.0, 0.0, 1.0, 0.3);
  ASSERT_EQ(h.t.size(), 5u);
  EXPECT_DOUBLE_EQ(h.t.back(), 1.0);
  EXPECT_NEAR(h.y.back(), std::exp(-1.0), 1e-4);
  const auto h2 = rk4_history(f, 1.0, 0.0, 1.0, 0.01, 30);  // steps 0, 30, 60, 90, 100
  ASSERT_EQ(h2.t.size(), 5u);
  EXPECT_DOUBLE_EQ(h2.t[3], 0.9);
  int calls = 0;
  integrate_rk4(f, 1.0, 0.0, 1.0, 0.1, [&](long n, double t, const double&) {
    EXPECT_NEAR(t, 0.1 * double(n), 1e-14);
    ++calls;
  });
  EXPECT_EQ(calls, 11);
}

TEST(RungeKutta, SystemRhsMarchesNormalFormOntoItsCycle) {
  // x1^2 + x2^2 -> mu on the normal form (s = +1), from inside and from outside.
  const hopf_normal_form m(1.0, 2, 3);
  const double mu = 0.04;
  for (double r0 : {0.05, 0.4}) {
    vec<double> w0 = r0 * m.basis().col(0) / std::sqrt(2.0);
    const vec<double> w = integrate_rk4(system_rhs(m, mu), w0, 0.0, 400.0, 0.02);
    EXPECT_NEAR(m.centre_coordinates(w).squaredNorm(), mu, 1e-9) << "r0 = " << r0;
  }
}

TEST(RungeKutta, RejectsBadInputAndReportsBlowUp) {
  auto f = [](double, const double& y) { return y * y; };
  EXPECT_THROW(integrate_rk4(f, 1.0, 0.0, 1.0, 0.0), input_error);
  EXPECT_THROW(integrate_rk4(f, 1.0, 1.0, 0.0, 0.1), input_error);
  EXPECT_THROW(integrate_rk4(f, std::nan(""), 0.0, 1.0, 0.1), input_error);
  try {
    integrate_rk4(f, 1.0, 0.0, 5.0, 0.1);  // y = 1/(1 - t) blows up at t = 1
    FAIL() << "no exception";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("step"), std::string::npos);
  }
}

// ---- fault injection (reliability) ----
// A right-hand side that is NaN (entry 1) on call k: time_march_error names integrate_rk4, the
// step, the stage and the entry, carries the last good state (the clean run's state at that
// step); continuing from it without the fault ends on the clean run's answer. The caller's
// initial state is untouched. An exception from the right-hand side keeps its type and gets the
// step in front.
TEST(RungeKutta, NanRightHandSideStopsWithTheLastGoodState) {
  const hopf_normal_form m(1.0, 2, 3);
  const double mu = 0.04;
  const auto f = system_rhs(m, mu);
  const vec<double> y0 = 0.3 * m.basis().col(0), y0_copy = y0;
  std::vector<vec<double>> clean_states;
  const vec<double> clean = integrate_rk4(f, y0, 0.0, 20.0, 0.05, [&](long, double, const vec<double>& y) {
    clean_states.push_back(y);
  });
  int calls = 0;
  auto faulty = [&](double t, const vec<double>& y) {
    vec<double> d = f(t, y);
    if (++calls == 4 * 37 + 2) d[1] = NAN;  // stage k2 of step 38
    return d;
  };
  try {
    integrate_rk4(faulty, y0, 0.0, 20.0, 0.05);
    FAIL() << "expected time_march_error";
  } catch (const time_march_error<vec<double>>& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("integrate_rk4: solution not finite at step 38"), std::string::npos) << what;
    EXPECT_NE(what.find("stage k2 has a non-finite entry 1"), std::string::npos) << what;
    EXPECT_EQ(e.step, 37);
    EXPECT_NEAR(e.t, 37 * 0.05, 1e-12);
    EXPECT_EQ(e.state, clean_states[37]);
    EXPECT_EQ(y0, y0_copy);
    const vec<double> resumed = integrate_rk4(f, e.state, e.t, 20.0, e.dt);
    EXPECT_LT((resumed - clean).norm(), 1e-12);
  }
  auto throwing = [&](double t, const vec<double>& y) {
    if (t > 1.0) throw error("rhs: refused");
    return f(t, y);
  };
  try {
    integrate_rk4(throwing, y0, 0.0, 20.0, 0.05);
    FAIL() << "expected error";
  } catch (const convergence_error&) {
    FAIL() << "the type of the original error must be kept";
  } catch (const error& e) {
    EXPECT_NE(std::string(e.what()).find("integrate_rk4: step 21"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rhs: refused"), std::string::npos) << e.what();
  }
  vec<double> bad = y0;
  bad[2] = NAN;
  try {
    integrate_rk4(f, bad, 0.0, 1.0, 0.1);
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("initial state entry 2"), std::string::npos) << e.what();
  }
}
