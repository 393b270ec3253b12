#pragma once
// Newton-Krylov solve of the equilibrium f(w, mu) = 0 of a dynamical system from a NEARBY state:
// the steady flow at a Mach number next to ones already solved (a continuation in M, the nested
// steady solves of the fixed-equilibrium Hopf-curve tracer). The pseudo-transient solver of
// flow/steady_solver.hpp is the robust start from the free stream; from a good guess it is the
// wrong tool (measured on the medium aerofoil grid, M = 0.90 -> 0.9012: still 25-71
// pseudo-time steps, as its CFL law and its relative stopping test are built for a start far away),
// while Newton converges quadratically in 2-5 steps.
//
// Method: Newton on f(w, mu) = 0 with
//   * the EXACT Jacobian f_w in the bordered form (krylov_exact_jacobian, nonlinear/block_system.hpp:
//     flow blocks + structural border, e.g. the aerofoil's second-order flow Jacobian) as the
//     GMRES operator, so the convergence is quadratic;
//   * right preconditioning by the real BILU(k) of the flow part of the preconditioning matrix
//     (the modified-order Jacobian of the aerofoil: BILU of the exact second-order one is poor,
//     spec 05) with the border eliminated exactly (bordered_block_ilu), factorised ONCE, at the
//     start (later iterates move w little);
//   * the inexact-Newton forcing eta_k = min(0.5, eta_max, max(||f_k||, 0.1 tol / ||f_k||)) (GMRES
//     relative tolerance: loose far away, quadratic near the solution, never tighter than the last
//     step needs);
//   * an optional halving line search on ||f|| (newton_options::line_search) against
//     non-physical or rising iterates.
// Convergence: ||f(w, mu)||_2 <= newton.abs_tolerance (+ rel_tolerance ||f_0||), or a full step
// at the rounding floor (newton_options::step_tolerance). Failure (no convergence in
// max_iterations, a residual that is not finite, a GMRES failure, a BILU breakdown, a
// non-physical state refused by the model) follows newton_iterate: with
// newton.throw_on_failure (the default) it is thrown, an exception from inside a step with its
// own type (a GMRES failure is a convergence_error, a BILU breakdown a singular_matrix_error),
// else returned with report.converged = false and w the last good iterate; the message names
// `label`, the iterate, ||f|| and mu. The caller's start is never modified (it is taken by
// value). Input checks (input_error): the options, a finite mu, a finite start of the system's
// size (the first bad entry named).
//
// B: block size of the flow unknowns for BILU (4 for 2D Euler), S any dynamical_system with
// sparse Jacobians or a block_system / bordered_system of block size B (krylov_jacobians).
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "../nonlinear/block_system.hpp"
#include "../linalg/krylov.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "hopf_bordered.hpp"

