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
//
// Failures: a stage or the new state that is not finite ends the march with
// time_march_error<State> (a convergence_error) naming integrate_rk4, the step, its time, the
// stage and the first non-finite entry, and carrying the last good state (continue from it
// with integrate_rk4 from (error.t, error.state)); an exception from the right-hand side is
// rethrown with its own type and the step and time in front of its message (the observer has
// seen the last good state). Input checks (input_error): times, dt, a finite initial state (the
// first bad entry named).
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

/// The first non-finite entry of y (0 for a scalar state), -1 if none.
template <class State>
long first_non_finite_entry(const State& y) {
  if constexpr (std::is_arithmetic_v<State> || is_complex_v<State>) {
    return all_finite(y) ? -1 : 0;
  } else {
    for (Eigen::Index i = 0; i < y.size(); ++i)
      if (!is_finite_value(y[i])) return static_cast<long>(i);
    return -1;
  }
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
/// observer(step, t, y) at the start and after every step; returns y(t_end). Failures: file
/// comment.
template <class Rhs, class State, class Observer>
State integrate_rk4(Rhs&& f, State y0, double t0, double t_end, double dt, Observer&& observer) {
  const char* who = "integrate_rk4";
  const long steps = internal::step_count(t0, t_end, dt, who);
  if constexpr (std::is_arithmetic_v<State> || is_complex_v<State>)
    require(internal::all_finite(y0), who, ": initial state is not finite (", y0, ")");
  else
    require_finite(y0, who, "initial state");
  const double h = steps > 0 ? (t_end - t0) / double(steps) : 0.0;
  State y = std::move(y0);
  observer(0L, t0, static_cast<const State&>(y));
  for (long n = 1; n <= steps; ++n) {
    const double t = t0 + double(n - 1) * h;
    const char* stage = nullptr;
    long entry = -1;
    State yn;
    try {
      // rk4_step, with each stage checked so that the first non-finite one is named
      auto checked = [&](State k, const char* name) {
        if (!stage && (entry = internal::first_non_finite_entry(k)) >= 0) stage = name;
        return k;
      };
      const State k1 = checked(f(t, y), "k1 = f(t_n, y_n)");
      const State k2 = checked(f(t + 0.5 * h, State(y + (0.5 * h) * k1)), "k2");
      const State k3 = checked(f(t + 0.5 * h, State(y + (0.5 * h) * k2)), "k3");
      const State k4 = checked(f(t + h, State(y + h * k3)), "k4");
      yn = State(y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4));
    } catch (...) {
      internal::rethrow_with_context(internal::concat(who, ": step ", n, " (from t = ", t, ") failed: "));
    }
    if (!stage && (entry = internal::first_non_finite_entry(yn)) >= 0) stage = "the new state";
    if (stage)
      throw time_march_error<State>(internal::concat(who, ": solution not finite at step ", n, " (t = ", t + h, "): ",
                                                     "stage ", stage, " has a non-finite entry ", entry,
                                                     "; the last good state is that of step ", n - 1, " at t = ", t),
                                    n - 1, t, h, std::move(y));
    y = std::move(yn);
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
