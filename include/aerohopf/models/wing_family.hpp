#pragma once
// A flexible wing as a flutter_family (bifurcation/flutter_boundary.hpp): grid levels are the
// strides of a fine wing_cgrid (8 very coarse, 4 coarse, 2 medium, 1 fine), one wing_system per
// level and Mach number, the equilibrium with the wing at rest (a symmetric wing at zero
// incidence: the same for every density), injection between levels of ratio 2, the modal
// unknowns (a, a') for the mode test.
//
// Flight conditions: at each Mach number the free-stream speed U = M a(M), a the speed of sound
// of the wind tunnel's schedule (speed_of_sound_schedule: piecewise linear in M through the
// test points, constant beyond them), which fixes the reduced frequencies k_i = omega_i c / U;
// the bifurcation parameter is the density parameter mu = rho c^3 (models/wing.hpp). A flutter
// point (mu*, omega*) then gives the flutter density rho = mu / c^3, the mass ratio and the
// flutter speed index FSI = U / (b_s omega_alpha sqrt(mass ratio)) (flutter_numbers).
//
// The parameter enters the coupled Jacobian as mu B with B the derivative of the generalised
// forces: its rows are the structural ones, its columns include the wall cells' flow unknowns
// (axis_crossings.hpp handles that: H(w) = B_ss + B_sf X^{-1} A_fs). Its crossing check needs a
// complex sparse LU of the 3D flow Jacobian per frequency sample, so boundary_options() switches
// it off (turn it on for very coarse grids); on real grids the example's V-g diagram is the check
// that a point is the lowest crossing.
#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../bifurcation/flutter_boundary.hpp"
#include "../coupling/mesh_deformation.hpp"
#include "../error.hpp"
#include "../flow/euler_model.hpp"
#include "../flow/steady_solver.hpp"
#include "../flow/wing_grid.hpp"
#include "../structure/modal_data.hpp"
#include "../structure/modal_structure.hpp"
#include "wing.hpp"

namespace aerohopf::models {

/// Speed of sound a(M) (m/s) of a test schedule: linear in M between the points (mach
/// increasing), constant beyond the first and the last.
struct speed_of_sound_schedule {
  std::vector<double> mach, speed_of_sound;

  void validate(const std::string& who) const {
    require(!mach.empty() && mach.size() == speed_of_sound.size(), who, ": speed-of-sound schedule of ", mach.size(),
            " Mach numbers and ", speed_of_sound.size(), " speeds");
    for (std::size_t i = 0; i < mach.size(); ++i) {
      require(std::isfinite(mach[i]) && mach[i] > 0 && std::isfinite(speed_of_sound[i]) && speed_of_sound[i] > 0, who,
              ": schedule point ", i, " (M = ", mach[i], ", a = ", speed_of_sound[i], ") must be finite and > 0");
      require(i == 0 || mach[i] > mach[i - 1], who, ": schedule Mach numbers must increase (", mach[i - 1], ", ", mach[i],
              ")");
    }
  }
  double at(double m) const {
    if (m <= mach.front()) return speed_of_sound.front();
    if (m >= mach.back()) return speed_of_sound.back();
    const auto hi = static_cast<std::size_t>(std::upper_bound(mach.begin(), mach.end(), m) - mach.begin());
    const double t = (m - mach[hi - 1]) / (mach[hi] - mach[hi - 1]);
    return (1 - t) * speed_of_sound[hi - 1] + t * speed_of_sound[hi];
  }
  /// The free-stream speed M a(M).
  double speed(double m) const { return m * at(m); }
};

/// What turns a flutter density into the flutter speed index: FSI = U / (b_s omega_alpha
/// sqrt(mass ratio)), mass ratio = wing mass / (rho * frustum volume).
struct flutter_reference {
  double wing_mass = 0;       ///< kg
  double frustum_volume = 0;  ///< m^3: the truncated cone on the root and tip chords over the semi-span
  double semichord = 0;       ///< b_s, m (the root semichord)
  double omega_alpha = 0;     ///< rad/s (the first torsion mode's)

