#pragma once
// Two-parameter continuation of Hopf points: the Hopf curve (flutter boundary) in a plane
// (mu, nu). mu is the system's own parameter (Ubar, the Damkohler number); nu indexes a family
// of systems, family(nu) -> S with S a dynamical_system (the Mach number: one aerofoil_system
// per Mach number). Natural continuation in nu (solve_hopf at nu_k from the point at nu_{k-1})
// diverges where the curve is steep or turns back in nu; pseudo-arclength does not.
//
// Unknowns X = [w, p_r, p_i, mu, nu, omega] (3n + 3). Equations: the augmented Hopf system of
// hopf.hpp (Griewank-Reddien) at the current nu, plus one pseudo-arclength equation:
//
//   G(X) = [ f(w, mu; nu)
//            A p_r + omega p_i
//            A p_i - omega p_r
//            s.p_r
//            s.p_i - 1
//            c.(y - y_pred) ]           y = (mu, nu, omega),  c_j = t_j / sigma_j^2
//
//   J_G  = [ A          0         0         f_mu        f_nu           0
//            A_w p_r    A         omega I   A_mu p_r    (A p_r)_nu     p_i
//            A_w p_i   -omega I   A         A_mu p_i    (A p_i)_nu    -p_r
//            0          s^T       0         0           0              0
//            0          0         s^T       0           0              0
//            0          0         0         c_mu        c_nu           c_omega ]
//
// The arclength metric is the scaled (mu, nu, omega) space, |dy|^2 = sum_j (dy_j / sigma_j)^2
// with user scales sigma_mu, sigma_nu, sigma_omega (sigma_omega = 0 drops omega: the pure
// (mu, nu) plane). w and p are NOT in the metric: their size depends on the model and the
// normalisation, and the curve is a curve in the parameter plane. Keeping omega in (the
// default) makes the end of a Hopf curve at a Bogdanov-Takens point (omega -> 0, where the
// curve turns back in (mu, nu) onto itself with -omega) a regular point of the metric, so it
// is reached and reported instead of stalling the step control.
//
// Derivatives: w and mu exactly as solve_hopf (exact Jacobian, jacobian_directional,
// jacobian_d_mu, residual_d_mu); nu by central differences of the family,
//   f_nu = (f(w, mu; nu + h) - f(w, mu; nu - h)) / 2h,  (A p)_nu likewise with the exact
//   matrix-free products A p (taylor pass), h = nu_step or cbrt(eps) max(1, |nu|)
// (error O(h^2) ~ 1e-11 relative). They only enter J_G (the convergence rate), never G, so the
// points satisfy the exact equations. family(nu) is called for the current nu (residual) and
// for nu +/- h (Jacobian): three constructions per Newton iteration; each is cached.
//
// Normalisation s: as solve_hopf (largest component s = e_k for sparse Jacobians, keeping the
// border rows sparse; the rotated eigenvector for dense ones), refreshed at every accepted
// point. The previous point's p is re-scaled to the new s (p <- i p / (s.p)) before the secant,
// so the secant of p compares like with like.
//
// Predictor: first step along the tangent dX/dnu from J_G with the last row e_nu (needs
// dnu/ds != 0 at the start: start away from a turning point in nu), oriented by `direction`;
// then the secant X_k - X_{k-1} scaled to unit length in the metric; after a failed corrector
// the exact tangent at X_k (J_G t = e_last with the secant as last row) replaces the secant
// (the chord points off the curve at every step size where the curve bends sharply: measured
// on the heavy-case aerofoil near M = 0.84, where the secant stalled the trace). Corrector: newton_iterate
// on G. Step control: halve on corrector failure (non-convergence, divergence, singular
// matrix, NaN, any aerohopf::error thrown by family(nu) or the system, a corrector that moved
// farther than corrector_distance x the step from the prediction, or one that landed behind the
// last point or more than acos(min_cosine) off the predicted direction: both are jumps to another
// sheet where the curve folds, measured on the heavy-case aerofoil near M = 0.84), grow by
// `growth` after <= fast_iterations Newton iterations, clamp to [min_step, max_step]; below
// min_step: convergence_error naming the last converged point, the attempted step and the last
// failure (or, with throw_on_failure = false, stop with step_failure keeping the points). The
// observer sees every point as it is accepted (write expensive curves out as they come).
//
// Stops: max_points; leaving [nu_min, nu_max] or [mu_min, mu_max] (the crossing is landed on
// the bound exactly: Newton with the last row nu - bound = 0); omega <= omega_min or a sign
// change of omega (Bogdanov-Takens: estimate of its (mu, nu) by extrapolating the last points
// in omega^2, along which (mu, nu) are smooth); the curve closing on its start; stop_after
// returning true for an accepted point (hopf_curve_stop::requested). nu_targets:
// every crossing of a listed nu is landed exactly (a flutter boundary at given Mach numbers).
//
// Post-checks (those of hopf.hpp, for every accepted point): a converged corrector's
// ||f(w, mu; nu)|| is at most the ||G|| its Newton run resolved (f is a block of G; confirmed,
// else a failed corrector), and its omega must exceed the resolved frequency 10 ||G|| / ||p||:
// below it omega is indistinguishable from 0 and the step is the Bogdanov-Takens end (with
// omega_min = 0 too); a landing below it is a failed landing. The start is converged by
// solve_hopf, whose post-checks refuse a real eigenvalue. Options and the start are checked by
// name first (input_error). A corrector failure names the corrector's last accepted iterate
// (||G||, nu, mu, omega); an aerohopf::error raised outside the correctors ends the trace with
// the last point's number and coordinates: rethrown as the same type, or, with
// throw_on_failure = false, a step_failure stop that keeps the points (a restart from
// points.back().point() continues the curve).
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <concepts>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "../error.hpp"
#include "../linalg/assemble.hpp"
#include "../linalg/direct.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "hopf.hpp"
#include "hopf_point.hpp"

