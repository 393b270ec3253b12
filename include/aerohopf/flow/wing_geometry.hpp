#pragma once
// Wing geometry shared by the wing grid generator (flow/) and the plate finite elements that make
// the wing's modes (structure/): a straight-tapered swept planform and a symmetric section given
// by half-thickness ordinates.
//
// Planform (spec 06): x streamwise (downstream), y spanwise from the root (symmetry plane) to the
// tip, z up. The leading edge is the straight line x_le(y) = y tan(Lambda_le); the chord falls
// linearly from c_root to c_tip. Lengths in metres, or in any unit used consistently.
//
// Section: tabulated ordinates z/c at stations x/c (the half-thickness of a symmetric section, or
// the upper and lower surfaces of a cambered one), each interpolated by a monotone cubic
// (Fritsch-Carlson) in u = sqrt(x/c): a round leading edge has z ~ sqrt(x/c), which is linear in
// u, so the interpolant keeps the nose shape that a cubic in x/c would wiggle about and it never
// overshoots the table (no negative thickness, no spurious bumps).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"

namespace aerohopf::flow {

namespace internal {
/// Monotone piecewise-cubic Hermite interpolant (Fritsch-Carlson) of z over increasing u.
class monotone_cubic {
 public:
  monotone_cubic() = default;
  monotone_cubic(std::vector<double> u, std::vector<double> z) : u_(std::move(u)), z_(std::move(z)) {
    const std::size_t n = u_.size();
    std::vector<double> del(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) del[k] = (z_[k + 1] - z_[k]) / (u_[k + 1] - u_[k]);
    d_.assign(n, 0.0);
    d_[0] = del[0];
    d_[n - 1] = del[n - 2];
    for (std::size_t k = 1; k + 1 < n; ++k) {
      if (del[k - 1] * del[k] <= 0) continue;  // a local extremum: flat
      const double w1 = 2 * (u_[k + 1] - u_[k]) + (u_[k] - u_[k - 1]);
      const double w2 = (u_[k + 1] - u_[k]) + 2 * (u_[k] - u_[k - 1]);
      d_[k] = (w1 + w2) / (w1 / del[k - 1] + w2 / del[k]);  // weighted harmonic mean
    }
  }
  double operator()(double u) const {
    const auto it = std::upper_bound(u_.begin(), u_.end(), u);
    const std::size_t k = std::min<std::size_t>(std::max<std::ptrdiff_t>(it - u_.begin(), 1), u_.size() - 1) - 1;
    const double h = u_[k + 1] - u_[k], s = (u - u_[k]) / h;
    const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s), h01 = s * s * (3 - 2 * s),
                 h11 = s * s * (s - 1);
    return h00 * z_[k] + h10 * h * d_[k] + h01 * z_[k + 1] + h11 * h * d_[k + 1];
  }

 private:
  std::vector<double> u_, z_, d_;
};
}  // namespace internal

/// Section by ordinates (fractions of the chord) at stations x/c: symmetric (half-thickness) or
/// cambered (upper and lower surfaces).
class section_ordinates {
 public:
  /// Symmetric section: x_over_c strictly increasing from 0 to 1; half_thickness >= 0, 0 at the
  /// leading edge (a blunt trailing edge keeps its last ordinate).
  section_ordinates(std::vector<double> x_over_c, std::vector<double> half_thickness, std::string name)
      : x_(std::move(x_over_c)), z_(std::move(half_thickness)), name_(std::move(name)) {
    zl_.resize(z_.size());
    for (std::size_t i = 0; i < z_.size(); ++i) zl_[i] = -z_[i];
    build(true);
  }
  /// Cambered section: upper and lower surface ordinates z/c at the same stations, upper >= lower,
  /// equal at the leading edge.
  section_ordinates(std::vector<double> x_over_c, std::vector<double> upper, std::vector<double> lower, std::string name)
      : x_(std::move(x_over_c)), z_(std::move(upper)), zl_(std::move(lower)), name_(std::move(name)) {
    build(false);
  }

  const std::string& name() const { return name_; }
  const std::vector<double>& stations() const { return x_; }
  /// The upper surface's ordinates (the half-thickness of a symmetric section).
  const std::vector<double>& ordinates() const { return z_; }
  const std::vector<double>& lower_ordinates() const { return zl_; }
  bool symmetric() const { return symmetric_; }

