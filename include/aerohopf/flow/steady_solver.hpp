#pragma once
// Steady Euler solutions by implicit pseudo-transient continuation (spec 05, "steady solver"):
//
//   (V_i/dt_i ... in our per-volume form)   (D - J) dw = R(w),   D = diag(1 / dt_i),
//   w <- w + dw,
//
// with J the MODIFIED-ORDER Jacobian (5 blocks per row in 2D; well conditioned, so BILU(0)
// works) and local time steps dt_i = CFL V_i / sum_f (|u.n - s_n| + c)|S_f|. The CFL follows
// switched evolution relaxation (Mulder & van Leer 1985):
//   CFL_n = min(CFL_max, CFL_0 (||R_0|| / ||R_n||)^beta),
// so the method turns into a (modified) Newton method as the residual falls. A step that
// produces a non-physical state (rho <= 0 or p <= 0) or a non-finite residual is rejected and
// CFL_0 is halved. Optionally, below a residual drop of exact_switch_drop, the operator of the
// linear systems becomes the exact second-order Jacobian (true Newton: quadratic convergence),
// still preconditioned by BILU(0) of the modified-order matrix (BILU(0) of the exact Jacobian
// itself is poor, spec 05). The linear systems are solved inexactly by GMRES.
//
// Failure (no residual drop by max_steps, CFL_0 collapsed below 1e-6 by rejected steps, or an
// exception inside a step: a BILU breakdown, a model error) throws convergence_error (an
// exception from inside a step keeps its own type) or, with throw_on_failure = false, is
// returned in the report (converged = false, reason). The message names solve_steady, the
// step, ||R|| / sqrt(n) of the last accepted state, the CFL, the Mach number and incidence (and
// the circulation with the vortex far field) and the original error text. w always holds the
// last accepted state (physical, finite residual), so a run can continue from it. Every
// rejected step is recorded in the report (which step, what was non-finite or non-physical).
// Input checks (input_error, before w or the model is touched): the options (finite, in range),
// the state size, finite entries (the first bad one named) and positive density and pressure.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/krylov.hpp"
#include "../nonlinear/newton.hpp"
#include "jacobian.hpp"

