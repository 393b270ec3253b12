// Continuation: natural-parameter steps agree with pseudo-arclength; folds are passed and
// located where the dense Jacobian becomes singular (an independent check).
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/models/tubular_reactor.hpp>

#include <gtest/gtest.h>

using namespace aerohopf;

TEST(continuation, ArclengthPassesBothFoldsOfTheReactor) {
  const tubular_reactor r(16);
  continuation_options o;
  o.ds = 0.01;
  o.ds_max = 0.05;
  o.mu_max = 0.3;
  o.max_steps = 400;
  const auto res = pseudo_arclength_continuation(r, r.rest_state(), 0.0, o);
  std::vector<double> folds;
  for (const auto& b : res.bifurcations)
    if (b.kind == bifurcation_kind::fold) {
      folds.push_back(b.mu);
      // at a fold the Jacobian has a zero eigenvalue: smallest |lambda| << typical |lambda|
      double smallest = 1e300;
      for (auto l : dense_spectrum(r.jacobian(b.w, b.mu))) smallest = std::min(smallest, std::abs(l));
      EXPECT_LT(smallest, 1e-6);
      EXPECT_LT(r.residual(b.w, b.mu).norm(), 1e-9);
    }
  ASSERT_EQ(folds.size(), 2u);
  EXPECT_GT(folds[0], folds[1]);  // hysteresis: the branch turns back, then forward again
  EXPECT_GT(res.points.back().mu, 0.3);
}

TEST(continuation, NaturalAndArclengthAgreeBelowTheFold) {
  const tubular_reactor r(16);
  continuation_options o;
  o.ds = 0.01;
  o.max_steps = 15;
  const auto nat = natural_continuation(r, r.rest_state(), 0.0, o);
  ASSERT_EQ(nat.points.size(), 16u);
  const auto& last = nat.points.back();
  // the same equilibrium by pseudo-arclength: continue to mu = 0.15 and compare by Newton
  const auto n2 = newton(r, r.rest_state(), last.mu);
  EXPECT_LT((n2.x - last.w).norm(), 1e-9);
  // Hopf test function: gamma = max Re of the complex eigenvalues, negative below mu = 0.165
  EXPECT_LT(last.gamma, 0.0);
}

TEST(continuation, NaturalStepsReportTheFold) {
  const tubular_reactor r(16);
  continuation_options o;
  o.ds = 0.01;
  o.max_steps = 30;  // would cross the fold near mu = 0.18
  EXPECT_THROW(natural_continuation(r, r.rest_state(), 0.0, o), convergence_error);
}

// ---- broken promises and fault injection (reliability) ----
namespace {
/// The reactor with a residual that is NaN (entry 2) on call nan_from, and on every later call
/// while persistent. d_mu and the Jacobian come from the clean reactor.
struct faulty_reactor {
  using jacobian_type = tubular_reactor::jacobian_type;
  const tubular_reactor& r;
  int nan_from = -1;
  bool persistent = false;
  mutable int calls = 0;
  Eigen::Index size() const { return r.size(); }
  vec<double> residual(const vec<double>& w, double mu) const {
    const int c = ++calls;
    vec<double> f = r.residual(w, mu);
    if (c == nan_from || (persistent && nan_from > 0 && c > nan_from)) f[2] = NAN;
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return r.jacobian(w, mu); }
  vec<double> d_mu(const vec<double>& w, double mu) const { return r.d_mu(w, mu); }
};
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }
}  // namespace

// Natural continuation, NaN residual inside the Newton solve of one step: with
// throw_on_failure = false the points so far are returned (equal to the clean run's), the
// reason names the algorithm, the step, mu and what was non-finite; continuing from the last
// good point without the fault reaches the clean run's end point. Thrown: convergence_error.
TEST(continuation, NaturalNanResidualKeepsThePointsSoFarAndCanContinue) {
  const tubular_reactor r(16);
  continuation_options o;
  o.ds = 0.01;
  o.max_steps = 12;
  o.detect_hopf = false;
  const auto clean = natural_continuation(r, r.rest_state(), 0.0, o);
  ASSERT_EQ(clean.points.size(), 13u);
  faulty_reactor f{r};
  f.nan_from = 20;
  continuation_options soft = o;
  soft.throw_on_failure = false;
  const vec<double> w0 = r.rest_state(), w0_copy = w0;
  const auto res = natural_continuation(f, w0, 0.0, soft);
  EXPECT_EQ(w0, w0_copy);
  EXPECT_TRUE(res.failed);
  ASSERT_GE(res.points.size(), 2u);
  ASSERT_LT(res.points.size(), clean.points.size());
  const std::size_t k = res.points.size();  // the failed step
  EXPECT_TRUE(has(res.stop_reason, internal::concat("natural_continuation: step ", k, " at mu = ", clean.points[k].mu)))
      << res.stop_reason;
  EXPECT_TRUE(has(res.stop_reason, "residual not finite at iterate")) << res.stop_reason;
  for (std::size_t i = 0; i < k; ++i) EXPECT_EQ(res.points[i].w, clean.points[i].w);
  continuation_options rest = o;
  rest.max_steps = o.max_steps - int(k - 1);
  const auto resumed = natural_continuation(r, res.points.back().w, res.points.back().mu, rest);
  EXPECT_NEAR(resumed.points.back().mu, clean.points.back().mu, 1e-12);
  EXPECT_LT((resumed.points.back().w - clean.points.back().w).norm(), 1e-10);
  faulty_reactor g{r};
  g.nan_from = 20;
  try {
    natural_continuation(g, w0, 0.0, o);
    FAIL() << "expected convergence_error";
  } catch (const convergence_error& e) {
    EXPECT_EQ(std::string(e.what()), res.stop_reason);
  }
}

