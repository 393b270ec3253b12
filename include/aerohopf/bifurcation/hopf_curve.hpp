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
//   matrix-free products A p (jacobian_product_pair), h = nu_step or cbrt(eps) max(1, |nu|)
// (error O(h^2) ~ 1e-11 relative). They only enter J_G (the convergence rate), never G, so the
// points satisfy the exact equations. family(nu) is called for the current nu (residual) and
// for nu +/- h (Jacobian): three constructions per Newton iteration; each is cached.
//
// Normalisation s: as solve_hopf (largest component s = e_k for sparse Jacobians, keeping the
// border rows sparse; the rotated eigenvector for dense ones), refreshed at every accepted
// point. The previous point's p is re-scaled to the new s (p <- i p / (s.p)) before the secant,
// so the secant of p compares like with like.
//
// Stepping (curve_stepper.hpp, shared with the fixed-equilibrium tracer and the equilibrium
// continuation): first step along the tangent dX/dnu from J_G with the last row e_nu (needs
// dnu/ds != 0 at the start: start away from a turning point in nu), oriented by `direction`;
// then the secant, with the exact tangent at X_k (J_G t = e_last, the secant as last row) for
// the retry after a failed corrector (where the curve bends sharply the chord points off the
// curve at every step size: measured on the heavy-case aerofoil near M = 0.84). Step control:
// halve on a failed corrector (non-convergence, divergence, singular matrix, NaN, any
// aerohopf::error thrown by family(nu) or the system) or a sheet jump (a corrector farther
// than corrector_distance x the step from the prediction, behind the last point, or more than
// acos(min_cosine) off the predicted direction), grow by `growth` after <= fast_iterations
// Newton iterations, clamp to [min_step, max_step]; below min_step: convergence_error naming
// the last converged point, the attempted step and the last failure (or, with
// throw_on_failure = false, stop with step_failure keeping the points). This file holds the
// corrector (Newton on G by LU) and run_hopf_curve, the part both tracers share: the metric,
// landings, the Bogdanov-Takens end, emission and failure policy. The observer sees every
// point as it is accepted (write expensive curves out as they come).
//
// Stops: max_points; leaving [nu_min, nu_max] or [mu_min, mu_max] (the crossing is landed on
// the bound exactly: Newton with the last row nu - bound = 0); omega <= omega_min or a sign
// change of omega (Bogdanov-Takens: estimate of its (mu, nu) by extrapolating the last points
// in omega^2, along which (mu, nu) are smooth); the curve closing on its start; stop_after
// returning true for an accepted point (hopf_curve_stop::requested). nu_targets (strictly
// monotone): every crossing of a listed nu is landed exactly (a flutter boundary at given Mach
// numbers).
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
#include <array>
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
#include "curve_stepper.hpp"
#include "hopf.hpp"
#include "hopf_point.hpp"

namespace aerohopf {

/// A callable family(nu) returning a dynamical_system (by value).
template <class F>
concept system_family = std::invocable<const F&, double> &&
                        dynamical_system<std::remove_cvref_t<std::invoke_result_t<const F&, double>>>;

template <system_family F>
using family_system_t = std::remove_cvref_t<std::invoke_result_t<const F&, double>>;

/// The family type the tracers are instantiated with: every lambda is a type of its own, so the
/// public entry points erase it and the tracer is compiled once per system type (one indirect
/// call per system built costs nothing beside the solves on it).
template <class S>
using family_function = std::function<S(double)>;

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

/// What a Hopf-curve corrector returns: the point, its iterations, and the smallest |omega| its
/// Newton run resolves (hopf.hpp: 10 ||G|| / ||p||; below it omega is indistinguishable from 0).
struct hopf_corrected : curve_corrected {
  double omega_floor = 0;
};

/// The unknowns of a Hopf-curve tracer, X = [w (full system only), p_r, p_i, mu, nu, omega], the
/// metric on (mu, nu, omega) and the normalisation of p.
struct hopf_curve_layout {
  using C = std::complex<double>;
  Eigen::Index n = 0, ipr = 0, ipi = 0, imu = 0, inu = 0, iom = 0, N = 0;
  double sig[3] = {1, 1, 1};  ///< sigma_mu, sigma_nu, sigma_omega (0: not in the metric)
  hopf_normalisation mode = hopf_normalisation::automatic;

