#pragma once
// Continuation of equilibrium branches f(w, mu) = 0 (the indirect approach of spec 02), with
// fold and Hopf detection along the branch.
//
//  * natural_continuation: mu_k = mu_0 + k dmu, previous solution as the Newton guess. Fails
//    (says so) at a fold.
//  * pseudo_arclength_continuation: unknowns x = (w, mu); tangent t from
//        [A  f_mu] t = 0,   t_prev . t = 1   (then |t| = 1, oriented along t_prev),
//    predictor x + ds t, corrector Newton on [f(x); t.(x - x_pred)] = 0. The step ds adapts
//    (halved on corrector failure, grown after fast convergence), so folds (limit points) are
//    passed: the reactor branch has two folds and hysteresis.
//
// Test functions: fold where the mu-component of the tangent changes sign; Hopf where
// gamma = max Re(lambda) over the eigenvalues with Im(lambda) != 0 changes sign. The spectrum
// comes from a user-selectable `spectrum` callable (default: a dense eigen-decomposition,
// right for small systems; large systems pass cayley_rightmost from cayley.hpp). Located
// points: a fold by secant iteration on t_mu over the arclength step; a Hopf point by Newton on
// the augmented system (hopf.hpp) started by inverse power at the interpolated crossing.
//
// Failures. A corrector that does not converge (no convergence in corrector_iterations, a
// non-finite residual, a singular bordered Jacobian) is not a failure of the run: the step is
// halved, and the run stops normally ("step size below ds_min") once ds < ds_min; the result
// counts the failed correctors and keeps the last one's reason (step, ds, iteration, mu, ||f||,
// what failed). A failure that ends the run (natural continuation: the Newton solve of a step;
// both: the start equilibrium, a tangent, a spectrum, any exception from the system) is thrown
// with throw_on_failure (its own type kept: singular_matrix_error stays one) or else returned
// with failed = true; either way the message names the algorithm, the step and mu and carries
// the original error text, and the points computed so far are kept (points.back() is the last
// good one: continue from it). A Hopf point that cannot be located is dropped as spurious.
// Input checks (input_error, before anything is evaluated): the options (finite, in range) and
// a start of the system's size with finite entries.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <complex>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <vector>

#include "../error.hpp"
#include "../linalg/assemble.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "hopf.hpp"

namespace aerohopf {

/// All eigenvalues of a (small) Jacobian by a dense eigen-decomposition.
template <class Matrix>
std::vector<std::complex<double>> dense_spectrum(const Matrix& a) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(a), false);
  require(es.info() == Eigen::Success, "dense_spectrum: eigenvalue computation failed");
  const auto ev = es.eigenvalues();
  return std::vector<std::complex<double>>(ev.data(), ev.data() + ev.size());
}

struct branch_point {
  double mu = 0;
  vec<double> w;
  double tangent_mu = 0;                 ///< dmu/ds (sign change = fold)
  double gamma = NAN;                    ///< max Re over complex eigenvalues (sign change = Hopf)
  std::complex<double> critical{NAN, NAN};  ///< the eigenvalue giving gamma
  double max_real = NAN;                 ///< max Re over all eigenvalues (stability)
  int newton_iterations = 0;
};

enum class bifurcation_kind { fold, hopf };

struct detected_bifurcation {
  bifurcation_kind kind;
  double mu = 0;
  vec<double> w;
  double omega = 0;                   ///< Hopf only
  vec<std::complex<double>> p;        ///< Hopf only: critical eigenvector
  int after_point = 0;                ///< index of the branch point before the crossing
  int locate_iterations = 0;
};

struct continuation_options {
  double ds = 0.01;        ///< initial arclength step (or dmu for natural continuation)
  double ds_min = 1e-7;
  double ds_max = 0.1;
  int max_steps = 500;
  double mu_min = -1e300, mu_max = 1e300;  ///< stop when mu leaves this interval
  int corrector_iterations = 8;            ///< max Newton iterations per corrector
  double corrector_tolerance = 1e-10;      ///< on ||f||_2
  double w_scale = 1.0;  ///< arclength metric ds^2 = |dw|^2 / (n w_scale^2) + dmu^2 (balances w and mu)
  bool detect_folds = true;
  bool detect_hopf = true;
  bool locate = true;                      ///< locate detected points
  double imag_tolerance = 1e-8;            ///< |Im lambda| above this counts as complex
  std::function<std::vector<std::complex<double>>(const Eigen::SparseMatrix<double>&)> sparse_spectrum;
  hopf_options hopf;                       ///< for locating Hopf points
  bool verbose = false;
  std::ostream* log = &std::cout;
  bool throw_on_failure = true;  ///< false: a failure ending the run is returned (failed, stop_reason)
};

