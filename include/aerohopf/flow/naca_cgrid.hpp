#pragma once
// C-grid generator for NACA 4-digit aerofoils (sharp trailing edge), split into three blocks at
// the trailing edge: lower wake, aerofoil, upper wake.
//
// Method (algebraic, normal marching, grid_marching.hpp): the inner C-curve (wake - lower
// surface - upper surface - wake) is pushed outward layer by layer along its own smoothed
// normals with geometrically growing steps (first step = first cell height, total = far-field
// distance). The wake cut is the x-axis behind the trailing edge; the outflow boundary is the
// vertical line x = 1 + far field.
//
// Index convention: i runs from the lower wake outflow, upstream along the wake, round the
// aerofoil clockwise (lower surface trailing edge to leading edge, then upper), and out along
// the upper wake; j runs outward. This is right-handed (positive volumes).
// The thickness uses the closed-trailing-edge coefficient -0.1036.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "../error.hpp"
#include "grid_marching.hpp"
#include "structured_grid.hpp"

namespace aerohopf::flow {

struct naca_cgrid_options {
  std::string digits = "0012";
  int points_around = 257;  // including both wake sides
  int points_normal = 65;
  int wake_cells = 32;      // per wake side
  double far_field = 15.0;  // chords (outer boundary distance and wake length)
  double first_height = 0.01;
  double clustering = 0.7;  // 0: uniform arc length; -> 1: strong clustering at LE and TE
  double smoothing = 8.0;   // strength of the normal smoothing while marching outward
  int redistribution_passes = 20;  // tangential point redistribution per layer
};

/// NACA 4-digit surface point at chordwise station x in [0, 1]; upper = true for the upper side.
inline std::array<double, 2> naca4_point(const std::string& digits, double x, bool upper) {
  const double m = (digits[0] - '0') / 100.0, p = (digits[1] - '0') / 10.0;
  const double t = std::stod(digits.substr(2, 2)) / 100.0;
  const double yt = 5.0 * t *
                    (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
                     0.1036 * x * x * x * x);
  double yc = 0.0, dyc = 0.0;
  if (m > 0.0) {
    if (x < p) {
      yc = m / (p * p) * (2.0 * p * x - x * x);
      dyc = 2.0 * m / (p * p) * (p - x);
    } else {
      yc = m / ((1 - p) * (1 - p)) * (1.0 - 2.0 * p + 2.0 * p * x - x * x);
      dyc = 2.0 * m / ((1 - p) * (1 - p)) * (p - x);
    }
  }
  const double th = std::atan(dyc);
  const double s = upper ? 1.0 : -1.0;
  return {x - s * yt * std::sin(th), yc + s * yt * std::cos(th)};
}

/// The three-block C-grid with its topology. Wall patches carry the tag "aerofoil".
inline multiblock_grid<2> naca_cgrid(const naca_cgrid_options& o = {}) {
  require(o.digits.size() == 4 && std::all_of(o.digits.begin(), o.digits.end(), ::isdigit),
          "naca_cgrid: digits '", o.digits, "' are not a NACA 4-digit designation");
  require(o.wake_cells >= 2 && o.points_around > 2 * o.wake_cells + 4 && o.points_normal >= 3,
          "naca_cgrid: too few points (around ", o.points_around, ", normal ", o.points_normal,
          ", wake cells ", o.wake_cells, ")");
  require((o.points_around - 1 - 2 * o.wake_cells) % 2 == 0, "naca_cgrid: aerofoil cell count ",
          o.points_around - 1 - 2 * o.wake_cells, " must be even");
  require(o.first_height > 0 && o.far_field > 1.0 && o.clustering >= 0.0 && o.clustering < 1.0,
          "naca_cgrid: bad first_height/far_field/clustering");
  const int n_side = (o.points_around - 1 - 2 * o.wake_cells) / 2;
  const int nw = o.wake_cells;
  const int ni = o.points_around, nj = o.points_normal;

  // Surface: fine polyline from LE to TE on one side, parameterised by arc length.
  auto side_points = [&](bool upper) {
    const int nfine = 20001;
    std::vector<std::array<double, 2>> poly(nfine);
    std::vector<double> arc(nfine, 0.0);
    for (int k = 0; k < nfine; ++k) {
      const double th = std::numbers::pi * k / (nfine - 1);
      poly[k] = naca4_point(o.digits, 0.5 * (1.0 - std::cos(th)), upper);
      if (k) arc[k] = arc[k - 1] + std::hypot(poly[k][0] - poly[k - 1][0], poly[k][1] - poly[k - 1][1]);
    }
    poly.back() = {1.0, 0.0};
    std::vector<std::array<double, 2>> pts(n_side + 1);
    const double a = o.clustering, len = arc.back();
    std::size_t seg = 0;
    for (int k = 0; k <= n_side; ++k) {
      const double u = double(k) / n_side;
      const double t = len * (u - a * std::sin(2.0 * std::numbers::pi * u) / (2.0 * std::numbers::pi));
      while (seg + 2 < arc.size() && arc[seg + 1] < t) ++seg;
      const double w = std::clamp((t - arc[seg]) / (arc[seg + 1] - arc[seg]), 0.0, 1.0);
      pts[k] = {poly[seg][0] + w * (poly[seg + 1][0] - poly[seg][0]),
                poly[seg][1] + w * (poly[seg + 1][1] - poly[seg][1])};
    }
    pts.front() = poly.front();
    pts.back() = {1.0, 0.0};
    return std::pair{pts, len};
  };
  const auto [upper, len_u] = side_points(true);
  const auto [lower, len_l] = side_points(false);
  const double h_te = 0.5 * (std::hypot(upper[n_side][0] - upper[n_side - 1][0], upper[n_side][1] - upper[n_side - 1][1]) +
                             std::hypot(lower[n_side][0] - lower[n_side - 1][0], lower[n_side][1] - lower[n_side - 1][1]));
  const double r_wake = internal::geometric_ratio(h_te, nw, o.far_field);
  std::vector<double> wake_x(nw + 1, 1.0);
  for (int k = 1; k <= nw; ++k) wake_x[k] = wake_x[k - 1] + h_te * std::pow(r_wake, k - 1);
  wake_x[nw] = 1.0 + o.far_field;

  // Inner C-curve.
  std::vector<std::array<double, 2>> curve(ni);
  for (int k = 0; k <= nw; ++k) curve[k] = {wake_x[nw - k], 0.0};
  for (int k = 0; k <= n_side; ++k) curve[nw + k] = lower[n_side - k];
  for (int k = 0; k <= n_side; ++k) curve[nw + n_side + k] = upper[k];
  for (int k = 0; k <= nw; ++k) curve[ni - 1 - nw + k] = {wake_x[k], 0.0};

  // March outward.
  const auto layer = internal::march_c_layers(curve, {}, nj, o.first_height, o.far_field, o.smoothing,
                                              o.redistribution_passes);

  multiblock_grid<2> g;
  const int i0[3] = {0, nw, nw + 2 * n_side};
  const int ncell[3] = {nw, 2 * n_side, nw};
  for (int b = 0; b < 3; ++b) {
    grid_block<double, 2> blk;
    blk.points = {ncell[b] + 1, nj};
    blk.x.resize(blk.n_points());
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i <= ncell[b]; ++i) blk.at({i, j}) = layer[j][i0[b] + i];
    g.points.blocks.push_back(std::move(blk));
    g.topology.cells.push_back({ncell[b], nj - 1});
  }
  auto& pt = g.topology.patches;
  const auto& c = g.topology.cells;
  using bk = boundary_kind;
  auto iface = [&](int ba, int fa, int bb, int fb, int tangential_sign) {
    auto p = whole_face<2>(ba, fa, c[ba], bk::interface);
    p.donor_block = bb;
    p.donor_face = fb;
    for (int d = 0; d < 2; ++d) p.donor_end[d] = c[bb][d];
    const int ta = 1 - fa / 2, tb = 1 - fb / 2;
    p.transform[ta] = tangential_sign * (tb + 1);
    return p;
  };
  pt.push_back(whole_face<2>(0, 0, c[0], bk::far_field));
  pt.push_back(iface(0, 1, 1, 0, +1));
  pt.push_back(iface(0, 2, 2, 2, -1));  // wake cut
  pt.push_back(whole_face<2>(0, 3, c[0], bk::far_field));
  pt.push_back(iface(1, 0, 0, 1, +1));
  pt.push_back(iface(1, 1, 2, 0, +1));
  auto wall = whole_face<2>(1, 2, c[1], bk::wall);
  wall.tag = "aerofoil";
  pt.push_back(wall);
  pt.push_back(whole_face<2>(1, 3, c[1], bk::far_field));
  pt.push_back(iface(2, 0, 1, 1, +1));
  pt.push_back(whole_face<2>(2, 1, c[2], bk::far_field));
  pt.push_back(iface(2, 2, 0, 2, -1));  // wake cut
  pt.push_back(whole_face<2>(2, 3, c[2], bk::far_field));
  return g;
}

}  // namespace aerohopf::flow