  hopf_curve_layout(Eigen::Index n_, bool with_w, const hopf_curve_options& opt, hopf_normalisation m)
      : n(n_), ipr(with_w ? n_ : 0), ipi(ipr + n_), imu(ipi + n_), inu(imu + 1), iom(imu + 2), N(imu + 3),
        sig{opt.mu_scale, opt.nu_scale, opt.omega_scale}, mode(m) {}

  vec<C> get_p(const vec<double>& x) const {
    vec<C> p(n);
    p.real() = x.segment(ipr, n);
    p.imag() = x.segment(ipi, n);
    return p;
  }
  void set_p(vec<double>& x, const vec<C>& p) const {
    x.segment(ipr, n) = p.real();
    x.segment(ipi, n) = p.imag();
  }
  /// p <- i p / (s.p): s.p_r = 0, s.p_i = 1 for the given s (so secants compare like with like)
  void rescale_p(vec<double>& x, const vec<double>& s, const std::string& label) const {
    vec<C> p = get_p(x);
    const C sp = s.template cast<C>().dot(p);
    require(std::abs(sp) > 0, label, ": eigenvector orthogonal to the normalisation vector");
    p *= C(0, 1) / sp;
    set_p(x, p);
  }
  /// A new s for the p of x (hopf_normalise), p of x rotated and scaled to it.
  vec<double> refresh_s(vec<double>& x) const {
    vec<C> p = get_p(x);
    vec<double> s = hopf_normalise(p, mode);
    set_p(x, p);
    return s;
  }
  /// |dy|^2 = sum_j (dy_j / sigma_j)^2 over y = (mu, nu, omega), sigma_j = 0 left out.
  curve_metric metric() const {
    vec<double> w = vec<double>::Zero(N);
    for (int j = 0; j < 3; ++j)
      if (sig[j] > 0) w[imu + j] = 1 / (sig[j] * sig[j]);
    return curve_metric(std::move(w));
  }
  /// The (mu, nu, omega) entries of a constraint row (the only ones a tracer's row has).
  std::array<double, 3> row3(const vec<double>& c) const { return {c[imu], c[inu], c[iom]}; }
  std::string describe(const vec<double>& x) const {
    return concat("nu = ", x[inu], ", mu = ", x[imu], ", omega = ", x[iom]);
  }
  /// The rows of G after the flow: A p_r + omega p_i, A p_i - omega p_r (exact matrix-free
  /// products at the flow state w), s.p_r, s.p_i - 1 and the constraint c.y - value.
  template <class S>
  void eigen_rows(const S& sys, const vec<double>& w, const vec<double>& x, const vec<double>& s,
                  const std::array<double, 3>& c, double value, vec<double>& f) const {
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const vec<double> pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    const auto [apr, api] = jacobian_product_pair(sys, w, mu, pr, pi);
    f.segment(ipr, n) = apr + om * pi;
    f.segment(ipi, n) = api - om * pr;
    f[imu] = s.dot(pr);
    f[inu] = s.dot(pi) - 1.0;
    f[iom] = c[0] * mu + c[1] * nu + c[2] * om - value;
  }
};

/// The input checks both tracers make first (input_error naming what is wrong).
inline void check_curve_trace(const hopf_curve_options& opt, double nu0, int direction) {
  const std::string& lab = opt.label;
  require(std::isfinite(nu0), lab, ": nu0 is not finite");
  check_curve_options(opt, lab);
  require(nu0 >= opt.nu_min && nu0 <= opt.nu_max, lab, ": nu0 = ", nu0, " outside [nu_min, nu_max]");
  require(direction == 1 || direction == -1, lab, ": direction must be +1 or -1");
}

/// A start of n unknowns (w, p finite and of that size; mu, omega finite).
inline void check_curve_start(const hopf_point& start, Eigen::Index n, const std::string& lab) {
  require(n > 0, lab, ": family(nu0) has no unknowns");
  require_size(start.w.size(), n, lab, "start.w (equilibrium at nu0)");
  require_size(start.p.size(), n, lab, "start.p (eigenvector)");
  require_finite(start.w, lab, "start.w (equilibrium at nu0)");
  require_finite(start.p, lab, "start.p (eigenvector)");
  require(std::isfinite(start.mu) && std::isfinite(start.omega), lab, ": start mu or omega is not finite (", start.mu,
          ", ", start.omega, ")");
}

/// The stepper options of a Hopf-curve tracer: step control, sheet-jump guard, landings on
/// nu_targets and on the finite bounds of nu and mu (in that order), closed-curve detection.
inline curve_stepper_options hopf_curve_stepper_options(const hopf_curve_options& opt, const hopf_curve_layout& L) {
  curve_stepper_options so;
  so.step = opt.step, so.min_step = opt.min_step, so.max_step = opt.max_step;
  so.growth = opt.growth, so.fast_iterations = opt.fast_iterations, so.max_points = opt.max_points;
  so.predictor = curve_predictor::secant;
  so.retry_exact_tangent = true;
  so.sheet_guard = true;
  so.corrector_distance = opt.corrector_distance;
  so.min_cosine = opt.min_cosine;
  so.detect_closed = opt.detect_closed;
  so.kink_primary = L.inu;  // the kinks of a C1 family lie on lines nu = const (hopf_curve_fixed_equilibrium.hpp)
  so.kink_secondary = L.imu;
  so.kink_primary_name = "nu";
  so.kink_secondary_name = "mu";
  if (!opt.nu_targets.empty()) so.targets.push_back({L.inu, opt.nu_targets, "nu"});
  if (std::isfinite(opt.nu_min)) so.bounds.push_back({L.inu, opt.nu_min, "nu"});
  if (std::isfinite(opt.nu_max)) so.bounds.push_back({L.inu, opt.nu_max, "nu"});
  if (std::isfinite(opt.mu_min)) so.bounds.push_back({L.imu, opt.mu_min, "mu"});
  if (std::isfinite(opt.mu_max)) so.bounds.push_back({L.imu, opt.mu_max, "mu"});
  so.label = opt.label;
  so.verbose = opt.verbose;
  so.log = opt.log;
  return so;
}

/// Traces a Hopf curve with the corrector `corr` through the converged start x (p not yet
/// normalised) on the curve stepper: the first tangent dX/dnu oriented by direction, the
/// emission of hopf_curve_points into res (observer, stop_after), the Bogdanov-Takens end
/// (omega at or below max(omega_min, the resolved frequency), or of the wrong sign: its (mu, nu)
/// by least squares in omega^2 over the last three points, along which they are smooth),
/// landed points refused below the resolved frequency, and the failure policy of the file
/// comment. The corrector provides
///   std::optional<hopf_corrected> correct(const curve_request&, const vec<double>& s, std::string& why)
///   vec<double> tangent(x, s, c)          J t = e_last with the last row c (not normalised)
///   vec<double> point_w(x)                the equilibrium of the point
///   void step_corrected(); void before_emit(bool landed); std::string costs_text();
///   void after_emit(const hopf_curve_point&)    (cost accounting per emitted point)
template <class Corrector, class Result>
Result run_hopf_curve(Corrector& corr, const hopf_curve_layout& L, vec<double> x, int start_iterations,
                      double start_seconds, const hopf_curve_options& opt, int direction, Result& res,
                      std::chrono::steady_clock::time_point t_begin, const curve_stepper_options& so) {
  const std::string& lab = opt.label;
  const curve_metric metric = L.metric();
  vec<double> s = L.refresh_s(x);
  auto finish = [&](hopf_curve_stop why, std::string reason) {
    res.stop = why;
    res.stop_reason = std::move(reason);
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_begin).count();
    if (opt.verbose && opt.log) *opt.log << lab << ": stop: " << res.stop_reason << std::endl;
    return std::move(res);
  };
  struct problem {
    Corrector& corr;
    const hopf_curve_layout& L;
    const hopf_curve_options& opt;
    Result& res;
    vec<double>& s;
    int start_iterations;
    double start_seconds;

