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
#include <concepts>
#include <cmath>
#include <cstdio>
#include <functional>
#include <ostream>
#include <string>
#include <utility>
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
  // The GMRES of each pseudo-time step: relative tolerance 1e-2, at most 200 iterations,
  // GMRES(60), no residual history. krylov.deflation = k gives GMRES-DR(60, k): 20 left the AGARD
  // medium steady solve (M = 0.96, 2 ranks) at the same 24 steps and 146 s against 142 s.
  krylov_options krylov{.relative_tolerance = 1e-2,
                        .max_iterations = 200,
                        .restart = 60,
                        .record_history = false,
                        .context = "solve_steady: GMRES"};
  int fill_level = 0;                 // k of the BILU(k) preconditioner (of the modified-order matrix)
  double exact_switch_drop = 1e-3;   // exact Jacobian once ||R||/||R_0|| < this (0: never)
  // With the exact Jacobian (Newton), fail as stalled when stall_steps steps in a row have not
  // brought ||R|| below stall_factor times its value before them (0: never); the message names
  // the cell with the largest residual. Off by default: the AGARD medium grid with unbounded wake
  // lines (wing_grid_options::max_shift = 0) at M = 0.678 sat at ||R|| ~ 1.5e-5 for more than
  // ten Newton steps (GMRES at its limit) and then converged.
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
  require(std::isfinite(o.krylov.relative_tolerance) && o.krylov.relative_tolerance > 0 &&
              o.krylov.relative_tolerance < 1,
          who, ": krylov.relative_tolerance must lie in (0, 1) (got ", o.krylov.relative_tolerance, ")");
  require(o.krylov.max_iterations >= 1, who, ": krylov.max_iterations must be >= 1 (got ", o.krylov.max_iterations,
          ")");
  validate_krylov_options(o.krylov, aerohopf::internal::concat(who, ": krylov"));  // restart, deflation
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

/// "M = .., alpha = .. deg": the free stream of m, for solver messages.
template <int Dim>
std::string conditions_text(const euler_model<Dim>& m) {
  return aerohopf::internal::concat("M = ", m.conditions().mach, ", alpha = ", m.conditions().alpha_rad * 180.0 / M_PI,
                                    " deg");
}

/// What the steady solver needs of a discretisation: the serial Euler model
/// (euler_discretisation below) or one rank's part of a partitioned grid
/// (distributed/mpi_steady.hpp). Vectors are the caller's part of the state (all of it in
/// serial); every member that decides something (`agree`, `global_sum`, `collective`) gives
/// the same answer on every process, so that the solver takes the same branches everywhere.
///  - block_size: values per cell; size(): values of the caller's part;
///  - residual(w), spectral_radius(w) (one value per cell), volumes() (one per cell);
///  - jacobian(w, kind, a): the caller's block rows of dR/dw;
///  - preconditioning_part(a): the matrix BILU(k) factorises (a itself, or its square part of
///    the caller's own cells: block Jacobi);
///  - gmres(a, pc, b, x, options): GMRES on the operator of a;
///  - global_sum(p, n): sums over the processes (no-op in serial);
///  - agree(text): the first non-empty text of any process, on every process;
///  - collective(what, f): runs f; if it throws anywhere, it throws everywhere;
///  - check_initial(w, who): size, finite entries, physical state (input_error);
///  - nonphysical(w): empty or which cell is not physical (this process's cells);
///  - forces(w): the force coefficients of the whole body;
///  - vortex(), circulation(), set_circulation(g): the vortex far field;
///  - conditions_text(): "M = .., alpha = .. deg" for messages;
///  - largest_residual(r): {norm, cell name} of the cell with the largest residual anywhere.
template <class D>
concept steady_discretisation =
    requires(D& d, const vec<double>& w, jacobian_kind k, block_sparse_matrix<double, D::block_size>& a, double* p,
             const std::string& text) {
      { D::block_size } -> std::convertible_to<int>;
      { d.size() } -> std::convertible_to<Eigen::Index>;
      { d.residual(w) } -> std::convertible_to<vec<double>>;
      { d.spectral_radius(w) } -> std::convertible_to<vec<double>>;
      { d.volumes() } -> std::convertible_to<const std::vector<double>&>;
      d.jacobian(w, k, a);
      { d.preconditioning_part(a) } -> std::convertible_to<const block_sparse_matrix<double, D::block_size>&>;
      d.global_sum(p, 1);
      { d.agree(text) } -> std::convertible_to<std::string>;
      d.check_initial(w, "who");
      { d.nonphysical(w) } -> std::convertible_to<std::string>;
      { d.forces(w) } -> std::convertible_to<force_coefficients>;
      { d.vortex() } -> std::convertible_to<bool>;
      { d.circulation() } -> std::convertible_to<double>;
      d.set_circulation(1.0);
      { d.conditions_text() } -> std::convertible_to<std::string>;
      { d.largest_residual(w) } -> std::convertible_to<std::pair<double, std::string>>;
    };

