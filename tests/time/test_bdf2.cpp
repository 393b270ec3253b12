// Implicit BDF2 with Newton (and dual-time) inner iterations: second order on a closed-form
// linear system, A-stability on a stiff one, agreement with RK4 on the nonlinear normal form
// (dense and sparse Jacobians), and the convergence_error naming the failing step.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>

#include <cmath>
#include <numbers>

#include "aerohopf/models/hopf_normal_form.hpp"
#include "aerohopf/linalg/krylov_solver.hpp"
#include "aerohopf/time.hpp"

using namespace aerohopf;

namespace {
/// w' = M w with M = [[-0.1, -2], [2, -0.1]] (+ a stiff decoupled mode -k): closed form.
struct linear_system {
  using jacobian_type = Eigen::MatrixXd;
  double stiff = 1.0;
  Eigen::Index size() const { return 3; }
  Eigen::MatrixXd matrix() const {
    Eigen::MatrixXd m(3, 3);
    m << -0.1, -2, 0, 2, -0.1, 0, 0, 0, -stiff;
    return m;
  }
  template <class T>
  vec<T> residual(const vec<T>& w, const T&) const {
    vec<T> r(3);
    r[0] = -0.1 * w[0] - 2.0 * w[1];
    r[1] = 2.0 * w[0] - 0.1 * w[1];
    r[2] = -stiff * w[2];
    return r;
  }
  Eigen::MatrixXd jacobian(const vec<double>&, double) const { return matrix(); }
  vec<double> exact(double t, const vec<double>& w0) const {
    vec<double> r(3);
    const double e = std::exp(-0.1 * t), c = std::cos(2 * t), s = std::sin(2 * t);
    r << e * (c * w0[0] - s * w0[1]), e * (s * w0[0] + c * w0[1]), std::exp(-stiff * t) * w0[2];
    return r;
  }
};

/// The normal form with a sparse Jacobian (exercises the sparse direct_solver path).
struct sparse_normal_form {
  using jacobian_type = Eigen::SparseMatrix<double>;
  hopf_normal_form m;
  Eigen::Index size() const { return m.size(); }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const { return m.residual(w, mu); }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return m.jacobian(w, mu).sparseView(); }
};

/// y' = y^2: the implicit step has no real solution once dt y > 1/4.
struct blow_up {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 1; }
  template <class T>
  vec<T> residual(const vec<T>& w, const T&) const { return vec<T>::Constant(1, w[0] * w[0]); }
  Eigen::MatrixXd jacobian(const vec<double>& w, double) const { return Eigen::MatrixXd::Constant(1, 1, 2 * w[0]); }
};
}  // namespace

TEST(Bdf2, SecondOrderOnLinearSystem) {
  const linear_system s;
  vec<double> w0(3);
  w0 << 1.0, 0.5, 0.2;
  double prev = 0;
  for (double dt : {0.02, 0.01, 0.005}) {
    const vec<double> w = integrate_bdf2(s, 0.0, w0, 0.0, 4.0, bdf2_options{.dt = dt});
    const double err = (w - s.exact(4.0, w0)).norm();
    if (prev > 0) {
      EXPECT_NEAR(prev / err, 4.0, 0.3) << "dt = " << dt;
    }
    prev = err;
  }
  EXPECT_LT(prev, 2e-3);
}

TEST(Bdf2, StableOnStiffModeWithLargeStep) {
  linear_system s;
  s.stiff = 1e6;  // explicit methods need dt < 3e-6; BDF2 is A-stable
  vec<double> w0(3);
  w0 << 1.0, 0.0, 1.0;
  const vec<double> w = integrate_bdf2(s, 0.0, w0, 0.0, 2.0, bdf2_options{.dt = 0.01});
  EXPECT_LT(std::abs(w[2]), 1e-6);
  EXPECT_LT((w.head(2) - s.exact(2.0, w0).head(2)).norm(), 1e-2);
}

