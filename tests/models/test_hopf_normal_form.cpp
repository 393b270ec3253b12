// Hopf normal form model: the exact Jacobian, f_mu, A_mu and A_w v against independent
// derivatives (taylor jets, central differences), the spectrum against Eigen's dense
// eigensolver, and the closed-form Hopf data (p, eigenvalues mu +- i, -d_k).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "aerohopf/models/hopf_normal_form.hpp"
#include "aerohopf/nonlinear/system.hpp"
#include "aerohopf/scalar/qd.hpp"
#include "aerohopf/scalar/taylor.hpp"

using namespace aerohopf;
using C = std::complex<double>;

static_assert(aerohopf::dynamical_system<hopf_normal_form>);
static_assert(system_over<hopf_normal_form, dd_real>);
static_assert(system_over<hopf_normal_form, qd_real>);
static_assert(system_over<hopf_normal_form, taylor<double, 3>>);
static_assert(system_over<hopf_normal_form, taylor<dd_real, 3>>);

namespace {
vec<double> test_state(Eigen::Index n) {
  vec<double> w(n);
  for (Eigen::Index i = 0; i < n; ++i) w[i] = 0.3 * std::sin(1.7 * double(i) + 0.4);
  return w;
}
}  // namespace

TEST(HopfNormalForm, BasisIsWellConditionedAndSkewed) {
  for (int extra : {0, 4, 30}) {
    for (unsigned seed : {1u, 7u, 12345u}) {
      const hopf_normal_form big(1.0, extra, seed);
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(big.basis());
      EXPECT_LT(svd.singularValues()(0) / svd.singularValues().tail(1)(0), 20.0) << extra << " " << seed;
    }
  }
  const hopf_normal_form m(1.0, 4, 7);
  // Not orthogonal and not diagonal.
  const Eigen::MatrixXd g = m.basis().transpose() * m.basis();
  EXPECT_GT((g - Eigen::MatrixXd(g.diagonal().asDiagonal())).norm(), 0.1);
  EXPECT_NEAR(m.basis().col(0).norm(), std::sqrt(2.0), 1e-15);
}

TEST(HopfNormalForm, JacobianMatchesTaylorProducts) {
  for (double s : {1.0, -1.0}) {
    const hopf_normal_form m(s, 3, 2);
    const vec<double> w = test_state(m.size());
    const double mu = 0.13;
    const Eigen::MatrixXd a = m.jacobian(w, mu);
    for (Eigen::Index j = 0; j < m.size(); ++j) {
      using J = taylor<double, 1>;
      vec<J> wj(m.size());
      for (Eigen::Index i = 0; i < m.size(); ++i) wj[i] = J::variable(w[i], i == j ? 1.0 : 0.0);
      const vec<J> f = m.residual(wj, J(mu));
      for (Eigen::Index i = 0; i < m.size(); ++i) EXPECT_NEAR(f[i][1], a(i, j), 1e-13) << i << "," << j;
    }
  }
}

TEST(HopfNormalForm, ParameterAndDirectionalDerivativesMatchJets) {
  const hopf_normal_form m(1.0, 3, 3);
  const vec<double> w = test_state(m.size());
  const double mu = -0.2;
  using J = taylor<double, 1>;
  // f_mu by a jet in mu.
  const vec<J> fj = m.residual(w.cast<J>().eval(), J::variable(mu));
  const vec<double> fmu = m.d_mu(w, mu);
  for (Eigen::Index i = 0; i < m.size(); ++i) EXPECT_NEAR(fj[i][1], fmu[i], 1e-14);
  // A_mu and A_w v against central differences of the (independently checked) Jacobian;
  // A is affine in mu and quadratic in w, so central differences are exact up to rounding.
  const double h = 1e-3;
  const Eigen::MatrixXd amu = (m.jacobian(w, mu + h) - m.jacobian(w, mu - h)) / (2 * h);
  EXPECT_LT((amu - m.jacobian_d_mu(w, mu)).norm(), 1e-10);
  const vec<double> v = test_state(m.size()).reverse();
  const Eigen::MatrixXd awv = (m.jacobian(w + h * v, mu) - m.jacobian(w - h * v, mu)) / (2 * h);
  EXPECT_LT((awv - m.jacobian_directional(w, mu, v)).norm(), 1e-10);
}

