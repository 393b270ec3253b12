#pragma once
// Direct calculation of a Hopf (flutter) point by Newton's method on the augmented system of
// Griewank and Reddien (spec 02). Unknowns W = [w, p_r, p_i, mu, omega], fixed real vector s:
//
//   F_A = [ f(w, mu);  A p_r + omega p_i;  A p_i - omega p_r;  s.p_r;  s.p_i - 1 ] = 0
//
//   J_A = [ A          0         0         f_mu        0
//           A_w p_r    A         omega I   A_mu p_r    p_i
//           A_w p_i   -omega I   A         A_mu p_i   -p_r
//           0          s^T       0         0           0
//           0          0         s^T       0           0   ]
//
// The fixed-equilibrium case (w0 does not depend on mu, e.g. a symmetric aerofoil at
// zero incidence) drops the first block row and column: unknowns [p_r, p_i, mu, omega].
//
// Structure: hopf_problem holds either formulation (unknowns, s, the exact F_A, unpacking and
// post-checks); hopf_newton is the one Newton driver; the Newton correction comes from a linear
// strategy: hopf_augmented_lu (here: LU of the real J_A), hopf_bordered_direct and
// hopf_bordered_krylov (hopf_bordered.hpp: block elimination on A - i omega I, by complex LU or
// BILU-GMRES). solve_hopf, solve_hopf_bordered and solve_hopf_krylov pick one of each.
//
// The right-hand side products A p are evaluated matrix-free with the EXACT residual (one
// taylor<double,1> pass when the residual is templated); the left-hand-side matrix may be the
// system's approximate Jacobian (hopf_options::approximate_lhs) at the price of losing
// quadratic convergence. Start: p from shift-invert inverse power at i omega_guess.
//
// The normalisation vector s is any fixed vector with s.p_i != 0. Two choices:
//  * eigenvector (the original work): phase of p rotated so that p_r is orthogonal to p_i,
//    s = p_i/|p_i|, p scaled so that s.p_i = 1;
//  * largest_component: s = e_k with k the largest component of p, whose phase is rotated to
//    make p_k = i (so s.p_r = 0, s.p_i = 1). The border rows s^T are then sparse: a dense row in
//    a sparse LU fills the factors (measured: 29x more non-zeros and 40x the time at 6,146
//    unknowns), so this is the default for sparse Jacobians.
//
// Post-checks (hopf_problem::result, so every strategy of hopf_newton). Newton
// stops at ||F_A|| <= r, r = max(abs_tolerance + rel_tolerance ||F_0||, ||F_final||) (the
// second term covers the rounding-floor criterion of newton.hpp). A converged point is accepted
// only if
//  * w* is an equilibrium at mu*: ||f(w*, mu*)|| <= r in the full formulation (f is its first
//    block, so this only confirms it), and <= max(equilibrium_tolerance, equilibrium_factor r)
//    in the fixed-equilibrium one, where f is not among the equations and w was converged by
//    another solver (steady CFD solves stop at a relative drop or their rounding floor:
//    measured 8e-11 to 8e-10 on the NACA 0012 very coarse and coarse grids against r = 1e-10,
//    hence the default factor 1e3). An equilibrium that moves with mu, or w from another mu,
//    leaves ||f(w, mu*)|| of the size of that movement, decades above;
//  * the frequency is resolved: the eigen-equations A p_r + omega p_i, A p_i - omega p_r change
//    by about |omega| ||p|| between omega and 0, so a root with |omega| ||p|| <= 10 r is
//    indistinguishable from omega = 0, a real eigenvalue (fold or divergence), not a Hopf point.
// A refused point is a convergence_error naming mu*, omega, ||f|| and the tolerance, or, with
// newton.throw_on_failure = false, a result with report.converged = false and that reason.
// A failure inside the Newton run (a non-finite residual, a singular matrix, a model that
// throws) is reported with the solver's label, the last accepted iterate's number, ||F||, mu
// and omega, keeping the exception type; with throw_on_failure = false (convergence and
// singular-matrix failures only: bad input always throws) the result holds that iterate, a
// valid guess to restart from.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <concepts>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/assemble.hpp"
#include "../linalg/direct.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "hopf_point.hpp"
#include "inverse_power.hpp"