TEST(Bdf2, AgreesWithRk4OnNormalFormDenseAndSparse) {
  const hopf_normal_form m(1.0, 3, 5);
  const double mu = 0.05;
  const vec<double> w0 = 0.3 * m.basis().col(1) + 0.1 * m.basis().col(3);
  const vec<double> ref = integrate_rk4(system_rhs(m, mu), w0, 0.0, 10.0, 1e-3);
  const vec<double> wd = integrate_bdf2(m, mu, w0, 0.0, 10.0, bdf2_options{.dt = 2.5e-3});
  EXPECT_LT((wd - ref).norm() / ref.norm(), 1e-4);
  const sparse_normal_form sm{m};
  int max_inner = 0;
  const vec<double> ws = integrate_bdf2(sm, mu, w0, 0.0, 10.0, bdf2_options{.dt = 2.5e-3},
                                        [&](const bdf2_step_info& i, const vec<double>&) {
                                          max_inner = std::max(max_inner, i.inner_iterations);
                                        });
  EXPECT_LT((ws - wd).norm(), 1e-12);
  EXPECT_LE(max_inner, 4);  // Newton on the exact Jacobian from an extrapolated guess
  // Halving dt reduces the difference to RK4 by ~4.
  const vec<double> wh = integrate_bdf2(m, mu, w0, 0.0, 10.0, bdf2_options{.dt = 1.25e-3});
  EXPECT_NEAR((wd - ref).norm() / (wh - ref).norm(), 4.0, 0.4);
}

TEST(Bdf2, DualTimeConvergesToSameSolution) {
  const hopf_normal_form m(-1.0, 2, 8);
  const vec<double> w0 = 0.2 * m.basis().col(0);
  const bdf2_options newton{.dt = 0.01};
  const bdf2_options dual{.dt = 0.01, .inner_tolerance = 1e-12, .max_inner_iterations = 200, .pseudo_dt = 0.05};
  int dual_iters = 0;
  const vec<double> wn = integrate_bdf2(m, -0.1, w0, 0.0, 2.0, newton);
  const vec<double> wd = integrate_bdf2(m, -0.1, w0, 0.0, 2.0, dual, [&](const bdf2_step_info& i, const vec<double>&) {
    dual_iters = std::max(dual_iters, i.inner_iterations);
  });
  EXPECT_LT((wn - wd).norm(), 1e-9);
  EXPECT_GT(dual_iters, 3);  // pseudo-time iterations converge linearly
}

// CFD-style inner iterations: matrix formed and factored once per physical step (a chord
// iteration), solved by BILU-GMRES (krylov_solver), stopped by a residual drop. The frozen
// matrix converges linearly, so it takes more inner iterations, but to the same solution: the
// inner residual drop bounds the difference to the fully converged Newton run.
TEST(Bdf2, FrozenMatrixKrylovAndResidualDropReachTheNewtonSolution) {
  const hopf_normal_form m(1.0, 3, 5);
  const sparse_normal_form sm{m};
  const double mu = 0.05;
  const vec<double> w0 = 0.3 * m.basis().col(1) + 0.1 * m.basis().col(3);
  const bdf2_options newton{.dt = 0.01};
  bdf2_options chord{.dt = 0.01, .max_inner_iterations = 60};
  chord.inner_residual_drop = 1e-8;
  chord.freeze_matrix = true;
  chord.approximate_jacobian = true;  // falls back to the exact Jacobian for this system
  krylov_solver_options ko;
  ko.krylov.relative_tolerance = 1e-10;
  krylov_solver<Eigen::SparseMatrix<double>> solver(ko);
  int max_chord = 0;
  const vec<double> wn = integrate_bdf2(sm, mu, w0, 0.0, 3.0, newton);
  const vec<double> wc = integrate_bdf2(
      sm, mu, w0, 0.0, 3.0, chord,
      [&](const bdf2_step_info& i, const vec<double>&) { max_chord = std::max(max_chord, i.inner_iterations); }, solver);
  EXPECT_LT((wn - wc).norm(), 1e-7 * wn.norm());
  EXPECT_GE(max_chord, 2);
  // a residual drop that cannot be met in the allowed iterations is reported, with the step
  bdf2_options tight = chord;
  tight.inner_residual_drop = 1e-300;
  tight.inner_tolerance = 1e-300;
  tight.max_inner_iterations = 2;
  EXPECT_THROW(integrate_bdf2(sm, mu, w0, 0.0, 0.1, tight, [](const bdf2_step_info&, const vec<double>&) {}, solver),
               convergence_error);
  bdf2_options bad = chord;
  bad.inner_residual_drop = 1.5;
  EXPECT_THROW(integrate_bdf2(sm, mu, w0, 0.0, 0.1, bad), input_error);
}