    std::optional<hopf_corrected> correct(const curve_request& q, std::string& why) {
      std::optional<hopf_corrected> r = corr.correct(q, s, why);
      if (r && q.kind == curve_attempt::landing && !(r->x[L.iom] > r->omega_floor)) {
        why = concat("the landed point has omega = ", r->x[L.iom], ", not above the resolved frequency ",
                     r->omega_floor);
        r.reset();
      }
      return r;
    }
    vec<double> tangent(const vec<double>& x, const vec<double>& c) { return corr.tangent(x, s, c); }
    bool emit(const vec<double>& x, const curve_point_info& i) {
      hopf_curve_point pt;
      pt.w = corr.point_w(x);
      pt.p = L.get_p(x);
      pt.mu = x[L.imu];
      pt.nu = x[L.inu];
      pt.omega = x[L.iom];
      pt.newton_iterations = i.start ? start_iterations : i.iterations;
      pt.attempts = i.attempts;
      pt.step = i.distance;
      pt.seconds = i.start ? start_seconds : i.seconds;
      pt.landed = i.landed;
      corr.before_emit(pt.landed);
      if (opt.verbose && opt.log)
        *opt.log << opt.label << " " << std::setw(4) << res.points.size() << "  nu " << std::setprecision(10) << pt.nu
                 << "  mu " << pt.mu << "  omega " << pt.omega << "  newton " << pt.newton_iterations
                 << corr.costs_text() << "  step " << std::setprecision(4) << pt.step << "  " << std::setprecision(3)
                 << pt.seconds << " s"
                 << (pt.attempts > 1 ? "  (" + std::to_string(pt.attempts - 1) + " retries)" : "")
                 << (pt.landed ? "  (landed)" : "") << std::setprecision(6) << std::endl;
      if (opt.observer) opt.observer(pt);
      corr.after_emit(pt);
      const bool stop = opt.stop_after && opt.stop_after(pt);
      res.points.push_back(std::move(pt));
      return stop;
    }
    std::optional<curve_end> end_of_curve(const hopf_corrected& r, const vec<double>* before, const vec<double>& last,
                                          const vec<double>& xnew) {
      corr.step_corrected();
      if (xnew[L.iom] > std::max(opt.omega_min, r.omega_floor)) return std::nullopt;
      // least squares of y = a + b omega^2 over the last points
      std::vector<const vec<double>*> pts = {&last, &xnew};
      if (before) pts.push_back(before);
      double s1 = 0, sz = 0, szz = 0, sy[2] = {0, 0}, szy[2] = {0, 0};
      for (const vec<double>* q : pts) {
        const double z = (*q)[L.iom] * (*q)[L.iom];
        s1 += 1, sz += z, szz += z * z;
        for (int j = 0; j < 2; ++j) sy[j] += (*q)[L.imu + j], szy[j] += z * (*q)[L.imu + j];
      }
      const double det = s1 * szz - sz * sz;
      for (int j = 0; j < 2; ++j) {
        const double a = std::abs(det) > 1e-300 ? (szz * sy[j] - sz * szy[j]) / det : xnew[L.imu + j];
        (j == 0 ? res.bogdanov_takens_mu : res.bogdanov_takens_nu) = a;
      }
      return curve_end{xnew[L.iom] > r.omega_floor,  // a Hopf point with a resolved frequency
                       concat("omega -> 0: the Hopf curve ends at a Bogdanov-Takens point near nu = ",
                              res.bogdanov_takens_nu, ", mu = ", res.bogdanov_takens_mu, " (last omega ", xnew[L.iom],
                              ")")};
    }
    void renormalise(vec<double>& xnew, vec<double>& last) {
      s = L.refresh_s(xnew);
      L.rescale_p(last, s, opt.label);
    }
    std::string describe(const vec<double>& x) const { return L.describe(x); }
  } prob{corr, L, opt, res, s, start_iterations, start_seconds};

