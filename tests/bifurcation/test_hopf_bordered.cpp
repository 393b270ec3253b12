// The bordered solvers of the fixed-equilibrium Hopf system (hopf_bordered.hpp) on the coupled Euler /
// pitch-plunge NACA 0012 (very coarse grid, light case, M = 0.5), against the independent
// reference of solve_hopf (real (2n+2) sparse LU of the augmented matrix): the same flutter
// point to 1e-9 from the same inverse-power start, the eigen-equation A p = i omega p satisfied,
// quadratic convergence of the exact variants, the GMRES iteration count reported, and the
// grid-sequencing transfer (prolong_from) giving a start on the coarse grid from which
// solve_hopf_krylov converges. Bad input is refused with a clear error.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/equilibrium_krylov.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include "support/bordered_test_system.hpp"
#include "support/hopf_test_systems.hpp"

#include <Eigen/Eigenvalues>

#include <complex>
#include <cstdlib>
#include <iomanip>
#include <iostream>

using namespace aerohopf;
using namespace aerohopf::flow;
using models::aerofoil_system;
using cplx = std::complex<double>;

namespace {

aerofoil_system make(int stride) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), stride), {.mach = 0.5, .alpha_rad = 0.0}),
                         structure::pitch_plunge(p));
}

struct fixture {
  aerofoil_system s = make(8);
  vec<double> w = s.steady_equilibrium();
  hopf_point start = hopf_start(s, w, 1.75, 0.6);
  hopf_options opt = [] {
    hopf_options o;
    o.fixed_equilibrium = true;
    return o;
  }();
};

const fixture& fix() {
  static const fixture f;
  return f;
}

const hopf_result& reference() {
  static const hopf_result r = solve_hopf(fix().s, fix().start, fix().opt);
  return r;
}

double eigen_residual(const aerofoil_system& s, const hopf_point& h) {
  const Eigen::SparseMatrix<cplx> a = s.jacobian(h.w, h.mu).cast<cplx>();
  return (a * h.p - cplx(0, h.omega) * h.p).norm() / h.p.norm();
}

}  // namespace

TEST(hopf_bordered, direct_complex_bordering_matches_the_augmented_lu) {
  const auto& f = fix();
  direct_solver<Eigen::SparseMatrix<cplx>> lu;
  const hopf_result r = solve_hopf_bordered(f.s, f.start, f.opt, lu);
  std::cout << "reference Ubar* " << reference().point.mu << " omega* " << reference().point.omega << "; bordered "
            << r.point.mu << " " << r.point.omega << " in " << r.report.iterations << " iterations\n";
  EXPECT_NEAR(r.point.mu, reference().point.mu, 1e-9);
  EXPECT_NEAR(r.point.omega, reference().point.omega, 1e-9);
  EXPECT_LT(eigen_residual(f.s, r.point), 1e-9);
  EXPECT_EQ(r.linear_iterations, 0);
  EXPECT_LE(r.report.iterations, 6);
}

TEST(hopf_bordered, krylov_newton_matches_and_converges_quadratically) {
  const auto& f = fix();
  for (bool reuse : {false, true}) {
    hopf_krylov_options ko;
    ko.fill_level = 1;
    ko.reuse_matrices = reuse;
    const hopf_result r = solve_hopf_krylov<4>(f.s, f.start, f.opt, ko);
    const auto& h = r.report.residual_history;
    std::cout << "reuse " << reuse << ": Ubar* " << r.point.mu << " omega* " << r.point.omega << ", "
              << r.report.iterations << " Newton iterations, " << r.linear_iterations << " GMRES iterations; |F|:";
    for (double x : h) std::cout << " " << x;
    std::cout << "\n";
    EXPECT_NEAR(r.point.mu, reference().point.mu, 1e-9);
    EXPECT_NEAR(r.point.omega, reference().point.omega, 1e-9);
    EXPECT_LT(eigen_residual(f.s, r.point), 1e-9);
    EXPECT_GT(r.linear_iterations, 0);
    EXPECT_LE(r.report.iterations, 7);
    EXPECT_GT(r.setup_seconds, 0.0);  // the timing split is filled in
    EXPECT_GT(r.linear_seconds, 0.0);
    EXPECT_GT(r.residual_seconds, 0.0);
    ASSERT_GE(h.size(), 3u);
    if (!reuse) {  // exact Newton with inexact (eta = O(|F|)) solves: at least superlinear
      for (std::size_t k = 1; k + 1 < h.size(); ++k)
        if (h[k] < 1e-3 && h[k + 1] > 1e-10) {
          EXPECT_LT(h[k + 1], 10 * h[k] * h[k] + 1e-2 * h[k]) << "step " << k;
        }
    }
  }
}

// Every linear strategy of hopf_newton in both formulations on the symmetric section (the
// equilibrium does not move with Ubar, so the full formulation lands on the same point, its flow
// part on the steady solution): against the fixed-equilibrium sparse-LU reference.
TEST(hopf_bordered, every_strategy_every_formulation_matches_the_augmented_lu) {
  const auto& f = fix();
  const hopf_point& ref = reference().point;
  for (const bool fixed : {true, false}) {
    hopf_options o = f.opt;
    o.fixed_equilibrium = fixed;
    o.label = fixed ? "fixed" : "full";
    const hopf_problem<aerofoil_system> prob(f.s, f.start, o, "test");
    hopf_augmented_lu<aerofoil_system> lu(o);
    direct_solver<Eigen::SparseMatrix<cplx>> complex_lu;
    hopf_bordered_direct<aerofoil_system, direct_solver<Eigen::SparseMatrix<cplx>>> direct(o, complex_lu);
    hopf_krylov_options ko;
    ko.fill_level = 1;
    ko.full_system = !fixed;
    hopf_bordered_krylov<4, aerofoil_system> krylov(o, ko);
    const hopf_result r[] = {hopf_newton(prob, lu, o), hopf_newton(prob, direct, o), hopf_newton(prob, krylov, o)};
    const char* names[] = {"augmented LU", "bordered direct", "bordered Krylov"};
    for (int k = 0; k < 3; ++k) {
      std::cout << o.label << ", " << names[k] << ": Ubar* " << std::setprecision(12) << r[k].point.mu << " omega* "
                << r[k].point.omega << ", " << r[k].report.iterations << " Newton, " << r[k].linear_iterations
                << " linear iterations, " << r[k].setup_seconds + r[k].linear_seconds + r[k].residual_seconds
                << " s\n";
      ASSERT_TRUE(r[k].report.converged) << names[k];
      EXPECT_NEAR(r[k].point.mu, ref.mu, (fixed ? 1e-9 : 1e-8) * ref.mu) << names[k];
      EXPECT_NEAR(r[k].point.omega, ref.omega, (fixed ? 1e-9 : 1e-8) * ref.omega) << names[k];
      EXPECT_NEAR(r[k].point.mu, r[0].point.mu, 1e-9 * ref.mu) << names[k];
      EXPECT_NEAR(r[k].point.omega, r[0].point.omega, 1e-9 * ref.omega) << names[k];
      EXPECT_LT((r[k].point.w - f.w).norm(), 1e-7 * f.w.norm()) << names[k];
      EXPECT_LT(eigen_residual(f.s, r[k].point), 1e-9) << names[k];
      EXPECT_LE(r[k].report.iterations, 7) << names[k];
    }
  }
}