// The growth-rate estimator against a closed form: a damped cosine with a phase and a few
// samples per period (peaks refined only to the sampling) gives sigma to the sampling accuracy.
TEST(Bdf2, PeakGrowthRateOfADampedCosine) {
  for (double sigma : {-0.05, 0.0, 0.03}) {
    std::vector<double> t, y;
    for (int k = 0; k <= 4000; ++k) {
      t.push_back(0.01 * k);
      y.push_back(std::exp(sigma * t.back()) * std::cos(2.0 * t.back() + 0.4));
    }
    int peaks = 0;
    EXPECT_NEAR(peak_growth_rate(t, y, 1.0, &peaks), sigma, 1e-4) << "sigma " << sigma;
    EXPECT_GE(peaks, 20);  // both signs: two peaks per period of |y|
  }
  // 20.3 samples per period (the peaks fall at a different phase each period): the maxima
  // refined by parabolas give sigma to 1e-6 (the raw sampled maxima to 6e-5 only)
  for (double sigma : {-0.05, 0.0, 0.03}) {
    std::vector<double> t, y;
    const double h = std::numbers::pi / 20.3;
    for (int k = 0; k * h < 40.0; ++k) {
      t.push_back(k * h);
      y.push_back(std::exp(sigma * t.back()) * std::cos(2.0 * t.back() + 0.4));
    }
    EXPECT_NEAR(peak_growth_rate(t, y, 1.0), sigma, 2e-6) << "sigma " << sigma;
  }
  int peaks = -1;
  EXPECT_TRUE(std::isnan(peak_growth_rate({0.0, 1.0}, {1.0, 2.0}, 0.0, &peaks)));
  EXPECT_EQ(peaks, 0);
  EXPECT_THROW(peak_growth_rate({0.0}, {1.0, 2.0}, 0.0), input_error);
}

TEST(Bdf2, HistoryAndErrors) {
  const linear_system s;
  vec<double> w0(3);
  w0 << 1.0, 0.0, 0.0;
  const auto h = bdf2_history(s, 0.0, w0, 0.0, 1.0, bdf2_options{.dt = 0.1}, 3);
  ASSERT_EQ(h.t.size(), 5u);  // steps 0, 3, 6, 9, 10
  EXPECT_DOUBLE_EQ(h.t.back(), 1.0);
  EXPECT_THROW(integrate_bdf2(s, 0.0, w0, 0.0, 1.0, bdf2_options{.dt = -1}), input_error);
  EXPECT_THROW(integrate_bdf2(s, 0.0, vec<double>::Zero(2).eval(), 0.0, 1.0, bdf2_options{}), input_error);
  try {
    integrate_bdf2(blow_up{}, 0.0, vec<double>::Constant(1, 1.0), 0.0, 2.0,
                   bdf2_options{.dt = 0.1, .max_inner_iterations = 30});
    FAIL() << "no exception";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("time step"), std::string::npos) << e.what();
  } catch (const singular_matrix_error&) {
    SUCCEED();  // the Newton matrix c - 2 y can also become singular on the way
  }
}

// Amplitude envelope against the closed form of the Landau equation dA/dt = sigma A + beta A^3
// (supercritical: beta < 0, limit cycle at A = sqrt(-sigma / beta)):
// A^-2 = (A0^-2 + beta / sigma) e^{-2 sigma t} - beta / sigma, signal y = m + A cos(omega t).
TEST(Bdf2, AmplitudeEnvelopeOfALandauTransient) {
  const double sigma = 0.02, beta = -0.05, omega = 1.3, a0 = 0.05, mean = 0.3;
  auto amp = [&](double t) { return 1.0 / std::sqrt((1.0 / (a0 * a0) + beta / sigma) * std::exp(-2 * sigma * t) - beta / sigma); };
  std::vector<double> t, y;
  for (int k = 0; k <= 40000; ++k) {
    t.push_back(0.01 * k);
    y.push_back(mean + amp(t.back()) * std::cos(omega * t.back()));
  }
  const auto e = amplitude_envelope(t, y, 1.0);
  ASSERT_GT(e.size(), 150u);
  double worst_a = 0, worst_g = 0;
  for (const auto& s : e) {
    const double a = amp(s.t);
    worst_a = std::max(worst_a, std::abs(s.amplitude - a) / a);
    worst_g = std::max(worst_g, std::abs(s.growth_rate - (sigma + beta * a * a)));
  }
  std::cout << "envelope: max relative amplitude error " << worst_a << ", max growth-rate error " << worst_g << "\n";
  EXPECT_LT(worst_a, 1e-3);
  EXPECT_LT(worst_g, 5e-5);  // rates run from +0.02 to ~0 at the limit cycle (0.632)
  EXPECT_NEAR(e.back().amplitude, std::sqrt(-sigma / beta), 2e-3);
  EXPECT_TRUE(amplitude_envelope({0.0, 1.0}, {1.0, 2.0}, 0.0).empty());
  EXPECT_THROW(amplitude_envelope({0.0}, {1.0, 2.0}, 0.0), input_error);
}

