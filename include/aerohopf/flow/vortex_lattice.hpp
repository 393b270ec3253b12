#pragma once
// Lifting-surface theory for a planform's lift slope: the vortex-lattice method (horseshoe
// vortices on the quarter-chord line of each panel, control points on its three-quarter-chord
// line, trailing legs to x = +infinity in the wing plane; Katz and Plotkin, Low-Speed
// Aerodynamics, ch. 12), for a symmetric half wing with its mirror image, and compressibility by
// the Prandtl-Glauert-Goethert rule: the incompressible lift slope of the planform stretched by
// 1/beta in x, divided by beta (beta = sqrt(1 - M^2)). An independent check of the Euler wing
// solutions at small angle of attack (thin-wing limit: thickness adds a few percent).
#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <numbers>

#include "../error.hpp"
#include "wing_geometry.hpp"

namespace aerohopf::flow {

namespace internal {
using vec3 = std::array<double, 3>;
inline vec3 sub3(const vec3& a, const vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline vec3 cross3(const vec3& a, const vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot3(const vec3& a, const vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm3(const vec3& a) { return std::sqrt(dot3(a, a)); }

/// z-velocity at p of a unit horseshoe: from +infinity (along +x) to a, a to b, b to +infinity.
inline double horseshoe_w(const vec3& p, const vec3& a, const vec3& b) {
  const double core = 1e-12;
  auto segment = [&](const vec3& s0, const vec3& s1) {  // Biot-Savart, finite segment s0 -> s1
    const vec3 r1 = sub3(p, s0), r2 = sub3(p, s1), r0 = sub3(s1, s0);
    const vec3 c = cross3(r1, r2);
    const double c2 = dot3(c, c), n1 = norm3(r1), n2 = norm3(r2);
    if (c2 < core * core || n1 < core || n2 < core) return 0.0;
    return c[2] / c2 * (dot3(r0, r1) / n1 - dot3(r0, r2) / n2) / (4 * std::numbers::pi);
  };
  auto semi = [&](const vec3& q) {  // from q to +infinity along +x
    const vec3 e = {1, 0, 0}, r = sub3(p, q);
    const vec3 c = cross3(e, r);
    const double c2 = dot3(c, c), n = norm3(r);
    if (c2 < core * core) return 0.0;
    return c[2] / c2 * (1 + dot3(e, r) / n) / (4 * std::numbers::pi);
  };
  return segment(a, b) + semi(b) - semi(a);
}
}  // namespace internal

struct vortex_lattice_result {
  double lift_slope = 0;  ///< dCL/dalpha per radian, reference area the half wing's (= the wing's)
  Eigen::VectorXd span_loading;  ///< c c_l / (c_mean CL) at the span stations' mid-points, root to tip
  Eigen::VectorXd stations;      ///< y / semi-span of those mid-points
};

/// Lift slope of the planform at Mach number `mach` (< 1) with nc chordwise and ns spanwise panels
/// (spanwise cosine spacing, finer at root and tip; chordwise uniform).
inline vortex_lattice_result vortex_lattice_lift_slope(const wing_planform& p, double mach, int nc = 8, int ns = 24) {
  const char* who = "vortex_lattice_lift_slope";
  p.validate(who);
  require(std::isfinite(mach) && mach >= 0 && mach < 1, who, ": Mach number must lie in [0, 1) (got ", mach, ")");
  require(nc >= 1 && ns >= 1 && nc * ns <= 20000, who, ": need 1 <= nc, ns and nc ns <= 20000 (got ", nc, ", ", ns, ")");
  const double beta = std::sqrt(1 - mach * mach);
  const int n = nc * ns;
  std::vector<double> y(static_cast<std::size_t>(ns) + 1);
  for (int j = 0; j <= ns; ++j) y[static_cast<std::size_t>(j)] = p.semi_span * 0.5 * (1 - std::cos(std::numbers::pi * j / ns));
  auto point = [&](double xi, double yy) -> internal::vec3 { return {p.x_at(xi, yy) / beta, yy, 0.0}; };
  std::vector<internal::vec3> a(static_cast<std::size_t>(n)), b(static_cast<std::size_t>(n)), cp(static_cast<std::size_t>(n));
  std::vector<double> dy(static_cast<std::size_t>(n));
  for (int j = 0; j < ns; ++j)
    for (int i = 0; i < nc; ++i) {
      const auto m = static_cast<std::size_t>(j * nc + i);
      const double xi0 = static_cast<double>(i) / nc, dxi = 1.0 / nc;
      const double y0 = y[static_cast<std::size_t>(j)], y1 = y[static_cast<std::size_t>(j + 1)], ym = 0.5 * (y0 + y1);
      a[m] = point(xi0 + 0.25 * dxi, y0);
      b[m] = point(xi0 + 0.25 * dxi, y1);
      cp[m] = point(xi0 + 0.75 * dxi, ym);
      dy[m] = y1 - y0;
    }
  Eigen::MatrixXd inf(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const auto rc = static_cast<std::size_t>(r), cc = static_cast<std::size_t>(c);
      const internal::vec3 am = {a[cc][0], -a[cc][1], 0.0}, bm = {b[cc][0], -b[cc][1], 0.0};
      inf(r, c) = internal::horseshoe_w(cp[rc], a[cc], b[cc]) + internal::horseshoe_w(cp[rc], bm, am);  // + mirror
    }
  // flow tangency at alpha = 1 rad (linear): w_induced = -V alpha, V = 1
  const Eigen::VectorXd gamma = inf.partialPivLu().solve(Eigen::VectorXd::Constant(n, -1.0));
  require(gamma.allFinite(), who, ": the influence matrix is singular");
  vortex_lattice_result r;
  r.span_loading.resize(ns);
  r.stations.resize(ns);
  double lift = 0;  // half wing, rho = 1, V = 1
  for (int j = 0; j < ns; ++j) {
    double g = 0;
    for (int i = 0; i < nc; ++i) g += gamma[j * nc + i];
    lift += g * dy[static_cast<std::size_t>(j * nc)];
    r.span_loading[j] = g;
    r.stations[j] = 0.5 * (y[static_cast<std::size_t>(j)] + y[static_cast<std::size_t>(j + 1)]) / p.semi_span;
  }
  const double area_stretched = p.area() / beta;
  const double cl_inc = 2 * lift / area_stretched;  // CL = L / (q S), q = 1/2
  r.lift_slope = cl_inc / beta;
  // c c_l = 2 Gamma / V (Gamma is the same in the stretched problem); over the mean chord times CL
  r.span_loading *= 2 / (p.area() / p.semi_span * r.lift_slope);
  return r;
}

/// The DATCOM / Helmbold-Diederich semi-empirical lift slope per radian (section lift slope 2 pi),
/// 2 pi A / (2 + sqrt(A^2 beta^2 (1 + tan^2 Lambda_c/2 / beta^2) + 4)), A the full wing's aspect
/// ratio, Lambda_c/2 the mid-chord sweep: a second, independent estimate.
inline double datcom_lift_slope(const wing_planform& p, double mach) {
  p.validate("datcom_lift_slope");
  require(std::isfinite(mach) && mach >= 0 && mach < 1, "datcom_lift_slope: Mach number must lie in [0, 1) (got ",
          mach, ")");
  const double a = p.aspect_ratio(), b2 = 1 - mach * mach, t = p.sweep_tan(0.5);
  return 2 * std::numbers::pi * a / (2 + std::sqrt(a * a * b2 * (1 + t * t / b2) + 4));
}

}  // namespace aerohopf::flow
