#pragma once
// A stored time history (t_k, y_k) shared by the explicit and implicit integrators, and the
// step count rule they share: a requested step dt is rounded down so that an integer number
// of equal steps ends exactly on t_end (histories of different runs then align in time). The
// measures of a sampled oscillation: growth rate, amplitude envelope, the limit cycle that runs
// approach from both sides, and the amplitude and period of a settled run.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"

namespace aerohopf {

template <class State>
struct time_history {
  std::vector<double> t;
  std::vector<State> y;
};

/// A time march stopped because its solution (or an implicit step's inner iteration) became
/// non-finite or did not converge at step `step + 1`. It carries the last good state, so the
/// run can continue from it: `state` at time `t` after `step` steps of size `dt` (step 0: the
/// initial state), and for BDF2 `previous`, the level at t - dt (empty for RK4 and at step 0),
/// which resume_bdf2 takes to go on with BDF2 steps as an uninterrupted run would.
template <class State>
struct time_march_error : convergence_error {
  time_march_error(const std::string& message, long step_, double t_, double dt_, State state_, State previous_ = {})
      : convergence_error(message), step(step_), t(t_), dt(dt_), state(std::move(state_)),
        previous(std::move(previous_)) {}
  long step;
  double t;
  double dt;
  State state;
  State previous;
};

namespace internal {
/// Number of equal steps of size <= dt covering [t0, t_end]; throws on bad input.
inline long step_count(double t0, double t_end, double dt, const char* who) {
  require(std::isfinite(t0) && std::isfinite(t_end), who, ": start/end times must be finite (", t0, ", ", t_end, ")");
  require(t_end >= t0, who, ": t_end ", t_end, " is before t0 ", t0);
  require(std::isfinite(dt) && dt > 0, who, ": time step dt must be positive and finite (got ", dt, ")");
  return static_cast<long>(std::ceil((t_end - t0) / dt - 1e-9));
}
/// The extremum of the parabola through (t0, y0), (t1, y1), (t2, y2), t0 < t1 < t2 (steps need
/// not be equal), its time clamped to [t0, t2]: (t1, y1) where the three are collinear.
inline std::pair<double, double> parabolic_extremum(double t0, double t1, double t2, double y0, double y1, double y2) {
  const double h1 = t1 - t0, h2 = t2 - t1;
  const double d1 = (y1 - y0) / h1, d2 = (y2 - y1) / h2;
  const double c2 = (d2 - d1) / (h1 + h2);  // y ~ y1 + b (s - t1) + c2 (s - t1)^2
  const double b = d1 + c2 * h1;
  if (c2 == 0.0) return {t1, y1};
  const double ds = std::clamp(-b / (2.0 * c2), -h1, h2);
  return {t1 + ds, y1 + b * ds + c2 * ds * ds};
}
}  // namespace internal

/// Exponential growth rate of an oscillating signal: least-squares slope of log |y| against t
/// over the local maxima of |y| (peaks of both signs) at t >= t_skip, each refined by the
/// parabola through its three samples of |y| (so the estimate is not limited by where the
/// samples fall: at 20 samples per period a raw maximum errs by up to 1.2 % in amplitude). For
/// y ~ e^{sigma t} cos(omega t) it returns sigma (the real part of the mode's eigenvalue),
/// independent of the phase. peaks (optional) receives the number of maxima used; fewer than
/// two gives NaN.
inline double peak_growth_rate(const std::vector<double>& t, const std::vector<double>& y, double t_skip,
                               int* peaks = nullptr) {
  require(t.size() == y.size(), "peak_growth_rate: ", t.size(), " times for ", y.size(), " values");
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t k = 1; k + 1 < y.size(); ++k) {
    if (t[k] < t_skip) continue;
    const double a0 = std::abs(y[k - 1]), a1 = std::abs(y[k]), a2 = std::abs(y[k + 1]);
    if (a1 > a0 && a1 >= a2) {
      const auto [tp, ap] = internal::parabolic_extremum(t[k - 1], t[k], t[k + 1], a0, a1, a2);
      const double l = std::log(ap);
      sx += tp;
      sy += l;
      sxx += tp * tp;
      sxy += tp * l;
      ++n;
    }
  }
  if (peaks) *peaks = n;
  return n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : NAN;
}

/// One sample of the amplitude envelope of an oscillation (amplitude_envelope).
struct amplitude_sample {
  double t = 0;            ///< mid time between two successive extrema
  double amplitude = 0;    ///< half the swing between them
  double growth_rate = 0;  ///< d ln(amplitude) / dt there (NaN with fewer than two samples)
};

