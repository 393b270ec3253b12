#pragma once
// Algebraic C-grid layers by normal marching, shared by the aerofoil C-grid (naca_cgrid.hpp) and
// the wing C-H grid (wing_grid.hpp), which marches one such 2D grid per spanwise station.
//
// Method: the inner C-curve (wake - one surface - the other surface - wake, in the order that
// makes the left normal of the curve point into the field) is pushed outward layer by layer
// along its own normals with geometrically growing steps (first step = first cell height). The
// normals are smoothed implicitly with a strength that grows with the step, and points are
// redistributed tangentially, so the lines stay orthogonal at the wall and fan out smoothly away
// from it (concave corners such as the trailing edge cannot make lines cross). The two end points
// of each layer (the outflow ends of the wake) move only normally to the wake.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "../error.hpp"

namespace aerohopf::flow::internal {

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

using point2 = std::array<double, 2>;

/// nj layers (layer 0 = curve) marched outward with steps first_height r^(j-1) summing to
/// far_field. first_reference (same size as curve, or empty) replaces the curve in the FIRST
/// step's normals and smoothing only: a zero-thickness section (a wing's cut beyond its tip) has
/// coincident points whose own tangents are undefined; a thin section of the same shape gives
/// them their normals. max_shift > 0 bounds each layer's tangential redistribution of the wake's
/// points (the first and last wake_points + 1 of the curve) to max_shift times its step, so no
/// wake line leans by more than atan(max_shift) from the marching direction over one layer; 0:
/// unbounded. Where the tangential spacing is many steps long (a far wake of thin layers) the
/// unbounded redistribution leans the lines nearly along the layer and the cells next to the
/// wake cut become slivers whose faces all run with the flow.
inline std::vector<std::vector<point2>> march_c_layers(const std::vector<point2>& curve,
                                                       const std::vector<point2>& first_reference, int nj,
                                                       double first_height, double far_field, double smoothing,
                                                       int redistribution_passes, double max_shift = 0.0,
                                                       int wake_points = 0) {
  const int ni = static_cast<int>(curve.size());
  require(ni >= 3 && nj >= 2, "march_c_layers: need at least 3 points along the curve and 2 layers (got ", ni, ", ",
          nj, ")");
  require(first_reference.empty() || first_reference.size() == curve.size(),
          "march_c_layers: the first-step reference curve has ", first_reference.size(), " points, the curve ", ni);
  const double r_normal = geometric_ratio(first_height, nj - 1, far_field);
  std::vector<std::vector<point2>> layer(static_cast<std::size_t>(nj), curve);
  std::vector<point2> nrm(static_cast<std::size_t>(ni)), tmp(static_cast<std::size_t>(ni));
  auto at = [](const std::vector<point2>& v, int i) -> const point2& { return v[static_cast<std::size_t>(i)]; };
  // the outflow ends march along the left normal of the wake's end segments, at every layer
  const auto last = static_cast<std::size_t>(ni - 1);
  const double t0x = curve[1][0] - curve[0][0], t0y = curve[1][1] - curve[0][1];
  const double t1x = curve[last][0] - curve[last - 1][0], t1y = curve[last][1] - curve[last - 1][1];
  const point2 n_first = {-t0y / std::hypot(t0x, t0y), t0x / std::hypot(t0x, t0y)};
  const point2 n_last = {-t1y / std::hypot(t1x, t1y), t1x / std::hypot(t1x, t1y)};
  for (int j = 1; j < nj; ++j) {
    const auto& prev = layer[static_cast<std::size_t>(j - 1)];
    const auto& ref = j == 1 && !first_reference.empty() ? first_reference : prev;
    const double h = first_height * std::pow(r_normal, j - 1);
    for (int i = 0; i < ni; ++i) {
      const auto& a = at(ref, std::max(i - 1, 0));
      const auto& b = at(ref, std::min(i + 1, ni - 1));
      const double tx = b[0] - a[0], ty = b[1] - a[1];
      const double l = std::hypot(tx, ty);
      nrm[static_cast<std::size_t>(i)] = {-ty / l, tx / l};
    }
    nrm[0] = n_first;
    nrm[last] = n_last;
    // Implicit smoothing of the normals, (I - kappa_i delta^2) n_new = n, with kappa_i =
    // (step / local spacing)^2: normals then vary slowly over one step length along the layer,
    // so neighbouring lines cannot cross at concave corners, while near the wall (small
    // steps) they stay almost exactly orthogonal. Thomas algorithm; rows 0 and ni-1 fixed.
    {
      std::vector<double> cp(static_cast<std::size_t>(ni), 0.0), dx(static_cast<std::size_t>(ni)),
          dy(static_cast<std::size_t>(ni));
      auto n_at = [&](int i) -> point2& { return nrm[static_cast<std::size_t>(i)]; };
      for (int i = 1; i < ni - 1; ++i) {
        const double ds = 0.5 * std::hypot(at(ref, i + 1)[0] - at(ref, i - 1)[0], at(ref, i + 1)[1] - at(ref, i - 1)[1]);
        const double kap = smoothing * (h / ds) * (h / ds);
        double rx = n_at(i)[0], ry = n_at(i)[1];
        if (i == 1) {
          rx += kap * n_at(0)[0];
          ry += kap * n_at(0)[1];
        }
        if (i == ni - 2) {
          rx += kap * n_at(ni - 1)[0];
          ry += kap * n_at(ni - 1)[1];
        }
        const auto u = static_cast<std::size_t>(i);
        const double m = 1.0 + 2.0 * kap + (i > 1 ? kap * cp[u - 1] : 0.0);
        cp[u] = -kap / m;
        dx[u] = (rx + (i > 1 ? kap * dx[u - 1] : 0.0)) / m;
        dy[u] = (ry + (i > 1 ? kap * dy[u - 1] : 0.0)) / m;
      }
      for (int i = ni - 3; i >= 1; --i) {
        const auto u = static_cast<std::size_t>(i);
        dx[u] -= cp[u] * dx[u + 1];
        dy[u] -= cp[u] * dy[u + 1];
      }
      for (int i = 1; i < ni - 1; ++i) {
        const auto u = static_cast<std::size_t>(i);
        const double l = std::hypot(dx[u], dy[u]);
        nrm[u] = {dx[u] / l, dy[u] / l};
      }
    }
    auto& cur = layer[static_cast<std::size_t>(j)];
    for (int i = 0; i < ni; ++i) {
      const auto u = static_cast<std::size_t>(i);
      cur[u] = {prev[u][0] + h * nrm[u][0], prev[u][1] + h * nrm[u][1]};
    }
    // the wake's outflow ends move normally to the wake only (exactly, against rounding)
    auto project = [](point2& p, const point2& base, double tx, double ty) {
      const double l2 = tx * tx + ty * ty, s = ((p[0] - base[0]) * tx + (p[1] - base[1]) * ty) / l2;
      p = {p[0] - s * tx, p[1] - s * ty};
    };
    project(cur[0], prev[0], t0x, t0y);
    project(cur[last], prev[last], t1x, t1y);
    // Tangential redistribution: move each point along the layer towards the mid-point of its
    // neighbours (tangential component only), more strongly away from the wall.
    const double omega = std::min(0.5, 0.05 * j);
    const std::vector<point2> marched = max_shift > 0 ? cur : std::vector<point2>{};
    for (int s = 0; s < redistribution_passes; ++s) {
      for (int i = 1; i < ni - 1; ++i) {
        const auto u = static_cast<std::size_t>(i);
        const double tx = cur[u + 1][0] - cur[u - 1][0], ty = cur[u + 1][1] - cur[u - 1][1];
        const double l2 = tx * tx + ty * ty;
        const double dx = 0.5 * (cur[u + 1][0] + cur[u - 1][0]) - cur[u][0];
        const double dy = 0.5 * (cur[u + 1][1] + cur[u - 1][1]) - cur[u][1];
        const double along = (dx * tx + dy * ty) / l2;
        tmp[u] = {cur[u][0] + omega * along * tx, cur[u][1] + omega * along * ty};
      }
      for (int i = 1; i < ni - 1; ++i) cur[static_cast<std::size_t>(i)] = tmp[static_cast<std::size_t>(i)];
    }
    if (max_shift > 0)  // the wake lines' lean over this layer at most atan(max_shift)
      for (int i = 1; i < ni - 1; ++i) {
        if (i > wake_points && i < ni - 1 - wake_points) continue;
        const auto u = static_cast<std::size_t>(i);
        const double dx = cur[u][0] - marched[u][0], dy = cur[u][1] - marched[u][1], d = std::hypot(dx, dy);
        if (d > max_shift * h) cur[u] = {marched[u][0] + dx * (max_shift * h / d), marched[u][1] + dy * (max_shift * h / d)};
      }
  }
  return layer;
}

}  // namespace aerohopf::flow::internal