  /// The frustum of a planform: pi b / 12 (c_r^2 + c_r c_t + c_t^2).
  static double frustum_of(const flow::wing_planform& p) {
    const double cr = p.root_chord, ct = p.tip_chord;
    return std::numbers::pi * p.semi_span / 12 * (cr * cr + cr * ct + ct * ct);
  }
};

/// The flutter numbers of a point (mu*, omega*) at speed U and reference chord c.
struct flutter_numbers {
  double density = 0;          ///< rho = mu / c^3, kg/m^3
  double mass_ratio = 0;
  double fsi = 0;              ///< flutter speed index
  double frequency_ratio = 0;  ///< omega_f / omega_alpha, omega_f = omega* U / c
  double dynamic_pressure = 0; ///< rho U^2 / 2, Pa
  double frequency_hz = 0;

  static flutter_numbers of(double mu, double omega, double speed, double chord, const flutter_reference& r) {
    require(mu > 0 && std::isfinite(mu) && speed > 0 && chord > 0 && r.wing_mass > 0 && r.frustum_volume > 0 &&
                r.semichord > 0 && r.omega_alpha > 0,
            "flutter_numbers: need mu > 0 (got ", mu, "), speed, chord and the reference quantities > 0");
    flutter_numbers n;
    n.density = mu / (chord * chord * chord);
    n.mass_ratio = r.wing_mass / (n.density * r.frustum_volume);
    n.fsi = speed / (r.semichord * r.omega_alpha * std::sqrt(n.mass_ratio));
    const double omega_f = std::abs(omega) * speed / chord;
    n.frequency_ratio = omega_f / r.omega_alpha;
    n.frequency_hz = omega_f / (2 * std::numbers::pi);
    n.dynamic_pressure = 0.5 * n.density * speed * speed;
    return n;
  }
};

class wing_family {
 public:
  using system_type = wing_system;
  static constexpr int block_size = wing_system::nv;

  /// wing and grid: the fine grid wing_cgrid(wing, grid) whose coarsenings by `strides` are the
  /// levels (each a power of 2 dividing the grid's counts); modes: the structure's modal data
  /// (points in metres); damping_ratio: one per mode, or one entry for all; sound: the test's
  /// speed-of-sound schedule; flow: Euler options (force_tag defaults to the wing's "wing").
  wing_family(const flow::wing_geometry& wing, const flow::wing_grid_options& grid, std::vector<int> strides,
              structure::modal_data modes, Eigen::VectorXd damping_ratio, speed_of_sound_schedule sound,
              flow::euler_options flow = {.force_tag = "wing"})
      : planform_(wing.planform), modes_(std::move(modes)), sound_(std::move(sound)), flow_(std::move(flow)) {
    const char* who = "wing_family";
    modes_.validate(who);
    sound_.validate(who);
    require(!strides.empty(), who, ": no grid levels");
    const Eigen::Index m = modes_.modes();
    require(damping_ratio.size() == m || damping_ratio.size() == 1, who, ": ", damping_ratio.size(),
            " damping ratios for ", m, " modes");
    zeta_ = damping_ratio.size() == m ? damping_ratio : Eigen::VectorXd::Constant(m, damping_ratio[0]);
    if (flow_.force_tag.empty()) flow_.force_tag = "wing";
    std::sort(strides.begin(), strides.end());
    strides.erase(std::unique(strides.begin(), strides.end()), strides.end());
    const flow::multiblock_grid<3> fine = flow::wing_cgrid(wing, grid);
    for (int s : strides) {
      require(s >= 1 && (s & (s - 1)) == 0, who, ": grid stride ", s, " must be a power of 2");
      (void)flow::wing_grid_layout::of(grid, s);  // refuses a stride that does not divide the counts
      level l{s == 1 ? fine : flow::coarsen(fine, s), {}};
      coupling::wing_motion_options o;
      o.length_scale = planform_.root_chord;
      o.grid = grid;
      o.stride = s;
      l.motion.emplace(l.grid, modes_, o);
      levels_.emplace(s, std::move(l));
    }
  }

  /// The coupled system on level `stride` at Mach number `mach` (U = M a(M)).
  wing_system system(int stride, double mach) const {
    const level& l = at(stride);
    require(std::isfinite(mach) && mach > 0, "wing_family: Mach number ", mach, " must be finite and > 0");
    return wing_system(flow::euler_model<3>(l.grid, {.mach = mach, .alpha_rad = 0.0}, flow_), *l.motion,
                       structure::modal_structure::from_physical(modes_.omega, zeta_, planform_.root_chord,
                                                                 sound_.speed(mach)));
  }

  static std::string level_name(int stride) { return flow::level_name(stride); }