namespace aerohopf {

/// A callable family(nu) returning a dynamical_system (by value).
template <class F>
concept system_family = std::invocable<const F&, double> &&
                        dynamical_system<std::remove_cvref_t<std::invoke_result_t<const F&, double>>>;

template <system_family F>
using family_system_t = std::remove_cvref_t<std::invoke_result_t<const F&, double>>;

struct hopf_curve_point {
  double nu = 0, mu = 0, omega = 0;
  vec<double> w;                 ///< equilibrium
  vec<std::complex<double>> p;   ///< A p = i omega p, normalised s.p = i for the s in use
  int newton_iterations = 0;     ///< of the accepted corrector (start: of solve_hopf)
  int attempts = 1;              ///< corrector attempts including the failed (halved) ones
  double step = 0;               ///< scaled (mu, nu, omega) distance from the previous point
  double seconds = 0;            ///< wall time spent on this point
  bool landed = false;           ///< computed at a requested nu (nu_targets) or on a bound
  hopf_point point() const { return {w, mu, omega, p}; }
};

enum class hopf_curve_stop { max_points, nu_bounds, mu_bounds, bogdanov_takens, closed_curve, step_failure, requested };

struct hopf_curve_options {
  double step = 0.01;       ///< initial step in the scaled (mu, nu, omega) metric
  double min_step = 1e-6;
  double max_step = 0.1;
  double growth = 1.5;      ///< step factor after fast convergence
  int fast_iterations = 3;  ///< corrector iterations that count as fast
  double mu_scale = 1.0, nu_scale = 1.0;  ///< sigma_mu, sigma_nu of the metric
  double omega_scale = 1.0;               ///< sigma_omega; 0 = omega not in the metric
  double nu_min = -std::numeric_limits<double>::infinity(), nu_max = std::numeric_limits<double>::infinity();
  double mu_min = -std::numeric_limits<double>::infinity(), mu_max = std::numeric_limits<double>::infinity();
  int max_points = 200;                   ///< including the start and landed points
  std::vector<double> nu_targets;         ///< land a point exactly on each crossing of these nu
  double omega_min = 1e-6;                ///< omega at or below: Bogdanov-Takens end
  bool detect_closed = true;              ///< stop when the curve returns to its start
  double corrector_distance = 0.5;        ///< reject a corrector farther than this x step from the prediction
  double min_cosine = 0.5;                ///< reject a step whose direction is more than acos(this) off the tangent
  double nu_step = 0;                     ///< h of the nu differences; 0 = cbrt(eps) max(1, |nu|)
  newton_options newton = [] {
    newton_options o;
    o.abs_tolerance = 1e-10;
    o.max_iterations = 10;
    return o;
  }();                                    ///< corrector (throw_on_failure is ignored)
  hopf_options start;                     ///< for converging the start point at fixed nu0
  hopf_normalisation normalisation = hopf_normalisation::automatic;
  bool throw_on_failure = true;           ///< false: stop with step_failure instead of throwing
  std::function<void(const hopf_curve_point&)> observer;  ///< called for every accepted point
  /// Called for every accepted point after the observer(s); true ends the trace there with
  /// hopf_curve_stop::requested (e.g. a caller that needs the curve only up to the next landed
  /// target, or only while nu increases).
  std::function<bool(const hopf_curve_point&)> stop_after;
  bool verbose = false;
  std::ostream* log = &std::cout;
  std::string label = "hopf curve";
};

struct hopf_curve_result {
  std::vector<hopf_curve_point> points;  ///< in curve order (start first)
  hopf_curve_stop stop = hopf_curve_stop::max_points;
  std::string stop_reason;
  double bogdanov_takens_mu = NAN, bogdanov_takens_nu = NAN;  ///< estimate, if the curve ended there
  std::vector<double> missed_targets;    ///< nu_targets crossed whose landing Newton failed
  int failed_correctors = 0;
  double seconds = 0;
};

namespace internal {
/// Throws input_error naming the offending option unless the options of a curve tracer are
/// usable (both tracers): step sizes finite with 0 < min_step <= step <= ... and min_step <=
/// max_step, growth >= 1, scales finite (mu, nu > 0, omega >= 0), bounds ordered, targets finite,
/// the corrector's Newton options valid.
inline void check_curve_options(const hopf_curve_options& o, const std::string& where) {
  require(std::isfinite(o.step) && std::isfinite(o.min_step) && std::isfinite(o.max_step) && o.step > 0 &&
              o.min_step > 0 && o.max_step >= o.min_step && o.step >= o.min_step,
          where, ": bad step sizes (step ", o.step, ", min_step ", o.min_step, ", max_step ", o.max_step,
          "): need finite 0 < min_step <= step, min_step <= max_step");
  require(std::isfinite(o.mu_scale) && std::isfinite(o.nu_scale) && std::isfinite(o.omega_scale) && o.mu_scale > 0 &&
              o.nu_scale > 0 && o.omega_scale >= 0,
          where, ": metric scales must be finite, mu_scale and nu_scale > 0, omega_scale >= 0 (got ", o.mu_scale, ", ",
          o.nu_scale, ", ", o.omega_scale, ")");
  require(std::isfinite(o.growth) && o.growth >= 1, where, ": growth must be finite and >= 1 (got ", o.growth, ")");
  require(o.fast_iterations >= 0, where, ": fast_iterations must be >= 0 (got ", o.fast_iterations, ")");
  require(!std::isnan(o.nu_min) && !std::isnan(o.nu_max) && o.nu_min <= o.nu_max, where,
          ": need nu_min <= nu_max (got ", o.nu_min, ", ", o.nu_max, ")");
  require(!std::isnan(o.mu_min) && !std::isnan(o.mu_max) && o.mu_min <= o.mu_max, where,
          ": need mu_min <= mu_max (got ", o.mu_min, ", ", o.mu_max, ")");
  require(o.max_points >= 1, where, ": max_points must be >= 1 (got ", o.max_points, ")");
  require_finite(o.nu_targets, where, "nu_targets");
  require(std::isfinite(o.omega_min) && o.omega_min >= 0, where, ": omega_min must be finite and >= 0 (got ",
          o.omega_min, ")");
  require(o.corrector_distance > 0 && !std::isnan(o.corrector_distance), where,
          ": corrector_distance must be > 0 (got ", o.corrector_distance, ")");
  require(o.min_cosine >= -1 && o.min_cosine < 1, where, ": min_cosine must lie in [-1, 1) (got ", o.min_cosine, ")");
  require(std::isfinite(o.nu_step) && o.nu_step >= 0, where, ": nu_step must be finite and >= 0 (got ", o.nu_step,
          ")");
  check_newton_options(o.newton, where, "newton");
  check_hopf_options(o.start, where + " (start options)");
}

/// The equilibrium post-check of hopf.hpp for a converged corrector of a tracer: ||f(w, mu)|| =
/// fn against tol_f. Empty if accepted, else the reason. (The frequency check is the caller's:
/// omega below the resolved floor is the Bogdanov-Takens end, not a failed corrector.)
inline std::string curve_equilibrium_check(double fn, double tol_f, double nu, double mu, double omega) {
  if (!(fn <= tol_f))
    return concat("the equilibrium does not hold at the corrected point (nu = ", nu, ", mu = ", mu, ", omega = ", omega,
                  "): ||f(w, mu)|| = ", fn, " > tolerance ", tol_f);
  return {};
}

/// What a tracer that stops on an aerohopf::error thrown outside its correctors says: the label,
/// the number and coordinates of the last accepted point.
inline std::string curve_failure_context(const std::string& label, std::size_t points, double nu, double mu,
                                         double omega) {
  return concat(label, ": stopped after point ", points == 0 ? 0 : points - 1, " (nu = ", nu, ", mu = ", mu,
                ", omega = ", omega, "): ");
}

/// family(nu) for one nu at a time, reconstructed only when nu changes.
template <class F, class S>
class family_cache {
 public:
  explicit family_cache(const F& f) : f_(f) {}
  const S& at(double nu) {
    if (!sys_ || nu != nu_) {
      sys_.reset();
      sys_.emplace(f_(nu));
      nu_ = nu;
    }
    return *sys_;
  }