namespace aerohopf {

enum class hopf_normalisation { automatic, eigenvector, largest_component };

struct hopf_options {
  newton_options newton = [] {
    newton_options o;
    o.abs_tolerance = 1e-10;
    o.max_iterations = 30;
    return o;
  }();
  bool approximate_lhs = false;  ///< use the system's approximate Jacobian in J_A
  bool fixed_equilibrium = false;        ///< w fixed (independent of mu): solve for [p_r, p_i, mu, omega]
  hopf_normalisation normalisation = hopf_normalisation::automatic;  ///< choice of s
  /// Acceptance of the equilibrium after convergence (see "Post-checks" in the file comment):
  /// ||f(w*, mu*)|| must not exceed max(equilibrium_tolerance, equilibrium_factor x the
  /// residual the Newton run resolved).
  double equilibrium_factor = 1e3;
  double equilibrium_tolerance = 0;  ///< absolute floor of that tolerance (0: none)
  bool verbose = false;
  std::ostream* log = &std::cout;
  std::string label = "hopf";
};

struct hopf_result {
  hopf_point point;      ///< p normalised with s.p_r = 0, s.p_i = 1
  vec<double> s;         ///< the normalisation vector used
  newton_report report;  ///< per-iteration residuals of the augmented system
  long linear_iterations = 0;  ///< Krylov iterations over all solves (0 for direct solvers)
  /// Wall-clock split: matrix assembly and factorisation (or preconditioner), linear solves,
  /// and residual evaluations (with the second-derivative products of the bordered full step).
  double setup_seconds = 0, linear_seconds = 0, residual_seconds = 0;
  bool start_refined = false;  ///< solve_hopf_krylov: the start refinement was kept
};

/// Rotates the phase of p and scales it so that s.p_r = 0 and s.p_i = 1 for the returned s
/// (see the file comment for the two choices). p is updated.
inline vec<double> hopf_normalise(vec<std::complex<double>>& p, hopf_normalisation mode = hopf_normalisation::eigenvector) {
  require(p.allFinite() && p.norm() > 0, "hopf_normalise: eigenvector is zero or not finite");
  if (mode == hopf_normalisation::largest_component) {
    Eigen::Index k = 0;
    p.cwiseAbs().maxCoeff(&k);
    p *= std::complex<double>(0.0, 1.0) / p[k];  // p_k = i exactly (up to rounding)
    p[k] = {0.0, 1.0};
    vec<double> s = vec<double>::Zero(p.size());
    s[k] = 1.0;
    return s;
  }
  // Maximise |Im(e^{i t} p)|: with a = Re p, b = Im p, |Im|^2 = |a sin t + b cos t|^2.
  const vec<double> a = p.real(), b = p.imag();
  const double aa = a.squaredNorm(), bb = b.squaredNorm(), ab = a.dot(b);
  // d/dt of (aa sin^2 + bb cos^2 + 2 ab sin cos) = 0  =>  tan 2t = 2 ab / (bb - aa)
  double t = 0.5 * std::atan2(2 * ab, bb - aa);
  p *= std::complex<double>(std::cos(t), std::sin(t));
  const double nb = p.imag().norm();
  vec<double> s = p.imag() / nb;
  p /= nb;  // now s.p_i = 1 and s.p_r = 0 (p_r orthogonal to p_i)
  return s;
}

/// `automatic` made concrete for matrix type M: largest_component for sparse, eigenvector for dense.
template <class M>
hopf_normalisation resolve_normalisation(hopf_normalisation requested) {
  if (requested != hopf_normalisation::automatic) return requested;
  return is_sparse_matrix_v<M> ? hopf_normalisation::largest_component : hopf_normalisation::eigenvector;
}

namespace internal {

/// Throws input_error naming the offending option unless the Newton and acceptance options of
/// a Hopf solve are usable: tolerances finite and >= 0 (not both zero), max_iterations >= 1,
/// relaxation in (0, 1], factors positive.
/// The Newton part of those checks; `name` is how the caller's options call the struct
/// ("newton", "start.newton", ...).
inline void check_newton_options(const newton_options& n, const std::string& where, const std::string& name) {
  auto finite_nonneg = [&](double v, const char* what) {
    require(std::isfinite(v) && v >= 0, where, ": ", name, ".", what, " must be finite and >= 0 (got ", v, ")");
  };
  finite_nonneg(n.abs_tolerance, "abs_tolerance");
  finite_nonneg(n.rel_tolerance, "rel_tolerance");
  finite_nonneg(n.step_tolerance, "step_tolerance");
  require(n.abs_tolerance > 0 || n.rel_tolerance > 0, where, ": ", name, ".abs_tolerance and ", name,
          ".rel_tolerance are both 0 (no convergence target)");
  require(n.max_iterations >= 1, where, ": ", name, ".max_iterations must be >= 1 (got ", n.max_iterations, ")");
  require(n.relaxation > 0 && n.relaxation <= 1, where, ": ", name, ".relaxation must lie in (0, 1] (got ",
          n.relaxation, ")");
  require(n.relax_until >= 0 && !std::isnan(n.relax_until), where, ": ", name, ".relax_until must be >= 0 (got ",
          n.relax_until, ")");
  require(n.divergence_factor > 0 && !std::isnan(n.divergence_factor), where, ": ", name,
          ".divergence_factor must be > 0 (got ", n.divergence_factor, ")");
  require(n.max_contraction > 0 && !std::isnan(n.max_contraction), where, ": ", name,
          ".max_contraction must be > 0 (got ", n.max_contraction, ")");
}

inline void check_hopf_options(const hopf_options& o, const std::string& where) {
  check_newton_options(o.newton, where, "newton");
  require(std::isfinite(o.equilibrium_factor) && o.equilibrium_factor >= 1, where,
          ": equilibrium_factor must be finite and >= 1 (got ", o.equilibrium_factor, ")");
  require(std::isfinite(o.equilibrium_tolerance) && o.equilibrium_tolerance >= 0, where,
          ": equilibrium_tolerance must be finite and >= 0 (got ", o.equilibrium_tolerance, ")");
}

/// ||v||_2, or NaN if an entry is not finite.
inline double hopf_norm(const vec<double>& v) { return v.allFinite() ? v.norm() : NAN; }

/// The entry checks of every Hopf solver: sizes and finiteness of the guess against sys.
template <dynamical_system S>
void check_hopf_guess(const S& sys, const hopf_point& g, const std::string& where) {
  const Eigen::Index n = sys.size();
  require(n > 0, where, ": the system has no unknowns");
  require_size(g.w.size(), n, where, "guess.w (equilibrium)");
  require_finite(g.w, where, "guess.w (equilibrium)");
  require_size(g.p.size(), n, where, "guess.p (eigenvector)");
  require_finite(g.p, where, "guess.p (eigenvector)");
  require(g.p.norm() > 0, where, ": guess.p (eigenvector) is zero");
  require(std::isfinite(g.mu), where, ": guess.mu is not finite (", g.mu, ")");
  require(std::isfinite(g.omega), where, ": guess.omega is not finite (", g.omega, ")");
}

/// ||F|| a converged Newton run guarantees: its target, or the residual it stopped at when the
/// rounding-floor criterion (newton.hpp) accepted a larger one.
inline double hopf_resolved_residual(const newton_report& rep, const newton_options& o) {
  const double f0 = rep.residual_history.empty() ? 0.0 : rep.residual_history.front();
  const double fin = rep.residual_history.empty() ? 0.0 : rep.residual_history.back();
  return std::max(o.abs_tolerance + o.rel_tolerance * f0, std::isfinite(fin) ? fin : 0.0);
}

/// Smallest |omega| the Hopf equations resolve at residual r with eigenvector norm ||p||: the
/// eigen-equations change by about |omega| ||p|| between omega and 0 (file comment).
inline double hopf_frequency_floor(double resolved, double p_norm) {
  return 10.0 * resolved / std::max(p_norm, 1e-300);
}

/// The post-checks of the file comment for a converged point h (omega already made >= 0).
/// Returns an empty string if h is accepted, else the reason.
template <dynamical_system S>
std::string hopf_post_check(const S& sys, const hopf_point& h, const newton_report& rep, const hopf_options& opt,
                            bool fixed_equilibrium) {
  const double r = hopf_resolved_residual(rep, opt.newton);
  const double tol_f = fixed_equilibrium ? std::max(opt.equilibrium_tolerance, opt.equilibrium_factor * r) : r;
  const double fn = hopf_norm(vec<double>(sys.residual(h.w, h.mu)));
  if (!(fn <= tol_f))
    return concat("the equilibrium does not hold at mu* = ", h.mu, " (omega = ", h.omega, "): ||f(w, mu*)|| = ", fn,
                  " > tolerance ", tol_f,
                  fixed_equilibrium
                      ? " (fixed-equilibrium formulation, hopf_options::fixed_equilibrium: w must be an equilibrium at every "
                        "mu; an equilibrium that moves with mu, or w from another mu? use the full formulation or "
                        "re-converge w at mu*)"
                      : "");
  const double pn = h.p.norm(), floor = hopf_frequency_floor(r, pn);
  if (!(std::abs(h.omega) > floor))
    return concat("converged to omega = ", h.omega, " at mu* = ", h.mu, ", below the resolved frequency ", floor,
                  " (10 ||F|| / ||p||, ||F|| <= ", r, ", ||p|| = ", pn,
                  "): a real eigenvalue (fold/divergence), not a Hopf point");
  return {};
}

/// Applies hopf_post_check to a converged result: on refusal throws convergence_error (label:
/// reason) or, with throw_on_failure = false, marks the report not converged with the reason.
template <dynamical_system S>
void hopf_accept(const S& sys, hopf_result& r, const hopf_options& opt, bool fixed_equilibrium) {
  if (!r.report.converged) return;
  const std::string why = hopf_post_check(sys, r.point, r.report, opt, fixed_equilibrium);
  if (why.empty()) return;
  if (opt.newton.throw_on_failure) throw convergence_error(opt.label + ": " + why);
  r.report.converged = false;
  r.report.reason = why;
}

/// Rethrows the exception being handled with `prefix` and `suffix` around its message, keeping
/// its aerohopf type (call only inside a catch block for aerohopf::error).
[[noreturn]] inline void rethrow_with_context(const std::string& prefix, const std::string& suffix) {
  try {
    throw;
  } catch (const input_error& e) {
    throw input_error(prefix + e.what() + suffix);
  } catch (const singular_matrix_error& e) {
    throw singular_matrix_error(prefix + e.what() + suffix);
  } catch (const convergence_error& e) {
    throw convergence_error(prefix + e.what() + suffix);
  } catch (const error& e) {
    throw error(prefix + e.what() + suffix);
  }
}

/// The last iterate a Hopf Newton run accepted (recorded by its step function, which is called
/// once per iteration with the current iterate and its residual): what a failure reports and
/// what a run with throw_on_failure = false returns to restart from.
struct hopf_iterate_log {
  int iteration = 0;       ///< 0: the start
  double residual = NAN;   ///< ||F|| there (NaN: not evaluated yet)
  double mu = NAN, omega = NAN, nu = NAN;
  vec<double> x;
  std::vector<double> history;

