// V-g / V-f diagram (bifurcation/vg_diagram.hpp): mode tracking by the eigenvector through a
// frequency crossing and the flutter point, against the closed form and a dense
// eigen-decomposition of a two-mode linear system (also as an aeroelastic_system, tracked by
// its structural part by default); on the heavy very coarse aerofoil, the zero
// crossing of g against the Hopf point of the augmented-system Newton solve.
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/root_locus.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>

#include "support/aerofoil_cases.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <iomanip>
#include <iostream>
#include <vector>

using namespace aerohopf;
using cplx = std::complex<double>;

namespace {

// dw/dt = A(mu) w, A = T(mu) D(mu) T(mu)^{-1}, D = blockdiag(B1, B2, -2, -3), B = [[a, w], [-w, a]]:
//   mode 0: lambda_0 = -0.1 + i (1 + mu/2)                 (damped throughout)
//   mode 1: lambda_1 = 0.3 (mu - 1.6) + i (2 - mu/2)       (g = 0 at mu = 1.6, rising)
// The frequencies cross at mu = 1 (both 1.5; the eigenvalues stay 0.08 apart there). The first
// four unknowns are the "structure" (tracked part); the last two are damped lag states. T(mu)
// couples everything, so no coordinate is one mode. Eigenvector of mode k: T(mu) (e_{2k} + i e_{2k+1}).
struct two_mode_system {
  using jacobian_type = Eigen::MatrixXd;
  static cplx lambda(int k, double mu) {
    return k == 0 ? cplx(-0.1, 1 + 0.5 * mu) : cplx(0.3 * (mu - 1.6), 2 - 0.5 * mu);
  }
  static Eigen::MatrixXd t(double mu) {
    Eigen::MatrixXd r0(6, 6), r1(6, 6);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        r0(i, j) = std::sin(1.7 * i + 2.3 * j + 0.4);
        r1(i, j) = std::cos(0.9 * i - 1.3 * j + 0.2);
      }
    return Eigen::MatrixXd::Identity(6, 6) + 0.3 * r0 + 0.1 * mu * r1;
  }
  static Eigen::MatrixXd a(double mu) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(6, 6);
    for (int k = 0; k < 2; ++k) {
      const cplx l = lambda(k, mu);
      d(2 * k, 2 * k) = d(2 * k + 1, 2 * k + 1) = l.real();
      d(2 * k, 2 * k + 1) = l.imag();
      d(2 * k + 1, 2 * k) = -l.imag();
    }
    d(4, 4) = -2;
    d(5, 5) = -3;
    const Eigen::MatrixXd tm = t(mu);
    return tm * d * tm.inverse();
  }
  static vec<cplx> eigenvector(int k, double mu) {
    vec<cplx> e = vec<cplx>::Zero(6);
    e[2 * k] = 1;
    e[2 * k + 1] = cplx(0, 1);
    return t(mu).cast<cplx>() * e;
  }
  Eigen::Index size() const { return 6; }
  vec<double> residual(const vec<double>& w, double mu) const { return a(mu) * w; }
  jacobian_type jacobian(const vec<double>&, double mu) const { return a(mu); }
};

const auto zero_state = [](double) { return vec<double>(vec<double>::Zero(6)); };

std::vector<double> grid(double first, double step, int n) {
  std::vector<double> m;
  for (int k = 0; k < n; ++k) m.push_back(first + step * k);
  return m;
}

cplx nearest(const Eigen::VectorXcd& ev, cplx z) {
  cplx best = ev[0];
  for (const auto& l : ev)
    if (std::abs(l - z) < std::abs(best - z)) best = l;
  return best;
}

vg_options two_mode_options() {
  vg_options o;
  o.tracked_size = 4;  // the "structure": entries 0..3
  // at the crossing the nearest eigenvalue is 0.82-0.87 times as far from the shift as the next:
  // enough iterations that the inverse power converges there (to the OTHER mode's eigenvalue, so
  // that the assignment by overlap decides, not a failed inverse power)
  o.inverse_power.max_iterations = 500;
  return o;
}

}  // namespace

