#pragma once
// Shared set-up of the aerofoil flutter example programs (main.cpp, branch.cpp): the grid
// levels (every stride-th point of the fine NACA 0012 C-grid), the two structural cases of
// spec 05, the coupled system at a Mach number, and the timed steady solve from the free
// stream (the unit of cost the examples report), and the options of the fixed-equilibrium Hopf-curve
// tracer for aerofoil_branch.
#include <aerohopf/bifurcation/hopf_curve_fixed_equilibrium.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace aerofoil_example {

using aerohopf::vec;
using aerohopf::models::aerofoil_system;
using clk = std::chrono::steady_clock;

inline double seconds_since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

struct grid_level {
  std::string name;
  int stride;  // every stride-th point of the fine grid
};

inline grid_level level_named(const std::string& name) {
  if (name == "very_coarse") return {name, 8};
  if (name == "coarse") return {name, 4};
  if (name == "medium") return {name, 2};
  if (name == "fine") return {name, 1};
  throw aerohopf::input_error("unknown grid level '" + name + "' (very_coarse, coarse, medium, fine)");
}

struct structural_case {
  std::string name;
  double mu_s;
  double ubar_guess, omega_guess;  // start of the first inverse power (very coarse M = 0.5 values)
};

inline const structural_case light_case{"light", 10.0, 1.66, 0.75};
inline const structural_case heavy_case{"heavy", 100.0, 4.6, 0.22};

inline structural_case case_named(const std::string& name) {
  if (name == "light") return light_case;
  if (name == "heavy") return heavy_case;
  throw aerohopf::input_error("unknown structural case '" + name + "' (light, heavy)");
}

inline const aerohopf::flow::multiblock_grid<2>& fine_grid() {
  static const aerohopf::flow::multiblock_grid<2> g = aerohopf::flow::naca_cgrid();
  return g;
}

/// The coupled Euler / pitch-plunge system of spec 05 on grid level g at Mach number `mach`
/// (contact_smoothing: euler_options::contact_smoothing, 0 = the exact Osher switches).
inline aerofoil_system make_system(const grid_level& g, double mach, double mu_s, double contact_smoothing = 0.0) {
  aerohopf::structure::pitch_plunge_parameters p;
  p.mu_s = mu_s;
  aerohopf::flow::euler_options fo;
  fo.contact_smoothing = contact_smoothing;
  return aerofoil_system(aerohopf::flow::euler_model<2>(aerohopf::flow::coarsen(fine_grid(), g.stride),
                                                         {.mach = mach, .alpha_rad = 0.0}, fo),
                         aerohopf::structure::pitch_plunge(p));
}

/// The family of the boundary driver (flutter_boundary.hpp): levels are grid strides.
inline aerohopf::models::aerofoil_family family_of(const structural_case& c, double alpha_rad = 0.0) {
  aerohopf::structure::pitch_plunge_parameters p;
  p.mu_s = c.mu_s;
  return aerohopf::models::aerofoil_family(fine_grid(), p, {}, alpha_rad);
}

inline std::string fixed(double x, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << x;
  return os.str();
}

/// Steady equilibrium from the free stream, timed (the unit of cost of the whole method).
struct steady_result {
  vec<double> w;
  double seconds = 0;
};
inline steady_result steady(const aerofoil_system& s) {
  const auto t0 = clk::now();
  aerohopf::flow::steady_options so;
  steady_result r;
  r.w = s.steady_equilibrium(so);
  r.seconds = seconds_since(t0);
  return r;
}

/// The value of --tracer-corrector / --corrector: true for "joint"
/// (fixed_equilibrium_hopf_curve_options::joint_equilibrium), false for "nested".
inline bool joint_corrector(const std::string& value, const std::string& option) {
  aerohopf::require(value == "joint" || value == "nested", option, " must be joint or nested (got ", value, ")");
  return value == "joint";
}

/// Options of trace_fixed_equilibrium_hopf_curve for aerofoil_branch: the family's
/// (aerofoil_family::boundary_options) with the user's metric scales and largest step, M in
/// [m0, m_max] with every M = 0.01 k landed exactly, BILU(fill), the nested steady solves'
/// third start the pseudo-transient solve from the free stream.
struct tracer_options {
  aerohopf::hopf_curve_options curve;
  aerohopf::fixed_equilibrium_hopf_curve_options fixed_equilibrium;
};
inline tracer_options aerofoil_tracer_options(const grid_level& g, const structural_case& c, double m0, double m_max,
                                              int fill, double mu_scale, double nu_scale, double omega_scale,
                                              double max_step) {
  const aerohopf::flutter_boundary_options b = family_of(c).boundary_options();
  tracer_options t{b.curve, b.fixed_equilibrium};
  auto& ho = t.curve;
  ho.mu_scale = mu_scale;
  ho.nu_scale = nu_scale;
  ho.omega_scale = omega_scale;
  ho.max_step = max_step;
  ho.step = std::min(ho.step, max_step);
  ho.nu_min = m0 - 1e-9;
  ho.nu_max = m_max;
  for (int k = static_cast<int>(std::ceil(m0 * 100 + 1e-6)); k <= static_cast<int>(std::floor(m_max * 100 + 1e-6)); ++k)
    ho.nu_targets.push_back(k / 100.0);
  ho.throw_on_failure = false;
  ho.label = c.name + " " + g.name;
  ho.verbose = true;
  t.fixed_equilibrium.fill_level = fill;
  t.fixed_equilibrium.equilibrium_start = [g, mu_s = c.mu_s](double mach) { return make_system(g, mach, mu_s).steady_equilibrium(); };
  return t;
}

}  // namespace aerofoil_example