 private:
  const F& f_;
  std::optional<S> sys_;
  double nu_ = NAN;
};
}  // namespace internal

/// Traces the Hopf curve of family(nu) through the Hopf point `start` of family(nu0) (a guess:
/// it is first converged by solve_hopf at fixed nu0), initially in the direction of increasing
/// (direction = +1) or decreasing (-1) nu. See the file comment.
template <system_family F>
hopf_curve_result trace_hopf_curve(const F& family, double nu0, const hopf_point& start,
                                   const hopf_curve_options& opt = {}, int direction = +1) {
  using S = family_system_t<F>;
  using M = jacobian_t<S>;
  using C = std::complex<double>;
  using clock = std::chrono::steady_clock;
  const std::string& lab = opt.label;
  const auto t_begin = clock::now();
  require(std::isfinite(nu0), lab, ": nu0 is not finite");
  internal::check_curve_options(opt, lab);
  require(nu0 >= opt.nu_min && nu0 <= opt.nu_max, lab, ": nu0 = ", nu0, " outside [nu_min, nu_max]");
  require(direction == 1 || direction == -1, lab, ": direction must be +1 or -1");
  require(!opt.start.fixed_equilibrium, lab, ": the fixed-equilibrium Hopf system is not supported (w depends on nu)");

  hopf_curve_result res;
  // ---- converge the start at fixed nu0 ----
  const auto t_start = clock::now();
  hopf_result h0;
  Eigen::Index n = 0;
  {
    const S sys0 = family(nu0);
    n = sys0.size();
    require(n > 0, lab, ": family(nu0) has no unknowns");
    require_size(start.w.size(), n, lab, "start.w (equilibrium at nu0)");
    require_size(start.p.size(), n, lab, "start.p (eigenvector)");
    require_finite(start.w, lab, "start.w (equilibrium at nu0)");
    require_finite(start.p, lab, "start.p (eigenvector)");
    require(std::isfinite(start.mu) && std::isfinite(start.omega), lab, ": start mu or omega is not finite (",
            start.mu, ", ", start.omega, ")");
    hopf_options ho = opt.start;
    ho.label = lab + ": start point at nu = " + internal::concat(nu0);
    h0 = solve_hopf(sys0, start, ho);
    require(h0.report.converged, lab, ": start point at nu = ", nu0, " did not converge (", h0.report.reason, ")");
  }
  require(h0.point.omega > opt.omega_min, lab, ": start point has omega = ", h0.point.omega,
          " <= omega_min (not a Hopf point)");
  const Eigen::Index N = 3 * n + 3, ipr = n, ipi = 2 * n, imu = 3 * n, inu = 3 * n + 1, iom = 3 * n + 2;
  const hopf_normalisation mode = resolve_normalisation<M>(opt.normalisation);
  const double sig[3] = {opt.mu_scale, opt.nu_scale, opt.omega_scale};
  auto yv = [&](const vec<double>& x, int j) { return x[imu + j]; };
  // scaled metric on y = (mu, nu, omega)
  auto ydot = [&](const vec<double>& a, const vec<double>& b) {
    double d = 0;
    for (int j = 0; j < 3; ++j)
      if (sig[j] > 0) d += yv(a, j) * yv(b, j) / (sig[j] * sig[j]);
    return d;
  };
  auto ydist = [&](const vec<double>& a, const vec<double>& b) {
    const vec<double> d = a - b;
    return std::sqrt(ydot(d, d));
  };
  auto get_p = [&](const vec<double>& x) {
    vec<C> p(n);
    p.real() = x.segment(ipr, n);
    p.imag() = x.segment(ipi, n);
    return p;
  };
  auto set_p = [&](vec<double>& x, const vec<C>& p) {
    x.segment(ipr, n) = p.real();
    x.segment(ipi, n) = p.imag();
  };
  // p <- i p / (s.p): s.p_r = 0, s.p_i = 1 for a given s
  auto rescale_p = [&](vec<double>& x, const vec<double>& s) {
    vec<C> p = get_p(x);
    const C sp = s.template cast<C>().dot(p);
    require(std::abs(sp) > 0, lab, ": eigenvector orthogonal to the normalisation vector");
    p *= C(0, 1) / sp;
    set_p(x, p);
  };
  auto refresh_s = [&](vec<double>& x) {
    vec<C> p = get_p(x);
    vec<double> s = hopf_normalise(p, mode);
    set_p(x, p);
    return s;
  };

  internal::family_cache<F, S> cur(family), plus(family), minus(family);
  auto nu_h = [&](double nu) { return opt.nu_step > 0 ? opt.nu_step : std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, std::abs(nu)); };
  auto check_size = [&](const S& s, double nu) {
    require(s.size() == n, lab, ": family(", nu, ") has ", s.size(), " unknowns, family(nu0) ", n);
  };

