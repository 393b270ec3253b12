#pragma once
// Root locus (damping map): follow one eigenvalue of A(w0(mu), mu) along mu by shift-invert
// inverse power, each step using the previous eigenvalue as the shift and the previous
// eigenvector as the start (spec 01, step 2). The equilibrium is supplied per mu, so the
// asymmetric case (static aeroelastic deflection) is handled by passing a static solver.
#include <complex>
#include <functional>
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

/// equilibrium(mu) returns w0(mu); shift0 starts the first inverse power (e.g. i omega_structural).
template <dynamical_system S>
std::vector<root_locus_point> root_locus(const S& sys, const std::function<vec<double>(double)>& equilibrium,
                                         const std::vector<double>& mus, std::complex<double> shift0,
                                         const inverse_power_options& ipo = {}) {
  std::vector<root_locus_point> out;
  std::complex<double> shift = shift0;
  vec<std::complex<double>> start;
  for (double mu : mus) {
    const vec<double> w = equilibrium(mu);
    check_state(sys, w, mu, "root_locus");
    const eigen_pair ep = inverse_power(sys.jacobian(w, mu), shift, ipo, start.size() ? &start : nullptr);
    out.push_back({mu, ep.lambda, ep.iterations, ep.residual});
    shift = ep.lambda;
    start = ep.vector;
  }
  return out;
}

}  // namespace aerohopf
