// Heavy case (mu_s = 100), M = 0.5, very coarse grid: a dense root-locus scan along Ubar
// brackets the first crossing of a complex pair (flutter) and tells it apart from the static
// divergence (a real eigenvalue through zero); solve_hopf (symmetric) from the bracket must
// land inside it, with the dense spectrum straddling the imaginary axis at Ubar* -/+ 0.01.
// Slow (a dense eigen-decomposition per scan point): labelled long.
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
struct rightmost {
  std::complex<double> complex_pair{-1e300, 0};  // rightmost eigenvalue with Im > 1e-6
  double real_eigenvalue = -1e300;               // rightmost real eigenvalue
};
rightmost scan_point(const aerofoil_system& s, const vec<double>& w, double ubar) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(w, ubar)), false);
  rightmost r;
  for (const auto& l : es.eigenvalues()) {
    if (l.imag() > 1e-6 && l.real() > r.complex_pair.real()) r.complex_pair = l;
    if (std::abs(l.imag()) <= 1e-6) r.real_eigenvalue = std::max(r.real_eigenvalue, l.real());
  }
  return r;
}
}  // namespace

TEST(aerofoil_hopf_long, heavy_case_flutter_bracket_and_hopf_point) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 100;
  const aerofoil_system s(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.0}),
                          structure::pitch_plunge(p));
  const vec<double> w = s.steady_equilibrium();

  double lo = -1, hi = -1, omega_guess = 0;
  double prev_u = 0;
  rightmost prev;
  for (double u = 1.0; u <= 12.0; u += 1.0) {
    const auto r = scan_point(s, w, u);
    std::cout << "Ubar " << u << ": rightmost complex " << r.complex_pair << ", rightmost real " << r.real_eigenvalue
              << "\n";
    if (u > 1.0 && prev.complex_pair.real() < 0 && r.complex_pair.real() > 0) {
      lo = prev_u;
      hi = u;
      omega_guess = 0.5 * (prev.complex_pair.imag() + r.complex_pair.imag());
      break;
    }
    prev = r;
    prev_u = u;
  }
  ASSERT_GT(lo, 0.0) << "no complex crossing found in the scan";
  const hopf_point start = hopf_start(s, w, 0.5 * (lo + hi), omega_guess);
  hopf_options opt;
  opt.fixed_equilibrium = true;
  const hopf_result h = solve_hopf(s, start, opt);
  std::cout << "heavy case flutter point: Ubar* = " << h.point.mu << ", omega* = " << h.point.omega << " (bracket ["
            << lo << ", " << hi << "])\n";
  EXPECT_GT(h.point.mu, lo);
  EXPECT_LT(h.point.mu, hi);
  const auto below = scan_point(s, w, h.point.mu - 0.01), above = scan_point(s, w, h.point.mu + 0.01);
  std::cout << "rightmost complex at Ubar*-0.01: " << below.complex_pair << ", at Ubar*+0.01: " << above.complex_pair
            << "\n";
  EXPECT_LT(below.complex_pair.real(), 0.0);
  EXPECT_GT(above.complex_pair.real(), 0.0);
  EXPECT_NEAR(above.complex_pair.imag(), h.point.omega, 0.05 * h.point.omega);
  EXPECT_LT(below.real_eigenvalue, 0.0);  // no divergence before flutter
}
