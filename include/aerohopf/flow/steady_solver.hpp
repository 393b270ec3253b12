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
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/krylov.hpp"
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
  double exact_switch_drop = 1e-3;   // exact Jacobian once ||R||/||R_0|| < this (0: never)
  std::ostream* log = nullptr;        // progress line per step when set
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
};

/// true if every cell has positive density and pressure
template <int Dim>
bool physical_state(const euler_model<Dim>& m, const vec<double>& w) {
  constexpr int nv = Dim + 2;
  for (std::size_t c = 0; c < m.n_cells(); ++c) {
    state<double, Dim> s;
    for (int v = 0; v < nv; ++v) s[v] = w[static_cast<Eigen::Index>(c * nv + v)];
    const auto q = to_primitive<double, Dim>(s);
    if (!(q.rho > 0.0) || !(q.p > 0.0)) return false;
  }
  return true;
}

/// Drives w (in: initial guess, out: converged state) to R(w) = 0. With the vortex far field the
/// model's circulation is updated (hence the non-const model). Throws convergence_error if
/// the residual has not dropped by residual_drop after max_steps (the state reached is kept in w).
template <int Dim>
steady_report solve_steady(euler_model<Dim>& m, vec<double>& w, const steady_options& opt = {}) {
  constexpr int nv = Dim + 2;
  require(w.size() == m.size(), "solve_steady: state has ", w.size(), " entries, model has ", m.size());
  require(physical_state<Dim>(m, w), "solve_steady: initial state has non-positive density or pressure");
  const auto t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<Eigen::Index>(m.n_cells());
  const double rootn = std::sqrt(static_cast<double>(w.size()));
  block_sparse_matrix<double, nv> a, ax;  // modified-order (preconditioner), exact (operator)
  block_ilu<double, nv> ilu;
  bool analysed = false;
  jacobian_kind kind = jacobian_kind::modified_order;
  steady_report rep;
  const bool vortex = Dim == 2 && m.options().vortex_far_field;
  if (vortex) m.set_circulation(0.5 * m.forces(w).cl);
  vec<double> r = m.residual(w);
  double res = r.norm() / rootn;
  require(std::isfinite(res), "solve_steady: residual of the initial state is not finite");
  rep.initial_residual = res;
  double cfl0 = opt.cfl_initial;
  std::vector<double> vol(static_cast<std::size_t>(n));
  for (std::size_t b = 0, c = 0; b < m.metrics().blocks.size(); ++b)
    for (double v : m.metrics().blocks[b].volume) vol[c++] = v;

  for (int step = 1; step <= opt.max_steps; ++step) {
    if (res <= opt.residual_drop * rep.initial_residual || res <= opt.absolute_tolerance) {
      rep.converged = true;
      break;
    }
    if (opt.exact_switch_drop > 0.0 && res < opt.exact_switch_drop * rep.initial_residual &&
        kind != jacobian_kind::exact) {
      kind = jacobian_kind::exact;
    }
    const double cfl = std::min(opt.cfl_max, cfl0 * std::pow(rep.initial_residual / res, opt.ser_exponent));
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
    const auto lin = kind == jacobian_kind::exact ? gmres<double>(ax, ilu, r, dw, ko) : gmres<double>(a, ilu, r, dw, ko);
    rep.linear_iterations += lin.iterations;
    vec<double> wn = w + dw;
    vec<double> rn;
    bool ok = physical_state<Dim>(m, wn);
    if (ok) {
      rn = m.residual(wn);
      ok = std::isfinite(rn.norm());
    }
    if (!ok) {
      cfl0 *= 0.5;
      require(cfl0 > 1e-6, "solve_steady: CFL collapsed");
      if (opt.log) *opt.log << "step " << step << ": non-physical update rejected, CFL_0 -> " << cfl0 << "\n";
      continue;
    }
    w = std::move(wn);
    const double cl = m.forces(w).cl;
    if (vortex) {
      m.set_circulation(0.5 * cl);  // lagged: consistent at convergence
      rn = m.residual(w);
    }
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
  }
  if (res <= opt.residual_drop * rep.initial_residual || res <= opt.absolute_tolerance) rep.converged = true;
  rep.final_residual = res;
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!rep.converged)
    throw convergence_error(aerohopf::internal::concat("solve_steady: residual dropped only to ",
                                                       res / rep.initial_residual, " of its initial value ",
                                                       rep.initial_residual, " after ", rep.steps, " steps"));
  return rep;
}

}  // namespace aerohopf::flow
