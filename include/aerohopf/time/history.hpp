#pragma once
// A stored time history (t_k, y_k) shared by the explicit and implicit integrators, and the
// step count rule they share: a requested step dt is rounded down so that an integer number
// of equal steps ends exactly on t_end (histories of different runs then align in time).
#include <cmath>
#include <vector>

#include "../error.hpp"

namespace aerohopf {

template <class State>
struct time_history {
  std::vector<double> t;
  std::vector<State> y;
};

namespace internal {
/// Number of equal steps of size <= dt covering [t0, t_end]; throws on bad input.
inline long step_count(double t0, double t_end, double dt, const char* who) {
  require(std::isfinite(t0) && std::isfinite(t_end), who, ": start/end times must be finite (", t0, ", ", t_end, ")");
  require(t_end >= t0, who, ": t_end ", t_end, " is before t0 ", t0);
  require(std::isfinite(dt) && dt > 0, who, ": time step dt must be positive and finite (got ", dt, ")");
  return static_cast<long>(std::ceil((t_end - t0) / dt - 1e-9));
}
}  // namespace internal

/// Exponential growth rate of an oscillating signal: least-squares slope of log |y| against t
/// over the local maxima of |y| (peaks of both signs) at t >= t_skip. For y ~ e^{sigma t}
/// cos(omega t) it returns sigma (the real part of the mode's eigenvalue), independent of the
/// phase. peaks (optional) receives the number of maxima used; fewer than two gives NaN.
inline double peak_growth_rate(const std::vector<double>& t, const std::vector<double>& y, double t_skip,
                               int* peaks = nullptr) {
  require(t.size() == y.size(), "peak_growth_rate: ", t.size(), " times for ", y.size(), " values");
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t k = 1; k + 1 < y.size(); ++k) {
    if (t[k] < t_skip) continue;
    const double a = std::abs(y[k]);
    if (a > std::abs(y[k - 1]) && a >= std::abs(y[k + 1])) {
      const double l = std::log(a);
      sx += t[k];
      sy += l;
      sxx += t[k] * t[k];
      sxy += t[k] * l;
      ++n;
    }
  }
  if (peaks) *peaks = n;
  return n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : NAN;
}

}  // namespace aerohopf
