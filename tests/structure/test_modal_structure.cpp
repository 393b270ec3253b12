// Modal structural model: the in-vacuo eigenvalues of A_ss against the damped-oscillator closed
// form -zeta k +- i k sqrt(1 - zeta^2), A_ss and dR/dmu against jet derivatives of the templated
// residual, the non-dimensionalisation (reduced frequency, density parameter), and refusals.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/scalar/jet.hpp>
#include <aerohopf/structure/modal_structure.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::structure;

TEST(ModalStructure, InVacuoEigenvaluesAreTheDampedOscillators) {
  const Eigen::Vector3d k(0.12, 0.47, 0.61), zeta(0.0, 0.005, 0.02);
  const modal_structure s(k, zeta);
  Eigen::EigenSolver<Eigen::MatrixXd> es(s.a_ss());
  std::vector<std::complex<double>> got(es.eigenvalues().data(), es.eigenvalues().data() + 6);
  for (int i = 0; i < 3; ++i)
    for (double sign : {1.0, -1.0}) {
      const std::complex<double> want(-zeta[i] * k[i], sign * k[i] * std::sqrt(1 - zeta[i] * zeta[i]));
      const auto it = std::min_element(got.begin(), got.end(),
                                       [&](auto a, auto b) { return std::abs(a - want) < std::abs(b - want); });
      EXPECT_NEAR(std::abs(*it - want), 0.0, 1e-13) << "mode " << i << " sign " << sign;
    }
}

TEST(ModalStructure, AnalyticDerivativesEqualJetDerivatives) {
  const modal_structure s(Eigen::Vector2d(0.3, 0.8), Eigen::Vector2d(0.01, 0.03));
  const Eigen::Vector4d w(0.1, -0.2, 0.05, 0.3);
  const Eigen::Vector2d g(0.7, -1.1);
  const double mu = 0.04;
  using J = jet<double, 5>;  // four state directions and mu
  Eigen::Matrix<J, 4, 1> wj;
  for (int i = 0; i < 4; ++i) wj[i] = J::variable(w[i], i);
  const J muj = J::variable(mu, 4);
  const Eigen::Matrix<J, Eigen::Dynamic, 1> r = s.residual<J>(wj, g.cast<J>(), muj);
  const Eigen::MatrixXd a = s.a_ss();
  const Eigen::VectorXd dmu = s.d_mu(g);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(r[i].derivative(j), a(i, j), 1e-15) << i << "," << j;
    EXPECT_NEAR(r[i].derivative(4), dmu[i], 1e-15);
  }
  // the force coupling: dR/dg by a jet in g
  Eigen::Matrix<J, 2, 1> gj;
  for (int i = 0; i < 2; ++i) gj[i] = J::variable(g[i], i);
  const auto rg = s.residual<J>(w.cast<J>(), gj, J(mu));
  const Eigen::MatrixXd b = s.force_coupling(mu);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(rg[i].derivative(j), b(i, j), 1e-15);
  // and the residual itself: [a'; mu g - K a - D a']
  const Eigen::VectorXd rv = s.residual<double>(w, g, mu);
  EXPECT_NEAR(rv[0], w[2], 1e-15);
  EXPECT_NEAR(rv[3], mu * g[1] - 0.64 * w[1] - 2 * 0.03 * 0.8 * w[3], 1e-15);
}

TEST(ModalStructure, PhysicalParameters) {
  // AGARD 445.6 first bending, 9.6 Hz, root chord 0.5587 m at 310.96 m/s (M = 0.96 in the tunnel)
  const Eigen::VectorXd om = Eigen::VectorXd::Constant(1, 2 * 3.141592653589793 * 9.6);
  const modal_structure s = modal_structure::from_physical(om, Eigen::VectorXd::Zero(1), 0.5587, 310.96);
  EXPECT_NEAR(s.reduced_frequency()[0], om[0] * 0.5587 / 310.96, 1e-15);
  EXPECT_NEAR(modal_structure::density_parameter(0.0634, 0.5587), 0.0634 * std::pow(0.5587, 3), 1e-15);
}

TEST(ModalStructure, RefusesBadInput) {
  EXPECT_THROW(modal_structure(Eigen::VectorXd(0), Eigen::VectorXd(0)), input_error);
  EXPECT_THROW(modal_structure(Eigen::Vector2d(0.1, -0.2), Eigen::Vector2d(0, 0)), input_error);
  EXPECT_THROW(modal_structure(Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0, 1.5)), input_error);
  EXPECT_THROW(modal_structure(Eigen::Vector2d(0.1, 0.2), Eigen::VectorXd::Zero(3)), input_error);
  EXPECT_THROW(modal_structure::from_physical(Eigen::Vector2d(1, 2), Eigen::Vector2d(0, 0), -1, 100), input_error);
  const modal_structure s(Eigen::Vector2d(0.3, 0.8), Eigen::Vector2d(0.01, 0.03));
  EXPECT_THROW(s.residual<double>(Eigen::Vector3d::Zero(), Eigen::Vector2d::Zero(), 1.0), input_error);
  EXPECT_THROW(s.d_mu(Eigen::Vector3d::Zero()), input_error);
}