struct continuation_result {
  std::vector<branch_point> points;
  std::vector<detected_bifurcation> bifurcations;
  std::string stop_reason;
  bool failed = false;                  ///< the run ended by a failure (stop_reason says which)
  int corrector_failures = 0;           ///< pseudo-arclength correctors that failed (step halved)
  std::string last_corrector_failure;   ///< the reason of the last one
};

/// Throws input_error naming the option and its value unless o is finite and in range
/// (natural continuation: ds is the signed mu step, nonzero).
inline void check_continuation_options(const continuation_options& o, const char* who, bool natural) {
  if (natural) {
    require(std::isfinite(o.ds) && o.ds != 0, who, ": continuation_options::ds must be finite and nonzero (got ", o.ds,
            ")");
  } else {
    require(std::isfinite(o.ds) && o.ds > 0, who, ": continuation_options::ds must be finite and > 0 (got ", o.ds, ")");
    require(std::isfinite(o.ds_min) && o.ds_min > 0, who, ": continuation_options::ds_min must be finite and > 0 (got ",
            o.ds_min, ")");
    require(std::isfinite(o.ds_max) && o.ds_max >= o.ds_min, who,
            ": continuation_options::ds_max must be finite and >= ds_min (got ", o.ds_max, ")");
    require(std::isfinite(o.w_scale) && o.w_scale > 0, who, ": continuation_options::w_scale must be finite and > 0 (got ",
            o.w_scale, ")");
  }
  require(o.max_steps >= 0, who, ": continuation_options::max_steps must be >= 0 (got ", o.max_steps, ")");
  require(!std::isnan(o.mu_min) && !std::isnan(o.mu_max) && o.mu_min <= o.mu_max, who,
          ": continuation_options::mu_min <= mu_max required (got ", o.mu_min, ", ", o.mu_max, ")");
  require(o.corrector_iterations >= 1, who, ": continuation_options::corrector_iterations must be >= 1 (got ",
          o.corrector_iterations, ")");
  require(std::isfinite(o.corrector_tolerance) && o.corrector_tolerance > 0, who,
          ": continuation_options::corrector_tolerance must be finite and > 0 (got ", o.corrector_tolerance, ")");
  require(std::isfinite(o.imag_tolerance) && o.imag_tolerance >= 0, who,
          ": continuation_options::imag_tolerance must be finite and >= 0 (got ", o.imag_tolerance, ")");
}

namespace internal {
template <dynamical_system S>
void evaluate_spectrum(const S& sys, branch_point& bp, const continuation_options& opt) {
  std::vector<std::complex<double>> ev;
  const auto a = sys.jacobian(bp.w, bp.mu);
  if constexpr (is_sparse_matrix_v<jacobian_t<S>>) {
    ev = opt.sparse_spectrum ? opt.sparse_spectrum(a) : dense_spectrum(a);
  } else {
    ev = dense_spectrum(a);
  }
  bp.gamma = -1e300;
  bp.max_real = -1e300;
  for (const auto& l : ev) {
    bp.max_real = std::max(bp.max_real, l.real());
    if (std::abs(l.imag()) > opt.imag_tolerance && l.real() > bp.gamma) {
      bp.gamma = l.real();
      bp.critical = l;
    }
  }
  if (bp.gamma == -1e300) bp.gamma = NAN;  // no complex eigenvalue
}
}  // namespace internal

