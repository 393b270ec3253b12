#pragma once
// Pseudo-arclength continuation of the SYMMETRIC Hopf curve with Krylov linear algebra: the
// flutter boundary Ubar(M) of a symmetric aerofoil traced through its steep transonic branches
// at a cost close to a steady solve per point, for grids where the full (3n+3) system of
// hopf_curve.hpp (sparse LU, w as unknowns) costs a minute per point.
//
// Setting: a family S(nu) (nu = Mach number) whose equilibrium w0(nu) does NOT depend on the
// system's parameter mu (Ubar: the structure is at rest, K(Ubar) w_s = 0) but does depend on nu.
// The flow is then not an unknown of the Hopf system: it is the solution of a NESTED steady
// solve at every nu the corrector visits, and the curve is traced in the unknowns
//     X = [p_r, p_i, mu, nu, omega]                                   (2n + 3)
// with the equations
//     G(X) = [ A(nu, mu) p_r + omega p_i            A(nu, mu) = f_w(w0(nu), mu; nu)
//              A(nu, mu) p_i - omega p_r
//              s.p_r
//              s.p_i - 1
//              c.(y - y_pred) ]                     y = (mu, nu, omega),  c_j = t_j / sigma_j^2
// (the fixed-equilibrium Hopf system of hopf_bordered.hpp at w = w0(nu), plus the pseudo-arclength row
// in the scaled (mu, nu, omega) metric of hopf_curve.hpp). A p is evaluated exactly and matrix-
// free (jacobian_product_pair: one jet pass through the residual), so every point satisfies the
// exact equations to the Newton tolerance, whatever the approximations below.
//
// Nested steady solve (w0(nu), the Newton-Krylov solve of equilibrium_krylov.hpp): Newton on
// f(w, mu; nu) = 0 with the exact Jacobian as the GMRES
// operator, right-preconditioned by the real BILU(k) of lhs_jacobian (the modified-order
// Jacobian for the aerofoil: BILU of the exact second-order flow Jacobian is poor, spec 05),
// factorised once per steady solve; inexact-Newton forcing eta = min(eta_max, ||f||) and
// convergence at ||f||_2 <= steady.abs_tolerance (default 1e-11) or a full step at the rounding
// floor (newton_options::step_tolerance). Warm start w0(nu_e) + (nu - nu_e) dw0/dnu(nu_e) from the
// nearest nu_e already solved. Failure (no convergence, a non-physical state thrown by the
// model, a GMRES failure) is a convergence_error naming nu; inside the trace it counts as a
// failed corrector, so the step is halved. Solved equilibria are cached by nu (the corrector
// revisits the same nu in the residual and the Jacobian).
//     dw0/dnu = -f_w^{-1} f_nu,   f_nu = (f(w0, mu; nu + h) - f(w0, mu; nu - h)) / 2h
// (GMRES with the same preconditioner, relative tolerance derivative_tolerance), once per nu.
//
// Jacobian of G (never needed exactly: it sets the convergence rate only):
//     J = [ A         omega I   A_mu p_r   G_nu,r   p_i
//          -omega I   A         A_mu p_i   G_nu,i  -p_r
//           s^T       0         0          0        0
//           0         s^T       0          0        0
//           0         0         c_mu       c_nu     c_omega ]
// with the column G_nu = d/dnu [A(w0(nu), mu; nu) p] INCLUDING the change of the equilibrium, by
// central differences with the equilibrium extrapolated linearly:
//     G_nu ~ (A(w0 + h w0', mu; nu + h) p - A(w0 - h w0', mu; nu - h) p) / 2h,   w0' = dw0/dnu.
// This is exact to O(h^2): w0(nu +- h) = w0 +- h w0' + h^2/2 w0'' + O(h^3), and the h^2 terms
// cancel in the central difference, so only w0' (not w0'') enters the first derivative and no
// steady solves at nu +- h are needed. h = nu_step or cbrt(eps) max(1, |nu|).
//
// Linear solves: right-preconditioned GMRES on the WHOLE bordered matrix J (the real 2n block
// applied as two SpMVs with the assembled exact Jacobian, three border unknowns mu, nu, omega,
// two normalisation rows and the arclength row), preconditioned by bordered_preconditioner
// (block elimination of the 3 x 3 border, linalg/block_sparse_matrix.hpp) around the complex
// BILU(k) of the modified-order L - i omega I. NOT Keller block elimination with the fixed-nu
// Hopf Jacobian (the (2n+2) matrix of solve_hopf_krylov): that matrix is singular exactly where
// the curve turns in nu (dnu/ds = 0), which are the steep branches this tracer is for; J is not.
// The same solve with the right-hand side e_last gives the exact tangent (the first predictor
// and the retry after a failed secant step). GMRES uses the inexact-Newton forcing of
// solve_hopf_krylov: eta = min(eta_max, max(||G||, 0.1 abs_tolerance / ||G||)).
//
// Cost per corrector iteration: one steady Newton solve at the new nu (1-3 iterations from the
// linear extrapolation), one dw0/dnu solve, assembly of A, L, A_mu, one complex BILU(k), two
// jet passes of the residual for G_nu, one GMRES on J.
//
// Joint corrector (fixed_equilibrium_hopf_curve_options::joint_equilibrium). The nested solve above
// converges w0(nu) at every nu the corrector visits, though only the last one matters. The joint
// corrector makes w an unknown beside x = (p, mu, nu, omega) and solves [G(x, w); f(w, mu; nu)] = 0
// by Newton, each step by block elimination of the flow rows (f_w dw + f_nu dnu = -f):
//     dw = dw_a + dnu dw_nu,   f_w dw_a = -f,   f_w dw_nu = -f_nu      (two real GMRES, one BILU)
// and then the Hopf rows, with G_w dw substituted,
//     J(x) dx = -G(x, w) - G_w dw_a,   G_w dw_a = d/de [A(w + e dw_a) p] (central differences),
// where J is the bordered matrix above with its column G_nu taken along dw_nu at the iterate.
// f_mu dmu is left out of the flow rows: f_mu = 0 at the equilibrium (it does not depend on mu),
// so the error of the step vanishes at the solution and Newton stays quadratic. The residual is
// [G; sigma f] with sigma = newton.abs_tolerance / steady.abs_tolerance, so convergence of its
// norm to newton.abs_tolerance holds G to that tolerance and f to the steady one: every accepted
// point is again an exact solution. Cost per corrector iteration: one assembly of f_w and L, one
// real and one complex BILU(k), two real GMRES and the bordered GMRES; no nested Newton.
// The joint corrector makes the first attempt of every step (and of every landing, which falls
// back to the nested corrector when it fails); once it failed, the step's retries (fixed mu or
// nu, exact tangent, halving) use the nested steady solves. Measured on the heavy aerofoil at
// its kinks (medium grid, M = 0.8276, joint corrector for every attempt): it failed at every step
// size down to 0.004 where the nested one crossed at fixed M. Its iterates cross the
// discretisation's switches in w away from the equilibrium, so the kinks are not on lines
// nu = const for it. Measured on that grid's stretch M = 0.825 -> 0.83 (four runs each, joint
// and nested alternated): 16 points, 23 nested steady solves, 106 flow Newton steps, 17.9-23.1 s
// against 12 points, 74 solves, 154 steps, 18.2-25.3 s; a joint corrector iteration costs about
// 0.16 s there, a nested one 0.23 s, but its steps grew less (5 iterations per point).
//
// Kinks. A discretisation that is only C1 (the Osher flux's subpath switches at sonic points,
// limiters) has a Jacobian A that is continuous but not differentiable in w, so the Hopf curve
// is continuous with KINKS wherever a face of the steady flow crosses a switch as nu changes
// (measured: heavy case, coarse grid, M = 0.7888: dUbar/dM jumps from +29 to -11 within
// dM = 2e-5, and again 2e-4 later; the fixed-Mach Hopf solves converge on both sides). Where
// the curve turns by more than 90 degrees in the metric at a kink, the arclength hyperplane
// does not meet the next piece near the prediction and no step size helps. As w0 depends on
// nu only, the switches are crossed at fixed values of nu: the kinks lie on lines nu = const.
// kink_fallback: after the arclength corrector diverged from the secant prediction, or failed
// from the secant and the exact tangent, the same step is retried with the last row fixing nu
// (or first mu where the curve is nearly vertical in nu), then the other one, at its value
// predicted along the secant -- a local parametrisation, which crosses the kink as natural
// continuation does (measured: at a peak of Ubar(M) at a kink, M = 0.8850 coarse grid, only
// fixed M crosses) -- and accepted if it lands within kink_distance x step of the last point
// and ahead along the secant. The fallback comes before the exact-tangent retry when the
// corrector diverged (measured on the heavy medium grid, M = 0.825 -> 0.83: the exact tangent
// never rescued a diverged corrector there, only ones that converged too far from the
// prediction; failed correctors 7 -> 5, nested steady solves 82 -> 74). A corrected point that
// goes back along the secant (possible after the exact-tangent retry at a kink: measured, the
// trace reversed at M = 0.867 and retraced the curve) is rejected like a sheet jump, and so is
// one (also of the fallback) within a quarter step of the polyline of the points traced before
// the last three.
// Nested steady solves that fail from the extrapolated start are retried from the nearest
// solved equilibrium and then from equilibrium_start(nu) if given (transonic flow: the shock
// moves fast with M, and Newton from the extrapolation can meet non-physical states).
// Cheap failure: a corrector iterate farther than iterate_distance steps from its prediction is
// abandoned before the nested steady solve at its nu, and opt.newton.max_contraction (the
// contraction test of newton.hpp) abandons a corrector whose ||F|| rises after its first step;
// each corrector iteration costs a steady solve, so a failed one should cost two or three.
//
// This file holds the corrector (internal::fixed_equilibrium_hopf_corrector: the nested and the
// joint Newton correctors, the steady solves, the bordered GMRES). The stepping is the curve
// stepper's (curve_stepper.hpp) through run_hopf_curve of hopf_curve.hpp, with its option and
// result types: metric and step control, retry along the exact tangent, the sheet-jump guard,
// plus the retrace guard and the kink step (primary coordinate nu, secondary mu) of this
// tracer; stops, landings, observer per accepted point, throw_on_failure = false. opt.start (hopf_options)
// converges the start at nu0 with solve_hopf_krylov (fixed equilibrium forced). Per-point costs (GMRES
// iterations, steady solves) are returned alongside in fixed_equilibrium_hopf_curve_result::stats.
// Post-checks and failure reports as hopf_curve.hpp, with the equilibrium check of the fixed
// equilibrium: the w0(nu*) a converged corrector used must satisfy ||f(w0, mu*)|| <=
// ||f(w0, mu_solved)|| + steady.abs_tolerance (it was solved at mu_solved; a family whose
// equilibrium moves with mu fails this, and its start point is refused by solve_hopf_krylov,
// whose equilibrium tolerance is what the start's steady solve reached + steady.abs_tolerance).
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/krylov.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "equilibrium_krylov.hpp"
#include "hopf.hpp"
#include "hopf_bordered.hpp"
#include "hopf_curve.hpp"
#include "hopf_point.hpp"

