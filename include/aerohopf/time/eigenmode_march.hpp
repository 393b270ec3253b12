#pragma once
// Time-marching check of an eigenvalue: the equilibrium perturbed along a (critical) eigenvector
// and marched by BDF2; the growth rate of one coordinate's oscillation is compared with the
// real part of the eigenvalue. This is how a flutter engineer verifies a Hopf point without
// trusting the eigen-solver: below the flutter speed the response decays at Re(lambda) < 0,
// above it grows at Re(lambda) > 0.
//
// Set-up. With ep = (lambda, p) an eigenpair of A(w_eq, mu), the start is
//     w0 = w_eq + Re(c p),   c = amplitude / p[coordinate]
// so that the watched coordinate starts at `amplitude` (real) and the perturbation lies in the
// real invariant plane of the pair. The run covers `cycles` periods 2 pi / |Im lambda|, with
// dt = period / steps_per_period (or the given dt). The growth rate is peak_growth_rate of the
// watched coordinate's deviation from w_eq over the peaks after skip_cycles periods (the
// other modes' transient has decayed by then).
//
// Accuracy. BDF2 turns the mode e^{lambda t} into z^{t/dt}, z the principal root of
// (3 - 2 dt lambda) z^2 - 4 z + 1 = 0, so the marched rate is Re(log z) / dt (bdf2_rate, in the
// result) instead of Re(lambda): for lambda = i omega about -(omega dt)^3 omega / 4, plus a term
// in Re(lambda) (omega dt)^2 off the axis; at the default 72 steps per period (dt = 0.125 at the
// NACA 0012's omega = 0.7) up to 4e-4 omega for |Re(lambda)| <= 0.04 omega. The peak fit adds
// its own error (up to about 1e-4), and the amplitude must be small enough that the nonlinear terms
// do not change the rate (a cubic normal form changes it by l1 amplitude^2).
//
// Defaults of the inner iterations: the CFD practice of cfd_bdf2_options (three orders of the
// unsteady residual per real step, the modified-order matrix frozen over the step).
// Failures: bad input (sizes, a zero or non-finite watched component, a real eigenvalue, non-
// positive amplitude, cycles or steps) is an input_error naming march_eigenmode; a failed step
// is the time_march_error of integrate_bdf2.
#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "../bifurcation/inverse_power.hpp"
#include "../error.hpp"
#include "../nonlinear/system.hpp"
#include "bdf2.hpp"
#include "history.hpp"