  // G(X) with the last row c.(y) - value
  auto residual = [&](const vec<double>& x, const vec<double>& s, const double* c, double value) {
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const S& sys = cur.at(nu);
    check_size(sys, nu);
    const vec<double> w = x.head(n), pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    vec<double> f(N);
    f.head(n) = sys.residual(w, mu);
    f.segment(ipr, n) = jacobian_product(sys, w, mu, pr) + om * pi;
    f.segment(ipi, n) = jacobian_product(sys, w, mu, pi) - om * pr;
    f[imu] = s.dot(pr);
    f[inu] = s.dot(pi) - 1.0;
    f[iom] = c[0] * mu + c[1] * nu + c[2] * om - value;
    return f;
  };
  auto jacobian = [&](const vec<double>& x, const vec<double>& s, const double* c) {
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const vec<double> w = x.head(n), pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    const double h = nu_h(nu);
    const S& sp = plus.at(nu + h);
    const S& sm = minus.at(nu - h);
    check_size(sp, nu + h);
    check_size(sm, nu - h);
    const vec<double> f_nu = (vec<double>(sp.residual(w, mu)) - vec<double>(sm.residual(w, mu))) / (2 * h);
    const vec<double> apr_nu = (jacobian_product(sp, w, mu, pr) - jacobian_product(sm, w, mu, pr)) / (2 * h);
    const vec<double> api_nu = (jacobian_product(sp, w, mu, pi) - jacobian_product(sm, w, mu, pi)) / (2 * h);
    const S& sys = cur.at(nu);
    const M a = sys.jacobian(w, mu);
    const M amu = jacobian_d_mu(sys, w, mu);
    block_assembler<M> j(N, N);
    j.add(0, 0, a);
    j.add_column(0, imu, residual_d_mu(sys, w, mu));
    j.add_column(0, inu, f_nu);
    j.add(ipr, 0, jacobian_directional(sys, w, mu, pr));
    j.add(ipi, 0, jacobian_directional(sys, w, mu, pi));
    j.add(ipr, ipr, a);
    j.add_identity(ipr, ipi, n, om);
    j.add_identity(ipi, ipr, n, -om);
    j.add(ipi, ipi, a);
    j.add_column(ipr, imu, amu * pr);
    j.add_column(ipi, imu, amu * pi);
    j.add_column(ipr, inu, apr_nu);
    j.add_column(ipi, inu, api_nu);
    j.add_column(ipr, iom, pi);
    j.add_column(ipi, iom, -pr);
    j.add_row(imu, ipr, s);
    j.add_row(inu, ipi, s);
    for (int k = 0; k < 3; ++k) j.add_entry(iom, imu + k, c[k]);
    return j.build();
  };
  direct_solver<M> lu(lab + ": extended Hopf Jacobian");

