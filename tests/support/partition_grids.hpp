#pragma once
// Small multi-block grids for the partition tests: the NACA 0012 C-grid's three blocks (2D)
// and a row of three boxes along x (3D) with point-matched interfaces, a slip wall below and far
// field elsewhere, its points a smooth distortion of a uniform lattice so that interface points
// coincide.
#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>

#include <cmath>
#include <random>

namespace aerohopf::test {

inline flow::multiblock_grid<2> partition_cgrid() { return flow::coarsen(flow::naca_cgrid(), 8); }

inline flow::multiblock_grid<3> box_row_3d() {
  using namespace aerohopf::flow;
  const int ni[3] = {4, 3, 2};
  multiblock_grid<3> g;
  double x0 = 0.0;
  for (int b = 0; b < 3; ++b) {
    grid_block<double, 3> blk;
    blk.points = {ni[b] + 1, 4, 4};
    blk.x.resize(blk.n_points());
    for (std::size_t k = 0; k < blk.x.size(); ++k) {
      const auto i = unravel<3>(k, blk.points);
      const double X = x0 + 0.25 * i[0], Y = 0.25 * i[1], Z = 0.25 * i[2];
      blk.x[k] = {X + 0.03 * std::sin(3.0 * Y + Z), Y + 0.02 * std::sin(2.0 * X) * Y, Z + 0.02 * std::cos(X + Y) * Z};
    }
    x0 += 0.25 * ni[b];
    g.topology.cells.push_back(blk.cells());
    g.points.blocks.push_back(std::move(blk));
  }
  auto& pt = g.topology.patches;
  for (int b = 0; b < 3; ++b)
    for (int f = 0; f < 6; ++f) {
      if ((f == 1 && b < 2) || (f == 0 && b > 0)) continue;
      pt.push_back(whole_face<3>(b, f, g.topology.cells[b], f == 2 ? boundary_kind::wall : boundary_kind::far_field));
    }
  for (int b = 0; b < 2; ++b)
    for (const int side : {0, 1}) {  // side 0: b's i-max face reads b+1; side 1: b+1's i-min face reads b
      const int me = b + side, other = b + 1 - side;
      auto p = whole_face<3>(me, side == 0 ? 1 : 0, g.topology.cells[me], boundary_kind::interface);
      p.donor_block = other;
      p.donor_face = side == 0 ? 0 : 1;
      p.donor_end = g.topology.cells[other];
      p.transform = {0, 2, 3};
      pt.push_back(p);
    }
  return g;
}

/// The free stream with a random smooth-enough perturbation (density and energy stay positive).
template <int Dim>
vec<double> perturbed_free_stream(const flow::euler_model<Dim>& m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  vec<double> w = m.free_stream_vector();
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  return w;
}

}  // namespace aerohopf::test