/// Amplitude envelope of an oscillation whose amplitude and mean vary slowly (a transient
/// towards or away from a limit cycle): the extrema of y at t >= t_skip, each refined by the
/// parabola through its three samples; between successive extrema (a maximum and a minimum)
/// the amplitude is half the swing, A = |y_k - y_{k-1}| / 2, at t = (t_k + t_{k-1}) / 2 (for
/// y = A(t) cos(omega t) + mean this is A(t) to O((T A'/A)^2)); the growth rate is
/// d ln A / dt by central differences of the samples (one-sided at the ends). Plotting the
/// growth rate against the amplitude gives the amplitude-dependent damping; its zero is the
/// limit-cycle amplitude (stable where the slope is negative).
inline std::vector<amplitude_sample> amplitude_envelope(const std::vector<double>& t, const std::vector<double>& y,
                                                        double t_skip) {
  require(t.size() == y.size(), "amplitude_envelope: ", t.size(), " times for ", y.size(), " values");
  std::vector<double> te, ye;  // refined extrema
  for (std::size_t k = 1; k + 1 < y.size(); ++k) {
    if (t[k] < t_skip) continue;
    const bool is_max = y[k] > y[k - 1] && y[k] >= y[k + 1], is_min = y[k] < y[k - 1] && y[k] <= y[k + 1];
    if (!is_max && !is_min) continue;
    const auto [tk, yk] = internal::parabolic_extremum(t[k - 1], t[k], t[k + 1], y[k - 1], y[k], y[k + 1]);
    te.push_back(tk);
    ye.push_back(yk);
  }
  std::vector<amplitude_sample> r;
  for (std::size_t k = 1; k < te.size(); ++k)
    r.push_back({0.5 * (te[k] + te[k - 1]), 0.5 * std::abs(ye[k] - ye[k - 1]), NAN});
  for (std::size_t k = 0; k < r.size() && r.size() >= 2; ++k) {
    const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == r.size() ? k : k + 1;
    r[k].growth_rate = std::log(r[b].amplitude / r[a].amplitude) / (r[b].t - r[a].t);
  }
  return r;
}

/// A limit cycle found from the envelopes of time-marching runs (limit_cycle_from_envelopes).
struct envelope_cycle {
  double amplitude = NAN;  ///< where the fitted growth rate vanishes
  double slope = NAN;      ///< d sigma / dA of the fit
  double exponent = NAN;   ///< amplitude * slope: the cycle's radial Floquet exponent (< 0: stable)
  int samples = 0;         ///< finite growth-rate samples used
  bool bracketed = false;  ///< samples on both sides of the amplitude (an interpolation)
};

/// The limit cycle that runs approach from inside and outside (or leave, if it is unstable): the
/// line sigma(A) = s0 + s1 A fitted by least squares to the growth rates of every envelope
/// sample of every run (amplitude_envelope); its zero A* is the cycle's amplitude, and A* s1 is
/// its radial Floquet exponent (the derivative of dA/dt = sigma(A) A at A*). Runs started at 0.9
/// and 1.1 times a cycle bracket it, so the line interpolates over a range where sigma(A) is
/// nearly linear, long before either run has settled. Throws input_error with fewer than three
/// finite samples or a single amplitude, convergence_error when the fitted slope is zero.
inline envelope_cycle limit_cycle_from_envelopes(const std::vector<std::vector<amplitude_sample>>& runs) {
  const char* who = "limit_cycle_from_envelopes";
  double sx = 0, sy = 0, sxx = 0, sxy = 0, amin = INFINITY, amax = -INFINITY;
  int ns = 0;
  for (const auto& run : runs)
    for (const amplitude_sample& e : run) {
      if (!std::isfinite(e.growth_rate) || !std::isfinite(e.amplitude)) continue;
      sx += e.amplitude, sy += e.growth_rate, sxx += e.amplitude * e.amplitude, sxy += e.amplitude * e.growth_rate;
      amin = std::min(amin, e.amplitude);
      amax = std::max(amax, e.amplitude);
      ++ns;
    }
  require(ns >= 3, who, ": ", ns, " finite envelope samples (at least 3 needed: run longer)");
  require(amax > amin, who, ": every sample has the amplitude ", amin, ": no growth-rate line");
  envelope_cycle c;
  c.samples = ns;
  c.slope = (ns * sxy - sx * sy) / (ns * sxx - sx * sx);
  const double s0 = (sy - c.slope * sx) / ns;
  if (!(std::abs(c.slope) > 0) || !std::isfinite(c.slope))
    throw convergence_error(internal::concat(who, ": the growth rate does not change with the amplitude (slope ", c.slope,
                                             " over ", ns, " samples, amplitudes ", amin, " .. ", amax, ")"));
  c.amplitude = -s0 / c.slope;
  c.exponent = c.amplitude * c.slope;
  c.bracketed = amin < c.amplitude && c.amplitude < amax;
  return c;
}

/// What a run that has settled on a limit cycle shows over its last cycles (last_cycles).
struct cycle_measure {
  double amplitude = NAN;  ///< mean half swing between successive extrema
  double period = NAN;     ///< mean time between extrema of the same kind
  int cycles = 0;          ///< cycles used (0: too few extrema)
};

/// Amplitude and period of an oscillation over its last `cycles` cycles (the limit cycle a
/// time-marching run has settled on): the 2 cycles half swings between successive refined
/// extrema of amplitude_envelope, averaged, and the time they span divided by `cycles`. Fewer
/// extrema than that use what there is; fewer than three give NaN (cycles = 0).
inline cycle_measure last_cycles(const std::vector<double>& t, const std::vector<double>& y, int cycles) {
  require(cycles >= 1, "last_cycles: cycles must be >= 1 (got ", cycles, ")");
  const std::vector<amplitude_sample> e = amplitude_envelope(t, y, t.empty() ? 0.0 : t.front());
  cycle_measure m;
  const int c = std::min<int>(cycles, int(e.size()) / 2);
  if (c < 1) return m;
  const std::size_t first = e.size() - std::size_t(2 * c);
  double a = 0;
  for (std::size_t k = first; k < e.size(); ++k) a += e[k].amplitude;
  m.amplitude = a / (2 * c);
  // the samples sit half a period apart: 2c samples span (2c - 1) half periods
  m.period = 2 * (e.back().t - e[first].t) / (2 * c - 1);
  m.cycles = c;
  return m;
}

}  // namespace aerohopf
