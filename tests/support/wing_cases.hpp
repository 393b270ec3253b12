#pragma once
// Wing cases shared by several tests (not a test itself: tests/CMakeLists.txt builds only
// tests/<layer>/test_*.cpp): the AGARD 445.6 geometry, a tiny C-H grid of it (16 x 4 x 6 cells,
// for dense spectra) and four plate modes on an 8 x 8 mesh.
#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/structure/modal_data.hpp>
#include <aerohopf/structure/wing_plate.hpp>

namespace aerohopf::test_support {

inline const flow::wing_geometry& agard() {
  static const flow::wing_geometry w = flow::agard445_6();
  return w;
}

inline flow::wing_grid_options tiny_wing_options() {
  flow::wing_grid_options o;
  o.wake_cells = 2;
  o.section_cells = 6;
  o.normal_cells = 4;
  o.span_cells = 4;
  o.outboard_cells = 2;
  o.multiple = 1;
  o.first_height = 0.02;
  o.far_field = 6;
  o.redistribution_passes = 5;
  o.max_shift = 0;  // the geometry that the wing tests' start guesses and reference points were set on
  return o;
}

/// The first four modes of the AGARD 445.6 plate (clamped root, laminated mahogany), 8 x 8 quads.
inline const structure::modal_data& agard_plate_modes() {
  static const structure::modal_data d = [] {
    const structure::plate_mesh pm = structure::wing_plate_mesh(agard(), 8, 8);
    const auto km = structure::assemble_plate(pm, structure::agard445_6_mahogany(agard().planform));
    structure::plate_mode_options mo;
    mo.count = 4;
    return structure::modal_data_from_plate(pm, structure::plate_modes_of(km, structure::clamped_root(pm, 8), mo));
  }();
  return d;
}

}  // namespace aerohopf::test_support
