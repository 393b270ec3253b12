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
// Post-checks (every Hopf solver: solve_hopf, solve_hopf_bordered, solve_hopf_krylov). Newton
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
#include <cmath>
#include <complex>
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
  /// Wall-clock split (solve_hopf_krylov only; 0 elsewhere): matrix assembly and preconditioner
  /// factorisation, Krylov solves, and residual evaluations.
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

/// Newton on the augmented system from a guess (w, mu, omega, p of any normalisation).
template <dynamical_system S>
hopf_result solve_hopf(const S& sys, const hopf_point& guess, const hopf_options& opt = {}) {
  using M = jacobian_t<S>;
  const Eigen::Index n = sys.size();
  internal::check_hopf_guess(sys, guess, "solve_hopf");
  internal::check_hopf_options(opt, "solve_hopf");

  vec<std::complex<double>> p = guess.p;
  const hopf_normalisation mode = resolve_normalisation<M>(opt.normalisation);
  const vec<double> s = hopf_normalise(p, mode);
  const bool sym = opt.fixed_equilibrium;
  const Eigen::Index off = sym ? 0 : n;  // offset of p_r in the unknown vector
  const Eigen::Index N = off + 2 * n + 2;
  vec<double> x(N);
  if (!sym) x.head(n) = guess.w;
  x.segment(off, n) = p.real();
  x.segment(off + n, n) = p.imag();
  x[N - 2] = guess.mu;
  x[N - 1] = guess.omega;
  const vec<double> w_fixed = guess.w;

  auto unpack_w = [&](const vec<double>& y) -> vec<double> { return sym ? w_fixed : vec<double>(y.head(n)); };
  auto residual = [&](const vec<double>& y) {
    const vec<double> w = unpack_w(y);
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> pr = y.segment(off, n), pi = y.segment(off + n, n);
    vec<double> f(N);
    if (!sym) f.head(n) = sys.residual(w, mu);
    f.segment(off, n) = jacobian_product(sys, w, mu, pr) + om * pi;
    f.segment(off + n, n) = jacobian_product(sys, w, mu, pi) - om * pr;
    f[N - 2] = s.dot(pr);
    f[N - 1] = s.dot(pi) - 1.0;
    return f;
  };
  direct_solver<M> lu(opt.label + ": augmented Jacobian");
  internal::hopf_iterate_log last(x, N - 2, N - 1);
  auto step = [&](const vec<double>& y, const vec<double>& f, int k) {
    last.record(y, f, k);
    const vec<double> w = unpack_w(y);
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> pr = y.segment(off, n), pi = y.segment(off + n, n);
    const M a = opt.approximate_lhs ? lhs_jacobian(sys, w, mu) : M(sys.jacobian(w, mu));
    const M amu = jacobian_d_mu(sys, w, mu);
    block_assembler<M> j(N, N);
    if (!sym) {
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
    lu.compute(j.build());
    return vec<double>(-lu.solve(f));
  };
  newton_options nopt = opt.newton;
  if (opt.verbose && opt.log && !nopt.observer) {
    std::ostream& os = *opt.log;
    const std::string label = opt.label;
    nopt.observer = [&os, label, N](const newton_step_info& i) {
      os << label << " it " << std::setw(2) << i.iteration << "  |F| " << std::scientific << std::setprecision(3)
         << i.residual << "  mu " << std::setprecision(12) << std::defaultfloat << (*i.x)[N - 2] << "  omega "
         << (*i.x)[N - 1] << (i.relaxation < 1 ? "  (relaxed)" : "") << "\n";
    };
  }
  newton_result nr = internal::run_hopf_newton(
      [&] { return newton_iterate(residual, step, x, nopt, opt.label + " (augmented system)"); }, last, opt);
  hopf_result r;
  r.s = s;
  r.report = std::move(nr.report);
  const vec<double>& y = nr.x;
  r.point.w = unpack_w(y);
  r.point.mu = y[N - 2];
  r.point.omega = y[N - 1];
  r.point.p = vec<std::complex<double>>(n);
  r.point.p.real() = y.segment(off, n);
  r.point.p.imag() = y.segment(off + n, n);
  if (r.report.converged && r.point.omega < 0) {
    // The conjugate pair was found: same point, report omega > 0.
    r.point.omega = -r.point.omega;
    r.point.p = r.point.p.conjugate().eval();
  }
  internal::hopf_accept(sys, r, opt, sym);
  return r;
}

}  // namespace aerohopf
