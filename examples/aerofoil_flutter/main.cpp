// Flutter of the pitch-plunge NACA 0012 (spec 05): direct Hopf-point stability boundaries
// Ubar(M), their verification by dense spectra and by time marching, and the centre-manifold
// reduced model at a transonic Mach number of the heavy case.
//
// Usage: aerofoil_flutter [out_dir] [options]
//   --case light|heavy|both     structural case (mu_s = 10 / 100), default both
//   --grids coarse,medium       grid levels of the boundaries (very_coarse, coarse, medium, fine)
//   --mach-min M --mach-max M   Mach range (default 0.5 .. 0.95; steps 0.05, and 0.01 from 0.80)
//   --mach-step d               one uniform step instead of the default list
//   --method natural|arclength  boundary by natural continuation in M (previous point as the
//                               start, secant predictor, step halving on failure) or by
//                               pseudo-arclength continuation of the Hopf curve in (M, Ubar)
//   --fill k                    BILU(k) of the Hopf preconditioner (default 2)
//   --hopf-tol t                Newton tolerance ||F|| of the boundary points (default 1e-7)
//   --start-iterations k        inverse iterations on the continued eigenvector before each
//                               boundary point's Newton iteration (default 1; 0 = none)
//   --hopf-gram-schmidt once|twice   Gram-Schmidt passes in the GMRES of the Hopf Newton
//                               corrections (default once: hopf_krylov_options)
//   --start-gram-schmidt once|twice  ... of the inverse-power start (default once)
//   --skip-spectra --skip-boundaries --skip-vg --skip-jump-check --skip-verify --skip-reduced   parts to leave out
//   --vg-mach M                 Mach number of the V-g / V-f diagrams (default 0.80)
//   --vg-grid g                 their grid (default the first of --grids)
//   --vg-solver lu|krylov|auto  linear algebra of the diagrams' inverse powers: sparse LU of A - sigma I,
//                               or GMRES preconditioned by BILU(--fill) of the modified-order L - sigma I
//                               (auto: LU up to the coarse grid)
//   --vg-range a,b --vg-points n   Ubar from a Ubar* to b Ubar* in n values (default 0.5,1.4 and 40;
//                               Ubar* from this run's boundary point at --vg-mach, else a Hopf solve)
//   --verify-grid g             grid of the time-marching verification (default medium)
//   --contact-smoothing d       contact-switch smoothing of the reduced-model part (default 0.05;
//                               0 = exact Osher switch, whose residual is not C2 at the equilibrium)
//   --quick                     coarse grid, M = 0.5 .. 0.8 step 0.1, shorter time marching
//   --tracer-corrector joint|nested   corrector of the arclength hand-over: the flow as an unknown
//                               of the corrector, one steady Newton step per iteration (joint, the
//                               default), or a nested steady solve at every iterate's M (nested)
//   --jump-search bottom|top    where the start from the previous point converges to another mode at
//                               the full Mach step, try 1/8 of the step next (bottom, default) or
//                               halve the step down to 1/8 (top)
//   --coarse-restart on|off     where the start from the previous boundary point fails at a listed
//                               Mach number, restart from the coarser grid's point there before
//                               halving the step (default on; finer grids of a multi-grid run only)
//   --coarse-guided-restart on|off  restart from the coarser grid's point BEFORE the start from the
//                               previous point where the coarser boundary changes mode and its branch
//                               ends within 1/4 of the listed step (default on)
//   --coarse-predictor off|values|full|auto  predict Ubar*, omega* (values) and the eigenvector
//                               (full) from the previous point plus the coarser boundary's increment
//                               between the two Mach numbers; auto (default): the eigenvector only
//                               where the secant one's Hopf residual exceeds the refinement threshold
//   --tracer-max-step s         largest arclength step of the hand-over, in its metric (default 1)
//   --tracer-dw-tol t           GMRES tolerance of dw0/dnu in the arclength hand-over
//                               (symmetric_hopf_curve_options::derivative_tolerance)
//   --crossing-medium           run the crossing check (every imaginary-axis crossing at the jumps
//                               and last points) on the medium grid too, not only the coarse one
//   --verbose                   a line per Hopf Newton iteration (and per arclength corrector iteration)
//
// Outputs under out_dir (default out/aerofoil_flutter):
//   flutter_point_very_coarse.txt, spectra.csv (ubar,re,im)     very coarse, light, M = 0.5
//   boundary_<case>_very_coarse.csv, jump_check.csv             boundary jumps checked by dense spectra
//   crossing_check.csv (case,grid,mach,ubar_star,omega_star,ubar,omega)   every imaginary-axis crossing at
//                               the jumps and last points of the coarse/medium boundaries (Schur complement)
//   boundary_<case>_<grid>.csv  mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds
//   vg_<case>_<grid>_M<mach>.csv  mode,parameter,damping_g,frequency,re,im: V-g / V-f diagram (parameter
//                               Ubar; g = 2 Re/|Im lambda|; frequency |Im lambda| in 1/(c/U_inf);
//                               mode 0 plunge, 1 pitch by in-vacuo frequency)
//   vg_flutter_<case>_<grid>_M<mach>.csv  mode,parameter,frequency,hopf_parameter,hopf_frequency:
//                               its zero crossings of g, against the Hopf point
//   verification.csv, history_<case>_M<mach>_<factor>.csv       time marching at 0.97 / 1.03 Ubar*
//   costs.csv                                                   cost ratios to the steady solve
//   reduced_coefficients.csv, reduced_damping.csv, reduced_lco.csv   reduced model (heavy case)
//   reduced_envelope.csv        amplitude-dependent growth rate: time marching vs reduced model
// plot.py in this folder turns them into PNGs.
#include <aerohopf/bifurcation/axis_crossings.hpp>
#include <aerohopf/bifurcation/equilibrium_krylov.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/hopf_curve.hpp>
#include <aerohopf/bifurcation/hopf_curve_symmetric.hpp>
#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/reduction.hpp>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/time/bdf2.hpp>

#include "setup.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::flow;
using namespace aerofoil_example;
using cplx = std::complex<double>;

namespace {

struct options {
  std::filesystem::path out = "out/aerofoil_flutter";
  std::vector<structural_case> cases{light_case, heavy_case};
  std::vector<grid_level> grids{level_named("coarse"), level_named("medium")};
  double mach_min = 0.5, mach_max = 0.95, mach_step = 0;
  std::string method = "natural";
  // BILU(2): measured on the medium grid (M 0.5-0.80, step 0.05), mean Hopf / steady heavy 0.89
  // vs 0.99 with BILU(1), light 0.52 both, inverse-power start 6.4 / 4.3 s vs 9.1 / 5.0 s
  int fill = 2;
  double contact_smoothing = 0.05;  // of the reduced model's discretisation (osher_flux.hpp)
  bool spectra = true, boundaries = true, jump_check = true, verify = true, reduced = true, quick = false;
  bool vg = true;
  double vg_mach = 0.80;  // transonic (shocks on both surfaces), as the reduced model
  std::optional<grid_level> vg_grid;  // default: the first of grids
  double vg_from = 0.5, vg_to = 1.4;  // Ubar range of the diagrams, in Ubar*
  // 40 values: steps of 0.023 Ubar*, none of them Ubar* itself, so that the g = 0 crossing is a
  // genuine interpolation (the cubic's error at this step: ~1e-4 relative, test_vg_diagram.cpp)
  int vg_points = 40;
  std::string vg_solver = "auto";  // lu | krylov | auto (LU up to the coarse grid)
  bool crossing_medium = false;  // --crossing-medium: the crossing check on the medium grid too (~1 s per LU)
  grid_level verify_grid = level_named("medium");
};

/// true if m is one of the listed Mach numbers (to 1e-9)
bool is_listed(const std::vector<double>& machs, double m) {
  return std::any_of(machs.begin(), machs.end(), [&](double l) { return std::abs(l - m) < 1e-9; });
}

std::vector<double> mach_list(const options& o) {
  std::vector<double> m;
  if (o.mach_step > 0) {
    for (int k = 0;; ++k) {
      const double x = o.mach_min + k * o.mach_step;
      if (x > o.mach_max + 1e-9) break;
      m.push_back(std::round(x * 1e4) / 1e4);
    }
    return m;
  }
  for (int k = 0; k <= 6; ++k) m.push_back(0.5 + 0.05 * k);  // 0.50 .. 0.80
  for (int k = 1; k <= 15; ++k) m.push_back(0.80 + 0.01 * k);  // 0.81 .. 0.95
  std::vector<double> r;
  for (double x : m)
    if (x >= o.mach_min - 1e-9 && x <= o.mach_max + 1e-9) r.push_back(std::round(x * 1e4) / 1e4);
  return r;
}

bool verbose_newton = false;  // --verbose: a line per Newton iteration
int start_iterations = 1;     // --start-iterations (hopf_krylov_options::start_iterations)
int start_restart = 50;       // --start-restart: GMRES restart of the inverse-power start (50: measured
                              // light medium start 5.0-5.8 s vs 6.9-7.3 s with 80; heavy equal)
double start_tolerance = 1e-2;  // --start-tolerance (hopf_krylov_options::start_tolerance)
int hopf_restart = 80;          // --hopf-restart: GMRES restart of the Hopf Newton corrections
double hopf_forcing = 1.0;      // --hopf-forcing: hopf_krylov_options::forcing_exponent
bool hopf_reorthogonalize = false;  // --hopf-gram-schmidt once|twice: krylov_options::reorthogonalize of the
                                    // Newton corrections (once: the library default, see hopf_krylov_options)
bool start_reorthogonalize = false;  // --start-gram-schmidt once|twice: ... of the inverse-power start (once:
                                     // the same GMRES counts at tolerance 1e-9, light medium start 5.7 s
                                     // instead of 6.9 s, measured)

/// Newton criterion ||F|| <= tolerance on the Hopf system (p normalised by s.p = i at its
/// largest component). Boundaries use 1e-7 (--hopf-tol): measured on the medium grid, Ubar*
/// then changes by < 1e-9 relative in a further iteration (light case, M = 0.6: 3e-10 from
/// ||F|| = 6.6e-8), far below the grid error (1-3 %),
/// and the last, most expensive Newton step (GMRES to 1e-5) is saved. The very coarse check
/// and the reduced model keep 1e-10. That one case is not the rule: ||F|| <= 1e-7 fixes Ubar*
/// only to about 2e-5 relative on the heavy medium boundary (Ubar* enters only through the
/// structural stiffness, so dF/dUbar is small). Measured there: two runs with different
/// predictors differ by up to 1.7e-5 (M = 0.82: 4.184011 at ||F|| = 8.6e-8, 4.184081 at
/// 1.0e-8), and by 1.6e-5 from a run to 1e-9, which costs 14 % more (0.86 -> 0.98 steady solves
/// per listed Mach number).
double boundary_tolerance = 1e-7;
bool tracer_joint = true;  // --tracer-corrector joint|nested: symmetric_hopf_curve_options::joint_equilibrium
double tracer_max_step = 0;  // --tracer-max-step: hopf_curve_options::max_step of the hand-over (0: 1.0)
bool jump_search_bottom = true;  // --jump-search bottom|top: natural_boundary's search after an other-mode point
bool use_coarse_restart = true;  // --coarse-restart on|off: natural_boundary's grid-sequenced restart
bool coarse_guided_restart = true;  // --coarse-guided-restart on|off: natural_boundary's restart BEFORE the start
                                    // from the previous point where the coarser boundary changes mode
double start_residual_threshold = 10.0;  // hopf_krylov_options::start_residual_threshold of hopf_at: subsonic
                                        // continued guesses (||F|| 3-7) go straight to Newton
int coarse_predictor = 3;  // --coarse-predictor off|values|full|auto: natural_boundary's predictor from the
                           // coarser boundary's increments (0 off; 1 Ubar and omega; 2 also the eigenvector;
                           // 3 Ubar and omega, and the eigenvector where the secant one is far off)
double tracer_derivative_tolerance = 0;  // --tracer-dw-tol: symmetric_hopf_curve_options::derivative_tolerance
                                         // of the hand-over (0: aerofoil_tracer_options' value)

hopf_options hopf_opts(const std::string& label, double tolerance = 1e-10) {
  hopf_options ho;
  ho.symmetric = true;
  ho.label = label;
  ho.newton.abs_tolerance = tolerance;
  ho.newton.max_iterations = 20;
  ho.verbose = verbose_newton;
  return ho;
}

/// Inverse-power start of the Hopf Newton iteration at (w, Ubar) with shift i omega (spec 02):
/// GMRES on the exact A - i omega I preconditioned by the complex BILU(k) of the modified-order
/// L - i omega I (krylov_solver::precondition_with); no sparse LU. GMRES to 1e-9 per solve:
/// inexact inverse iteration stagnates near the solve tolerance (inverse_power.hpp).
hopf_point krylov_start(const aerofoil_system& s, const vec<double>& w, double ubar, double omega, int fill) {
  krylov_solver_options ko;
  ko.fill_level = fill;
  ko.krylov.relative_tolerance = 1e-9;
  ko.krylov.max_iterations = 2000;
  ko.krylov.restart = start_restart;
  ko.krylov.record_history = false;
  ko.krylov.reorthogonalize = start_reorthogonalize;
  krylov_solver<Eigen::SparseMatrix<cplx>, 4> solver(ko, "inverse power, complex BILU-GMRES");
  solver.precondition_with(shifted(lhs_jacobian(s, w, ubar), cplx(0.0, omega)));
  inverse_power_options ipo;
  ipo.tolerance = 1e-8;  // a start for Newton, which converges the pair exactly
  const auto t0 = clk::now();
  const eigen_pair ep = inverse_power(s.jacobian(w, ubar), cplx(0.0, omega), ipo, nullptr, solver);
  std::printf("    inverse power (BILU(%d)-GMRES): lambda = %+.6f %+.6fi, %d iterations, %ld GMRES iterations, %.2f s\n",
              fill, ep.lambda.real(), ep.lambda.imag(), ep.iterations, ep.linear_iterations, seconds_since(t0));
  return aerohopf::internal::hopf_point_from(w, ubar, ep);
}

// ---------------------------------------------------------------------------------------------
// Part 1: very coarse grid, light case, M = 0.5: Hopf point and the dense spectra around it.

void spectra_part(const options& o) {
  std::cout << "\n=== very coarse grid, light case, M = 0.5: flutter point and dense spectra ===\n";
  const auto s = make_system(level_named("very_coarse"), 0.5, light_case.mu_s);
  const auto st = steady(s);
  hopf_options ho = hopf_opts("hopf very coarse");
  ho.verbose = true;
  const hopf_result h = solve_hopf_krylov<4>(s, krylov_start(s, st.w, light_case.ubar_guess, light_case.omega_guess, o.fill), ho);
  const double ubar = h.point.mu, omega = h.point.omega;
  std::cout << std::setprecision(10) << "very coarse grid (" << s.flow().n_cells() << " cells), light case, M = 0.5: Ubar* = "
            << ubar << ", omega* = " << omega << " (" << h.report.iterations << " Newton iterations)\n";
  {
    std::ofstream f(o.out / "flutter_point_very_coarse.txt");
    f << std::setprecision(12) << "ubar_star " << ubar << "\nomega_star " << omega << "\n";
  }
  csv_writer csv(o.out / "spectra.csv", "ubar_offset,ubar,re,im");
  for (double d : {-0.01, 0.0, 0.01}) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(st.w, ubar + d)), false);
    cplx crit = es.eigenvalues()[0];
    double other = -1e300;
    for (const auto& l : es.eigenvalues()) {
      csv.row({d, ubar + d, l.real(), l.imag()});
      if (std::abs(l - cplx(0, omega)) < std::abs(crit - cplx(0, omega))) crit = l;
    }
    for (const auto& l : es.eigenvalues())
      if (std::abs(l - crit) > 1e-9 && std::abs(l - std::conj(crit)) > 1e-9) other = std::max(other, l.real());
    std::cout << "  Ubar* " << (d < 0 ? "- 0.01" : d > 0 ? "+ 0.01" : "       ") << ": critical eigenvalue " << crit
              << ", largest real part of the others " << other << "\n";
  }
}