  /// Upper and lower surface z/c at x/c in [0, 1] (clamped outside).
  double upper(double x_over_c) const { return up_(std::sqrt(std::clamp(x_over_c, 0.0, 1.0))); }
  double lower(double x_over_c) const {
    return symmetric_ ? -upper(x_over_c) : lo_(std::sqrt(std::clamp(x_over_c, 0.0, 1.0)));
  }
  /// Half-thickness z_t / c and camber z_c / c (0 for a symmetric section, exactly).
  double half_thickness(double x_over_c) const {
    return symmetric_ ? upper(x_over_c) : 0.5 * (upper(x_over_c) - lower(x_over_c));
  }
  double camber(double x_over_c) const { return symmetric_ ? 0.0 : 0.5 * (upper(x_over_c) + lower(x_over_c)); }
  /// Thickness-to-chord ratio (largest 2 z_t / c over a fine sampling).
  double thickness_ratio() const {
    double t = 0;
    for (int i = 0; i <= 2000; ++i) t = std::max(t, half_thickness(i / 2000.0));
    return 2 * t;
  }

 private:
  void build(bool symmetric) {
    symmetric_ = symmetric;
    const std::string who = "section_ordinates(" + name_ + ")";
    require(x_.size() == z_.size() && x_.size() == zl_.size(), who, ": ", x_.size(), " stations but ", z_.size(),
            " upper and ", zl_.size(), " lower ordinates");
    require(x_.size() >= 3, who, ": need at least 3 stations (got ", x_.size(), ")");
    require_finite(x_, who, "x/c");
    require_finite(z_, who, symmetric ? "half-thickness" : "upper ordinate");
    require_finite(zl_, who, "lower ordinate");
    require(x_.front() == 0.0 && x_.back() == 1.0, who, ": stations must run from x/c = 0 to 1 (got ", x_.front(),
            " .. ", x_.back(), ")");
    for (std::size_t i = 1; i < x_.size(); ++i)
      require(x_[i] > x_[i - 1], who, ": stations must increase strictly (x/c[", i, "] = ", x_[i], " after ", x_[i - 1],
              ")");
    for (std::size_t i = 0; i < z_.size(); ++i) {
      if (symmetric)
        require(z_[i] >= 0.0 && z_[i] < 0.5, who, ": half-thickness ", z_[i], " at x/c = ", x_[i], " outside [0, 0.5)");
      else
        require(z_[i] >= zl_[i] && z_[i] - zl_[i] < 1.0 && std::abs(z_[i]) < 0.5 && std::abs(zl_[i]) < 0.5, who,
                ": at x/c = ", x_[i], " the upper ordinate ", z_[i], " lies below the lower one ", zl_[i],
                " or outside (-0.5, 0.5)");
    }
    require(z_.front() == zl_.front(), who, ": the surfaces must meet at the leading edge (z/c ", z_.front(), " and ",
            zl_.front(), ")");
    std::vector<double> u(x_.size());
    for (std::size_t i = 0; i < x_.size(); ++i) u[i] = std::sqrt(x_[i]);
    up_ = internal::monotone_cubic(u, z_);
    if (!symmetric) lo_ = internal::monotone_cubic(u, zl_);
  }
  std::vector<double> x_, z_, zl_;
  std::string name_;
  bool symmetric_ = true;
  internal::monotone_cubic up_, lo_;
};

/// Straight-tapered swept planform.
struct wing_planform {
  double root_chord = 1.0;
  double tip_chord = 1.0;
  double semi_span = 1.0;
  double leading_edge_sweep_tan = 0.0;  ///< tan of the leading-edge sweep angle