TEST(hopf_bordered, grid_sequencing_start_from_the_coarser_grid) {
  const auto& f = fix();
  const aerofoil_system fine = make(4);
  const vec<double> wf = fine.steady_equilibrium();
  // injection keeps a uniform field exactly and preserves the mean of any field (4 equal children)
  EXPECT_EQ((fine.prolong_from(f.s, 2, f.s.free_stream_state()) - fine.free_stream_state()).norm(), 0.0);
  const vec<double> wi = fine.prolong_from(f.s, 2, f.w);
  EXPECT_NEAR(wi.head(fine.flow_size()).sum(), 4 * f.w.head(f.s.flow_size()).sum(), 1e-9 * wi.sum());
  hopf_point g = reference().point;
  g.w = wf;
  g.p = fine.prolong_from<cplx>(f.s, 2, reference().point.p);
  hopf_krylov_options ko;
  const hopf_result r = solve_hopf_krylov<4>(fine, g, f.opt, ko);
  std::cout << "coarse grid from the very coarse point: Ubar* " << r.point.mu << " omega* " << r.point.omega << " in "
            << r.report.iterations << " Newton iterations\n";
  EXPECT_LT(eigen_residual(fine, r.point), 1e-9);
  EXPECT_NEAR(r.point.mu, reference().point.mu, 0.05);  // grid convergence: close, not equal
  EXPECT_NEAR(r.point.omega, reference().point.omega, 0.02);
  EXPECT_LE(r.report.iterations, 6);
}

// The start refinement (hopf_krylov_options::start_iterations): a continuation-like guess whose
// eigenvector carries a large wrong component (half its norm, spread over the flow unknowns as
// when shocks move) and whose Ubar, omega are off by 2 %: one inverse iteration must lower the
// Hopf residual at the guess by more than 10x, be kept, and Newton must land on the same point
// as the reference in no more iterations than from the raw guess. An exact guess must not be
// spoilt: the refinement raises ||F|| there, so it is discarded.
TEST(hopf_bordered, start_refinement_recovers_a_poor_eigenvector_guess) {
  const auto& f = fix();
  const hopf_point& ref = reference().point;
  hopf_point g = ref;
  g.mu *= 1.02;
  g.omega *= 0.98;
  std::srand(7);
  vec<cplx> noise = vec<cplx>::Random(ref.p.size());
  noise.tail(aerofoil_system::n_structure).setZero();
  g.p += (0.5 * ref.p.norm() / noise.norm()) * noise;
  hopf_krylov_options raw;
  raw.fill_level = 1;
  hopf_options verbose = f.opt;
  verbose.verbose = true;
  verbose.label = "raw guess";
  const hopf_result r0 = solve_hopf_krylov<4>(f.s, g, verbose, raw);
  hopf_krylov_options refined = raw;
  refined.start_iterations = 1;
  verbose.label = "refined guess";
  const hopf_result r1 = solve_hopf_krylov<4>(f.s, g, verbose, refined);
  std::cout << "Newton iterations from the perturbed guess: raw " << r0.report.iterations << ", refined "
            << r1.report.iterations << " (|F| at the start " << r0.report.residual_history.front() << " -> "
            << r1.report.residual_history.front() << ")\n";
  EXPECT_TRUE(r1.start_refined);
  EXPECT_FALSE(r0.start_refined);
  EXPECT_LT(r1.report.residual_history.front(), 0.1 * r0.report.residual_history.front());
  EXPECT_LE(r1.report.iterations, r0.report.iterations);
  EXPECT_NEAR(r1.point.mu, ref.mu, 1e-9);
  EXPECT_NEAR(r1.point.omega, ref.omega, 1e-9);
  EXPECT_LT(eigen_residual(f.s, r1.point), 1e-9);
  EXPECT_GT(r1.linear_iterations, r1.report.iterations);  // the start's GMRES iterations are counted

  hopf_krylov_options above = refined;  // a guess below the threshold is not refined
  above.start_residual_threshold = 2 * r0.report.residual_history.front();
  EXPECT_FALSE(solve_hopf_krylov<4>(f.s, g, f.opt, above).start_refined);

  verbose.label = "exact guess";
  const hopf_result r2 = solve_hopf_krylov<4>(f.s, ref, verbose, refined);
  EXPECT_FALSE(r2.start_refined);
  // the singular start solve is capped (hopf_krylov_options::start_max_iterations)
  EXPECT_LE(r2.linear_iterations, refined.start_max_iterations + 100);
  EXPECT_NEAR(r2.point.mu, ref.mu, 1e-9);
  EXPECT_LE(r2.report.iterations, 1);
}

