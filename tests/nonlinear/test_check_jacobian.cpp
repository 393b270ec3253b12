// check_jacobian: the exact Jacobians of the tubular reactor, the Hopf normal form and the
// aerofoil (very coarse grid) pass at rounding level; the aerofoil's modified-order Jacobian is
// reported as different; one perturbed entry of the reactor Jacobian is found (row named) even
// where the norm-wise error hides it; the taylor fallback for residuals that do not take jets
// agrees with the jet reference; bad input is refused.
#include <gtest/gtest.h>

#include <aerohopf/models/hopf_normal_form.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear/check_jacobian.hpp>

#include <cmath>
#include <iostream>
#include <sstream>
#include <type_traits>

#include "support/aerofoil_cases.hpp"

using namespace aerohopf;

namespace {

vec<double> reactor_state(const tubular_reactor& r) {
  vec<double> w = r.rest_state();
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] += 0.3 * std::sin(0.7 * double(i)) + (i % 2 ? 0.2 : -0.1);
  return w;
}

// The reactor with entry (i, j) of its Jacobian changed by delta (a deliberately wrong Jacobian).
struct wrong_entry_reactor {
  using jacobian_type = Eigen::SparseMatrix<double>;
  tubular_reactor base;
  Eigen::Index i, j;
  double delta;
  Eigen::Index size() const { return base.size(); }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const { return base.residual(w, mu); }
  jacobian_type jacobian(const vec<double>& w, double mu) const {
    jacobian_type a = base.jacobian(w, mu);
    a.coeffRef(i, j) += delta;
    return a;
  }
};

// A residual that takes taylor<> but not jet<>: the reference falls back to taylor passes.
struct taylor_only_reactor {
  using jacobian_type = Eigen::SparseMatrix<double>;
  tubular_reactor base;
  Eigen::Index size() const { return base.size(); }
  template <class T>
    requires(std::is_same_v<T, double> || is_taylor_v<T>)
  vec<T> residual(const vec<T>& w, const T& mu) const { return base.residual(w, mu); }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return base.jacobian(w, mu); }
};

// A system whose Jacobian has the wrong size.
struct wrong_size_system {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 3; }
  template <class T>
  vec<T> residual(const vec<T>& w, const T&) const { return w; }
  jacobian_type jacobian(const vec<double>&, double) const { return Eigen::MatrixXd::Identity(2, 2); }
};

}  // namespace

static_assert(system_over<wrong_entry_reactor, jet<double, 4>>);
static_assert(!system_over<taylor_only_reactor, jet<double, 4>>);
static_assert(system_over<taylor_only_reactor, taylor<double, 1>>);
static_assert(has_block_jacobian_pair<models::aerofoil_system>);
static_assert(!has_block_jacobian_pair<tubular_reactor>);

TEST(check_jacobian, tubular_reactor_exact_jacobian_at_rounding_level) {
  const tubular_reactor r(40);
  const vec<double> w = reactor_state(r);
  const double mu = 0.12;
  const auto rep = check_jacobian(r, w, mu);
  std::cout << rep;
  EXPECT_EQ(rep.probes, 3);
  ASSERT_TRUE(rep.exact.present);
  EXPECT_GT(rep.exact.reference_norm, 1.0);
  EXPECT_LT(rep.exact.relative_error, 1e-14);
  EXPECT_LT(rep.exact.componentwise_error, 1e-14);
  EXPECT_FALSE(rep.approximate.present);  // the reactor has no approximate Jacobian
  EXPECT_FALSE(rep.block_exact.present);
  ASSERT_TRUE(rep.d_mu.present);
  EXPECT_LT(rep.d_mu.relative_error, 1e-15);
  // the same seed gives the same directions, hence the same report; more probes check more
  const auto again = check_jacobian(r, w, mu);
  EXPECT_EQ(again.exact.componentwise_error, rep.exact.componentwise_error);
  EXPECT_EQ(again.exact.relative_error, rep.exact.relative_error);
  const auto more = check_jacobian(r, w, mu, {.probes = 9, .seed = 5});
  EXPECT_EQ(more.probes, 9);
  EXPECT_LT(more.exact.componentwise_error, 1e-14);
}

