// Inverse power (right and adjoint), the Cayley-transform rightmost eigenvalues and root-locus
// tracing, all against Eigen's dense eigen-decomposition.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>
#include <aerohopf/models/tubular_reactor.hpp>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <initializer_list>
#include <iostream>
#include <limits>
#include <string>

using namespace aerohopf;

namespace {
std::complex<double> nearest(const std::vector<std::complex<double>>& ev, std::complex<double> z) {
  return *std::min_element(ev.begin(), ev.end(), [&](auto a, auto b) { return std::abs(a - z) < std::abs(b - z); });
}
vec<double> reactor_state(const tubular_reactor& r, double mu) {
  return newton(r, newton(r, r.rest_state(), 0.1).x, mu).x;
}
}  // namespace

TEST(inverse_power, RightAndAdjointEigenpairsDenseAndSparse) {
  const tubular_reactor r(24);
  const double mu = 0.16;
  const vec<double> w = reactor_state(r, mu);
  const Eigen::SparseMatrix<double> a = r.jacobian(w, mu);
  const Eigen::MatrixXd ad(a);
  const auto ev = dense_spectrum(ad);
  const std::complex<double> shift(0.0, 0.5);
  const auto ref = nearest(ev, shift);
  for (int dense = 0; dense < 2; ++dense) {
    const eigen_pair p = dense ? inverse_power(ad, shift) : inverse_power(a, shift);
    EXPECT_LT(std::abs(p.lambda - ref), 1e-10 * std::abs(ref));
    const Eigen::MatrixXcd ac = ad.cast<std::complex<double>>();
    EXPECT_LT((ac * p.vector - p.lambda * p.vector).norm(), 1e-10);
    const eigen_pair q = dense ? inverse_power_adjoint(ad, shift) : inverse_power_adjoint(a, shift);
    EXPECT_LT(std::abs(q.lambda - std::conj(ref)), 1e-10 * std::abs(ref));
    EXPECT_LT((ac.transpose() * q.vector - q.lambda * q.vector).norm(), 1e-10);
  }
}

// The Krylov route (complex BILU(k) of A - sigma I + GMRES behind the solver interface) gives
// the same eigenpair as the sparse LU, with inexact solves, and the same through hopf_start.
TEST(inverse_power, KrylovSolverMatchesDirectAndDense) {
  const tubular_reactor r(40);
  const double mu = 0.16;
  const vec<double> w = reactor_state(r, mu);
  const Eigen::SparseMatrix<double> a = r.jacobian(w, mu);
  const auto ev = dense_spectrum(Eigen::MatrixXd(a));
  const std::complex<double> shift(0.0, 0.5);
  const auto ref = nearest(ev, shift);
  krylov_solver_options ko;
  ko.fill_level = 1;
  ko.krylov.relative_tolerance = 1e-6;  // inexact on purpose: the outer residual test decides
  krylov_solver<Eigen::SparseMatrix<std::complex<double>>> ks(ko, "inverse power BILU(1)-GMRES");
  const eigen_pair p = inverse_power(a, shift, {}, nullptr, ks);
  const eigen_pair d = inverse_power(a, shift);
  EXPECT_LT(std::abs(p.lambda - ref), 1e-10 * std::abs(ref));
  EXPECT_LT(std::abs(p.lambda - d.lambda), 1e-10 * std::abs(ref));
  EXPECT_LT((p.vector - d.vector).norm(), 1e-8);  // both phase-normalised
  EXPECT_GT(p.linear_iterations, 0);
  EXPECT_EQ(d.linear_iterations, 0);
  std::cout << "Krylov inverse power: " << p.iterations << " outer, " << p.linear_iterations << " GMRES iterations; direct "
            << d.iterations << " outer\n";
  const hopf_point h = hopf_start(r, w, mu, 0.5, {}, ks);
  EXPECT_NEAR(h.omega, std::abs(ref.imag()), 1e-10);
}

TEST(inverse_power, FailsClearlyWhenNotConverging) {
  // Two eigenvalues equidistant from the shift: no convergence, a clear error.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2, 2);
  a(0, 0) = 1.0;
  a(1, 1) = -1.0;
  inverse_power_options o;
  o.max_iterations = 20;
  EXPECT_THROW(inverse_power(a, {0.0, 0.0}, o), convergence_error);
}

TEST(cayley, RightmostEigenvaluesMatchDenseSpectrum) {
  const tubular_reactor r(32);
  for (double mu : {0.12, 0.165, 0.17}) {
    const vec<double> w = reactor_state(r, mu);
    const auto a = r.jacobian(w, mu);
    auto ev = dense_spectrum(a);
    std::sort(ev.begin(), ev.end(), [](auto x, auto y) { return x.real() > y.real(); });
    const auto c = cayley_rightmost(a);
    ASSERT_FALSE(c.empty());
    EXPECT_LT(std::abs(c.front() - nearest(ev, c.front())), 1e-7);
    EXPECT_NEAR(c.front().real(), ev.front().real(), 1e-7) << "mu " << mu;
  }
}