namespace aerohopf {

/// Costs of one accepted point of the fixed-equilibrium tracer (parallel to hopf_curve_result::points).
struct fixed_equilibrium_hopf_curve_stats {
  long linear_iterations = 0;   ///< GMRES iterations of the corrector(s) and tangents (Hopf system)
  int steady_solves = 0;        ///< nested steady Newton solves (new nu values)
  int steady_iterations = 0;    ///< their Newton iterations
  long steady_linear_iterations = 0;  ///< their GMRES iterations (and those of dw0/dnu)
  double steady_seconds = 0;    ///< wall time in the nested steady solves and dw0/dnu
};

struct fixed_equilibrium_hopf_curve_result : hopf_curve_result {
  std::vector<fixed_equilibrium_hopf_curve_stats> stats;  ///< one per point, including failed attempts
  int kink_steps = 0;                   ///< steps taken at fixed mu or nu (kink_fallback)
  long linear_iterations = 0;
  int steady_solves = 0;
  int steady_iterations = 0;  ///< steady Newton iterations (nested solves) or steps (joint corrector)
  double steady_seconds = 0;
};

/// Linear algebra and nested steady solves of trace_fixed_equilibrium_hopf_curve (the curve options
/// are those of hopf_curve_options).
struct fixed_equilibrium_hopf_curve_options {
  int fill_level = 1;  ///< k of the complex BILU(k) of L - i omega I and of the real BILU(k) of L
  krylov_options krylov = [] {
    krylov_options o = newton_correction_krylov_options();
    o.relative_tolerance = 1e-6;  ///< when not adaptive
    return o;
  }();
  bool adaptive_tolerance = true;   ///< inexact-Newton forcing (file comment)
  double eta_max = 1e-2;
  double tangent_tolerance = 1e-8;  ///< relative GMRES tolerance of the exact tangents
  /// Relative GMRES tolerance of dw0/dnu. It enters only the Jacobian column G_nu (the
  /// convergence rate, not the converged point) and the warm start of the next steady solve, so
  /// it need not be tight: an error eta in it perturbs Newton's contraction by about eta.
  double derivative_tolerance = 1e-8;
  newton_options steady = [] {
    newton_options o;
    o.abs_tolerance = 1e-11;  ///< on ||f(w, mu; nu)||_2
    o.max_iterations = 12;
    o.line_search = true;     ///< halve while ||f|| does not decrease (or is not finite)
    return o;
  }();                              ///< nested steady Newton (throw_on_failure is ignored)
  std::size_t equilibrium_cache = 8;  ///< solved equilibria kept (by nu)
  /// Joint corrector (file comment): the flow w is an unknown of the corrector beside
  /// (p, mu, nu, omega), one steady Newton step per corrector iteration by block elimination,
  /// instead of a nested steady solve converged at every nu the corrector visits. It makes the
  /// first attempt of each step and landing; the retries after it failed are nested.
  bool joint_equilibrium = false;
  /// After the arclength corrector diverged from the secant prediction, or failed along the
  /// secant and the exact tangent, retry the same step at fixed mu or nu (file comment: kinks of the curve of a C1 discretisation);
  /// accepted if it lands ahead along the secant within kink_distance x step of the last point.
  bool kink_fallback = true;
  /// A start for the nested steady Newton at nu, tried when the warm starts (extrapolation along
  /// dw0/dnu, then the nearest solved equilibrium) fail, e.g. a pseudo-transient steady solve
  /// from the free stream (aerofoil_system::steady_equilibrium). Empty: no third start.
  std::function<vec<double>(double)> equilibrium_start;
  double kink_distance = 2.0;
  /// Abandon a corrector as soon as an iterate lies farther than iterate_distance x the step from
  /// its prediction (the metric of hopf_curve_options), BEFORE the nested steady solve at that
  /// iterate's nu: accepted points lie within corrector_distance (arclength) or kink_distance + 1
  /// (fixed mu or nu) steps of it, and an iterate far outside is a corrector on its way out
  /// (measured on the heavy medium grid: nu jumped from 0.828 to 0.066, where three steady starts
  /// failed, 24 steady Newton iterations). Infinity: off.
  double iterate_distance = 5.0;
  /// Called for every accepted point with its costs (after hopf_curve_options::observer).
  std::function<void(const hopf_curve_point&, const fixed_equilibrium_hopf_curve_stats&)> observer;
};

namespace internal {
/// The corrector of the fixed-equilibrium Hopf curve (file comment): nested steady solves
/// cached by nu, the bordered GMRES solves, the nested and the joint Newton correctors, and the
/// costs per emitted point. For run_hopf_curve; its pieces are usable alone (tests).
template <int B, system_family F>
  requires is_sparse_matrix_v<jacobian_t<family_system_t<F>>>
class fixed_equilibrium_hopf_corrector : hopf_curve_corrector_base<F> {
  using base = hopf_curve_corrector_base<F>;
  using base::L_, base::opt_, base::nu_h, base::system_at;

