#pragma once
// One curve stepper: the step control, predictor, landings, guards and stop conditions of every
// continuation in the library (equilibrium branches, Hopf curves), written once. What a curve
// is made of (the equations, their Newton iteration, normalisations, what is recorded per
// point) is a CORRECTOR plugged into it.
//
// Unknowns x in R^N. The metric is diagonal, <a, b> = sum_i weight_i a_i b_i (weight_i >= 0):
// the equilibrium continuation weights all of (w, mu), the Hopf tracers only (mu, nu, omega).
// A corrector solves its equations closed by ONE linear constraint c.x = value, from an initial
// point x0 (curve_request). The stepper chooses c:
//  * arclength step: c = W t (W = diag(weight), t the unit direction), value = c.(x_k + ds t);
//  * landing on a listed value v of coordinate j: c = e_j, value = v;
//  * kink step: c = e_j, value = (x_k + ds t)_j (a local parametrisation by one coordinate).
// A corrector returns the corrected point and its iteration count, or nothing with the reason
// (a failed corrector: the step is retried or halved); an exception it throws ends the trace.
//
// Predictors (curve_predictor):
//  * secant: x_k + ds s_k, s_k = (x_k - x_{k-1}) / |x_k - x_{k-1}| (the first step: the start's
//    unit tangent). After a failed corrector, the same step is retried once along the exact
//    tangent at x_k (J t = e_last with the row c = W s_k), oriented along s_k: where the curve
//    bends sharply the chord points off the curve at every step size;
//  * tangent: the exact unit tangent at every accepted point, oriented along the previous one;
//  * natural: coordinate j steps by a fixed amount, x_k itself is the prediction; point k has
//    x_j = x_{0,j} + k step direction exactly (no accumulated rounding). Neither halving nor
//    growth: a failed corrector ends the trace.
//
// Step control: a failed or rejected corrector halves ds (after the retries above); a step
// whose corrector needed <= fast_iterations iterations grows ds by `growth`; ds stays in
// [min_step, max_step]. Below min_step the trace stops (curve_stop::step_underflow) naming the
// last point, the last attempted step and the last failure.
//
// Guards on a converged step (each a rejection: the step is retried or halved):
//  * sheet jump: the corrected point moved more than corrector_distance ds from the prediction,
//    or d = x_new - x_k has <d, t> <= min_cosine |d| (behind the last point, or far off the
//    predicted direction): a jump to another sheet where a curve folds;
//  * retrace: <d, s_k> <= 0 (back along the secant, possible after the exact-tangent retry at a
//    kink), or x_new within a quarter step of the polyline of the points before the last three
//    (the trace turned back and runs over the curve again). The segment from the start is left
//    out when closed curves are detected (closing on the start is a stop, not a retrace).
// Kink step: a piecewise smooth curve (only C1 equations) can turn by more than 90 degrees at a
// kink, where the arclength hyperplane does not meet the next piece near the prediction. After
// a corrector that failed (did not converge) from the secant prediction, and again after the
// exact-tangent retry failed, the same step is tried with c = e_j for the primary coordinate
// and then the secondary one (the secondary first where |s_primary| sqrt(w_primary) < 0.1
// |s_secondary| sqrt(w_secondary): the curve is nearly parallel to primary = const there).
// Accepted if it lands ahead (<d, s_k> > 0, no retrace) within kink_distance ds of x_k.
//
// Landings: every crossing of a listed value (targets) or of a bound by the step x_k -> x_new
// (sign change of x_j - v, or x_new,j = v) is corrected with c = e_j from the linear
// interpolation, in curve order, and emitted as a landed point; a failed target landing is
// recorded in curve_outcome::missed, a bound ends the trace there (the unlanded x_new emitted
// instead when its landing failed). Limits: an accepted point outside [lo, hi] of a coordinate
// ends the trace after it is emitted (in natural mode the next value is tested before it is
// solved, so no point outside is computed).
//
// Stops (curve_stop): max_points emitted (start and landed points count); a bound; a limit;
// the corrector's end_of_curve hook (e.g. omega -> 0 at a Bogdanov-Takens point); the curve
// closing on its start (arclength > 3 len and |x_new - x_0| < len for the last step len); the
// emit hook asking to stop; step underflow; a failed natural-mode corrector.
//
// The problem P (any object): required
//     std::optional<R> correct(const curve_request&, std::string& why)   R has .x, .iterations
//     bool emit(const vec<double>& x, const curve_point_info&)          true: stop requested
// optional
//     vec<double> tangent(const vec<double>& x, const vec<double>& c)    J t = e_last, row c
//     std::optional<curve_end> end_of_curve(const R&, const vec<double>* before_last,
//                                           const vec<double>& last, const vec<double>& x_new)
//     void renormalise(vec<double>& x_new, vec<double>& x_last)          before the secant
//     std::string describe(const vec<double>& x)                         for messages
// Invariants: every emitted point was returned by the corrector (or is the start); the
// direction t is unit in the metric; ds never exceeds max_step; the trace ends with a stop.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <concepts>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../nonlinear/system.hpp"

