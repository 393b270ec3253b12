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

}  // namespace aerohopf
