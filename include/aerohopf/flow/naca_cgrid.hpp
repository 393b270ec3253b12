#pragma once
// C-grid generator for NACA 4-digit aerofoils (sharp trailing edge), split into three blocks at
// the trailing edge: lower wake, aerofoil, upper wake.
//
// Method (algebraic, normal marching): the inner C-curve (wake - lower surface - upper surface
// - wake) is pushed outward layer by layer along its own normals with geometrically growing
// steps (first step = first cell height, total = far-field distance). Normals are smoothed
// with a number of averaging passes that grows with the layer, and points are redistributed
// tangentially, so the lines stay orthogonal at the wall and fan out smoothly away from it
// (concave corners such as the trailing edge cannot make lines cross). The wake cut is the
// x-axis behind the trailing edge; the outflow boundary is the vertical line x = 1 + far field.
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

namespace internal {
/// Ratio r of a geometric sequence with first term h and n terms summing to total.
inline double geometric_ratio(double h, int n, double total) {
  require(h * n < total, "geometric_ratio: first spacing ", h, " times ", n, " exceeds ", total);
  double lo = 1.0 + 1e-12, hi = 10.0;
  for (int it = 0; it < 200; ++it) {
    const double r = 0.5 * (lo + hi);
    const double s = h * (std::pow(r, n) - 1.0) / (r - 1.0);
    (s > total ? hi : lo) = r;
  }
  return 0.5 * (lo + hi);
}
}  // namespace internal

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
  const double r_normal = internal::geometric_ratio(o.first_height, nj - 1, o.far_field);
  std::vector<std::vector<std::array<double, 2>>> layer(nj, curve);
  std::vector<std::array<double, 2>> nrm(ni), tmp(ni);
  for (int j = 1; j < nj; ++j) {
    const auto& prev = layer[j - 1];
    const double h = o.first_height * std::pow(r_normal, j - 1);
    for (int i = 0; i < ni; ++i) {
      const auto& a = prev[std::max(i - 1, 0)];
      const auto& b = prev[std::min(i + 1, ni - 1)];
      double tx = b[0] - a[0], ty = b[1] - a[1];
      const double l = std::hypot(tx, ty);
      nrm[i] = {-ty / l, tx / l};
    }
    nrm[0] = {0.0, -1.0};
    nrm[ni - 1] = {0.0, 1.0};
    // Implicit smoothing of the normals, (I - kappa_i delta^2) n_new = n, with kappa_i =
    // (step / local spacing)^2: normals then vary slowly over one step length along the layer,
    // so neighbouring lines cannot cross at concave corners, while near the wall (small
    // steps) they stay almost exactly orthogonal.
    {
      // Thomas algorithm; rows 0 and ni-1 are fixed (Dirichlet), sub/super diagonals -kappa.
      std::vector<double> cp(ni, 0.0), dx(ni), dy(ni);
      for (int i = 1; i < ni - 1; ++i) {
        const double ds = 0.5 * std::hypot(prev[i + 1][0] - prev[i - 1][0], prev[i + 1][1] - prev[i - 1][1]);
        const double kap = o.smoothing * (h / ds) * (h / ds);
        double rx = nrm[i][0], ry = nrm[i][1];
        if (i == 1) {
          rx += kap * nrm[0][0];
          ry += kap * nrm[0][1];
        }
        if (i == ni - 2) {
          rx += kap * nrm[ni - 1][0];
          ry += kap * nrm[ni - 1][1];
        }
        const double m = 1.0 + 2.0 * kap + (i > 1 ? kap * cp[i - 1] : 0.0);
        cp[i] = -kap / m;
        dx[i] = (rx + (i > 1 ? kap * dx[i - 1] : 0.0)) / m;
        dy[i] = (ry + (i > 1 ? kap * dy[i - 1] : 0.0)) / m;
      }
      for (int i = ni - 3; i >= 1; --i) {
        dx[i] -= cp[i] * dx[i + 1];
        dy[i] -= cp[i] * dy[i + 1];
      }
      for (int i = 1; i < ni - 1; ++i) {
        const double l = std::hypot(dx[i], dy[i]);
        nrm[i] = {dx[i] / l, dy[i] / l};
      }
    }
    auto& cur = layer[j];
    for (int i = 0; i < ni; ++i) cur[i] = {prev[i][0] + h * nrm[i][0], prev[i][1] + h * nrm[i][1]};
    cur[0][0] = prev[0][0];
    cur[ni - 1][0] = prev[ni - 1][0];
    // Tangential redistribution: move each point along the layer towards the mid-point of its
    // neighbours (tangential component only), more strongly away from the wall.
    const double omega = std::min(0.5, 0.05 * j);
    for (int s = 0; s < o.redistribution_passes; ++s) {
      for (int i = 1; i < ni - 1; ++i) {
        const double tx = cur[i + 1][0] - cur[i - 1][0], ty = cur[i + 1][1] - cur[i - 1][1];
        const double l2 = tx * tx + ty * ty;
        const double dx = 0.5 * (cur[i + 1][0] + cur[i - 1][0]) - cur[i][0];
        const double dy = 0.5 * (cur[i + 1][1] + cur[i - 1][1]) - cur[i][1];
        const double along = (dx * tx + dy * ty) / l2;
        tmp[i] = {cur[i][0] + omega * along * tx, cur[i][1] + omega * along * ty};
      }
      for (int i = 1; i < ni - 1; ++i) cur[i] = tmp[i];
    }
  }

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
