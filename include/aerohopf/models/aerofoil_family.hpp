#pragma once
// The pitch-plunge aerofoil of spec 05 as a flutter_family (bifurcation/flutter_boundary.hpp):
// grid levels are the strides of a fine C-grid (every stride-th point: 8 very coarse, 4 coarse,
// 2 medium, 1 fine), one aerofoil_system per level and Mach number, the equilibrium with the
// section at rest (symmetric section at zero incidence: the same for every Ubar), injection
// between levels of ratio 2, the structural unknowns (h, h', alpha, alpha') for the mode test,
// and Ubar entering the stiffness as 1/Ubar^2 (the crossing check).
// At a non-zero angle of attack the flow loads the section, so the equilibrium is the static
// aeroelastic one and moves with Ubar (spec 05, "A moving equilibrium"): static_equilibrium
// solves it by Newton-Krylov on the coupled system from the steady flow about the section at
// rest (pseudo-transient, the unit of cost). boundary_options() are the driver's options that
// suit this family (the tracer's step metric in (Ubar, M, omega), its bounds and tolerances).
#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <utility>

#include "../bifurcation/equilibrium_krylov.hpp"
#include "../bifurcation/flutter_boundary.hpp"
#include "../error.hpp"
#include "../flow/euler_model.hpp"
#include "../flow/steady_solver.hpp"
#include "../flow/structured_grid.hpp"
#include "../structure/pitch_plunge.hpp"
#include "aerofoil.hpp"

namespace aerohopf::models {

class aerofoil_family {
 public:
  using system_type = aerofoil_system;
  static constexpr int block_size = aerofoil_system::nv;

  /// fine: the finest grid (levels coarsen it); structure: the section; flow: the Euler options;
  /// alpha_rad: the free-stream angle of attack.
  aerofoil_family(flow::multiblock_grid<2> fine, structure::pitch_plunge_parameters structure,
                  flow::euler_options flow = {}, double alpha_rad = 0.0)
      : fine_(std::move(fine)), structure_(structure), flow_(flow), alpha_(alpha_rad) {
    require(std::isfinite(alpha_rad), "aerofoil_family: angle of attack ", alpha_rad, " is not finite");
  }

  /// The coupled system on level `stride` at Mach number `mach`.
  aerofoil_system system(int stride, double mach) const {
    require(stride >= 1, "aerofoil_family: grid stride ", stride, " must be >= 1");
    return aerofoil_system(flow::euler_model<2>(stride == 1 ? fine_ : flow::coarsen(fine_, stride),
                                                {.mach = mach, .alpha_rad = alpha_}, flow_),
                           structure::pitch_plunge(structure_));
  }

  static std::string level_name(int stride) { return flow::level_name(stride); }

  /// The equilibrium of s at Ubar: at zero incidence the steady flow from the free stream with
  /// the section at rest (aerofoil_system::steady_equilibrium: throws convergence_error if the
  /// flow loads the section), the same for every Ubar; else static_equilibrium.
  vec<double> equilibrium(const aerofoil_system& s, double ubar) const {
    return alpha_ == 0.0 ? s.steady_equilibrium(steady_) : static_equilibrium(s, ubar);
  }

  /// true: the equilibrium does not depend on Ubar (zero incidence), the fixed-equilibrium Hopf
  /// system applies.
  bool fixed_equilibrium() const { return alpha_ == 0.0; }

  /// The static aeroelastic equilibrium at Ubar: the steady flow about the section at rest
  /// (aerofoil_system::steady_equilibrium, loads allowed), then Newton-Krylov on the coupled
  /// system (solve_equilibrium_krylov, BILU(fill), ||f||_2 <= tolerance) for the deflected section
  /// and its flow, in FULL Newton steps: from the loaded rest state the first step overshoots the
  /// deflection and raises ||f||, and a halving line search then crawls (NACA 0012 coarse,
  /// alpha_0 = 1 deg, Ubar = 1.66: no convergence in 40 damped iterations; 6 full ones on the
  /// very coarse grid).
  vec<double> static_equilibrium(const aerofoil_system& s, double ubar, int fill = 2, double tolerance = 1e-10) const {
    require(std::isfinite(ubar) && ubar != 0.0, "aerofoil_family::static_equilibrium: Ubar = ", ubar);
    return static_equilibrium_from(s, s.steady_equilibrium(steady_, INFINITY), 0.0, ubar, fill, tolerance);
  }

  /// The same from w0, the static equilibrium at Ubar u0 (0: the section at rest, any Ubar),
  /// continued to ubar (up or down in |Ubar|; the deflection grows like Ubar^2): a failed solve
  /// is retried from half the remaining step, down to 1/64 of |Ubar|; then convergence_error
  /// names the last Ubar reached.
  vec<double> static_equilibrium_from(const aerofoil_system& s, vec<double> w0, double u0, double ubar, int fill = 2,
                                      double tolerance = 1e-10) const {
    require(std::isfinite(ubar) && ubar != 0.0 && std::isfinite(u0), "aerofoil_family::static_equilibrium_from: Ubar = ",
            ubar, " from ", u0);
    require_size(w0.size(), s.size(), "aerofoil_family::static_equilibrium_from", "start state");
    equilibrium_krylov_options eo;
    eo.fill_level = fill;
    eo.newton.abs_tolerance = tolerance;
    eo.newton.max_iterations = 25;
    eo.newton.throw_on_failure = false;
    eo.newton.line_search = false;
    const std::string who =
        internal::concat("aerofoil_family::static_equilibrium at M = ", s.flow().conditions().mach, ", Ubar = ", ubar);
    return continue_in_ubar(std::move(w0), u0, ubar, who,
                            [&](const vec<double>& w, double u, std::string& why) -> std::optional<vec<double>> {
                              auto r = solve_equilibrium_krylov<block_size>(s, u, w, eo, who);
                              if (r.report.converged) return std::move(r.w);
                              why = r.report.reason;
                              return std::nullopt;
                            });
  }