  /// x0: the start; imu, iom (and inu >= 0 for a curve tracer): where mu, omega (nu) are in x.
  hopf_iterate_log(const vec<double>& x0, Eigen::Index imu, Eigen::Index iom, Eigen::Index inu = -1)
      : mu(x0[imu]), omega(x0[iom]), nu(inu >= 0 ? x0[inu] : NAN), x(x0), imu_(imu), iom_(iom), inu_(inu) {}
  void record(const vec<double>& y, const vec<double>& f, int k) {
    iteration = k - 1;  // the step of iteration k starts from iterate k - 1
    residual = hopf_norm(f);
    mu = y[imu_];
    omega = y[iom_];
    if (inu_ >= 0) nu = y[inu_];
    x = y;
    if (history.size() < std::size_t(k)) history.push_back(residual);
  }
  std::string describe() const {
    return concat(" [last accepted iterate ", iteration, ": ||F|| = ", residual, inu_ >= 0 ? concat(", nu = ", nu) : "",
                  ", mu = ", mu, ", omega = ", omega, "]");
  }

 private:
  Eigen::Index imu_, iom_, inu_;
};

/// Runs the Newton iteration run() of a Hopf solver and puts the last accepted iterate into any
/// failure (file comment): an aerohopf::error is rethrown as the same type with "label: ... [last
/// accepted iterate ...]"; with throw_on_failure = false a convergence or singular-matrix failure
/// becomes a not-converged result at that iterate, and a Newton report that did not converge
/// gets the iterate appended to its reason.
template <class Run>
newton_result run_hopf_newton(Run&& run, const hopf_iterate_log& last, const hopf_options& opt) {
  try {
    newton_result nr = run();
    if (!nr.report.converged) nr.report.reason = opt.label + ": " + nr.report.reason + last.describe();
    return nr;
  } catch (const input_error&) {
    rethrow_with_context(opt.label + ": ", last.describe());
  } catch (const error& e) {
    if (opt.newton.throw_on_failure) rethrow_with_context(opt.label + ": ", last.describe());
    newton_result nr;
    nr.x = last.x;
    nr.report.converged = false;
    nr.report.reason = opt.label + ": " + e.what() + last.describe();
    nr.report.iterations = last.iteration;
    nr.report.residual_history = last.history;
    return nr;
  }
}

inline hopf_point hopf_point_from(const vec<double>& w, double mu, const eigen_pair& ep) {
  hopf_point h{w, mu, ep.lambda.imag(), ep.vector};
  if (h.omega < 0) {
    h.omega = -h.omega;
    h.p = h.p.conjugate().eval();
  }
  return h;
}
}  // namespace internal

/// Start point for the Hopf Newton iteration: inverse power at (w, mu) with shift i omega_guess.
template <dynamical_system S>
hopf_point hopf_start(const S& sys, const vec<double>& w, double mu, double omega_guess,
                      const inverse_power_options& ipo = {}) {
  check_state(sys, w, mu, "hopf_start");
  return internal::hopf_point_from(w, mu, inverse_power(sys.jacobian(w, mu), {0.0, omega_guess}, ipo));
}

/// The same with a solver for A - i omega_guess I (inverse_power.hpp), e.g. complex BILU(k) +
/// GMRES (krylov_solver) for CFD sizes.
template <dynamical_system S, class Solver>
hopf_point hopf_start(const S& sys, const vec<double>& w, double mu, double omega_guess,
                      const inverse_power_options& ipo, Solver& solver) {
  check_state(sys, w, mu, "hopf_start");
  return internal::hopf_point_from(w, mu, inverse_power(sys.jacobian(w, mu), {0.0, omega_guess}, ipo, nullptr, solver));
}

/// One Hopf problem in either formulation (file comment), from opt.fixed_equilibrium:
///  * full (3n + 2 unknowns y = [w, p_r, p_i, mu, omega]): the equilibrium moves with mu;
///  * fixed equilibrium (2n + 2 unknowns y = [p_r, p_i, mu, omega]): w = guess.w at every mu.
/// Holds the normalisation vector s, the start y0 (the guess with p normalised) and the exact
/// residual F_A (matrix-free eigen-equations); result() unpacks a Newton run and applies the
/// post-checks. Every Hopf solver is hopf_newton over this problem with a linear strategy.
template <dynamical_system S>
class hopf_problem {
 public:
  /// Checks the guess and opt (input_error naming `who`) and normalises guess.p.
  hopf_problem(const S& system, const hopf_point& guess, const hopf_options& opt, const std::string& who)
      : sys_(&system), fixed_(opt.fixed_equilibrium) {
    internal::check_hopf_guess(system, guess, who);
    internal::check_hopf_options(opt, who);
    n_ = system.size();
    off_ = fixed_ ? 0 : n_;
    vec<std::complex<double>> p = guess.p;
    s_ = hopf_normalise(p, resolve_normalisation<jacobian_t<S>>(opt.normalisation));
    y0_.resize(unknowns());
    if (fixed_) w_fixed_ = guess.w;
    else y0_.head(n_) = guess.w;
    y0_.segment(off_, n_) = p.real();
    y0_.segment(off_ + n_, n_) = p.imag();
    y0_[unknowns() - 2] = guess.mu;
    y0_[unknowns() - 1] = guess.omega;
  }

