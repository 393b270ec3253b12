// The Newton family on the tubular reactor (below the first fold, where the equilibrium is
// unique) and on a small closed-form problem: convergence orders, agreement of all solvers,
// failure reports.
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear.hpp>

#include <gtest/gtest.h>
#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;

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

// ---- broken promises and fault injection (reliability) ----
namespace {
/// The tubular reactor with injected faults: the residual returns NaN in entry 3 on call
/// nan_call (1-based count of residual calls), throws on call throw_call, and the Jacobian is
/// the zero matrix on call zero_jacobian_call. -1: no fault.
struct faulty_reactor {
  using jacobian_type = tubular_reactor::jacobian_type;
  const tubular_reactor& r;
  int nan_call = -1, throw_call = -1, zero_jacobian_call = -1;
  mutable int calls = 0, jacobian_calls = 0;
  Eigen::Index size() const { return r.size(); }
  vec<double> residual(const vec<double>& w, double mu) const {
    ++calls;
    if (calls == throw_call) throw error("faulty_reactor: refused state");
    vec<double> f = r.residual(w, mu);
    if (calls == nan_call) f[3] = NAN;
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const {
    ++jacobian_calls;
    jacobian_type a = r.jacobian(w, mu);
    if (jacobian_calls == zero_jacobian_call) a *= 0.0;
    return a;
  }
};


newton_options reactor_options() {
  newton_options o;
  o.abs_tolerance = 1e-11;
  o.max_iterations = 50;
  return o;
}
}  // namespace

// A singular Jacobian inside a step (here at the step from iterate 1) honours
// throw_on_failure = false: a result, converged = false, naming the algorithm, the iterate,
// ||F|| there, mu and the LU's own message; x is iterate 1, from which the run continues to the
// uninjected answer. With throw_on_failure = true the same context is thrown as
// singular_matrix_error.
TEST(newton, SingularJacobianInAStepIsAFailedResultNamingTheIterate) {
  const tubular_reactor base(16);
  const double mu = 0.1;
  const newton_options o = reactor_options();
  const auto clean = newton(base, base.rest_state(), mu, o);
  ASSERT_TRUE(clean.report.converged);
  newton_options one = o;
  one.max_iterations = 1;
  one.throw_on_failure = false;
  const auto first = newton(base, base.rest_state(), mu, one);  // iterate 1 of the same run
  ASSERT_EQ(first.report.iterations, 1);

  faulty_reactor f{base};
  f.zero_jacobian_call = 2;
  newton_options soft = o;
  soft.throw_on_failure = false;
  const vec<double> w0 = base.rest_state(), w0_copy = w0;
  const auto r = newton(f, w0, mu, soft);
  EXPECT_FALSE(r.report.converged);
  EXPECT_EQ(r.report.failed_iteration, 2);
  const std::string& why = r.report.reason;
  EXPECT_TRUE(contains(why, "newton (equilibrium, mu = 0.1)")) << why;
  EXPECT_TRUE(contains(why, "step 2 from iterate 1")) << why;
  EXPECT_TRUE(contains(why, internal::concat("||F|| = ", first.report.final_residual()))) << why;
  EXPECT_TRUE(contains(why, "newton: Jacobian: sparse LU failed")) << why;
  EXPECT_EQ(w0, w0_copy);
  EXPECT_EQ(r.x, first.x);
  ASSERT_EQ(r.report.residual_history.size(), 2u);
  const auto resumed = newton(base, r.x, mu, o);
  ASSERT_TRUE(resumed.report.converged);
  EXPECT_LT((resumed.x - clean.x).norm(), 1e-12);

  faulty_reactor g{base};
  g.zero_jacobian_call = 2;
  try {
    newton(g, w0, mu, o);
    FAIL() << "expected singular_matrix_error";
  } catch (const singular_matrix_error& e) {
    EXPECT_TRUE(contains(e.what(), "step 2 from iterate 1")) << e.what();
    EXPECT_TRUE(contains(e.what(), "mu = 0.1")) << e.what();
    EXPECT_TRUE(contains(e.what(), "newton: Jacobian")) << e.what();
  }
  // the chord and Broyden factor their first matrix inside step 1: reported the same way
  faulty_reactor h{base};
  h.zero_jacobian_call = 1;
  const auto c = newton_chord(h, w0, mu, soft);
  EXPECT_FALSE(c.report.converged);
  EXPECT_TRUE(contains(c.report.reason, "step 1 from iterate 0")) << c.report.reason;
  EXPECT_EQ(c.x, w0);
}

// Any exception raised inside a step (a model refusing a state) is reported the same way and
// keeps its type when thrown.
TEST(newton, ExceptionFromTheResidualInsideAStepKeepsItsTypeAndGetsContext) {
  const tubular_reactor base(16);
  faulty_reactor f{base};
  f.throw_call = 3;  // the trial point of step 2
  newton_options soft = reactor_options();
  soft.throw_on_failure = false;
  const auto r = newton(f, base.rest_state(), 0.1, soft);
  EXPECT_FALSE(r.report.converged);
  EXPECT_TRUE(contains(r.report.reason, "step 2 from iterate 1")) << r.report.reason;
  EXPECT_TRUE(contains(r.report.reason, "faulty_reactor: refused state")) << r.report.reason;
  EXPECT_TRUE(r.x.allFinite());
  faulty_reactor g{base};
  g.throw_call = 3;
  try {
    newton(g, base.rest_state(), 0.1, reactor_options());
    FAIL() << "expected an error";
  } catch (const convergence_error&) {
    FAIL() << "the type of the original error must be kept";
  } catch (const error& e) {
    EXPECT_TRUE(contains(e.what(), "step 2 from iterate 1")) << e.what();
    EXPECT_TRUE(contains(e.what(), "refused state")) << e.what();
  }
}

// Fault injection: the residual is NaN at the trial point of step k. The report names the
// algorithm, the iterate, ||F|| and mu; the caller's start is untouched; x is the last good
// iterate, from which the run continues (fault removed) to the uninjected answer.
TEST(newton, NanResidualAtIterateKLeavesTheLastGoodIterate) {
  const tubular_reactor base(16);
  const double mu = 0.12;
  const newton_options o = reactor_options();
  const auto clean = newton(base, base.rest_state(), mu, o);
  ASSERT_TRUE(clean.report.converged);
  ASSERT_GE(clean.report.iterations, 3);
  for (int k : {1, 2, 3}) {
    faulty_reactor f{base};
    f.nan_call = k + 1;  // call 1 is the initial residual, call k + 1 the trial point of step k
    newton_options soft = o;
    soft.throw_on_failure = false;
    const vec<double> w0 = base.rest_state(), w0_copy = w0;
    const auto r = newton(f, w0, mu, soft);
    EXPECT_EQ(w0, w0_copy);
    EXPECT_FALSE(r.report.converged);
    EXPECT_EQ(r.report.failed_iteration, k);
    const std::string& why = r.report.reason;
    EXPECT_TRUE(contains(why, "newton (equilibrium, mu = 0.12)")) << why;
    EXPECT_TRUE(contains(why, internal::concat("residual not finite at iterate ", k))) << why;
    EXPECT_TRUE(contains(why, internal::concat("iterate ", k - 1, " (||F|| = ", clean.report.residual_history[k - 1])))
        << why;
    ASSERT_TRUE(r.x.allFinite());
    EXPECT_NEAR(r.report.final_residual(), clean.report.residual_history[k - 1], 0.0);
    const auto resumed = newton(base, r.x, mu, o);
    ASSERT_TRUE(resumed.report.converged);
    EXPECT_LT((resumed.x - clean.x).norm(), 1e-12) << "k = " << k;
    // thrown: the same context
    faulty_reactor g{base};
    g.nan_call = k + 1;
    try {
      newton(g, w0, mu, o);
      FAIL() << "expected convergence_error";
    } catch (const convergence_error& e) {
      EXPECT_EQ(std::string(e.what()), why);
    }
  }
}

// Options are validated at the entry point: a clear input_error naming the option, instead of
// an iteration that burns its budget (NaN tolerance, zero relaxation).
TEST(newton, RejectsBadOptionsNamingThem) {
  circle c;
  const vec<double> w0 = vec<double>::Constant(2, 3.0);
  auto expect_refused = [&](newton_options o, const char* name) {
    try {
      newton(c, w0, 2.0, o);
      ADD_FAILURE() << "expected input_error for " << name;
    } catch (const input_error& e) {
      EXPECT_TRUE(contains(e.what(), name)) << e.what();
    }
    o.throw_on_failure = false;  // refused even when failures are to be returned
    EXPECT_THROW(newton_chord(c, w0, 2.0, o), input_error) << name;
  };
  newton_options o;
  o.relaxation = 0;
  expect_refused(o, "relaxation");
  o.relaxation = -0.5;
  expect_refused(o, "relaxation");
  o.relaxation = 1.5;
  expect_refused(o, "relaxation");
  o = {};
  o.abs_tolerance = NAN;
  expect_refused(o, "abs_tolerance");
  o = {};
  o.rel_tolerance = NAN;
  expect_refused(o, "rel_tolerance");
  o = {};
  o.abs_tolerance = 0;
  expect_refused(o, "abs_tolerance");
  o = {};
  o.step_tolerance = NAN;
  expect_refused(o, "step_tolerance");
  o = {};
  o.max_iterations = -1;
  expect_refused(o, "max_iterations");
  o = {};
  o.divergence_factor = NAN;
  expect_refused(o, "divergence_factor");
  o = {};
  o.relax_until = NAN;
  expect_refused(o, "relax_until");
  o = {};
  o.contraction_from = 0;
  expect_refused(o, "contraction_from");
  pseudo_transient_options p;
  p.dt0 = 0;
  EXPECT_THROW(pseudo_transient_newton(c, w0, 2.0, {}, p), input_error);
  p = {};
  p.ser_exponent = NAN;
  EXPECT_THROW(pseudo_transient_newton(c, w0, 2.0, {}, p), input_error);
  // the engine itself: NaN start named by entry, before the residual is evaluated
  int calls = 0;
  vec<double> bad = w0;
  bad[1] = NAN;
  try {
    newton_iterate([&](const vec<double>& x) { ++calls; return x; },
                   [](const vec<double>&, const vec<double>& f, int) { return vec<double>(-f); }, bad, {}, "engine");
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_TRUE(contains(e.what(), "initial iterate entry 1")) << e.what();
  }
  EXPECT_EQ(calls, 0);
}

// f(x) = sqrt(x) - 1/2 on x >= 0, the model refusing x < 0 (as the Euler residual refuses a
// negative density). From x0 = 2 the full Newton step lands at x = -0.586: the line search must
// halve past the refused point (to x = 0.707, ||f|| 0.34 < 0.91) and converge to the root 1/4;
// without it the refusal is the failure, in the model's words.
TEST(Newton, LineSearchHalvesPastATrialPointTheModelRefuses) {
  auto residual = [](const vec<double>& x) {
    if (x[0] < 0) throw input_error("model: negative density at x = " + std::to_string(x[0]));
    vec<double> f(1);
    f[0] = std::sqrt(x[0]) - 0.5;
    return f;
  };
  auto step = [](const vec<double>& x, const vec<double>& f, int) {
    vec<double> dx(1);
    dx[0] = -f[0] * 2.0 * std::sqrt(x[0]);
    return dx;
  };
  vec<double> x0(1);
  x0[0] = 2.0;
  newton_options o;
  o.abs_tolerance = 1e-13;
  o.line_search = true;
  const newton_result r = newton_iterate(residual, step, x0, o, "sqrt");
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  EXPECT_NEAR(r.x[0], 0.25, 1e-12);
  EXPECT_EQ(x0[0], 2.0);

  o.line_search = false;
  o.throw_on_failure = false;
  const newton_result f = newton_iterate(residual, step, x0, o, "sqrt");
  EXPECT_FALSE(f.report.converged);
  EXPECT_NE(f.report.reason.find("negative density"), std::string::npos) << f.report.reason;
  EXPECT_EQ(f.x[0], 2.0);  // the last good iterate
}