 public:
  using typename base::S, typename base::M;
  using C = std::complex<double>;
  using clock = std::chrono::steady_clock;
  using real_block = block_sparse_matrix<double, B>;
  using row = std::array<double, 3>;

  /// A solved equilibrium w0(nu), its dw0/dnu (empty until needed) and the mu it was solved at
  /// (the post-check compares f at mu* with f there).
  struct equilibrium {
    double nu;
    vec<double> w, dw;
    double mu;
  };

  fixed_equilibrium_hopf_corrector(const F& family, const hopf_curve_layout& L, const hopf_curve_options& opt,
                                   const fixed_equilibrium_hopf_curve_options& sopt,
                                   fixed_equilibrium_hopf_curve_result& res, family_cache<F, S> cur)
      : base(L, opt), sopt_(sopt), res_(res), cur_(std::move(cur)), plus_(family), minus_(family), aux_(family),
        padded_(padded_block_count(L.n, B) * B), rilu_(ilu_options("real BILU(", "of the steady Newton matrix")),
        cilu_(ilu_options("complex BILU(", "of L - i omega I")), joint_now_(sopt.joint_equilibrium) {}

  /// The costs since the last emitted point.
  fixed_equilibrium_hopf_curve_stats& costs() { return acc_; }

  /// The start: the equilibrium at nu0 by the nested steady Newton from start.w, then the
  /// fixed-equilibrium Hopf point there by hopf_newton with the bordered Krylov strategy
  /// (solve_hopf_krylov).
  hopf_result converge_start(double nu0, const hopf_point& start) {
    check_state(system_at(cur_, nu0), start.w, start.mu, "trace_fixed_equilibrium_hopf_curve");
    vec<double> w0 = steady_solve(nu0, start.mu, start.w);
    cache_.push_back({nu0, w0, vec<double>(), start.mu});
    hopf_point g = start;
    g.w = std::move(w0);
    hopf_options ho = opt_.start;
    ho.fixed_equilibrium = true;
    ho.normalisation = opt_.normalisation;
    // the equilibrium holds to what the nested steady solve reached (post-checks, hopf.hpp)
    ho.equilibrium_tolerance =
        std::max(ho.equilibrium_tolerance,
                 hopf_norm(vec<double>(system_at(cur_, nu0).residual(g.w, start.mu))) + sopt_.steady.abs_tolerance);
    ho.label = opt_.label + ": start point at nu = " + concat(nu0);
    hopf_krylov_options ko;
    ko.fill_level = sopt_.fill_level;
    hopf_result h0 = solve_hopf_krylov<B>(system_at(cur_, nu0), g, ho, ko);
    require(h0.report.converged, opt_.label, ": start point at nu = ", nu0, " did not converge (", h0.report.reason,
            ")");
    acc_.linear_iterations += h0.linear_iterations;
    return h0;
  }