TEST(HopfNormalForm, ResidualAgreesAcrossScalars) {
  const hopf_normal_form m(-1.0, 2, 5);
  const vec<double> w = test_state(m.size());
  const vec<double> fd = m.residual(w, 0.05);
  vec<qd_real> wq(m.size());
  for (Eigen::Index i = 0; i < m.size(); ++i) wq[i] = qd_real(w[i]);
  const vec<qd_real> fq = m.residual(wq, qd_real(0.05));
  for (Eigen::Index i = 0; i < m.size(); ++i) EXPECT_NEAR(fd[i], to_double(fq[i]), 1e-15);
  // The equilibrium w = 0 for every mu.
  EXPECT_EQ(m.residual(vec<double>::Zero(m.size()).eval(), 0.7).norm(), 0.0);
}

TEST(HopfNormalForm, SpectrumAndExactEigenvector) {
  const hopf_normal_form m(1.0, 3, 11);
  for (double mu : {-0.3, 0.0, 0.25}) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(m.jacobian(vec<double>::Zero(m.size()), mu));
    std::vector<C> ev(es.eigenvalues().begin(), es.eigenvalues().end());
    std::vector<C> expected{C(mu, 1), C(mu, -1)};
    for (int k = 0; k < m.n_extra(); ++k) expected.push_back(C(-m.decay_rates()[k], 0));
    auto by_value = [](C a, C b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); };
    std::sort(ev.begin(), ev.end(), by_value);
    std::sort(expected.begin(), expected.end(), by_value);
    ASSERT_EQ(ev.size(), expected.size());
    for (size_t k = 0; k < ev.size(); ++k) EXPECT_NEAR(std::abs(ev[k] - expected[k]), 0.0, 1e-12);
  }
  const hopf_point hp = m.exact_hopf_point();
  const Eigen::MatrixXcd a = m.jacobian(hp.w, hp.mu).cast<C>();
  EXPECT_LT((a * hp.p - C(0, hp.omega) * hp.p).norm(), 1e-14);
  EXPECT_NEAR(hp.p.norm(), 1.0, 1e-15);
  // z = x1 + i x2 for w = z p + conj(z p).
  const C z(0.3, -0.7);
  const vec<double> wz = 2 * (z * hp.p).real();
  const Eigen::Vector2d x = m.centre_coordinates(wz);
  EXPECT_NEAR(x[0], z.real(), 1e-14);
  EXPECT_NEAR(x[1], z.imag(), 1e-14);
}

TEST(HopfNormalForm, RejectsBadInput) {
  EXPECT_THROW(hopf_normal_form(0.0), input_error);
  EXPECT_THROW(hopf_normal_form(1.0, -1), input_error);
  const hopf_normal_form m;
  EXPECT_THROW(m.residual(vec<double>::Zero(3).eval(), 0.0), input_error);
}

TEST(HopfNormalForm, EveryEvaluationRefusesWrongSizeAndNonFiniteStates) {
  const hopf_normal_form m;  // size 5
  const vec<double> w0 = vec<double>::Zero(5), longer = vec<double>::Zero(6), shorter = vec<double>::Zero(4);
  EXPECT_EQ(m.jacobian(w0, 0.0).rows(), 5);  // valid
  // the products with T^{-1} used to ignore or read past the extra / missing entries
  EXPECT_THROW(m.jacobian(longer, 0.0), input_error);
  EXPECT_THROW(m.jacobian(shorter, 0.0), input_error);
  EXPECT_THROW(m.d_mu(longer, 0.0), input_error);
  EXPECT_THROW(m.jacobian_d_mu(shorter, 0.0), input_error);
  EXPECT_THROW(m.jacobian_directional(w0, 0.0, longer), input_error);
  EXPECT_THROW(m.jacobian_directional(longer, 0.0, w0), input_error);
  EXPECT_THROW(m.coordinates(longer), input_error);
  EXPECT_THROW(m.centre_coordinates(shorter), input_error);
  vec<double> bad = w0;
  bad[3] = std::nan("");
  EXPECT_THROW(m.jacobian(bad, 0.0), input_error);
  EXPECT_THROW(m.jacobian(w0, std::nan("")), input_error);
  EXPECT_THROW(m.jacobian_directional(w0, 0.0, bad), input_error);
}
