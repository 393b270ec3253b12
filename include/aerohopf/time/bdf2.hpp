#pragma once
// Implicit second-order backward differences (BDF2) for dw/dt = f(w, mu) at fixed mu: the
// time-marching reference of the original work (verification runs of LCOs and of the
// damping below the flutter point).
//
// Each physical step solves the unsteady residual
//     R(w) = (3 w - 4 w^n + w^{n-1}) / (2 dt) - f(w, mu) = 0     (BDF2)
//     R(w) = (w - w^n) / dt - f(w, mu) = 0                        (first step: BDF1)
// by inner Newton iterations on the exact Jacobian, (c I - A(w)) dw = -R(w) with c = 3/(2 dt)
// (or 1/dt), through direct_solver of the system's jacobian_type, so dense and sparse systems
// work unchanged. BDF2 is A-stable, so dt is set by accuracy, not by the stiff modes.
//
// Dual (pseudo) time: with pseudo_dt > 0 each inner iteration is a pseudo-time step
//     (1/pseudo_dt + c) I - A) dw = -R(w),
// which is how CFD codes drive the unsteady residual to zero (robust far from the solution,
// linear instead of quadratic inner convergence). pseudo_dt = 0 is plain Newton.
//
// Inner convergence: ||dw||_inf <= inner_tolerance * (1 + ||w||_inf) (in dual time also
// ||R||_inf / c below the same bound), or, with inner_residual_drop > 0, ||R||_inf dropped by
// that factor from its value at the first inner iterate of the step (the CFD practice: "three
// orders per real step").
//
// Failures: if neither is reached in max_inner_iterations, or the unsteady residual or the
// iterate becomes non-finite, time_march_error<vec<double>> (a convergence_error) names
// integrate_bdf2, the time step, its time, mu, the inner iteration, ||R||_inf, the last
// ||dw||_inf and what was non-finite, and carries the last good state and the level before it:
// resume_bdf2 continues from them with BDF2 steps exactly as the uninterrupted run. An
// exception inside an inner iteration (a singular inner matrix, a model error) is rethrown with
// its own type and the same context in front of its message (the observer has seen the last
// good state). Input checks (input_error): the options, times, a finite state of the system's
// size (the first bad entry named), finite mu.
//
// CFD-sized systems: the inner matrix may be the system's approximate (modified-order)
// Jacobian (approximate_jacobian) and may be formed and factored once per physical step
// (freeze_matrix: a chord / dual-time iteration); the linear solver is a template argument with
// the compute/solve interface (direct_solver by default, krylov_solver for BILU + GMRES).
#include <Eigen/Core>

#include <cmath>
#include <string>
#include <utility>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../nonlinear/system.hpp"
#include "history.hpp"