namespace aerohopf {

/// Diagonal metric <a, b> = sum_i weight_i a_i b_i on the unknowns of a curve.
class curve_metric {
 public:
  curve_metric() = default;
  explicit curve_metric(vec<double> weight) : w_(std::move(weight)) {
    bool any = false;
    for (Eigen::Index i = 0; i < w_.size(); ++i) {
      require(std::isfinite(w_[i]) && w_[i] >= 0, "curve_metric: weight entry ", i, " must be finite and >= 0 (got ",
              w_[i], ")");
      if (w_[i] > 0) support_.push_back(i), any = true;
    }
    require(any, "curve_metric: all weights are zero");
  }
  Eigen::Index size() const { return w_.size(); }
  const vec<double>& weight() const { return w_; }
  /// The coordinates with a positive weight (the metric sees only these).
  const std::vector<Eigen::Index>& support() const { return support_; }
  double dot(const vec<double>& a, const vec<double>& b) const {
    double d = 0;
    for (Eigen::Index i : support_) d += w_[i] * a[i] * b[i];
    return d;
  }
  double norm(const vec<double>& a) const { return std::sqrt(dot(a, a)); }
  double distance(const vec<double>& a, const vec<double>& b) const {
    double d = 0;
    for (Eigen::Index i : support_) d += w_[i] * (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(d);
  }
  /// c = W t: the constraint row whose hyperplane through x + ds t is orthogonal to t.
  vec<double> row(const vec<double>& t) const { return w_.cwiseProduct(t); }
  /// The scaled coordinates sqrt(w_i) x_i of the support (Euclidean distances there are metric ones).
  vec<double> scaled(const vec<double>& x) const {
    vec<double> y(Eigen::Index(support_.size()));
    for (std::size_t k = 0; k < support_.size(); ++k) y[Eigen::Index(k)] = std::sqrt(w_[support_[k]]) * x[support_[k]];
    return y;
  }

 private:
  vec<double> w_;
  std::vector<Eigen::Index> support_;
};

enum class curve_predictor { secant, tangent, natural };

/// Why a corrector is called.
enum class curve_attempt { step, kink, landing };

/// A corrector's task: solve the curve's equations with c.x = value from x0.
struct curve_request {
  vec<double> x0;     ///< initial point (the prediction)
  vec<double> c;      ///< constraint row
  double value = 0;   ///< constraint value
  double step = 0;    ///< the current step ds (a scale for trust radii)
  curve_attempt kind = curve_attempt::step;
  bool first = true;  ///< the first attempt of this step (false for retries, kink steps)
  int point = 0;      ///< number of points emitted so far
};

/// What a corrector returns on success (a corrector may return a type derived from it).
struct curve_corrected {
  vec<double> x;
  int iterations = 0;
};

/// Passed with each emitted point.
struct curve_point_info {
  int iterations = 0;    ///< of the accepted corrector
  int attempts = 1;      ///< corrector attempts of the step (retries included)
  double distance = 0;   ///< metric distance from the point the step started from
  double seconds = 0;    ///< wall time of the step (of the landing, for a landed point)
  bool start = false, landed = false, kink = false;
  const vec<double>* tangent = nullptr;    ///< tangent predictor: the unit tangent at the point
  const vec<double>* from = nullptr;       ///< the point the step started from
  const vec<double>* direction = nullptr;  ///< the unit direction of the prediction
  double step = 0;                         ///< the step ds taken
};

/// Returned by a problem's end_of_curve hook to end the trace at a converged step.
struct curve_end {
  bool emit = false;  ///< emit the step's point before stopping
  std::string reason;
};

/// Listed values of one coordinate to land on exactly (non-empty, finite, strictly monotone).
struct curve_targets {
  Eigen::Index index = 0;
  std::vector<double> values;
  std::string name = "x";
};

/// A bound of one coordinate: landed on exactly when crossed, and the trace stops there.
struct curve_bound {
  Eigen::Index index = 0;
  double value = 0;
  std::string name = "x";
};

/// [lo, hi] of one coordinate: the trace stops after the first point outside.
struct curve_limit {
  Eigen::Index index = 0;
  double lo = -INFINITY, hi = INFINITY;
};

struct curve_stepper_options {
  double step = 0.01;        ///< initial step (metric; natural: the fixed coordinate step)
  double min_step = 1e-6;
  double max_step = 0.1;
  double growth = 1.5;       ///< step factor after a fast corrector
  int fast_iterations = 3;   ///< corrector iterations that count as fast
  int max_points = 200;      ///< emitted points, start and landed ones included
  curve_predictor predictor = curve_predictor::secant;
  Eigen::Index natural_index = -1;  ///< natural: the stepped coordinate
  int natural_direction = 1;        ///< natural: +1 or -1
  bool retry_exact_tangent = true;  ///< secant: retry a failed step once along the exact tangent
  bool sheet_guard = false;
  double corrector_distance = 0.5;  ///< sheet guard: max distance from the prediction / ds
  double min_cosine = 0.5;          ///< sheet guard: min cosine between the step and t
  bool retrace_guard = false;
  bool kink_step = false;
  Eigen::Index kink_primary = -1, kink_secondary = -1;  ///< coordinates of the kink step
  std::string kink_primary_name = "primary", kink_secondary_name = "secondary";  ///< for messages
  double kink_distance = 2.0;       ///< kink step: max distance from the last point / ds
  bool detect_closed = false;
  std::vector<curve_targets> targets;
  std::vector<curve_bound> bounds;
  std::vector<curve_limit> limits;
  std::string label = "curve";
  bool verbose = false;
  std::ostream* log = nullptr;
};

enum class curve_stop { max_points, bound, limit, end_of_curve, closed_curve, requested, step_underflow, corrector_failure };

struct curve_outcome {
  curve_stop stop = curve_stop::max_points;
  std::string reason;
  int points = 0;             ///< emitted points
  int failed_correctors = 0;  ///< failed or rejected step correctors
  int kink_steps = 0;         ///< steps accepted at a fixed coordinate
  double arclength = 0;       ///< sum of the accepted steps' metric lengths
  std::vector<double> missed;  ///< target values crossed whose landing failed
  // the bound that stopped the trace
  Eigen::Index bound_index = -1;
  double bound_value = NAN;
  bool bound_landed = false;
  // step underflow / corrector failure
  std::string last_failure;
  double last_step = NAN;     ///< the last attempted step
};

namespace internal {
template <class P>
std::string describe_point(P& prob, const vec<double>& x) {
  if constexpr (requires { { prob.describe(x) } -> std::convertible_to<std::string>; }) return prob.describe(x);
  else return internal::concat("x = (", x.size(), " entries)");
}
}  // namespace internal

/// Throws input_error naming the option unless o is usable for N unknowns under metric m.
inline void check_curve_stepper_options(const curve_stepper_options& o, Eigen::Index N, const curve_metric& m) {
  const std::string& w = o.label;
  require(m.size() == N, w, ": the metric has ", m.size(), " weights for ", N, " unknowns");
  require(std::isfinite(o.step) && o.step > 0, w, ": step must be finite and > 0 (got ", o.step, ")");
  if (o.predictor != curve_predictor::natural) {
    require(std::isfinite(o.min_step) && o.min_step > 0, w, ": min_step must be finite and > 0 (got ", o.min_step, ")");
    require(std::isfinite(o.max_step) && o.max_step >= o.min_step, w,
            ": max_step must be finite and >= min_step (got ", o.max_step, ", min_step ", o.min_step, ")");
    require(o.step >= o.min_step, w, ": step ", o.step, " < min_step ", o.min_step);
  } else {
    require(o.natural_index >= 0 && o.natural_index < N, w, ": natural_index ", o.natural_index, " outside [0, ", N, ")");
    require(o.natural_direction == 1 || o.natural_direction == -1, w, ": natural_direction must be +1 or -1");
  }
  require(std::isfinite(o.growth) && o.growth >= 1, w, ": growth must be finite and >= 1 (got ", o.growth, ")");
  require(o.fast_iterations >= 0, w, ": fast_iterations must be >= 0 (got ", o.fast_iterations, ")");
  require(o.max_points >= 1, w, ": max_points must be >= 1 (got ", o.max_points, ")");
  require(o.corrector_distance > 0 && !std::isnan(o.corrector_distance), w, ": corrector_distance must be > 0 (got ",
          o.corrector_distance, ")");
  require(o.min_cosine >= -1 && o.min_cosine < 1, w, ": min_cosine must lie in [-1, 1) (got ", o.min_cosine, ")");
  if (o.kink_step) {
    require(o.kink_primary >= 0 && o.kink_primary < N && o.kink_secondary >= 0 && o.kink_secondary < N, w,
            ": kink coordinates (", o.kink_primary, ", ", o.kink_secondary, ") outside [0, ", N, ")");
    require(std::isfinite(o.kink_distance) && o.kink_distance > 0, w, ": kink_distance must be finite and > 0 (got ",
            o.kink_distance, ")");
  }
  for (const auto& t : o.targets) {
    require(t.index >= 0 && t.index < N, w, ": listed ", t.name, " values: coordinate ", t.index, " outside [0, ", N, ")");
    require(!t.values.empty(), w, ": listed ", t.name, " values are empty (leave the list out instead)");
    for (std::size_t k = 0; k < t.values.size(); ++k)
      require(std::isfinite(t.values[k]), w, ": listed ", t.name, " value ", k, " is not finite (", t.values[k], ")");
    const bool up = t.values.size() < 2 || t.values[1] > t.values[0];
    for (std::size_t k = 1; k < t.values.size(); ++k)
      require(up ? t.values[k] > t.values[k - 1] : t.values[k] < t.values[k - 1], w, ": listed ", t.name,
              " values must be strictly monotone (entries ", k - 1, " and ", k, ": ", t.values[k - 1], ", ", t.values[k],
              ")");
  }
  for (const auto& b : o.bounds) {
    require(b.index >= 0 && b.index < N, w, ": bound on ", b.name, ": coordinate ", b.index, " outside [0, ", N, ")");
    require(std::isfinite(b.value), w, ": bound on ", b.name, " is not finite (", b.value, ")");
  }
  for (const auto& l : o.limits) {
    require(l.index >= 0 && l.index < N, w, ": limit: coordinate ", l.index, " outside [0, ", N, ")");
    require(!std::isnan(l.lo) && !std::isnan(l.hi) && l.lo <= l.hi, w, ": limit needs lo <= hi (got ", l.lo, ", ",
            l.hi, ")");
  }
}

/// The unit tangent at x: prob.tangent(x, c) (J t = e_last with the last row c) normalised in
/// the metric and oriented so that <t, orient> >= 0. Throws singular_matrix_error if it is zero
/// or not finite.
template <class P>
vec<double> curve_unit_tangent(P& prob, const curve_metric& m, const vec<double>& x, const vec<double>& c,
                               const vec<double>& orient, const std::string& label) {
  vec<double> t = prob.tangent(x, c);
  const double tn = m.norm(t);
  if (!(std::isfinite(tn) && tn > 0)) throw singular_matrix_error(label + ": tangent is not finite");
  t /= tn;
  if (m.dot(t, orient) < 0) t = -t;
  return t;
}

/// True if y (scaled coordinates, curve_metric::scaled) lies within radius of the polyline
/// path[first .. last] (Euclidean in the scaled coordinates).
inline bool curve_near_polyline(const std::vector<vec<double>>& path, std::size_t first, std::size_t last,
                                const vec<double>& y, double radius) {
  for (std::size_t k = first; k < last && k + 1 < path.size(); ++k) {
    const vec<double> ab = path[k + 1] - path[k];
    const double l2 = ab.squaredNorm();
    const double th = l2 > 0 ? std::clamp((y - path[k]).dot(ab) / l2, 0.0, 1.0) : 0.0;
    if ((y - path[k] - th * ab).norm() < radius) return true;
  }
  return false;
}

/// Traces the curve from the converged point x0 with unit tangent t0 (secant, tangent; ignored
/// by natural). See the file comment. `out` is kept up to date as the trace goes (counts, the
/// stop), so it is valid when an exception from the problem ends the trace.
template <class P>
void trace_curve(P& prob, const vec<double>& x0, const vec<double>& t0, const curve_metric& metric,
                 const curve_stepper_options& o, curve_outcome& out) {
  using clock = std::chrono::steady_clock;
  const std::string& lab = o.label;
  const Eigen::Index N = x0.size();
  require(N > 0, lab, ": the start has no unknowns");
  require_finite(x0, lab, "start");
  check_curve_stepper_options(o, N, metric);
  const bool natural = o.predictor == curve_predictor::natural;
  constexpr bool has_tangent =
      requires(P& p, const vec<double>& v) { { p.tangent(v, v) } -> std::convertible_to<vec<double>>; };
  if (!natural) {
    require(t0.size() == N, lab, ": the start tangent has ", t0.size(), " entries for ", N, " unknowns");
    require_finite(t0, lab, "start tangent");
    require(std::abs(metric.norm(t0) - 1) < 1e-8, lab, ": the start tangent is not unit in the metric (norm ",
            metric.norm(t0), ")");
    require(has_tangent || (o.predictor == curve_predictor::secant && !o.retry_exact_tangent), lab,
            ": the predictor needs exact tangents: the problem has no tangent(x, c)");
  }
  auto log = [&]() -> std::ostream* { return o.verbose ? o.log : nullptr; };
  auto seconds_since = [](clock::time_point t) { return std::chrono::duration<double>(clock::now() - t).count(); };

  out = curve_outcome{};
  std::vector<vec<double>> path;  // scaled coordinates of the emitted points (retrace test)
  auto emit = [&](const vec<double>& x, const curve_point_info& info) {
    if (o.retrace_guard) path.push_back(metric.scaled(x));
    ++out.points;
    return prob.emit(x, info);
  };
  auto finish = [&](curve_stop why, std::string reason) {
    out.stop = why;
    out.reason = std::move(reason);
  };
  // Retrace test: within a quarter step of the polyline of the points before the last three.
  auto revisits = [&](const vec<double>& x, double step) {
    if (!o.retrace_guard || path.size() < 5) return false;
    return curve_near_polyline(path, o.detect_closed ? 1 : 0, path.size() - 4, metric.scaled(x), 0.25 * step);
  };
  auto outside_limit = [&](const vec<double>& x) {
    for (const auto& l : o.limits)
      if (x[l.index] < l.lo || x[l.index] > l.hi) return true;
    return false;
  };
  auto stop_after_emit = [&](const vec<double>& x, bool requested) -> std::optional<curve_stop> {
    if (outside_limit(x)) return curve_stop::limit;
    if (out.points >= o.max_points) return curve_stop::max_points;
    if (requested) return curve_stop::requested;
    return std::nullopt;
  };
  auto stop_text = [&](curve_stop s) -> std::string {
    switch (s) {
      case curve_stop::limit: return "left the limits";
      case curve_stop::max_points: return "max_points reached";
      case curve_stop::requested: return "stop requested";
      default: return "";
    }
  };

  vec<double> x = x0, t = t0, x_prev;
  {
    curve_point_info info;
    info.start = true;
    if (o.predictor == curve_predictor::tangent) info.tangent = &t;
    const bool req = emit(x, info);
    if (auto s = stop_after_emit(x, req)) return finish(*s, stop_text(*s));
  }

  // ---- natural parameter: fixed coordinate steps, the previous point as prediction ----
  if (natural) {
    const Eigen::Index j = o.natural_index;
    const double dmu = o.natural_direction * o.step, start = x0[j];
    for (int k = 1;; ++k) {
      const double value = start + k * dmu;
      for (const auto& l : o.limits)
        if (l.index == j && (value < l.lo || value > l.hi)) return finish(curve_stop::limit, stop_text(curve_stop::limit));
      curve_request q;
      q.x0 = x;
      q.c = vec<double>::Unit(N, j);
      q.value = value;
      q.step = o.step;
      q.point = out.points;
      const auto t_point = clock::now();
      std::string why;
      auto r = prob.correct(q, why);
      if (!r) {
        ++out.failed_correctors;
        out.last_failure = why;
        out.last_step = o.step;
        return finish(curve_stop::corrector_failure,
                      internal::concat(lab, ": the corrector failed at ", internal::describe_point(prob, x), " + step: ", why));
      }
      curve_point_info info;
      info.iterations = r->iterations;
      info.distance = metric.distance(r->x, x);
      info.seconds = seconds_since(t_point);
      info.from = &x;
      info.step = o.step;
      out.arclength += info.distance;
      const bool req = emit(r->x, info);
      x = std::move(r->x);
      if (auto s = stop_after_emit(x, req)) return finish(*s, stop_text(*s));
    }
  }

  // every listed value and bound, in the order given (targets first)
  struct landing {
    Eigen::Index index;
    double value;
    bool bound;
    std::string name;
  };
  std::vector<landing> lands;
  for (const auto& tg : o.targets)
    for (double v : tg.values) lands.push_back({tg.index, v, false, tg.name});
  for (const auto& b : o.bounds) lands.push_back({b.index, b.value, true, b.name});

  double ds = std::min(o.step, o.max_step);
  for (;;) {
    const auto t_point = clock::now();
    int attempts = 0;
    bool exact_t = o.predictor == curve_predictor::tangent || out.points == 1;  // t is the exact tangent at x
    const vec<double> t_secant = t;  // the direction of travel so far (t may become the exact tangent)
    bool first = true, kink_tried = false, kinked = false;
    std::string why;
    using corrected_t = std::remove_cvref_t<decltype(*prob.correct(std::declval<const curve_request&>(), why))>;
    std::optional<corrected_t> xn;
    auto request = [&](vec<double> x0r, vec<double> c, double value, curve_attempt kind) {
      curve_request q;
      q.x0 = std::move(x0r);
      q.c = std::move(c);
      q.value = value;
      q.step = ds;
      q.kind = kind;
      q.first = first && kind == curve_attempt::step;
      q.point = out.points;
      return q;
    };
    // The same step at a fixed coordinate (file comment); true: xn holds the accepted point.
    auto kink_step = [&]() -> bool {
      kink_tried = true;
      const auto sc = [&](Eigen::Index i) { return std::abs(t_secant[i]) * std::sqrt(metric.weight()[i]); };
      const bool primary_first = sc(o.kink_primary) >= 0.1 * sc(o.kink_secondary);
      const Eigen::Index order[2] = {primary_first ? o.kink_primary : o.kink_secondary,
                                     primary_first ? o.kink_secondary : o.kink_primary};
      const vec<double> xp = x + ds * t_secant;
      for (Eigen::Index j : order) {
        auto xk = prob.correct(request(xp, vec<double>::Unit(N, j), xp[j], curve_attempt::kink), why);
        const std::string& name = j == o.kink_primary ? o.kink_primary_name : o.kink_secondary_name;
        const std::string at = internal::concat("fixed-", name, " step");
        if (xk) {
          const double dist = metric.distance(xk->x, x);
          const bool forward = metric.dot(vec<double>(xk->x - x), t_secant) > 0 && !revisits(xk->x, ds);
          if (forward && dist <= o.kink_distance * ds) {
            xn = std::move(xk);
            ++out.kink_steps;
            kinked = true;
            if (auto* L = log())
              *L << lab << ": step " << ds << " from " << internal::describe_point(prob, x) << " taken at fixed " << name
                 << " (a kink of the curve?)" << std::endl;
            return true;
          }
          why = forward ? internal::concat(at, " landed ", dist, " from the last point (step ", ds, ")")
                        : internal::concat(at, " went back along the curve");
        } else {
          why = internal::concat(at, " failed: ", why);
        }
        if (auto* L = log()) *L << lab << ": " << why << std::endl;
      }
      return false;
    };
    for (;;) {
      ++attempts;
      const vec<double> xp = x + ds * t;
      vec<double> c = metric.row(t);
      const double value = c.dot(xp);
      xn = prob.correct(request(xp, std::move(c), value, curve_attempt::step), why);
      const bool diverged = !xn;  // the corrector failed (not: converged to a point rejected below)
      if (xn) {
        const vec<double> d = xn->x - x;
        const double dn = metric.norm(d);
        if (o.sheet_guard && !(metric.distance(xn->x, xp) <= o.corrector_distance * ds)) {
          why = internal::concat("corrector moved ", metric.distance(xn->x, xp), " from the prediction (step ", ds, ")");
          xn.reset();
        } else if (o.sheet_guard && !(metric.dot(d, t) > o.min_cosine * dn)) {
          why = "the corrected point lies behind the last point or off the predicted direction";
          xn.reset();
        } else if (o.retrace_guard && !(metric.dot(d, t_secant) > 0)) {
          why = "the corrected point goes back along the traced curve";
          xn.reset();
        } else if (revisits(xn->x, ds)) {
          why = "the corrected point lies on a stretch of the curve traced before";
          xn.reset();
        }
      }
      if (xn) break;
      ++out.failed_correctors;
      first = false;
      if (diverged && o.kink_step && !kink_tried) {
        if (auto* L = log())
          *L << lab << ": step " << ds << " from " << internal::describe_point(prob, x) << " failed (" << why
             << "), trying it at fixed " << o.kink_primary_name << " or "
             << o.kink_secondary_name << std::endl;
        if (kink_step()) break;
      }
      bool retry_same = false;
      if (o.predictor == curve_predictor::secant && o.retry_exact_tangent && !exact_t) {
        if constexpr (has_tangent) {
          try {
            t = curve_unit_tangent(prob, metric, x, metric.row(t), t, lab);
            retry_same = true;
          } catch (const error& e) {
            why += internal::concat(" (exact tangent failed: ", e.what(), ")");
          }
        }
        exact_t = true;
      }
      if (auto* L = log())
        *L << lab << ": step " << ds << " from " << internal::describe_point(prob, x) << " failed (" << why << "), "
           << (retry_same ? "retrying along the exact tangent" : "halving") << std::endl;
      if (retry_same) continue;
      if (o.kink_step && !kink_tried && kink_step()) break;
      kink_tried = false;
      ds *= 0.5;
      if (ds < o.min_step) {
        out.last_failure = why;
        out.last_step = 2 * ds;
        return finish(curve_stop::step_underflow,
                      internal::concat(lab, ": step fell below min_step = ", o.min_step, " after the point ",
                             internal::describe_point(prob, x), " (point ", out.points - 1, "); last attempted step ",
                             2 * ds, ", last failure: ", why));
      }
    }
    vec<double> xnew = std::move(xn->x);
    const int iters = xn->iterations;
    const double step_seconds = seconds_since(t_point);
    auto step_info = [&] {
      curve_point_info info;
      info.iterations = iters;
      info.attempts = attempts;
      info.distance = metric.distance(xnew, x);
      info.seconds = step_seconds;
      info.kink = kinked;
      info.from = &x;
      info.direction = &t;
      info.step = ds;
      return info;
    };

    // ---- the end of the curve, as the problem sees it ----
    if constexpr (requires { prob.end_of_curve(*xn, &x, x, xnew); }) {
      if (std::optional<curve_end> end = prob.end_of_curve(*xn, x_prev.size() ? &x_prev : nullptr, x, xnew)) {
        if (end->emit) emit(xnew, step_info());
        return finish(curve_stop::end_of_curve, std::move(end->reason));
      }
    }

    // ---- landings on listed values and bounds crossed by this step, in curve order ----
    std::vector<std::pair<double, const landing*>> crossed;
    for (const auto& l : lands) {
      const double a = x[l.index] - l.value, b = xnew[l.index] - l.value;
      if (a * b < 0 || (b == 0 && a != 0)) crossed.push_back({a / (a - b), &l});
    }
    std::sort(crossed.begin(), crossed.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
    for (const auto& [theta, l] : crossed) {
      const auto t_land = clock::now();
      auto xl = prob.correct(request(vec<double>(x + theta * (xnew - x)), vec<double>::Unit(N, l->index), l->value,
                                     curve_attempt::landing),
                             why);
      bool req = false;
      if (xl) {
        curve_point_info info;
        info.iterations = xl->iterations;
        info.distance = metric.distance(xl->x, x);
        info.seconds = seconds_since(t_land);
        info.landed = true;
        info.from = &x;
        info.step = ds;
        req = emit(xl->x, info);
      } else {
        if (auto* L = log()) *L << lab << ": landing on " << l->name << " = " << l->value << " failed: " << why << std::endl;
        if (!l->bound) out.missed.push_back(l->value);
      }
      if (l->bound) {
        if (!xl) emit(xnew, step_info());
        out.bound_index = l->index;
        out.bound_value = l->value;
        out.bound_landed = xl.has_value();
        return finish(curve_stop::bound, internal::concat("reached ", l->name, " = ", l->value,
                                                xl ? "" : " (landing failed: the last point lies outside)"));
      }
      if (out.points >= o.max_points) return finish(curve_stop::max_points, stop_text(curve_stop::max_points));
      if (req) return finish(curve_stop::requested, stop_text(curve_stop::requested));
    }

    // ---- accept ----
    const double len = metric.distance(xnew, x);
    out.arclength += len;
    vec<double> t_new;
    if (o.predictor == curve_predictor::tangent) {
      if constexpr (has_tangent) t_new = curve_unit_tangent(prob, metric, xnew, metric.row(t), t, lab);
    }
    {
      curve_point_info info = step_info();
      if (t_new.size()) info.tangent = &t_new;
      const bool req = emit(xnew, info);
      if (auto s = stop_after_emit(xnew, req)) return finish(*s, stop_text(*s));
    }
    if constexpr (requires { prob.renormalise(xnew, x); }) prob.renormalise(xnew, x);
    if (o.predictor == curve_predictor::tangent) {
      t = std::move(t_new);
    } else {
      t = xnew - x;
      t /= metric.norm(t);
    }
    x_prev = std::move(x);
    x = std::move(xnew);
    if (o.detect_closed && out.arclength > 3 * len && metric.distance(x, x0) < len)
      return finish(curve_stop::closed_curve, internal::concat("the curve closed on its start after arclength ", out.arclength));
    if (iters <= o.fast_iterations) ds = std::min(o.max_step, o.growth * ds);
  }
}

/// trace_curve returning the outcome.
template <class P>
curve_outcome trace_curve(P& prob, const vec<double>& x0, const vec<double>& t0, const curve_metric& metric,
                          const curve_stepper_options& o) {
  curve_outcome out;
  trace_curve(prob, x0, t0, metric, o, out);
  return out;
}

/// A problem for trace_curve from callables: correct(request, why) -> optional<R>,
/// tangent(x, c) -> vec<double> (or std::nullptr_t: none), emit(x, info) -> bool.
template <class Correct, class Tangent, class Emit>
struct curve_problem {
  Correct correct_fn;
  Tangent tangent_fn;
  Emit emit_fn;
  auto correct(const curve_request& q, std::string& why) { return correct_fn(q, why); }
  vec<double> tangent(const vec<double>& x, const vec<double>& c)
    requires(!std::same_as<Tangent, std::nullptr_t>)
  {
    return tangent_fn(x, c);
  }
  bool emit(const vec<double>& x, const curve_point_info& info) { return emit_fn(x, info); }
};
template <class Correct, class Tangent, class Emit>
curve_problem(Correct, Tangent, Emit) -> curve_problem<Correct, Tangent, Emit>;

}  // namespace aerohopf