  struct corrected {
    vec<double> x;
    int iterations = 0;
    double omega_floor = 0;  ///< the smallest |omega| its Newton run resolves (hopf.hpp)
  };
  std::string last_failure;
  // Newton on G from x0 with the last row c.y = value; nullopt (and last_failure, with the last
  // accepted iterate) on failure. A converged point passes the post-checks of hopf.hpp: f is the
  // first block of G, so ||f(w, mu)|| <= the resolved ||G|| (confirmed, not assumed), and omega
  // must exceed the resolved frequency 10 ||G|| / ||p|| or it is a real eigenvalue (the caller
  // treats it as the Bogdanov-Takens end, omega -> 0).
  auto correct = [&](const vec<double>& x0, const vec<double>& s, const double* c,
                     double value) -> std::optional<corrected> {
    newton_options no = opt.newton;
    no.throw_on_failure = true;
    internal::hopf_iterate_log last(x0, imu, iom, inu);
    try {
      newton_result nr = newton_iterate(
          [&](const vec<double>& x) { return residual(x, s, c, value); },
          [&](const vec<double>& x, const vec<double>& f, int k) {
            last.record(x, f, k);
            lu.compute(jacobian(x, s, c));
            return vec<double>(-lu.solve(f));
          },
          x0, no, lab + " corrector");
      if (!nr.x.allFinite()) {
        last_failure = "corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      const double r = internal::hopf_resolved_residual(nr.report, no);
      const vec<double>& xc = nr.x;
      const double fn = internal::hopf_norm(vec<double>(cur.at(xc[inu]).residual(vec<double>(xc.head(n)), xc[imu])));
      const double floor = internal::hopf_frequency_floor(r, xc.segment(ipr, 2 * n).norm());
      const std::string why = internal::curve_equilibrium_check(fn, r, xc[inu], xc[imu], xc[iom]);
      if (!why.empty()) {
        last_failure = why;
        return std::nullopt;
      }
      return corrected{std::move(nr.x), nr.report.iterations, floor};
    } catch (const error& e) {
      last_failure = e.what() + last.describe();
      return std::nullopt;
    }
  };

  auto make_point = [&](const vec<double>& x, int iters, int attempts, double step, double secs, bool landed) {
    hopf_curve_point pt;
    pt.w = x.head(n);
    pt.p = get_p(x);
    pt.mu = x[imu];
    pt.nu = x[inu];
    pt.omega = x[iom];
    pt.newton_iterations = iters;
    pt.attempts = attempts;
    pt.step = step;
    pt.seconds = secs;
    pt.landed = landed;
    return pt;
  };
  bool stop_requested = false;  // opt.stop_after said so for the last accepted point
  auto emit = [&](hopf_curve_point pt) {
    if (opt.verbose && opt.log)
      *opt.log << lab << " " << std::setw(4) << res.points.size() << "  nu " << std::setprecision(10) << pt.nu
               << "  mu " << pt.mu << "  omega " << pt.omega << "  newton " << pt.newton_iterations << "  step "
               << std::setprecision(4) << pt.step << (pt.attempts > 1 ? "  (" + std::to_string(pt.attempts - 1) + " retries)" : "")
               << (pt.landed ? "  (landed)" : "") << std::setprecision(6) << "\n";
    if (opt.observer) opt.observer(pt);
    stop_requested = opt.stop_after && opt.stop_after(pt);
    res.points.push_back(std::move(pt));
  };
  auto finish = [&](hopf_curve_stop why, std::string reason) {
    res.stop = why;
    res.stop_reason = std::move(reason);
    res.seconds = std::chrono::duration<double>(clock::now() - t_begin).count();
    if (opt.verbose && opt.log) *opt.log << lab << ": stop: " << res.stop_reason << "\n";
    return res;
  };
  auto seconds_since = [](clock::time_point t) { return std::chrono::duration<double>(clock::now() - t).count(); };

  // ---- start point and first tangent dX/dnu ----
  vec<double> x(N);
  x.head(n) = h0.point.w;
  set_p(x, h0.point.p);
  x[imu] = h0.point.mu;
  x[inu] = nu0;
  x[iom] = h0.point.omega;
  vec<double> s = refresh_s(x);
  emit(make_point(x, h0.report.iterations, 1, 0.0, seconds_since(t_start), false));
  // Exact tangent at x: J_G with the last row c (any direction not orthogonal to the curve),
  // J_G t = e_last, normalised in the metric. Throws singular_matrix_error.
  auto exact_tangent = [&](const vec<double>& xx, const vec<double>& ss, const double* c) {
    lu.compute(jacobian(xx, ss, c));
    vec<double> e = vec<double>::Zero(N);
    e[iom] = 1;
    vec<double> tt = lu.solve(e);
    const double tn = std::sqrt(ydot(tt, tt));
    if (!(std::isfinite(tn) && tn > 0)) throw singular_matrix_error(lab + ": tangent is not finite");
    return vec<double>(tt / tn);
  };
  vec<double> t;
  {
    const double c_nu[3] = {0, 1, 0};
    try {
      t = exact_tangent(x, s, c_nu);
    } catch (const singular_matrix_error& e) {
      throw convergence_error(internal::concat(lab, ": no tangent dX/dnu at the start (nu = ", nu0, ", mu = ", x[imu],
                                               "): a turning point of the curve in nu or a degenerate Hopf point? ",
                                               e.what()));
    }
    if (t[inu] * direction < 0) t = -t;
  }
  if (res.points.size() >= size_t(opt.max_points)) return finish(hopf_curve_stop::max_points, "max_points reached");
  if (stop_requested) return finish(hopf_curve_stop::requested, "stop requested by stop_after");

  // nu/mu values whose crossing is landed exactly: (row, value, is_bound)
  struct landing {
    int row;  // 0: mu, 1: nu
    double value;
    bool bound;
  };
  std::vector<landing> lands;
  for (double v : opt.nu_targets) lands.push_back({1, v, false});
  if (std::isfinite(opt.nu_min)) lands.push_back({1, opt.nu_min, true});
  if (std::isfinite(opt.nu_max)) lands.push_back({1, opt.nu_max, true});
  if (std::isfinite(opt.mu_min)) lands.push_back({0, opt.mu_min, true});
  if (std::isfinite(opt.mu_max)) lands.push_back({0, opt.mu_max, true});

  const vec<double> x_first = x;
  vec<double> x_prev;  // the point before x (for the Bogdanov-Takens extrapolation)
  double ds = std::min(opt.step, opt.max_step), arclength = 0;
  // An aerohopf::error escaping the step (a normalisation that breaks down, a family that throws
  // outside a corrector) ends the trace like a step failure: rethrown with the last point's
  // context (same type), or with throw_on_failure = false a step_failure stop keeping the points.
  try {
    for (;;) {
      const auto t_point = clock::now();
      int attempts = 0;
      bool exact_t = false;  // t is the exact tangent at x (not the secant)
      std::optional<corrected> xn;
      for (;;) {
        ++attempts;
        const vec<double> xp = x + ds * t;
        double c[3], value = 0;
        for (int j = 0; j < 3; ++j) {
          c[j] = sig[j] > 0 ? yv(t, j) / (sig[j] * sig[j]) : 0.0;
          value += c[j] * yv(xp, j);
        }
        xn = correct(xp, s, c, value);
        if (xn) {
          // reject a corrector that wandered (another branch) or reversed the direction
          const double moved = ydist(xn->x, xp);
          const vec<double> d = xn->x - x;
          const double dn = std::sqrt(ydot(d, d));
          if (!(moved <= opt.corrector_distance * ds)) {
            last_failure = internal::concat("corrector moved ", moved, " from the prediction (step ", ds, ")");
            xn.reset();
          } else if (!(ydot(d, t) > opt.min_cosine * dn)) {
            // behind the last point, or far off the predicted direction: a jump to another
            // sheet of a folded curve (measured on the heavy-case aerofoil near M = 0.84)
            last_failure = "the corrected point lies behind the last point or off the predicted direction";
            xn.reset();
          }
        }
        if (xn) break;
        ++res.failed_correctors;
        // First failure at this point: the secant is the chord of the last step and, where the
        // curve bends sharply, points off the curve at any step size. Retry the same step along
        // the exact tangent at x (oriented along the secant), then halve.
        bool retry_same = false;
        if (!exact_t && res.points.size() > 1) {
          try {
            double c[3];
            for (int j = 0; j < 3; ++j) c[j] = sig[j] > 0 ? yv(t, j) / (sig[j] * sig[j]) : 0.0;
            vec<double> te = exact_tangent(x, s, c);
            if (ydot(te, t) < 0) te = -te;
            t = std::move(te);
            retry_same = true;
          } catch (const error& e) {
            last_failure += internal::concat(" (exact tangent failed: ", e.what(), ")");
          }
          exact_t = true;
        }
        if (opt.verbose && opt.log)
          *opt.log << lab << ": step " << ds << " from nu = " << x[inu] << ", mu = " << x[imu] << " failed ("
                   << last_failure << "), " << (retry_same ? "retrying along the exact tangent" : "halving") << "\n";
        if (retry_same) continue;
        ds *= 0.5;
        if (ds < opt.min_step) {
          const std::string why = internal::concat(
              lab, ": step fell below min_step = ", opt.min_step, " after the point nu = ", x[inu], ", mu = ", x[imu],
              ", omega = ", x[iom], " (point ", res.points.size() - 1, "); last attempted step ", 2 * ds,
              ", last failure: ", last_failure,
              opt.omega_scale == 0 && x[iom] < 1e-2 ? " (omega is small: a Bogdanov-Takens end? set omega_scale > 0)" : "");
          if (opt.throw_on_failure) throw convergence_error(why);
          return finish(hopf_curve_stop::step_failure, why);
        }
      }
      vec<double> xnew = std::move(xn->x);
      const int iters = xn->iterations;

      // ---- Bogdanov-Takens: omega reaches zero (or below what the corrector resolves) or changes sign ----
      const double omega_floor = xn->omega_floor;
      if (xnew[iom] <= std::max(opt.omega_min, omega_floor)) {
        // (mu, nu) are smooth in omega^2 along the curve: least squares of y = a + b omega^2
        std::vector<const vec<double>*> pts = {&x, &xnew};
        if (x_prev.size()) pts.push_back(&x_prev);
        double s1 = 0, sz = 0, szz = 0;
        double sy[2] = {0, 0}, szy[2] = {0, 0};
        for (const vec<double>* q : pts) {
          const double z = (*q)[iom] * (*q)[iom];
          s1 += 1, sz += z, szz += z * z;
          for (int j = 0; j < 2; ++j) sy[j] += (*q)[imu + j], szy[j] += z * (*q)[imu + j];
        }
        const double det = s1 * szz - sz * sz;
        for (int j = 0; j < 2; ++j) {
          const double a = std::abs(det) > 1e-300 ? (szz * sy[j] - sz * szy[j]) / det : xnew[imu + j];
          (j == 0 ? res.bogdanov_takens_mu : res.bogdanov_takens_nu) = a;
        }
        if (xnew[iom] > omega_floor)  // a Hopf point with a resolved frequency
          emit(make_point(xnew, iters, attempts, ydist(xnew, x), seconds_since(t_point), false));
        return finish(hopf_curve_stop::bogdanov_takens,
                      internal::concat("omega -> 0: the Hopf curve ends at a Bogdanov-Takens point near nu = ",
                                       res.bogdanov_takens_nu, ", mu = ", res.bogdanov_takens_mu, " (last omega ",
                                       xnew[iom], ")"));
      }

      // ---- landings on targets and bounds crossed by this step, in curve order ----
      std::vector<std::pair<double, landing>> crossed;
      for (const auto& l : lands) {
        const double a = x[imu + l.row] - l.value, b = xnew[imu + l.row] - l.value;
        if (a * b < 0 || (b == 0 && a != 0)) crossed.push_back({a / (a - b), l});
      }
      std::sort(crossed.begin(), crossed.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
      for (const auto& [theta, l] : crossed) {
        const auto t_land = clock::now();
        const vec<double> x0 = x + theta * (xnew - x);
        double c[3] = {0, 0, 0};
        c[l.row] = 1;
        auto xl = correct(x0, s, c, l.value);
        if (xl && !(xl->x[iom] > xl->omega_floor)) {
          last_failure = internal::concat("the landed point has omega = ", xl->x[iom], ", not above the resolved frequency ",
                                          xl->omega_floor);
          xl.reset();
        }
        if (xl) {
          emit(make_point(xl->x, xl->iterations, 1, ydist(xl->x, x), seconds_since(t_land), true));
        } else {
          if (opt.verbose && opt.log)
            *opt.log << lab << ": landing on " << (l.row ? "nu = " : "mu = ") << l.value << " failed: " << last_failure
                     << "\n";
          if (!l.bound) res.missed_targets.push_back(l.value);
        }
        if (l.bound) {
          if (!xl) emit(make_point(xnew, iters, attempts, ydist(xnew, x), seconds_since(t_point), false));
          return finish(l.row ? hopf_curve_stop::nu_bounds : hopf_curve_stop::mu_bounds,
                        internal::concat("reached ", l.row ? "nu = " : "mu = ", l.value,
                                         xl ? "" : " (landing failed: the last point lies outside)"));
        }
        if (res.points.size() >= size_t(opt.max_points)) return finish(hopf_curve_stop::max_points, "max_points reached");
        if (stop_requested) return finish(hopf_curve_stop::requested, "stop requested by stop_after");
      }

      // ---- accept ----
      const double len = ydist(xnew, x);
      arclength += len;
      emit(make_point(xnew, iters, attempts, len, seconds_since(t_point), false));
      if (res.points.size() >= size_t(opt.max_points)) return finish(hopf_curve_stop::max_points, "max_points reached");
      if (stop_requested) return finish(hopf_curve_stop::requested, "stop requested by stop_after");
      s = refresh_s(xnew);
      x_prev = std::move(x);
      rescale_p(x_prev, s);
      t = xnew - x_prev;
      const double tn = std::sqrt(ydot(t, t));
      t /= tn;
      x = std::move(xnew);
      if (opt.detect_closed && arclength > 3 * len && ydist(x, x_first) < len)
        return finish(hopf_curve_stop::closed_curve,
                      internal::concat("the curve closed on its start after arclength ", arclength));
      if (iters <= opt.fast_iterations) ds = std::min(opt.max_step, opt.growth * ds);
    }
  } catch (const error& e) {
    const hopf_curve_point& lp = res.points.back();  // the start at least
    const std::string where = internal::curve_failure_context(lab, res.points.size(), lp.nu, lp.mu, lp.omega);
    if (opt.throw_on_failure) internal::rethrow_with_context(where, "");
    return finish(hopf_curve_stop::step_failure, where + e.what());
  }
}

}  // namespace aerohopf