// Through the frequency crossing at mu = 1 with a step of 0.2: the previous eigenvalue of mode 0
// is then NEARER mode 1's new eigenvalue (root_locus follows it there: checked below), and a
// frequency sort swaps the two past mu = 1. The tracked mode must stay the same eigenvector.
TEST(vg_diagram, follows_the_eigenvector_through_a_frequency_crossing) {
  const two_mode_system sys;
  const std::vector<double> mus = grid(0.05, 0.2, 10);  // 0.05 .. 1.85
  const vg_result r = vg_diagram(sys, zero_state, mus, {{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}}, two_mode_options());
  ASSERT_EQ(r.modes, 2);
  ASSERT_EQ(r.points.size(), 2 * mus.size());
  for (const auto& p : r.points) {
    const cplx exact = two_mode_system::lambda(p.mode, p.mu);
    const Eigen::VectorXcd ev = Eigen::EigenSolver<Eigen::MatrixXd>(two_mode_system::a(p.mu), false).eigenvalues();
    EXPECT_LT(std::abs(exact - nearest(ev, exact)), 1e-12) << "the closed form is an eigenvalue";
    EXPECT_LT(std::abs(p.lambda - exact), 1e-10) << "mode " << p.mode << " at mu = " << p.mu << ": " << p.lambda;
    EXPECT_NEAR(p.damping, 2 * exact.real() / exact.imag(), 1e-9);
    EXPECT_NEAR(p.frequency, exact.imag(), 1e-10);
    EXPECT_LE(p.residual, 1e-10);
  }
  // the frequency order swaps: a frequency sort would exchange the modes past mu = 1
  const auto m0 = r.mode(0), m1 = r.mode(1);
  EXPECT_LT(m0.front().frequency, m1.front().frequency);
  EXPECT_GT(m0.back().frequency, m1.back().frequency);
  // and the nearest-eigenvalue tracker (root_locus) from mode 0's start ends on mode 1 there
  inverse_power_options slow;  // the nearest eigenvalue is only 0.82 times as far as the next one
  slow.max_iterations = 500;
  const auto locus = root_locus(sys, std::function<vec<double>(double)>(zero_state), mus, cplx(0, 1.0), slow);
  EXPECT_LT(std::abs(locus.back().lambda - two_mode_system::lambda(1, mus.back())), 1e-10)
      << "the test case no longer discriminates: root_locus stays on mode 0";
  // flutter: mode 1 only, g rising through 0 at mu = 1.6 (between the listed 1.45 and 1.65)
  ASSERT_EQ(r.flutter.size(), 1u);
  EXPECT_EQ(r.flutter[0].mode, 1);
  // the cubic through g = 0.6 (mu - 1.6) / (2 - mu/2) at 1.25 .. 1.85
  EXPECT_NEAR(r.flutter[0].mu, 1.6, 1e-4);
  // the frequency 2 - mu/2 is linear in mu, so its cubic is exact at the located mu
  EXPECT_NEAR(r.flutter[0].frequency, 2 - 0.5 * r.flutter[0].mu, 1e-12);
  std::cout << std::setprecision(10) << "flutter at mu = " << r.flutter[0].mu << " (exact 1.6), " << r.inverse_powers << " inverse powers, "
            << r.subdivisions << " halved steps\n";
}

// With the tracked vectors (e.g. in-vacuo shapes) the modes are named by shape, not by shift:
// mode 0 is given the shift nearer mode 1's eigenvalue and mode 0's shape.
TEST(vg_diagram, tracked_start_vectors_name_the_modes) {
  const two_mode_system sys;
  const std::vector<double> mus = grid(0.05, 0.2, 10);
  const double mu0 = mus.front();
  std::vector<vg_mode_start> starts{{cplx(0, 1.9), two_mode_system::eigenvector(0, mu0).head(4)},
                                    {cplx(0, 1.1), two_mode_system::eigenvector(1, mu0).head(4)}};
  const vg_result r = vg_diagram(sys, zero_state, mus, starts, two_mode_options());
  for (const auto& p : r.points) EXPECT_LT(std::abs(p.lambda - two_mode_system::lambda(p.mode, p.mu)), 1e-10);
  EXPECT_GT(r.mode(0).front().overlap, 0.999);  // the start's shape is the exact one
}