TEST(hopf_bordered, refuses_bad_input) {
  const auto& f = fix();
  hopf_options not_sym = f.opt;
  not_sym.fixed_equilibrium = false;
  EXPECT_THROW(solve_hopf_krylov<4>(f.s, f.start, not_sym), input_error);
  hopf_point bad = f.start;
  bad.p.resize(3);
  EXPECT_THROW(solve_hopf_krylov<4>(f.s, bad, f.opt), input_error);
  bad = f.start;
  bad.omega = NAN;
  direct_solver<Eigen::SparseMatrix<cplx>> lu;
  EXPECT_THROW(solve_hopf_bordered(f.s, bad, f.opt, lu), input_error);
  EXPECT_THROW(make(8).prolong_from<double>(f.s, 2, vec<double>::Zero(7)), input_error);
  EXPECT_THROW((prolong_cells<2, double>(f.s.flow().grid().topology, f.s.flow().grid().topology, 2,
                                         vec<double>::Zero(f.s.flow_size()), 4)),
               input_error);
}

// ---- hostile input on the small systems of tests/support/hopf_test_systems.hpp (real
// eigenvalue mu, Hopf pair mu - 1 +- 2i, equilibrium w*(mu) = c mu), for the complex bordering
// (dense LU) and the Krylov solver (sparse Jacobian, B = 2) ----
namespace {
using test_support::faulty_system;
using test_support::moving_equilibrium_system;
using dense_sys = moving_equilibrium_system<Eigen::MatrixXd>;
using sparse_sys = moving_equilibrium_system<Eigen::SparseMatrix<double>>;
using test_support::moving_c;

hopf_options fixed_options(double tol = 1e-10) {
  hopf_options o;
  o.fixed_equilibrium = true;
  o.newton.abs_tolerance = tol;
  return o;
}

/// Both bordered solvers on system type D (dense, bordering) and Sp (sparse, Krylov).
template <class D, class Sp>
std::pair<hopf_result, hopf_result> both(const D& d, const Sp& sp, const hopf_point& g, const hopf_options& o,
                                         const hopf_krylov_options& ko = {}) {
  direct_solver<Eigen::MatrixXcd> lu;
  hopf_result a = solve_hopf_bordered(d, g, o, lu);
  hopf_result b = solve_hopf_krylov<2>(sp, g, o, ko);
  return {std::move(a), std::move(b)};
}

/// Guess near the real eigenvalue at mu = 0 (Newton converges to omega ~ 1e-11 at tolerance 1e-8).
hopf_point real_eigenvalue_guess(const dense_sys& s, double mu0) {
  hopf_point g = hopf_start(s, s.equilibrium(mu0), mu0, 0.3);
  vec<cplx> q(4);
  q << cplx(0.1, 0.7), cplx(-0.4, 0.2), cplx(0.3, -0.5), cplx(0.6, 0.1);
  g.p += 0.3 * q;
  return g;
}
}  // namespace

TEST(hopf_bordered_hostile, moving_or_stale_equilibrium_is_refused) {
  const dense_sys d(moving_c);
  const sparse_sys sp(moving_c);
  for (double mu_w : {0.9, 0.3}) {  // the equilibrium at the guess's mu, and a stale one
    hopf_point g = hopf_start(d, d.equilibrium(1.0), 0.9, 1.9);
    g.w = d.equilibrium(mu_w);
    const hopf_point copy = g;
    hopf_options o = fixed_options();
    direct_solver<Eigen::MatrixXcd> lu;
    try {
      solve_hopf_bordered(d, g, o, lu);
      ADD_FAILURE() << "bordered: accepted";
    } catch (const convergence_error& e) {
      EXPECT_NE(std::string(e.what()).find("equilibrium does not hold at mu*"), std::string::npos) << e.what();
    }
    try {
      solve_hopf_krylov<2>(sp, g, o);
      ADD_FAILURE() << "krylov: accepted";
    } catch (const convergence_error& e) {
      EXPECT_NE(std::string(e.what()).find("equilibrium does not hold at mu*"), std::string::npos) << e.what();
    }
    o.newton.throw_on_failure = false;
    const auto [a, b] = both(d, sp, g, o);
    EXPECT_FALSE(a.report.converged);
    EXPECT_FALSE(b.report.converged);
    EXPECT_NE(b.report.reason.find("||f(w, mu*)||"), std::string::npos) << b.report.reason;
    EXPECT_EQ(g.w, copy.w);
    EXPECT_EQ(g.p, copy.p);
  }
  // the same guess with the true equilibrium at mu* = 1 (w* = c) converges in both
  hopf_point g = hopf_start(d, d.equilibrium(1.0), 0.9, 1.9);
  const auto [a, b] = both(d, sp, g, fixed_options());
  ASSERT_TRUE(a.report.converged);
  ASSERT_TRUE(b.report.converged);
  EXPECT_NEAR(a.point.mu, 1.0, 1e-10);
  EXPECT_NEAR(b.point.mu, 1.0, 1e-10);
  EXPECT_NEAR(a.point.omega, 2.0, 1e-10);
  EXPECT_NEAR(b.point.omega, 2.0, 1e-10);
}

TEST(hopf_bordered_hostile, unresolved_frequency_is_refused) {
  const dense_sys d;
  const sparse_sys sp;
  const hopf_point g = real_eigenvalue_guess(d, 0.2);
  hopf_options o = fixed_options(1e-8);
  o.newton.throw_on_failure = false;
  hopf_krylov_options ko;
  ko.reuse_matrices = false;
  const auto [a, b] = both(d, sp, g, o, ko);
  EXPECT_FALSE(a.report.converged) << "omega " << a.point.omega;
  EXPECT_FALSE(b.report.converged) << "omega " << b.point.omega;
  EXPECT_NE(a.report.reason.find("real eigenvalue"), std::string::npos) << a.report.reason;
  EXPECT_NE(b.report.reason.find("real eigenvalue"), std::string::npos) << b.report.reason;
  o.newton.throw_on_failure = true;
  direct_solver<Eigen::MatrixXcd> lu;
  EXPECT_THROW(solve_hopf_bordered(d, g, o, lu), convergence_error);
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, o, ko), convergence_error);
}