  /// The steady flow about the wing at rest (wing_system::steady_equilibrium), the same for every mu.
  vec<double> equilibrium(const wing_system& s, double /*mu*/) const { return s.steady_equilibrium(steady_); }
  vec<double> equilibrium_from(const wing_system& s, const vec<double>& w0, double, double) const {
    require_size(w0.size(), s.size(), "wing_family::equilibrium_from", "start state");
    return w0;
  }
  bool fixed_equilibrium() const { return true; }

  bool refines(int coarse, int fine) const {
    return coarse == 2 * fine && levels_.count(coarse) && levels_.count(fine);
  }
  std::optional<int> coarser_level(int stride) const {
    return levels_.count(2 * stride) ? std::optional<int>(2 * stride) : std::nullopt;
  }
  vec<std::complex<double>> prolong(const wing_system& fine, const wing_system& coarse,
                                    const vec<std::complex<double>>& p) const {
    return fine.prolong_from<std::complex<double>>(coarse, 2, p);
  }
  vec<std::complex<double>> structure_part(const vec<std::complex<double>>& p) const {
    const Eigen::Index ns = 2 * modes_.modes();
    require(p.size() >= ns, "wing_family::structure_part: vector of size ", p.size());
    return p.tail(ns);
  }
  /// A = A0 + mu B (B: the generalised forces' derivative, structural rows; file comment).
  static double stiffness_factor(double mu) { return mu; }
  static double parameter_of_factor(double q) { return q; }

  /// The driver's options for a wing: the tracer's metric mu / 0.005, M / 0.01, omega / 0.02
  /// (AGARD 445.6: mu* 0.005-0.08, omega* 0.15-0.5), mu in [1e-4, 1] (also for the continued
  /// points: flutter_boundary_options::mu_min); the inverse-power start
  /// to 1e-3 (its solves are the dearest part of a first point: 110 s of 131 s on the coarse
  /// grid at 1e-8, measured) with GMRES(80) (GMRES(50) stagnated at a relative residual of 0.98
  /// on the coarse grid at M = 0.901, GMRES(80) converged); no crossing check (its sparse
  /// LUs: file comment).
  flutter_boundary_options boundary_options() const {
    flutter_boundary_options o;
    o.check_crossings = false;
    o.start_restart = 80;
    o.mu_min = 1e-4;  // mu = 0: the undamped in-vacuo modes (flutter_boundary_options::mu_min)
    o.positive_parameter = true;  // the secant in log mu (a linear one predicted mu < 0 past M = 0.68)
    hopf_curve_options& c = o.curve;
    c.mu_scale = 0.005;
    c.nu_scale = 0.01;
    c.omega_scale = 0.02;
    c.max_step = 1.0;
    c.step = 0.5;
    c.min_step = 1e-3;
    c.mu_min = 1e-4;
    c.mu_max = 1.0;
    c.newton.max_iterations = 8;
    c.newton.max_contraction = 1.0;
    o.fixed_equilibrium.steady.abs_tolerance = 1e-10;
    o.fixed_equilibrium.derivative_tolerance = 1e-4;
    return o;
  }

  /// The flutter numbers of a point (mu, omega) at Mach number `mach`.
  flutter_numbers numbers(double mach, double mu, double omega, const flutter_reference& r) const {
    return flutter_numbers::of(mu, omega, sound_.speed(mach), planform_.root_chord, r);
  }

  const flow::multiblock_grid<3>& grid(int stride) const { return at(stride).grid; }
  const coupling::wing_modal_motion& motion(int stride) const { return *at(stride).motion; }
  const structure::modal_data& modes() const { return modes_; }
  const speed_of_sound_schedule& sound() const { return sound_; }
  const flow::wing_planform& planform() const { return planform_; }
  flow::steady_options& steady_options() { return steady_; }
  const flow::steady_options& steady_options() const { return steady_; }

 private:
  struct level {
    flow::multiblock_grid<3> grid;
    std::optional<coupling::wing_modal_motion> motion;
  };
  const level& at(int stride) const {
    const auto it = levels_.find(stride);
    require(it != levels_.end(), "wing_family: no grid level of stride ", stride);
    return it->second;
  }

  flow::wing_planform planform_;
  structure::modal_data modes_;
  Eigen::VectorXd zeta_;
  speed_of_sound_schedule sound_;
  flow::euler_options flow_;
  std::map<int, level> levels_;
  flow::steady_options steady_;
};

}  // namespace aerohopf::models
