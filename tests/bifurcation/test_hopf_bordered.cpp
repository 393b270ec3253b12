// The bordered solvers of the symmetric Hopf system (hopf_bordered.hpp) on the coupled Euler /
// pitch-plunge NACA 0012 (very coarse grid, light case, M = 0.5), against the independent
// reference of solve_hopf (real (2n+2) sparse LU of the augmented matrix): the same flutter
// point to 1e-9 from the same inverse-power start, the eigen-equation A p = i omega p satisfied,
// quadratic convergence of the exact variants, the GMRES iteration count reported, and the
// grid-sequencing transfer (prolong_from) giving a start on the coarse grid from which
// solve_hopf_krylov converges. Bad input is refused with a clear error.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include "support/hopf_test_systems.hpp"

#include <complex>
#include <cstdlib>
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
    o.symmetric = true;
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
  not_sym.symmetric = false;
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
const Eigen::Vector4d moving_c(1.0, 0.5, -0.3, 0.2);

hopf_options fixed_options(double tol = 1e-10) {
  hopf_options o;
  o.symmetric = true;
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
  // each residual evaluation is two taylor products: call 5 is the residual at iterate 2
  direct_solver<Eigen::MatrixXcd> lu;
  const auto check = [&](const std::string& m) {
    for (const char* part : {"injected bordered", "last accepted iterate", "||F|| = ", "mu = ", "omega = "})
      EXPECT_NE(m.find(part), std::string::npos) << part << " not in: " << m;
  };
  try {
    solve_hopf_bordered(faulty_system(d, 5), g, o, lu);
    ADD_FAILURE() << "bordered: no exception";
  } catch (const convergence_error& e) {
    check(e.what());
  }
  try {
    solve_hopf_krylov<2>(faulty_system(sp, 5), g, o);
    ADD_FAILURE() << "krylov: no exception";
  } catch (const convergence_error& e) {
    check(e.what());
  }
  o.newton.throw_on_failure = false;
  const hopf_result bad = solve_hopf_krylov<2>(faulty_system(sp, 5), g, o);
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