  /// A step's first attempt and every landing start with the joint corrector when
  /// joint_equilibrium is set (a landing falls back to the nested one); retries and kink steps
  /// are nested (file comment).
  std::optional<hopf_corrected> correct(const curve_request& q, const vec<double>& s, std::string& why) {
    const row c = L_.row3(q.c);
    const double radius = sopt_.iterate_distance * q.step;
    joint_now_ = sopt_.joint_equilibrium && (q.kind == curve_attempt::landing || q.first);
    if (joint_now_) {
      auto r = correct_joint(q.x0, s, c, q.value, radius, why);
      if (r || q.kind != curve_attempt::landing) return r;
      joint_now_ = false;
    }
    return correct_nested(q.x0, s, c, q.value, radius, why);
  }
  /// J t = e_last with the last row c, by the bordered GMRES (tangent_tolerance).
  vec<double> tangent(const vec<double>& x, const vec<double>& s, const vec<double>& c) {
    const row cc = L_.row3(c);
    return solve_bordered(x, s, cc, vec<double>(vec<double>::Unit(L_.N, L_.iom)), sopt_.tangent_tolerance,
                          opt_.label + ": GMRES for the tangent");
  }
  /// w0(nu) of a point (cached: the corrector's last residual was at its nu).
  vec<double> point_w(const vec<double>& x) { return equilibrium_at(x[L_.inu], x[L_.imu]).w; }
  /// Costs of a step are kept apart from those of the landings emitted before its point.
  void step_corrected() { step_costs_ = std::exchange(acc_, fixed_equilibrium_hopf_curve_stats{}); }
  void before_emit(bool landed) {
    if (landed) return;
    acc_.linear_iterations += step_costs_.linear_iterations;
    acc_.steady_solves += step_costs_.steady_solves;
    acc_.steady_iterations += step_costs_.steady_iterations;
    acc_.steady_linear_iterations += step_costs_.steady_linear_iterations;
    acc_.steady_seconds += step_costs_.steady_seconds;
    step_costs_ = {};
  }
  std::string costs_text() const {
    return concat("  gmres ", acc_.linear_iterations, "  steady ", acc_.steady_solves, " (", acc_.steady_iterations,
                  " its)");
  }
  void after_emit(const hopf_curve_point& pt) {
    if (sopt_.observer) sopt_.observer(pt, acc_);
    res_.linear_iterations += acc_.linear_iterations;
    res_.steady_solves += acc_.steady_solves;
    res_.steady_iterations += acc_.steady_iterations;
    res_.steady_seconds += acc_.steady_seconds;
    res_.stats.push_back(acc_);
    acc_ = {};
  }

  // ---- nested steady solves, cached by nu ----
  /// w0(nu) (solved if not cached), warm-started from the nearest cached nu: linear
  /// extrapolation along its dw0/dnu, then that equilibrium itself, then the user's start.
  equilibrium& equilibrium_at(double nu, double mu) {
    if (equilibrium* e = find_equilibrium(nu)) return *e;
    equilibrium* best = &nearest_equilibrium(nu, mu);
    vec<double> w;
    std::string failures;
    for (int attempt = 0; attempt < 3 && w.size() == 0; ++attempt) {
      if (attempt == 2 && !sopt_.equilibrium_start) break;
      try {
        vec<double> w0 = attempt == 0   ? vec<double>(best->w + (nu - best->nu) * best->dw)
                         : attempt == 1 ? best->w
                                        : sopt_.equilibrium_start(nu);
        require(w0.size() == L_.n, opt_.label, ": equilibrium_start(", nu, ") has ", w0.size(), " entries, system ",
                L_.n);
        w = steady_solve(nu, mu, std::move(w0));
      } catch (const error& e) {
        failures += concat(failures.empty() ? "" : "; ",
                           attempt == 0   ? "from the extrapolated"
                           : attempt == 1 ? "from the nearest"
                                          : "from the user's",
                           " start: ", e.what());
      }
    }
    if (w.size() == 0) throw convergence_error(concat(opt_.label, ": no steady state at nu = ", nu, " (", failures, ")"));
    return remember(nu, std::move(w), vec<double>(), mu);
  }

