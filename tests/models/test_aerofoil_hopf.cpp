// Flutter (Hopf) point of the coupled Euler / pitch-plunge NACA 0012 (spec 05, light case
// mu_s = 10, M = 0.5, very coarse grid), computed by the augmented Newton solver with the
// symmetric option (the equilibrium, steady flow at alpha = 0 with the section at rest, does
// not depend on Ubar) and checked against the full dense eigen-spectrum of the coupled
// Jacobian: at Ubar* the eigenvalue nearest i omega* lies on the imaginary axis, and at
// Ubar* -/+ 0.01 the critical pair is on the stable / unstable side (all others stable).
// A dense root-locus scan put the crossing between Ubar = 1.5 and 2 (omega ~ 0.6), with the
// static divergence (real eigenvalue) later, between Ubar = 2 and 3.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/hopf_curve_fixed_equilibrium.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include "support/dense_spectrum.hpp"

#include <complex>
#include <iostream>

using namespace aerohopf;
using namespace aerohopf::flow;
using models::aerofoil_system;

namespace {
// Dense spectrum: the eigenvalue nearest target, and the largest real part of all others.
std::pair<std::complex<double>, double> spectrum_near(const aerofoil_system& s, const vec<double>& w, double ubar,
                                                      std::complex<double> target) {
  return test_support::eigenvalue_near(s.jacobian(w, ubar), target);
}
// The aerofoil seen only through the dynamical_system interface (Eigen sparse Jacobians): the
// Krylov Hopf solver and the Hopf-curve tracer then take the from_sparse route instead of the
// model's block Jacobians.
struct sparse_owner {
  aerofoil_system s;
  using jacobian_type = aerofoil_system::jacobian_type;
  Eigen::Index size() const { return s.size(); }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    return s.residual<T>(w, mu);
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s.jacobian(w, mu); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const { return s.approximate_jacobian(w, mu); }
  vec<double> d_mu(const vec<double>& w, double mu) const { return s.d_mu(w, mu); }
  jacobian_type jacobian_d_mu(const vec<double>& w, double mu) const { return s.jacobian_d_mu(w, mu); }
};
static_assert(!has_block_jacobians<sparse_owner, 4>);
aerofoil_system light_very_coarse(double mach) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = mach, .alpha_rad = 0.0}),
                         structure::pitch_plunge(p));
}
static_assert(has_block_jacobians<aerofoil_system, 4>);
}  // namespace

TEST(aerofoil_hopf, block_jacobians_give_the_same_krylov_hopf_iterates_as_the_sparse_route) {
  const aerofoil_system s = light_very_coarse(0.5);
  const vec<double> w = s.steady_equilibrium();
  // the blocks: cells + 1 block rows, the structural unknowns last, the same entries as jacobian()
  vec<double> wd = w;
  wd.tail(4) << 0.01, -0.02, 0.03, 0.01;  // a moved grid (the rigid-motion path of the assembly)
  const auto blocks = s.block_jacobian(wd, 1.7);
  EXPECT_EQ(blocks.block_rows(), s.size() / 4);
  EXPECT_EQ(blocks.logical_rows(), s.size());
  EXPECT_EQ(blocks.col_index()[blocks.row_ptr()[1] - 1], s.size() / 4 - 1);  // row 0 ends in the structure
  const Eigen::SparseMatrix<double> dj = s.jacobian(wd, 1.7) - blocks.to_sparse();
  EXPECT_EQ(dj.norm(), 0.0);
  const Eigen::SparseMatrix<double> dl = s.approximate_jacobian(wd, 1.7) - s.approximate_block_jacobian(wd, 1.7).to_sparse();
  EXPECT_EQ(dl.norm(), 0.0);
  const auto [pe, pa] = s.block_jacobians(wd, 1.7);  // both at once, coupling blocks shared
  EXPECT_EQ(pe.values(), blocks.values());
  EXPECT_EQ(pa.values(), s.approximate_block_jacobian(wd, 1.7).values());
  EXPECT_EQ(pa.col_index(), s.approximate_block_jacobian(wd, 1.7).col_index());

  const hopf_point start = hopf_start(s, w, 1.75, 0.6);
  hopf_options opt;
  opt.fixed_equilibrium = true;
  opt.newton.abs_tolerance = 1e-9;
  const hopf_result hb = solve_hopf_krylov<4>(s, start, opt);
  const hopf_result hs = solve_hopf_krylov<4>(sparse_owner{s}, start, opt);
  ASSERT_TRUE(hb.report.converged);
  ASSERT_TRUE(hs.report.converged);
  EXPECT_EQ(hb.report.iterations, hs.report.iterations);
  EXPECT_EQ(hb.linear_iterations, hs.linear_iterations);
  EXPECT_NEAR(hb.point.mu, hs.point.mu, 1e-12);
  EXPECT_NEAR(hb.point.omega, hs.point.omega, 1e-12);
  // and it is the Hopf point of solve_hopf (Newton with the sparse LU of the full augmented
  // system), the one the dense-spectrum test below checks
  const hopf_result hd = solve_hopf(s, start, opt);
  EXPECT_NEAR(hb.point.mu, hd.point.mu, 1e-8);
  EXPECT_NEAR(hb.point.omega, hd.point.omega, 1e-8);
}