/// The serial Euler model as a steady_discretisation, R(w) evaluated by `residual(w)` (the
/// model's own residual, or a wrapper for monitoring or fault injection).
template <int Dim, class Residual>
class euler_discretisation {
 public:
  static constexpr int block_size = Dim + 2;
  euler_discretisation(euler_model<Dim>& m, Residual residual) : m_(m), residual_(std::move(residual)) {
    vol_.reserve(m.n_cells());
    for (const auto& b : m.metrics().blocks) vol_.insert(vol_.end(), b.volume.begin(), b.volume.end());
  }
  Eigen::Index size() const { return m_.size(); }
  vec<double> residual(const vec<double>& w) { return residual_(w); }
  vec<double> spectral_radius(const vec<double>& w) const { return m_.spectral_radius(w); }
  const std::vector<double>& volumes() const { return vol_; }
  void jacobian(const vec<double>& w, jacobian_kind kind, block_sparse_matrix<double, block_size>& a) const {
    assemble_jacobian<Dim>(m_, w, kind, a);
  }
  const block_sparse_matrix<double, block_size>& preconditioning_part(
      const block_sparse_matrix<double, block_size>& a) const {
    return a;
  }
  template <class Pc>
  krylov_report gmres(const block_sparse_matrix<double, block_size>& a, const Pc& pc, const vec<double>& b,
                      vec<double>& x, const krylov_options& ko) const {
    return aerohopf::gmres<double>(a, pc, b, x, ko);
  }
  void global_sum(double*, int) const {}
  std::string agree(const std::string& text) const { return text; }
  template <class F>
  void collective(const char*, F&& f) const {
    f();
  }
  void check_initial(const vec<double>& w, const char* who) const {
    require_size(w.size(), m_.size(), who, "state");
    require_finite(w, who, "state");
    m_.require_physical(w.data(), aerohopf::internal::concat(who, ": initial state"));
  }
  std::string nonphysical(const vec<double>& w) const {
    const auto d = m_.first_nonphysical_cell(w.data());
    if (!d) return {};
    return aerohopf::internal::concat("non-positive density or pressure in block ", d->block, " (state cell ", d->global,
                                      ")");
  }
  force_coefficients forces(const vec<double>& w) const { return m_.forces(w); }
  bool vortex() const { return Dim == 2 && m_.options().vortex_far_field; }
  double circulation() const { return m_.circulation(); }
  void set_circulation(double g) { m_.set_circulation(g); }
  std::string conditions_text() const { return flow::conditions_text(m_); }
  std::pair<double, std::string> largest_residual(const vec<double>& r) const {
    constexpr int nv = block_size;
    Eigen::Index worst = 0;
    double worst_norm = -1;
    for (Eigen::Index c = 0; c < r.size() / nv; ++c)
      if (const double v = r.segment(c * nv, nv).norm(); v > worst_norm) {
        worst_norm = v;
        worst = c;
      }
    return {worst_norm, m_.cell_name(static_cast<std::size_t>(worst))};
  }

 private:
  euler_model<Dim>& m_;
  Residual residual_;
  std::vector<double> vol_;
};