  const S& system() const { return *sys_; }
  bool fixed_equilibrium() const { return fixed_; }
  Eigen::Index size() const { return n_; }                  ///< n, the system's unknowns
  Eigen::Index unknowns() const { return off_ + 2 * n_ + 2; }  ///< 3n + 2 or 2n + 2
  Eigen::Index eigen_offset() const { return off_; }        ///< where p_r starts in y
  const vec<double>& s() const { return s_; }
  const vec<double>& start() const { return y0_; }

  vec<double> w(const vec<double>& y) const { return fixed_ ? w_fixed_ : vec<double>(y.head(n_)); }
  vec<double> p_re(const vec<double>& y) const { return y.segment(off_, n_); }
  vec<double> p_im(const vec<double>& y) const { return y.segment(off_ + n_, n_); }
  double mu(const vec<double>& y) const { return y[unknowns() - 2]; }
  double omega(const vec<double>& y) const { return y[unknowns() - 1]; }

  /// F_A(y) (file comment); the fixed-equilibrium formulation drops the first block f(w, mu).
  vec<double> residual(const vec<double>& y) const {
    const vec<double> wy = w(y), pr = p_re(y), pi = p_im(y);
    const double m = mu(y), om = omega(y);
    vec<double> f(unknowns());
    if (!fixed_) f.head(n_) = sys_->residual(wy, m);
    const auto [apr, api] = jacobian_product_pair(*sys_, wy, m, pr, pi);
    f.segment(off_, n_) = apr + om * pi;
    f.segment(off_ + n_, n_) = api - om * pr;
    f[unknowns() - 2] = s_.dot(pr);
    f[unknowns() - 1] = s_.dot(pi) - 1.0;
    return f;
  }

