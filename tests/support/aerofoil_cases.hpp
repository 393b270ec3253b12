#pragma once
// Aerofoil systems shared by several tests (not a test itself: tests/CMakeLists.txt builds only
// tests/<layer>/test_*.cpp).
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>

namespace aerohopf::test_support {

/// The heavy case (mu_s = 100, the other spec 05 parameters by default) of the pitch-plunge
/// NACA 0012 on the very coarse grid (the C-grid coarsened by 8, as the aerofoil example), at
/// Mach number `mach` and zero incidence.
inline models::aerofoil_system heavy_very_coarse_aerofoil(double mach) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 100;
  return models::aerofoil_system(
      flow::euler_model<2>(flow::coarsen(flow::naca_cgrid(), 8), {.mach = mach, .alpha_rad = 0.0}),
      structure::pitch_plunge(p));
}

/// Its Hopf point at M = 0.5 (the section is symmetric: the steady flow is the equilibrium for
/// every Ubar) by the fixed-equilibrium augmented system from an inverse-power start at Ubar
/// 4.6, omega 0.22.
inline hopf_result heavy_very_coarse_hopf(const models::aerofoil_system& s) {
  hopf_options ho;
  ho.fixed_equilibrium = true;
  return solve_hopf(s, hopf_start(s, s.steady_equilibrium(), 4.6, 0.22), ho);
}

}  // namespace aerohopf::test_support