namespace aerohopf {

struct equilibrium_krylov_options {
  int fill_level = 1;  ///< k of the real BILU(k) of lhs_jacobian
  newton_options newton = [] {
    newton_options o;
    o.abs_tolerance = 1e-11;  ///< on ||f(w, mu)||_2
    o.max_iterations = 12;
    o.line_search = true;     ///< halve while ||f|| does not decrease (or is not finite)
    return o;
  }();
  double eta_max = 1e-2;  ///< largest GMRES relative tolerance (the forcing of the file comment)
  krylov_options krylov = newton_correction_krylov_options();  ///< GMRES of the Newton corrections (relative_tolerance is set by the forcing)
};

struct equilibrium_krylov_result {
  vec<double> w;             ///< the equilibrium
  newton_report report;      ///< iterations, ||f|| history
  long linear_iterations = 0;  ///< GMRES iterations over all Newton steps
  double seconds = 0;
};

namespace internal {
/// Inexact-Newton forcing for a residual of norm fn converging to abs_tol (file comment).
inline double inexact_forcing(double fn, double abs_tol, double eta_max) {
  return std::min(0.5, std::min(eta_max, std::max(fn, 0.1 * abs_tol / fn)));
}

/// The Newton-Krylov equilibrium solve of solve_equilibrium_krylov with the caller's
/// preconditioner, which after the call holds the factorisation of the preconditioning matrix at
/// the start: a bordered_block_ilu<double, B> (the bordered form of every Krylov solve), or a
/// block_ilu<double, B> of the padded whole matrix (the form hopf_curve_fixed_equilibrium.hpp
/// reuses for dw0/dnu). linear_iterations is incremented, not reset.
/// Failures are thrown unless throw_on_failure is false (then returned, newton_iterate's
/// contract); the default true is the contract of the nested solves of the Hopf-curve tracer.
template <int B, dynamical_system S, class Preconditioner>
newton_result equilibrium_newton_krylov(const S& sys, double mu, vec<double> w, const equilibrium_krylov_options& o,
                                        Preconditioner& ilu, long& linear_iterations, const std::string& label,
                                        bool throw_on_failure = true) {
  constexpr bool padded = std::is_same_v<Preconditioner, block_ilu<double, B>>;
  static_assert(padded || std::is_same_v<Preconditioner, bordered_block_ilu<double, B>>,
                "equilibrium_newton_krylov: the preconditioner is a bordered_block_ilu<double, B> or block_ilu<double, B>");
  const Eigen::Index n = sys.size();
  require_size(w.size(), n, label, "start");
  require(std::isfinite(mu), label, ": mu is not finite (", mu, ")");
  require_finite(w, label, "start");
  require(o.newton.abs_tolerance > 0 || o.newton.rel_tolerance > 0, label,
          ": Newton needs abs_tolerance > 0 or rel_tolerance > 0");
  require(o.eta_max > 0 && o.eta_max < 1, label, ": eta_max must lie in (0, 1) (got ", o.eta_max, ")");
  check_newton_options(o.newton, label);
  newton_options no = o.newton;
  no.throw_on_failure = throw_on_failure;
  if (!no.describe) no.describe = [mu](const vec<double>&) { return internal::concat("mu = ", mu); };
  std::conditional_t<padded, block_sparse_matrix<double, B>, bordered_block_matrix<double, B>> a;
  return newton_iterate(
      [&](const vec<double>& v) { return vec<double>(sys.residual(v, mu)); },
      [&](const vec<double>& v, const vec<double>& f, int k) {
        if constexpr (padded) {
          if (k == 1) {
            block_sparse_matrix<double, B> l;
            std::tie(a, l) = exact_and_lhs_blocks<B>(sys, v, mu, label);
            ilu.compute(l);
          } else {
            a = exact_blocks<B>(sys, v, mu, label);
          }
        } else {
          bordered_block_matrix<double, B> l;
          krylov_matrices<B>(sys, v, mu, k > 1, label, a, l);
          if (k == 1) ilu.compute(l);
        }
        krylov_options ko = o.krylov;
        ko.relative_tolerance = inexact_forcing(f.norm(), o.newton.abs_tolerance, o.eta_max);
        ko.throw_on_failure = true;
        ko.context = internal::concat(label, ", GMRES at Newton iterate ", k);
        // the padded form's vectors are longer than n (zero padding); the bordered form's are n
        vec<double> rhs = vec<double>::Zero(a.rows()), dx = vec<double>::Zero(a.rows());
        rhs.head(n) = -f;
        linear_iterations += gmres<double>(a, ilu, rhs, dx, ko).iterations;
        return vec<double>(dx.head(n));
      },
      std::move(w), no, label);
}
}  // namespace internal

/// Newton-Krylov solve of f(w, mu) = 0 from the nearby state w0 (file comment; failures and
/// input checks there).
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
equilibrium_krylov_result solve_equilibrium_krylov(const S& sys, double mu, vec<double> w0,
                                                   const equilibrium_krylov_options& o = {},
                                                   const std::string& label = "equilibrium (Newton-Krylov)") {
  require(std::isfinite(mu), label, ": mu is not finite");
  require(o.fill_level >= 0, label, ": fill level ", o.fill_level, " < 0");
  const auto t0 = std::chrono::steady_clock::now();
  block_ilu_options io;
  io.fill_level = o.fill_level;
  io.context = label + ": real BILU(" + std::to_string(o.fill_level) + ") of the preconditioning Jacobian";
  bordered_block_ilu<double, B> ilu(io);
  equilibrium_krylov_result r;
  newton_result nr = internal::equilibrium_newton_krylov<B>(sys, mu, std::move(w0), o, ilu, r.linear_iterations, label,
                                                            o.newton.throw_on_failure);
  r.w = std::move(nr.x);
  r.report = std::move(nr.report);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace aerohopf