// A tracked mode that moves fast past a fixed aerodynamic-like eigenvalue D = -0.15 + 0.76 i
// (the same coupling T(mu) as two_mode_system, so D's eigenvector shares the tracked part):
//   mode 0: lambda_0 = -0.1 + i (1 - 0.6 mu - 0.1 mu^2)
// Steps of 0.25 and min_overlap 0 (only the inverse power's shift decides): from mu = 0.25 to
// 0.5 the PREVIOUS eigenvalue (-0.1 + 0.844 i) is 0.098 from D and 0.169 from the mode's new
// one, so an inverse power shifted there converges to D; the secant prediction (-0.1 + 0.688 i)
// is 0.013 from the mode and 0.088 from D. The tracked eigenvalues must be the closed form's.
struct distractor_system : two_mode_system {
  static cplx lambda0(double mu) { return {-0.1, 1 - 0.6 * mu - 0.1 * mu * mu}; }
  static Eigen::MatrixXd a(double mu) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(6, 6);
    const cplx l[2] = {lambda0(mu), cplx(-0.15, 0.76)};
    for (int k = 0; k < 2; ++k) {
      d(2 * k, 2 * k) = d(2 * k + 1, 2 * k + 1) = l[k].real();
      d(2 * k, 2 * k + 1) = l[k].imag();
      d(2 * k + 1, 2 * k) = -l[k].imag();
    }
    d(4, 4) = -2;
    d(5, 5) = -3;
    const Eigen::MatrixXd tm = t(mu);
    return tm * d * tm.inverse();
  }
  vec<double> residual(const vec<double>& w, double mu) const { return a(mu) * w; }
  jacobian_type jacobian(const vec<double>&, double mu) const { return a(mu); }
};

TEST(vg_diagram, tracks_from_the_secant_prediction_past_a_nearby_eigenvalue) {
  const distractor_system sys;
  vg_options o = two_mode_options();
  o.min_overlap = 0.0;
  const vg_result r = vg_diagram(sys, zero_state, {0.0, 0.25, 0.5, 0.75}, {{cplx(0, 1.0), {}}}, o);
  ASSERT_TRUE(r.complete) << r.stop_reason;
  ASSERT_EQ(r.points.size(), 4u);
  for (const auto& p : r.points)
    EXPECT_LT(std::abs(p.lambda - distractor_system::lambda0(p.mu)), 1e-8) << "mu " << p.mu << ": " << p.lambda;
}

// One listed step of 1.8 across the crossing: the overlap test (min_overlap 0.999) halves it
// until the shapes agree, and the modes still come out right.
TEST(vg_diagram, halves_a_step_whose_overlap_is_too_low) {
  const two_mode_system sys;
  vg_options o = two_mode_options();
  o.min_overlap = 0.999;
  o.max_subdivisions = 8;
  const vg_result r = vg_diagram(sys, zero_state, {0.05, 1.85}, {{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}}, o);
  EXPECT_GT(r.subdivisions, 0);
  for (const auto& p : r.points) {
    EXPECT_LT(std::abs(p.lambda - two_mode_system::lambda(p.mode, p.mu)), 1e-10) << "mode " << p.mode << " mu " << p.mu;
    if (p.mu > 1) {
      EXPECT_GE(p.overlap, 0.999);
    }
  }
  // no halving allowed: a clear error instead of a swapped mode
  o.max_subdivisions = 0;
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.05, 1.85}, {{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}}, o), convergence_error);
}