/// Drives w (in: initial guess, out: converged state, or the last accepted one on failure;
/// the caller's part of the state) to R(w) = 0 for any steady_discretisation. With the vortex
/// far field the circulation is updated (hence the non-const discretisation). Failures: file
/// comment.
template <steady_discretisation D>
steady_report solve_steady(D& d, vec<double>& w, const steady_options& opt) {
  constexpr int nv = D::block_size;
  const char* who = "solve_steady";
  check_steady_options(opt, who);
  d.check_initial(w, who);
  const auto t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<Eigen::Index>(w.size() / nv);  // the caller's cells
  double total = static_cast<double>(w.size());
  d.global_sum(&total, 1);
  const double rootn = std::sqrt(total);
  auto norm = [&](const vec<double>& v) {
    double s2 = v.squaredNorm();
    d.global_sum(&s2, 1);
    return std::sqrt(s2);
  };
  // "" if v is finite everywhere, else where it is not (the same text on every process)
  auto non_finite = [&](const vec<double>& v, const char* what) {
    const Eigen::Index i = internal::first_non_finite(v);
    return d.agree(i < 0 ? std::string() : aerohopf::internal::concat(what, " not finite (entry ", i, " of ", v.size(), ")"));
  };
  block_sparse_matrix<double, nv> a, ax;  // modified-order (preconditioner), exact (operator)
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.context = "solve_steady: BILU";
  block_ilu<double, nv> ilu(io);
  bool analysed = false;
  jacobian_kind kind = jacobian_kind::modified_order;
  steady_report rep;
  const bool vortex = d.vortex();
  double res = NAN, cfl = NAN;
  int step = 0;
  int exact_from = -1;  // history index of the first step with the exact Jacobian
  // "step k (||R|| = .., CFL .., M = .., alpha = .. deg[, circulation ..])": the context of a failure
  auto where = [&]() {
    std::string s = aerohopf::internal::concat("step ", step, " (||R||/sqrt(n) = ", res, " of the last accepted state");
    if (std::isfinite(cfl)) s += aerohopf::internal::concat(", CFL ", cfl);
    s += ", " + d.conditions_text();
    if (vortex) s += aerohopf::internal::concat(", circulation ", d.circulation());
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
    if (vortex) d.set_circulation(0.5 * d.forces(w).cl);
    r = d.residual(static_cast<const vec<double>&>(w));
  } catch (...) {
    const std::string ctx = aerohopf::internal::concat(who, ": residual of the initial state failed: ");
    rep.reason = ctx + aerohopf::internal::current_exception_text();
    finish();
    if (opt.throw_on_failure) aerohopf::internal::rethrow_with_context(ctx);
    return rep;
  }
  require_size(r.size(), w.size(), who, "residual");
  if (const std::string bad = non_finite(r, "residual of the initial state"); !bad.empty())
    throw input_error(aerohopf::internal::concat(who, ": ", bad));
  res = norm(r) / rootn;
  rep.initial_residual = res;
  double cfl0 = opt.cfl_initial;
  const std::vector<double>& vol = d.volumes();
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
      const vec<double> rad = d.spectral_radius(w);
      auto pseudo_time_matrix = [&](jacobian_kind k, block_sparse_matrix<double, nv>& mat) {
        d.jacobian(w, k, mat);
        for (auto& x : mat.values()) x = -x;
        for (Eigen::Index c = 0; c < n; ++c)
          mat.block(c, c).diagonal().array() += rad[c] / (cfl * vol[static_cast<std::size_t>(c)]);
      };
      pseudo_time_matrix(jacobian_kind::modified_order, a);
      if (kind == jacobian_kind::exact) pseudo_time_matrix(jacobian_kind::exact, ax);
      const block_sparse_matrix<double, nv>& pa = d.preconditioning_part(a);
      d.collective("solve_steady: BILU", [&] {
        if (!analysed) ilu.analyze(pa);
        ilu.factorize(pa);
      });
      analysed = true;
      vec<double> dw = vec<double>::Zero(w.size());
      lin = d.gmres(kind == jacobian_kind::exact ? ax : a, ilu, r, dw, opt.krylov);
      rep.linear_iterations += lin.iterations;
      wn = w + dw;
      rejected = non_finite(dw, "update");
      if (!rejected.empty()) {
        rejected += aerohopf::internal::concat(" (GMRES: ", lin.reason, ")");
      } else if (rejected = d.agree(d.nonphysical(wn)); rejected.empty()) {
        rn = d.residual(static_cast<const vec<double>&>(wn));
        require_size(rn.size(), w.size(), who, "residual");
        rejected = non_finite(rn, "residual of the trial state");
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
      cl = d.forces(w).cl;
      if (vortex) {
        d.set_circulation(0.5 * cl);  // lagged: consistent at convergence
        rn = d.residual(static_cast<const vec<double>&>(w));
      }
    } catch (...) {
      const std::string ctx = aerohopf::internal::concat(who, ": ", where(), " failed after its update was accepted: ");
      rep.reason = ctx + aerohopf::internal::current_exception_text();
      finish();
      if (opt.throw_on_failure) aerohopf::internal::rethrow_with_context(ctx);
      return rep;
    }
    if (const std::string bad = non_finite(rn, "residual"); !bad.empty())
      return fail(aerohopf::internal::concat(bad, " after the circulation update at ", where()));
    r = std::move(rn);
    res = norm(r) / rootn;
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
          const auto [worst_norm, cell] = d.largest_residual(r);
          return fail(aerohopf::internal::concat(
              "Newton stalled: ", opt.stall_steps, " steps with the exact Jacobian took ||R|| only from ", before, " to ",
              best, " (GMRES at ", lin.iterations, " of at most ", opt.krylov.max_iterations,
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

/// solve_steady of the Euler model with R(w) evaluated by `residual(w)` (a wrapper of the
/// model's residual for monitoring or fault injection); the Jacobians, time steps and forces
/// are the model's. Input checks (input_error) come before w or the model is touched.
template <int Dim, class Residual>
steady_report solve_steady(euler_model<Dim>& m, vec<double>& w, const steady_options& opt, Residual&& residual) {
  check_steady_options(opt, "solve_steady");
  require_size(w.size(), m.size(), "solve_steady", "state");
  auto fn = [&residual](const vec<double>& x) { return vec<double>(residual(x)); };
  euler_discretisation<Dim, decltype(fn)> d(m, fn);
  return solve_steady(d, w, opt);
}

/// solve_steady with the model's own residual.
template <int Dim>
steady_report solve_steady(euler_model<Dim>& m, vec<double>& w, const steady_options& opt = {}) {
  return solve_steady<Dim>(m, w, opt, [&m](const vec<double>& x) { return vec<double>(m.residual(x)); });
}

}  // namespace aerohopf::flow