TEST(hopf_bordered_hostile, nan_residual_is_reported_with_the_last_good_iterate) {
  const dense_sys d;
  const sparse_sys sp;
  hopf_point g = hopf_start(d, d.equilibrium(0.0), 0.6, 1.2);
  g.p += 0.2 * vec<cplx>::Ones(4);
  const hopf_point copy = g;
  hopf_options o = fixed_options();
  o.label = "injected bordered";
  const auto [ra, rb] = both(d, sp, g, o);
  ASSERT_TRUE(ra.report.converged);
  ASSERT_TRUE(rb.report.converged);
  ASSERT_GE(rb.report.iterations, 3);
  // each residual evaluation is one jet pass (A p_r and A p_i): call 3 is the residual at iterate 2
  direct_solver<Eigen::MatrixXcd> lu;
  const auto check = [&](const std::string& m) {
    for (const char* part : {"injected bordered", "last accepted iterate", "||F|| = ", "mu = ", "omega = "})
      EXPECT_NE(m.find(part), std::string::npos) << part << " not in: " << m;
  };
  try {
    solve_hopf_bordered(faulty_system(d, 3), g, o, lu);
    ADD_FAILURE() << "bordered: no exception";
  } catch (const convergence_error& e) {
    check(e.what());
  }
  try {
    solve_hopf_krylov<2>(faulty_system(sp, 3), g, o);
    ADD_FAILURE() << "krylov: no exception";
  } catch (const convergence_error& e) {
    check(e.what());
  }
  o.newton.throw_on_failure = false;
  const hopf_result bad = solve_hopf_krylov<2>(faulty_system(sp, 3), g, o);
  EXPECT_FALSE(bad.report.converged);
  check(bad.report.reason);
  ASSERT_TRUE(bad.point.p.allFinite() && std::isfinite(bad.point.mu) && std::isfinite(bad.point.omega));
  o.newton.throw_on_failure = true;
  const hopf_result again = solve_hopf_krylov<2>(sp, bad.point, o);
  EXPECT_NEAR(again.point.mu, rb.point.mu, 1e-10);
  EXPECT_NEAR(again.point.omega, rb.point.omega, 1e-10);
  EXPECT_EQ(g.p, copy.p);
  EXPECT_EQ(g.mu, copy.mu);
}

TEST(hopf_bordered_hostile, krylov_options_are_checked) {
  const sparse_sys sp;
  const hopf_point g = hopf_start(sp, sp.equilibrium(0.0), 0.9, 1.9);
  const hopf_options o = fixed_options();
  auto message = [&](const hopf_krylov_options& ko) -> std::string {
    try {
      solve_hopf_krylov<2>(sp, g, o, ko);
    } catch (const input_error& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("wrong exception type: ") + e.what();
    }
    return "no exception";
  };
  hopf_krylov_options k;
  k.fill_level = -1;
  EXPECT_NE(message(k).find("fill_level"), std::string::npos) << message(k);
  k = {};
  k.eta_max = 0;
  EXPECT_NE(message(k).find("eta_max"), std::string::npos) << message(k);
  k = {};
  k.forcing_exponent = NAN;
  EXPECT_NE(message(k).find("forcing_exponent"), std::string::npos) << message(k);
  k = {};
  k.start_tolerance = 1.5;
  EXPECT_NE(message(k).find("start_tolerance"), std::string::npos) << message(k);
  k = {};
  k.reuse_window = -1;
  EXPECT_NE(message(k).find("reuse_window"), std::string::npos) << message(k);
  k = {};
  k.start_max_iterations = 0;
  EXPECT_NE(message(k).find("start_max_iterations"), std::string::npos) << message(k);
  hopf_options bad = o;
  bad.newton.max_iterations = -3;
  direct_solver<Eigen::MatrixXcd> lu;
  const dense_sys d;
  EXPECT_THROW(solve_hopf_bordered(d, g, bad, lu), input_error);
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, bad), input_error);
  hopf_point short_w = g;
  short_w.w = vec<double>::Zero(2);
  EXPECT_THROW(solve_hopf_krylov<2>(sp, short_w, o), input_error);
  EXPECT_THROW(solve_hopf_bordered(d, short_w, o, lu), input_error);
}

// ---- the full formulation (hopf_krylov_options::full_system: [w, p_r, p_i, mu, omega], the
// equilibrium moving with mu) and the Krylov inverse-power start (hopf_start_krylov) ----
namespace {
hopf_options full_options(double tol = 1e-10) {
  hopf_options o;
  o.fixed_equilibrium = false;
  o.newton.abs_tolerance = tol;
  return o;
}
/// A guess off the equilibrium branch (w of mu = 0.7 moved off it) with the eigenvector there.
hopf_point far_guess(const sparse_sys& sp) {
  hopf_point g = hopf_start(sp, sp.equilibrium(0.7), 0.7, 1.7);
  vec<double> d(4);
  d << 1.0, -1.0, 1.0, 0.5;
  g.w += 0.05 * d;
  return g;
}
hopf_krylov_options full_krylov(int fill = 1) {
  hopf_krylov_options k;
  k.full_system = true;
  k.fill_level = fill;
  return k;
}
}  // namespace

// The second-derivative product B(u, v) = (A_w u) v by taylor<double, 2> polarisation against
// central differences of the assembled Jacobian (system.hpp's jacobian_directional), and its
// symmetry.
TEST(hopf_bordered_full, second_derivative_product_matches_differenced_jacobians) {
  const sparse_sys sp(moving_c);
  vec<double> w(4), u(4), v(4);
  w << 0.3, -0.2, 0.5, 0.1;
  u << 1.0, -0.4, 0.3, 0.8;
  v << -0.2, 0.9, 0.5, -0.6;
  const double mu = 0.7;
  const vec<double> b = aerohopf::internal::second_derivative_product(sp, w, mu, u, v);
  const vec<double> fd = jacobian_directional(sp, w, mu, u) * v;
  EXPECT_LT((b - fd).norm(), 1e-8 * fd.norm()) << b.transpose() << " vs " << fd.transpose();
  EXPECT_LT((b - aerohopf::internal::second_derivative_product(sp, w, mu, v, u)).norm(), 1e-13 * b.norm());
  EXPECT_GT(b.norm(), 1e-3);
  EXPECT_EQ(aerohopf::internal::second_derivative_product(sp, w, mu, u, vec<double>(vec<double>::Zero(4))).norm(), 0.0);
  // the differenced pair (jet<double, 2> Jacobian products at w +- h v) against the exact one
  const auto [dr, di] = aerohopf::internal::second_derivative_pair(sp, w, mu, u, w, v, false);
  const auto [er, ei] = aerohopf::internal::second_derivative_pair(sp, w, mu, u, w, v, true);
  EXPECT_LT((dr - b).norm(), 1e-8 * b.norm());
  EXPECT_LT((er - b).norm(), 1e-14 * b.norm());
  EXPECT_LT((di - ei).norm(), 1e-8 * ei.norm());
}

