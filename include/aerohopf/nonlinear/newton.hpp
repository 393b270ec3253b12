#pragma once
// The Newton family for F(x) = 0 (spec 02), all sharing one engine and one report:
//
//  * newton                 exact Jacobian every step; quadratic near a regular root
//  * newton_chord           Jacobian factored once at the first iterate; linear convergence
//  * pseudo_transient_newton  (I/dt - A) dx = F with dt ramped by switched evolution relaxation
//                           dt_k = dt_0 ||F_0|| / ||F_k|| (capped), recovering Newton as dt -> inf.
//                           This is how the CFD steady solver works; A may be an approximate
//                           (e.g. modified-order) Jacobian while F is the exact residual.
//  * broyden                rank-one updates A+ = A + (y - A s) s^T / (s.s) of a dense matrix.
//                           It destroys sparsity, and the final A is NOT the true Jacobian (never
//                           use it for eigenvalues).
//
// The engine (newton_iterate) works on any residual/Jacobian callables, so the equilibrium
// problem, the pseudo-arclength corrector and the augmented Hopf systems all use it.
//
// Convergence criterion (stated, checked, reported): ||F(x_k)||_2 <= abs_tolerance +
// rel_tolerance ||F(x_0)||_2, or, once the residual has reached its rounding floor (fine grids
// have ||A|| ~ 1/h^2, so ||F|| cannot drop below about eps ||A|| ||x||), a full Newton step
// with ||dx||_inf <= step_tolerance (1 + ||x||_inf). The report says which one held.
// Failure modes: non-finite residual or step, growth beyond divergence_factor ||F(x_0)||, the
// iteration limit, the contraction test below, and any exception raised inside an iteration
// (a singular LU, a BILU breakdown, a GMRES failure, a non-physical state refused by the
// model). With throw_on_failure = false every one of them is a result with converged = false;
// with throw_on_failure = true it is thrown. Either way the reason (report.reason, the thrown
// message) names `what`, the iterate k, ||F(x_k)||, the parameter values of the iterate when
// newton_options::describe gives them, and the original error text; an exception from inside
// an iteration is rethrown with its own type (singular_matrix_error stays one; a foreign
// std::exception becomes convergence_error, std::bad_alloc passes unchanged). The result's x is
// the last accepted iterate, whose residual is finite, so a run can continue from it. An
// exception from the observer passes unchanged.
// Input checks (input_error, before anything is evaluated): the options (finite, in range,
// check_newton_options) and a finite initial iterate.
// Under-relaxation: steps are scaled by `relaxation` until ||F|| has dropped below
// relax_until ||F_0||, then full steps
// (the start-up strategy reported for the augmented Hopf system); an optional backtracking
// line search halves a step that does not decrease ||F||.
// Contraction test (off by default): from iteration contraction_from on, an iteration whose
// residual ratio ||F(x_k)|| / ||F(x_{k-1})|| exceeds max_contraction fails at once ("not
// contracting"). Newton's residual ratio in the region of quadratic convergence is ~||F_k||,
// and a ratio near or above 1 after the first steps means the start is outside that region (a
// monotonicity test after Deuflhard). Callers with a fallback (continuation correctors that halve
// the step, a retry along another direction) use it so that a corrector that will not converge
// costs two or three iterations, not max_iterations.
#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <iostream>
#include <string>
#include <string_view>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "system.hpp"

