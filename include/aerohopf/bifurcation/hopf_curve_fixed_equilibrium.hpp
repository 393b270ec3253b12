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
// free (jacobian_product: a taylor pass through the residual), so every point satisfies the
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
// linear extrapolation), one dw0/dnu solve, assembly of A, L, A_mu, one complex BILU(k), four
// taylor products for G_nu, one GMRES on J.
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
// Everything else mirrors hopf_curve.hpp and uses its option and result types: metric and
// step control (halve on failure, grow after <= fast_iterations, clamp), retry along the exact
// tangent after a failed secant step, the sheet-jump guard (corrector_distance, min_cosine),
// stops (max_points, nu/mu bounds landed exactly, Bogdanov-Takens, closed curve), landing on
// nu_targets, observer per accepted point, throw_on_failure = false. opt.start (hopf_options)
// converges the start at nu0 with solve_hopf_krylov (fixed equilibrium forced). Per-point costs (GMRES
// iterations, steady solves) are returned alongside in fixed_equilibrium_hopf_curve_result::stats.
// Post-checks and failure reports as hopf_curve.hpp, with the equilibrium check of the fixed
// equilibrium: the w0(nu*) a converged corrector used must satisfy ||f(w0, mu*)|| <=
// ||f(w0, mu_solved)|| + steady.abs_tolerance (it was solved at mu_solved; a family whose
// equilibrium moves with mu fails this, and its start point is refused by solve_hopf_krylov,
// whose equilibrium tolerance is what the start's steady solve reached + steady.abs_tolerance).
#include <Eigen/Core>