// The small system with w*(mu) = c mu: the full Krylov solve lands on the known Hopf point
// (mu* = 1, omega* = 2, w* = c) and on the full sparse-LU solve (solve_hopf), quadratically,
// with the equilibrium part moved from the guess's mu; hopf_start_krylov equals hopf_start.
TEST(hopf_bordered_full, small_moving_equilibrium_krylov_matches_lu) {
  const sparse_sys sp(moving_c);
  const hopf_point g0 = far_guess(sp);
  eigen_pair info;
  hopf_point g = hopf_start_krylov<2>(sp, sp.equilibrium(0.7), 0.7, 1.7, {}, &info);
  g.w = g0.w;
  EXPECT_NEAR(g.omega, g0.omega, 1e-8);
  EXPECT_GT(info.linear_iterations, 0);
  EXPECT_NEAR(std::abs(g.p.dot(g0.p)), 1.0, 1e-8);  // the same unit eigenvector up to phase
  const hopf_result lu = solve_hopf(sp, g, full_options());
  for (const bool exact : {false, true}) {
    hopf_options vo = full_options();
    vo.verbose = true;
    vo.label = exact ? "full krylov (small, exact B)" : "full krylov (small)";
    hopf_krylov_options ko = full_krylov();
    ko.exact_second_derivatives = exact;
    const hopf_result kr = solve_hopf_krylov<2>(sp, g, vo, ko);
    ASSERT_TRUE(kr.report.converged);
    EXPECT_NEAR(kr.point.mu, 1.0, 1e-10);
    EXPECT_NEAR(kr.point.omega, 2.0, 1e-10);
    EXPECT_LT((kr.point.w - sp.equilibrium(1.0)).norm(), 1e-10);
    EXPECT_NEAR(kr.point.mu, lu.point.mu, 1e-12);
    EXPECT_NEAR(kr.point.omega, lu.point.omega, 1e-12);
    EXPECT_LT((kr.point.w - lu.point.w).norm(), 1e-10);
    EXPECT_GT(kr.linear_iterations, 0);
    EXPECT_LE(kr.report.iterations, lu.report.iterations + 1);
    EXPECT_GE(kr.report.iterations, 3);
    const auto& h = kr.report.residual_history;
    for (std::size_t k = 1; k + 1 < h.size(); ++k)
      if (h[k] < 1e-2 && h[k + 1] > 1e-12) {
        EXPECT_LT(h[k + 1], 10 * h[k] * h[k] + 1e-2 * h[k]) << "step " << k;
      }
  }
  // the fixed-equilibrium Krylov solve of the same guess is refused by its post-check
  hopf_options fixed = fixed_options();
  fixed.newton.throw_on_failure = false;
  const hopf_result sym = solve_hopf_krylov<2>(sp, g, fixed);
  EXPECT_FALSE(sym.report.converged);
  EXPECT_NE(sym.report.reason.find("equilibrium does not hold at mu*"), std::string::npos) << sym.report.reason;
}

TEST(hopf_bordered_full, full_formulation_hostile_input) {
  const sparse_sys sp(moving_c);
  const hopf_point g = far_guess(sp);
  ASSERT_GE(solve_hopf_krylov<2>(sp, g, full_options(), full_krylov()).report.iterations, 3);
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, full_options()), input_error);  // full_system not set
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, fixed_options(), full_krylov()), input_error);  // symmetric set
  hopf_krylov_options k = full_krylov();
  k.start_iterations = 1;
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, full_options(), k), input_error);
  k = full_krylov();
  k.fill_level = -2;
  EXPECT_THROW(solve_hopf_krylov<2>(sp, g, full_options(), k), input_error);
  hopf_point bad = g;
  bad.w[1] = NAN;
  EXPECT_THROW(solve_hopf_krylov<2>(sp, bad, full_options(), full_krylov()), input_error);
  // a NaN residual inside the run (call 15: 2 calls per residual of F, f and one jet pass for
  // A p_r and A p_i; 5 per step with f_mu and the four differenced second-derivative passes, so
  // the residual at iterate 2): the last accepted iterate is named, or returned
  hopf_options o = full_options();
  o.label = "injected full";
  try {
    solve_hopf_krylov<2>(faulty_system(sp, 15), g, o, full_krylov());
    ADD_FAILURE() << "no exception";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("last accepted iterate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("injected full"), std::string::npos) << e.what();
  }
  // a NaN in f_mu inside a step (call 17, the first of step 3): a failed step, not bad input
  // to GMRES; and in a second-derivative pass of that step (call 18)
  for (const long at : {17L, 18L}) {
    try {
      solve_hopf_krylov<2>(faulty_system(sp, at), g, o, full_krylov());
      ADD_FAILURE() << "no exception, fault at call " << at;
    } catch (const convergence_error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(at == 17 ? "f_mu" : "second-derivative product"), std::string::npos) << m;
      EXPECT_NE(m.find("last accepted iterate 2"), std::string::npos) << m;
    }
  }
  o.newton.throw_on_failure = false;
  const hopf_result r = solve_hopf_krylov<2>(faulty_system(sp, 15), g, o, full_krylov());
  EXPECT_FALSE(r.report.converged);
  EXPECT_TRUE(r.point.w.allFinite() && r.point.p.allFinite());
  // hopf_start_krylov input checks
  EXPECT_THROW(hopf_start_krylov<2>(sp, vec<double>(vec<double>::Zero(3)), 0.9, 1.9), input_error);
  EXPECT_THROW(hopf_start_krylov<2>(sp, sp.equilibrium(0.9), 0.9, NAN), input_error);
  hopf_start_krylov_options so;
  so.inverse_power.max_iterations = 0;
  EXPECT_THROW(hopf_start_krylov<2>(sp, sp.equilibrium(0.9), 0.9, 1.9, so), input_error);
  so = {};
  so.inverse_power.max_iterations = 1;
  so.inverse_power.tolerance = 1e-14;
  EXPECT_THROW(hopf_start_krylov<2>(sp, sp.equilibrium(0.9), 0.9, 1.9, so), convergence_error);
}

