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
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include <Eigen/Eigenvalues>

#include <complex>
#include <iostream>

using namespace aerohopf;
using namespace aerohopf::flow;
using models::aerofoil_system;

namespace {
// Dense spectrum: the eigenvalue nearest target, and the largest real part of all others.
std::pair<std::complex<double>, double> spectrum_near(const aerofoil_system& s, const vec<double>& w, double ubar,
                                                      std::complex<double> target) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(w, ubar)), false);
  const auto& ev = es.eigenvalues();
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < ev.size(); ++i)
    if (std::abs(ev[i] - target) < std::abs(ev[best] - target)) best = i;
  double other = -1e300;
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (std::abs(ev[i] - ev[best]) > 1e-9 && std::abs(ev[i] - std::conj(ev[best])) > 1e-9)
      other = std::max(other, ev[i].real());
  return {ev[best], other};
}
}  // namespace

TEST(aerofoil_hopf, light_case_flutter_point_matches_dense_spectrum) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  const aerofoil_system s(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.0}),
                          structure::pitch_plunge(p));
  const vec<double> w = s.steady_equilibrium();

  const hopf_point start = hopf_start(s, w, 1.75, 0.6);
  hopf_options opt;
  opt.symmetric = true;
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