TEST(check_jacobian, hopf_normal_form_dense_exact_jacobian) {
  const hopf_normal_form f(-1.0, 4, 3);
  vec<double> w(f.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = 0.4 - 0.15 * double(i);
  const auto rep = check_jacobian(f, w, 0.3, {.probes = 5});
  std::cout << rep;
  EXPECT_LT(rep.exact.relative_error, 1e-14);
  EXPECT_LT(rep.exact.componentwise_error, 1e-14);
  EXPECT_LT(rep.d_mu.relative_error, 1e-14);
}

// One entry off by 1e-6 of its size in a 160-unknown Jacobian: the norm-wise error is small,
// the componentwise one names the row.
TEST(check_jacobian, one_wrong_entry_is_found_and_located) {
  const tubular_reactor base(80);
  const vec<double> w = reactor_state(base);
  const double mu = 0.12;
  const Eigen::Index i = 101, j = 100;  // d f_Theta / d y of cell 50
  const double aij = base.jacobian(w, mu).coeff(i, j);
  ASSERT_GT(std::abs(aij), 1e-3);
  for (const double rel : {1e-6, 1e-2}) {
    const wrong_entry_reactor bad{base, i, j, rel * aij};
    const auto rep = check_jacobian(bad, w, mu);
    std::cout << "entry off by " << rel << ": " << rep.exact.relative_error << " norm-wise, "
              << rep.exact.componentwise_error << " componentwise at row " << rep.exact.worst_row << "\n";
    EXPECT_EQ(rep.exact.worst_row, i);
    EXPECT_GT(rep.exact.componentwise_error, 1e-3 * rel);
    EXPECT_LT(rep.exact.componentwise_error, 2.0 * rel);
    EXPECT_LT(rep.exact.relative_error, rep.exact.componentwise_error);
    EXPECT_GT(rep.exact.relative_error, 1e-14);
  }
  // the correct Jacobian of the same wrapper passes
  const auto ok = check_jacobian(wrong_entry_reactor{base, i, j, 0.0}, w, mu);
  EXPECT_LT(ok.exact.componentwise_error, 1e-14);
}

TEST(check_jacobian, taylor_fallback_agrees_with_the_jet_reference) {
  const tubular_reactor r(30);
  const vec<double> w = reactor_state(r);
  const wrong_entry_reactor bad{r, 7, 6, 1e-4};
  const auto via_jet = check_jacobian(bad, w, 0.2, {.probes = 6});
  const auto via_taylor = check_jacobian(taylor_only_reactor{r}, w, 0.2, {.probes = 6});
  EXPECT_LT(via_taylor.exact.componentwise_error, 1e-14);
  // same directions: the jet reference finds the perturbed row too, and the exact one passes
  EXPECT_EQ(via_jet.exact.worst_row, 7);
  const auto exact_via_jet = check_jacobian(wrong_entry_reactor{r, 7, 6, 0.0}, w, 0.2, {.probes = 6});
  EXPECT_NEAR(exact_via_jet.exact.reference_norm, via_taylor.exact.reference_norm, 1e-13 * via_taylor.exact.reference_norm);
}

TEST(check_jacobian, aerofoil_exact_passes_and_modified_order_differs) {
  const auto s = test_support::heavy_very_coarse_aerofoil(0.8);
  vec<double> w = s.free_stream_state();
  for (Eigen::Index k = 0; k < s.flow_size(); ++k) w[k] *= 1.0 + 0.02 * std::sin(1.3 * double(k));
  w.tail(4) << 0.01, -0.02, 0.03, 0.05;  // displaced, moving section: all coupling blocks active
  const auto rep = check_jacobian(s, w, 2.5);
  std::cout << rep;
  for (const auto* e : {&rep.exact, &rep.block_exact}) {
    ASSERT_TRUE(e->present) << e->name;
    EXPECT_LT(e->relative_error, 1e-13) << e->name;     // measured 1e-15
    EXPECT_LT(e->componentwise_error, 1e-12) << e->name;  // measured 2e-15
  }
  for (const auto* e : {&rep.approximate, &rep.block_approximate}) {
    ASSERT_TRUE(e->present) << e->name;
    EXPECT_GT(e->relative_error, 1e-3) << e->name;
    EXPECT_GT(e->componentwise_error, 1e-2) << e->name;
    EXPECT_LT(e->worst_row, s.flow_size()) << e->name;  // only the flow block is approximated
  }
  ASSERT_TRUE(rep.d_mu.present);
  EXPECT_LT(rep.d_mu.relative_error, 1e-13);
  std::ostringstream os;
  os << rep;
  EXPECT_NE(os.str().find("approximate_jacobian: ||A v - f'v||"), std::string::npos) << os.str();
}

TEST(check_jacobian, rejects_bad_input) {
  const tubular_reactor r(10);
  const vec<double> w = r.rest_state();
  EXPECT_THROW(check_jacobian(r, vec<double>::Ones(5), 0.1), input_error);
  vec<double> wn = w;
  wn[3] = std::nan("");
  EXPECT_THROW(check_jacobian(r, wn, 0.1), input_error);
  EXPECT_THROW(check_jacobian(r, w, std::nan("")), input_error);
  EXPECT_THROW(check_jacobian(r, w, 0.1, {.probes = 0}), input_error);
  try {
    check_jacobian(wrong_size_system{}, vec<double>::Ones(3), 0.0);
    FAIL() << "no input_error for a 2 x 2 Jacobian of a 3-unknown system";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("2 x 2"), std::string::npos) << e.what();
  }
  // a residual whose derivative is not finite at w (reactor at Theta = 0: exp(gamma - gamma/0))
  vec<double> w0 = w;
  w0[1] = 0.0;
  EXPECT_THROW(check_jacobian(r, w0, 0.1), input_error);
}