  vec<double> t;
  try {
    const vec<double> e_nu = vec<double>::Unit(L.N, L.inu);
    t = curve_unit_tangent(prob, metric, x, e_nu, vec<double>(direction * e_nu), lab);
  } catch (const error& e) {
    throw convergence_error(concat(lab, ": no tangent dX/dnu at the start (nu = ", x[L.inu], ", mu = ", x[L.imu],
                                   "): a turning point of the curve in nu or a degenerate Hopf point? ", e.what()));
  }
  curve_outcome oc;
  // An aerohopf::error escaping the stepper (a normalisation that breaks down, a family or a
  // steady solve that throws outside a corrector) ends the trace like a step failure.
  try {
    trace_curve(prob, x, t, metric, so, oc);
    if constexpr (requires { res.kink_steps; }) res.kink_steps = oc.kink_steps;
    res.failed_correctors = oc.failed_correctors;
    res.missed_targets = oc.missed;
    switch (oc.stop) {
      case curve_stop::max_points: return finish(hopf_curve_stop::max_points, "max_points reached");
      case curve_stop::requested: return finish(hopf_curve_stop::requested, "stop requested by stop_after");
      case curve_stop::bound:
        return finish(oc.bound_index == L.inu ? hopf_curve_stop::nu_bounds : hopf_curve_stop::mu_bounds, oc.reason);
      case curve_stop::end_of_curve: return finish(hopf_curve_stop::bogdanov_takens, oc.reason);
      case curve_stop::closed_curve: return finish(hopf_curve_stop::closed_curve, oc.reason);
      default: break;
    }
    const hopf_curve_point& lp = res.points.back();
    std::string why = oc.reason;
    if (opt.omega_scale == 0 && lp.omega < 1e-2) why += " (omega is small: a Bogdanov-Takens end? set omega_scale > 0)";
    if (opt.throw_on_failure) throw convergence_error(why);
    return finish(hopf_curve_stop::step_failure, why);
  } catch (const error& e) {
    if constexpr (requires { res.kink_steps; }) res.kink_steps = oc.kink_steps;
    res.failed_correctors = oc.failed_correctors;
    res.missed_targets = oc.missed;
    const bool none = res.points.empty();
    const std::string where =
        curve_failure_context(lab, res.points.size(), none ? x[L.inu] : res.points.back().nu,
                              none ? x[L.imu] : res.points.back().mu, none ? x[L.iom] : res.points.back().omega);
    if (opt.throw_on_failure) rethrow_with_context(where, "");
    return finish(hopf_curve_stop::step_failure, where + e.what());
  }
}

