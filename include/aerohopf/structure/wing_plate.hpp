#pragma once
// A wing's plate model: a structured quadrilateral mesh over the planform with the local section
// thickness (flow/wing_geometry.hpp), clamped at the root, for the plate elements of
// plate_fe.hpp; and the AGARD 445.6 weakened model 3's laminated mahogany (spec 06).
#include <cmath>

#include "../error.hpp"
#include "../flow/wing_geometry.hpp"
#include "plate_fe.hpp"

namespace aerohopf::structure {

/// ni x nj quads over the planform, uniform in chord fraction (i) and span (j); node i + (ni + 1) j
/// at chord fraction i / ni of the station y = j b / nj, thickness 2 z_t c there (zero at the
/// leading and trailing edges, where the Gauss points still see a positive thickness).
inline plate_mesh wing_plate_mesh(const flow::wing_geometry& w, int ni, int nj) {
  require(ni >= 2 && nj >= 1, "wing_plate_mesh: need at least 2 x 1 quads (got ", ni, " x ", nj, ")");
  w.planform.validate("wing_plate_mesh");
  return structured_plate_mesh(
      ni, nj,
      [&](double s, double r) {
        const double y = r * w.planform.semi_span;
        return Eigen::Vector2d(w.planform.x_at(s, y), y);
      },
      [&](double x, double y) { return w.thickness(x, y); });
}

/// The root nodes (j = 0) of a wing_plate_mesh with ni chordwise quads clamped.
inline plate_constraints clamped_root(const plate_mesh& m, int ni) {
  require(ni >= 1 && static_cast<std::size_t>(ni + 1) <= m.nodes.size(), "clamped_root: ", ni,
          " chordwise quads for a mesh of ", m.nodes.size(), " nodes");
  plate_constraints c(m.nodes.size());
  for (int i = 0; i <= ni; ++i) c.clamp(i);
  return c;
}

/// Laminated mahogany of the AGARD 445.6 weakened model 3 (spec 06): E1 = 3.1511 GPa along the
/// fibre, E2 = 0.4162 GPa, G12 = 0.4392 GPa, nu12 = 0.31, rho = 381.98 kg/m^3 (transverse shear
/// moduli not published: G12), the fibre along the quarter-chord line of `p`.
inline orthotropic_material agard445_6_mahogany(const flow::wing_planform& p) {
  orthotropic_material m;
  m.e1 = 3.1511e9;
  m.e2 = 0.4162e9;
  m.g12 = 0.4392e9;
  m.nu12 = 0.31;
  m.density = 381.98;
  m.fibre_angle = std::atan(p.sweep_tan(0.25));
  return m;
}

}  // namespace aerohopf::structure