/// Natural-parameter continuation: mu_k = mu0 + k dmu (opt.ds), k = 1..opt.max_steps.
template <dynamical_system S>
continuation_result natural_continuation(const S& sys, const vec<double>& w0, double mu0,
                                         const continuation_options& opt = {}) {
  const char* who = "natural_continuation";
  check_continuation_options(opt, who, true);
  check_state(sys, w0, mu0, who);
  continuation_result res;
  newton_options no;
  no.abs_tolerance = opt.corrector_tolerance;
  no.max_iterations = opt.corrector_iterations;
  vec<double> w = w0;
  for (int k = 0; k <= opt.max_steps; ++k) {
    const double mu = mu0 + k * opt.ds;
    if (mu < opt.mu_min || mu > opt.mu_max) {
      res.stop_reason = "left the mu interval";
      break;
    }
    const std::string ctx = internal::concat(who, ": step ", k, " at mu = ", mu,
                                             res.points.empty() ? std::string()
                                                                : internal::concat(" (from mu = ", res.points.back().mu, ")"),
                                             " failed (a fold? use pseudo-arclength): ");
    branch_point bp;
    try {
      const newton_result nr = newton(sys, w, mu, no);
      bp.mu = mu;
      bp.w = nr.x;
      bp.tangent_mu = 1;
      bp.newton_iterations = nr.report.iterations;
      if (opt.detect_hopf) internal::evaluate_spectrum(sys, bp, opt);
    } catch (...) {
      res.failed = true;
      res.stop_reason = ctx + internal::current_exception_text();
      if (opt.throw_on_failure) internal::rethrow_with_context(ctx);
      return res;
    }
    w = bp.w;
    res.points.push_back(std::move(bp));
  }
  if (res.stop_reason.empty()) res.stop_reason = "step limit";
  return res;
}