// partial_on_lost_tracking: the same failure ends the diagram at the last parameter reached,
// with the reason, instead of throwing; the points before it are those of the full diagram.
TEST(vg_diagram, partial_diagram_ends_where_the_tracking_is_lost) {
  const two_mode_system sys;
  vg_options o = two_mode_options();
  o.min_overlap = 0.999;
  o.max_subdivisions = 0;
  o.partial_on_lost_tracking = true;
  const std::vector<cplx> shifts{cplx(0, 1.0), cplx(0, 2.0)};
  const vg_result r = vg_diagram(sys, zero_state, {0.05, 0.25, 1.85}, {{shifts[0], {}}, {shifts[1], {}}}, o);
  EXPECT_FALSE(r.complete);
  EXPECT_NE(r.stop_reason.find("mode tracking lost between mu = 0.25 and 1.85"), std::string::npos) << r.stop_reason;
  ASSERT_EQ(r.points.size(), 4u);  // two modes at 0.05 and 0.25
  for (const auto& p : r.points) {
    EXPECT_LE(p.mu, 0.25);
    EXPECT_LT(std::abs(p.lambda - two_mode_system::lambda(p.mode, p.mu)), 1e-10);
  }
  EXPECT_TRUE(vg_diagram(sys, zero_state, {0.05, 0.25}, {{shifts[0], {}}, {shifts[1], {}}}, o).complete);
}

// stop_after_flutter: the diagram ends one listed parameter after mode 1's g first rises
// through 0 (mu = 1.6, between 1.45 and 1.65), and that crossing is located as in the full one.
TEST(vg_diagram, stop_after_flutter_ends_one_parameter_after_the_first_rising_zero) {
  const two_mode_system sys;
  vg_options o = two_mode_options();
  o.stop_after_flutter = true;
  const std::vector<double> mus = grid(0.05, 0.2, 14);  // 0.05 .. 2.65
  const vg_result r = vg_diagram(sys, zero_state, mus, {{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}}, o);
  EXPECT_FALSE(r.complete);
  EXPECT_NE(r.stop_reason.find("stop_after_flutter"), std::string::npos) << r.stop_reason;
  const auto m1 = r.mode(1);
  ASSERT_FALSE(m1.empty());
  EXPECT_NEAR(m1.back().mu, 1.85, 1e-12);  // 1.65 has g > 0, then one more
  ASSERT_EQ(r.flutter.size(), 1u);
  EXPECT_EQ(r.flutter[0].mode, 1);
  EXPECT_NEAR(r.flutter[0].mu, 1.6, 1e-4);
}

// A solver object for every A - sigma I, and a factory of one solver per inverse power, give
// the same diagram as the default LU.
TEST(vg_diagram, solver_and_solver_factory_overloads) {
  const two_mode_system sys;
  const std::vector<double> mus = grid(0.05, 0.2, 10);
  const std::vector<vg_mode_start> starts{{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}};
  const vg_result ref = vg_diagram(sys, zero_state, mus, starts, two_mode_options());
  direct_solver<Eigen::MatrixXcd> lu("V-g dense LU");
  const vg_result a = vg_diagram(sys, zero_state, mus, starts, two_mode_options(), lu);
  int made = 0;
  auto factory = [&](const vec<double>&, double, cplx) {
    ++made;
    krylov_solver_options ko;
    ko.fill_level = 0;
    ko.krylov.relative_tolerance = 1e-13;
    return krylov_solver<Eigen::MatrixXcd>(ko, "V-g GMRES");
  };
  const vg_result b = vg_diagram(sys, zero_state, mus, starts, two_mode_options(), factory);
  EXPECT_EQ(made, b.inverse_powers);
  EXPECT_GT(b.linear_iterations, 0);
  ASSERT_EQ(a.points.size(), ref.points.size());
  ASSERT_EQ(b.points.size(), ref.points.size());
  for (std::size_t i = 0; i < ref.points.size(); ++i) {
    EXPECT_LT(std::abs(a.points[i].lambda - ref.points[i].lambda), 1e-12);
    EXPECT_LT(std::abs(b.points[i].lambda - ref.points[i].lambda), 1e-10);
  }
}