// ---------------------------------------------------------------------------------------------
// Part 2: stability boundaries Ubar(M) by the direct method.

struct boundary_point {
  double mach, ubar, omega;
  int newton_iterations;
  long linear_iterations;
  double hopf_seconds, steady_seconds;
  hopf_point point;  // with the flow state of this Mach number
  // false for the points of an arclength stretch: their steady_seconds is the unit of cost
  // (the steady solve where the stretch starts), not a steady solve run at their Mach number
  bool own_steady = true;
};

using boundary = std::vector<boundary_point>;

/// One Hopf point at Mach M from the guess (p, Ubar, omega); steady flow from the free stream.
std::optional<boundary_point> hopf_at(const aerofoil_system& s, double mach, const steady_result& st,
                                      const hopf_point& guess, int fill, const std::string& label) {
  hopf_point g = guess;
  g.w = st.w;
  hopf_krylov_options ko;
  ko.fill_level = fill;
  // Ubar enters A only through the stiffness (1/Ubar^2), so A0 + dUbar A_mu0 stays an accurate
  // operator over a continuation step (the predictor is off by ~0.5 % in Ubar); re-assembling
  // at the first Newton iterate (the default 0.2 % window) cost 25 % of a Hopf point, measured.
  ko.reuse_window = 2e-2;
  ko.start_iterations = start_iterations;
  ko.start_tolerance = start_tolerance;
  ko.start_residual_threshold = start_residual_threshold;
  ko.krylov.restart = hopf_restart;
  ko.forcing_exponent = hopf_forcing;
  ko.krylov.reorthogonalize = hopf_reorthogonalize;
  hopf_options ho = hopf_opts(label, boundary_tolerance);
  // from a refined continuation start Newton needs 2-4 iterations (light medium, M 0.55-0.90);
  // a point still unconverged after 12 is abandoned for a smaller Mach step
  ho.newton.max_iterations = 12;
  // ... and abandoned as soon as ||F|| more than doubles after the first step
  // (newton_options::max_contraction): measured on the heavy medium boundary, the failures near
  // M = 0.83 rose 29-230x at iterations 2-4 and then wandered (mu -> 1e77) until iteration 8-12;
  // a bound of 1 (monotonicity) also stopped the light medium point at M = 0.905, which rises
  // 1.43x at iteration 3 and then converges
  ho.newton.max_contraction = 2.0;
  // The contraction test starts at the second step (the first may raise ||F||); a first step
  // that raises it more than 100x is abandoned too (newton_options::divergence_factor).
  // Measured, ||F_1|| / ||F_0|| over the default coarse and medium boundaries, both cases: at
  // most 33 where Newton then converged (heavy coarse M = 0.91, the other mode), 125-1812 at the
  // attempts that failed after 5-7 iterations (heavy, M = 0.9025 and 0.82625: omega* -> 4-6, Ubar*
  // -> 1e85); one failure rose 92x and is still left to the contraction test.
  ho.newton.divergence_factor = 100.0;
  const auto t0 = clk::now();
  try {
    hopf_result h = solve_hopf_krylov<4>(s, g, ho, ko);
    // Ubar enters the model only through 1/Ubar^2 (spec 05), so -Ubar* is the same point:
    // Newton may land on that mirror image; report the physical, positive speed.
    h.point.mu = std::abs(h.point.mu);
    if (verbose_newton)
      std::printf("    %s: setup (assembly + BILU) %.3f s, GMRES %.3f s, residuals %.3f s\n", label.c_str(), h.setup_seconds,
                  h.linear_seconds, h.residual_seconds);
    return boundary_point{mach, h.point.mu, h.point.omega, h.report.iterations, h.linear_iterations,
                          seconds_since(t0), st.seconds, h.point};
  } catch (const error& e) {
    std::cout << "    " << label << " failed: " << e.what() << "\n";
    return std::nullopt;
  }
}

/// Cosine of the angle between the structural parts (h, h', alpha, alpha') of two eigenvectors:
/// the mode test of natural continuation. Measured on the light medium boundary: 0.957-0.9991
/// between neighbouring points of one branch (Mach steps up to 0.05, also across the steep rise
/// of Ubar* by 22 % between M = 0.75 and 0.80), 0.81-0.82 for the other mode's Hopf point past
/// M = 0.90. The flow part is no test: shock motion rotates it (full cosine 0.16-0.45 on one branch).
double structural_cosine(const vec<cplx>& p0, const vec<cplx>& p1) {
  const vec<cplx> s0 = p0.tail(aerofoil_system::n_structure), s1 = p1.tail(aerofoil_system::n_structure);
  return std::abs(s0.dot(s1)) / (s0.norm() * s1.norm());
}
constexpr double same_mode_cosine = 0.9;

