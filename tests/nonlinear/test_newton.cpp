// The Newton family on the tubular reactor (below the first fold, where the equilibrium is
// unique) and on a small closed-form problem: convergence orders, agreement of all solvers,
// failure reports.
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear.hpp>

#include <gtest/gtest.h>

using namespace aerohopf;

namespace {
/// f(w) = (w0^2 + w1^2 - 4 mu, w0 - w1): root (sqrt(2 mu), sqrt(2 mu)) for mu > 0.
struct circle {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 2; }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    vec<T> f(2);
    f[0] = w[0] * w[0] + w[1] * w[1] - T(4.0) * mu;
    f[1] = w[0] - w[1];
    return f;
  }
  Eigen::MatrixXd jacobian(const vec<double>& w, double) const {
    Eigen::MatrixXd a(2, 2);
    a << 2 * w[0], 2 * w[1], 1, -1;
    return a;
  }
};

/// A function with no real root: Newton must fail with a convergence_error, never return.
struct no_root {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 1; }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    vec<T> f(1);
    f[0] = w[0] * w[0] + T(1.0) + mu;
    return f;
  }
  Eigen::MatrixXd jacobian(const vec<double>& w, double) const { return Eigen::MatrixXd::Constant(1, 1, 2 * w[0]); }
};
}  // namespace

TEST(newton, QuadraticConvergenceOnClosedForm) {
  circle c;
  const auto r = newton(c, vec<double>::Constant(2, 3.0), 2.0);
  ASSERT_TRUE(r.report.converged);
  EXPECT_NEAR(r.x[0], 2.0, 1e-12);
  EXPECT_NEAR(r.x[1], 2.0, 1e-12);
  // error e_{k+1} ~ C e_k^2: the ratios r_{k+1}/r_k^2 stay bounded while r_k -> 0
  const auto& h = r.report.residual_history;
  ASSERT_GE(h.size(), 4u);
  for (size_t k = 1; k + 1 < h.size(); ++k) {
    if (h[k] < 1e-2 && h[k + 1] > 1e-14) {
      EXPECT_LT(h[k + 1] / (h[k] * h[k]), 10.0);
    }
  }
}

TEST(newton, AllSolversAgreeOnReactor) {
  tubular_reactor r(32);
  const double mu = 0.1;
  newton_options o;
  o.abs_tolerance = 1e-11;
  o.max_iterations = 200;
  const auto exact = newton(r, r.rest_state(), mu, o);
  const auto chord = newton_chord(r, r.rest_state(), mu, o);
  const auto ptc = pseudo_transient_newton(r, r.rest_state(), mu, o, {1.0, 1e12, 1.0});
  const auto bro = broyden(r, r.rest_state(), mu, o);
  for (const auto* x : {&chord, &ptc, &bro}) {
    ASSERT_TRUE(x->report.converged);
    EXPECT_LT((x->x - exact.x).norm(), 1e-9);
  }
  // orders: Newton needs fewer iterations than Broyden, Broyden fewer than chord (linear)
  EXPECT_LE(exact.report.iterations, 5);
  EXPECT_LT(exact.report.iterations, bro.report.iterations);
  EXPECT_LT(bro.report.iterations, chord.report.iterations + 1);
  // chord convergence is linear: consecutive residual ratios roughly constant and < 1
  const auto& h = chord.report.residual_history;
  ASSERT_GE(h.size(), 5u);
  const double q1 = h[3] / h[2], q2 = h[4] / h[3];
  EXPECT_LT(q1, 1.0);
  EXPECT_NEAR(q2 / q1, 1.0, 0.5);
}

TEST(newton, ReportsFailureClearly) {
  no_root f;
  newton_options o;
  o.max_iterations = 30;
  try {
    newton(f, vec<double>::Constant(1, 0.5), 0.0, o);
    FAIL() << "expected a convergence_error";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("newton"), std::string::npos);
  }
  o.throw_on_failure = false;
  const auto r = newton(f, vec<double>::Constant(1, 0.5), 0.0, o);
  EXPECT_FALSE(r.report.converged);
  EXPECT_FALSE(r.report.reason.empty());
}