namespace {
// The two-mode system with its lag states first: w' = (w_4, w_5, w_0 .. w_3), A' = P A P^T. As an
// aeroelastic_system (2 "flow", 4 structural unknowns) its structural part is the tracked part
// of two_mode_options, found from the concept without offsets. claimed_flow: a layout that does
// not add up to size().
struct two_mode_aeroelastic {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index claimed_flow = 2;
  static Eigen::MatrixXd p() {
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(6, 6);
    for (int i = 0; i < 6; ++i) m(i, (i + 4) % 6) = 1;
    return m;
  }
  Eigen::Index size() const { return 6; }
  vec<double> residual(const vec<double>& w, double mu) const { return jacobian(w, mu) * w; }
  jacobian_type jacobian(const vec<double>&, double mu) const { return p() * two_mode_system::a(mu) * p().transpose(); }
  Eigen::Index flow_size() const { return claimed_flow; }
  Eigen::Index structure_size() const { return 4; }
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    require_size(v.size(), 6, "two_mode_aeroelastic::structure_part", "vector");
    return v.tail(4);
  }
};
static_assert(aeroelastic_system<two_mode_aeroelastic> && !aeroelastic_system<two_mode_system>);
}  // namespace

// An aeroelastic_system is tracked by its structure_part with the default tracked range: the
// same modes and flutter point as the explicit range of the unpermuted system, the 4-entry
// in-vacuo-like start shapes accepted (the whole vector would need 6), a bad layout refused.
TEST(vg_diagram, aeroelastic_system_is_tracked_by_its_structural_part_by_default) {
  const two_mode_aeroelastic sys;
  const std::vector<double> mus = grid(0.05, 0.2, 10);
  vg_options o;
  o.inverse_power.max_iterations = 500;
  ASSERT_EQ(o.tracked_offset, 0);
  ASSERT_EQ(o.tracked_size, 0);
  const double mu0 = mus.front();
  const std::vector<vg_mode_start> starts{{cplx(0, 1.9), two_mode_system::eigenvector(0, mu0).head(4)},
                                          {cplx(0, 1.1), two_mode_system::eigenvector(1, mu0).head(4)}};
  const vg_result r = vg_diagram(sys, zero_state, mus, starts, o);
  const vg_result ref = vg_diagram(two_mode_system{}, zero_state, mus, starts, two_mode_options());
  ASSERT_EQ(r.points.size(), ref.points.size());
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    EXPECT_EQ(r.points[i].mode, ref.points[i].mode);
    EXPECT_LT(std::abs(r.points[i].lambda - two_mode_system::lambda(r.points[i].mode, r.points[i].mu)), 1e-10);
    EXPECT_NEAR(r.points[i].overlap, ref.points[i].overlap, 1e-9);
  }
  ASSERT_EQ(r.flutter.size(), 1u);
  EXPECT_EQ(r.flutter[0].mode, 1);
  EXPECT_NEAR(r.flutter[0].mu, ref.flutter[0].mu, 1e-9);
  two_mode_aeroelastic bad;
  bad.claimed_flow = 3;
  EXPECT_THROW(vg_diagram(bad, zero_state, mus, starts, o), input_error);
}

TEST(vg_diagram, refuses_bad_input_with_context) {
  const two_mode_system sys;
  const std::vector<vg_mode_start> starts{{cplx(0, 1.0), {}}, {cplx(0, 2.0), {}}};
  const vg_options o = two_mode_options();
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.5, 0.5}, starts, o), input_error);       // not increasing
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.5, NAN}, starts, o), input_error);       // not finite
  EXPECT_THROW(vg_diagram(sys, zero_state, {}, starts, o), input_error);
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.5}, {}, o), input_error);
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.5}, {{cplx(0, 1), vec<cplx>::Ones(3)}}, o), input_error);  // size 3, not 4
  auto short_state = [](double) { return vec<double>(vec<double>::Zero(5)); };
  try {
    vg_diagram(sys, short_state, {0.5}, starts, o);
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("equilibrium(mu = 0.5) has 5 entries, expected 6"), std::string::npos) << e.what();
  }
  vg_options bad = o;
  bad.tracked_size = 7;
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.5}, starts, bad), input_error);
  // two starts on one eigenvalue, no shapes to tell them apart
  EXPECT_THROW(vg_diagram(sys, zero_state, {0.05}, {{cplx(0, 1.0), {}}, {cplx(0, 1.01), {}}}, o), input_error);
}