// The bordered direct strategy in the full formulation on the small moving-equilibrium system
// (dense complex LU, real LU for the flow update): the known point, as fast as the augmented LU;
// a NaN residual inside the run names (or returns) the last accepted iterate.
TEST(hopf_bordered_full, small_moving_equilibrium_bordered_direct) {
  const dense_sys d(moving_c);
  const hopf_point g = far_guess(sparse_sys(moving_c));
  direct_solver<Eigen::MatrixXcd> lu;
  const hopf_result lu_full = solve_hopf(d, g, full_options());
  const hopf_result r = solve_hopf_bordered(d, g, full_options(), lu);
  ASSERT_TRUE(r.report.converged) << r.report.reason;
  EXPECT_NEAR(r.point.mu, 1.0, 1e-10);
  EXPECT_NEAR(r.point.omega, 2.0, 1e-10);
  EXPECT_LT((r.point.w - d.equilibrium(1.0)).norm(), 1e-10);
  EXPECT_LE(r.report.iterations, lu_full.report.iterations + 1);
  hopf_options o = full_options();
  o.label = "injected bordered full";
  try {
    solve_hopf_bordered(faulty_system(d, 15), g, o, lu);
    ADD_FAILURE() << "no exception";
  } catch (const convergence_error& e) {
    EXPECT_NE(std::string(e.what()).find("last accepted iterate"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("injected bordered full"), std::string::npos) << e.what();
  }
  o.newton.throw_on_failure = false;
  const hopf_result bad = solve_hopf_bordered(faulty_system(d, 15), g, o, lu);
  EXPECT_FALSE(bad.report.converged);
  EXPECT_TRUE(bad.point.w.allFinite() && bad.point.p.allFinite());
  const hopf_result again = solve_hopf_bordered(d, bad.point, full_options(), lu);
  EXPECT_TRUE(again.report.converged);
  EXPECT_NEAR(again.point.mu, 1.0, 1e-10);
}

// ---- the NACA 0012 pitch-plunge at a mean incidence alpha_0 = 1 deg (very coarse grid, light
// case, M = 0.5): the steady flow lifts and pitches the section, so the equilibrium (its static
// pitch and plunge deflection) depends on Ubar and only the full formulation applies ----
namespace {
constexpr double alpha0 = 1.0 * 3.14159265358979323846 / 180.0;

aerofoil_system make_incidence(int stride, double mach) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), stride), {.mach = mach, .alpha_rad = alpha0}),
                         structure::pitch_plunge(p));
}

struct incidence_fixture {
  aerofoil_system s = make_incidence(8, 0.5);
  // the steady flow with the section at rest (loaded: not an equilibrium of the coupled system)
  vec<double> rest = s.steady_equilibrium({}, INFINITY);
  /// The static aeroelastic equilibrium at ubar: Newton-Krylov on the coupled system from w0.
  vec<double> static_equilibrium(double ubar, const vec<double>& w0) const {
    equilibrium_krylov_options eo;
    eo.newton.abs_tolerance = 1e-11;
    // full Newton steps: from the loaded rest state the first step raises ||f|| 100x (the
    // deflection it jumps to, alpha = 1.6 deg at Ubar = 1.75, exceeds alpha_0) and the halving
    // line search crawls instead (measured: ||f|| 0.030 -> 0.025 in 20 iterations; 6 without)
    eo.newton.line_search = false;
    return solve_equilibrium_krylov<4>(s, ubar, w0, eo, "static aeroelastic solve").w;
  }
  vec<double> w_guess = static_equilibrium(1.75, rest);
  hopf_point start = hopf_start_krylov<4>(s, w_guess, 1.75, 0.6);
  hopf_result lu = solve_hopf(s, start, full_options());
  hopf_result krylov = [this] {
    hopf_options o = full_options();
    o.verbose = true;
    o.label = "full krylov, alpha_0 = 1 deg";
    return solve_hopf_krylov<4>(s, start, o, full_krylov());
  }();
  hopf_result direct = [this] {
    direct_solver<Eigen::SparseMatrix<cplx>> lu;
    return solve_hopf_bordered(s, start, full_options(), lu);
  }();
};

const incidence_fixture& incidence() {
  static const incidence_fixture f;
  return f;
}
double pitch(const aerofoil_system& s, const vec<double>& w) { return w[s.flow_size() + 2]; }
}  // namespace

TEST(hopf_bordered_full, incidence_krylov_full_matches_lu_full) {
  const auto& f = incidence();
  const hopf_point &k = f.krylov.point, &l = f.lu.point;
  {
    hopf_krylov_options ko = full_krylov();
    ko.exact_second_derivatives = true;
    const hopf_result e = solve_hopf_krylov<4>(f.s, f.start, full_options(), ko);
    EXPECT_NEAR(e.point.mu, l.mu, 1e-8 * l.mu);
    EXPECT_NEAR(e.point.omega, l.omega, 1e-8 * l.omega);
    EXPECT_EQ(e.report.iterations, f.krylov.report.iterations);
  }
  std::cout << "alpha_0 = 1 deg: LU Ubar* " << std::setprecision(12) << l.mu << " omega* " << l.omega << " ("
            << f.lu.report.iterations << " Newton); Krylov " << k.mu << " " << k.omega << " ("
            << f.krylov.report.iterations << " Newton, " << f.krylov.linear_iterations << " GMRES); static pitch "
            << pitch(f.s, k.w) << " rad at Ubar*, " << pitch(f.s, f.w_guess) << " at 1.75\n";
  ASSERT_TRUE(f.krylov.report.converged);
  EXPECT_NEAR(k.mu, l.mu, 1e-8 * l.mu);
  EXPECT_NEAR(k.omega, l.omega, 1e-8 * l.omega);
  EXPECT_LT((k.w - l.w).norm(), 1e-7 * l.w.norm());
  EXPECT_LT(eigen_residual(f.s, k), 1e-9);
  EXPECT_LE(f.krylov.report.iterations, 7);
  // the deflection is real and moves with Ubar (else the fixed-equilibrium system would do)
  EXPECT_GT(std::abs(pitch(f.s, k.w)), 1e-4);
  EXPECT_GT(std::abs(pitch(f.s, k.w) - pitch(f.s, f.w_guess)), 1e-3 * std::abs(pitch(f.s, k.w)));
}

