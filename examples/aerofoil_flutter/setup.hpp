#pragma once
// Shared set-up of the aerofoil flutter example programs (main.cpp, branch.cpp): the grid
// levels (every stride-th point of the fine NACA 0012 C-grid), the two structural cases of
// spec 05, the coupled system at a Mach number, and the timed steady solve from the free
// stream (the unit of cost the examples report).
#include <aerohopf/error.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include <chrono>
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

}  // namespace aerofoil_example