namespace aerohopf {

struct bdf2_options {
  double dt = 0.01;
  double inner_tolerance = 1e-10;  ///< on ||dw||_inf / (1 + ||w||_inf)
  int max_inner_iterations = 20;
  double pseudo_dt = 0;            ///< > 0: dual-time inner iterations with this pseudo step
  double inner_residual_drop = 0;  ///< > 0: also converged once ||R||_inf <= this x its first value
  bool approximate_jacobian = false;  ///< inner matrix from lhs_jacobian (e.g. modified order)
  bool freeze_matrix = false;      ///< form and factor the inner matrix once per physical step
};

/// The CFD practice for verification runs (dual time in the wide sense): the modified-order
/// matrix (approximate_jacobian) formed and factored once per physical step, the unsteady
/// residual dropped by three orders per step, at most 40 inner iterations.
inline bdf2_options cfd_bdf2_options(double dt) {
  bdf2_options b;
  b.dt = dt;
  b.inner_residual_drop = 1e-3;
  b.approximate_jacobian = true;
  b.freeze_matrix = true;
  b.max_inner_iterations = 40;
  return b;
}

/// What the observer sees after each physical step.
struct bdf2_step_info {
  long step = 0;                ///< 0 = initial state
  double t = 0;
  int inner_iterations = 0;
  double inner_residual = 0;    ///< ||R(w)||_inf at the accepted iterate (before the last update)
};

namespace internal {
/// The BDF2 march of integrate_bdf2 and resume_bdf2: from w at t0, with w_prev the level at
/// t0 - h when `resume` (first step BDF2), else w_prev unused (first step BDF1).
template <dynamical_system S, class Observer, class Solver>
vec<double> bdf2_march(const S& s, double mu, vec<double> w_prev, vec<double> w, bool resume, double t0, double t_end,
                       const bdf2_options& opt, Observer&& observer, Solver& solver, const char* who) {
  check_state(s, w, mu, who);
  if (resume) {
    require_size(w_prev.size(), s.size(), who, "previous state");
    require_finite(w_prev, who, "previous state");
  }
  const long steps = internal::step_count(t0, t_end, opt.dt, who);
  require(std::isfinite(opt.inner_tolerance) && opt.inner_tolerance > 0, who,
          ": inner_tolerance must be positive (got ", opt.inner_tolerance, ")");
  require(opt.max_inner_iterations >= 1, who, ": max_inner_iterations must be >= 1 (got ", opt.max_inner_iterations, ")");
  require(std::isfinite(opt.pseudo_dt) && opt.pseudo_dt >= 0, who, ": pseudo_dt must be >= 0 (got ", opt.pseudo_dt, ")");
  require(std::isfinite(opt.inner_residual_drop) && opt.inner_residual_drop >= 0 && opt.inner_residual_drop < 1, who,
          ": inner_residual_drop must be in [0, 1) (got ", opt.inner_residual_drop, ")");
  const double h = steps > 0 ? (t_end - t0) / double(steps) : 0.0;

  using matrix = jacobian_t<S>;
  if (!resume) w_prev = vec<double>();
  bdf2_step_info info;
  info.t = t0;
  observer(static_cast<const bdf2_step_info&>(info), static_cast<const vec<double>&>(w));

  for (long n = 1; n <= steps; ++n) {
    const bool first = n == 1 && !resume;
    const double c = first ? 1.0 / h : 1.5 / h;
    const double shift = c + (opt.pseudo_dt > 0 ? 1.0 / opt.pseudo_dt : 0.0);
    const double tn = t0 + double(n) * h;
    // History part of the unsteady residual: R(x) = c x - hist - f(x).
    const vec<double> hist = first ? vec<double>(w / h) : vec<double>((4.0 * w - w_prev) / (2.0 * h));
    vec<double> x = first ? w : vec<double>(2.0 * w - w_prev);  // linear extrapolation as guess
    bool converged = false;
    double rnorm = NAN, dnorm = NAN, r0 = 0;
    int it = 0;
    std::string bad;  // what became non-finite
    try {
      while (it < opt.max_inner_iterations) {
        const vec<double> r = c * x - hist - s.residual(x, mu);
        for (Eigen::Index i = 0; i < r.size() && bad.empty(); ++i)
          if (!std::isfinite(r[i])) bad = internal::concat("unsteady residual entry ", i, " is not finite");
        if (!bad.empty()) break;
        rnorm = r.template lpNorm<Eigen::Infinity>();
        if (it == 0) r0 = rnorm;
        if (it > 0 && opt.inner_residual_drop > 0 && rnorm <= opt.inner_residual_drop * r0) {
          converged = true;
          break;
        }
        ++it;
        if (it == 1 || !opt.freeze_matrix) {
          const matrix a = opt.approximate_jacobian ? lhs_jacobian(s, x, mu) : matrix(s.jacobian(x, mu));
          const matrix lhs = matrix(identity_like<double>(a) * shift) - a;
          solver.compute(lhs);
        }
        const vec<double> dx = solver.solve(vec<double>(-r));
        x += dx;
        dnorm = dx.template lpNorm<Eigen::Infinity>();
        if (!std::isfinite(dnorm)) {
          bad = "inner correction dw is not finite";
          break;
        }
        const double scale = opt.inner_tolerance * (1.0 + x.template lpNorm<Eigen::Infinity>());
        // In dual time a small pseudo step makes dw small long before R is: also require the
        // plain implicit correction R / c to be small.
        if (dnorm <= scale && (opt.pseudo_dt == 0 || rnorm / c <= scale)) {
          converged = true;
          break;
        }
      }
    } catch (...) {
      internal::rethrow_with_context(internal::concat(who, ": time step ", n, " (t = ", tn, ", mu = ", mu, "), inner ",
                                                      opt.pseudo_dt > 0 ? "dual-time" : "Newton", " iteration ",
                                                      it, " (||R||_inf = ", rnorm, ") failed: "));
    }
    if (!converged || !x.allFinite())
      throw time_march_error<vec<double>>(
          internal::concat(who, ": inner ", opt.pseudo_dt > 0 ? "dual-time" : "Newton", " iteration failed at time step ",
                           n, " (t = ", tn, ", mu = ", mu, ") after ", it, " iterations: ",
                           bad.empty() ? std::string("no convergence") : bad, "; ||R||_inf = ", rnorm,
                           ", last ||dw||_inf = ", dnorm, "; the last good state is that of step ", n - 1, " at t = ",
                           tn - h),
          n - 1, tn - h, h, w, w_prev);
    w_prev = std::move(w);
    w = std::move(x);
    info.step = n;
    info.t = tn;
    info.inner_iterations = it;
    info.inner_residual = rnorm;
    observer(static_cast<const bdf2_step_info&>(info), static_cast<const vec<double>&>(w));
  }
  return w;
}
}  // namespace internal

/// Integrates from w0 at t0 to t_end; calls observer(const bdf2_step_info&, const vec<double>& w)
/// at the start and after every step; returns w(t_end). solver: compute(matrix)/solve(vector)
/// for the inner matrix (c + 1/pseudo_dt) I - A. Failures: file comment.
template <dynamical_system S, class Observer, class Solver>
vec<double> integrate_bdf2(const S& s, double mu, vec<double> w0, double t0, double t_end, const bdf2_options& opt,
                           Observer&& observer, Solver& solver) {
  return internal::bdf2_march(s, mu, vec<double>(), std::move(w0), false, t0, t_end, opt,
                              std::forward<Observer>(observer), solver, "integrate_bdf2");
}

/// Continues a BDF2 run from two consecutive levels, w at t0 and w_prev at t0 - h (e.g. state
/// and previous of a time_march_error), with BDF2 from the first step. h is the step this call
/// takes, (t_end - t0) / steps with steps from opt.dt as in integrate_bdf2: pass the interrupted
/// run's step (time_march_error::dt) as opt.dt to go on exactly as it would have.
template <dynamical_system S, class Observer, class Solver>
vec<double> resume_bdf2(const S& s, double mu, vec<double> w_prev, vec<double> w, double t0, double t_end,
                        const bdf2_options& opt, Observer&& observer, Solver& solver) {
  return internal::bdf2_march(s, mu, std::move(w_prev), std::move(w), true, t0, t_end, opt,
                              std::forward<Observer>(observer), solver, "resume_bdf2");
}

template <dynamical_system S, class Observer>
vec<double> resume_bdf2(const S& s, double mu, vec<double> w_prev, vec<double> w, double t0, double t_end,
                        const bdf2_options& opt, Observer&& observer) {
  direct_solver<jacobian_t<S>> solver("resume_bdf2: inner Newton matrix");
  return resume_bdf2(s, mu, std::move(w_prev), std::move(w), t0, t_end, opt, std::forward<Observer>(observer), solver);
}

template <dynamical_system S>
vec<double> resume_bdf2(const S& s, double mu, vec<double> w_prev, vec<double> w, double t0, double t_end,
                        const bdf2_options& opt) {
  return resume_bdf2(s, mu, std::move(w_prev), std::move(w), t0, t_end, opt,
                     [](const bdf2_step_info&, const vec<double>&) {});
}

/// Same with the direct solver of the system's matrix type.
template <dynamical_system S, class Observer>
vec<double> integrate_bdf2(const S& s, double mu, vec<double> w0, double t0, double t_end, const bdf2_options& opt,
                           Observer&& observer) {
  direct_solver<jacobian_t<S>> solver("integrate_bdf2: inner Newton matrix");
  return integrate_bdf2(s, mu, std::move(w0), t0, t_end, opt, std::forward<Observer>(observer), solver);
}

template <dynamical_system S>
vec<double> integrate_bdf2(const S& s, double mu, vec<double> w0, double t0, double t_end, const bdf2_options& opt) {
  return integrate_bdf2(s, mu, std::move(w0), t0, t_end, opt, [](const bdf2_step_info&, const vec<double>&) {});
}

/// BDF2 run storing every store_every-th step (and always the first and the last).
template <dynamical_system S>
time_history<vec<double>> bdf2_history(const S& s, double mu, vec<double> w0, double t0, double t_end,
                                       const bdf2_options& opt, long store_every = 1) {
  require(store_every >= 1, "bdf2_history: store_every must be >= 1 (got ", store_every, ")");
  const long steps = internal::step_count(t0, t_end, opt.dt, "bdf2_history");
  time_history<vec<double>> hist;
  integrate_bdf2(s, mu, std::move(w0), t0, t_end, opt, [&](const bdf2_step_info& info, const vec<double>& w) {
    if (info.step % store_every == 0 || info.step == steps) {
      hist.t.push_back(info.t);
      hist.y.push_back(w);
    }
  });
  return hist;
}

}  // namespace aerohopf
