// Steady solver: 10-orders residual drop on the very coarse and medium C-grids at M = 0.5,
// alpha = 0, with the closed-form checks CL = 0 (symmetry, to rounding), upper/lower Cp equal,
// and the stagnation Cp against the isentropic value (2/(gamma M^2))((1 + 0.2 M^2)^3.5 - 1).
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>

#include <algorithm>
#include <cmath>

using namespace aerohopf;
using namespace aerohopf::flow;

TEST(steady_solver, subsonic_symmetric_flow_converges_ten_orders) {
  for (int level : {8, 2}) {
    euler_model<2> m(coarsen(naca_cgrid(), level), {.mach = 0.5, .alpha_rad = 0.0});
    auto w = m.free_stream_vector();
    steady_options opt;
    opt.exact_switch_drop = 1e-3;
    const auto rep = solve_steady<2>(m, w, opt);
    EXPECT_TRUE(rep.converged);
    EXPECT_LE(rep.final_residual, 1e-10 * rep.initial_residual);
    EXPECT_LT(rep.steps, 80) << "level " << level;
    EXPECT_LT(m.residual(w).norm() / std::sqrt(double(w.size())), 1e-10 * rep.initial_residual);
    const auto f = m.forces(w);
    EXPECT_LT(std::abs(f.cl), 1e-9) << "level " << level;
    EXPECT_LT(std::abs(f.cm), 1e-9) << "level " << level;
    // wall faces come lower surface (TE -> LE) then upper (LE -> TE): mirror pairs
    const auto wall = m.wall_faces(w);
    const std::size_t n = wall.size();
    for (std::size_t k = 0; k < n / 2; ++k) {
      EXPECT_NEAR(wall[k].centre[0], wall[n - 1 - k].centre[0], 1e-12);
      EXPECT_NEAR(wall[k].cp, wall[n - 1 - k].cp, 1e-8);
    }
    if (level == 8) {  // deflated restarts of short GMRES cycles: the same steady state
      steady_options d = opt;
      d.krylov.restart = 8;
      d.krylov.deflation = 4;
      auto wd = m.free_stream_vector();
      const auto rd = solve_steady<2>(m, wd, d);
      EXPECT_TRUE(rd.converged);
      EXPECT_LT((wd - w).cwiseAbs().maxCoeff(), 1e-8);
    }
    if (level == 2) {
      double cp_max = -1e9;
      for (const auto& wf : wall) cp_max = std::max(cp_max, wf.cp);
      const double cp0 = 2.0 / (1.4 * 0.25) * (std::pow(1.0 + 0.2 * 0.25, 3.5) - 1.0);
      // the wall face centres nearest the leading edge lie about 0.002 c from the stagnation point
      EXPECT_NEAR(cp_max, cp0, 0.15 * cp0);
      EXPECT_LT(cp_max, cp0);  // a finite-volume average never overshoots the isentropic peak here
    }
  }
}

TEST(steady_solver, rejects_bad_input) {
  euler_model<2> m(coarsen(naca_cgrid(), 8), {.mach = 0.5});
  vec<double> w = m.free_stream_vector();
  w[0] = -1.0;  // negative density
  EXPECT_THROW(solve_steady<2>(m, w), input_error);
  vec<double> short_state(3);
  EXPECT_THROW(solve_steady<2>(m, short_state), input_error);
}

// The point-vortex far field removes the dependence of the lift on the far-field distance:
// the medium grid (same points) with the outer boundary at 15 and at 50 chords, M = 0.8,
// alpha = 1.25 deg, where the lift of a plain characteristic far field at 15 chords is ~5% low.
TEST(steady_solver, vortex_far_field_removes_domain_size_dependence) {
  double cl[2][2];
  for (int v = 0; v < 2; ++v)
    for (int k = 0; k < 2; ++k) {
      naca_cgrid_options go;
      go.far_field = k == 0 ? 15.0 : 50.0;
      euler_options eo;
      eo.vortex_far_field = v == 1;
      euler_model<2> m(coarsen(naca_cgrid(go), 2), {.mach = 0.8, .alpha_rad = 1.25 * M_PI / 180}, eo);
      auto w = m.free_stream_vector();
      steady_options opt;
      opt.exact_switch_drop = 1e-3;
      opt.residual_drop = 1e-8;
      (void)solve_steady<2>(m, w, opt);
      cl[v][k] = m.forces(w).cl;
      if (v == 1) {
        EXPECT_NEAR(m.circulation(), 0.5 * cl[v][k], 1e-6);
      }
    }
  const double without = std::abs(cl[0][0] - cl[0][1]), with = std::abs(cl[1][0] - cl[1][1]);
  EXPECT_GT(without, 0.01);
  EXPECT_LT(with, 0.3 * without) << cl[0][0] << " " << cl[0][1] << " " << cl[1][0] << " " << cl[1][1];
}