// Heavy case, very coarse grid, M = 0.5: the two structural modes from the in-vacuo shapes over
// Ubar = (0.7025 .. 1.3025) Ubar* in steps of 0.025 Ubar*; g of the flutter mode crosses zero at
// the Hopf point of the augmented-system Newton solve (an independent calculation).
TEST(vg_diagram, aerofoil_zero_damping_is_the_hopf_point) {
  const auto s = test_support::heavy_very_coarse_aerofoil(0.5);
  const hopf_result h = test_support::heavy_very_coarse_hopf(s);
  ASSERT_TRUE(h.report.converged);
  const vec<double> w = h.point.w;
  const double ubar_star = std::abs(h.point.mu), omega_star = h.point.omega;
  std::vector<double> mus;
  for (int k = 0; k <= 24; ++k) mus.push_back((0.7025 + 0.025 * k) * ubar_star);
  vg_options o;
  o.tracked_offset = s.flow_size();
  o.tracked_size = 4;
  const auto equilibrium = [&](double) { return w; };  // symmetric section: the same flow for every Ubar
  const auto starts = vg_mode_starts(s.structure().in_vacuo_matrix(mus.front()));
  ASSERT_EQ(starts.size(), 2u);  // plunge, pitch
  const vg_result r = vg_diagram(s, equilibrium, mus, starts, o);
  ASSERT_EQ(r.flutter.size(), 1u) << "one mode goes unstable in the range";
  const vg_flutter_point f = r.flutter[0];
  std::cout << std::setprecision(10) << "Hopf Ubar* = " << ubar_star << ", omega* = " << omega_star << "; V-g: mode "
            << f.mode << " at Ubar = " << f.mu << ", frequency " << f.frequency << " (" << r.inverse_powers
            << " inverse powers, " << r.subdivisions << " halved steps)\n";
  for (int k = 0; k < 2; ++k)
    for (const auto& p : r.mode(k))
      std::cout << "  mode " << k << " Ubar " << p.mu << " g " << p.damping << " freq " << p.frequency << " overlap "
                << p.overlap << "\n";
  // the resolution of the diagram (cubic interpolation over steps of 0.025 Ubar*; measured
  // 8.5e-5 and 2.6e-4 relative; 9e-4 and 1.3e-3 with steps of 0.05 Ubar*)
  EXPECT_NEAR(f.mu / ubar_star, 1.0, 2e-4);
  EXPECT_NEAR(f.frequency / omega_star, 1.0, 5e-4);
  // every reported eigenpair is one of A (residual test of the inverse power, relative to |lambda|)
  for (const auto& p : r.points) EXPECT_LE(p.residual, 1e-10);

  // the BILU-Krylov route for CFD sizes (vg_krylov_solvers): a fresh GMRES solver per inverse
  // power, preconditioned by the complex BILU(1) of the modified-order L - sigma I; the same diagram
  vg_krylov_options ko;
  ko.fill_level = 1;
  ko.krylov.relative_tolerance = 1e-11;
  ko.krylov.max_iterations = 1000;
  ko.krylov.restart = 60;
  const auto factory = vg_krylov_solvers<4>(s, ko);
  vg_options ok = o;
  ok.inverse_power.tolerance = 1e-10;
  const vg_result rk = vg_diagram(s, equilibrium, mus, starts, ok, factory);
  ASSERT_EQ(rk.points.size(), r.points.size());
  for (std::size_t i = 0; i < r.points.size(); ++i)
    EXPECT_LT(std::abs(rk.points[i].lambda - r.points[i].lambda), 1e-8 * std::abs(r.points[i].lambda));
  ASSERT_EQ(rk.flutter.size(), 1u);
  EXPECT_NEAR(rk.flutter[0].mu, f.mu, 1e-7 * f.mu);
  EXPECT_GT(rk.linear_iterations, 0);
  ko.fill_level = -1;
  EXPECT_THROW((void)vg_krylov_solvers<4>(s, ko), input_error);
}