// Pseudo-arclength: one NaN residual makes one corrector fail (counted, the reason kept); the
// step is halved and the run finds the same folds. A residual NaN from some call on stops the
// run at the last good point, the reason naming the corrector failure; continuing from that
// point without the fault finds the clean run's folds.
TEST(continuation, ArclengthNanResidualIsRecordedAndTheRunCanContinue) {
  const tubular_reactor r(16);
  continuation_options o;
  o.ds = 0.01;
  o.ds_max = 0.05;
  o.mu_max = 0.3;
  o.max_steps = 400;
  o.detect_hopf = false;
  const auto clean = pseudo_arclength_continuation(r, r.rest_state(), 0.0, o);
  ASSERT_EQ(clean.bifurcations.size(), 2u);
  {
    faulty_reactor f{r};
    f.nan_from = 60;
    const auto res = pseudo_arclength_continuation(f, r.rest_state(), 0.0, o);
    EXPECT_EQ(res.corrector_failures, clean.corrector_failures + 1);
    EXPECT_TRUE(has(res.last_corrector_failure, "residual entry 2 is not finite")) << res.last_corrector_failure;
    EXPECT_TRUE(has(res.last_corrector_failure, "pseudo_arclength_continuation: corrector of step "))
        << res.last_corrector_failure;
    ASSERT_EQ(res.bifurcations.size(), 2u);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(res.bifurcations[i].mu, clean.bifurcations[i].mu, 1e-8);
  }
  faulty_reactor f{r};
  f.nan_from = 60;
  f.persistent = true;
  const vec<double> w0 = r.rest_state(), w0_copy = w0;
  const auto res = pseudo_arclength_continuation(f, w0, 0.0, o);
  EXPECT_EQ(w0, w0_copy);
  EXPECT_FALSE(res.failed);  // a normal stop: the step size fell below ds_min
  EXPECT_TRUE(has(res.stop_reason, "step size below ds_min")) << res.stop_reason;
  EXPECT_TRUE(has(res.stop_reason, "residual entry 2 is not finite")) << res.stop_reason;
  ASSERT_GE(res.points.size(), 2u);
  EXPECT_TRUE(res.bifurcations.empty());
  const branch_point& last = res.points.back();
  EXPECT_LT(r.residual(last.w, last.mu).norm(), 1e-9);
  const auto resumed = pseudo_arclength_continuation(r, last.w, last.mu, o);
  ASSERT_EQ(resumed.bifurcations.size(), 2u);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(resumed.bifurcations[i].mu, clean.bifurcations[i].mu, 1e-8);
}

// A singular bordered matrix at the start (a tangent that cannot be formed) ends the run: thrown
// as singular_matrix_error with the context, or returned with failed = true.
TEST(continuation, FailureOutsideACorrectorHonoursThrowOnFailure) {
  struct zero_system {  // f = 0 for all (w, mu): A = 0, f_mu = 0, the bordered matrix is singular
    using jacobian_type = Eigen::MatrixXd;
    Eigen::Index size() const { return 2; }
    vec<double> residual(const vec<double>& w, double) const { return vec<double>::Zero(w.size()); }
    Eigen::MatrixXd jacobian(const vec<double>&, double) const { return Eigen::MatrixXd::Zero(2, 2); }
    vec<double> d_mu(const vec<double>&, double) const { return vec<double>::Zero(2); }
  } z;
  continuation_options o;
  o.detect_hopf = false;
  try {
    pseudo_arclength_continuation(z, vec<double>::Zero(2), 0.5, o);
    FAIL() << "expected singular_matrix_error";
  } catch (const singular_matrix_error& e) {
    EXPECT_TRUE(has(e.what(), "pseudo_arclength_continuation: start at mu = 0.5")) << e.what();
  }
  o.throw_on_failure = false;
  const auto res = pseudo_arclength_continuation(z, vec<double>::Zero(2), 0.5, o);
  EXPECT_TRUE(res.failed);
  EXPECT_TRUE(has(res.stop_reason, "singular")) << res.stop_reason;
}

TEST(continuation, RejectsBadOptionsNamingThem) {
  const tubular_reactor r(8);
  auto refused = [&](continuation_options o, const char* name, bool natural) {
    try {
      if (natural) natural_continuation(r, r.rest_state(), 0.0, o);
      else pseudo_arclength_continuation(r, r.rest_state(), 0.0, o);
      ADD_FAILURE() << "expected input_error for " << name;
    } catch (const input_error& e) {
      EXPECT_TRUE(has(e.what(), name)) << e.what();
    }
  };
  continuation_options o;
  o.ds = NAN;
  refused(o, "continuation_options::ds", true);
  refused(o, "continuation_options::ds", false);
  o = {};
  o.corrector_tolerance = NAN;
  refused(o, "corrector_tolerance", true);
  refused(o, "corrector_tolerance", false);
  o = {};
  o.w_scale = 0;
  refused(o, "w_scale", false);
  o = {};
  o.corrector_iterations = 0;
  refused(o, "corrector_iterations", true);
  o = {};
  o.mu_min = 1;
  o.mu_max = 0;
  refused(o, "mu_min", false);
  vec<double> bad = r.rest_state();
  bad[3] = NAN;
  try {
    pseudo_arclength_continuation(r, bad, 0.0, {});
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_TRUE(has(e.what(), "state entry 3")) << e.what();
  }
}