// The bordered direct strategy in the full formulation (complex sparse LU of A - i omega I, the
// flow update by real LU solves with A) lands on the same point as the Krylov and the LU solve.
TEST(hopf_bordered_full, incidence_bordered_direct_full_matches_lu_full_and_krylov_full) {
  const auto& f = incidence();
  const hopf_point &d = f.direct.point, &k = f.krylov.point, &l = f.lu.point;
  for (const auto* r : {&f.lu, &f.direct, &f.krylov})
    std::cout << "alpha_0 = 1 deg, " << (r == &f.lu ? "augmented LU" : r == &f.direct ? "bordered direct" : "bordered Krylov")
              << ": Ubar* " << std::setprecision(12) << r->point.mu << " omega* " << r->point.omega << ", "
              << r->report.iterations << " Newton, " << r->linear_iterations << " linear iterations, "
              << r->setup_seconds + r->linear_seconds + r->residual_seconds << " s\n";
  ASSERT_TRUE(f.direct.report.converged);
  EXPECT_NEAR(d.mu, 1.71058562195, 1e-10);
  EXPECT_NEAR(d.omega, 0.75640197411, 1e-10);
  EXPECT_NEAR(d.mu, l.mu, 1e-8 * l.mu);
  EXPECT_NEAR(d.omega, l.omega, 1e-8 * l.omega);
  EXPECT_NEAR(d.mu, k.mu, 1e-8 * l.mu);
  EXPECT_NEAR(d.omega, k.omega, 1e-8 * l.omega);
  EXPECT_LT((d.w - l.w).norm(), 1e-7 * l.w.norm());
  EXPECT_LT(eigen_residual(f.s, d), 1e-9);
  EXPECT_EQ(f.direct.linear_iterations, 0);
  EXPECT_LE(f.direct.report.iterations, f.lu.report.iterations + 1);
}

// A static aeroelastic solve at Ubar* from the loaded rest state gives the equilibrium part of
// the Hopf point, the structural deflection in particular.
TEST(hopf_bordered_full, incidence_equilibrium_is_the_static_aeroelastic_solution) {
  const auto& f = incidence();
  const hopf_point& k = f.krylov.point;
  const vec<double> ws = f.static_equilibrium(k.mu, f.rest);
  std::cout << "static solve at Ubar*: pitch " << std::setprecision(12) << pitch(f.s, ws) << ", Hopf point "
            << pitch(f.s, k.w) << "\n";
  EXPECT_NEAR(pitch(f.s, ws), pitch(f.s, k.w), 1e-8 * std::abs(pitch(f.s, k.w)));
  const auto n = f.s.flow_size();
  EXPECT_LT((ws.tail(4) - k.w.tail(4)).norm(), 1e-8 * k.w.tail(4).norm());
  EXPECT_LT((ws.head(n) - k.w.head(n)).norm(), 1e-8 * k.w.head(n).norm());
}

// The dense spectrum of A at the static equilibrium of Ubar* - 0.01, Ubar*, Ubar* + 0.01: the
// critical pair crosses the imaginary axis at Ubar* (real part through zero, imaginary part
// omega*), every other eigenvalue stays in the left half-plane.
TEST(hopf_bordered_full, incidence_dense_spectrum_crosses_at_the_hopf_point) {
  const auto& f = incidence();
  const hopf_point& k = f.krylov.point;
  double re[3];
  int i = 0;
  for (double d : {-0.01, 0.0, 0.01}) {
    const vec<double> w = d == 0.0 ? k.w : f.static_equilibrium(k.mu + d, k.w);
    Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(f.s.jacobian(w, k.mu + d)), false);
    const auto& ev = es.eigenvalues();
    Eigen::Index best = 0;
    for (Eigen::Index j = 1; j < ev.size(); ++j)
      if (std::abs(ev[j] - cplx(0, k.omega)) < std::abs(ev[best] - cplx(0, k.omega))) best = j;
    double other = -1e300;
    for (Eigen::Index j = 0; j < ev.size(); ++j)
      if (std::abs(ev[j] - ev[best]) > 1e-9 && std::abs(ev[j] - std::conj(ev[best])) > 1e-9)
        other = std::max(other, ev[j].real());
    std::cout << "Ubar* " << std::showpos << d << std::noshowpos << ": critical " << ev[best] << ", others <= " << other
              << "\n";
    re[i++] = ev[best].real();
    EXPECT_LT(other, 0.0);
    if (d == 0.0) {
      EXPECT_NEAR(ev[best].imag(), k.omega, 1e-8);
    }
  }
  EXPECT_LT(re[0], 0.0);
  EXPECT_GT(re[2], 0.0);
  EXPECT_LT(std::abs(re[1]), 1e-8);
  EXPECT_LT(std::abs(re[1]), 1e-4 * std::min(-re[0], re[2]));
}

// The fixed-equilibrium formulation is refused here: the Krylov solver without full_system
// (input_error), and with hopf_options::fixed_equilibrium by its post-check, as the equilibrium of
// Ubar = 1.75 does not hold at the Ubar it converges to.
TEST(hopf_bordered_full, incidence_fixed_equilibrium_is_refused) {
  const auto& f = incidence();
  EXPECT_THROW(solve_hopf_krylov<4>(f.s, f.start, full_options()), input_error);
  hopf_options o = full_options();
  o.fixed_equilibrium = true;
  o.newton.throw_on_failure = false;
  const hopf_result r = solve_hopf_krylov<4>(f.s, f.start, o);
  EXPECT_FALSE(r.report.converged);
  EXPECT_NE(r.report.reason.find("equilibrium does not hold at mu*"), std::string::npos) << r.report.reason;
}