/// Hand-over of natural continuation to pseudo-arclength continuation where natural continuation
/// stops: a steep stretch of the boundary, where the Hopf point moves so fast with M that no
/// Mach step of the secant predictor lands in Newton's basin (heavy case, coarse grid: at
/// M = 0.826-0.828 Ubar* peaks at ~6.1 while omega* moves from 0.20 to 0.41). The symmetric
/// Hopf-curve tracer (trace_symmetric_hopf_curve, options of aerofoil_tracer_options) starts
/// from the last boundary point `from` and follows the curve in (M, Ubar, omega) up to the first
/// listed Mach number above from.mach that it lands on exactly, and stops there, or earlier if
/// the curve turns back in M by more than 0.005 (the boundary is then not this curve: natural
/// continuation finds the other mode) or the tracer fails (dense kinks). Returns its accepted points with
/// M > from.mach, in M order; natural continuation resumes from the last one. Their
/// steady_seconds is from.steady_seconds (the unit of cost: no extra steady solves are run).
boundary arclength_bridge(const structural_case& c, const grid_level& g, const std::vector<double>& machs,
                          const boundary_point& from, int fill) {
  const double m_max = machs.back();
  tracer_options to = aerofoil_tracer_options(g, c, from.mach, m_max, fill);
  hopf_curve_options& ho = to.curve;
  if (tracer_max_step > 0) {  // --tracer-max-step: the cap, and the first step no larger than it
    ho.max_step = tracer_max_step;
    ho.step = std::min(ho.step, tracer_max_step);
  }
  ho.nu_targets.clear();
  for (double m : machs)
    if (m > from.mach + 1e-9) ho.nu_targets.push_back(m);
  ho.max_points = 200;
  ho.label = c.name + " " + g.name + " arclength";
  ho.start.newton.abs_tolerance = boundary_tolerance;
  ho.newton.abs_tolerance = boundary_tolerance;
  if (verbose_newton) ho.newton.observer = newton_progress("      corrector");
  if (tracer_derivative_tolerance > 0) to.symmetric.derivative_tolerance = tracer_derivative_tolerance;
  to.symmetric.joint_equilibrium = tracer_joint;
  double m_hi = from.mach;
  const double fold_tolerance = 0.005;
  boundary out;
  to.symmetric.observer = [&](const hopf_curve_point& p, const symmetric_hopf_curve_stats& st) {
    if (p.nu <= m_hi + 1e-9) return;  // the start, or a point back in M
    m_hi = p.nu;
    hopf_point q = p.point();
    q.mu = std::abs(q.mu);  // Ubar enters only through 1/Ubar^2 (spec 05)
    out.push_back({p.nu, q.mu, p.omega, p.newton_iterations, st.linear_iterations, p.seconds, from.steady_seconds,
                   std::move(q), false});
  };
  // a fold in M smaller than half a listed step (medium grid: the curve turns back by ~1e-4 in M at
  // the Ubar* peak near M = 0.826 and forward again) is traced through; the points on its way
  // back are not boundary points (the observer skips them: the boundary jumps to the branch below)
  // A RETRACE is different: at a kink the corrector can turn round and follow the curve back
  // (measured on the medium grid at M = 0.8276: 18 points with M falling by 1e-5 each, each one
  // near the stretch traced just before). Stop when a point comes within retrace_distance (in
  // the tracer's metric; steps are 0.3-0.85 there) of the polyline of this trace's points before
  // the last three. A genuine fold moves away from it in omega (medium grid, M = 0.826: >= 0.7).
  std::vector<Eigen::Vector3d> trail;  // scaled (Ubar, M, omega) of the accepted points
  const double retrace_distance = 0.1;
  std::string why = "landed";
  ho.stop_after = [&](const hopf_curve_point& p) {
    const Eigen::Vector3d y(std::abs(p.mu) / ho.mu_scale, p.nu / ho.nu_scale, p.omega / ho.omega_scale);
    const std::size_t n_old = trail.size() >= 3 ? trail.size() - 3 : 0;  // points before the last three
    double d = n_old > 0 ? (trail[0] - y).norm() : INFINITY;
    for (std::size_t k = 0; k + 1 < n_old; ++k) {
      const Eigen::Vector3d a = trail[k], e = trail[k + 1] - a;
      const double t = e.squaredNorm() > 0 ? std::clamp((y - a).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
      d = std::min(d, (a + t * e - y).norm());
    }
    trail.push_back(y);
    if (d < retrace_distance) {
      why = "retrace: the trace turned back along the curve at a kink";
      return true;
    }
    if (p.nu < m_hi - fold_tolerance) {
      why = "the curve turns back in M by more than " + fixed(fold_tolerance, 3);
      return true;
    }
    return p.landed && p.nu > from.mach + 1e-9;
  };
  auto family = [&](double mach) { return make_system(g, mach, c.mu_s); };
  std::printf("    hand-over to pseudo-arclength continuation of the Hopf curve from M = %.5f (Ubar* = %.5f, omega* = "
              "%.5f) up to the next listed Mach number\n",
              from.mach, from.ubar, from.omega);
  symmetric_hopf_curve_result r;
  const auto t_bridge = clk::now();
  // The cost of the stretch not in its boundary points' own steps (the re-solved start, the
  // points back in M, the step that crossed the landed Mach number): charged to its last point,
  // so that the boundary's hopf_seconds add up to the whole stretch.
  auto charge_rest = [&] {
    if (out.empty()) return;
    double own = 0;
    for (const auto& q : out) own += q.hopf_seconds;
    out.back().hopf_seconds += std::max(0.0, seconds_since(t_bridge) - own);
  };
  try {
    r = trace_symmetric_hopf_curve<4>(family, from.mach, from.point, ho, +1, to.symmetric);
  } catch (const error& e) {  // e.g. the start's nested steady solve: keep what was traced
    std::printf("    arclength failed: %s\n", e.what());
    charge_rest();
    return out;
  }
  charge_rest();
  long gmres_hopf = 0, gmres_steady = 0;
  for (const auto& st : r.stats) {
    gmres_hopf += st.linear_iterations;
    gmres_steady += st.steady_linear_iterations;
  }
  std::printf("    arclength (%s corrector): %zu points (%zu beyond M = %.5f), %d failed correctors, %d steps at fixed M "
              "or Ubar, %d nested steady solves, %d flow Newton steps (%.2f s with dw0/dnu), GMRES %ld Hopf + %ld "
              "steady and dw0/dnu, %.2f s; stop: %s\n",
              tracer_joint ? "joint" : "nested", r.points.size(), out.size(), from.mach, r.failed_correctors,
              r.kink_steps, r.steady_solves, r.steady_iterations, r.steady_seconds, gmres_hopf, gmres_steady, r.seconds,
              r.stop == hopf_curve_stop::requested ? why.c_str() : r.stop_reason.c_str());
  return out;
}

/// Natural continuation in M: each point starts from the previous one (Ubar, omega and the
/// eigenvector by secant extrapolation over the last two points of the branch, the eigenvector
/// then refined by one inverse iteration: hopf_krylov_options::start_iterations). A point is
/// accepted if its eigenvector's structural part continues the previous one (structural_cosine
/// >= 0.9); a failed or other-mode point is retried from half the Mach step (down to 1/8), and
/// the step doubles again after a success. The intermediate converged points are kept. On a
/// finer grid of a multi-grid run, a listed Mach number whose start from the previous point fails
/// is first restarted from the coarser grid's point there (coarse_restart below). Where
/// no Mach step down to 1/8 converges (and no other mode turned up), natural continuation hands
/// over to the Hopf-curve tracer (arclength_bridge).
/// Where the start from the previous point converges to the other mode at the full step, 1/8 of
/// the step is tried next (the jump search from the bottom, comment at its use below).
/// Where even 1/8 of the step finds only the other mode's Hopf point, the continued branch
/// has ended (it turns back in M between the two Mach numbers) and the boundary JUMPS to that
/// mode: it is accepted as the start of a new branch, reported on the terminal, and the CSV
/// carries the jump; the other mode's points found at the larger steps of the same search
/// continue the new branch and are kept, not solved again. (That the jump point is the lowest
/// crossing is checked apart: jump_check_part, crossing_check_part.) The wall time of rejected
/// attempts (failed or other-mode solves, with their steady solves at intermediate Mach
/// numbers) is charged to the next written point's hopf_seconds.
boundary natural_boundary(const structural_case& c, const grid_level& g, const std::vector<double>& machs,
                          const boundary* coarser, int coarser_ratio, int fill, csv_writer& csv) {
  boundary b;
  std::size_t branch_start = 0;  // first point of the current branch (a jump starts a new one)
  // Wall time of the attempts not accepted since the last written point (failed Hopf solves,
  // other-mode points, each with the steady solve at its Mach number if that is not a listed
  // one): charged to the next written point's hopf_seconds, so that the CSV's hopf_seconds add up
  // to the whole cost of the boundary beyond one steady solve per point.
  double rejected_seconds = 0;
  // Steady flows solved in this boundary, by Mach number. A listed Mach number gets the steady
  // solve from the free stream (the unit of cost) and keeps it for a second attempt there (heavy
  // medium: M = 0.83 was tried twice before the hand-over). An intermediate Mach number (a
  // halved step) is not a steady solve the user asked for: its flow is a Newton-Krylov solve
  // (solve_equilibrium_krylov) from the linear interpolation or extrapolation of the two nearest
  // flows solved. That is also the fallback where the free-stream solve ends on a NON-SYMMETRIC
  // (lifting) steady flow, which is no equilibrium with the section at rest
  // (aerofoil_system::steady_equilibrium throws; measured on the medium grid at M = 0.90125,
  // C_l = 6.1e-3): Newton from the neighbouring symmetric flows stays on the symmetric branch.
  // The free-stream solve is the last resort of an intermediate Mach number.
  struct solved_flow {
    double mach;
    steady_result st;
    bool charged = false;  // its seconds were added to rejected_seconds (an attempt there was rejected)
    // ... and a written point has taken them since: the steady solve stays booked as lost work
    // even if a point at its (intermediate) Mach number is written later (conservative: then it
    // is counted as both; taking it back would make that later point's hopf_seconds negative)
    bool settled = false;
  };
  std::deque<solved_flow> flows;  // references stay valid as it grows
  // cosine: structural_cosine to the previous point (NAN for the first point of the boundary;
  // at a jump, to the last point of the ended branch)
  auto write = [&](boundary_point p, double cosine) {
    p.hopf_seconds += std::exchange(rejected_seconds, 0.0);
    for (auto& f : flows) f.settled = f.settled || f.charged;
    b.push_back(p);
    csv.row({p.mach, p.ubar, p.omega, static_cast<long long>(p.newton_iterations),
             static_cast<long long>(p.linear_iterations), p.hopf_seconds, p.steady_seconds});
    std::printf("  %-6s %-8s M = %.4f  Ubar* = %.6f  omega* = %.6f  Newton %d  GMRES %5ld  hopf %.2f s  steady %.2f s  (ratio %.2f)  mode cosine %s\n",
                c.name.c_str(), g.name.c_str(), p.mach, p.ubar, p.omega, p.newton_iterations, p.linear_iterations,
                p.hopf_seconds, p.steady_seconds, p.hopf_seconds / p.steady_seconds,
                std::isfinite(cosine) ? fixed(cosine, 3).c_str() : "-");
    std::fflush(stdout);
  };
  // Newton-Krylov from the two nearest solved flows; empty if it fails
  auto warm_flow = [&](const aerofoil_system& s, double m, double mu) -> vec<double> {
    std::vector<const solved_flow*> near;
    for (const auto& f : flows) near.push_back(&f);
    std::sort(near.begin(), near.end(),
              [&](const solved_flow* a, const solved_flow* e) { return std::abs(a->mach - m) < std::abs(e->mach - m); });
    vec<double> w0 = near[0]->st.w;
    if (near.size() > 1)
      w0 += (m - near[0]->mach) / (near[1]->mach - near[0]->mach) * (near[1]->st.w - near[0]->st.w);
    const std::string label = c.name + " " + g.name + " steady Newton-Krylov at M = " + fixed(m, 5);
    try {
      equilibrium_krylov_options eo;
      eo.fill_level = fill;
      // ||f||_2 <= 1e-10: the free-stream solve (||R|| down 10 orders) ends at 1e-10 .. 3e-8
      // (measured, coarse and medium grids); from the interpolated flow the shock moves in
      // 5-15 damped Newton steps before the quadratic ones (medium grid, M = 0.90 .. 0.91)
      eo.newton.abs_tolerance = 1e-10;
      eo.newton.max_iterations = 25;
      const auto r = solve_equilibrium_krylov<4>(s, mu, std::move(w0), eo, label);
      std::printf("    %s (from M = %.5f%s): %d Newton iterations, %ld GMRES, ||f|| %.2e -> %.2e, %.2f s\n",
                  label.c_str(), near[0]->mach, near.size() > 1 ? (" and " + fixed(near[1]->mach, 5)).c_str() : "",
                  r.report.iterations, r.linear_iterations, r.report.residual_history.front(), r.report.final_residual(),
                  r.seconds);
      return r.w;
    } catch (const error& e) {
      std::printf("    %s failed: %s\n", label.c_str(), e.what());
      return {};
    }
  };
  auto flow_at = [&](const aerofoil_system& s, double m, double mu) -> solved_flow& {
    for (auto& f : flows)
      if (std::abs(f.mach - m) < 1e-12) return f;
    const auto t0 = clk::now();
    solved_flow f{m, {}, false};
    if (!is_listed(machs, m) && !flows.empty()) f.st.w = warm_flow(s, m, mu);
    if (f.st.w.size() == 0) {
      try {
        f.st = steady(s);
      } catch (const convergence_error& e) {
        if (flows.empty()) throw;
        std::printf("    M = %.5f: %s\n    -> the symmetric flow by Newton-Krylov from the neighbouring Mach numbers\n", m,
                    e.what());
        f.st.w = warm_flow(s, m, mu);
        if (f.st.w.size() == 0) throw;
      }
    }
    f.st.seconds = seconds_since(t0);  // with the failed attempts, if any
    flows.push_back(std::move(f));
    return flows.back();
  };
  // charged = true: an attempt at m was rejected, its steady solve is lost work; false: a point
  // there is written after all
  // A LISTED Mach number's steady solve is never charged: it is the unit of cost of the point
  // written there in the end (a rejected attempt there is followed by one, unless the boundary
  // stops early). Only intermediate Mach numbers' flows are lost work when an attempt is rejected.
  auto set_charged = [&](double m, bool charged) {
    if (is_listed(machs, m)) return;
    for (auto& f : flows)
      if (std::abs(f.mach - m) < 1e-12 && f.charged != charged) {
        if (!f.settled) rejected_seconds += charged ? f.st.seconds : -f.st.seconds;
        f.charged = charged;  // once settled, a flow's steady solve is booked for good (see solved_flow)
      }
  };
  // Grid sequencing at a listed Mach number where the start from the previous point failed:
  // the coarser boundary's point at that Mach number (eigenvector prolonged, its Ubar* and
  // omega*) is the start, as for the first point. It is what the original work did by hand on
  // the heavy case's steep branches ("computed separately from coarse-grid information"), here
  // automatic. The point it finds is accepted like any other: on the continued branch if its mode
  // continues it, else as the other mode's point that a jump may take (the halved steps below
  // decide). Tried once per Mach number (the result is kept; a second failure of the start from
  // the previous point there reuses it at no cost: its time was charged the first time). Where
  // it fails too, the step halving and the arclength hand-over go on as before.
  // The coarser boundary's point at Mach number m as a start on this grid (its Ubar*, omega*,
  // the eigenvector prolonged); none if the coarser boundary has no point there.
  // the coarser boundary's point at Mach number m, if it has one
  auto coarse_at = [&](double m) -> const boundary_point* {
    if (!coarser) return nullptr;
    const auto cp = std::find_if(coarser->begin(), coarser->end(),
                                 [&](const boundary_point& q) { return std::abs(q.mach - m) < 1e-9; });
    return cp == coarser->end() ? nullptr : &*cp;
  };
  auto coarse_guess = [&](const aerofoil_system& s, double m) -> std::optional<hopf_point> {
    const boundary_point* cp = coarse_at(m);
    if (!cp) return std::nullopt;
    const auto sc = make_system({"coarser", g.stride * coarser_ratio}, m, c.mu_s);
    hopf_point guess = cp->point;
    guess.p = s.prolong_from<cplx>(sc, coarser_ratio, cp->point.p);
    return guess;
  };
  std::map<double, std::optional<boundary_point>> restarts;
  auto coarse_restart = [&](const aerofoil_system& s, double m, const steady_result& st,
                            const std::string& label) -> std::optional<boundary_point> {
    if (const auto it = restarts.find(m); it != restarts.end()) {
      if (!it->second) return std::nullopt;
      boundary_point q = *it->second;
      q.hopf_seconds = 0;  // charged when it was solved
      std::printf("    %s: the coarse-grid restart found before: Ubar* = %.6f, omega* = %.6f\n", label.c_str(), q.ubar,
                  q.omega);
      return q;
    }
    const auto t0 = clk::now();
    const std::optional<hopf_point> guess = coarse_guess(s, m);
    if (!guess) return std::nullopt;
    std::printf("    %s: restart from the coarse-grid point (Ubar* = %.6f, omega* = %.6f)\n", label.c_str(), guess->mu,
                guess->omega);
    auto q = hopf_at(s, m, st, *guess, fill, label + " (coarse-grid restart)");
    if (q) q->hopf_seconds = seconds_since(t0);
    restarts[m] = q;
    return q;
  };
  for (double mach : machs) {
    const double m_done = b.empty() ? mach : b.back().mach;
    const double full_step = mach - m_done;
    double step = full_step;
    // the other mode's points found in this search, in the order found (falling steps, so falling
    // M), and the structural cosine of the last one to b.back()
    std::vector<boundary_point> others;
    double other_cosine = NAN;
    while (b.empty() || b.back().mach < mach - 1e-9) {
      if (!b.empty()) step = std::min(step, mach - b.back().mach);  // halve the step actually tried
      const double m = b.empty() || step >= mach - b.back().mach ? mach : b.back().mach + step;
      const auto s = make_system(g, m, c.mu_s);
      const steady_result& st = flow_at(s, m, b.empty() ? c.ubar_guess : b.back().ubar).st;
      hopf_point guess;
      const std::string label = c.name + " " + g.name + " M=" + fixed(m, 4);
      const auto t0 = clk::now();
      // Coarse-guided restart: at the first attempt of a listed step across which the coarser
      // boundary changes mode AND its branch ends within 1/4 of the step (its last point of the
      // mode it has at m_done lies below m_done + step/4), the start from the previous point is
      // skipped: the coarse-grid restart is solved at once, and where it finds the other mode the
      // jump search starts from the bottom (1/8 of the step), as after a start that converged to
      // the other mode. Measured, heavy medium M = 0.90 -> 0.91 (coarse branch to 0.90125): the
      // start from the previous point took 7 Newton iterations to reach the other mode, the
      // restart 3. Where the coarser branch goes on past step/4 the finer one may go on too
      // (heavy M = 0.82 -> 0.83: coarse to 0.8267, medium to 0.8259) or not (light M = 0.90 -> 0.91:
      // coarse to 0.90625, medium to below 0.90125), and the start from the previous point decides
      // as before.
      bool preempted = false;
      if (coarse_guided_restart && use_coarse_restart && coarser && !b.empty() && std::abs(m - mach) < 1e-12 &&
          std::abs(b.back().mach - m_done) < 1e-12 && is_listed(machs, m)) {
        const boundary_point* c0 = coarse_at(m_done);
        const boundary_point* c1 = coarse_at(m);
        if (c0 && c1 && structural_cosine(c0->point.p, c1->point.p) < same_mode_cosine) {
          double m_end = m_done;  // the coarser boundary's last point of c0's mode before m
          for (const auto& q : *coarser)
            if (q.mach > m_done + 1e-9 && q.mach < m - 1e-9 && structural_cosine(c0->point.p, q.point.p) >= same_mode_cosine)
              m_end = std::max(m_end, q.mach);
          preempted = m_end - m_done < 0.25 * full_step + 1e-12;
          if (preempted)
            std::printf("    %s: the coarser boundary's branch ends at M = %.5f and it changes mode before M = %.4f: "
                        "restart from its point first\n",
                        label.c_str(), m_end, m);
        }
      }
      if (preempted) {
        // no start from the previous point: the coarse-grid restart below is this attempt (and
        // the first-point branches further down must not run: b is not empty)
      } else if (!b.empty()) {
        guess = b.back().point;
        // secant predictor in M for Ubar, omega and the eigenvector, over a base no shorter than
        // a tenth of the step: after an arclength stretch the last two points can lie 4e-5 apart
        // in M (measured), and a secant extrapolated 250 times its base is no predictor
        const double min_base = 0.1 * (m - b.back().mach);
        std::optional<std::size_t> i1;  // the latest earlier point of the branch that far back; none: the last point
        for (std::size_t i = b.size() - 1; i-- > branch_start;)
          if (b.back().mach - b[i].mach >= min_base) {
            i1 = i;
            break;
          }
        if (i1) {
          const auto& p1 = b[*i1];
          const auto& p2 = b.back();
          const double t = (m - p2.mach) / (p2.mach - p1.mach);
          guess.mu = p2.ubar + t * (p2.ubar - p1.ubar);
          guess.omega = p2.omega + t * (p2.omega - p1.omega);
          // p1 in the normalisation of p2 (same value at p2's largest component), then the secant
          Eigen::Index k = 0;
          p2.point.p.cwiseAbs().maxCoeff(&k);
          if (std::abs(p1.point.p[k]) > 0) {
            const vec<cplx> q1 = p1.point.p * (p2.point.p[k] / p1.point.p[k]);
            guess.p = p2.point.p + t * (p2.point.p - q1);
          }
        }
        // Coarse-grid increment predictor (finer grid of a multi-grid run, where the coarser
        // boundary has points of one mode at both Mach numbers): Ubar* and omega* of the previous
        // point plus the coarser boundary's change between the two Mach numbers. The transonic
        // boundary wiggles as shocks cross cells, the same way on both grids (heavy case,
        // M 0.87 -> 0.88: coarse -0.513, medium -0.524 in Ubar*), which no secant through the
        // last two points can follow. The eigenvector likewise: the previous one plus the
        // prolonged coarse-grid change (see coarse_predictor for when it is used). Measured on the
        // heavy medium boundary: 89 -> 61-71 Newton iterations over its 23 points.
        if (coarser && coarse_predictor > 0) {
          const auto c0 = coarse_at(b.back().mach), c1 = coarse_at(m);
          if (c0 && c1 && structural_cosine(c0->point.p, c1->point.p) >= same_mode_cosine) {
            const boundary_point& p2 = b.back();
            guess.mu = p2.ubar + (c1->ubar - c0->ubar);
            guess.omega = p2.omega + (c1->omega - c0->omega);
            // the eigenvector from the coarser increment: always (full), never (values), or (auto)
            // where the secant eigenvector's Hopf residual at the predicted Ubar, omega is too large
            // for Newton without the start refinement (hopf_at's threshold 10: subsonic secant
            // guesses have ||F|| 3-6); the coarser increment's ||F|| is 20-660, from the prolonged
            // coarse-grid flow part, but one inverse iteration takes it to 3e-4 .. 5e-2, against
            // 2e-2 .. 6e-1 from the secant one
            bool use_increment = coarse_predictor == 2;
            if (coarse_predictor == 3) {
              hopf_point h = guess;
              h.w = st.w;
              vec<double> y;
              const aerohopf::internal::symmetric_hopf_problem<aerofoil_system> pr(
                  s, h, hopf_opts(label + " predictor", boundary_tolerance), "predictor", y);
              const double f_secant = pr.residual(y).norm();
              use_increment = !(f_secant <= start_residual_threshold);
              if (verbose_newton)
                std::printf("    %s: predictor ||F|| %.3e with the secant eigenvector: %s\n", label.c_str(), f_secant,
                            use_increment ? "the coarser increment's instead" : "kept");
            }
            if (use_increment) {
              Eigen::Index kc = 0, k = 0;
              c0->point.p.cwiseAbs().maxCoeff(&kc);
              p2.point.p.cwiseAbs().maxCoeff(&k);
              const auto sc = make_system({"coarser", g.stride * coarser_ratio}, m, c.mu_s);
              const vec<cplx> d = c1->point.p * (c0->point.p[kc] / c1->point.p[kc]) - c0->point.p;
              const vec<cplx> q0 = s.prolong_from<cplx>(sc, coarser_ratio, c0->point.p);
              if (std::abs(q0[k]) > 0) guess.p = p2.point.p + (p2.point.p[k] / q0[k]) * s.prolong_from<cplx>(sc, coarser_ratio, d);
            }
          }
        }
      } else if (coarser) {  // grid sequencing from the coarser boundary at this Mach number
        auto cg = coarse_guess(s, m);
        require(cg.has_value(), "no coarse-grid point at M = ", m, " to start the finer grid from");
        guess = std::move(*cg);
      } else {
        guess = krylov_start(s, st.w, c.ubar_guess, c.omega_guess, fill);
        guess.mu = c.ubar_guess;
      }
      const double start_seconds = seconds_since(t0);
      auto p = preempted ? std::nullopt : hopf_at(s, m, st, guess, fill, label);
      auto t_attempt = t0;  // start of the attempt whose time a failure charges to rejected_seconds
      if (p) p->hopf_seconds += start_seconds;
      const bool restarted = !p && use_coarse_restart && coarser && !b.empty() && is_listed(machs, m);
      if (restarted) {
        // grid sequencing where the start from the previous point failed (file comment above)
        set_charged(m, true);
        rejected_seconds += seconds_since(t0);
        t_attempt = clk::now();
        p = coarse_restart(s, m, st, label);
      }
      double cosine = NAN;
      if (p && !b.empty()) cosine = structural_cosine(b.back().point.p, p->point.p);
      if (!p) {
        set_charged(m, true);
        rejected_seconds += seconds_since(t_attempt);
      }
      if (p && b.size() > branch_start && cosine < same_mode_cosine) {
        set_charged(m, true);
        rejected_seconds += p->hopf_seconds;  // taken back if it becomes the jump point
        std::printf("    %s: Hopf point Ubar* = %.4f, omega* = %.4f belongs to another mode (structural cosine %.3f "
                    "to the point at M = %.4f)\n",
                    label.c_str(), p->ubar, p->omega, cosine, b.back().mach);
        others.push_back(std::move(*p));
        other_cosine = cosine;
        p.reset();
      }
      if (p) {
        set_charged(m, false);
        write(*p, cosine);
        others.clear();  // this branch goes on: the other mode's points found above it are not boundary points
        step = std::min(2.0 * step, full_step);
        continue;
      }
      if (b.empty())
        throw convergence_error(aerohopf::internal::concat("boundary ", c.name, " ", g.name,
                                                           ": no Hopf point at the first Mach number ", m));
      // Natural continuation gives up at 1/8 of the step only: handing over at the second failure
      // in one listed step saved 2 failed solves (1.2 s each) before the heavy medium stretch at
      // M = 0.83, but in a trial with the tracer's last points before M = 0.83 placed otherwise
      // (a fixed-omega kink fallback, not kept) the secant predictor from them failed twice at
      // 0.84 and sent M = 0.83 -> 0.84 to the tracer too: 47.6 s, 15 failed correctors at kinks.
      if (step < full_step / 8.0 + 1e-12) {
        if (!others.empty()) {
          std::printf("    %s: the branch continued from M = %.4f ends before M = %.4f (no Hopf point of its mode "
                      "within 1/8 of the Mach step); the boundary jumps to the other mode's Hopf point found there\n",
                      label.c_str(), b.back().mach, others.back().mach);
          branch_start = b.size();
          // The other mode's points found at the larger steps lie on the new branch up to this
          // listed Mach number: kept as they are (no second solve at the same M and guess
          // quality) while each continues the branch (structural cosine to the point before).
          // Measured on the light medium grid: the re-solves at M = 0.9025, 0.905, 0.91 after
          // the jump reproduced them to 1e-5 in Ubar*, at 5.8 s.
          std::vector<std::pair<const boundary_point*, double>> kept = {{&others.back(), other_cosine}};
          for (auto q = std::next(others.rbegin()); q != others.rend(); ++q) {
            const boundary_point& last = *kept.back().first;
            const double cq = structural_cosine(last.point.p, q->point.p);
            if (q->mach <= last.mach + 1e-9 || cq < same_mode_cosine) break;
            kept.emplace_back(&*q, cq);
          }
          for (const auto& [q, cq] : kept) {
            rejected_seconds -= q->hopf_seconds;
            set_charged(q->mach, false);
          }
          for (const auto& [q, cq] : kept) write(*q, cq);  // the rest of rejected_seconds goes to the jump point
          others.clear();
          step = std::min(2.0 * step, full_step);
          continue;
        }
        std::cout << "    " << label << ": no convergence from M = " << b.back().mach
                  << " even with 1/8 of the Mach step\n";
        const double m_before = b.back().mach;
        for (auto& q : arclength_bridge(c, g, machs, b.back(), fill)) {
          const double cosine = structural_cosine(b.back().point.p, q.point.p);
          write(q, cosine);
        }
        if (b.back().mach <= m_before + 1e-9) {
          std::printf("    the boundary is not continued past M = %.5f (natural and arclength continuation failed)\n",
                      m_before);
          return b;
        }
        step = full_step;  // natural continuation resumes from the last point of the arclength stretch
        continue;
      }
      // Jump search from the bottom: where the start from the previous point CONVERGED to the
      // other mode at the full listed step, the continued branch has most likely ended just past
      // its last point (turned back in M), so the smallest step (1/8) is tried first rather than
      // halving down to it; if the branch goes on there, the step doubles from it as after any
      // success. Measured at the three such jumps of the default run: the branch ended within 1/8
      // of the step at two (light and heavy medium, M = 0.90 -> 0.91) and between 1/8 and 1/4 at
      // the third (heavy coarse). Where the start FAILED, the step is halved (the branch may go on
      // close below m: heavy medium M = 0.83, whose branch continues to 0.825).
      if (jump_search_bottom && (!restarted || preempted) && !others.empty() && std::abs(others.back().mach - m) < 1e-12 &&
          step > 0.5 * full_step) {
        step = full_step / 8.0;
        std::cout << "    the other mode at the full step: retrying with the smallest Mach step " << step << "\n";
        continue;
      }
      step *= 0.5;
      std::cout << "    retrying with Mach step " << step << "\n";
    }
  }
  return b;
}


/// Pseudo-arclength continuation of the Hopf curve in (M, Ubar) (hopf_curve.hpp) from one start
/// at the first Mach number: the full augmented system with the steady flow as unknowns, so the
/// curve is followed through steep parts and turns in M. Every crossing of a listed Mach number
/// is landed exactly and written to the boundary CSV (steady_seconds: a separate free-stream
/// steady solve at that Mach number, the unit of cost); all points go to hopf_curve_<case>_<grid>.csv.
boundary arclength_boundary(const structural_case& c, const grid_level& g, const std::vector<double>& machs,
                            const options& o, csv_writer& csv) {
  boundary b;
  const double m0 = machs.front();
  const auto s0 = make_system(g, m0, c.mu_s);
  const auto st0 = steady(s0);
  hopf_point guess = krylov_start(s0, st0.w, c.ubar_guess, c.omega_guess, o.fill);
  guess.mu = c.ubar_guess;
  const auto first = hopf_at(s0, m0, st0, guess, o.fill, c.name + " " + g.name + " start");
  require(first.has_value(), "no Hopf point at the start Mach number ", m0);
  const hopf_point start = first->point;
  auto family = [&](double mach) { return make_system(g, mach, c.mu_s); };
  csv_writer curve(o.out / ("hopf_curve_" + c.name + "_" + g.name + ".csv"),
                   "mach,ubar,omega,newton_iterations,attempts,step,seconds,landed");
  hopf_curve_options ho;
  ho.mu_scale = 0.5;
  ho.nu_scale = 0.05;
  ho.omega_scale = 0.05;
  ho.step = 0.5;
  ho.max_step = 1.0;
  ho.min_step = 1e-3;
  ho.nu_min = m0 - 1e-9;
  ho.nu_max = machs.back();
  ho.mu_min = 0.2;
  ho.mu_max = 20.0;
  ho.max_points = 400;
  ho.fast_iterations = 4;  // Newton needs 4 quadratic steps to 1e-10 here
  ho.nu_targets = machs;
  ho.throw_on_failure = false;
  ho.label = c.name + " " + g.name + " Hopf curve";
  ho.verbose = true;
  ho.observer = [&](const hopf_curve_point& p) {
    curve.row({p.nu, std::abs(p.mu), p.omega, static_cast<long long>(p.newton_iterations),
               static_cast<long long>(p.attempts), p.step, p.seconds, static_cast<long long>(p.landed)});
    // the boundary: the start and the points landed on the listed Mach numbers
    if (std::none_of(machs.begin(), machs.end(), [&](double m) { return std::abs(m - p.nu) < 1e-9; })) return;
    const auto st = steady(make_system(g, p.nu, c.mu_s));
    boundary_point q{p.nu, std::abs(p.mu), p.omega, p.newton_iterations, 0, p.seconds, st.seconds, p.point()};
    b.push_back(q);
    csv.row({q.mach, q.ubar, q.omega, static_cast<long long>(q.newton_iterations), 0LL, q.hopf_seconds,
             q.steady_seconds});
  };
  const auto r = trace_hopf_curve(family, m0, start, ho, +1);
  std::cout << "  Hopf curve: " << r.points.size() << " points, stop: " << r.stop_reason << " (" << r.failed_correctors
            << " failed correctors, " << r.seconds << " s)\n";
  return b;
}

std::map<std::string, boundary> boundaries_part(const options& o) {
  std::map<std::string, boundary> all;
  const auto machs = mach_list(o);
  for (const auto& c : o.cases) {
    const boundary* coarser = nullptr;
    std::string coarser_name;
    for (const auto& g : o.grids) {
      std::cout << "\n=== stability boundary: " << c.name << " case (mu_s = " << c.mu_s << "), " << g.name
                << " grid, " << machs.size() << " Mach numbers, method " << o.method << " ===\n";
      csv_writer csv(o.out / ("boundary_" + c.name + "_" + g.name + ".csv"),
                     "mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds");
      const int ratio = coarser ? level_named(coarser_name).stride / g.stride : 0;
      const auto t0 = clk::now();
      boundary b = o.method == "arclength" ? arclength_boundary(c, g, machs, o, csv)
                                           : natural_boundary(c, g, machs, ratio == 2 ? coarser : nullptr, ratio, o.fill, csv);
      double hopf = 0, steady_total = 0;
      for (const auto& p : b) {
        hopf += p.hopf_seconds;
        steady_total += p.steady_seconds;
      }
      std::printf("  %s %s: %zu points in %.1f s (Hopf %.1f s + steady %.1f s); Hopf / steady = %.2f\n", c.name.c_str(),
                  g.name.c_str(), b.size(), seconds_since(t0), hopf, steady_total, hopf / steady_total);
      all[c.name + "_" + g.name] = b;
      coarser = &all[c.name + "_" + g.name];
      coarser_name = g.name;
    }
  }
  return all;
}


// ---------------------------------------------------------------------------------------------
// Part 2a: V-g / V-f diagrams at one Mach number (bifurcation/vg_diagram.hpp): damping
// g = 2 Re/|Im| and frequency of the plunge and pitch modes against Ubar, traced from the
// in-vacuo modes at the lowest Ubar by shift-invert inverse power and tracked by the structural
// part of the eigenvector; g = 0 from below is the flutter point, checked against the Hopf point.

void vg_part(const options& o, const std::map<std::string, boundary>& all) {
  const grid_level g = o.vg_grid ? *o.vg_grid : o.grids.front();
  for (const auto& c : o.cases) {
    std::cout << "\n=== V-g / V-f diagram: " << c.name << " case, " << g.name << " grid, M = " << fixed(o.vg_mach, 2)
              << " ===\n";
    try {
      const auto t0 = clk::now();
      const auto s = make_system(g, o.vg_mach, c.mu_s);
      const auto st = steady(s);
      // the Hopf point of this run's boundary at vg_mach, else one Hopf solve from the inverse-power start
      std::optional<boundary_point> hp;
      if (const auto it = all.find(c.name + "_" + g.name); it != all.end())
        for (const auto& q : it->second)
          if (std::abs(q.mach - o.vg_mach) < 1e-9) hp = q;
      if (!hp) {
        hopf_point guess = krylov_start(s, st.w, c.ubar_guess, c.omega_guess, o.fill);
        guess.mu = c.ubar_guess;
        hp = hopf_at(s, o.vg_mach, st, guess, o.fill, c.name + " " + g.name + " V-g Hopf point");
      }
      require(hp.has_value(), "no Hopf point at M = ", o.vg_mach, " to set the Ubar range");
      std::vector<double> ubars;
      for (int k = 0; k < o.vg_points; ++k)
        ubars.push_back(hp->ubar * (o.vg_from + (o.vg_to - o.vg_from) * k / std::max(1, o.vg_points - 1)));
      vg_options vo;
      vo.tracked_offset = s.flow_size();  // the structural unknowns (h, h', alpha, alpha')
      vo.tracked_size = aerofoil_system::n_structure;
      vo.inverse_power.tolerance = 1e-10;
      const auto starts = vg_mode_starts(s.structure().in_vacuo_matrix(ubars.front()));  // plunge, pitch
      const auto equilibrium = [&](double) { return st.w; };  // symmetric section: one flow for every Ubar
      vg_result r;
      const bool lu = o.vg_solver == "lu" || (o.vg_solver == "auto" && g.stride >= 4);
      if (lu) {  // sparse LU of A - sigma I
        r = vg_diagram(s, equilibrium, ubars, starts, vo);
      } else {  // GMRES on the exact A - sigma I, BILU(k) of the modified-order L - sigma I
        vo.inverse_power.tolerance = 1e-9;  // inexact inverse iteration: GMRES below it (inverse_power.hpp)
        double l_mu = NAN;  // the modified-order Jacobian of the last Ubar (the same for every shift there)
        Eigen::SparseMatrix<double> l;
        r = vg_diagram(s, equilibrium, ubars, starts, vo, [&](const vec<double>& w, double mu, cplx sigma) {
          if (!(mu == l_mu)) {
            l = lhs_jacobian(s, w, mu);
            l_mu = mu;
          }
          krylov_solver_options ko;
          ko.fill_level = o.fill;
          ko.krylov.relative_tolerance = 1e-10;
          ko.krylov.max_iterations = 2000;
          ko.krylov.restart = start_restart;
          ko.krylov.record_history = false;
          krylov_solver<Eigen::SparseMatrix<cplx>, 4> solver(ko, "V-g inverse power, complex BILU-GMRES");
          solver.precondition_with(shifted(l, sigma));
          return solver;
        });
      }
      const std::string tag = c.name + "_" + g.name + "_M" + fixed(o.vg_mach, 2);
      csv_writer csv(o.out / ("vg_" + tag + ".csv"), "mode,parameter,damping_g,frequency,re,im");
      for (const auto& p : r.points)
        csv.row({static_cast<long long>(p.mode), p.mu, p.damping, p.frequency, p.lambda.real(), p.lambda.imag()});
      csv_writer fc(o.out / ("vg_flutter_" + tag + ".csv"), "mode,parameter,frequency,hopf_parameter,hopf_frequency");
      const char* names[] = {"plunge", "pitch"};
      for (const auto& f : r.flutter) {
        fc.row({static_cast<long long>(f.mode), f.mu, f.frequency, hp->ubar, hp->omega});
        std::printf("  g = 0 (rising): mode %d (%s) at Ubar = %.6f, frequency %.6f; Hopf point Ubar* = %.6f, omega* = %.6f "
                    "(%+.1e, %+.1e relative)\n",
                    f.mode, f.mode < 2 ? names[f.mode] : "?", f.mu, f.frequency, hp->ubar, hp->omega, f.mu / hp->ubar - 1,
                    f.frequency / hp->omega - 1);
      }
      if (r.flutter.empty()) std::printf("  no zero crossing of g in Ubar = %.4f .. %.4f\n", ubars.front(), ubars.back());
      long iterations = 0;
      for (const auto& p : r.points) iterations += p.iterations;
      std::printf("  %d modes x %zu Ubar values (%s): %d inverse powers (%ld iterations in the accepted ones), %d halved "
                  "steps, %ld GMRES iterations, %.1f s (with the steady solve)\n",
                  r.modes, ubars.size(), lu ? "sparse LU" : "BILU-GMRES", r.inverse_powers, iterations, r.subdivisions,
                  r.linear_iterations, seconds_since(t0));
    } catch (const error& e) {
      std::cout << "  V-g diagram failed: " << e.what() << "\n";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Part 2b: where a boundary jumps to another mode, is the new point the LOWEST flutter speed?
// Natural continuation only knows the mode it follows; after its branch ends (or the tracer
// passes a fold) it accepts the other mode's Hopf point it finds. On the very coarse grid (256
// cells, 1028 unknowns: a dense eigen-decomposition takes ~2 s) the whole spectrum decides: at
// the Mach number of every jump, and at the last one, the largest real part over ALL eigenvalues
// of the coupled Jacobian is scanned over Ubar = 0.2 .. 0.98 Ubar* (14 values) and at
// 0.995 / 1.005 Ubar*. The point is the lowest crossing (within the scan) iff max Re < 0 below
// it and > 0 just above it. Writes jump_check.csv (case,mach,ubar_star,ubar,max_re,im_at_max).

/// The points of a boundary whose lowest-crossing property is checked: the jumps (structural
/// cosine < 0.9 to the previous point) and the last point.
std::vector<std::pair<std::size_t, const char*>> check_points(const boundary& b) {
  std::vector<std::pair<std::size_t, const char*>> at;
  for (std::size_t k = 1; k < b.size(); ++k)
    if (structural_cosine(b[k - 1].point.p, b[k].point.p) < same_mode_cosine) at.emplace_back(k, "jump");
  if (!b.empty() && (at.empty() || at.back().first != b.size() - 1)) at.emplace_back(b.size() - 1, "last point");
  return at;
}

void jump_check_part(const options& o, const std::map<std::string, boundary>& all) {
  const grid_level g = level_named("very_coarse");
  const auto machs = mach_list(o);
  csv_writer out(o.out / "jump_check.csv", "case,mach,ubar_star,ubar,max_re,im_at_max");
  std::vector<double> factors;  // of Ubar*: 0.20 .. 0.98, then just below and above
  for (int j = 0; j < 14; ++j) factors.push_back(0.2 + 0.06 * j);
  factors.push_back(0.995);
  factors.push_back(1.005);
  int checked = 0, failed = 0;
  for (const auto& c : o.cases) {
    std::cout << "\n=== jump check: " << c.name << " case, very coarse grid (dense spectra over Ubar) ===\n";
    // the very coarse boundary of the boundaries part if it ran on this grid, else computed here
    const auto known = all.find(c.name + "_" + g.name);
    const boundary b = known != all.end() ? known->second : [&] {
      csv_writer bcsv(o.out / ("boundary_" + c.name + "_" + g.name + ".csv"),
                      "mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds");
      return natural_boundary(c, g, machs, nullptr, 0, o.fill, bcsv);
    }();
    for (const auto& [k, what] : check_points(b)) {
      const auto& p = b[k];
      const auto s = make_system(g, p.mach, c.mu_s);
      const vec<double>& w0 = p.point.w;  // the steady flow at this Mach number (symmetric Hopf point)
      bool ok = true;
      double worst_below = -1e300, lowest_unstable = NAN;
      for (double f : factors) {
        const double ubar = f * p.ubar;
        Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(w0, ubar)), false);
        cplx top = es.eigenvalues()[0];
        for (const auto& l : es.eigenvalues())
          if (l.real() > top.real()) top = l;
        out.row({c.name, p.mach, p.ubar, ubar, top.real(), std::abs(top.imag())});
        if (f < 1) {
          worst_below = std::max(worst_below, top.real());
          if (top.real() > 0 && !std::isfinite(lowest_unstable)) lowest_unstable = ubar;
          ok = ok && top.real() < 0;
        } else {
          ok = ok && top.real() > 0;
          std::printf("    M = %.4f (%s): above Ubar* (1.005 Ubar*) max Re lambda = %+.3e at omega = %.4f (Hopf omega* %.4f)\n",
                      p.mach, what, top.real(), std::abs(top.imag()), p.omega);
        }
      }
      std::printf("    M = %.4f  Ubar* = %.5f: max Re lambda over 0.2 .. 0.995 Ubar* = %+.3e -> %s\n", p.mach, p.ubar,
                  worst_below,
                  ok ? "lowest crossing (PASS)"
                     : (std::isfinite(lowest_unstable)
                            ? ("unstable already at Ubar = " + fixed(lowest_unstable, 4) + " (FAIL)").c_str()
                            : "no crossing at Ubar* (FAIL)"));
      ++checked;
      failed += ok ? 0 : 1;
    }
  }
  std::printf("  jump check: %d points checked, %d failed\n", checked, failed);
}

/// The same question on the coarse and medium grids, where a dense spectrum is out of reach:
/// J(Ubar) = A0 + B / Ubar^2 with B in the structural block (the equilibrium does not depend on
/// Ubar), so imaginary_axis_crossings (bifurcation/axis_crossings.hpp: Schur complement onto the
/// four structural unknowns, one complex sparse LU of i omega I - A_ff per frequency) lists
/// EVERY crossing of the imaginary axis with omega in [0.05, 6 omega*]. That band holds the
/// crossings down to Ubar = 0.2 Ubar* (the structural frequencies in c/U time scale with
/// 1/Ubar). PASS: the lowest crossing above 0.2 Ubar* is the boundary point itself.
void crossing_check_part(const options& o, const std::map<std::string, boundary>& all) {
  csv_writer out(o.out / "crossing_check.csv", "case,grid,mach,ubar_star,omega_star,ubar,omega");
  int checked = 0, failed = 0;
  for (const auto& g : o.grids) {
    if (g.name == "very_coarse" || (g.name == "medium" && !o.crossing_medium)) continue;
    for (const auto& c : o.cases) {
      const auto known = all.find(c.name + "_" + g.name);
      if (known == all.end()) continue;
      std::cout << "\n=== crossing check: " << c.name << " case, " << g.name
                << " grid (all imaginary-axis crossings by the structural Schur complement) ===\n";
      const boundary& b = known->second;
      for (const auto& [k, what] : check_points(b)) {
        const auto& p = b[k];
        const auto t0 = clk::now();
        const auto s = make_system(g, p.mach, c.mu_s);
        const vec<double>& w0 = p.point.w;
        const double u1 = p.ubar, u2 = 0.5 * p.ubar;
        const affine_split sp =
            split_affine(s.jacobian(w0, u1), 1 / (u1 * u1), s.jacobian(w0, u2), 1 / (u2 * u2), 4, "crossing check");
        axis_crossing_options ao;
        ao.omega_min = 0.05;
        ao.omega_max = 6 * p.omega;
        ao.samples = std::max(100, static_cast<int>(std::ceil((ao.omega_max - ao.omega_min) / 0.02)));
        ao.context = c.name + " " + g.name + " crossing check";
        const axis_crossing_result r = imaginary_axis_crossings(sp.a0, sp.b_ss, ao);
        const axis_crossing* lowest = nullptr;
        for (const auto& x : r.crossings) {
          if (!(x.q > 0)) continue;
          const double u = 1 / std::sqrt(x.q);
          out.row({c.name, g.name, p.mach, p.ubar, p.omega, u, x.omega});
          if (u >= 0.2 * p.ubar && (!lowest || x.q > lowest->q)) lowest = &x;
        }
        const double ul = lowest ? 1 / std::sqrt(lowest->q) : NAN;
        const bool ok = lowest && std::abs(ul - p.ubar) <= 1e-5 * p.ubar && std::abs(lowest->omega - p.omega) <= 1e-4;
        std::printf("    M = %.4f (%s)  Ubar* = %.5f omega* = %.4f: %zu crossings in omega 0.05 .. %.2f (%d LU), lowest "
                    "Ubar = %.5f at omega = %.4f -> %s  (%.1f s)\n",
                    p.mach, what, p.ubar, p.omega, r.crossings.size(), ao.omega_max, r.factorisations, ul,
                    lowest ? lowest->omega : NAN, ok ? "lowest crossing (PASS)" : "FAIL", seconds_since(t0));
        ++checked;
        failed += ok ? 0 : 1;
      }
    }
  }
  std::printf("  crossing check: %d points checked, %d failed\n", checked, failed);
}

// ---------------------------------------------------------------------------------------------
// Part 3: time marching at 0.97 and 1.03 Ubar* (implicit BDF2, dual time, dt = 0.125).

struct march_result {
  double ubar = 0, growth_rate = 0, re_lambda = 0, im_lambda = 0, seconds = 0, steady_seconds = 0;
  long steps = 0, inner_iterations = 0;
  int peaks = 0;
};

/// BDF2 (dt = 0.125, 3 orders per step, frozen modified-order matrix, BILU(0)-GMRES) of system s
/// at ubar from w0 to t_end; the plunge and pitch histories go to history_<tag>.csv.
struct march_history {
  std::vector<double> t, alpha;
  long steps = 0, inner_iterations = 0;
  double seconds = 0;
};
march_history march(const aerofoil_system& s, double ubar, const vec<double>& w0, double t_end, const std::string& tag,
                    const options& o) {
  bdf2_options bo;
  bo.dt = 0.125;
  bo.inner_residual_drop = 1e-3;  // three orders per real time step
  bo.approximate_jacobian = true;  // modified-order Jacobian, frozen over the step (dual time)
  bo.freeze_matrix = true;
  bo.max_inner_iterations = 40;
  krylov_solver_options ko;
  ko.fill_level = 0;
  ko.krylov.relative_tolerance = 1e-2;
  ko.krylov.max_iterations = 400;
  ko.krylov.record_history = false;
  krylov_solver<Eigen::SparseMatrix<double>, 4> solver(ko, "BDF2 inner BILU(0)-GMRES");
  march_history r;
  const Eigen::Index ih = s.flow_size(), ia = s.flow_size() + 2;
  csv_writer csv(o.out / ("history_" + tag + ".csv"), "t,h,alpha");
  const auto t0 = clk::now();
  integrate_bdf2(
      s, ubar, w0, 0.0, t_end, bo,
      [&](const bdf2_step_info& i, const vec<double>& w) {
        r.t.push_back(i.t);
        r.alpha.push_back(w[ia]);
        csv.row({i.t, w[ih], w[ia]});
        r.steps = i.step;
        r.inner_iterations += i.inner_iterations;
        if (i.step > 0 && i.step % 100 == 0)
          std::printf("    %s: step %ld  t = %.2f  alpha = %+.5e  inner iterations %d\n", tag.c_str(), i.step, i.t,
                      w[ia], i.inner_iterations);
      },
      solver);
  r.seconds = seconds_since(t0);
  return r;
}

/// BDF2 run of the coupled system at Ubar = factor Ubar*, started on the critical eigenvector
/// at that Ubar (pitch amplitude 0.01 rad), compared with the real part of that eigenvalue.
march_result time_march(const structural_case& c, const grid_level& g, const boundary_point& bp, double factor,
                        double cycles, const options& o) {
  march_result r;
  const auto s = make_system(g, bp.mach, c.mu_s);
  const auto st = steady(s);
  r.steady_seconds = st.seconds;
  r.ubar = factor * bp.ubar;
  // the critical eigenpair at this Ubar (shift-invert from the Hopf eigenvalue)
  vec<cplx> p0 = bp.point.p.size() == s.size() ? bp.point.p : vec<cplx>();
  const eigen_pair ep = inverse_power(s.jacobian(st.w, r.ubar), cplx(0.0, bp.omega), {}, p0.size() ? &p0 : nullptr);
  r.re_lambda = ep.lambda.real();
  r.im_lambda = std::abs(ep.lambda.imag());
  vec<cplx> v = ep.vector;
  v *= 0.01 / v[s.flow_size() + 2];  // pitch component real, 0.01 rad
  const vec<double> w0 = st.w + v.real();
  const std::string tag = c.name + "_" + g.name + "_M" + fixed(bp.mach, 2) + "_" + fixed(factor, 2);
  const march_history h = march(s, r.ubar, w0, cycles * 2 * std::numbers::pi / bp.omega, tag, o);
  r.steps = h.steps;
  r.inner_iterations = h.inner_iterations;
  r.seconds = h.seconds;
  r.growth_rate = peak_growth_rate(h.t, h.alpha, 2 * std::numbers::pi / bp.omega, &r.peaks);
  return r;
}

void verification_part(const options& o, const std::map<std::string, boundary>& all, std::vector<double>& march_costs) {
  const structural_case& c = light_case;
  const auto it = all.find(c.name + "_" + o.verify_grid.name);
  if (it == all.end()) {
    std::cout << "\n(time-marching verification skipped: no " << c.name << " boundary on the " << o.verify_grid.name
              << " grid in this run)\n";
    return;
  }
  std::cout << "\n=== time marching (BDF2, dt = 0.125, 3 orders per step) at 0.97 / 1.03 Ubar*, " << c.name << " case, "
            << o.verify_grid.name << " grid ===\n";
  csv_writer csv(o.out / "verification.csv",
                 "case,grid,mach,ubar_star,factor,ubar,growth_rate,re_lambda,im_lambda,steps,inner_iterations,march_seconds,"
                 "steady_seconds");
  const std::vector<double> machs = o.quick ? std::vector<double>{0.5} : std::vector<double>{0.5, 0.8, 0.85};
  for (double m : machs) {
    const auto p = std::find_if(it->second.begin(), it->second.end(),
                                [&](const boundary_point& q) { return std::abs(q.mach - m) < 1e-9; });
    if (p == it->second.end()) {
      std::cout << "  no boundary point at M = " << m << "\n";
      continue;
    }
    for (double f : {0.97, 1.03}) {
      const march_result r = time_march(c, o.verify_grid, *p, f, o.quick ? 3.0 : 4.0, o);
      csv.row({c.name, o.verify_grid.name, m, p->ubar, f, r.ubar, r.growth_rate, r.re_lambda, r.im_lambda,
               static_cast<long long>(r.steps), static_cast<long long>(r.inner_iterations), r.seconds, r.steady_seconds});
      march_costs.push_back(r.seconds / r.steady_seconds);
      std::printf("  M = %.2f  Ubar = %.4f (%.2f Ubar*): %s, growth rate %+.5f (%d peaks) vs Re(lambda) %+.5f; %ld steps, "
                  "%.1f inner its/step, %.1f s = %.0f steady solves\n",
                  m, r.ubar, f, r.growth_rate < 0 ? "decays" : "grows", r.growth_rate, r.peaks, r.re_lambda, r.steps,
                  double(r.inner_iterations) / double(std::max(1L, r.steps)), r.seconds, r.seconds / r.steady_seconds);
      std::fflush(stdout);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Part 4: centre-manifold reduced model at a transonic Mach number of the heavy case.

void reduced_part(const options& o, const std::map<std::string, boundary>& all) {
  const structural_case& c = heavy_case;
  const grid_level g = level_named("coarse");
  const double mach = 0.8;  // transonic: shocks on both surfaces at zero incidence
  const double delta = o.contact_smoothing;
  std::cout << "\n=== reduced model: heavy case, coarse grid, M = " << mach << ", contact smoothing delta = " << delta
            << " ===\n";
  // The exact Osher switch is C1 but not C2 at the symmetric equilibrium (wake cut, outer
  // boundary: see osher_flux.hpp), so the 2nd/3rd derivatives the reduction needs are taken on
  // the smoothed discretisation, and every comparison below (Hopf point, time marching) uses it.
  const auto s = make_system(g, mach, c.mu_s, delta);
  const auto st = steady(s);
  hopf_point guess;
  const auto it = all.find(c.name + "_" + g.name);
  const boundary_point* bp = nullptr;
  if (it != all.end())
    for (const auto& q : it->second)
      if (std::abs(q.mach - mach) < 1e-9) bp = &q;
  if (bp) {
    guess = bp->point;
  } else {
    std::cout << "  (no " << c.name << " " << g.name << " boundary point at M = " << mach
              << " in this run: inverse-power start)\n";
    guess = krylov_start(s, st.w, c.ubar_guess, c.omega_guess, o.fill);
  }
  guess.w = st.w;
  hopf_krylov_options hk;
  hk.fill_level = o.fill;
  hopf_result h = solve_hopf_krylov<4>(s, guess, hopf_opts("reduced-model Hopf point"), hk);
  h.point.mu = std::abs(h.point.mu);
  const hopf_point& hp = h.point;
  std::printf("  Hopf point (smoothed): Ubar* = %.8f, omega* = %.8f", hp.mu, hp.omega);
  if (bp) std::printf("  (exact switch: %.8f, %.8f: smoothing moves Ubar* by %+.2e)", bp->ubar, bp->omega, hp.mu / bp->ubar - 1);
  std::printf("\n");

  const auto t0 = clk::now();
  const auto cm = reduce_to_centre_manifold(s, hp, taylor_products<double>{});
  const double t_taylor = seconds_since(t0);
  csv_writer cc(o.out / "reduced_coefficients.csv", "provider,h,re_G20,im_G20,re_G11,im_G11,re_g21,im_g21,re_c1,im_c1,l1,seconds");
  auto row = [&](const std::string& name, double hstep, const centre_manifold_coefficients& k, double sec) {
    cc.row({name, hstep, k.G20.real(), k.G20.imag(), k.G11.real(), k.G11.imag(), k.g21.real(), k.g21.imag(),
            k.c1.real(), k.c1.imag(), k.l1, sec});
    std::printf("  %-12s h = %-8.1e  G20 = %+.6e %+.6ei  G11 = %+.6e %+.6ei  g21 = %+.6e %+.6ei  l1 = %+.8e  (%.2f s)\n",
                name.c_str(), hstep, k.G20.real(), k.G20.imag(), k.G11.real(), k.G11.imag(), k.g21.real(), k.g21.imag(),
                k.l1, sec);
  };
  row("taylor", 0.0, cm, t_taylor);
  // finite differences: double, and the plateau in double-double (spec 03 / 08)
  for (double hstep : o.quick ? std::vector<double>{1e-4} : std::vector<double>{1e-3, 1e-4, 1e-5}) {
    const auto t1 = clk::now();
    row("fd<double>", hstep, reduce_to_centre_manifold(s, hp, fd_products<double>{hstep}), seconds_since(t1));
  }
  double worst = 0;
  for (double hstep : o.quick ? std::vector<double>{1e-6} : std::vector<double>{1e-4, 1e-6, 1e-8}) {
    const auto t1 = clk::now();
    const auto k = reduce_to_centre_manifold(s, hp, fd_products<dd_real>{hstep});
    row("fd<dd>", hstep, k, seconds_since(t1));
    if (hstep <= 1e-6) worst = std::max(worst, std::abs(k.g21 - cm.g21) / std::abs(cm.g21));
  }
  std::printf("  fd<dd> (h <= 1e-6) vs taylor: |dg21| / |g21| <= %.1e\n", worst);
  std::printf("  adjoint: %d inverse-power iterations, ||A^T q + i omega q|| / ||q|| = %.2e; l1 = %+.6e: %s Hopf bifurcation\n",
              cm.adjoint_iterations, cm.q_residual, cm.l1, cm.l1 < 0 ? "SUPERCRITICAL (stable LCO above Ubar*)"
                                                                       : "SUBCRITICAL (unstable LCO below Ubar*)");
  const centre_manifold_model model(cm);
  const Eigen::Index ia = s.flow_size() + 2;
  const double period = 2 * std::numbers::pi / hp.omega;

  // damping below the boundary: reduced eigenvalue vs the exact one and one time-marching run
  csv_writer dc(o.out / "reduced_damping.csv", "ubar,re_reduced,im_reduced,re_exact,im_exact,growth_march");
  vec<cplx> p = hp.p;
  for (double f : {0.90, 0.93, 0.95, 0.97, 0.99, 1.01, 1.03}) {
    const double ubar = f * hp.mu;
    const cplx lr = model.eigenvalue(ubar - hp.mu);
    const eigen_pair ep = inverse_power(s.jacobian(st.w, ubar), cplx(0.0, hp.omega), {}, &p);
    double growth = NAN;
    if (std::abs(f - 0.97) < 1e-9 && o.verify) {
      // pitch amplitude 1e-4 rad: the LINEAR regime (at 0.01 rad the cubic term below adds
      // -0.0019 to the growth rate of this case, more than the linear damping itself)
      vec<cplx> v = ep.vector;
      v *= 1e-4 / v[ia];
      const auto mh = march(s, ubar, (st.w + v.real()).eval(), (o.quick ? 3.0 : 4.0) * period,
                            "heavy_coarse_M0.80_0.97_smoothed", o);
      // mean envelope growth rate after the start transient (1.5 periods)
      const auto env = amplitude_envelope(mh.t, mh.alpha, 1.5 * period);
      growth = env.empty() ? NAN : 0.0;
      for (const auto& e : env) growth += e.growth_rate / double(env.size());
      std::printf("  time marching at %.2f Ubar*: growth rate %+.6f (%zu envelope samples, %.1f s)\n", f, growth,
                  env.size(), mh.seconds);
    }
    dc.row({ubar, lr.real(), lr.imag(), ep.lambda.real(), std::abs(ep.lambda.imag()), growth});
    std::printf("  Ubar = %.5f (%.2f Ubar*): reduced lambda = %+.6f %+.6fi, exact %+.6f %+.6fi\n", ubar, f, lr.real(),
                lr.imag(), ep.lambda.real(), std::abs(ep.lambda.imag()));
  }

  // LCO amplitude (pitch) of the reduced model
  csv_writer lc(o.out / "reduced_lco.csv", "ubar,alpha_amplitude,z_amplitude,frequency,stable");
  const double side = cm.l1 < 0 ? 1.0 : -1.0;  // supercritical: cycles above Ubar*
  for (double fr : {0.0005, 0.001, 0.002, 0.005, 0.01, 0.015, 0.02, 0.03, 0.04, 0.05}) {
    const double dmu = side * fr * hp.mu;
    const auto l = model.lco(dmu);
    if (!l.exists) continue;
    const auto [amp, mean] = model.component_amplitude(ia, dmu);
    (void)mean;
    lc.row({hp.mu + dmu, amp, l.amplitude, l.frequency, static_cast<long long>(l.stable)});
    std::printf("  LCO at Ubar = %.5f: pitch amplitude %.5f rad, frequency %.5f, %s\n", hp.mu + dmu, amp, l.frequency,
                l.stable ? "stable" : "unstable");
  }
  if (!o.verify) return;

  // Verification of the nonlinear term by time marching: the amplitude-dependent growth rate.
  // On the centre manifold |z|' = |z| (Re(a) dmu + Re(c1) |z|^2), and the pitch amplitude is
  // kappa |z| (kappa = 2 |p_alpha|; k20 and k11 carry no pitch at a symmetric equilibrium), so
  // the model predicts sigma(A) = Re(a) dmu + Re(c1) (A / kappa)^2, zero on the LCO. BDF2 runs
  // of the full system started ON the manifold (w = reconstruct(z0)) give measured (A, sigma)
  // along their envelopes (amplitude_envelope; the first 1.5 periods are skipped as transient).
  // (a) at Ubar* (dmu = 0) the measured sigma(A) checks Re(c1) directly, amplitude by amplitude;
  // (b) above it, runs from below and above the predicted cycle and a least-squares line
  //     sigma = s0 + s2 A^2 through their samples give the time-marching LCO amplitude
  //     sqrt(-s0 / s2) (marching onto the cycle itself would take hundreds of periods here).
  csv_writer ec(o.out / "reduced_envelope.csv", "ubar,start_amplitude,t,alpha_amplitude,growth_march,growth_model");
  csv_writer lm(o.out / "reduced_lco_march.csv",
                "ubar,alpha_amplitude_model,alpha_amplitude_march,growth0_model,growth0_march,runs");
  const double kappa = 2.0 * std::abs(cm.p[ia]);
  const double re_a = model.z_mu_coefficient().real();
  auto model_rate = [&](double dmu, double amp) { return re_a * dmu + cm.c1.real() * std::pow(amp / kappa, 2); };
  struct fit {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
  };
  // one run: envelope samples to the CSV and the fit; returns the mean measured and model rates
  auto envelope_run = [&](double dmu, double a0, const std::string& tag, fit& f) {
    const double ubar = hp.mu + dmu;
    const auto mh = march(s, ubar, model.reconstruct(cplx(a0 / kappa, 0.0), dmu), (o.quick ? 4.0 : 5.0) * period, tag, o);
    const auto env = amplitude_envelope(mh.t, mh.alpha, 1.5 * period);
    double gm = 0, gp = 0, am = 0;
    for (const auto& e : env) {
      const double g = model_rate(dmu, e.amplitude);
      ec.row({ubar, a0, e.t, e.amplitude, e.growth_rate, g});
      const double x = e.amplitude * e.amplitude;
      f.sx += x;
      f.sy += e.growth_rate;
      f.sxx += x * x;
      f.sxy += x * e.growth_rate;
      ++f.n;
      gm += e.growth_rate / double(env.size());
      gp += g / double(env.size());
      am += e.amplitude / double(env.size());
    }
    std::printf("    Ubar = %.5f, start %.5f rad: mean amplitude %.5f, growth rate %+.4e (time marching) vs %+.4e "
                "(reduced model), %zu envelope samples, %.1f s\n",
                ubar, a0, am, gm, gp, env.size(), mh.seconds);
  };
  std::cout << "  (a) amplitude-dependent growth rate at Ubar* (pure cubic term):\n";
  for (double a0 : o.quick ? std::vector<double>{0.002} : std::vector<double>{0.001, 0.002, 0.004}) {
    fit f;
    envelope_run(0.0, a0, "heavy_coarse_M0.80_envelope_" + fixed(a0, 3), f);
  }
  std::cout << "  (b) LCO amplitude above Ubar*: reduced model vs time marching (envelope fit)\n";
  for (double fct : o.quick ? std::vector<double>{1.002} : std::vector<double>{1.001, 1.002, 1.02}) {
    const double dmu = side * (fct - 1.0) * hp.mu, ubar = hp.mu + dmu;
    const auto l = model.lco(dmu);
    if (!l.exists) continue;
    const double a_pred = kappa * l.amplitude;
    fit f;
    for (double start : {0.6, 1.4})
      envelope_run(dmu, start * a_pred, "heavy_coarse_M0.80_lco_" + fixed(fct, 3) + "_" + fixed(start, 1), f);
    if (f.n < 3) continue;
    const double s2 = (f.n * f.sxy - f.sx * f.sy) / (f.n * f.sxx - f.sx * f.sx), s0 = (f.sy - s2 * f.sx) / f.n;
    const double a_march = -s0 / s2 > 0 ? std::sqrt(-s0 / s2) : NAN;
    lm.row({ubar, a_pred, a_march, re_a * dmu, s0, 2LL});
    std::printf("  Ubar = %.5f (%.3f Ubar*): LCO pitch amplitude %.5f rad (time marching) vs %.5f (reduced model), %+.1f %%; "
                "growth at zero amplitude %+.4e vs %+.4e\n",
                ubar, ubar / hp.mu, a_march, a_pred, 100 * (a_march / a_pred - 1), s0, re_a * dmu);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines appear as they are printed
  std::cout << std::unitbuf;
  options o;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        require(i + 1 < argc, "option ", a, " needs a value");
        return argv[++i];
      };
      if (a == "--case") {
        const std::string v = next();
        o.cases.clear();
        if (v == "light" || v == "both") o.cases.push_back(light_case);
        if (v == "heavy" || v == "both") o.cases.push_back(heavy_case);
        require(!o.cases.empty(), "--case: light, heavy or both (got ", v, ")");
      } else if (a == "--grids") {
        o.grids.clear();
        std::stringstream ss(next());
        for (std::string t; std::getline(ss, t, ',');) o.grids.push_back(level_named(t));
      } else if (a == "--mach-min") {
        o.mach_min = std::stod(next());
      } else if (a == "--mach-max") {
        o.mach_max = std::stod(next());
      } else if (a == "--mach-step") {
        o.mach_step = std::stod(next());
      } else if (a == "--method") {
        o.method = next();
        require(o.method == "natural" || o.method == "arclength", "--method: natural or arclength (got ", o.method, ")");
      } else if (a == "--fill") {
        o.fill = std::stoi(next());
      } else if (a == "--contact-smoothing") {
        o.contact_smoothing = std::stod(next());
        require(o.contact_smoothing >= 0, "--contact-smoothing must be >= 0");
      } else if (a == "--hopf-tol") {
        boundary_tolerance = std::stod(next());
        require(boundary_tolerance > 0, "--hopf-tol must be > 0");
      } else if (a == "--verify-grid") {
        o.verify_grid = level_named(next());
      } else if (a == "--skip-spectra") {
        o.spectra = false;
      } else if (a == "--skip-boundaries") {
        o.boundaries = false;
      } else if (a == "--skip-vg") {
        o.vg = false;
      } else if (a == "--vg-mach") {
        o.vg_mach = std::stod(next());
        require(o.vg_mach > 0 && o.vg_mach < 1, "--vg-mach must be in (0, 1)");
      } else if (a == "--vg-grid") {
        o.vg_grid = level_named(next());
      } else if (a == "--vg-range") {
        const std::string v = next();
        const auto comma = v.find(',');
        require(comma != std::string::npos, "--vg-range takes a,b (fractions of Ubar*), not ", v);
        o.vg_from = std::stod(v.substr(0, comma));
        o.vg_to = std::stod(v.substr(comma + 1));
        require(o.vg_from > 0 && o.vg_to > o.vg_from, "--vg-range: need 0 < a < b (got ", v, ")");
      } else if (a == "--vg-solver") {
        o.vg_solver = next();
        require(o.vg_solver == "lu" || o.vg_solver == "krylov" || o.vg_solver == "auto",
                "--vg-solver takes lu, krylov or auto, not ", o.vg_solver);
      } else if (a == "--vg-points") {
        o.vg_points = std::stoi(next());
        require(o.vg_points >= 2, "--vg-points must be >= 2");
      } else if (a == "--skip-jump-check") {
        o.jump_check = false;
      } else if (a == "--skip-verify") {
        o.verify = false;
      } else if (a == "--skip-reduced") {
        o.reduced = false;
      } else if (a == "--start-iterations") {
        start_iterations = std::stoi(next());
        require(start_iterations >= 0, "--start-iterations must be >= 0");
      } else if (a == "--hopf-restart") {
        hopf_restart = std::stoi(next());
        require(hopf_restart >= 1, "--hopf-restart must be >= 1");
      } else if (a == "--hopf-gram-schmidt") {
        const std::string v = next();
        require(v == "once" || v == "twice", "--hopf-gram-schmidt takes once or twice");
        hopf_reorthogonalize = v == "twice";
      } else if (a == "--start-gram-schmidt") {
        const std::string v = next();
        require(v == "once" || v == "twice", "--start-gram-schmidt takes once or twice");
        start_reorthogonalize = v == "twice";
      } else if (a == "--hopf-forcing") {
        hopf_forcing = std::stod(next());
        require(hopf_forcing > 0 && hopf_forcing <= 1, "--hopf-forcing must be in (0, 1]");
      } else if (a == "--start-restart") {
        start_restart = std::stoi(next());
        require(start_restart >= 1, "--start-restart must be >= 1");
      } else if (a == "--start-tolerance") {
        start_tolerance = std::stod(next());
        require(start_tolerance > 0 && start_tolerance < 1, "--start-tolerance must be in (0, 1)");
      } else if (a == "--tracer-corrector") {
        tracer_joint = joint_corrector(next(), a);
      } else if (a == "--jump-search") {
        const std::string v = next();
        require(v == "bottom" || v == "top", "--jump-search takes bottom or top, not ", v);
        jump_search_bottom = v == "bottom";
      } else if (a == "--coarse-guided-restart") {
        const std::string v = next();
        require(v == "on" || v == "off", "--coarse-guided-restart takes on or off, not ", v);
        coarse_guided_restart = v == "on";
      } else if (a == "--coarse-predictor") {
        const std::string v = next();
        require(v == "off" || v == "values" || v == "full" || v == "auto",
                "--coarse-predictor takes off, values, full or auto, not ", v);
        coarse_predictor = v == "off" ? 0 : v == "values" ? 1 : v == "full" ? 2 : 3;
      } else if (a == "--coarse-restart") {
        const std::string v = next();
        require(v == "on" || v == "off", "--coarse-restart takes on or off, not ", v);
        use_coarse_restart = v == "on";
      } else if (a == "--tracer-max-step") {
        tracer_max_step = std::stod(next());
        require(tracer_max_step > 0, "--tracer-max-step must be > 0");
      } else if (a == "--tracer-dw-tol") {
        tracer_derivative_tolerance = std::stod(next());
        require(tracer_derivative_tolerance > 0 && tracer_derivative_tolerance < 1, "--tracer-dw-tol must be in (0, 1)");
      } else if (a == "--crossing-medium") {
        o.crossing_medium = true;
      } else if (a == "--verbose") {
        verbose_newton = true;
      } else if (a == "--quick") {
        o.quick = true;
      } else if (!a.empty() && a[0] != '-') {
        o.out = a;
      } else {
        throw input_error("unknown option " + a);
      }
    }
    if (o.quick) {
      o.jump_check = false;
      o.grids = {level_named("coarse")};
      o.verify_grid = level_named("coarse");
      o.mach_step = o.mach_step > 0 ? o.mach_step : 0.1;
      o.mach_max = std::min(o.mach_max, 0.8);
    }
    std::filesystem::create_directories(o.out);
    const auto t0 = clk::now();
    if (o.spectra) spectra_part(o);
    std::map<std::string, boundary> all;
    if (o.boundaries) all = boundaries_part(o);
    if (o.vg) vg_part(o, all);
    if (o.jump_check) jump_check_part(o, all);
    if (o.jump_check && o.boundaries) crossing_check_part(o, all);
    std::vector<double> march_costs;
    if (o.verify) verification_part(o, all, march_costs);
    if (o.reduced) reduced_part(o, all);
    // cost table
    {
      csv_writer csv(o.out / "costs.csv", "case,grid,quantity,ratio_to_steady");
      std::cout << "\n=== cost per unit steady solve (same run, same machine) ===\n";
      const std::vector<double> listed = mach_list(o);
      // over the continued points (the first includes the inverse-power start; hopf_seconds
      // include the rejected attempts before each point and the whole arclength stretches)
      struct continued_cost {
        double hopf = 0, st = 0, extra = 0, st_listed = 0;
        std::size_t n_listed = 0;
      };
      auto cost_of = [&](const boundary& b) {
        continued_cost r;
        for (std::size_t k = 1; k < b.size(); ++k) {
          r.hopf += b[k].hopf_seconds;
          r.st += b[k].steady_seconds;
          if (is_listed(listed, b[k].mach)) {
            r.st_listed += b[k].steady_seconds;
            ++r.n_listed;
          } else if (b[k].own_steady) {
            r.extra += b[k].steady_seconds;  // a steady solve at an intermediate Mach number
          }
        }
        return r;
      };
      for (const auto& [key, b] : all) {
        const auto [hopf, st, extra, st_listed, n_listed] = cost_of(b);
        if (b.size() > 1) {
          std::printf("  %-22s Hopf point / steady solve = %.2f (mean over %zu continued points)\n", key.c_str(),
                      hopf / st, b.size() - 1);
          csv.row({key, std::string(""), std::string("hopf_per_steady"), hopf / st});
        }
        if (n_listed > 0) {
          // everything beyond one steady solve per listed Mach number (intermediate points, their
          // steady solves, rejected attempts, arclength stretches), per listed steady solve
          std::printf("  %-22s all Hopf work / steady solve = %.2f (per listed Mach number, %zu continued)\n",
                      key.c_str(), (hopf + extra) / st_listed, n_listed);
          csv.row({key, std::string(""), std::string("hopf_per_steady_listed"), (hopf + extra) / st_listed});
        }
      }
      // A finer boundary of a multi-grid run starts from the coarser one and uses it (restarts,
      // predictor): the same figure with the coarser boundary's whole wall time (every steady
      // solve and all its Hopf work) charged too, in the finer grid's listed steady solves.
      if (o.method == "natural")
        for (const auto& c : o.cases)
          for (std::size_t i = 1; i < o.grids.size(); ++i) {
            if (o.grids[i - 1].stride != 2 * o.grids[i].stride) continue;
            const auto fine = all.find(c.name + "_" + o.grids[i].name), coarse = all.find(c.name + "_" + o.grids[i - 1].name);
            if (fine == all.end() || coarse == all.end() || fine->second.size() < 2) continue;
            const continued_cost f = cost_of(fine->second);
            if (f.n_listed == 0) continue;
            double coarse_work = 0;
            for (const boundary_point& q : coarse->second) coarse_work += q.hopf_seconds + (q.own_steady ? q.steady_seconds : 0.0);
            const double ratio = (f.hopf + f.extra + coarse_work) / f.st_listed;
            std::printf("  %-22s all Hopf work + the whole %s boundary / steady solve = %.2f (per listed Mach number)\n",
                        fine->first.c_str(), o.grids[i - 1].name.c_str(), ratio);
            csv.row({fine->first, std::string(""), std::string("hopf_and_coarser_per_steady_listed"), ratio});
          }
      for (double r : march_costs) {
        std::printf("  time-marching run (4 cycles) / steady solve = %.1f\n", r);
        csv.row({std::string("light"), o.verify_grid.name, std::string("march_per_steady"), r});
      }
    }
    std::cout << "\ntotal " << seconds_since(t0) << " s; results in " << o.out << "\n";
  } catch (const std::exception& e) {
    std::cerr << "aerofoil_flutter: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
