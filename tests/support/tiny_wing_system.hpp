#pragma once
// The tiny AGARD 445.6 wing as an aeroelastic system (models::wing_system), shared by the wing
// model's tests: the tiny C-H grid (support/wing_cases.hpp), its modal motion and structure.
#include <aerohopf/coupling/mesh_deformation.hpp>
#include <aerohopf/models/wing.hpp>

#include <numbers>

#include "support/wing_cases.hpp"

namespace aerohopf::test_support {

inline const flow::multiblock_grid<3>& tiny_wing_grid() {
  static const flow::multiblock_grid<3> g = flow::wing_cgrid(agard(), tiny_wing_options());
  return g;
}

/// The modes d on the tiny grid (lengths scaled by the root chord).
inline coupling::wing_modal_motion tiny_wing_motion(const structure::modal_data& d) {
  coupling::wing_motion_options o;
  o.length_scale = agard().planform.root_chord;
  o.grid = tiny_wing_options();
  return coupling::wing_modal_motion(tiny_wing_grid(), d, o);
}

/// M = 0.5 at U = 170 m/s, mean incidence alpha_deg, damping ratio zeta in every mode.
inline models::wing_system tiny_wing(double alpha_deg = 0.0, double zeta = 0.0,
                                     const structure::modal_data& d = agard_plate_modes()) {
  const double c = agard().planform.root_chord;
  return models::wing_system(
      flow::euler_model<3>(tiny_wing_grid(), {.mach = 0.5, .alpha_rad = alpha_deg * std::numbers::pi / 180},
                           {.force_tag = "wing"}),
      tiny_wing_motion(d),
      structure::modal_structure::from_physical(d.omega, Eigen::VectorXd::Constant(d.modes(), zeta), c, 170.0));
}

}  // namespace aerohopf::test_support