namespace aerohopf {

struct eigenmode_march_options {
  Eigen::Index coordinate = -1;  ///< the watched coordinate (e.g. the pitch angle); required
  double amplitude = 0.01;       ///< its start value (the perturbation's scale)
  double cycles = 4;             ///< length of the run in periods 2 pi / |Im lambda|
  double skip_cycles = 1;        ///< the growth-rate fit starts after this many periods
  int steps_per_period = 72;     ///< dt = period / steps_per_period (unless dt > 0)
  double dt = 0;                 ///< > 0: this time step instead
  bdf2_options bdf2 = cfd_bdf2_options(0);  ///< the inner iterations (dt is replaced)
};

struct eigenmode_march_result {
  double growth_rate = NAN;  ///< from the peaks of the watched coordinate's deviation
  double re_lambda = NAN, im_lambda = NAN;  ///< of the eigenpair marched (im >= 0)
  double bdf2_rate = NAN;    ///< the rate BDF2 gives the linear mode at this dt (file comment)
  int peaks = 0;             ///< used by the fit
  double dt = 0;
  long steps = 0, inner_iterations = 0;
  double seconds = 0;
  std::vector<double> t, y;  ///< the watched coordinate's deviation from w_eq at every step
};

/// BDF2 from w_eq + Re(c p) (file comment) at mu; observer(info, w) after every step as in
/// integrate_bdf2; solver: the inner matrices' solver (compute/solve).
template <dynamical_system S, class Solver, class Observer>
eigenmode_march_result march_eigenmode(const S& s, double mu, const vec<double>& w_eq, const eigen_pair& ep,
                                       const eigenmode_march_options& o, Solver& solver, Observer&& observer) {
  const char* who = "march_eigenmode";
  const Eigen::Index n = s.size();
  require_size(w_eq.size(), n, who, "equilibrium");
  require_size(ep.vector.size(), n, who, "eigenvector");
  require(std::isfinite(ep.lambda.real()) && std::isfinite(ep.lambda.imag()) && ep.lambda.imag() != 0, who,
          ": the eigenvalue ", ep.lambda.real(), " + ", ep.lambda.imag(), " i is not a finite complex pair");
  require(o.coordinate >= 0 && o.coordinate < n, who, ": coordinate ", o.coordinate, " outside 0 .. ", n - 1);
  const std::complex<double> pk = ep.vector[o.coordinate];
  require(std::isfinite(std::abs(pk)) && std::abs(pk) > 0, who, ": the eigenvector's component ", o.coordinate,
          " is zero or not finite (watch another coordinate)");
  require(std::isfinite(o.amplitude) && o.amplitude > 0, who, ": amplitude must be positive (got ", o.amplitude, ")");
  require(std::isfinite(o.cycles) && o.cycles > 0 && std::isfinite(o.skip_cycles) && o.skip_cycles >= 0 &&
              o.skip_cycles < o.cycles,
          who, ": need 0 <= skip_cycles < cycles (got ", o.skip_cycles, ", ", o.cycles, ")");
  require(o.steps_per_period >= 8, who, ": steps_per_period must be >= 8 (got ", o.steps_per_period, ")");
  require(std::isfinite(o.dt) && o.dt >= 0, who, ": dt must be >= 0 (got ", o.dt, ")");

  eigenmode_march_result r;
  r.re_lambda = ep.lambda.real();
  r.im_lambda = std::abs(ep.lambda.imag());
  const double period = 2 * std::numbers::pi / r.im_lambda;
  bdf2_options bo = o.bdf2;
  bo.dt = o.dt > 0 ? o.dt : period / o.steps_per_period;
  r.dt = bo.dt;
  {
    const std::complex<double> a = 3.0 - 2.0 * bo.dt * std::complex<double>(r.re_lambda, r.im_lambda);
    const std::complex<double> d = std::sqrt(std::complex<double>(16.0) - 4.0 * a);
    const std::complex<double> z1 = (4.0 + d) / (2.0 * a), z2 = (4.0 - d) / (2.0 * a);
    r.bdf2_rate = std::log(std::abs(std::abs(z1) >= std::abs(z2) ? z1 : z2)) / bo.dt;
  }
  const vec<std::complex<double>> v = ep.vector * (o.amplitude / pk);
  const vec<double> w0 = w_eq + v.real();
  const double y_eq = w_eq[o.coordinate];
  const auto t0 = std::chrono::steady_clock::now();
  integrate_bdf2(
      s, mu, w0, 0.0, o.cycles * period, bo,
      [&](const bdf2_step_info& i, const vec<double>& w) {
        r.t.push_back(i.t);
        r.y.push_back(w[o.coordinate] - y_eq);
        r.steps = i.step;
        r.inner_iterations += i.inner_iterations;
        observer(i, w);
      },
      solver);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.growth_rate = peak_growth_rate(r.t, r.y, o.skip_cycles * period, &r.peaks);
  return r;
}

/// Same with the direct solver of the system's matrix type and no observer.
template <dynamical_system S>
eigenmode_march_result march_eigenmode(const S& s, double mu, const vec<double>& w_eq, const eigen_pair& ep,
                                       const eigenmode_march_options& o) {
  direct_solver<jacobian_t<S>> solver("march_eigenmode: inner matrix");
  return march_eigenmode(s, mu, w_eq, ep, o, solver, [](const bdf2_step_info&, const vec<double>&) {});
}

}  // namespace aerohopf