  /// The point of a Newton run with omega > 0 (a converged conjugate pair is the same point),
  /// after the post-checks (hopf_accept).
  hopf_result result(newton_result&& nr, const hopf_options& opt) const {
    hopf_result res;
    res.s = s_;
    res.report = std::move(nr.report);
    const vec<double>& y = nr.x;
    res.point.w = w(y);
    res.point.mu = mu(y);
    res.point.omega = omega(y);
    res.point.p = vec<std::complex<double>>(n_);
    res.point.p.real() = p_re(y);
    res.point.p.imag() = p_im(y);
    if (res.report.converged && res.point.omega < 0) {
      res.point.omega = -res.point.omega;
      res.point.p = res.point.p.conjugate().eval();
    }
    internal::hopf_accept(*sys_, res, opt, fixed_);
    return res;
  }

 private:
  const S* sys_;
  bool fixed_;
  Eigen::Index n_ = 0, off_ = 0;
  vec<double> s_, y0_, w_fixed_;
};

/// What a linear strategy of hopf_newton counts: Krylov iterations (0 for direct solvers) and
/// the wall-clock split of hopf_result.
struct hopf_linear_stats {
  long linear_iterations = 0;
  double setup_seconds = 0, linear_seconds = 0, residual_seconds = 0;
};

namespace internal {
using hopf_clock = std::chrono::steady_clock;
inline double seconds_since(hopf_clock::time_point t0) {
  return std::chrono::duration<double>(hopf_clock::now() - t0).count();
}

/// Progress line per Newton iteration of a Hopf solve with N unknowns, mu and omega last (with
/// the running linear-iteration count when `linear_iterations` is given); only with
/// opt.verbose and no observer of the caller's.
inline void add_hopf_progress(newton_options& nopt, const hopf_options& opt, Eigen::Index N,
                              const long* linear_iterations) {
  if (!opt.verbose || !opt.log || nopt.observer) return;
  std::ostream& os = *opt.log;
  nopt.observer = [&os, label = opt.label, N, linear_iterations](const newton_step_info& i) {
    os << label << " it " << std::setw(2) << i.iteration << "  |F| " << std::scientific << std::setprecision(3)
       << i.residual << "  mu " << std::setprecision(12) << std::defaultfloat << (*i.x)[N - 2] << "  omega "
       << (*i.x)[N - 1];
    if (linear_iterations) os << "  linear its " << *linear_iterations;
    os << (i.relaxation < 1 ? "  (relaxed)" : "") << "\n";
  };
}
inline void add_hopf_progress(newton_options& nopt, const hopf_options& opt, Eigen::Index N,
                              const long& linear_iterations) {
  add_hopf_progress(nopt, opt, N, &linear_iterations);
}
}  // namespace internal

/// A linear strategy of hopf_newton: the Newton correction dx of the problem's formulation at
/// the iterate y with residual f = F_A(y), its counts in `stats`, and the name of the system it
/// solves (for messages).
template <class L, class S>
concept hopf_linear_strategy = requires(L& l, const hopf_problem<S>& prob, const vec<double>& y, int it) {
  { l.newton_step(prob, y, y, it) } -> std::convertible_to<vec<double>>;
  { l.description(prob) } -> std::convertible_to<std::string>;
  { l.stats } -> std::convertible_to<hopf_linear_stats>;
  { L::reports_linear_iterations } -> std::convertible_to<bool>;
};

/// The Hopf Newton driver: Newton (newton_iterate: relaxation, tolerances, divergence guards)
/// on prob's F_A from prob.start(), the corrections from `strategy`, progress lines with
/// opt.verbose, failures naming the last accepted iterate (run_hopf_newton) and the post-checks
/// of the converged point (file comment).
template <dynamical_system S, class Strategy>
  requires hopf_linear_strategy<Strategy, S>
hopf_result hopf_newton(const hopf_problem<S>& prob, Strategy& strategy, const hopf_options& opt) {
  const Eigen::Index N = prob.unknowns();
  hopf_linear_stats& st = strategy.stats;
  auto residual = [&](const vec<double>& y) {
    const auto t0 = internal::hopf_clock::now();
    vec<double> f = prob.residual(y);
    st.residual_seconds += internal::seconds_since(t0);
    return f;
  };
  internal::hopf_iterate_log last(prob.start(), N - 2, N - 1);
  auto step = [&](const vec<double>& y, const vec<double>& f, int it) {
    last.record(y, f, it);
    return vec<double>(strategy.newton_step(prob, y, f, it));
  };
  newton_options nopt = opt.newton;
  internal::add_hopf_progress(nopt, opt, N, Strategy::reports_linear_iterations ? &st.linear_iterations : nullptr);
  const std::string what = opt.label + " (" + strategy.description(prob) + ")";
  newton_result nr = internal::run_hopf_newton(
      [&] { return newton_iterate(residual, step, prob.start(), nopt, what); }, last, opt);
  hopf_result r = prob.result(std::move(nr), opt);
  r.linear_iterations = st.linear_iterations;
  r.setup_seconds = st.setup_seconds;
  r.linear_seconds = st.linear_seconds;
  r.residual_seconds = st.residual_seconds;
  return r;
}

/// Linear strategy (a): the whole real augmented Jacobian J_A (file comment; 3n + 2 or 2n + 2)
/// assembled at every iterate and solved by LU (sparse or dense as the system's Jacobian).
/// opt.approximate_lhs puts the system's approximate Jacobian in place of A.
template <dynamical_system S>
class hopf_augmented_lu {
 public:
  static constexpr bool reports_linear_iterations = false;
  hopf_linear_stats stats;