// ---- broken promises and fault injection (reliability) ----
namespace {
/// The model's residual with injected faults: NaN in entry 7 on residual call nan_from (and on
/// every later call while persistent), an aerohopf::error thrown on call throw_call.
struct faulty_residual {
  const euler_model<2>& m;
  int nan_from = -1, throw_call = -1;
  bool persistent = false;
  int* calls;
  vec<double> operator()(const vec<double>& w) const {
    const int c = ++*calls;
    if (c == throw_call) throw error("faulty residual: refused");
    vec<double> r = m.residual(w);
    if (c == nan_from || (persistent && nan_from > 0 && c > nan_from)) r[7] = NAN;
    return r;
  }
};
bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }
}  // namespace

// One NaN residual (the trial state of step 3): the step is rejected and recorded (which step,
// what was non-finite), the run goes on and reaches the uninjected answer.
TEST(steady_solver, nan_residual_once_is_rejected_and_recorded) {
  euler_model<2> m(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.02});
  steady_options opt;
  vec<double> clean = m.free_stream_vector();
  ASSERT_TRUE(solve_steady<2>(m, clean, opt).converged);
  int calls = 0;
  vec<double> w = m.free_stream_vector();
  const auto rep = solve_steady<2>(m, w, opt, faulty_residual{m, 4, -1, false, &calls});
  EXPECT_TRUE(rep.converged) << rep.reason;
  ASSERT_EQ(rep.rejections.size(), 1u);
  EXPECT_TRUE(has(rep.rejections[0], "step 3: residual of the trial state not finite (entry 7")) << rep.rejections[0];
  EXPECT_LT((w - clean).norm(), 1e-8 * clean.norm());
}

// A residual that stays NaN from the trial state of step 3 on: CFL_0 collapses; with
// throw_on_failure = false the report says so (solve_steady, the step, ||R||, M, what was
// non-finite), w is the last accepted state, and the run continues from it to the uninjected
// answer. Thrown: the same message. An exception inside a step keeps its type and gets the
// context.
TEST(steady_solver, persistent_nan_residual_fails_clearly_and_keeps_the_last_good_state) {
  euler_model<2> m(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.02});
  steady_options opt;
  vec<double> clean = m.free_stream_vector();
  ASSERT_TRUE(solve_steady<2>(m, clean, opt).converged);
  steady_options soft = opt;
  soft.throw_on_failure = false;
  int calls = 0;
  vec<double> w = m.free_stream_vector();
  const auto rep = solve_steady<2>(m, w, soft, faulty_residual{m, 4, -1, true, &calls});
  EXPECT_FALSE(rep.converged);
  EXPECT_EQ(rep.steps, 2);
  EXPECT_TRUE(has(rep.reason, "solve_steady: CFL_0 collapsed")) << rep.reason;
  EXPECT_TRUE(has(rep.reason, "residual of the trial state not finite (entry 7")) << rep.reason;
  EXPECT_TRUE(has(rep.reason, "M = 0.5")) << rep.reason;
  EXPECT_TRUE(has(rep.reason, aerohopf::internal::concat("||R||/sqrt(n) = ", rep.history.back().residual))) << rep.reason;
  ASSERT_TRUE(w.allFinite());
  EXPECT_TRUE(physical_state<2>(m, w));
  EXPECT_NEAR(m.residual(w).norm() / std::sqrt(double(w.size())), rep.final_residual, 1e-14 * rep.initial_residual);
  // continue from the last good state without the fault
  ASSERT_TRUE(solve_steady<2>(m, w, opt).converged);
  EXPECT_LT((w - clean).norm(), 1e-8 * clean.norm());

  calls = 0;
  vec<double> w2 = m.free_stream_vector();
  try {
    solve_steady<2>(m, w2, opt, faulty_residual{m, 4, -1, true, &calls});
    FAIL() << "expected convergence_error";
  } catch (const convergence_error& e) {
    EXPECT_TRUE(has(e.what(), "CFL_0 collapsed")) << e.what();
  }
  calls = 0;
  vec<double> w3 = m.free_stream_vector();
  try {
    solve_steady<2>(m, w3, opt, faulty_residual{m, -1, 3, false, &calls});
    FAIL() << "expected an error";
  } catch (const convergence_error&) {
    FAIL() << "the type of the original error must be kept";
  } catch (const error& e) {
    EXPECT_TRUE(has(e.what(), "solve_steady: step 2 (")) << e.what();
    EXPECT_TRUE(has(e.what(), "faulty residual: refused")) << e.what();
  }
  EXPECT_TRUE(physical_state<2>(m, w3));
}