TEST(root_locus, TracksDenseEigenvalueAlongMu) {
  const tubular_reactor r(16);
  std::vector<double> mus;
  for (int k = 0; k <= 10; ++k) mus.push_back(0.15 + 0.002 * k);
  vec<double> w = reactor_state(r, 0.15);
  auto equilibrium = [&](double mu) {
    w = newton(r, w, mu).x;
    return w;
  };
  // start from the rightmost complex eigenvalue at mu = 0.15
  auto ev0 = dense_spectrum(r.jacobian(w, 0.15));
  std::complex<double> start{-1e300, 0};
  for (auto l : ev0)
    if (l.imag() > 1e-6 && l.real() > start.real()) start = l;
  const auto locus = root_locus(r, std::function<vec<double>(double)>(equilibrium), mus, start);
  ASSERT_EQ(locus.size(), mus.size());
  vec<double> w2 = reactor_state(r, 0.15);
  for (const auto& p : locus) {
    w2 = newton(r, w2, p.mu).x;
    const auto ev = dense_spectrum(r.jacobian(w2, p.mu));
    EXPECT_LT(std::abs(p.lambda - nearest(ev, p.lambda)), 1e-9);
  }
  // it crosses the imaginary axis between 0.164 and 0.166 (the first Hopf point)
  EXPECT_LT(locus[7].lambda.real(), 0.0);
  EXPECT_GT(locus[8].lambda.real(), 0.0);
}

namespace {
/// Runs f, expects input_error whose message contains every one of the given words.
template <class F>
void expect_input_error(F f, std::initializer_list<const char*> words) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    for (const char* w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what() << " / " << w;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an input_error: " << e.what();
  }
}
}  // namespace

TEST(inverse_power, RefusesNonFiniteShiftStartMatrixAndBadOptions) {
  // diag(1, 2, 3): the valid call converges to 2 from the shift 1.9
  Eigen::MatrixXd a = Eigen::Vector3d(1.0, 2.0, 3.0).asDiagonal();
  const Eigen::SparseMatrix<double> as = a.sparseView();
  EXPECT_NEAR(std::abs(inverse_power(a, 1.9).lambda - 2.0), 0.0, 1e-12);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { inverse_power(a, {nan, 0.0}); }, {"inverse power", "shift"});
  expect_input_error([&] { inverse_power(as, {0.0, INFINITY}); }, {"inverse power", "shift"});
  // a NaN or zero start was replaced by the default start without a word
  vec<std::complex<double>> bad = vec<std::complex<double>>::Ones(3);
  bad[1] = {nan, 0.0};
  expect_input_error([&] { inverse_power(a, 1.9, {}, &bad); }, {"start vector", "entry 1"});
  const vec<std::complex<double>> zero = vec<std::complex<double>>::Zero(3);
  expect_input_error([&] { inverse_power(a, 1.9, {}, &zero); }, {"start vector", "zero"});
  const vec<std::complex<double>> short_start = vec<std::complex<double>>::Ones(2);
  expect_input_error([&] { inverse_power(a, 1.9, {}, &short_start); }, {"start vector", "has 2 entries, expected 3"});
  inverse_power_options o;
  o.max_iterations = 0;
  expect_input_error([&] { inverse_power(a, 1.9, o); }, {"max_iterations", "0"});
  o = {};
  o.tolerance = nan;
  expect_input_error([&] { inverse_power(a, 1.9, o); }, {"tolerance"});
  o.tolerance = -1e-8;
  expect_input_error([&] { inverse_power_adjoint(as, 1.9, o); }, {"adjoint inverse power", "tolerance"});
  // a NaN entry of A, dense and sparse, named by position
  Eigen::MatrixXd an = a;
  an(2, 1) = nan;
  expect_input_error([&] { inverse_power(an, 1.9); }, {"matrix entry (2, 1)"});
  const Eigen::SparseMatrix<double> asn = an.sparseView();
  expect_input_error([&] { inverse_power(asn, 1.9); }, {"matrix entry (2, 1)"});
}

TEST(cayley, RefusesNonSquareNonFiniteMatrixAndBadOptions) {
  const tubular_reactor r(8);
  const auto a = r.jacobian(r.rest_state(), 0.1);
  cayley_options o;
  o.wanted = 0;  // returned an empty list without a word
  expect_input_error([&] { cayley_rightmost(a, o); }, {"cayley_rightmost", "wanted"});
  o = {};
  o.a2 = -INFINITY;
  expect_input_error([&] { cayley_rightmost(a, o); }, {"cayley_rightmost", "a2"});
  o = {};
  o.tolerance = 0;
  expect_input_error([&] { cayley_rightmost(a, o); }, {"cayley_rightmost", "tolerance"});
  Eigen::MatrixXd d = Eigen::MatrixXd(a);
  d(3, 4) = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { cayley_rightmost(d); }, {"cayley_rightmost", "(3, 4)"});
  const Eigen::MatrixXd rect = Eigen::MatrixXd::Identity(4, 5);
  expect_input_error([&] { cayley_rightmost(rect); }, {"cayley_rightmost", "4x5"});
}

TEST(root_locus, RefusesNonFiniteShiftAndMuBeforeAnyEquilibriumSolve) {
  const tubular_reactor r(8);
  int solves = 0;
  const std::function<vec<double>(double)> equilibrium = [&](double mu) {
    ++solves;
    return reactor_state(r, mu);
  };
  // a NaN mu further down the list used to be found only after the earlier points were computed
  expect_input_error([&] { root_locus(r, equilibrium, {0.12, 0.13, std::nan("")}, {-1.0, 1.0}); }, {"root_locus", "mus[2]"});
  EXPECT_EQ(solves, 0);
  expect_input_error([&] { root_locus(r, equilibrium, {0.12}, {std::nan(""), 1.0}); }, {"root_locus", "shift0"});
  inverse_power_options o;
  o.max_iterations = 0;
  expect_input_error([&] { root_locus(r, equilibrium, {0.12}, {-1.0, 1.0}, o); }, {"root_locus", "max_iterations"});
  EXPECT_EQ(solves, 0);
}
