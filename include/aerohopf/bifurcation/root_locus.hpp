#pragma once
// Root locus (damping map): follow one eigenvalue of A(w0(mu), mu) along mu by shift-invert
// inverse power, each step using the previous eigenvalue as the shift and the previous
// eigenvector as the start (spec 01, step 2). The equilibrium is supplied per mu, so the
// asymmetric case (static aeroelastic deflection) is handled by passing a static solver. The loop
// is written once (internal::root_locus_loop); the distributed aerofoil runs it on MPI ranks
// (distributed/mpi_aerofoil.hpp).
#include <cmath>
#include <complex>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "../nonlinear/system.hpp"
#include "inverse_power.hpp"

namespace aerohopf {

struct root_locus_point {
  double mu = 0;
  std::complex<double> lambda;
  int iterations = 0;
  double residual = 0;
};

namespace internal {

/// The root-locus loop, written once: checks, then for each mu the equilibrium, then
/// eigen_at(mu, w, shift, start) -> eigen_pair (start nullptr at the first point), the previous
/// eigenvalue the next shift and the previous eigenvector the next start. `check(w, mu)`
/// validates each equilibrium. Errors: as root_locus below.
template <class Equilibrium, class Check, class EigenAt>
std::vector<root_locus_point> root_locus_loop(const Equilibrium& equilibrium, const Check& check,
                                              const EigenAt& eigen_at, const std::vector<double>& mus,
                                              std::complex<double> shift0, const inverse_power_options& ipo,
                                              const char* who) {
  // Checked before the first equilibrium solve: the shift and the options inverse power uses at
  // every point, and every mu (a NaN mu in the middle would otherwise fail only after the
  // preceding points have been computed).
  require(std::isfinite(shift0.real()) && std::isfinite(shift0.imag()), who, ": shift0 ", shift0, " is not finite");
  require(ipo.max_iterations >= 1, who, ": inverse power max_iterations must be >= 1 (got ", ipo.max_iterations, ")");
  require(std::isfinite(ipo.tolerance) && ipo.tolerance > 0, who,
          ": inverse power tolerance must be finite and > 0 (got ", ipo.tolerance, ")");
  require(static_cast<bool>(equilibrium), who, ": equilibrium function is empty");
  for (std::size_t k = 0; k < mus.size(); ++k)
    require(std::isfinite(mus[k]), who, ": mus[", k, "] = ", mus[k], " is not finite");
  std::vector<root_locus_point> out;
  std::complex<double> shift = shift0;
  vec<std::complex<double>> start;
  for (double mu : mus) {
    const vec<double> w = equilibrium(mu);
    check(w, mu);
    eigen_pair ep;
    try {
      ep = eigen_at(mu, w, shift, start.size() ? &start : nullptr);
    } catch (const convergence_error& e) {
      throw convergence_error(internal::concat(who, ": at mu = ", mu, " (point ", out.size(), " of ", mus.size(),
                                               "): ", e.what()));
    }
    out.push_back({mu, ep.lambda, ep.iterations, ep.residual});
    shift = ep.lambda;
    start = std::move(ep.vector);
  }
  return out;
}

}  // namespace internal

/// equilibrium(mu) returns w0(mu); shift0 starts the first inverse power (e.g. i omega_structural).
/// input_error for a non-finite shift0 or mu, bad options or an equilibrium of the wrong size or
/// not finite; convergence_error (with the mu) if inverse power fails at one of the mus.
template <dynamical_system S>
std::vector<root_locus_point> root_locus(const S& sys, const std::function<vec<double>(double)>& equilibrium,
                                         const std::vector<double>& mus, std::complex<double> shift0,
                                         const inverse_power_options& ipo = {}) {
  return internal::root_locus_loop(
      equilibrium, [&sys](const vec<double>& w, double mu) { check_state(sys, w, mu, "root_locus"); },
      [&](double mu, const vec<double>& w, std::complex<double> shift, const vec<std::complex<double>>* start) {
        return inverse_power(sys.jacobian(w, mu), shift, ipo, start);
      },
      mus, shift0, ipo, "root_locus");
}

}  // namespace aerohopf