TEST(newton, RejectsNonFiniteStateWithoutTouchingIt) {
  tubular_reactor r(8);
  vec<double> w = r.rest_state();
  w[5] = NAN;
  const vec<double> copy = w;
  try {
    newton(r, w, 0.1);
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("entry 5"), std::string::npos);
  }
  EXPECT_TRUE(std::isnan(w[5]));
  EXPECT_EQ(w.head(5), copy.head(5));
  EXPECT_THROW(newton(r, vec<double>::Ones(3), 0.1), input_error);
}

// The contraction (monotonicity) test: off by default; when set, an iteration whose residual
// ratio exceeds max_contraction fails at once, naming the iterate, and a contracting iteration
// is not affected.
TEST(newton, ContractionTestStopsANonContractingIterationEarly) {
  // f = w^2 + 1 has no real root; Newton is w <- (w - 1/w)/2 (chaotic). From w = 0.5 the
  // residuals are 1.25, 1.5625 (k = 1, not tested: contraction_from = 2), 1.085, 3.46 (k = 3).
  no_root f;
  newton_options o;
  o.max_iterations = 30;
  o.throw_on_failure = false;
  const auto plain = newton(f, vec<double>::Constant(1, 0.5), 0.0, o);
  EXPECT_FALSE(plain.report.converged);
  EXPECT_EQ(plain.report.iterations, 30);
  o.max_contraction = 1.0;
  const auto r = newton(f, vec<double>::Constant(1, 0.5), 0.0, o);
  EXPECT_FALSE(r.report.converged);
  EXPECT_EQ(r.report.iterations, 3);
  EXPECT_NE(r.report.reason.find("not contracting at iterate 3"), std::string::npos) << r.report.reason;
  const auto& h = r.report.residual_history;
  ASSERT_EQ(h.size(), 4u);
  EXPECT_GT(h[1], h[0]);  // the first step may raise ||F||
  EXPECT_GT(h[3], h[2]);
  o.throw_on_failure = true;
  EXPECT_THROW(newton(f, vec<double>::Constant(1, 0.5), 0.0, o), convergence_error);
  o.max_contraction = 0.0;
  EXPECT_THROW(newton(f, vec<double>::Constant(1, 0.5), 0.0, o), input_error);
}

TEST(newton, ContractionTestLeavesContractingIterationsAlone) {
  // quadratic: the residual ratios fall with ||F||, so a strict bound does not bite
  circle c;
  newton_options o;
  o.max_contraction = 0.5;
  const auto q = newton(c, vec<double>::Constant(2, 3.0), 2.0, o);
  ASSERT_TRUE(q.report.converged) << q.report.reason;
  EXPECT_NEAR(q.x[0], 2.0, 1e-12);
  // linear (chord): the rate q is measured without the test; a bound above it leaves the
  // iteration unchanged, a bound below it stops it at the first tested iterate
  tubular_reactor r(32);
  newton_options base;
  base.abs_tolerance = 1e-11;
  base.max_iterations = 200;
  const auto chord = newton_chord(r, r.rest_state(), 0.1, base);
  ASSERT_TRUE(chord.report.converged);
  const auto& h = chord.report.residual_history;
  double worst = 0;
  for (size_t k = 2; k < h.size(); ++k) worst = std::max(worst, h[k] / h[k - 1]);
  ASSERT_LT(worst, 1.0);
  newton_options loose = base;
  loose.max_contraction = std::min(1.0, 1.5 * worst);
  const auto same = newton_chord(r, r.rest_state(), 0.1, loose);
  ASSERT_TRUE(same.report.converged);
  EXPECT_EQ(same.report.iterations, chord.report.iterations);
  EXPECT_EQ((same.x - chord.x).norm(), 0.0);
  newton_options tight = base;
  tight.max_contraction = 0.5 * (h[2] / h[1]);
  tight.throw_on_failure = false;
  const auto stopped = newton_chord(r, r.rest_state(), 0.1, tight);
  EXPECT_FALSE(stopped.report.converged);
  EXPECT_EQ(stopped.report.iterations, 2);
  EXPECT_NE(stopped.report.reason.find("not contracting at iterate 2"), std::string::npos) << stopped.report.reason;
}