TEST(aerofoil_hopf, light_case_flutter_point_matches_dense_spectrum) {
  const aerofoil_system s = light_very_coarse(0.5);
  const vec<double> w = s.steady_equilibrium();

  const hopf_point start = hopf_start(s, w, 1.75, 0.6);
  hopf_options opt;
  opt.fixed_equilibrium = true;
  const hopf_result h = solve_hopf(s, start, opt);
  const double ubar = h.point.mu, omega = h.point.omega;
  std::cout << "flutter point: Ubar* = " << ubar << ", omega* = " << omega << " (Newton iterations "
            << h.report.iterations << ")\n";
  ASSERT_GT(ubar, 1.5);
  ASSERT_LT(ubar, 2.0);
  // A p = i omega p at the converged point (sparse residual of the eigen-equation)
  const Eigen::SparseMatrix<std::complex<double>> ac = s.jacobian(w, ubar).cast<std::complex<double>>();
  const vec<std::complex<double>> p_vec = h.point.p;
  EXPECT_LT((ac * p_vec - std::complex<double>(0, omega) * p_vec).norm(), 1e-8 * p_vec.norm());

  const auto [at, other_at] = spectrum_near(s, w, ubar, {0.0, omega});
  const auto [below, other_below] = spectrum_near(s, w, ubar - 0.01, {0.0, omega});
  const auto [above, other_above] = spectrum_near(s, w, ubar + 0.01, {0.0, omega});
  std::cout << "critical eigenvalue at Ubar*-0.01: " << below << ", at Ubar*: " << at << ", at Ubar*+0.01: " << above
            << "; largest other real part " << other_below << " / " << other_at << " / " << other_above << "\n";
  EXPECT_NEAR(at.real(), 0.0, 1e-8);
  EXPECT_NEAR(at.imag(), omega, 1e-8);
  EXPECT_LT(below.real(), 0.0);
  EXPECT_GT(above.real(), 0.0);
  EXPECT_GT(std::abs(below.imag()), 0.1);  // a complex pair (flutter), not the divergence eigenvalue
  EXPECT_LT(other_below, 0.0);             // stable before flutter: it is the first crossing
}

TEST(aerofoil_hopf, hopf_curve_tracer_gives_the_same_points_with_block_jacobians) {
  // three points of the light case's Hopf curve in (M, Ubar) from M = 0.5 on the very coarse
  // grid, with the nested steady solves and bordered corrections on the model's block Jacobians
  // and on the Eigen route: the same points, landed on M = 0.51
  const double m0 = 0.5;
  const aerofoil_system s0 = light_very_coarse(m0);
  const vec<double> w = s0.steady_equilibrium();
  hopf_options ho;
  ho.fixed_equilibrium = true;
  hopf_point start = solve_hopf(s0, hopf_start(s0, w, 1.75, 0.6), ho).point;
  hopf_curve_options co;
  co.mu_scale = 0.5;
  co.nu_scale = 0.01;
  co.omega_scale = 0.05;
  co.step = 0.5;
  co.max_step = 0.5;
  co.max_points = 3;
  co.nu_targets = {0.51};
  co.throw_on_failure = true;
  fixed_equilibrium_hopf_curve_options so;
  so.steady.abs_tolerance = 1e-10;
  const auto rb = trace_fixed_equilibrium_hopf_curve<4>([](double m) { return light_very_coarse(m); }, m0, start, co, +1, so);
  const auto rs =
      trace_fixed_equilibrium_hopf_curve<4>([](double m) { return sparse_owner{light_very_coarse(m)}; }, m0, start, co, +1, so);
  ASSERT_EQ(rb.points.size(), 3u);
  ASSERT_EQ(rs.points.size(), rb.points.size());
  EXPECT_EQ(rb.linear_iterations, rs.linear_iterations);
  for (std::size_t k = 0; k < rb.points.size(); ++k) {
    EXPECT_NEAR(rb.points[k].nu, rs.points[k].nu, 1e-10) << k;
    EXPECT_NEAR(rb.points[k].mu, rs.points[k].mu, 1e-9) << k;
    EXPECT_NEAR(rb.points[k].omega, rs.points[k].omega, 1e-9) << k;
  }
  EXPECT_GT(rb.points.back().nu, m0);
}