namespace aerohopf::flow {

struct steady_options {
  double cfl_initial = 10.0;
  double cfl_max = 1e8;
  double ser_exponent = 1.0;          // beta of the SER law
  int max_steps = 300;
  double residual_drop = 1e-10;       // stop when ||R|| / ||R_0|| falls below this
  double absolute_tolerance = 1e-15;  // ... or ||R|| / sqrt(n) below this
  double linear_tolerance = 1e-2;     // relative tolerance of each GMRES solve
  int linear_max_iterations = 200;
  int restart = 60;
  int fill_level = 0;                 // k of the BILU(k) preconditioner (of the modified-order matrix)
  double exact_switch_drop = 1e-3;   // exact Jacobian once ||R||/||R_0|| < this (0: never)
  // With the exact Jacobian (Newton), fail as stalled when stall_steps steps in a row have not
  // brought ||R|| below stall_factor times its value before them (0: never); the message names
  // the cell with the largest residual. Off by default: the AGARD medium grid at M = 0.678 sits
  // at ||R|| ~ 1.5e-5 for more than ten Newton steps (GMRES at its limit) and then converges.
  int stall_steps = 0;
  double stall_factor = 0.5;
  std::ostream* log = nullptr;        // progress line per step when set
  bool throw_on_failure = true;       // false: a failure is returned in the report (reason)
};

struct steady_step_record {
  int step;
  double residual;  // ||R||_2 / sqrt(n)
  double cfl;
  int linear_iterations;
  double cl;
};

struct steady_report {
  bool converged = false;
  int steps = 0;
  int linear_iterations = 0;
  double initial_residual = 0.0, final_residual = 0.0;
  double seconds = 0.0;
  std::vector<steady_step_record> history;
  std::string reason;                  // why the iteration stopped (the failure, when not converged)
  std::vector<std::string> rejections;  // one line per rejected step: step, cause, CFL_0 after
};

/// Throws input_error naming the option and its value unless o is finite and in range.
inline void check_steady_options(const steady_options& o, const char* who) {
  require(std::isfinite(o.cfl_initial) && o.cfl_initial > 0, who, ": cfl_initial must be finite and > 0 (got ",
          o.cfl_initial, ")");
  require(o.cfl_max >= o.cfl_initial, who, ": cfl_max must be >= cfl_initial (got ", o.cfl_max, ")");
  require(std::isfinite(o.ser_exponent) && o.ser_exponent >= 0, who, ": ser_exponent must be finite and >= 0 (got ",
          o.ser_exponent, ")");
  require(o.max_steps >= 0, who, ": max_steps must be >= 0 (got ", o.max_steps, ")");
  require(std::isfinite(o.residual_drop) && o.residual_drop >= 0 && o.residual_drop < 1, who,
          ": residual_drop must lie in [0, 1) (got ", o.residual_drop, ")");
  require(std::isfinite(o.absolute_tolerance) && o.absolute_tolerance >= 0, who,
          ": absolute_tolerance must be finite and >= 0 (got ", o.absolute_tolerance, ")");
  require(o.residual_drop > 0 || o.absolute_tolerance > 0, who,
          ": residual_drop and absolute_tolerance are both 0 (no residual could be accepted)");
  require(std::isfinite(o.linear_tolerance) && o.linear_tolerance > 0 && o.linear_tolerance < 1, who,
          ": linear_tolerance must lie in (0, 1) (got ", o.linear_tolerance, ")");
  require(o.linear_max_iterations >= 1, who, ": linear_max_iterations must be >= 1 (got ", o.linear_max_iterations,
          ")");
  require(o.restart >= 1, who, ": restart must be >= 1 (got ", o.restart, ")");
  require(o.stall_steps >= 0 && std::isfinite(o.stall_factor) && o.stall_factor > 0 && o.stall_factor < 1, who,
          ": need stall_steps >= 0 and stall_factor in (0, 1) (got ", o.stall_steps, ", ", o.stall_factor, ")");
  require(o.fill_level >= 0 && o.fill_level <= 8, who, ": fill_level must lie in [0, 8] (got ", o.fill_level, ")");
  require(std::isfinite(o.exact_switch_drop) && o.exact_switch_drop >= 0 && o.exact_switch_drop <= 1, who,
          ": exact_switch_drop must lie in [0, 1] (got ", o.exact_switch_drop, ")");
}

/// true if every cell has positive, finite density and pressure (euler_model::is_physical, the
/// one physical-state test of the flow layer).
template <int Dim>
bool physical_state(const euler_model<Dim>& m, const vec<double>& w) {
  return m.is_physical(w);
}

namespace internal {
/// Index of the first non-finite entry of v, -1 if none.
inline Eigen::Index first_non_finite(const vec<double>& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) return i;
  return -1;
}
}  // namespace internal

