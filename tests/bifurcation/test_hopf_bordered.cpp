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