  /// Nested corrector: Newton on G with w = w0(nu) solved at every nu it visits.
  std::optional<hopf_corrected> correct_nested(const vec<double>& x0, const vec<double>& s, const row& c, double value,
                                               double radius, std::string& why) {
    newton_options no = opt_.newton;
    no.throw_on_failure = true;
    hopf_iterate_log last(x0, L_.imu, L_.iom, L_.inu);
    try {
      newton_result nr = newton_iterate(
          [&](const vec<double>& x) {
            check_radius(x, x0, radius, "corrector");
            return hopf_residual(x, equilibrium_at(x[L_.inu], x[L_.imu]).w, s, c, value);
          },
          [&](const vec<double>& x, const vec<double>& f, int it) {
            last.record(x, f, it);
            return vec<double>(solve_bordered(x, s, c, vec<double>(-f), corrector_tolerance(f.norm()),
                                              concat(opt_.label, ": GMRES at corrector iteration ", it)));
          },
          x0, no, opt_.label + " corrector");
      if (!nr.x.allFinite()) {
        why = "corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      return post_check(std::move(nr.x), nr.report, no, why);
    } catch (const error& e) {
      why = e.what() + last.describe();
      return std::nullopt;
    }
  }

  /// Joint corrector (file comment): Newton on [x; w] with f(w, mu; nu) = 0 as n more
  /// equations (scaled so that the Hopf tolerance on the whole residual is the steady tolerance
  /// on f), each step by block elimination of the flow rows.
  std::optional<hopf_corrected> correct_joint(const vec<double>& x0, const vec<double>& s, const row& c, double value,
                                              double radius, std::string& why) {
    const Eigen::Index n = L_.n, N = L_.N, inu = L_.inu, imu = L_.imu;
    const double fscale = opt_.newton.abs_tolerance / sopt_.steady.abs_tolerance;
    newton_options no = opt_.newton;
    no.throw_on_failure = true;
    vec<double> dw_nu_last;
    hopf_iterate_log last(x0, imu, L_.iom, inu);
    try {
      vec<double> X0(N + n);
      X0.head(N) = x0;
      {
        const equilibrium& e = nearest_equilibrium(x0[inu], x0[imu]);
        X0.tail(n) = e.w + (x0[inu] - e.nu) * e.dw;
      }
      newton_result nr = newton_iterate(
          [&](const vec<double>& X) {
            const vec<double> x = X.head(N), w = X.tail(n);
            check_radius(x, x0, radius, "joint corrector");
            vec<double> r(N + n);
            r.head(N) = hopf_residual(x, w, s, c, value);
            r.tail(n) = fscale * vec<double>(system_at(cur_, x[inu]).residual(w, x[imu]));
            return r;
          },
          [&](const vec<double>& X, const vec<double>& r, int it) {
            last.record(X, r, it);
            const auto t0 = clock::now();
            const vec<double> x = X.head(N), w = X.tail(n);
            const double mu = x[imu], nu = x[inu];
            const std::string what = concat(opt_.label, ": joint corrector iteration ", it, " at nu = ", nu);
            const S& sys = system_at(cur_, nu);
            const auto [a, lb] = exact_and_lhs_blocks<B>(sys, w, mu, what);
            rilu_.compute(lb);
            // the flow rows: dw = dw_a + dnu dw_nu (the f_mu dmu term left out: f_mu = 0 at the
            // equilibrium, so the step's error vanishes at the solution and the rate stays quadratic)
            const vec<double> f = r.tail(n) / fscale;
            const double fn = f.norm();
            vec<double> dwa = vec<double>::Zero(n);
            if (fn > 0)
              dwa = gmres_real(a, vec<double>(-f), forcing(fn, sopt_.steady.abs_tolerance), what + ", GMRES for the flow step");
            vec<double> dwnu = flow_nu_derivative(w, mu, nu, a, what + ", GMRES for dw/dnu");
            acc_.steady_iterations += 1;
            acc_.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
            // the Hopf rows: G_x dx + G_w dw_nu dnu = -G - G_w dw_a, G_w dw_a = d/de A(w + e dw_a) p by
            // central differences
            vec<double> rhs = -r.head(N);
            const double da = dwa.template lpNorm<Eigen::Infinity>();
            if (da > 0) {
              const double e = std::cbrt(Eigen::NumTraits<double>::epsilon()) *
                               std::max(1.0, w.template lpNorm<Eigen::Infinity>()) / da;
              const vec<double> wp = w + e * dwa, wm = w - e * dwa;
              for (const Eigen::Index i0 : {L_.ipr, L_.ipi}) {
                const vec<double> q = x.segment(i0, n);
                rhs.segment(i0, n) -= (jacobian_product(sys, wp, mu, q) - jacobian_product(sys, wm, mu, q)) / (2 * e);
              }
            }
            const vec<double> dx =
                solve_bordered_at(x, w, dwnu, a, lb, s, c, rhs, corrector_tolerance(r.norm()), what + ", GMRES");
            vec<double> dX(N + n);
            dX.head(N) = dx;
            dX.tail(n) = dwa + dx[inu] * dwnu;
            dw_nu_last = std::move(dwnu);
            return dX;
          },
          std::move(X0), no, opt_.label + " joint corrector");
      if (!nr.x.allFinite()) {
        why = "joint corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      vec<double> x = nr.x.head(N);
      // dw0/dnu of the last step's iterate: it differs from the converged flow by that step only
      remember(x[inu], nr.x.tail(n), std::move(dw_nu_last), x[imu]);
      return post_check(std::move(x), nr.report, no, why);
    } catch (const error& e) {
      why = e.what() + last.describe();
      return std::nullopt;
    }
  }

 private:
  block_ilu_options ilu_options(const char* what, const char* of) const {
    block_ilu_options o;
    o.fill_level = sopt_.fill_level;
    o.context = concat(opt_.label, ": ", what, sopt_.fill_level, ") ", of);
    return o;
  }
  vec<double> pad(const vec<double>& v) const {
    vec<double> r = vec<double>::Zero(padded_);
    r.head(L_.n) = v;
    return r;
  }
  vec<double> gmres_real(const real_block& a, const vec<double>& rhs, double tol, const std::string& what) {
    krylov_options ko = sopt_.krylov;
    ko.relative_tolerance = tol;
    ko.throw_on_failure = true;
    ko.context = what;
    vec<double> xp = vec<double>::Zero(padded_);
    const krylov_report rep = gmres<double>(a, rilu_, pad(rhs), xp, ko);
    acc_.steady_linear_iterations += rep.iterations;
    return vec<double>(xp.head(L_.n));
  }
  // Inexact-Newton forcing (file comment) for a residual of norm fn converging to abs_tol.
  double forcing(double fn, double abs_tol) const { return inexact_forcing(fn, abs_tol, sopt_.eta_max); }
  // Newton on f(w, mu; nu) = 0 from w (file comment); throws convergence_error naming nu.
  vec<double> steady_solve(double nu, double mu, vec<double> w) {
    const auto t0 = clock::now();
    const std::string what = concat(opt_.label, ": steady state at nu = ", nu);
    try {
      const S& sys = system_at(cur_, nu);
      equilibrium_krylov_options eo;
      eo.fill_level = sopt_.fill_level;
      eo.newton = sopt_.steady;
      eo.newton.observer = nullptr;
      eo.eta_max = sopt_.eta_max;
      eo.krylov = sopt_.krylov;
      // rilu keeps the BILU of the start's lhs_jacobian (dw0/dnu reuses it)
      newton_result nr = equilibrium_newton_krylov<B>(sys, mu, std::move(w), eo, rilu_, acc_.steady_linear_iterations, what);
      acc_.steady_solves += 1;
      acc_.steady_iterations += nr.report.iterations;
      acc_.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      return std::move(nr.x);
    } catch (const convergence_error&) {
      acc_.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      throw;
    } catch (const error& e) {  // e.g. a non-physical state or a singular pivot: a failed solve
      acc_.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      throw convergence_error(what + ": " + e.what());
    }
  }
  equilibrium* find_equilibrium(double nu) {
    for (auto& e : cache_)
      if (e.nu == nu) return &e;
    return nullptr;
  }
  // dw/dnu = -f_w^{-1} f_nu at the flow state w (f_w = a; rilu holds the BILU of its
  // preconditioner), f_nu by central differences in nu
  vec<double> flow_nu_derivative(const vec<double>& w, double mu, double nu, const real_block& a,
                                 const std::string& what) {
    const double h = nu_h(nu);
    const vec<double> f_nu =
        (vec<double>(system_at(plus_, nu + h).residual(w, mu)) - vec<double>(system_at(minus_, nu - h).residual(w, mu))) /
        (2 * h);
    return gmres_real(a, vec<double>(-f_nu), sopt_.derivative_tolerance, what);
  }
  // dw0/dnu at a solved equilibrium (f_w = a, preconditioner BILU of lb).
  void ensure_derivative(equilibrium& e, double mu, const real_block& a, const real_block& lb) {
    if (e.dw.size() == L_.n) return;
    const auto t0 = clock::now();
    rilu_.compute(lb);
    e.dw = flow_nu_derivative(e.w, mu, e.nu, a, concat(opt_.label, ": dw0/dnu at nu = ", e.nu, ", GMRES"));
    acc_.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
  }
  // The solved equilibrium nearest to nu, with its dw0/dnu.
  equilibrium& nearest_equilibrium(double nu, double mu) {
    require(!cache_.empty(), opt_.label, ": no equilibrium to start the steady solve at nu = ", nu, " from");
    equilibrium* best = &cache_.front();
    for (auto& e : cache_)
      if (std::abs(e.nu - nu) < std::abs(best->nu - nu)) best = &e;
    if (best->dw.size() != L_.n) {
      const S& sb = system_at(aux_, best->nu);
      const auto [a, lb] = exact_and_lhs_blocks<B>(sb, best->w, mu, opt_.label);
      ensure_derivative(*best, mu, a, lb);
    }
    return *best;
  }
  // Keeps w0(nu) (replacing an entry at the same nu; the oldest goes when the cache is full).
  equilibrium& remember(double nu, vec<double> w, vec<double> dw, double mu) {
    if (equilibrium* e = find_equilibrium(nu)) {
      e->w = std::move(w);
      e->dw = std::move(dw);
      e->mu = mu;
      return *e;
    }
    if (cache_.size() >= std::max<std::size_t>(sopt_.equilibrium_cache, 2)) cache_.erase(cache_.begin());
    cache_.push_back({nu, std::move(w), std::move(dw), mu});
    return cache_.back();
  }

  // ---- the Hopf residual and the bordered linear solves ----
  // G(x) at the flow state w (the equilibrium w0(nu) in the nested scheme, the current iterate
  // in the joint one)
  vec<double> hopf_residual(const vec<double>& x, const vec<double>& w, const vec<double>& s, const row& c,
                            double value) {
    vec<double> f(L_.N);
    L_.eigen_rows(system_at(cur_, x[L_.inu]), w, x, s, c, value, f);
    return f;
  }
  // Solves J(x) dx = rhs (J with the last row c) by GMRES with the bordered complex-BILU
  // preconditioner at the flow state w with a = f_w(w) (exact) and lb (modified order), and
  // dw_nu the change of the flow with nu that the column G_nu follows (dw0/dnu; the joint
  // scheme's -f_w^{-1} f_nu); throws convergence_error / singular_matrix_error.
  vec<double> solve_bordered_at(const vec<double>& x, const vec<double>& w, const vec<double>& dw_nu, const real_block& a,
                                const real_block& lb, const vec<double>& s, const row& c, const vec<double>& rhs,
                                double tol, const std::string& what) {
    const Eigen::Index n = L_.n;
    const double mu = x[L_.imu], nu = x[L_.inu], om = x[L_.iom];
    const S& sys = system_at(cur_, nu);
    const vec<double> pr = x.segment(L_.ipr, n), pi = x.segment(L_.ipi, n);
    const M amu = jacobian_d_mu(sys, w, mu);
    // G_nu by central differences along the linearly extrapolated equilibrium (file comment)
    const double h = nu_h(nu);
    const S& sp = system_at(plus_, nu + h);
    const S& sm = system_at(minus_, nu - h);
    const vec<double> wp = w + h * dw_nu, wm = w - h * dw_nu;
    const auto [apr_p, api_p] = jacobian_product_pair(sp, wp, mu, pr, pi);
    const auto [apr_m, api_m] = jacobian_product_pair(sm, wm, mu, pr, pi);
    const vec<double> gr = (apr_p - apr_m) / (2 * h);
    const vec<double> gi = (api_p - api_m) / (2 * h);
    cilu_.compute(shifted(lb, C(0.0, om)));
    const real_split_shifted_operator<real_block> inner(a, om, n);
    const complex_preconditioner_split_form<block_ilu<C, B>> inner_pre(cilu_, n, padded_);
    Eigen::MatrixXd u(2 * n, 3), vt = Eigen::MatrixXd::Zero(3, 2 * n), d = Eigen::MatrixXd::Zero(3, 3);
    u.col(0) << amu * pr, amu * pi;
    u.col(1) << gr, gi;
    u.col(2) << pi, -pr;
    vt.row(0).head(n) = s.transpose();
    vt.row(1).tail(n) = s.transpose();
    for (int k = 0; k < 3; ++k) d(2, k) = c[k];
    const bordered_operator<decltype(inner), double> jop(inner, 2 * n, std::move(u), std::move(vt), std::move(d));
    const bordered_preconditioner<decltype(inner_pre), double> jpre(jop, inner_pre);
    krylov_options ko = sopt_.krylov;
    ko.relative_tolerance = tol;
    ko.context = what;
    ko.throw_on_failure = true;
    vec<double> dx = vec<double>::Zero(L_.N);
    const krylov_report rep = gmres<double>(jop, jpre, rhs, dx, ko);
    acc_.linear_iterations += rep.iterations;
    return dx;
  }
  // J(x) dx = rhs at the equilibrium w0(nu) (solved if not cached)
  vec<double> solve_bordered(const vec<double>& x, const vec<double>& s, const row& c, const vec<double>& rhs, double tol,
                             const std::string& what) {
    const double mu = x[L_.imu], nu = x[L_.inu];
    equilibrium& e = equilibrium_at(nu, mu);
    const auto [a, lb] = exact_and_lhs_blocks<B>(system_at(cur_, nu), e.w, mu, opt_.label);
    ensure_derivative(e, mu, a, lb);
    return solve_bordered_at(x, e.w, e.dw, a, lb, s, c, rhs, tol, what);
  }
  // Post-checks of a converged corrector (hopf.hpp). The equilibrium w0(nu*) it used must hold
  // at mu* as it did where it was solved: ||f(w0, mu*)|| <= ||f(w0, mu_solved)|| +
  // steady.abs_tolerance (mu_solved = mu* for the joint corrector, whose residual holds f; for
  // the nested one this catches an equilibrium that moves with mu, which the fixed-equilibrium
  // Hopf system cannot follow). The frequency floor 10 ||G|| / ||p|| goes to the caller.
  std::optional<hopf_corrected> post_check(vec<double> x, const newton_report& rep, const newton_options& no,
                                           std::string& why) {
    const double r = hopf_resolved_residual(rep, no);
    const double mu = x[L_.imu], nu = x[L_.inu];
    const equilibrium& e = equilibrium_at(nu, mu);  // cached: the corrector's last residual was at this nu
    const S& sys = system_at(cur_, nu);
    const double fn = hopf_norm(vec<double>(sys.residual(e.w, mu)));
    const double f_solved = e.mu == mu ? fn : hopf_norm(vec<double>(sys.residual(e.w, e.mu)));
    const std::string bad = curve_equilibrium_check(fn, f_solved + sopt_.steady.abs_tolerance, nu, mu, x[L_.iom]);
    if (!bad.empty()) {
      why = bad;
      return std::nullopt;
    }
    hopf_corrected out;
    out.omega_floor = hopf_frequency_floor(r, x.segment(L_.ipr, 2 * L_.n).norm());
    out.x = std::move(x);
    out.iterations = rep.iterations;
    return out;
  }
  // GMRES tolerance of a corrector iteration at residual norm fn (file comment)
  double corrector_tolerance(double fn) const {
    return sopt_.adaptive_tolerance ? forcing(fn, opt_.newton.abs_tolerance) : std::min(sopt_.krylov.relative_tolerance, 0.5);
  }
  // Cheap failure (file comment): an iterate x farther than radius from the prediction x0.
  void check_radius(const vec<double>& x, const vec<double>& x0, double radius, const char* who) const {
    double d2 = 0;
    for (int j = 0; j < 3; ++j)
      if (L_.sig[j] > 0) d2 += std::pow((x[L_.imu + j] - x0[L_.imu + j]) / L_.sig[j], 2);
    const double d = std::sqrt(d2);
    if (!(d <= radius))
      throw convergence_error(concat(opt_.label, " ", who, ": iterate at nu = ", x[L_.inu], ", mu = ", x[L_.imu],
                                     " lies ", d, " from the prediction (more than ", radius, ")"));
  }

  const fixed_equilibrium_hopf_curve_options& sopt_;
  fixed_equilibrium_hopf_curve_result& res_;
  family_cache<F, S> cur_, plus_, minus_, aux_;  // aux_: dw0/dnu at a cached nu other than the current one
  Eigen::Index padded_;
  std::vector<equilibrium> cache_;
  block_ilu<double, B> rilu_;
  block_ilu<C, B> cilu_;
  fixed_equilibrium_hopf_curve_stats acc_, step_costs_;  // costs since the last emitted point; of the step
  bool joint_now_;
};

template <int B, system_family F>
fixed_equilibrium_hopf_curve_result trace_fixed_equilibrium_hopf_curve_erased(
    const F& family, double nu0, const hopf_point& start, const hopf_curve_options& opt, int direction,
    const fixed_equilibrium_hopf_curve_options& sopt) {
  using clock = std::chrono::steady_clock;
  const auto t_begin = clock::now();
  using S = family_system_t<F>;
  const std::string& lab = opt.label;
  internal::check_curve_trace(opt, nu0, direction);
  require(sopt.fill_level >= 0, lab, ": fill level ", sopt.fill_level, " < 0");
  require(sopt.eta_max > 0 && sopt.eta_max < 1 && sopt.tangent_tolerance > 0 && sopt.tangent_tolerance < 1 &&
              sopt.derivative_tolerance > 0 && sopt.derivative_tolerance < 1,
          lab, ": GMRES tolerances must lie in (0, 1) (eta_max ", sopt.eta_max, ", tangent ", sopt.tangent_tolerance,
          ", dw0/dnu ", sopt.derivative_tolerance, ")");
  require(sopt.steady.abs_tolerance > 0 && sopt.steady.max_iterations >= 1, lab,
          ": nested steady Newton needs abs_tolerance > 0 and max_iterations >= 1");
  internal::check_newton_options(sopt.steady, lab, "steady");
  require(std::isfinite(sopt.steady.abs_tolerance), lab, ": steady.abs_tolerance is not finite");
  require(sopt.krylov.relative_tolerance >= 0 && sopt.krylov.relative_tolerance < 1, lab,
          ": krylov.relative_tolerance must lie in [0, 1) (got ", sopt.krylov.relative_tolerance, ")");
  require(sopt.krylov.max_iterations >= 1 && sopt.krylov.restart >= 1, lab,
          ": krylov.max_iterations and krylov.restart must be >= 1 (got ", sopt.krylov.max_iterations, ", ",
          sopt.krylov.restart, ")");
  require(sopt.iterate_distance > 0, lab, ": iterate_distance must be > 0 (got ", sopt.iterate_distance, ")");
  require(std::isfinite(sopt.kink_distance) && sopt.kink_distance > 0, lab,
          ": kink_distance must be finite and > 0 (got ", sopt.kink_distance, ")");

  internal::family_cache<F, S> cur(family);
  const Eigen::Index n = cur.at(nu0).size();
  internal::check_curve_start(start, n, lab);
  const internal::hopf_curve_layout L(n, false, opt, resolve_normalisation<jacobian_t<S>>(opt.normalisation));

  fixed_equilibrium_hopf_curve_result res;
  internal::fixed_equilibrium_hopf_corrector<B, F> corr(family, L, opt, sopt, res, std::move(cur));
  // ---- the start: equilibrium at nu0, then the fixed-equilibrium Hopf point there ----
  const auto t_start = clock::now();
  const hopf_result h0 = corr.converge_start(nu0, start);
  require(h0.point.omega > opt.omega_min, lab, ": start point has omega = ", h0.point.omega,
          " <= omega_min (not a Hopf point)");
  vec<double> x(L.N);
  L.set_p(x, h0.point.p);
  x[L.imu] = h0.point.mu;
  x[L.inu] = nu0;
  x[L.iom] = h0.point.omega;
  curve_stepper_options so = internal::hopf_curve_stepper_options(opt, L);
  so.retrace_guard = true;
  so.kink_step = sopt.kink_fallback;
  so.kink_distance = sopt.kink_distance;
  return internal::run_hopf_curve(corr, L, std::move(x), h0.report.iterations,
                                  std::chrono::duration<double>(clock::now() - t_start).count(), opt, direction, res,
                                  t_begin, so);
}
}  // namespace internal

/// Traces the fixed-equilibrium Hopf curve of family(nu) through the Hopf point `start` of family(nu0)
/// (a guess: start.w an approximate equilibrium at nu0, polished by the nested steady Newton;
/// then (p, mu, omega) converged by solve_hopf_krylov<B> at fixed nu0), initially towards
/// increasing (direction = +1) or decreasing (-1) nu. B: block size of the unknowns for BILU
/// (4 for 2D Euler + pitch-plunge). See the file comment.
template <int B, system_family F>
  requires is_sparse_matrix_v<jacobian_t<family_system_t<F>>>
fixed_equilibrium_hopf_curve_result trace_fixed_equilibrium_hopf_curve(const F& family, double nu0, const hopf_point& start,
                                                       const hopf_curve_options& opt = {}, int direction = +1,
                                                       const fixed_equilibrium_hopf_curve_options& sopt = {}) {
  return internal::trace_fixed_equilibrium_hopf_curve_erased<B>(family_function<family_system_t<F>>(std::cref(family)),
                                                                nu0, start, opt, direction, sopt);
}

}  // namespace aerohopf