/// Drives w (in: initial guess, out: converged state, or the last accepted one on failure) to
/// R(w) = 0 with R evaluated by `residual(w)` (the model's own residual in the overload below;
/// a wrapper serves monitoring or fault injection), the Jacobians and time steps by the model.
/// With the vortex far field the model's circulation is updated (hence the non-const model).
/// Failures: file comment.
template <int Dim, class Residual>
steady_report solve_steady(euler_model<Dim>& m, vec<double>& w, const steady_options& opt, Residual&& residual) {
  constexpr int nv = Dim + 2;
  const char* who = "solve_steady";
  check_steady_options(opt, who);
  require_size(w.size(), m.size(), who, "state");
  require_finite(w, who, "state");
  m.require_physical(w.data(), "solve_steady: initial state");
  const auto t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<Eigen::Index>(m.n_cells());
  const double rootn = std::sqrt(static_cast<double>(w.size()));
  block_sparse_matrix<double, nv> a, ax;  // modified-order (preconditioner), exact (operator)
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.context = "solve_steady: BILU";
  block_ilu<double, nv> ilu(io);
  bool analysed = false;
  jacobian_kind kind = jacobian_kind::modified_order;
  steady_report rep;
  const bool vortex = Dim == 2 && m.options().vortex_far_field;
  double res = NAN, cfl = NAN;
  int step = 0;
  int exact_from = -1;  // history index of the first step with the exact Jacobian
  // "step k (||R|| = .., CFL .., M = .., alpha = .. deg[, circulation ..])": the context of a failure
  auto where = [&]() {
    std::string s = aerohopf::internal::concat("step ", step, " (||R||/sqrt(n) = ", res, " of the last accepted state");
    if (std::isfinite(cfl)) s += aerohopf::internal::concat(", CFL ", cfl);
    s += aerohopf::internal::concat(", M = ", m.conditions().mach, ", alpha = ", m.conditions().alpha_rad * 180.0 / M_PI, " deg");
    if (vortex) s += aerohopf::internal::concat(", circulation ", m.circulation());
    return s + ")";
  };
  auto finish = [&]() {
    rep.final_residual = res;
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto fail = [&](const std::string& why) {
    rep.converged = false;
    rep.reason = aerohopf::internal::concat(who, ": ", why);
    finish();
    if (opt.throw_on_failure) throw convergence_error(rep.reason);
    return rep;
  };
  vec<double> r;
  try {
    if (vortex) m.set_circulation(0.5 * m.forces(w).cl);
    r = residual(static_cast<const vec<double>&>(w));
  } catch (...) {
    const std::string ctx = aerohopf::internal::concat(who, ": residual of the initial state failed: ");
    rep.reason = ctx + aerohopf::internal::current_exception_text();
    finish();
    if (opt.throw_on_failure) aerohopf::internal::rethrow_with_context(ctx);
    return rep;
  }
  require_size(r.size(), w.size(), who, "residual");
  {
    const Eigen::Index i = internal::first_non_finite(r);
    require(i < 0, who, ": residual of the initial state is not finite (entry ", i, ")");
  }
  res = r.norm() / rootn;
  rep.initial_residual = res;
  double cfl0 = opt.cfl_initial;
  std::vector<double> vol(static_cast<std::size_t>(n));
  for (std::size_t b = 0, c = 0; b < m.metrics().blocks.size(); ++b)
    for (double v : m.metrics().blocks[b].volume) vol[c++] = v;
  auto done = [&] { return res <= opt.residual_drop * rep.initial_residual || res <= opt.absolute_tolerance; };

  for (step = 1; step <= opt.max_steps; ++step) {
    if (done()) break;
    if (opt.exact_switch_drop > 0.0 && res < opt.exact_switch_drop * rep.initial_residual &&
        kind != jacobian_kind::exact) {
      kind = jacobian_kind::exact;
    }
    cfl = std::min(opt.cfl_max, cfl0 * std::pow(rep.initial_residual / res, opt.ser_exponent));
    std::string rejected;  // why the trial state is refused (empty: accepted)
    vec<double> wn, rn;
    krylov_report lin;
    try {
      const vec<double> rad = m.spectral_radius(w);
      auto pseudo_time_matrix = [&](jacobian_kind k, block_sparse_matrix<double, nv>& mat) {
        assemble_jacobian<Dim>(m, w, k, mat);
        for (auto& x : mat.values()) x = -x;
        for (Eigen::Index c = 0; c < n; ++c)
          mat.block(c, c).diagonal().array() += rad[c] / (cfl * vol[static_cast<std::size_t>(c)]);
      };
      pseudo_time_matrix(jacobian_kind::modified_order, a);
      if (kind == jacobian_kind::exact) pseudo_time_matrix(jacobian_kind::exact, ax);
      if (!analysed) {
        ilu.analyze(a);
        analysed = true;
      }
      ilu.factorize(a);
      krylov_options ko;
      ko.relative_tolerance = opt.linear_tolerance;
      ko.max_iterations = opt.linear_max_iterations;
      ko.restart = opt.restart;
      ko.record_history = false;
      vec<double> dw = vec<double>::Zero(w.size());
      lin = kind == jacobian_kind::exact ? gmres<double>(ax, ilu, r, dw, ko) : gmres<double>(a, ilu, r, dw, ko);
      rep.linear_iterations += lin.iterations;
      wn = w + dw;
      if (const Eigen::Index i = internal::first_non_finite(dw); i >= 0) {
        rejected = aerohopf::internal::concat("update not finite (entry ", i, "; GMRES: ", lin.reason, ")");
      } else if (const auto d = m.first_nonphysical_cell(wn.data())) {
        rejected = aerohopf::internal::concat("non-positive density or pressure in block ", d->block, " (state cell ",
                                              d->global, ")");
      } else {
        rn = residual(static_cast<const vec<double>&>(wn));
        require_size(rn.size(), w.size(), who, "residual");
        if (const Eigen::Index i = internal::first_non_finite(rn); i >= 0)
          rejected = aerohopf::internal::concat("residual of the trial state not finite (entry ", i, " of ", rn.size(), ")");
      }
    } catch (...) {
      const std::string ctx = aerohopf::internal::concat(who, ": ", where(), " failed: ");
      rep.reason = ctx + aerohopf::internal::current_exception_text();
      finish();
      if (opt.throw_on_failure) aerohopf::internal::rethrow_with_context(ctx);
      return rep;
    }
    if (!rejected.empty()) {
      cfl0 *= 0.5;
      rep.rejections.push_back(aerohopf::internal::concat("step ", step, ": ", rejected, "; rejected, CFL_0 -> ", cfl0));
      if (opt.log) *opt.log << rep.rejections.back() << "\n";
      if (!(cfl0 > 1e-6))
        return fail(aerohopf::internal::concat("CFL_0 collapsed to ", cfl0, " after ", rep.rejections.size(),
                                     " rejected steps at ", where(), "; last: ", rejected));
      continue;
    }
    w = std::move(wn);
    double cl = NAN;
    try {
      cl = m.forces(w).cl;
      if (vortex) {
        m.set_circulation(0.5 * cl);  // lagged: consistent at convergence
        rn = residual(static_cast<const vec<double>&>(w));
      }
    } catch (...) {
      const std::string ctx = aerohopf::internal::concat(who, ": ", where(), " failed after its update was accepted: ");
      rep.reason = ctx + aerohopf::internal::current_exception_text();
      finish();
      if (opt.throw_on_failure) aerohopf::internal::rethrow_with_context(ctx);
      return rep;
    }
    if (const Eigen::Index i = internal::first_non_finite(rn); i >= 0)
      return fail(aerohopf::internal::concat("residual not finite (entry ", i, ") after the circulation update at ", where()));
    r = std::move(rn);
    res = r.norm() / rootn;
    rep.history.push_back({step, res, cfl, lin.iterations, cl});
    rep.steps = step;
    if (opt.log) {
      char line[160];
      std::snprintf(line, sizeof line, "step %4d  res %.3e  drop %.2e  CFL %.3e  lin %3d  CL %+.6f%s\n", step, res,
                    res / rep.initial_residual, cfl, lin.iterations, cl, kind == jacobian_kind::exact ? "  (exact J)" : "");
      *opt.log << line << std::flush;
    }
    if (kind == jacobian_kind::exact) {
      if (exact_from < 0) exact_from = static_cast<int>(rep.history.size()) - 1;
      const int h = static_cast<int>(rep.history.size()) - 1;
      if (opt.stall_steps > 0 && h - exact_from >= opt.stall_steps && !done()) {
        const double before = rep.history[static_cast<std::size_t>(h - opt.stall_steps)].residual;
        double best = INFINITY;
        for (int k = h - opt.stall_steps + 1; k <= h; ++k) best = std::min(best, rep.history[static_cast<std::size_t>(k)].residual);
        if (!(best < opt.stall_factor * before)) {
          Eigen::Index worst = 0;
          double worst_norm = -1;
          for (Eigen::Index c = 0; c < n; ++c)
            if (const double v = r.segment(c * nv, nv).norm(); v > worst_norm) {
              worst_norm = v;
              worst = c;
            }
          const std::string cell = m.cell_name(static_cast<std::size_t>(worst));
          return fail(aerohopf::internal::concat(
              "Newton stalled: ", opt.stall_steps, " steps with the exact Jacobian took ||R|| only from ", before, " to ",
              best, " (GMRES at ", lin.iterations, " of at most ", opt.linear_max_iterations,
              " iterations in the last step); largest residual ", worst_norm, " in ", cell, ", at ", where()));
        }
      }
    }
  }
  step = rep.steps;
  if (done()) {
    rep.converged = true;
    rep.reason = aerohopf::internal::concat("||R|| dropped to ", res / rep.initial_residual, " of its initial value after ",
                                  rep.steps, " steps");
    finish();
    return rep;
  }
  return fail(aerohopf::internal::concat("residual dropped only to ", res / rep.initial_residual, " of its initial value ",
                               rep.initial_residual, " after ", rep.steps, " accepted steps (", rep.rejections.size(),
                               " rejected) at ", where()));
}

/// solve_steady with the model's own residual.
template <int Dim>
steady_report solve_steady(euler_model<Dim>& m, vec<double>& w, const steady_options& opt = {}) {
  return solve_steady<Dim>(m, w, opt, [&m](const vec<double>& x) { return vec<double>(m.residual(x)); });
}

}  // namespace aerohopf::flow
