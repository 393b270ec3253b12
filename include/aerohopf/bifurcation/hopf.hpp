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
// The symmetric case (the equilibrium w0 does not depend on mu, e.g. a symmetric aerofoil at
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
#include <Eigen/Core>

#include <complex>
#include <iomanip>
#include <iostream>
#include <string>

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
  bool symmetric = false;        ///< w fixed (independent of mu): solve for [p_r, p_i, mu, omega]
  hopf_normalisation normalisation = hopf_normalisation::automatic;  ///< choice of s
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
  check_state(sys, guess.w, guess.mu, "solve_hopf");
  require(guess.p.size() == n, "solve_hopf: eigenvector has ", guess.p.size(), " entries, system ", n);
  require(guess.p.allFinite() && guess.p.norm() > 0, "solve_hopf: eigenvector is zero or not finite");
  require(std::isfinite(guess.omega), "solve_hopf: omega is not finite");

  vec<std::complex<double>> p = guess.p;
  const hopf_normalisation mode = resolve_normalisation<M>(opt.normalisation);
  const vec<double> s = hopf_normalise(p, mode);
  const bool sym = opt.symmetric;
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
  auto step = [&](const vec<double>& y, const vec<double>& f, int) {
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
  newton_result nr = newton_iterate(residual, step, x, nopt, opt.label + " (augmented system)");
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
  if (r.report.converged && std::abs(r.point.omega) < 1e-12 * (1 + std::abs(r.point.mu)) && opt.newton.throw_on_failure)
    throw convergence_error(opt.label + ": converged to omega = 0 (a real eigenvalue: fold/divergence, not Hopf)");
  return r;
}

}  // namespace aerohopf