/// Pseudo-arclength continuation from an equilibrium (w0, mu0) in the direction of increasing
/// mu (direction = +1) or decreasing mu (-1).
template <dynamical_system S>
continuation_result pseudo_arclength_continuation(const S& sys, const vec<double>& w0, double mu0,
                                                  const continuation_options& opt = {}, int direction = +1) {
  using M = jacobian_t<S>;
  const char* who = "pseudo_arclength_continuation";
  const Eigen::Index n = sys.size();
  check_continuation_options(opt, who, false);
  check_state(sys, w0, mu0, who);
  continuation_result res;
  // Runs body; an exception from it ends the run (file comment): rethrown with ctx in front,
  // or recorded in res (failed, stop_reason) and false returned.
  auto guarded = [&](const std::string& ctx, auto&& body) -> bool {
    try {
      body();
      return true;
    } catch (...) {
      res.failed = true;
      res.stop_reason = internal::concat(who, ": ", ctx, ": ", internal::current_exception_text());
      if (opt.verbose && opt.log) *opt.log << res.stop_reason << "\n";
      if (opt.throw_on_failure) internal::rethrow_with_context(internal::concat(who, ": ", ctx, ": "));
      return false;
    }
  };
  int step = 0;
  double ds = opt.ds;
  // Scaled variables: the w-part of the arclength is weighted by 1 / (sqrt(n) w_scale).
  const double ws = 1.0 / (std::sqrt(double(n)) * opt.w_scale);
  auto dot = [&](const vec<double>& a, const vec<double>& b) {
    return ws * ws * a.head(n).dot(b.head(n)) + a[n] * b[n];
  };
  direct_solver<M> lu("pseudo-arclength: bordered Jacobian");
  auto bordered = [&](const vec<double>& x, const vec<double>& t) {
    block_assembler<M> j(n + 1, n + 1);
    j.add(0, 0, sys.jacobian(x.head(n), x[n]));
    j.add_column(0, n, residual_d_mu(sys, x.head(n), x[n]));
    vec<double> row = t;
    row.head(n) *= ws * ws;
    j.add_row(n, 0, row);
    return j.build();
  };
  auto tangent = [&](const vec<double>& x, const vec<double>& t_prev) {
    lu.compute(bordered(x, t_prev));
    vec<double> rhs = vec<double>::Zero(n + 1);
    rhs[n] = 1;
    vec<double> t = lu.solve(rhs);
    return vec<double>(t / std::sqrt(dot(t, t)));
  };
  // Corrector from the predicted point xp on the hyperplane t.(x - xp) = 0; nullopt on failure
  // (counted, the reason kept in res.last_corrector_failure).
  auto correct = [&](const vec<double>& xp, const vec<double>& t, int& iterations) -> std::optional<vec<double>> {
    vec<double> x = xp;
    double fn = NAN;
    auto failed = [&](int it, const std::string& why) -> std::optional<vec<double>> {
      ++res.corrector_failures;
      res.last_corrector_failure = internal::concat(who, ": corrector of step ", step, " (ds = ", ds, ") at iteration ",
                                                    it, ", mu = ", x[n], ", ||f|| = ", fn, ": ", why);
      return std::nullopt;
    };
    for (int it = 1; it <= opt.corrector_iterations; ++it) {
      vec<double> f(n + 1);
      try {
        f.head(n) = sys.residual(vec<double>(x.head(n)), x[n]);
        f[n] = dot(t, x - xp);
        for (Eigen::Index i = 0; i < f.size(); ++i)
          if (!std::isfinite(f[i])) return failed(it, internal::concat("residual entry ", i, " is not finite"));
        fn = f.head(n).norm();
        lu.compute(bordered(x, t));
        x -= lu.solve(f);
        iterations = it;
        fn = vec<double>(sys.residual(vec<double>(x.head(n)), x[n])).norm();
      } catch (const error& e) {
        return failed(it, e.what());
      }
      if (!std::isfinite(fn)) return failed(it, "residual after the update is not finite");
      if (fn <= opt.corrector_tolerance) return x;
    }
    return failed(opt.corrector_iterations, "no convergence");
  };

  vec<double> x(n + 1);
  x.head(n) = w0;
  x[n] = mu0;
  vec<double> t;
  auto push = [&](const vec<double>& xx, const vec<double>& tt, int iters) {
    branch_point bp;
    bp.w = xx.head(n);
    bp.mu = xx[n];
    bp.tangent_mu = tt[n];
    bp.newton_iterations = iters;
    if (opt.detect_hopf) internal::evaluate_spectrum(sys, bp, opt);
    if (opt.verbose && opt.log)
      *opt.log << "continuation " << std::setw(4) << res.points.size() << "  mu " << std::setprecision(10)
               << bp.mu << "  dmu/ds " << std::setprecision(3) << bp.tangent_mu << "  gamma " << bp.gamma
               << "  newton " << iters << std::setprecision(6) << "\n";
    res.points.push_back(std::move(bp));
  };
  if (!guarded(internal::concat("start at mu = ", mu0), [&] {
        newton_options no;  // make sure the start is an equilibrium
        no.abs_tolerance = opt.corrector_tolerance;
        no.max_iterations = 2 * opt.corrector_iterations;
        x.head(n) = newton(sys, w0, mu0, no).x;
        vec<double> t0 = vec<double>::Zero(n + 1);
        t0[n] = direction >= 0 ? 1.0 : -1.0;
        t = tangent(x, t0);
        push(x, t, 0);
      }))
    return res;
  for (step = 1; step <= opt.max_steps; ++step) {
    int iters = 0;
    std::optional<vec<double>> xn;
    while (!(xn = correct(x + ds * t, t, iters))) {
      ds *= 0.5;
      if (ds < opt.ds_min) {
        res.stop_reason = internal::concat("step size below ds_min at mu = ", x[n], " (step ", step,
                                           "; last corrector failure: ", res.last_corrector_failure, ")");
        if (opt.verbose && opt.log) *opt.log << "continuation: " << res.stop_reason << "\n";
        return res;
      }
    }
    const vec<double> x_prev = x, t_prev = t;
    if (!guarded(internal::concat("step ", step, ": tangent or spectrum at mu = ", (*xn)[n], " (from mu = ", x_prev[n],
                                  ")"),
                 [&] {
                   const vec<double> tn = tangent(*xn, t);
                   push(*xn, tn, iters);
                   x = *xn;
                   t = tn;
                 }))
      return res;
    const int k = int(res.points.size()) - 2;  // index of the previous point
    const branch_point& a = res.points[k];
    const branch_point& b = res.points[k + 1];
    // ---- fold: sign change of dmu/ds; secant on t_mu over the step length from x_prev ----
    if (opt.detect_folds && a.tangent_mu * b.tangent_mu < 0) {
      detected_bifurcation fold{bifurcation_kind::fold, b.mu, b.w, 0, {}, k, 0};
      if (opt.locate) {
        double s0 = 0, f0 = a.tangent_mu, s1 = ds, f1 = b.tangent_mu;
        vec<double> best = x;
        for (int it = 1; it <= 30 && std::abs(f1) > 1e-10; ++it) {
          const double s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
          int ci = 0;
          auto xs = correct(x_prev + s2 * t_prev, t_prev, ci);
          if (!xs) break;
          vec<double> ts;
          try {
            ts = tangent(*xs, t_prev);
          } catch (const error&) {  // a singular bordered matrix: keep the best point so far
            break;
          }
          s0 = s1, f0 = f1, s1 = s2, f1 = ts[n];
          best = *xs;
          fold.locate_iterations = it;
        }
        fold.mu = best[n];
        fold.w = best.head(n);
      }
      if (opt.verbose && opt.log)
        *opt.log << "continuation: fold at mu = " << std::setprecision(12) << fold.mu << std::setprecision(6) << "\n";
      res.bifurcations.push_back(std::move(fold));
    }
    // ---- Hopf: sign change of gamma ----
    if (opt.detect_hopf && std::isfinite(a.gamma) && std::isfinite(b.gamma) && a.gamma * b.gamma < 0) {
      const double th = a.gamma / (a.gamma - b.gamma);
      detected_bifurcation hb{bifurcation_kind::hopf, (1 - th) * a.mu + th * b.mu,
                              (1 - th) * a.w + th * b.w,
                              std::abs((1 - th) * a.critical.imag() + th * b.critical.imag()), {}, k, 0};
      if (opt.locate) {
        // Equilibrium near the crossing (on the branch), then the augmented Newton iteration.
        int ci = 0;
        const double len = std::sqrt(dot(x - x_prev, x - x_prev));
        auto xs = correct(x_prev + th * len * t_prev, t_prev, ci);
        const vec<double> wg = xs ? vec<double>(xs->head(n)) : hb.w;
        const double mug = xs ? (*xs)[n] : hb.mu;
        try {
          hopf_point guess = hopf_start(sys, wg, mug, hb.omega);
          const hopf_result hr = solve_hopf(sys, guess, opt.hopf);
          if (!hr.report.converged) throw convergence_error(hr.report.reason);  // hopf.throw_on_failure = false
          hb.mu = hr.point.mu;
          hb.w = hr.point.w;
          hb.omega = hr.point.omega;
          hb.p = hr.point.p;
          hb.locate_iterations = hr.report.iterations;
        } catch (const error& e) {  // no convergence, a singular pivot: not located
          hb.mu = 1e300;  // not located: treated as spurious below
          if (opt.verbose && opt.log) *opt.log << "continuation: Hopf location failed: " << e.what() << "\n";
        }
      }
      // A jump of gamma between two different complex pairs (e.g. a pair born from two real
      // eigenvalues near a fold) is not a Hopf crossing: keep only points located inside the
      // bracket (with a margin of one step) that were not found already.
      const double lo = std::min(a.mu, b.mu) - std::abs(b.mu - a.mu), hi = std::max(a.mu, b.mu) + std::abs(b.mu - a.mu);
      bool spurious = opt.locate && (hb.mu < lo || hb.mu > hi);
      for (const auto& other : res.bifurcations)
        if (other.kind == bifurcation_kind::hopf && std::abs(other.mu - hb.mu) < 1e-8 * (1 + std::abs(hb.mu)))
          spurious = true;
      if (spurious) {
        if (opt.verbose && opt.log)
          *opt.log << "continuation: gamma changed sign between mu = " << a.mu << " and " << b.mu
                   << " without a new Hopf crossing there (discarded)\n";
      } else {
      if (opt.verbose && opt.log)
        *opt.log << "continuation: Hopf point at mu = " << std::setprecision(12) << hb.mu << ", omega = " << hb.omega
                 << std::setprecision(6) << "\n";
      res.bifurcations.push_back(std::move(hb));
      }
    }
    if (x[n] < opt.mu_min || x[n] > opt.mu_max) {
      res.stop_reason = "left the mu interval";
      return res;
    }
    if (iters <= 3) ds = std::min(opt.ds_max, 1.5 * ds);
  }
  res.stop_reason = "step limit";
  return res;
}

}  // namespace aerohopf
