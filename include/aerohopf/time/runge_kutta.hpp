#pragma once
// Classical fourth-order Runge-Kutta with a fixed step, for verification runs: time marching
// of the full system (or of a reduced model) to compare LCO amplitudes and frequencies with
// the centre-manifold prediction.
//
// The right-hand side is any callable f(t, y) -> State, where State is anything with vector
// arithmetic: vec<double>, vec<std::complex<double>>, std::complex<double>, double. A system at
// fixed mu becomes such a callable with system_rhs(s, mu). Fixed steps (no error control) on
// purpose: the comparison runs need a known, uniform sampling and a known order (error ratio
// 16 on halving dt).
#include <Eigen/Core>

#include <cmath>
#include <complex>
#include <type_traits>
#include <utility>

#include "../error.hpp"
#include "../nonlinear/system.hpp"
#include "../scalar/complex.hpp"
#include "history.hpp"

namespace aerohopf {

namespace internal {
template <class State>
bool all_finite(const State& y) {
  if constexpr (std::is_arithmetic_v<State>) return std::isfinite(y);
  else if constexpr (is_complex_v<State>) return std::isfinite(y.real()) && std::isfinite(y.imag());
  else return y.allFinite();
}
}  // namespace internal

/// One RK4 step from (t, y) with step h.
template <class Rhs, class State>
State rk4_step(Rhs&& f, double t, const State& y, double h) {
  const State k1 = f(t, y);
  const State k2 = f(t + 0.5 * h, State(y + (0.5 * h) * k1));
  const State k3 = f(t + 0.5 * h, State(y + (0.5 * h) * k2));
  const State k4 = f(t + h, State(y + h * k3));
  return State(y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
}

/// Integrates y' = f(t, y) from (t0, y0) to t_end with a fixed step close to dt; calls
/// observer(step, t, y) at the start and after every step; returns y(t_end). Throws
/// convergence_error naming the step if the solution becomes non-finite.
template <class Rhs, class State, class Observer>
State integrate_rk4(Rhs&& f, State y0, double t0, double t_end, double dt, Observer&& observer) {
  const char* who = "integrate_rk4";
  const long steps = internal::step_count(t0, t_end, dt, who);
  require(internal::all_finite(y0), who, ": initial state is not finite");
  const double h = steps > 0 ? (t_end - t0) / double(steps) : 0.0;
  State y = std::move(y0);
  observer(0L, t0, static_cast<const State&>(y));
  for (long n = 1; n <= steps; ++n) {
    const double t = t0 + double(n - 1) * h;
    y = rk4_step(f, t, y, h);
    if (!internal::all_finite(y))
      throw convergence_error(internal::concat(who, ": solution not finite at step ", n, " (t = ", t + h, ")"));
    observer(n, t0 + double(n) * h, static_cast<const State&>(y));
  }
  return y;
}

template <class Rhs, class State>
State integrate_rk4(Rhs&& f, State y0, double t0, double t_end, double dt) {
  return integrate_rk4(std::forward<Rhs>(f), std::move(y0), t0, t_end, dt, [](long, double, const State&) {});
}

/// RK4 run storing every store_every-th step (and always the first and the last).
template <class Rhs, class State>
time_history<State> rk4_history(Rhs&& f, State y0, double t0, double t_end, double dt, long store_every = 1) {
  require(store_every >= 1, "rk4_history: store_every must be >= 1 (got ", store_every, ")");
  const long steps = internal::step_count(t0, t_end, dt, "rk4_history");
  time_history<State> h;
  integrate_rk4(std::forward<Rhs>(f), std::move(y0), t0, t_end, dt, [&](long n, double t, const State& y) {
    if (n % store_every == 0 || n == steps) {
      h.t.push_back(t);
      h.y.push_back(y);
    }
  });
  return h;
}

/// The callable (t, w) -> f(w, mu) of a system at fixed mu (autonomous; holds a reference to s).
template <dynamical_system S>
auto system_rhs(const S& s, double mu) {
  return [&s, mu](double, const vec<double>& w) -> vec<double> { return s.residual(w, mu); };
}

}  // namespace aerohopf