  explicit hopf_augmented_lu(const hopf_options& opt)
      : approximate_lhs_(opt.approximate_lhs), lu_(opt.label + ": augmented Jacobian") {}
  std::string description(const hopf_problem<S>&) const { return "augmented system"; }

  vec<double> newton_step(const hopf_problem<S>& prob, const vec<double>& y, const vec<double>& f, int) {
    using M = jacobian_t<S>;
    const S& sys = prob.system();
    const Eigen::Index n = prob.size(), N = prob.unknowns(), off = prob.eigen_offset();
    const vec<double> w = prob.w(y), pr = prob.p_re(y), pi = prob.p_im(y), &s = prob.s();
    const double mu = prob.mu(y), om = prob.omega(y);
    auto t0 = internal::hopf_clock::now();
    const M a = approximate_lhs_ ? lhs_jacobian(sys, w, mu) : M(sys.jacobian(w, mu));
    const M amu = jacobian_d_mu(sys, w, mu);
    block_assembler<M> j(N, N);
    if (!prob.fixed_equilibrium()) {
      j.add(0, 0, a);
      j.add_column(0, N - 2, residual_d_mu(sys, w, mu));
      j.add(off, 0, jacobian_directional(sys, w, mu, pr));
      j.add(off + n, 0, jacobian_directional(sys, w, mu, pi));
    }
    j.add(off, off, a);
    j.add_identity(off, off + n, n, om);
    j.add_identity(off + n, off, n, -om);
    j.add(off + n, off + n, a);
    j.add_column(off, N - 2, amu * pr);
    j.add_column(off + n, N - 2, amu * pi);
    j.add_column(off, N - 1, pi);
    j.add_column(off + n, N - 1, -pr);
    j.add_row(N - 2, off, s);
    j.add_row(N - 1, off + n, s);
    lu_.compute(j.build());
    stats.setup_seconds += internal::seconds_since(t0);
    t0 = internal::hopf_clock::now();
    vec<double> dx = -lu_.solve(f);
    stats.linear_seconds += internal::seconds_since(t0);
    return dx;
  }

 private:
  bool approximate_lhs_;
  direct_solver<jacobian_t<S>> lu_;
};

/// Newton on the augmented system from a guess (w, mu, omega, p of any normalisation), by LU of
/// the real augmented Jacobian (hopf_augmented_lu); opt.fixed_equilibrium picks the formulation.
template <dynamical_system S>
hopf_result solve_hopf(const S& sys, const hopf_point& guess, const hopf_options& opt = {}) {
  const hopf_problem<S> prob(sys, guess, opt, "solve_hopf");
  hopf_augmented_lu<S> lu(opt);
  return hopf_newton(prob, lu, opt);
}

}  // namespace aerohopf
