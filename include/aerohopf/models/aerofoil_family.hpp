#pragma once
// The pitch-plunge aerofoil of spec 05 as a flutter_family (bifurcation/flutter_boundary.hpp):
// grid levels are the strides of a fine C-grid (every stride-th point: 8 very coarse, 4 coarse,
// 2 medium, 1 fine), one aerofoil_system per level and Mach number, the equilibrium with the
// section at rest (symmetric section at zero incidence: the same for every Ubar), injection
// between levels of ratio 2, the structural unknowns (h, h', alpha, alpha') for the mode test,
// and Ubar entering the stiffness as 1/Ubar^2 (the crossing check).
#include <cmath>
#include <complex>
#include <string>
#include <utility>

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

  static std::string level_name(int stride) {
    switch (stride) {
      case 8: return "very_coarse";
      case 4: return "coarse";
      case 2: return "medium";
      case 1: return "fine";
      default: return "stride" + std::to_string(stride);
    }
  }

  /// The steady flow from the free stream with the section at rest (aerofoil_system::
  /// steady_equilibrium: throws convergence_error if the flow loads the section).
  vec<double> equilibrium(const aerofoil_system& s, double /*ubar*/) const { return s.steady_equilibrium(steady_); }

  bool refines(int coarse_stride, int fine_stride) const { return coarse_stride == 2 * fine_stride; }

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

 private:
  flow::multiblock_grid<2> fine_;
  structure::pitch_plunge_parameters structure_;
  flow::euler_options flow_;
  double alpha_;
  flow::steady_options steady_;
};

}  // namespace aerohopf::models