/// What the correctors of both tracers share: the layout, the options, the nu step of the
/// central differences, and family members checked for the size of family(nu0).
template <system_family F>
class hopf_curve_corrector_base {
 public:
  using S = family_system_t<F>;
  using M = jacobian_t<S>;

 protected:
  hopf_curve_corrector_base(const hopf_curve_layout& L, const hopf_curve_options& opt) : L_(L), opt_(opt) {}
  /// h of the nu differences: nu_step, or cbrt(eps) max(1, |nu|) (error O(h^2))
  double nu_h(double nu) const {
    return opt_.nu_step > 0 ? opt_.nu_step : std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, std::abs(nu));
  }
  const S& system_at(family_cache<F, S>& cache, double nu) const {
    const S& sys = cache.at(nu);
    require(sys.size() == L_.n, opt_.label, ": family(", nu, ") has ", sys.size(), " unknowns, family(nu0) ", L_.n);
    return sys;
  }
  const hopf_curve_layout& L_;
  const hopf_curve_options& opt_;
};

/// The corrector of the full Hopf curve: Newton on G (file comment) with the sparse or dense LU
/// of J_G, nu-derivatives by central differences of the family.
template <system_family F>
class hopf_curve_corrector : hopf_curve_corrector_base<F> {
  using base = hopf_curve_corrector_base<F>;
  using base::L_, base::opt_, base::nu_h, base::system_at;