  void validate(const std::string& who) const {
    require(std::isfinite(root_chord) && root_chord > 0, who, ": root chord must be > 0 (got ", root_chord, ")");
    require(std::isfinite(tip_chord) && tip_chord > 0, who, ": tip chord must be > 0 (got ", tip_chord, ")");
    require(std::isfinite(semi_span) && semi_span > 0, who, ": semi-span must be > 0 (got ", semi_span, ")");
    require(std::isfinite(leading_edge_sweep_tan), who, ": leading-edge sweep is not finite");
  }
  double chord(double y) const { return root_chord + (tip_chord - root_chord) * y / semi_span; }
  double x_leading_edge(double y) const { return y * leading_edge_sweep_tan; }
  /// Point at chord fraction xi (0 leading edge, 1 trailing edge) and span station y.
  double x_at(double xi, double y) const { return x_leading_edge(y) + xi * chord(y); }
  double taper_ratio() const { return tip_chord / root_chord; }
  /// Half-wing area.
  double area() const { return 0.5 * (root_chord + tip_chord) * semi_span; }
  /// Mean aerodynamic chord (2/3) c_r (1 + l + l^2) / (1 + l), l the taper ratio.
  double mean_aerodynamic_chord() const {
    const double l = taper_ratio();
    return 2.0 / 3.0 * root_chord * (1 + l + l * l) / (1 + l);
  }
  /// tan of the sweep of the line at chord fraction f (0.25: quarter chord).
  double sweep_tan(double f) const { return leading_edge_sweep_tan + f * (tip_chord - root_chord) / semi_span; }
  /// Aspect ratio of the full wing, (2 b)^2 / (2 S).
  double aspect_ratio() const { return 2 * semi_span * semi_span / area(); }
};

/// A wing: planform and section (the same section at every span station).
struct wing_geometry {
  std::string name;
  wing_planform planform;
  section_ordinates section;

  /// Local thickness at the planform point (x, y): 2 z_t(xi) c(y), 0 outside the chord.
  double thickness(double x, double y) const {
    const double c = planform.chord(y), xi = (x - planform.x_leading_edge(y)) / c;
    if (xi < 0 || xi > 1) return 0.0;
    return 2 * section.half_thickness(xi) * c;
  }
};

/// NACA 65A004 half-thickness ordinates in % chord (the AGARD R-765 set of spec 06).
inline section_ordinates naca65a004() {
  std::vector<double> x = {0,  0.5, 0.75, 1.25, 2.5, 5,  7.5, 10, 15, 20, 25, 30, 35,
                           40, 45,  50,   55,   60,  65, 70,  75, 80, 85, 90, 95, 100};
  std::vector<double> z = {0,     0.304, 0.368, 0.469, 0.647, 0.875, 1.059, 1.213, 1.459,
                           1.645, 1.789, 1.892, 1.962, 1.997, 1.996, 1.954, 1.868, 1.743,
                           1.586, 1.402, 1.195, 0.967, 0.729, 0.490, 0.250, 0};
  for (double& v : x) v /= 100;
  for (double& v : z) v /= 100;
  return section_ordinates(std::move(x), std::move(z), "NACA 65A004");
}

/// Biconvex parabolic-arc section of thickness ratio t (the Goland wing's, spec 06): z_t / c = 2 t
/// x (1 - x), tabulated at 81 cosine-spaced stations.
inline section_ordinates parabolic_arc(double t) {
  require(std::isfinite(t) && t > 0 && t < 0.5, "parabolic_arc: thickness ratio must lie in (0, 0.5) (got ", t, ")");
  std::vector<double> x(81), z(81);
  for (int i = 0; i <= 80; ++i) {
    x[static_cast<std::size_t>(i)] = 0.5 * (1 - std::cos(std::numbers::pi * i / 80));
    z[static_cast<std::size_t>(i)] = 2 * t * x[static_cast<std::size_t>(i)] * (1 - x[static_cast<std::size_t>(i)]);
  }
  x.front() = 0;
  x.back() = 1;
  z.front() = z.back() = 0;
  return section_ordinates(std::move(x), std::move(z), "parabolic arc " + std::to_string(t));
}

/// AGARD 445.6 wing (spec 06): root chord 0.5587 m, tip chord 0.3682 m, semi-span 0.762 m,
/// leading-edge sweep tan = 1.0625 (tip leading edge at x = 31.87 in), NACA 65A004 section.
inline wing_geometry agard445_6() {
  wing_planform p;
  p.root_chord = 0.5587;
  p.tip_chord = 0.3682;
  p.semi_span = 0.762;
  p.leading_edge_sweep_tan = 1.0625;
  return {"AGARD 445.6", p, naca65a004()};
}

}  // namespace aerohopf::flow