namespace aerohopf {

struct newton_step_info {
  int iteration = 0;
  double residual = 0;      ///< ||F(x)||_2 after the step
  double step = 0;          ///< ||dx||_2 of the step taken
  double relaxation = 1;    ///< factor applied to the step
  const vec<double>* x = nullptr;
};

struct newton_options {
  double abs_tolerance = 1e-10;
  double rel_tolerance = 0.0;
  double step_tolerance = 1e-12;  ///< relative full-step size that also counts as converged
  int max_iterations = 50;
  double divergence_factor = 1e10;
  double relaxation = 1.0;     ///< initial step scaling psi in (0, 1]
  double relax_until = 0.5;    ///< use psi until ||F|| < relax_until ||F_0||, then full steps
  bool line_search = false;    ///< halve the step (up to 10 times) while ||F|| does not decrease
  /// Fail when ||F(x_k)|| > max_contraction ||F(x_{k-1})|| at an iteration k >= contraction_from
  /// (infinity: never). The first step of a continuation corrector may raise ||F|| (the
  /// predictor's residual is small but its error is not), hence contraction_from = 2.
  double max_contraction = std::numeric_limits<double>::infinity();
  int contraction_from = 2;
  bool throw_on_failure = true;
  std::function<void(const newton_step_info&)> observer;  ///< called after every step
  /// Names the parameter values of an iterate in failure messages (e.g. "mu = 0.16, omega = 2.1"
  /// read off an augmented Hopf iterate); empty: the message names none. The fixed-mu solvers
  /// below name mu in their label instead.
  std::function<std::string(const vec<double>&)> describe;
};

struct newton_report {
  bool converged = false;
  std::string reason;
  int iterations = 0;
  std::vector<double> residual_history;  ///< ||F||_2 at x_0, x_1, ...
  std::vector<double> step_history;
  double seconds = 0;
  /// On a failure: the iteration whose step failed (the step from iterate failed_iteration - 1;
  /// 0: at the initial iterate); -1 when converged.
  int failed_iteration = -1;
  double final_residual() const { return residual_history.empty() ? NAN : residual_history.back(); }
};

struct newton_result {
  vec<double> x;
  newton_report report;
};

/// Progress printer for newton_options::observer.
inline std::function<void(const newton_step_info&)> newton_progress(std::string label, std::ostream& os = std::cout) {
  return [label = std::move(label), &os](const newton_step_info& s) {
    os << label << " it " << std::setw(3) << s.iteration << "  |F| " << std::scientific << std::setprecision(3)
       << s.residual << "  |dx| " << s.step << std::defaultfloat << std::setprecision(6)
       << (s.relaxation < 1 ? "  relaxed " + std::to_string(s.relaxation) : std::string()) << "\n";
  };
}

namespace internal {
inline double norm_or_nan(const vec<double>& v) { return v.allFinite() ? v.norm() : NAN; }

}  // namespace internal

/// Throws input_error naming the option and its value unless every field of o is finite and
/// in range (infinity is allowed where it means "never": divergence_factor, max_contraction).
inline void check_newton_options(const newton_options& o, std::string_view where) {
  require(std::isfinite(o.abs_tolerance) && o.abs_tolerance >= 0, where,
          ": newton_options::abs_tolerance must be finite and >= 0 (got ", o.abs_tolerance, ")");
  require(std::isfinite(o.rel_tolerance) && o.rel_tolerance >= 0, where,
          ": newton_options::rel_tolerance must be finite and >= 0 (got ", o.rel_tolerance, ")");
  require(o.abs_tolerance > 0 || o.rel_tolerance > 0, where,
          ": newton_options::abs_tolerance and rel_tolerance are both 0 (no residual could be accepted)");
  require(std::isfinite(o.step_tolerance) && o.step_tolerance >= 0, where,
          ": newton_options::step_tolerance must be finite and >= 0 (got ", o.step_tolerance, ")");
  require(o.max_iterations >= 0, where, ": newton_options::max_iterations must be >= 0 (got ", o.max_iterations, ")");
  require(o.divergence_factor > 0, where, ": newton_options::divergence_factor must be > 0 (got ", o.divergence_factor,
          ")");
  require(std::isfinite(o.relaxation) && o.relaxation > 0 && o.relaxation <= 1, where,
          ": newton_options::relaxation must lie in (0, 1] (got ", o.relaxation, ")");
  require(std::isfinite(o.relax_until) && o.relax_until >= 0 && o.relax_until <= 1, where,
          ": newton_options::relax_until must lie in [0, 1] (got ", o.relax_until, ")");
  require(o.max_contraction > 0, where, ": newton_options::max_contraction must be > 0 (got ", o.max_contraction, ")");
  require(o.contraction_from >= 1, where, ": newton_options::contraction_from must be >= 1 (got ", o.contraction_from,
          ")");
}

/// Generic Newton-type iteration. `residual(x)` returns F(x); `solve_step(x, F, k)` returns the
/// correction dx with (approximately) J(x) dx = -F. `what` names the problem in messages.
template <class ResidualFn, class StepFn>
newton_result newton_iterate(ResidualFn&& residual, StepFn&& solve_step, vec<double> x, const newton_options& opt,
                             const std::string& what) {
  check_newton_options(opt, what);
  require_finite(x, what, "initial iterate");
  const auto t0 = std::chrono::steady_clock::now();
  newton_result res;
  auto& rep = res.report;
  // "iterate k (||F|| = .., mu = ..)" of the current (last accepted) iterate x
  auto at = [&](int k, double fk) {
    std::string s = internal::concat("iterate ", k, " (||F|| = ", fk);
    if (opt.describe) {
      try {
        s += ", " + opt.describe(x);
      } catch (...) {  // a message must not fail: leave the parameters out
      }
    }
    return s + ")";
  };
  auto fail = [&](int k, const std::string& why) {
    rep.converged = false;
    rep.failed_iteration = k;
    rep.reason = what + ": " + why;
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (opt.throw_on_failure) throw convergence_error(rep.reason);
    res.x = x;
    return res;
  };
  // An exception raised inside iteration k (its step from iterate k - 1, or the residual at
  // the initial iterate for k = 0): a failed result, or rethrown with the same context.
  auto step_error = [&](int k, double fk) {
    const std::string ctx =
        k == 0 ? std::string("residual at the initial iterate failed: ")
               : internal::concat("step ", k, " from ", at(k - 1, fk), " failed: ");
    rep.converged = false;
    rep.failed_iteration = k;
    rep.reason = what + ": " + ctx + internal::current_exception_text();
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (opt.throw_on_failure) internal::rethrow_with_context(what + ": " + ctx);
    res.x = x;
    return res;
  };
  vec<double> f;
  try {
    f = residual(x);
  } catch (...) {
    return step_error(0, NAN);
  }
  if (f.size() != x.size())
    throw input_error(internal::concat(what, ": residual has ", f.size(), " entries, iterate ", x.size()));
  double fn = internal::norm_or_nan(f);
  if (!std::isfinite(fn)) return fail(0, "residual at the initial iterate is not finite");
  rep.residual_history.push_back(fn);
  const double f0 = fn;
  const double target = opt.abs_tolerance + opt.rel_tolerance * f0;
  bool relaxing = opt.relaxation < 1.0;
  for (int k = 1;; ++k) {
    if (fn <= target) {
      rep.converged = true;
      rep.reason = internal::concat("||F|| = ", fn, " <= ", target, " after ", rep.iterations, " iterations");
      break;
    }
    if (k > opt.max_iterations)
      return fail(k, internal::concat("no convergence in ", opt.max_iterations, " iterations: ", at(k - 1, fn),
                                      ", target ", target));
    vec<double> dx, xn, fnew;
    double dxn = NAN, psi = relaxing ? opt.relaxation : 1.0, fnn = NAN;
    std::string refused;  // the model's refusal of the last trial point, if any
    try {
      dx = solve_step(x, f, k);
      dxn = internal::norm_or_nan(dx);
      if (dx.size() == x.size() && std::isfinite(dxn)) {
        // With the line search, a trial point the model refuses (input_error: e.g. negative
        // density or pressure) is a step too long, halved like one with a non-finite residual;
        // the model's words are kept for the failure message.
        auto trial = [&] {
          xn = x + psi * dx;
          if (!opt.line_search) {
            fnew = residual(xn);
          } else {
            try {
              fnew = residual(xn);
            } catch (const input_error& e) {
              refused = e.what();
              fnew.resize(0);
            }
          }
          if (fnew.size() == 0) {
            fnn = NAN;
            return;
          }
          if (fnew.size() != x.size())
            throw input_error(internal::concat(what, ": residual at the trial point of step ", k, " has ", fnew.size(),
                                               " entries, the iterate ", x.size()));
          fnn = internal::norm_or_nan(fnew);
        };
        trial();
        if (opt.line_search) {
          for (int h = 0; h < 10 && !(fnn < fn); ++h) {
            psi *= 0.5;
            trial();
          }
        }
      }
    } catch (...) {
      return step_error(k, fn);
    }
    if (dx.size() != x.size())
      throw input_error(internal::concat(what, ": step ", k, " has ", dx.size(), " entries, iterate ", x.size()));
    if (!std::isfinite(dxn))
      return fail(k, internal::concat("Newton step ", k, " from ", at(k - 1, fn), " is not finite"));
    if (!std::isfinite(fnn))
      return fail(k, internal::concat("residual not finite at iterate ", k, " (the step from ", at(k - 1, fn),
                                      ", ||dx|| = ", psi * dxn, opt.line_search ? ", after the line search" : "",
                                      ")", refused.empty() ? "" : "; last trial point refused: ", refused));
    x = std::move(xn);
    f = std::move(fnew);
    fn = fnn;
    rep.iterations = k;
    rep.residual_history.push_back(fn);
    rep.step_history.push_back(psi * dxn);
    if (psi == 1.0 && dx.template lpNorm<Eigen::Infinity>() <= opt.step_tolerance * (1.0 + x.template lpNorm<Eigen::Infinity>()) &&
        fn <= 1e6 * target) {
      rep.converged = true;
      rep.reason = internal::concat("step ||dx|| = ", psi * dxn, " at the rounding floor (||F|| = ", fn, ") after ",
                                    rep.iterations, " iterations");
      if (opt.observer) opt.observer({k, fn, psi * dxn, psi, &x});
      break;
    }
    if (relaxing && fn < opt.relax_until * f0) relaxing = false;
    if (opt.observer) opt.observer({k, fn, psi * dxn, psi, &x});
    if (fn > opt.divergence_factor * std::max(f0, 1e-300))
      return fail(k, internal::concat("diverged at ", at(k, fn), " from ||F_0|| = ", f0));
    const double fprev = rep.residual_history[rep.residual_history.size() - 2];
    if (k >= opt.contraction_from && fn > target && fn > opt.max_contraction * fprev)
      return fail(k, internal::concat("not contracting at iterate ", k, ": ||F|| = ", fn, " from ", fprev, " (ratio ",
                                      fn / fprev, " > max_contraction ", opt.max_contraction, ")",
                                      opt.describe ? " at " + at(k, fn) : std::string()));
  }
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  res.x = std::move(x);
  return res;
}

namespace internal {
/// Label of the fixed-mu solvers: "<name> (equilibrium, mu = <mu>)".
inline std::string equilibrium_label(const char* name, double mu) {
  return internal::concat(name, " (equilibrium, mu = ", mu, ")");
}
}  // namespace internal

/// Newton with the exact Jacobian of the system at fixed mu.
template <dynamical_system S>
newton_result newton(const S& s, const vec<double>& w0, double mu, const newton_options& opt = {}) {
  check_state(s, w0, mu, "newton");
  direct_solver<jacobian_t<S>> lu("newton: Jacobian");
  return newton_iterate([&](const vec<double>& w) { return vec<double>(s.residual(w, mu)); },
                        [&](const vec<double>& w, const vec<double>& f, int) {
                          lu.compute(s.jacobian(w, mu));
                          return vec<double>(-lu.solve(f));
                        },
                        w0, opt, internal::equilibrium_label("newton", mu));
}

/// Newton chord: the Jacobian at w0 is factored once (in the first step, so that its failure
/// is reported like any other step's).
template <dynamical_system S>
newton_result newton_chord(const S& s, const vec<double>& w0, double mu, const newton_options& opt = {}) {
  check_state(s, w0, mu, "newton_chord");
  direct_solver<jacobian_t<S>> lu("newton_chord: Jacobian");
  return newton_iterate([&](const vec<double>& w) { return vec<double>(s.residual(w, mu)); },
                        [&](const vec<double>& w, const vec<double>& f, int k) {
                          if (k == 1) lu.compute(lhs_jacobian(s, w, mu));
                          return vec<double>(-lu.solve(f));
                        },
                        w0, opt, internal::equilibrium_label("newton chord", mu));
}

struct pseudo_transient_options {
  double dt0 = 1e-1;     ///< initial pseudo time step
  double dt_max = 1e12;  ///< cap; dt -> inf recovers Newton
  double ser_exponent = 1.0;  ///< dt_k = dt0 (||F_0|| / ||F_k||)^exponent
};

/// Pseudo-transient (relaxed) Newton: (I/dt - A) dw = f with the left-hand-side Jacobian (the
/// approximate one if the system provides it) and switched evolution relaxation of dt.
template <dynamical_system S>
newton_result pseudo_transient_newton(const S& s, const vec<double>& w0, double mu, const newton_options& opt = {},
                                      const pseudo_transient_options& pto = {}) {
  const char* who = "pseudo_transient_newton";
  check_state(s, w0, mu, who);
  require(std::isfinite(pto.dt0) && pto.dt0 > 0, who, ": pseudo_transient_options::dt0 must be finite and > 0 (got ",
          pto.dt0, ")");
  require(pto.dt_max >= pto.dt0, who, ": pseudo_transient_options::dt_max must be >= dt0 (got ", pto.dt_max, ")");
  require(std::isfinite(pto.ser_exponent) && pto.ser_exponent >= 0, who,
          ": pseudo_transient_options::ser_exponent must be finite and >= 0 (got ", pto.ser_exponent, ")");
  direct_solver<jacobian_t<S>> lu("pseudo-transient Newton: I/dt - A");
  double f0 = -1;
  return newton_iterate([&](const vec<double>& w) { return vec<double>(s.residual(w, mu)); },
                        [&](const vec<double>& w, const vec<double>& f, int) {
                          const double fn = f.norm();
                          if (f0 < 0) f0 = fn;
                          const double dt = std::min(pto.dt_max, pto.dt0 * std::pow(f0 / fn, pto.ser_exponent));
                          jacobian_t<S> m = lhs_jacobian(s, w, mu);
                          jacobian_t<S> lhs = identity_like<double>(m) * (1.0 / dt) - m;
                          lu.compute(lhs);
                          return vec<double>(lu.solve(f));
                        },
                        w0, opt, internal::equilibrium_label("pseudo-transient newton", mu));
}

/// Broyden's good method on a dense approximation started from the left-hand-side Jacobian at w0
/// (formed in the first step, so that its failure is reported like any other step's).
template <dynamical_system S>
newton_result broyden(const S& s, const vec<double>& w0, double mu, const newton_options& opt = {}) {
  check_state(s, w0, mu, "broyden");
  Eigen::MatrixXd a;
  vec<double> w_prev, f_prev;
  direct_solver<Eigen::MatrixXd> lu("broyden: Jacobian approximation");
  return newton_iterate([&](const vec<double>& w) { return vec<double>(s.residual(w, mu)); },
                        [&](const vec<double>& w, const vec<double>& f, int k) {
                          if (k == 1) {
                            a = Eigen::MatrixXd(lhs_jacobian(s, w, mu));
                          } else {
                            const vec<double> sv = w - w_prev, y = f - f_prev;
                            const double ss = sv.squaredNorm();
                            if (ss > 0) a += (y - a * sv) * sv.transpose() / ss;
                          }
                          w_prev = w;
                          f_prev = f;
                          lu.compute(a);
                          return vec<double>(-lu.solve(f));
                        },
                        w0, opt, internal::equilibrium_label("broyden", mu));
}

}  // namespace aerohopf