 public:
  using typename base::S, typename base::M;

  hopf_curve_corrector(const F& family, const hopf_curve_layout& L, const hopf_curve_options& opt)
      : base(L, opt), cur_(family), plus_(family), minus_(family), lu_(opt.label + ": extended Hopf Jacobian") {}

  /// Newton on G from q.x0 with the last row q.c.X = q.value. A converged point passes the
  /// post-checks of hopf.hpp: f is the first block of G, so ||f(w, mu)|| <= the resolved ||G||
  /// (confirmed, not assumed); the frequency floor goes with it to the caller.
  std::optional<hopf_corrected> correct(const curve_request& q, const vec<double>& s, std::string& why) {
    const auto c = L_.row3(q.c);
    newton_options no = opt_.newton;
    no.throw_on_failure = true;
    hopf_iterate_log last(q.x0, L_.imu, L_.iom, L_.inu);
    try {
      newton_result nr = newton_iterate(
          [&](const vec<double>& x) { return residual(x, s, c, q.value); },
          [&](const vec<double>& x, const vec<double>& f, int k) {
            last.record(x, f, k);
            lu_.compute(jacobian(x, s, c));
            return vec<double>(-lu_.solve(f));
          },
          q.x0, no, opt_.label + " corrector");
      if (!nr.x.allFinite()) {
        why = "corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      const double r = hopf_resolved_residual(nr.report, no);
      const vec<double>& xc = nr.x;
      const double fn = hopf_norm(vec<double>(cur_.at(xc[L_.inu]).residual(vec<double>(xc.head(L_.n)), xc[L_.imu])));
      const double floor = hopf_frequency_floor(r, xc.segment(L_.ipr, 2 * L_.n).norm());
      const std::string bad = curve_equilibrium_check(fn, r, xc[L_.inu], xc[L_.imu], xc[L_.iom]);
      if (!bad.empty()) {
        why = bad;
        return std::nullopt;
      }
      hopf_corrected out;
      out.x = std::move(nr.x);
      out.iterations = nr.report.iterations;
      out.omega_floor = floor;
      return out;
    } catch (const error& e) {
      why = e.what() + last.describe();
      return std::nullopt;
    }
  }
  /// J_G t = e_last with the last row c. Throws singular_matrix_error.
  vec<double> tangent(const vec<double>& x, const vec<double>& s, const vec<double>& c) {
    lu_.compute(jacobian(x, s, L_.row3(c)));
    return lu_.solve(vec<double>(vec<double>::Unit(L_.N, L_.iom)));
  }
  vec<double> point_w(const vec<double>& x) const { return x.head(L_.n); }
  void step_corrected() {}
  void before_emit(bool) {}
  std::string costs_text() const { return {}; }
  void after_emit(const hopf_curve_point&) {}

 private:
  using row = std::array<double, 3>;
  // G(X) with the last row c.y - value
  vec<double> residual(const vec<double>& x, const vec<double>& s, const row& c, double value) {
    const S& sys = system_at(cur_, x[L_.inu]);
    const vec<double> w = x.head(L_.n);
    vec<double> f(L_.N);
    f.head(L_.n) = sys.residual(w, x[L_.imu]);
    L_.eigen_rows(sys, w, x, s, c, value, f);
    return f;
  }
  M jacobian(const vec<double>& x, const vec<double>& s, const row& c) {
    const Eigen::Index n = L_.n, ipr = L_.ipr, ipi = L_.ipi, imu = L_.imu, inu = L_.inu, iom = L_.iom;
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const vec<double> w = x.head(n), pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    const double h = nu_h(nu);
    const S& sp = system_at(plus_, nu + h);
    const S& sm = system_at(minus_, nu - h);
    const vec<double> f_nu = (vec<double>(sp.residual(w, mu)) - vec<double>(sm.residual(w, mu))) / (2 * h);
    const auto [apr_p, api_p] = jacobian_product_pair(sp, w, mu, pr, pi);
    const auto [apr_m, api_m] = jacobian_product_pair(sm, w, mu, pr, pi);
    const vec<double> apr_nu = (apr_p - apr_m) / (2 * h);
    const vec<double> api_nu = (api_p - api_m) / (2 * h);
    const S& sys = system_at(cur_, nu);
    const M a = sys.jacobian(w, mu);
    const M amu = jacobian_d_mu(sys, w, mu);
    block_assembler<M> j(L_.N, L_.N);
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
  }

  family_cache<F, S> cur_, plus_, minus_;
  direct_solver<M> lu_;
};

template <system_family F>
hopf_curve_result trace_hopf_curve_erased(const F& family, double nu0, const hopf_point& start,
                                          const hopf_curve_options& opt, int direction) {
  using S = family_system_t<F>;
  using M = jacobian_t<S>;
  using clock = std::chrono::steady_clock;
  const std::string& lab = opt.label;
  const auto t_begin = clock::now();
  internal::check_curve_trace(opt, nu0, direction);
  require(!opt.start.fixed_equilibrium, lab, ": the fixed-equilibrium Hopf system is not supported (w depends on nu)");

  // ---- converge the start at fixed nu0 ----
  const auto t_start = clock::now();
  hopf_result h0;
  Eigen::Index n = 0;
  {
    const S sys0 = family(nu0);
    n = sys0.size();
    internal::check_curve_start(start, n, lab);
    hopf_options ho = opt.start;
    ho.label = lab + ": start point at nu = " + internal::concat(nu0);
    const hopf_problem<S> prob(sys0, start, ho, "solve_hopf");
    hopf_augmented_lu<S> lu(ho);
    h0 = hopf_newton(prob, lu, ho);
    require(h0.report.converged, lab, ": start point at nu = ", nu0, " did not converge (", h0.report.reason, ")");
  }
  require(h0.point.omega > opt.omega_min, lab, ": start point has omega = ", h0.point.omega,
          " <= omega_min (not a Hopf point)");
  const internal::hopf_curve_layout L(n, true, opt, resolve_normalisation<M>(opt.normalisation));
  vec<double> x(L.N);
  x.head(n) = h0.point.w;
  L.set_p(x, h0.point.p);
  x[L.imu] = h0.point.mu;
  x[L.inu] = nu0;
  x[L.iom] = h0.point.omega;
  internal::hopf_curve_corrector<F> corr(family, L, opt);
  hopf_curve_result res;
  return internal::run_hopf_curve(corr, L, std::move(x), h0.report.iterations,
                                  std::chrono::duration<double>(clock::now() - t_start).count(), opt, direction, res,
                                  t_begin, hopf_curve_stepper_options(opt, L));
}
}  // namespace internal

/// Traces the Hopf curve of family(nu) through the Hopf point `start` of family(nu0) (a guess:
/// it is first converged by solve_hopf at fixed nu0), initially in the direction of increasing
/// (direction = +1) or decreasing (-1) nu. See the file comment.
template <system_family F>
hopf_curve_result trace_hopf_curve(const F& family, double nu0, const hopf_point& start,
                                   const hopf_curve_options& opt = {}, int direction = +1) {
  return internal::trace_hopf_curve_erased(family_function<family_system_t<F>>(std::cref(family)), nu0, start, opt,
                                           direction);
}

}  // namespace aerohopf