// Options and the state are checked before anything is touched: input_error naming the option
// or the first non-finite entry.
TEST(steady_solver, rejects_bad_options_and_nan_state_naming_them) {
  euler_model<2> m(coarsen(naca_cgrid(), 8), {.mach = 0.5});
  const vec<double> w0 = m.free_stream_vector();
  auto refused = [&](steady_options o, const char* name) {
    vec<double> w = w0;
    try {
      solve_steady<2>(m, w, o);
      ADD_FAILURE() << "expected input_error for " << name;
    } catch (const input_error& e) {
      EXPECT_TRUE(has(e.what(), name)) << e.what();
    }
    EXPECT_EQ(w, w0);
  };
  steady_options o;
  o.cfl_initial = NAN;
  refused(o, "cfl_initial");
  o = {};
  o.residual_drop = NAN;
  refused(o, "residual_drop");
  o = {};
  o.krylov.relative_tolerance = 0;
  refused(o, "krylov.relative_tolerance");
  o = {};
  o.ser_exponent = NAN;
  refused(o, "ser_exponent");
  o = {};
  o.max_steps = -1;
  refused(o, "max_steps");
  o = {};
  o.stall_factor = 1.5;
  refused(o, "stall_factor");
  o = {};
  o.fill_level = -1;
  refused(o, "fill_level");
  o = {};
  o.krylov.deflation = o.krylov.restart - 1;
  refused(o, "krylov: deflation");
  vec<double> w = w0;
  w[5] = NAN;
  try {
    solve_steady<2>(m, w);
    FAIL() << "expected input_error";
  } catch (const input_error& e) {
    EXPECT_TRUE(has(e.what(), "state entry 5")) << e.what();
  }
  EXPECT_TRUE(std::isnan(w[5]));
}

// A Newton phase that cannot converge (one GMRES iteration per step) is reported as stalled,
// naming the cell with the largest residual, instead of running to max_steps; the same case with
// the default linear solves converges, also with BILU(1) as the preconditioner.
TEST(steady_solver, stalled_newton_fails_clearly_naming_the_worst_cell) {
  euler_model<2> m(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.02});
  steady_options o;
  o.exact_switch_drop = 1.0;  // Newton from the first step on
  o.krylov.max_iterations = 1;
  o.krylov.restart = 1;
  o.stall_steps = 3;
  o.stall_factor = 0.01;
  vec<double> w = m.free_stream_vector();
  try {
    solve_steady<2>(m, w, o);
    FAIL() << "expected convergence_error";
  } catch (const convergence_error& e) {
    EXPECT_TRUE(has(e.what(), "Newton stalled")) << e.what();
    EXPECT_TRUE(has(e.what(), " cell (")) << e.what();
    EXPECT_TRUE(has(e.what(), "largest residual")) << e.what();
  }
  EXPECT_TRUE(m.is_physical(w));  // the last accepted state
  for (int fill : {0, 1}) {
    steady_options d;
    d.fill_level = fill;
    vec<double> v = m.free_stream_vector();
    const steady_report r = solve_steady<2>(m, v, d);
    EXPECT_TRUE(r.converged) << "BILU(" << fill << "): " << r.reason;
  }
}