  /// The continuation of static_equilibrium_from, for any solver of the static equilibrium:
  /// from w, the equilibrium at u0, to ubar in steps of |Ubar| (doubled after a success);
  /// solve(w, u, why) returns the equilibrium at |Ubar| = u from w, or nothing with the reason in
  /// why; a failed step is retried from half of it, down to 1/64 of |Ubar|, then
  /// convergence_error (who, the Ubar tried and reached, the reason).
  template <class Solve>
  static vec<double> continue_in_ubar(vec<double> w, double u0, double ubar, const std::string& who, Solve&& solve) {
    const double a = std::abs(ubar);
    double u = std::abs(u0), step = a - u;  // signed: towards a
    while (u != a) {
      const double next = std::abs(a - u) <= std::abs(step) ? a : u + step;
      std::string why;
      if (auto r = solve(w, next, why)) {
        w = std::move(*r);
        u = next;
        step *= 2;
        continue;
      }
      step *= 0.5;
      if (std::abs(step) < a / 64)
        throw convergence_error(
            internal::concat(who, ": Newton-Krylov failed at Ubar = ", next, " from Ubar = ", u, " (", why, ")"));
    }
    return w;
  }

  /// The equilibrium at ubar from w0, the one at u0 (flutter_family's optional continuation):
  /// w0 itself at zero incidence, else static_equilibrium_from.
  vec<double> equilibrium_from(const aerofoil_system& s, const vec<double>& w0, double u0, double ubar) const {
    if (alpha_ != 0.0) return static_equilibrium_from(s, w0, u0, ubar);
    require_size(w0.size(), s.size(), "aerofoil_family::equilibrium_from", "start state");
    return w0;
  }

  /// The flutter-boundary driver's options for this family: the tracer's step metric Ubar / 0.5,
  /// M / 0.01, omega / 0.05 (a step of 1 is at most 0.01 in M), steps 0.5 .. 1 down to 1e-3,
  /// Ubar in [0.2, 20]; 8 Newton iterations per corrector, abandoned once ||F|| rises after its
  /// first step (on the heavy medium grid near M = 0.826 every converged corrector was monotone
  /// from iteration 2 on, the failed ones rose 1.4-2500x: fail fast for the next fallback); the
  /// nested steady Newton to ||f||_2 <= 1e-10 (1e-11 is the medium grid's rounding floor) and
  /// dw0/dnu by GMRES to 1e-4 (it only sets a Jacobian column and the warm start); Ubar enters
  /// as 1/Ubar^2 (parameter_even); the moving-equilibrium mode at non-zero incidence. The start
  /// guess (start_mu, start_omega) is the case's.
  flutter_boundary_options boundary_options() const {
    flutter_boundary_options o;
    o.parameter_even = true;
    o.moving_equilibrium = !fixed_equilibrium();
    hopf_curve_options& c = o.curve;
    c.mu_scale = 0.5;
    c.nu_scale = 0.01;
    c.omega_scale = 0.05;
    c.max_step = 1.0;
    c.step = 0.5;
    c.min_step = 1e-3;
    c.mu_min = 0.2;
    c.mu_max = 20.0;
    c.fast_iterations = 4;
    c.newton.max_iterations = 8;
    c.newton.max_contraction = 1.0;
    c.start.newton.max_iterations = 20;
    o.fixed_equilibrium.steady.abs_tolerance = 1e-10;
    o.fixed_equilibrium.derivative_tolerance = 1e-4;
    return o;
  }

  bool refines(int coarse_stride, int fine_stride) const { return coarse_stride == 2 * fine_stride; }

  /// The next coarser level (for flutter_boundary_options::coarser_level_bridge): twice the
  /// stride, down to the very coarse grid (stride 8: 256 cells; stride 16 would have 64).
  std::optional<int> coarser_level(int stride) const {
    require(stride >= 1, "aerofoil_family: grid stride ", stride, " must be >= 1");
    return 2 * stride <= 8 ? std::optional<int>(2 * stride) : std::nullopt;
  }

  vec<std::complex<double>> prolong(const aerofoil_system& fine, const aerofoil_system& coarse,
                                    const vec<std::complex<double>>& p) const {
    return fine.prolong_from<std::complex<double>>(coarse, 2, p);
  }

  vec<std::complex<double>> structure_part(const vec<std::complex<double>>& p) const {
    require(p.size() >= aerofoil_system::n_structure, "aerofoil_family::structure_part: vector of size ", p.size());
    return p.tail(aerofoil_system::n_structure);
  }

  static double stiffness_factor(double ubar) { return 1.0 / (ubar * ubar); }
  static double parameter_of_factor(double q) { return 1.0 / std::sqrt(q); }

  const flow::multiblock_grid<2>& fine_grid() const { return fine_; }
  const structure::pitch_plunge_parameters& structure() const { return structure_; }
  double alpha() const { return alpha_; }
  flow::steady_options& steady_options() { return steady_; }
  const flow::steady_options& steady_options() const { return steady_; }

 private:
  flow::multiblock_grid<2> fine_;
  structure::pitch_plunge_parameters structure_;
  flow::euler_options flow_;
  double alpha_;
  flow::steady_options steady_;
};

}  // namespace aerohopf::models