#include <algorithm>
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
    krylov_options o;
    o.relative_tolerance = 1e-6;  ///< when not adaptive
    o.max_iterations = 2000;
    o.restart = 80;
    o.record_history = false;
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
  using S = family_system_t<F>;
  using M = jacobian_t<S>;
  using C = std::complex<double>;
  using clock = std::chrono::steady_clock;
  using real_block = block_sparse_matrix<double, B>;
  const std::string& lab = opt.label;
  const auto t_begin = clock::now();
  require(std::isfinite(nu0), lab, ": nu0 is not finite");
  internal::check_curve_options(opt, lab);
  require(nu0 >= opt.nu_min && nu0 <= opt.nu_max, lab, ": nu0 = ", nu0, " outside [nu_min, nu_max]");
  require(direction == 1 || direction == -1, lab, ": direction must be +1 or -1");
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
  require(std::isfinite(start.mu) && std::isfinite(start.omega), lab, ": start mu or omega is not finite (", start.mu,
          ", ", start.omega, ")");
  require(sopt.iterate_distance > 0, lab, ": iterate_distance must be > 0 (got ", sopt.iterate_distance, ")");
  require(std::isfinite(sopt.kink_distance) && sopt.kink_distance > 0, lab,
          ": kink_distance must be finite and > 0 (got ", sopt.kink_distance, ")");

  fixed_equilibrium_hopf_curve_result res;
  fixed_equilibrium_hopf_curve_stats acc;  // costs since the last accepted point
  internal::family_cache<F, S> cur(family), plus(family), minus(family);
  Eigen::Index n = 0;
  {
    const S& s0 = cur.at(nu0);
    n = s0.size();
  }
  require(n > 0, lab, ": family(nu0) has no unknowns");
  require_size(start.w.size(), n, lab, "start.w (equilibrium at nu0)");
  require_size(start.p.size(), n, lab, "start.p (eigenvector)");
  require_finite(start.w, lab, "start.w (equilibrium at nu0)");
  require_finite(start.p, lab, "start.p (eigenvector)");
  const Eigen::Index padded = padded_block_count(n, B) * B;
  const Eigen::Index N = 2 * n + 3, ipr = 0, ipi = n, imu = 2 * n, inu = 2 * n + 1, iom = 2 * n + 2;
  const hopf_normalisation mode = resolve_normalisation<M>(opt.normalisation);
  const double sig[3] = {opt.mu_scale, opt.nu_scale, opt.omega_scale};
  auto yv = [&](const vec<double>& x, int j) { return x[imu + j]; };
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
  auto nu_h = [&](double nu) {
    return opt.nu_step > 0 ? opt.nu_step : std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, std::abs(nu));
  };
  auto system_at = [&](internal::family_cache<F, S>& cache, double nu) -> const S& {
    const S& s = cache.at(nu);
    require(s.size() == n, lab, ": family(", nu, ") has ", s.size(), " unknowns, family(nu0) ", n);
    return s;
  };
  auto pad = [&](const vec<double>& v) {
    vec<double> r = vec<double>::Zero(padded);
    r.head(n) = v;
    return r;
  };

  // ---- nested steady solves, cached by nu ----
  struct equilibrium {
    double nu;
    vec<double> w, dw;  // w0(nu), dw0/dnu (empty until needed)
    double mu;          // the mu it was solved at (the post-check compares f at mu* with f there)
  };
  std::vector<equilibrium> cache;
  block_ilu_options rio;
  rio.fill_level = sopt.fill_level;
  rio.context = lab + ": real BILU(" + std::to_string(sopt.fill_level) + ") of the steady Newton matrix";
  block_ilu<double, B> rilu(rio);
  auto gmres_real = [&](const real_block& a, const vec<double>& rhs, double tol, const std::string& what) {
    krylov_options ko = sopt.krylov;
    ko.relative_tolerance = tol;
    ko.throw_on_failure = true;
    ko.context = what;
    vec<double> xp = vec<double>::Zero(padded);
    const krylov_report rep = gmres<double>(a, rilu, pad(rhs), xp, ko);
    acc.steady_linear_iterations += rep.iterations;
    return vec<double>(xp.head(n));
  };
  // Inexact-Newton forcing (file comment) for a residual of norm fn converging to abs_tol.
  auto forcing = [&](double fn, double abs_tol) { return internal::inexact_forcing(fn, abs_tol, sopt.eta_max); };
  // Newton on f(w, mu; nu) = 0 from w (file comment); throws convergence_error naming nu.
  auto steady_solve = [&](double nu, double mu, vec<double> w) -> vec<double> {
    const auto t0 = clock::now();
    const std::string what = internal::concat(lab, ": steady state at nu = ", nu);
    try {
      const S& sys = system_at(cur, nu);
      equilibrium_krylov_options eo;
      eo.fill_level = sopt.fill_level;
      eo.newton = sopt.steady;
      eo.newton.observer = nullptr;
      eo.eta_max = sopt.eta_max;
      eo.krylov = sopt.krylov;
      // rilu keeps the BILU of the start's lhs_jacobian (dw0/dnu reuses it)
      newton_result nr =
          internal::equilibrium_newton_krylov<B>(sys, mu, std::move(w), eo, rilu, acc.steady_linear_iterations, what);
      acc.steady_solves += 1;
      acc.steady_iterations += nr.report.iterations;
      acc.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      return std::move(nr.x);
    } catch (const convergence_error&) {
      acc.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      throw;
    } catch (const error& e) {  // e.g. a non-physical state or a singular pivot: a failed solve
      acc.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
      throw convergence_error(what + ": " + e.what());
    }
  };
  auto find_equilibrium = [&](double nu) -> equilibrium* {
    for (auto& e : cache)
      if (e.nu == nu) return &e;
    return nullptr;
  };
  // dw/dnu = -f_w^{-1} f_nu at the flow state w (f_w = a; rilu holds the BILU of its
  // preconditioner), f_nu by central differences in nu
  auto flow_nu_derivative = [&](const vec<double>& w, double mu, double nu, const real_block& a,
                                const std::string& what) {
    const double h = nu_h(nu);
    const vec<double> f_nu =
        (vec<double>(system_at(plus, nu + h).residual(w, mu)) - vec<double>(system_at(minus, nu - h).residual(w, mu))) /
        (2 * h);
    return gmres_real(a, vec<double>(-f_nu), sopt.derivative_tolerance, what);
  };
  // dw0/dnu at a solved equilibrium (f_w = a, preconditioner BILU of lb).
  auto ensure_derivative = [&](equilibrium& e, double mu, const real_block& a, const real_block& lb) {
    if (e.dw.size() == n) return;
    const auto t0 = clock::now();
    rilu.compute(lb);
    e.dw = flow_nu_derivative(e.w, mu, e.nu, a, internal::concat(lab, ": dw0/dnu at nu = ", e.nu, ", GMRES"));
    acc.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
  };
  internal::family_cache<F, S> aux(family);  // for dw0/dnu at a cached nu other than the current one
  // The solved equilibrium nearest to nu, with its dw0/dnu.
  auto nearest_equilibrium = [&](double nu, double mu) -> equilibrium& {
    require(!cache.empty(), lab, ": no equilibrium to start the steady solve at nu = ", nu, " from");
    equilibrium* best = &cache.front();
    for (auto& e : cache)
      if (std::abs(e.nu - nu) < std::abs(best->nu - nu)) best = &e;
    if (best->dw.size() != n) {
      const S& sb = system_at(aux, best->nu);
      const auto [a, lb] = internal::exact_and_lhs_blocks<B>(sb, best->w, mu, lab);
      ensure_derivative(*best, mu, a, lb);
    }
    return *best;
  };
  // Keeps w0(nu) (replacing an entry at the same nu; the oldest goes when the cache is full).
  auto remember = [&](double nu, vec<double> w, vec<double> dw, double mu) -> equilibrium& {
    if (equilibrium* e = find_equilibrium(nu)) {
      e->w = std::move(w);
      e->dw = std::move(dw);
      e->mu = mu;
      return *e;
    }
    if (cache.size() >= std::max<std::size_t>(sopt.equilibrium_cache, 2)) cache.erase(cache.begin());
    cache.push_back({nu, std::move(w), std::move(dw), mu});
    return cache.back();
  };
  // w0(nu) (solved if not cached), warm-started from the nearest cached nu along its dw0/dnu.
  auto equilibrium_at = [&](double nu, double mu) -> equilibrium& {
    if (equilibrium* e = find_equilibrium(nu)) return *e;
    equilibrium* best = &nearest_equilibrium(nu, mu);
    // warm starts in turn: linear extrapolation, the nearest equilibrium, the user's start
    vec<double> w;
    std::string failures;
    for (int attempt = 0; attempt < 3 && w.size() == 0; ++attempt) {
      if (attempt == 2 && !sopt.equilibrium_start) break;
      try {
        vec<double> w0 = attempt == 0   ? vec<double>(best->w + (nu - best->nu) * best->dw)
                         : attempt == 1 ? best->w
                                        : sopt.equilibrium_start(nu);
        require(w0.size() == n, lab, ": equilibrium_start(", nu, ") has ", w0.size(), " entries, system ", n);
        w = steady_solve(nu, mu, std::move(w0));
      } catch (const error& e) {
        failures += internal::concat(failures.empty() ? "" : "; ",
                                     attempt == 0 ? "from the extrapolated" : attempt == 1 ? "from the nearest" : "from the user's",
                                     " start: ", e.what());
      }
    }
    if (w.size() == 0)
      throw convergence_error(internal::concat(lab, ": no steady state at nu = ", nu, " (", failures, ")"));
    return remember(nu, std::move(w), vec<double>(), mu);
  };

  // ---- the Hopf residual and the bordered linear solves ----
  // G(x) at the flow state w (the equilibrium w0(nu) in the nested scheme, the current iterate
  // in the joint one)
  auto hopf_residual = [&](const vec<double>& x, const vec<double>& w, const vec<double>& s, const double* c,
                           double value) {
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const S& sys = system_at(cur, nu);
    const vec<double> pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    vec<double> f(N);
    f.segment(ipr, n) = jacobian_product(sys, w, mu, pr) + om * pi;
    f.segment(ipi, n) = jacobian_product(sys, w, mu, pi) - om * pr;
    f[imu] = s.dot(pr);
    f[inu] = s.dot(pi) - 1.0;
    f[iom] = c[0] * x[imu] + c[1] * x[inu] + c[2] * x[iom] - value;
    return f;
  };
  auto residual = [&](const vec<double>& x, const vec<double>& s, const double* c, double value) {
    return hopf_residual(x, equilibrium_at(x[inu], x[imu]).w, s, c, value);
  };
  block_ilu_options cio;
  cio.fill_level = sopt.fill_level;
  cio.context = lab + ": complex BILU(" + std::to_string(sopt.fill_level) + ") of L - i omega I";
  block_ilu<C, B> cilu(cio);
  // Solves J(x) dx = rhs (J with the last row c) by GMRES with the bordered complex-BILU
  // preconditioner; throws convergence_error / singular_matrix_error.
  // At the flow state w with a = f_w(w) (exact) and lb (modified order), and dw_nu the change of
  // the flow with nu that the column G_nu follows (dw0/dnu; the joint scheme's -f_w^{-1} f_nu).
  auto solve_bordered_at = [&](const vec<double>& x, const vec<double>& w, const vec<double>& dw_nu,
                               const real_block& a, const real_block& lb, const vec<double>& s, const double* c,
                               const vec<double>& rhs, double tol, const std::string& what) {
    const double mu = x[imu], nu = x[inu], om = x[iom];
    const S& sys = system_at(cur, nu);
    const vec<double> pr = x.segment(ipr, n), pi = x.segment(ipi, n);
    const M amu = jacobian_d_mu(sys, w, mu);
    // G_nu by central differences along the linearly extrapolated equilibrium (file comment)
    const double h = nu_h(nu);
    const S& sp = system_at(plus, nu + h);
    const S& sm = system_at(minus, nu - h);
    const vec<double> wp = w + h * dw_nu, wm = w - h * dw_nu;
    const vec<double> gr = (jacobian_product(sp, wp, mu, pr) - jacobian_product(sm, wm, mu, pr)) / (2 * h);
    const vec<double> gi = (jacobian_product(sp, wp, mu, pi) - jacobian_product(sm, wm, mu, pi)) / (2 * h);
    cilu.compute(shifted(lb, C(0.0, om)));
    const internal::real_split_shifted_operator<std::decay_t<decltype(a)>> inner(a, om, n);
    const internal::complex_preconditioner_split_form<std::decay_t<decltype(cilu)>> inner_pre(cilu, n, padded);
    Eigen::MatrixXd u(2 * n, 3), vt = Eigen::MatrixXd::Zero(3, 2 * n), d = Eigen::MatrixXd::Zero(3, 3);
    u.col(0) << amu * pr, amu * pi;
    u.col(1) << gr, gi;
    u.col(2) << pi, -pr;
    vt.row(0).head(n) = s.transpose();
    vt.row(1).tail(n) = s.transpose();
    for (int k = 0; k < 3; ++k) d(2, k) = c[k];
    const bordered_operator<decltype(inner), double> jop(inner, 2 * n, std::move(u), std::move(vt), std::move(d));
    const bordered_preconditioner<decltype(inner_pre), double> jpre(jop, inner_pre);
    krylov_options ko = sopt.krylov;
    ko.relative_tolerance = tol;
    ko.context = what;
    ko.throw_on_failure = true;
    vec<double> dx = vec<double>::Zero(N);
    const krylov_report rep = gmres<double>(jop, jpre, rhs, dx, ko);
    acc.linear_iterations += rep.iterations;
    return dx;
  };
  // J(x) dx = rhs at the equilibrium w0(nu) (solved if not cached)
  auto solve_bordered = [&](const vec<double>& x, const vec<double>& s, const double* c, const vec<double>& rhs,
                            double tol, const std::string& what) {
    const double mu = x[imu], nu = x[inu];
    equilibrium& e = equilibrium_at(nu, mu);
    const auto [a, lb] = internal::exact_and_lhs_blocks<B>(system_at(cur, nu), e.w, mu, lab);
    ensure_derivative(e, mu, a, lb);
    return solve_bordered_at(x, e.w, e.dw, a, lb, s, c, rhs, tol, what);
  };

  struct corrected {
    vec<double> x;
    int iterations = 0;
    double omega_floor = 0;  ///< the smallest |omega| its Newton run resolves (hopf.hpp)
  };
  std::string last_failure;
  // Post-checks of a converged corrector (hopf.hpp). The equilibrium w0(nu*) it used must hold
  // at mu* as it did where it was solved: ||f(w0, mu*)|| <= ||f(w0, mu_solved)|| +
  // steady.abs_tolerance (mu_solved = mu* for the joint corrector, whose residual holds f; for
  // the nested one this catches an equilibrium that moves with mu, which the fixed-equilibrium
  // Hopf system cannot follow). The frequency floor 10 ||G|| / ||p|| goes to the caller
  // (below it: the Bogdanov-Takens end). nullopt and last_failure when refused.
  auto post_check = [&](vec<double> x, const newton_report& rep, const newton_options& no) -> std::optional<corrected> {
    const double r = internal::hopf_resolved_residual(rep, no);
    const double mu = x[imu], nu = x[inu];
    const equilibrium& e = equilibrium_at(nu, mu);  // cached: the corrector's last residual was at this nu
    const S& sys = system_at(cur, nu);
    const double fn = internal::hopf_norm(vec<double>(sys.residual(e.w, mu)));
    const double f_solved = e.mu == mu ? fn : internal::hopf_norm(vec<double>(sys.residual(e.w, e.mu)));
    const std::string why =
        internal::curve_equilibrium_check(fn, f_solved + sopt.steady.abs_tolerance, nu, mu, x[iom]);
    if (!why.empty()) {
      last_failure = why;
      return std::nullopt;
    }
    const double floor = internal::hopf_frequency_floor(r, x.segment(ipr, 2 * n).norm());
    return corrected{std::move(x), rep.iterations, floor};
  };
  // GMRES tolerance of a corrector iteration at residual norm fn (file comment)
  auto corrector_tolerance = [&](double fn) {
    return sopt.adaptive_tolerance ? forcing(fn, opt.newton.abs_tolerance)
                                   : std::min(sopt.krylov.relative_tolerance, 0.5);
  };
  // Cheap failure (file comment): an iterate x farther than radius from the prediction x0.
  auto check_radius = [&](const vec<double>& x, const vec<double>& x0, double radius, const char* who) {
    const double d = ydist(x, x0);
    if (!(d <= radius))
      throw convergence_error(internal::concat(lab, " ", who, ": iterate at nu = ", x[inu], ", mu = ", x[imu], " lies ",
                                               d, " from the prediction (more than ", radius, ")"));
  };
  // Joint corrector (fixed_equilibrium_hopf_curve_options::joint_equilibrium, file comment): Newton on
  // [x; w] with f(w, mu; nu) = 0 as n more equations (scaled so that the Hopf tolerance on the
  // whole residual is the steady tolerance on f), each step by block elimination.
  auto correct_joint = [&](const vec<double>& x0, const vec<double>& s, const double* c, double value,
                           double radius) -> std::optional<corrected> {
    const double fscale = opt.newton.abs_tolerance / sopt.steady.abs_tolerance;
    newton_options no = opt.newton;
    no.throw_on_failure = true;
    vec<double> dw_nu_last;
    internal::hopf_iterate_log last(x0, imu, iom, inu);
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
            r.tail(n) = fscale * vec<double>(system_at(cur, x[inu]).residual(w, x[imu]));
            return r;
          },
          [&](const vec<double>& X, const vec<double>& r, int it) {
            last.record(X, r, it);
            const auto t0 = clock::now();
            const vec<double> x = X.head(N), w = X.tail(n);
            const double mu = x[imu], nu = x[inu];
            const std::string what = internal::concat(lab, ": joint corrector iteration ", it, " at nu = ", nu);
            const S& sys = system_at(cur, nu);
            const auto [a, lb] = internal::exact_and_lhs_blocks<B>(sys, w, mu, what);
            rilu.compute(lb);
            // the flow rows: dw = dw_a + dnu dw_nu (the f_mu dmu term left out: f_mu = 0 at the
            // equilibrium, so the step's error vanishes at the solution and the rate stays quadratic)
            const vec<double> f = r.tail(n) / fscale;
            const double fn = f.norm();
            vec<double> dwa = vec<double>::Zero(n);
            if (fn > 0)
              dwa = gmres_real(a, vec<double>(-f), forcing(fn, sopt.steady.abs_tolerance), what + ", GMRES for the flow step");
            vec<double> dwnu = flow_nu_derivative(w, mu, nu, a, what + ", GMRES for dw/dnu");
            acc.steady_iterations += 1;
            acc.steady_seconds += std::chrono::duration<double>(clock::now() - t0).count();
            // the Hopf rows: G_x dx + G_w dw_nu dnu = -G - G_w dw_a, G_w dw_a = d/de A(w + e dw_a) p by
            // central differences
            vec<double> rhs = -r.head(N);
            const double da = dwa.template lpNorm<Eigen::Infinity>();
            if (da > 0) {
              const double e = std::cbrt(Eigen::NumTraits<double>::epsilon()) *
                               std::max(1.0, w.template lpNorm<Eigen::Infinity>()) / da;
              const vec<double> wp = w + e * dwa, wm = w - e * dwa;
              for (const Eigen::Index i0 : {ipr, ipi}) {
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
          std::move(X0), no, lab + " joint corrector");
      if (!nr.x.allFinite()) {
        last_failure = "joint corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      vec<double> x = nr.x.head(N);
      // dw0/dnu of the last step's iterate: it differs from the converged flow by that step only
      remember(x[inu], nr.x.tail(n), std::move(dw_nu_last), x[imu]);
      return post_check(std::move(x), nr.report, no);
    } catch (const error& e) {
      last_failure = e.what() + last.describe();
      return std::nullopt;
    }
  };
  // joint corrector for this attempt: each step's first (joint_equilibrium), the nested one for
  // the retries after it failed (file comment)
  bool joint_now = sopt.joint_equilibrium;
  auto correct = [&](const vec<double>& x0, const vec<double>& s, const double* c, double value,
                     double radius) -> std::optional<corrected> {
    if (joint_now) return correct_joint(x0, s, c, value, radius);
    newton_options no = opt.newton;
    no.throw_on_failure = true;
    internal::hopf_iterate_log last(x0, imu, iom, inu);
    try {
      newton_result nr = newton_iterate(
          [&](const vec<double>& x) {
            check_radius(x, x0, radius, "corrector");
            return residual(x, s, c, value);
          },
          [&](const vec<double>& x, const vec<double>& f, int it) {
            last.record(x, f, it);
            return vec<double>(solve_bordered(x, s, c, vec<double>(-f), corrector_tolerance(f.norm()),
                                              internal::concat(lab, ": GMRES at corrector iteration ", it)));
          },
          x0, no, lab + " corrector");
      if (!nr.x.allFinite()) {
        last_failure = "corrector returned a non-finite point" + last.describe();
        return std::nullopt;
      }
      return post_check(std::move(nr.x), nr.report, no);
    } catch (const error& e) {
      last_failure = e.what() + last.describe();
      return std::nullopt;
    }
  };

  auto make_point = [&](const vec<double>& x, int iters, int attempts, double step, double secs, bool landed) {
    hopf_curve_point pt;
    pt.w = equilibrium_at(x[inu], x[imu]).w;  // cached: the corrector's last residual was at this nu
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
               << "  mu " << pt.mu << "  omega " << pt.omega << "  newton " << pt.newton_iterations << "  gmres "
               << acc.linear_iterations << "  steady " << acc.steady_solves << " (" << acc.steady_iterations
               << " its)  step " << std::setprecision(4) << pt.step << "  " << std::setprecision(3) << pt.seconds << " s"
               << (pt.attempts > 1 ? "  (" + std::to_string(pt.attempts - 1) + " retries)" : "")
               << (pt.landed ? "  (landed)" : "") << std::setprecision(6) << std::endl;
    if (opt.observer) opt.observer(pt);
    if (sopt.observer) sopt.observer(pt, acc);
    res.linear_iterations += acc.linear_iterations;
    res.steady_solves += acc.steady_solves;
    res.steady_iterations += acc.steady_iterations;
    res.steady_seconds += acc.steady_seconds;
    res.stats.push_back(acc);
    acc = {};
    stop_requested = opt.stop_after && opt.stop_after(pt);
    res.points.push_back(std::move(pt));
  };
  auto finish = [&](hopf_curve_stop why, std::string reason) {
    res.stop = why;
    res.stop_reason = std::move(reason);
    res.seconds = std::chrono::duration<double>(clock::now() - t_begin).count();
    if (opt.verbose && opt.log) *opt.log << lab << ": stop: " << res.stop_reason << std::endl;
    return res;
  };
  auto seconds_since = [](clock::time_point t) { return std::chrono::duration<double>(clock::now() - t).count(); };

  // ---- the start: equilibrium at nu0, then the fixed-equilibrium Hopf point there ----
  const auto t_start = clock::now();
  hopf_result h0;
  {
    check_state(system_at(cur, nu0), start.w, start.mu, "trace_fixed_equilibrium_hopf_curve");
    vec<double> w0 = steady_solve(nu0, start.mu, start.w);
    cache.push_back({nu0, w0, vec<double>(), start.mu});
    hopf_point g = start;
    g.w = std::move(w0);
    hopf_options ho = opt.start;
    ho.fixed_equilibrium = true;
    ho.normalisation = opt.normalisation;
    // the equilibrium holds to what the nested steady solve reached (post-checks, hopf.hpp)
    ho.equilibrium_tolerance = std::max(
        ho.equilibrium_tolerance,
        internal::hopf_norm(vec<double>(system_at(cur, nu0).residual(g.w, start.mu))) + sopt.steady.abs_tolerance);
    ho.label = lab + ": start point at nu = " + internal::concat(nu0);
    hopf_krylov_options ko;
    ko.fill_level = sopt.fill_level;
    h0 = solve_hopf_krylov<B>(system_at(cur, nu0), g, ho, ko);
    require(h0.report.converged, lab, ": start point at nu = ", nu0, " did not converge (", h0.report.reason, ")");
    acc.linear_iterations += h0.linear_iterations;
  }
  require(h0.point.omega > opt.omega_min, lab, ": start point has omega = ", h0.point.omega,
          " <= omega_min (not a Hopf point)");
  vec<double> x(N);
  set_p(x, h0.point.p);
  x[imu] = h0.point.mu;
  x[inu] = nu0;
  x[iom] = h0.point.omega;
  vec<double> s = refresh_s(x);

  // Exact tangent at x: J t = e_last with the last row c, normalised in the metric.
  auto exact_tangent = [&](const vec<double>& xx, const vec<double>& ss, const double* c) {
    vec<double> e = vec<double>::Zero(N);
    e[iom] = 1;
    vec<double> tt = solve_bordered(xx, ss, c, e, sopt.tangent_tolerance, lab + ": GMRES for the tangent");
    const double tn = std::sqrt(ydot(tt, tt));
    if (!(std::isfinite(tn) && tn > 0)) throw singular_matrix_error(lab + ": tangent is not finite");
    return vec<double>(tt / tn);
  };
  vec<double> t;
  {
    const double c_nu[3] = {0, 1, 0};
    try {
      t = exact_tangent(x, s, c_nu);
    } catch (const error& e) {
      throw convergence_error(internal::concat(lab, ": no tangent dX/dnu at the start (nu = ", nu0, ", mu = ", x[imu],
                                               "): a turning point of the curve in nu or a degenerate Hopf point? ",
                                               e.what()));
    }
    if (t[inu] * direction < 0) t = -t;
  }
  emit(make_point(x, h0.report.iterations, 1, 0.0, seconds_since(t_start), false));
  if (res.points.size() >= size_t(opt.max_points)) return finish(hopf_curve_stop::max_points, "max_points reached");
  if (stop_requested) return finish(hopf_curve_stop::requested, "stop requested by stop_after");

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

  // Retrace test: y of xx within a quarter step (metric) of the polyline of the points traced
  // before the last three (a step that turned back at a kink and runs over the curve again).
  auto revisits = [&](const vec<double>& xx, double step) {
    const std::size_t m = res.points.size();
    if (m < 5) return false;
    auto yp = [&](const hopf_curve_point& p) { return Eigen::Vector3d(p.mu, p.nu, p.omega); };
    Eigen::Vector3d w3(sig[0] > 0 ? 1 / sig[0] : 0.0, sig[1] > 0 ? 1 / sig[1] : 0.0, sig[2] > 0 ? 1 / sig[2] : 0.0);
    const Eigen::Vector3d y = Eigen::Vector3d(xx[imu], xx[inu], xx[iom]).cwiseProduct(w3);
    for (std::size_t k = opt.detect_closed ? 1 : 0; k + 4 < m; ++k) {  // closing on the start: detect_closed
      const Eigen::Vector3d a = yp(res.points[k]).cwiseProduct(w3), b = yp(res.points[k + 1]).cwiseProduct(w3);
      const Eigen::Vector3d ab = b - a;
      const double l2 = ab.squaredNorm();
      const double th = l2 > 0 ? std::clamp((y - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
      if ((y - a - th * ab).norm() < 0.25 * step) return true;
    }
    return false;
  };
  const vec<double> x_first = x;
  vec<double> x_prev;
  double ds = std::min(opt.step, opt.max_step), arclength = 0;
  // An aerohopf::error escaping the step (a steady solve for a point's equilibrium, a
  // normalisation that breaks down) ends the trace like a step failure: rethrown with the last
  // point's context (same type), or with throw_on_failure = false a step_failure stop keeping
  // the points.
  try {
    for (;;) {
      const auto t_point = clock::now();
      int attempts = 0;
      bool exact_t = false;
      const vec<double> t_secant = t;  // the direction of travel so far (t may become the exact tangent)
      joint_now = sopt.joint_equilibrium;
      std::optional<corrected> xn;
      bool kink_tried = false;  // the kink fallback at this step size
      // Local parametrisation (file comment): the same step at fixed nu or mu at its value
      // predicted along the secant; nu first (the kinks lie on lines nu = const) unless the
      // curve is nearly vertical in nu there, then the other one (at a kink where one of
      // them reverses, only the other crosses it). True: xn holds the accepted point.
      auto kink_step = [&]() -> bool {
        kink_tried = true;
        const double rnu = std::abs(t_secant[inu]) / sig[1], rmu = std::abs(t_secant[imu]) / sig[0];
        const int order[2] = {rnu >= 0.1 * rmu ? 1 : 0, rnu >= 0.1 * rmu ? 0 : 1};
        const vec<double> xp = x + ds * t_secant;
        for (int j : order) {
          double c[3] = {0, 0, 0};
          c[j] = 1;
          auto xk = correct(xp, s, c, yv(xp, j), sopt.iterate_distance * ds);
          if (xk) {
            const double dist = ydist(xk->x, x);
            const bool forward = ydot(vec<double>(xk->x - x), t_secant) > 0 && !revisits(xk->x, ds);
            if (forward && dist <= sopt.kink_distance * ds) {
              xn = std::move(xk);
              ++res.kink_steps;
              if (opt.verbose && opt.log)
                *opt.log << lab << ": step " << ds << " from nu = " << x[inu] << ", mu = " << x[imu] << " taken at fixed "
                         << (j ? "nu" : "mu") << " (a kink of the curve?)" << std::endl;
              break;
            }
            last_failure = forward ? internal::concat("fixed-", j ? "nu" : "mu", " step landed ", dist,
                                                      " from the last point (step ", ds, ")")
                                   : internal::concat("fixed-", j ? "nu" : "mu", " step went back along the curve");
          } else {
            last_failure = internal::concat("fixed-", j ? "nu" : "mu", " step failed: ", last_failure);
          }
          if (opt.verbose && opt.log) *opt.log << lab << ": " << last_failure << std::endl;
        }
        return xn.has_value();
      };
      for (;;) {
        ++attempts;
        const vec<double> xp = x + ds * t;
        double c[3], value = 0;
        for (int j = 0; j < 3; ++j) {
          c[j] = sig[j] > 0 ? yv(t, j) / (sig[j] * sig[j]) : 0.0;
          value += c[j] * yv(xp, j);
        }
        xn = correct(xp, s, c, value, sopt.iterate_distance * ds);
        const bool diverged = !xn;  // the corrector failed (not: converged to a point rejected below)
        if (xn) {
          const double moved = ydist(xn->x, xp);
          const vec<double> d = xn->x - x;
          const double dn = std::sqrt(ydot(d, d));
          if (!(moved <= opt.corrector_distance * ds)) {
            last_failure = internal::concat("corrector moved ", moved, " from the prediction (step ", ds, ")");
            xn.reset();
          } else if (!(ydot(d, t) > opt.min_cosine * dn)) {
            last_failure = "the corrected point lies behind the last point or off the predicted direction";
            xn.reset();
          } else if (!(ydot(d, t_secant) > 0)) {
            // after the exact-tangent retry at a kink: a step back along the traced curve
            last_failure = "the corrected point goes back along the traced curve";
            xn.reset();
          } else if (revisits(xn->x, ds)) {
            last_failure = "the corrected point lies on a stretch of the curve traced before";
            xn.reset();
          }
        }
        if (xn) break;
        ++res.failed_correctors;
        joint_now = false;  // the retries of this step: nested steady solves (file comment)
        // A corrector that diverged from the secant prediction: the kink fallback first (file comment)
        if (diverged && sopt.kink_fallback && !kink_tried) {
          if (opt.verbose && opt.log)
            *opt.log << lab << ": step " << ds << " from nu = " << x[inu] << ", mu = " << x[imu] << " failed ("
                     << last_failure << "), trying it at fixed nu or mu" << std::endl;
          if (kink_step()) break;
        }
        bool retry_same = false;
        if (!exact_t && res.points.size() > 1) {
          try {
            double cc[3];
            for (int j = 0; j < 3; ++j) cc[j] = sig[j] > 0 ? yv(t, j) / (sig[j] * sig[j]) : 0.0;
            vec<double> te = exact_tangent(x, s, cc);
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
                   << last_failure << "), " << (retry_same ? "retrying along the exact tangent" : "halving") << std::endl;
        if (retry_same) continue;
        if (sopt.kink_fallback && !kink_tried && kink_step()) break;
        kink_tried = false;
        ds *= 0.5;
        if (ds < opt.min_step) {
          const std::string why = internal::concat(
              lab, ": step fell below min_step = ", opt.min_step, " after the point nu = ", x[inu], ", mu = ", x[imu],
              ", omega = ", x[iom], " (point ", res.points.size() - 1, "); last attempted step ", 2 * ds,
              ", last failure: ", last_failure);
          if (opt.throw_on_failure) throw convergence_error(why);
          return finish(hopf_curve_stop::step_failure, why);
        }
      }
      vec<double> xnew = std::move(xn->x);
      const int iters = xn->iterations;
      const double step_seconds = seconds_since(t_point);
      // costs of this step, kept apart from those of landings emitted before xnew
      const fixed_equilibrium_hopf_curve_stats step_costs = std::exchange(acc, fixed_equilibrium_hopf_curve_stats{});
      auto add_step_costs = [&] {
        acc.linear_iterations += step_costs.linear_iterations;
        acc.steady_solves += step_costs.steady_solves;
        acc.steady_iterations += step_costs.steady_iterations;
        acc.steady_linear_iterations += step_costs.steady_linear_iterations;
        acc.steady_seconds += step_costs.steady_seconds;
      };

      // ---- Bogdanov-Takens: omega reaches zero (or below what the corrector resolves) ----
      const double omega_floor = xn->omega_floor;
      if (xnew[iom] <= std::max(opt.omega_min, omega_floor)) {
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
        add_step_costs();
        if (xnew[iom] > omega_floor)  // a Hopf point with a resolved frequency
          emit(make_point(xnew, iters, attempts, ydist(xnew, x), step_seconds, false));
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
        joint_now = sopt.joint_equilibrium;
        auto xl = correct(x0, s, c, l.value, sopt.iterate_distance * ds);
        if (!xl && joint_now) {
          joint_now = false;
          xl = correct(x0, s, c, l.value, sopt.iterate_distance * ds);
        }
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
                     << std::endl;
          if (!l.bound) res.missed_targets.push_back(l.value);
        }
        if (l.bound) {
          if (!xl) {
            add_step_costs();
            emit(make_point(xnew, iters, attempts, ydist(xnew, x), step_seconds, false));
          }
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
      add_step_costs();
      emit(make_point(xnew, iters, attempts, len, step_seconds, false));
      if (res.points.size() >= size_t(opt.max_points)) return finish(hopf_curve_stop::max_points, "max_points reached");
      if (stop_requested) return finish(hopf_curve_stop::requested, "stop requested by stop_after");
      s = refresh_s(xnew);
      x_prev = std::move(x);
      rescale_p(x_prev, s);
      t = xnew - x_prev;
      t /= std::sqrt(ydot(t, t));
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