// hopf_start_krylov (complex BILU-GMRES inverse power on the model's block Jacobians) against
// hopf_start (sparse LU of A - i omega I): the same eigenvalue and eigenvector, with BILU of the
// modified-order L and of the exact A.
TEST(hopf_bordered_full, krylov_start_matches_the_sparse_lu_start) {
  const auto& f = incidence();
  inverse_power_options ipo;
  ipo.tolerance = 1e-10;
  const hopf_point lu = hopf_start(f.s, f.w_guess, 1.75, 0.6, ipo);
  for (const bool exact : {false, true}) {
    hopf_start_krylov_options so;
    so.precondition_exact = exact;
    so.inverse_power.tolerance = 1e-10;
    so.krylov.relative_tolerance = 1e-12;  // below the eigen-residual target (inverse_power.hpp)
    eigen_pair info;
    const hopf_point k = hopf_start_krylov<4>(f.s, f.w_guess, 1.75, 0.6, so, &info);
    std::cout << (exact ? "BILU(A)" : "BILU(L)") << " start: lambda " << info.lambda << ", " << info.iterations
              << " inverse iterations, " << info.linear_iterations << " GMRES\n";
    EXPECT_NEAR(k.omega, lu.omega, 1e-9);
    EXPECT_NEAR(std::abs(k.p.dot(lu.p)) / (k.p.norm() * lu.p.norm()), 1.0, 1e-9);
    EXPECT_EQ(k.mu, 1.75);
    EXPECT_EQ(k.w, f.w_guess);
    EXPECT_LE(info.residual, 1e-10 * std::max(1.0, std::abs(info.lambda)));
    EXPECT_GT(info.linear_iterations, info.iterations);
  }
}

// ---- a structure that is not one flow block: 5 unknowns per cell and 6 structural unknowns
// (tests/support/bordered_test_system.hpp), in the model's bordered form and through its Eigen
// sparse Jacobians. Every Krylov consumer (equilibrium, inverse-power start, fixed-equilibrium
// and full Hopf Newton, V-g solver factory) against the sparse-LU references ----
namespace {
using test_support::modal_block_system;
using test_support::sparse_view;
}  // namespace

TEST(hopf_bordered_structure, six_structural_unknowns_with_blocks_of_five) {
  const modal_block_system s(12);
  const sparse_view<modal_block_system> v{s};
  // the equilibrium: Newton-Krylov from a perturbed state, both routes the same iterates
  vec<double> w0 = vec<double>::Constant(s.size(), 1.0);
  w0.tail(6).setZero();
  const auto e = solve_equilibrium_krylov<5>(s, 0.5, w0);
  const auto ev = solve_equilibrium_krylov<5>(v, 0.5, w0);
  EXPECT_TRUE(e.report.converged);
  EXPECT_LE(s.residual<double>(e.w, 0.5).norm(), 1e-11);
  EXPECT_EQ(e.linear_iterations, ev.linear_iterations);
  EXPECT_EQ(e.w, ev.w);
  const vec<double> w = e.w;
  // the start: bordered BILU-GMRES inverse power against the sparse-LU one
  eigen_pair info;
  const hopf_point g = hopf_start_krylov<5>(s, w, 0.55, 1.0, {}, &info);
  const hopf_point gd = hopf_start(s, w, 0.55, 1.0);
  EXPECT_NEAR(g.omega, gd.omega, 1e-7);
  EXPECT_GT(info.linear_iterations, 0);
  // fixed equilibrium (the equilibrium does not depend on mu) and full: the sparse-LU Hopf point
  hopf_options fo = fixed_options(1e-11);
  const hopf_result ref = solve_hopf(s, g, fo);
  ASSERT_TRUE(ref.report.converged);
  EXPECT_GT(ref.point.mu, 0.4);
  EXPECT_LT(ref.point.mu, 0.8);
  const hopf_result fk = solve_hopf_krylov<5>(s, g, fo);
  const hopf_result fv = solve_hopf_krylov<5>(v, g, fo);
  ASSERT_TRUE(fk.report.converged);
  EXPECT_NEAR(fk.point.mu, ref.point.mu, 1e-9);
  EXPECT_NEAR(fk.point.omega, ref.point.omega, 1e-9);
  EXPECT_EQ(fk.linear_iterations, fv.linear_iterations);
  EXPECT_EQ(fk.point.mu, fv.point.mu);
  hopf_options uo = fo;
  uo.fixed_equilibrium = false;
  hopf_krylov_options uk;
  uk.full_system = true;
  const hopf_result uref = solve_hopf(s, g, uo);
  const hopf_result fu = solve_hopf_krylov<5>(s, g, uo, uk);
  ASSERT_TRUE(fu.report.converged);
  EXPECT_NEAR(fu.point.mu, uref.point.mu, 1e-9);
  EXPECT_NEAR(fu.point.omega, uref.point.omega, 1e-9);
  EXPECT_NEAR(fu.point.mu, ref.point.mu, 1e-9);
  EXPECT_LE((fu.point.w - w).norm(), 1e-8);
  // V-g: the bordered BILU-GMRES solver factory against the sparse-LU diagram
  const std::vector<double> mus{0.45, 0.55, 0.65, 0.75};
  const std::vector<vg_mode_start> starts{{cplx(-0.1, 1.0), {}}, {cplx(-0.2, 1.5), {}}};
  auto equilibrium = [&](double) { return w; };
  vg_options vo;
  vo.inverse_power.tolerance = 1e-10;
  const vg_result lu = vg_diagram(s, equilibrium, mus, starts, vo);
  vg_krylov_options vk;
  vk.krylov.relative_tolerance = 1e-12;
  const vg_result kr = vg_diagram(s, equilibrium, mus, starts, vo, vg_krylov_solvers<5>(s, vk));
  ASSERT_EQ(kr.points.size(), lu.points.size());
  for (std::size_t i = 0; i < lu.points.size(); ++i)
    EXPECT_LT(std::abs(kr.points[i].lambda - lu.points[i].lambda), 1e-8 * std::abs(lu.points[i].lambda)) << i;
  ASSERT_EQ(kr.flutter.size(), 1u);
  EXPECT_NEAR(kr.flutter[0].mu, ref.point.mu, 1e-3);
  EXPECT_GT(kr.linear_iterations, 0);
  std::cout << "n_f = 60, n_s = 6: Hopf mu* " << std::setprecision(12) << fk.point.mu << " omega* " << fk.point.omega
            << "; fixed " << fk.report.iterations << " Newton / " << fk.linear_iterations << " GMRES, full "
            << fu.report.iterations << " Newton / " << fu.linear_iterations << " GMRES; start " << info.iterations
            << " inverse iterations / " << info.linear_iterations << " GMRES\n";
}