// ---- fault injection (reliability) ----
namespace {
/// The normal form whose residual is NaN (entry 0) on call nan_call, and whose Jacobian on call
/// shift_call is c I (so that the inner matrix c I - A is zero: singular).
struct faulty_normal_form {
  using jacobian_type = Eigen::MatrixXd;
  hopf_normal_form m;
  int nan_call = -1, shift_call = -1;
  double shift = 0;
  mutable int calls = 0, jacobian_calls = 0;
  Eigen::Index size() const { return m.size(); }
  vec<double> residual(const vec<double>& w, double mu) const {
    vec<double> f = m.residual(w, mu);
    if (++calls == nan_call) f[0] = NAN;
    return f;
  }
  Eigen::MatrixXd jacobian(const vec<double>& w, double mu) const {
    if (++jacobian_calls == shift_call) return shift * Eigen::MatrixXd::Identity(size(), size());
    return m.jacobian(w, mu);
  }
};
}  // namespace

// NaN unsteady residual inside the inner Newton iteration of time step n: time_march_error
// names integrate_bdf2, the step, t, mu and what was non-finite, and carries the last good
// state and the level before it (the clean run's states); resume_bdf2 from them, fault removed,
// ends on the clean run's answer. A singular inner matrix stays singular_matrix_error, with the
// time step, t and mu in front.
TEST(Bdf2, NanResidualStopsWithTheLastTwoLevelsAndTheRunResumes) {
  const hopf_normal_form m(1.0, 2, 3);
  const double mu = 0.04;
  const bdf2_options o{.dt = 0.05};
  const vec<double> w0 = 0.3 * m.basis().col(0), w0_copy = w0;
  std::vector<vec<double>> states;
  const vec<double> clean =
      integrate_bdf2(m, mu, w0, 0.0, 10.0, o, [&](const bdf2_step_info&, const vec<double>& w) { states.push_back(w); });
  faulty_normal_form f{m};
  f.nan_call = 40;
  try {
    integrate_bdf2(f, mu, w0, 0.0, 10.0, o);
    FAIL() << "expected time_march_error";
  } catch (const time_march_error<vec<double>>& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("integrate_bdf2: inner Newton iteration failed at time step"), std::string::npos) << what;
    EXPECT_NE(what.find("mu = 0.04"), std::string::npos) << what;
    EXPECT_NE(what.find("unsteady residual entry 0 is not finite"), std::string::npos) << what;
    ASSERT_GE(e.step, 2);
    EXPECT_EQ(e.state, states[static_cast<std::size_t>(e.step)]);
    EXPECT_EQ(e.previous, states[static_cast<std::size_t>(e.step - 1)]);
    EXPECT_NEAR(e.t, 0.05 * double(e.step), 1e-12);
    EXPECT_EQ(w0, w0_copy);
    bdf2_options again = o;
    again.dt = e.dt;
    const vec<double> resumed = resume_bdf2(m, mu, e.previous, e.state, e.t, 10.0, again);
    EXPECT_LT((resumed - clean).norm(), 1e-12);
  }
  faulty_normal_form g{m};
  g.shift_call = 7;
  g.shift = 1.5 / 0.05;  // c of a BDF2 step
  try {
    integrate_bdf2(g, mu, w0, 0.0, 10.0, o);
    FAIL() << "expected singular_matrix_error";
  } catch (const singular_matrix_error& e) {
    EXPECT_NE(std::string(e.what()).find("integrate_bdf2: time step "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mu = 0.04"), std::string::npos) << e.what();
  }
  vec<double> bad = w0;
  bad[3] = NAN;
  try {
    integrate_bdf2(m, mu, bad, 0.0, 1.0, o);
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("state entry 3"), std::string::npos) << e.what();
  }
}
