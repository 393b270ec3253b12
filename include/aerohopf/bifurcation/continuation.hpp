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
#include "curve_stepper.hpp"
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

namespace internal {
/// The stepper options shared by both equilibrium continuations.
inline curve_stepper_options continuation_stepper_options(const continuation_options& o, Eigen::Index n,
                                                          const char* who) {
  curve_stepper_options so;
  so.max_points = o.max_steps + 1;  // the start and max_steps steps
  so.limits.push_back({n, o.mu_min, o.mu_max});
  so.label = who;
  so.verbose = o.verbose;
  so.log = o.log;
  return so;
}
}  // namespace internal

/// Natural-parameter continuation: mu_k = mu0 + k dmu (opt.ds), k = 1..opt.max_steps: the curve
/// stepper's natural predictor with Newton at fixed mu as the corrector.
template <dynamical_system S>
continuation_result natural_continuation(const S& sys, const vec<double>& w0, double mu0,
                                         const continuation_options& opt = {}) {
  const char* who = "natural_continuation";
  const Eigen::Index n = sys.size();
  check_continuation_options(opt, who, true);
  check_state(sys, w0, mu0, who);
  continuation_result res;
  newton_options no;
  no.abs_tolerance = opt.corrector_tolerance;
  no.max_iterations = opt.corrector_iterations;
  // point k (its Newton solve and spectrum) fails with this context
  auto context = [&] {
    const std::size_t k = res.points.size();
    return internal::concat(who, ": step ", k, " at mu = ", mu0 + double(k) * opt.ds,
                            res.points.empty() ? std::string()
                                               : internal::concat(" (from mu = ", res.points.back().mu, ")"),
                            " failed (a fold? use pseudo-arclength): ");
  };
  auto solve = [&](const vec<double>& w, double mu) {
    curve_corrected c;
    const newton_result nr = newton(sys, w, mu, no);
    c.x.resize(n + 1);
    c.x.head(n) = nr.x;
    c.x[n] = mu;
    c.iterations = nr.report.iterations;
    return c;
  };
  int start_iterations = 0;
  curve_problem prob{
      [&](const curve_request& q, std::string&) -> std::optional<curve_corrected> {
        return solve(q.x0.head(n), q.value);  // a failure throws: it ends the run
      },
      nullptr,
      [&](const vec<double>& x, const curve_point_info& info) {
        branch_point bp;
        bp.mu = x[n];
        bp.w = x.head(n);
        bp.tangent_mu = 1;
        bp.newton_iterations = info.start ? start_iterations : info.iterations;
        if (opt.detect_hopf) internal::evaluate_spectrum(sys, bp, opt);
        res.points.push_back(std::move(bp));
        return false;
      }};
  try {
    if (mu0 < opt.mu_min || mu0 > opt.mu_max) {
      res.stop_reason = "left the mu interval";
      return res;
    }
    const curve_corrected start = solve(w0, mu0);
    start_iterations = start.iterations;
    curve_stepper_options so = internal::continuation_stepper_options(opt, n, who);
    so.predictor = curve_predictor::natural;
    so.natural_index = n;
    so.natural_direction = opt.ds > 0 ? 1 : -1;
    so.step = std::abs(opt.ds);
    const curve_outcome oc = trace_curve(prob, start.x, vec<double>(), curve_metric(vec<double>::Ones(n + 1)), so);
    res.stop_reason = oc.stop == curve_stop::limit ? "left the mu interval" : "step limit";
  } catch (...) {
    res.failed = true;
    res.stop_reason = context() + internal::current_exception_text();
    if (opt.throw_on_failure) internal::rethrow_with_context(context());
  }
  return res;
}
/// Pseudo-arclength continuation from an equilibrium (w0, mu0) in the direction of increasing
/// mu (direction = +1) or decreasing mu (-1): the curve stepper's tangent predictor with the
/// bordered Newton corrector of the file comment; folds and Hopf points are detected and
/// located on every accepted step.
template <dynamical_system S>
continuation_result pseudo_arclength_continuation(const S& sys, const vec<double>& w0, double mu0,
                                                  const continuation_options& opt = {}, int direction = +1) {
  using M = jacobian_t<S>;
  const char* who = "pseudo_arclength_continuation";
  const Eigen::Index n = sys.size();
  check_continuation_options(opt, who, false);
  check_state(sys, w0, mu0, who);
  continuation_result res;
  // Scaled variables: the w-part of the arclength is weighted by 1 / (sqrt(n) w_scale).
  const double ws = 1.0 / (std::sqrt(double(n)) * opt.w_scale);
  vec<double> weight = vec<double>::Constant(n + 1, ws * ws);
  weight[n] = 1;
  const curve_metric metric(std::move(weight));
  direct_solver<M> lu("pseudo-arclength: bordered Jacobian");
  // [A f_mu; c^T] at x
  auto bordered = [&](const vec<double>& x, const vec<double>& c) {
    block_assembler<M> j(n + 1, n + 1);
    j.add(0, 0, sys.jacobian(x.head(n), x[n]));
    j.add_column(0, n, residual_d_mu(sys, x.head(n), x[n]));
    j.add_row(n, 0, c);
    return j.build();
  };
  // J t = e_last with the last row c (not normalised)
  auto raw_tangent = [&](const vec<double>& x, const vec<double>& c) {
    lu.compute(bordered(x, c));
    vec<double> rhs = vec<double>::Zero(n + 1);
    rhs[n] = 1;
    return vec<double>(lu.solve(rhs));
  };
  int step = 0;  // the step being corrected (for the failure reasons)
  double ds = opt.ds;
  // Newton on [f(x); c.x - value] = 0 from x0; nullopt on failure (counted, the reason kept in
  // res.last_corrector_failure).
  auto correct = [&](const vec<double>& x0, const vec<double>& c, double value) -> std::optional<curve_corrected> {
    vec<double> x = x0;
    double fn = NAN;
    auto failed = [&](int it, const std::string& why) -> std::optional<curve_corrected> {
      ++res.corrector_failures;
      res.last_corrector_failure = internal::concat(who, ": corrector of step ", step, " (ds = ", ds, ") at iteration ",
                                                    it, ", mu = ", x[n], ", ||f|| = ", fn, ": ", why);
      return std::nullopt;
    };
    for (int it = 1; it <= opt.corrector_iterations; ++it) {
      vec<double> f(n + 1);
      try {
        f.head(n) = sys.residual(vec<double>(x.head(n)), x[n]);
        f[n] = c.dot(x) - value;
        for (Eigen::Index i = 0; i < f.size(); ++i)
          if (!std::isfinite(f[i])) return failed(it, internal::concat("residual entry ", i, " is not finite"));
        fn = f.head(n).norm();
        lu.compute(bordered(x, c));
        x -= lu.solve(f);
        fn = vec<double>(sys.residual(vec<double>(x.head(n)), x[n])).norm();
      } catch (const error& e) {
        return failed(it, e.what());
      }
      if (!std::isfinite(fn)) return failed(it, "residual after the update is not finite");
      if (fn <= opt.corrector_tolerance) return curve_corrected{x, it};
    }
    return failed(opt.corrector_iterations, "no convergence");
  };
  // on the hyperplane through xp orthogonal to t (in the metric)
  auto correct_along = [&](const vec<double>& xp, const vec<double>& t) {
    const vec<double> c = metric.row(t);
    return correct(xp, c, c.dot(xp));
  };
  std::string context;  // what a failure ending the run was doing

  // Fold where dmu/ds changes sign: secant iteration on t_mu over the arclength from the
  // previous point along its tangent.
  auto locate_fold = [&](const vec<double>& x_prev, const vec<double>& t_prev, const vec<double>& x, double s1, int k) {
    const branch_point& a = res.points[k];
    const branch_point& b = res.points[k + 1];
    detected_bifurcation fold{bifurcation_kind::fold, b.mu, b.w, 0, {}, k, 0};
    if (opt.locate) {
      double s0 = 0, f0 = a.tangent_mu, f1 = b.tangent_mu;
      vec<double> best = x;
      for (int it = 1; it <= 30 && std::abs(f1) > 1e-10; ++it) {
        const double s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
        auto xs = correct_along(x_prev + s2 * t_prev, t_prev);
        if (!xs) break;
        vec<double> ts;
        try {
          ts = raw_tangent(xs->x, metric.row(t_prev));
        } catch (const error&) {  // a singular bordered matrix: keep the best point so far
          break;
        }
        s0 = s1, f0 = f1, s1 = s2, f1 = ts[n] / metric.norm(ts);
        best = xs->x;
        fold.locate_iterations = it;
      }
      fold.mu = best[n];
      fold.w = best.head(n);
    }
    if (opt.verbose && opt.log)
      *opt.log << "continuation: fold at mu = " << std::setprecision(12) << fold.mu << std::setprecision(6) << "\n";
    res.bifurcations.push_back(std::move(fold));
  };
  // Hopf point where gamma changes sign: Newton on the augmented system (hopf_problem,
  // hopf_newton) from the branch point at the interpolated crossing.
  auto locate_hopf = [&](const vec<double>& x_prev, const vec<double>& t_prev, const vec<double>& x, int k) {
    const branch_point& a = res.points[k];
    const branch_point& b = res.points[k + 1];
    const double th = a.gamma / (a.gamma - b.gamma);
    detected_bifurcation hb{bifurcation_kind::hopf, (1 - th) * a.mu + th * b.mu, (1 - th) * a.w + th * b.w,
                            std::abs((1 - th) * a.critical.imag() + th * b.critical.imag()), {}, k, 0};
    if (opt.locate) {
      auto xs = correct_along(vec<double>(x_prev + th * metric.distance(x, x_prev) * t_prev), t_prev);
      const vec<double> wg = xs ? vec<double>(xs->x.head(n)) : hb.w;
      const double mug = xs ? xs->x[n] : hb.mu;
      try {
        const hopf_problem<S> prob(sys, hopf_start(sys, wg, mug, hb.omega), opt.hopf, "solve_hopf");
        hopf_augmented_lu<S> strategy(opt.hopf);
        const hopf_result hr = hopf_newton(prob, strategy, opt.hopf);
        if (!hr.report.converged) throw convergence_error(hr.report.reason);  // hopf.throw_on_failure = false
        hb.mu = hr.point.mu;
        hb.w = hr.point.w;
        hb.omega = hr.point.omega;
        hb.p = hr.point.p;
        hb.locate_iterations = hr.report.iterations;
      } catch (const error& e) {  // no convergence, a singular pivot: not located
        hb.mu = 1e300;            // treated as spurious below
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
      return;
    }
    if (opt.verbose && opt.log)
      *opt.log << "continuation: Hopf point at mu = " << std::setprecision(12) << hb.mu << ", omega = " << hb.omega
               << std::setprecision(6) << "\n";
    res.bifurcations.push_back(std::move(hb));
  };

  curve_problem prob{
      [&](const curve_request& q, std::string& why) {
        step = q.point;
        ds = q.step;
        auto r = correct(q.x0, q.c, q.value);
        if (!r) why = res.last_corrector_failure;
        return r;
      },
      [&](const vec<double>& x, const vec<double>& c) {
        if (!res.points.empty())
          context = internal::concat("step ", res.points.size(), ": tangent or spectrum at mu = ", x[n],
                                     " (from mu = ", res.points.back().mu, ")");
        return raw_tangent(x, c);
      },
      [&](const vec<double>& x, const curve_point_info& info) {
        branch_point bp;
        bp.w = x.head(n);
        bp.mu = x[n];
        bp.tangent_mu = (*info.tangent)[n];
        bp.newton_iterations = info.iterations;
        if (opt.detect_hopf) internal::evaluate_spectrum(sys, bp, opt);
        if (opt.verbose && opt.log)
          *opt.log << "continuation " << std::setw(4) << res.points.size() << "  mu " << std::setprecision(10) << bp.mu
                   << "  dmu/ds " << std::setprecision(3) << bp.tangent_mu << "  gamma " << bp.gamma << "  newton "
                   << info.iterations << std::setprecision(6) << "\n";
        res.points.push_back(std::move(bp));
        if (info.start) return false;
        const int k = int(res.points.size()) - 2;  // the previous point
        const branch_point& a = res.points[k];
        const branch_point& b = res.points[k + 1];
        if (opt.detect_folds && a.tangent_mu * b.tangent_mu < 0) locate_fold(*info.from, *info.direction, x, info.step, k);
        if (opt.detect_hopf && std::isfinite(a.gamma) && std::isfinite(b.gamma) && a.gamma * b.gamma < 0)
          locate_hopf(*info.from, *info.direction, x, k);
        return false;
      }};

  try {
    context = internal::concat("start at mu = ", mu0);
    newton_options no;  // make sure the start is an equilibrium
    no.abs_tolerance = opt.corrector_tolerance;
    no.max_iterations = 2 * opt.corrector_iterations;
    vec<double> x(n + 1);
    x.head(n) = newton(sys, w0, mu0, no).x;
    x[n] = mu0;
    const vec<double> e_mu = vec<double>::Unit(n + 1, n);
    const vec<double> t = curve_unit_tangent(prob, metric, x, e_mu, vec<double>(direction >= 0 ? e_mu : -e_mu), who);
    curve_stepper_options so = internal::continuation_stepper_options(opt, n, who);
    so.predictor = curve_predictor::tangent;
    so.step = opt.ds;
    so.min_step = std::min(opt.ds_min, opt.ds);
    so.max_step = opt.ds_max;
    const curve_outcome oc = trace_curve(prob, x, t, metric, so);
    if (oc.stop == curve_stop::step_underflow) {
      res.stop_reason = internal::concat("step size below ds_min at mu = ", res.points.back().mu, " (step ",
                                         res.points.size(), "; last corrector failure: ", res.last_corrector_failure, ")");
      if (opt.verbose && opt.log) *opt.log << "continuation: " << res.stop_reason << "\n";
    } else {
      res.stop_reason = oc.stop == curve_stop::limit ? "left the mu interval" : "step limit";
    }
  } catch (...) {
    res.failed = true;
    res.stop_reason = internal::concat(who, ": ", context, ": ", internal::current_exception_text());
    if (opt.verbose && opt.log) *opt.log << res.stop_reason << "\n";
    if (opt.throw_on_failure) internal::rethrow_with_context(internal::concat(who, ": ", context, ": "));
  }
  return res;
}

}  // namespace aerohopf
