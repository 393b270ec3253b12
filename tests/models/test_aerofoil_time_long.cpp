// Time-marching check of the light-case flutter point (mu_s = 10, M = 0.5, very coarse grid):
// BDF2 runs of the coupled system at Ubar* -/+ 0.05, started on the critical eigenvector at
// that Ubar (inverse power), decay
// and grow, and the growth rate measured from the pitch peaks agrees with the real part of
// the critical eigenvalue of the dense spectrum at the same Ubar. This checks the coupled
// residual as an ODE (time scales of flow and structure consistent) independently of the
// Jacobian-based Hopf solver. Slow: labelled long.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/time/bdf2.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <complex>
#include <iostream>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::flow;
using models::aerofoil_system;

namespace {
std::complex<double> eigenvalue_near(const aerofoil_system& s, const vec<double>& w, double ubar, double omega) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(w, ubar)), false);
  std::complex<double> best = es.eigenvalues()[0];
  for (const auto& l : es.eigenvalues())
    if (std::abs(l - std::complex<double>(0, omega)) < std::abs(best - std::complex<double>(0, omega))) best = l;
  return best;
}

}  // namespace

TEST(aerofoil_time_long, growth_rates_straddling_the_flutter_point_match_dense_spectrum) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  const aerofoil_system s(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.0}),
                          structure::pitch_plunge(p));
  const vec<double> w = s.steady_equilibrium();
  hopf_options hopt;
  hopt.fixed_equilibrium = true;
  const hopf_result h = solve_hopf(s, hopf_start(s, w, 1.75, 0.6), hopt);
  const double ubar = h.point.mu, omega = h.point.omega;
  bdf2_options opt;
  opt.dt = 0.2;  // ~ 40 steps per cycle
  opt.inner_tolerance = 1e-9;
  for (double du : {-0.05, 0.05}) {
    // initial state on the critical mode at this Ubar (inverse power), pitch amplitude 1e-3 rad
    const vec<std::complex<double>> pv = hopf_start(s, w, ubar + du, omega).p;
    const vec<double> w0 = w + 1e-3 * pv.real() / std::abs(pv[s.size() - 2]);
    std::vector<double> t, alpha;
    integrate_bdf2(s, ubar + du, w0, 0.0, 4 * 2 * M_PI / omega, opt, [&](const bdf2_step_info& info, const vec<double>& y) {
      t.push_back(info.t);
      alpha.push_back(y[s.size() - 2]);
    });
    int peaks = 0;
    const double rate = peak_growth_rate(t, alpha, 2 * M_PI / omega, &peaks);
    EXPECT_GE(peaks, 4);
    const auto lambda = eigenvalue_near(s, w, ubar + du, omega);
    std::cout << "Ubar* " << (du < 0 ? "- " : "+ ") << std::abs(du) << ": time-marching growth rate " << rate
              << ", dense eigenvalue " << lambda << "\n";
    EXPECT_EQ(rate > 0, du > 0);
    EXPECT_NEAR(rate, lambda.real(), 0.15 * std::abs(lambda.real()));
  }
}
