#pragma once
// The flutter boundary mu*(M): the Hopf point of a family of aeroelastic systems at each listed
// Mach number (spec 02, 05), by natural continuation in M with a mode test, step control,
// grid sequencing from a coarser level, jumps to another mode where a branch ends, and the
// hand-over to the Hopf-curve tracer where natural continuation cannot follow a steep stretch.
//
// The family (concept flutter_family) is what a user's model supplies: the system at a grid
// level and Mach number, its equilibrium (the unit of cost: "a steady solve"), prolongation of
// an eigenvector from a coarser level, and the structural part of an eigenvector (the mode
// test). Everything else is here, once, for the aerofoil as for a wing.
//
// Natural continuation: each point starts from the previous one (mu, omega and the eigenvector
// by secant extrapolation over the last two points of the branch, the eigenvector then refined
// by inverse iteration: hopf_krylov_options::start_iterations), solved by solve_hopf_krylov. A
// point is accepted if the structural part of its eigenvector continues the previous one
// (|cos| >= same_mode_cosine); a failed or other-mode point is retried from half the Mach step
// down to 1/min_step_divisor, and the step doubles again after a success. On a finer level, a
// listed Mach number whose start from the previous point fails is restarted from the coarser
// boundary's point (grid sequencing: what the original work did by hand on the heavy case's
// steep branches), and the coarser boundary's increments predict mu, omega and, where the
// secant one is far off, the eigenvector. Where even the smallest step finds only the other
// mode, the branch has ended and the boundary JUMPS to that mode; where nothing converges and
// no coarser boundary was given, the stretch up to the listed Mach number is traced on the
// family's next coarser level (a sub-trace, which may bridge again) and this level restarted from
// its end (the coarser-level bridge); where that fails too, the fixed-equilibrium Hopf-curve
// tracer (trace_fixed_equilibrium_hopf_curve) takes over up to the next listed Mach number it
// lands on.
//
// Cost accounting: a listed Mach number's equilibrium from scratch is the unit; every other
// second (rejected attempts, intermediate Mach numbers' flows, arclength stretches) is charged
// to the next accepted point's hopf_seconds, so the points' hopf_seconds add up to the whole
// work beyond one steady solve per point. flutter_boundary_costs is a pure function of them.
//
// Check: every jump, the first point past a skipped Mach number and the last point are tested
// by imaginary_axis_crossings (the parameter enters the structural rows as q(mu) B, the
// family's stiffness_factor): PASS iff the lowest crossing above min_crossing_fraction mu* is
// the boundary point itself. It costs one sparse LU of the flow block per frequency sample.
//
// Moving equilibrium (moving_equilibrium: a mean incidence, the static deflection grows with
// mu): every point is a full Hopf system; where a branch ends, the tracer hand-over (it assumes a
// fixed equilibrium) is replaced by a V-g scan at the next listed Mach number whose lowest rising
// zero of the damping g starts the jump's Hopf solve, and the crossing check by a V-g scan from
// below mu* (scan_* options).
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <concepts>
#include <cstdarg>
#include <cstddef>
#include <cstdio>
#include <deque>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../linalg/krylov_solver.hpp"
#include "../nonlinear/aeroelastic_system.hpp"
#include "axis_crossings.hpp"
#include "equilibrium_krylov.hpp"
#include "hopf.hpp"
#include "hopf_bordered.hpp"
#include "hopf_curve_fixed_equilibrium.hpp"
#include "inverse_power.hpp"
#include "vg_diagram.hpp"

namespace aerohopf {

/// A family of aeroelastic systems over grid levels and Mach numbers, what
/// trace_flutter_boundary needs of a user's model:
/// - `system_type` (an aeroelastic_system), `block_size` (the unknowns' block size of the Krylov path);
/// - `system(level, mach)`: the system on that level at that Mach number;
/// - `level_name(level)`: for labels;
/// - `equilibrium(s, mu)`: the equilibrium of s at mu from scratch (a steady solve; may throw
///   convergence_error); optionally `equilibrium_from(s, w0, mu0, mu)`: the same continued from
///   w0, the equilibrium at mu0 (used where the equilibrium moves with mu);
/// - `prolong(fine, coarse, p)`: an eigenvector of `coarse` as one of `fine` (grid sequencing);
/// - `refines(coarse_level, fine_level)`: whether prolong works between the two levels;
/// - `structure_part(p)`: the structural unknowns of an eigenvector (the mode test);
/// - `stiffness_factor(mu)`: q(mu) with A(mu) = A0 + q(mu) B, B in the structural block, and
///   its inverse `parameter_of_factor(q)` > 0 (the crossing check; the aerofoil: q = 1/Ubar^2);
/// - optionally `coarser_level(level)` -> std::optional<int>: the next coarser level that refines
///   to `level` (flutter_boundary_options::coarser_level_bridge), empty on the coarsest;
/// - optionally its own solvers, used instead of the serial Krylov ones for every point and start
///   (e.g. on MPI ranks, distributed/mpi_aerofoil_family.hpp): `solve_hopf(s, guess,
///   hopf_options, hopf_krylov_options)` -> hopf_result for solve_hopf_krylov, and
///   `hopf_start(s, w, mu, omega, hopf_start_krylov_options, eigen_pair*)` -> hopf_point for
///   hopf_start_krylov. The driver itself (predictions, mode test, tracer hand-over, crossing
///   check) then runs on every rank alike, on the whole vectors those return.
template <class F>
concept flutter_family = aeroelastic_system<typename F::system_type> &&
                         requires(const F& f, const typename F::system_type& s, int level, double mach,
                                  const vec<std::complex<double>>& p) {
  { F::block_size } -> std::convertible_to<int>;
  { f.system(level, mach) } -> std::convertible_to<typename F::system_type>;
  { f.level_name(level) } -> std::convertible_to<std::string>;
  { f.equilibrium(s, mach) } -> std::convertible_to<vec<double>>;
  { f.prolong(s, s, p) } -> std::convertible_to<vec<std::complex<double>>>;
  { f.refines(level, level) } -> std::convertible_to<bool>;
  { f.structure_part(p) } -> std::convertible_to<vec<std::complex<double>>>;
  { f.stiffness_factor(mach) } -> std::convertible_to<double>;
  { f.parameter_of_factor(mach) } -> std::convertible_to<double>;
};

enum class coarse_predictor { off, values, full, automatic };

struct flutter_boundary_options {
  /// Start of the first point (inverse power with shift i start_omega at start_mu).
  double start_mu = 1, start_omega = 1;
  /// Or the first point by Newton from a Hopf point of a neighbouring problem on the same level
  /// (instead of the coarser boundary's point and the inverse power; a coarser boundary still
  /// serves the later points): continuation in a structural parameter, e.g. from this level's
  /// flutter point at another structural damping, where grid sequencing converges to another Hopf
  /// point (AGARD 445.6 medium, no damping, GMRES(80): the trivial one at mu = 0). p must have the
  /// level's size; w is not used. ||F|| there holds only the changed parameter's term and is small
  /// while the correction is not, so the first step is not judged by divergence_factor, and its
  /// GMRES restarts at start_point_restart at the least, plainly, with the second Gram-Schmidt
  /// pass where needed: GMRES(80) stalls on that correction (AGARD coarse, 0.5 % -> none: relative
  /// residual 0.98 after 400 iterations; unrestarted, 166), and GMRES-DR(80, 20) on the medium
  /// grid (0.99999 after 2,000).
  std::optional<hopf_point> start_point;
  int start_point_restart = 300;
  /// Newton criterion ||F|| <= tolerance of the boundary points. 1e-7: Ubar* then changes by
  /// < 1e-9 relative in a further iteration on the light medium NACA 0012 boundary, far below the
  /// grid error; it fixes Ubar* only to ~2e-5 on the heavy one (mu enters only the stiffness).
  double tolerance = 1e-7;
  /// BILU(k) of the Hopf preconditioner and of the inverse-power start (2: heavy medium mean
  /// Hopf / steady 0.89 vs 0.99 with BILU(1), measured).
  int fill_level = 2;
  /// Newton per point: 2-4 iterations from a refined continuation start; abandoned after
  /// max_iterations, when ||F|| more than doubles after the first step (max_contraction), or
  /// when the first step raises it 100x (divergence_factor; failures rose 125-1812x, converging
  /// starts at most 33x on the NACA 0012 boundaries).
  int max_iterations = 12;
  double max_contraction = 2.0, divergence_factor = 100.0;
  hopf_krylov_options krylov = [] {
    hopf_krylov_options k;
    // mu enters A only through the stiffness, so A0 + dmu A_mu0 stays accurate over a step
    k.reuse_window = 2e-2;
    k.start_iterations = 1;
    k.start_tolerance = 1e-2;
    k.start_residual_threshold = 10.0;  // subsonic continued guesses (||F|| 3-7) go straight to Newton
    return k;
  }();
  /// GMRES restart of the inverse-power start (50: light medium 5.0-5.8 s vs 6.9-7.3 s with 80).
  int start_restart = 50;
  /// Eigen-residual target of the inverse-power starts (first point, V-g scan jumps), each GMRES
  /// solve 10x tighter. The start only has to lie in the Hopf Newton's basin, which converges the
  /// pair itself (heavy medium first point: 6 iterations, 0.59 s, against 16 and 3.0 s at 1e-8;
  /// the same Newton iterates to 3 digits).
  double start_eigen_tolerance = 1e-3;
  double same_mode_cosine = 0.9;  ///< mode test on the structural parts (one branch: 0.957-0.9991)
  int min_step_divisor = 8;       ///< natural continuation gives up at 1/8 of a listed step
  bool jump_search_bottom = true;    ///< other mode at the full step: try the smallest step next
  bool coarse_restart = true;        ///< grid-sequenced restart where the start from the previous point fails
  bool coarse_guided_restart = true; ///< ... first, where the coarser boundary changes mode within 1/4 step
  coarse_predictor predictor = coarse_predictor::automatic;
  /// mu enters the system only through mu^2 (the aerofoil's 1/Ubar^2): -mu* is the same point.
  bool parameter_even = false;
  /// A point with mu* below this is refused (a failed attempt: the step is retried shorter).
  /// A wing's density parameter: at mu = 0 the undamped in-vacuo modes are trivial Hopf points,
  /// which a secant predictor through a falling boundary can land on (AGARD 445.6 coarse, no
  /// damping, M = 0.678 -> 0.901: mu* = -1e-11).
  double mu_min = -INFINITY;
  /// mu > 0 along the boundary, varying by a large factor (a wing's density parameter: 9x from
  /// M = 0.5 to 0.96 on AGARD 445.6): the predictors extrapolate log mu (the secant) and scale
  /// by the coarser boundary's ratio (the increment) instead of differences, so a falling
  /// boundary is not predicted through zero.
  bool positive_parameter = false;
  /// The equilibrium moves with mu (e.g. a mean incidence: the static aeroelastic deflection
  /// depends on Ubar): each point is a FULL Hopf system solved by solve_hopf_krylov with
  /// hopf_krylov_options::full_system (no start refinement), the family's equilibrium(s, mu) is
  /// the static aeroelastic solve. The fixed-equilibrium tracer hand-over and the axis-crossing
  /// check assume A0 independent of mu; in their place come V-g scans (below).
  bool moving_equilibrium = false;
  /// Moving equilibrium: where the full Hopf Newton fails from the continued guess, the secant
  /// on the frozen-flow map (flutter_boundary_tracer::full_hopf): iterations and largest step
  /// (relative to mu). NACA 0012 coarse, alpha_0 = 1 deg, M = 0.60-0.6625: 3-5 iterations.
  /// The point it leads to must be a flutter onset (moving_crossing_sides: Re(lambda) < 0 below,
  /// > 0 above), else the attempt fails.
  int frozen_secant_iterations = 8;
  double frozen_secant_max_step = 0.05;
  /// Moving equilibrium: V-g scans (vg_diagram with the equilibrium continued along mu, the
  /// oscillatory modes of the structural block A_ss at the first value as starts, inverse powers
  /// by sparse LU or BILU-GMRES: scan_direct_max_unknowns). Every scan starts at scan_from x the
  /// reference mu, where the aeroelastic modes are still near the in-vacuo ones (NACA 0012
  /// coarse, M = 0.7: from 0.75 Ubar* the in-vacuo plunge shift is as far from its mode as from a
  /// flow eigenvalue, and inverse power stalls), in steps of scan_lead_step up to scan_fine_from,
  /// then scan_step (0.02 throughout: NACA 0012 medium, alpha_0 = 1 deg, M = 0.65, steps of 0.05
  /// took flow eigenvalues whose structural parts overlap the mode's by 0.98-0.996 for it, and
  /// the scan found no rising zero of g, where steps of 0.02 find the onset, Ubar* = 1.5151).
  /// Where a branch
  /// ends (natural continuation fails down to 1/min_step_divisor), the next listed Mach number's
  /// lowest rising zero of g below scan_to x the last point's mu starts the jump's full Hopf
  /// solve. The check of every jump and the last point scans up to (1 - scan_step) mu*, then
  /// (1 -+ scan_delta) mu*: PASS iff the lowest rising zero of g lies between the last two (the
  /// point is the lowest crossing, and g rises through it). A scan misses an unstable band
  /// narrower than its step (NACA 0012 coarse, alpha_0 = 1 deg, M = 0.6625: Ubar 1.553-1.56).
  double scan_from = 0.5, scan_lead_step = 0.02, scan_fine_from = 0.75, scan_step = 0.02, scan_to = 1.6;
  double scan_delta = 1e-3;
  /// The scans' inverse-power tolerance (GMRES 10x below it) and mode-tracking overlap
  /// (vg_options::min_overlap): a scan needs g to a few digits, and near coalescence the two
  /// structural modes exchange shape faster than a tracking step of 1/16 of scan_step.
  double scan_tolerance = 1e-7, scan_min_overlap = 0.6;
  /// A scan's inverse powers by sparse LU of A - sigma I up to this many unknowns, by
  /// BILU-GMRES (vg_krylov_solvers) above: per inverse power, NACA 0012 at M = 0.65-0.70, coarse
  /// (4,100 unknowns) LU 0.31 s vs GMRES 0.37 s, medium (16,388) 3.4 s vs 4.4 s, and on the
  /// medium grid GMRES lost the mode tracking where LU did not.
  Eigen::Index scan_direct_max_unknowns = 20000;
  /// Hand-over to the fixed-equilibrium Hopf-curve tracer (its step metric and bounds are the
  /// model's: set curve.mu_scale, nu_scale, omega_scale, mu_min, mu_max, fixed_equilibrium.fill_level...).
  bool handover = true;
  /// Before the hand-over, on a level without a coarser boundary: trace the stretch on the
  /// family's next coarser level (flutter_family's optional coarser_level) and restart this level
  /// from its point at the listed Mach number (coarser_level_bridge; the tracer hand-over where
  /// it fails). NACA 0012 heavy medium boundary alone, the points M = 0.825 and 0.83 with their
  /// failed attempts: 13.8 s with the medium-grid tracer (12 points), 4.7 s with the bridge.
  bool coarser_level_bridge = true;
  hopf_curve_options curve;
  fixed_equilibrium_hopf_curve_options fixed_equilibrium;
  double fold_tolerance = 0.005;   ///< the traced curve turning back in M by more: stop
  double retrace_distance = 0.1;   ///< in the tracer's metric: a point this close to the old trail is a retrace
  int handover_max_points = 200;
  /// The crossing check of every jump and the last point (imaginary_axis_crossings; a V-g scan
  /// for a moving equilibrium).
  bool check_crossings = true;
  double crossing_omega_min = 0.05, crossing_omega_factor = 6.0, crossing_min_fraction = 0.2;
  double crossing_mu_tolerance = 1e-5, crossing_omega_tolerance = 1e-4;
  bool verbose = false;           ///< a line per Newton iteration (and per V-g scan step and failed inverse power)
  std::ostream* log = &std::cout;  ///< a line per point and attempt (nullptr: silent)
  std::string label = "boundary";
};

struct flutter_boundary_point {
  double mach = 0, mu = 0, omega = 0;
  int newton_iterations = 0;
  long linear_iterations = 0;
  double hopf_seconds = 0, steady_seconds = 0;
  hopf_point point;  ///< with the equilibrium at this Mach number
  /// false for the points of an arclength stretch: their steady_seconds is the unit of cost
  /// (the steady solve where the stretch starts), not a steady solve at their Mach number
  bool own_steady = true;
  double cosine = NAN;  ///< structural cosine to the previous point (NAN for the first)
  bool jump = false;    ///< starts a new branch (another mode, or a moving-equilibrium V-g scan's crossing)
};

/// One attempt of natural continuation (accepted or not) or an arclength stretch.
struct flutter_attempt {
  double mach = 0;
  std::string kind;     ///< "continued", "coarse restart", "first", "start point", "arclength", "coarser-level bridge", "bridge restart"
  std::string outcome;  ///< "accepted", "other mode", "failed: ..."
  double seconds = 0;
};

struct crossing_check_record {
  double mach = 0, mu = 0, omega = 0;
  std::string what;  ///< "jump" or "last point"
  double lowest_mu = NAN, lowest_omega = NAN;
  std::size_t crossings = 0;
  bool pass = false;
  std::vector<std::pair<double, double>> all;  ///< (mu, omega) of every crossing with q > 0
};

struct flutter_boundary {
  std::string label;
  int level = 0;
  std::vector<flutter_boundary_point> points;
  std::vector<flutter_attempt> attempts;
  bool complete = false;     ///< every listed Mach number reached (with a point, or in skipped)
  /// Listed Mach numbers without a point, with the reason (moving equilibrium: the V-g scan there
  /// found no rising zero of g, e.g. because the static equilibrium is lost first); the boundary
  /// goes on at the next one.
  std::vector<std::pair<double, std::string>> skipped;
  std::string stop_reason;   ///< why not, if not complete
  std::vector<crossing_check_record> checks;
  bool checks_passed() const {
    return std::all_of(checks.begin(), checks.end(), [](const crossing_check_record& c) { return c.pass; });
  }
};

/// The cost of a boundary per unit steady solve (pure function of its points).
struct flutter_boundary_costs {
  double hopf_per_steady = NAN;         ///< over the continued points (all but the first)
  double hopf_per_steady_listed = NAN;  ///< all work beyond one steady solve per listed Mach number
  std::size_t continued = 0, listed = 0;
  double work_seconds = 0;  ///< every second of the boundary (Hopf work and steady solves)
  /// of the continued points: the Hopf work and the steady solves at unlisted Mach numbers ...
  double beyond_steady_seconds = 0;
  /// ... and the steady solves at listed ones (the unit of hopf_per_steady_listed)
  double listed_steady_seconds = 0;
};

namespace internal {

inline double flutter_seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline bool flutter_listed(const std::vector<double>& machs, double m) {
  return std::any_of(machs.begin(), machs.end(), [&](double l) { return std::abs(l - m) < 1e-9; });
}

inline std::string flutter_fixed(double x, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, x);
  return b;
}

/// printf to opt.log (nothing if it is null)
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
inline void flutter_say(std::ostream* log, const char* fmt, ...) {
  if (!log) return;
  char buf[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  *log << buf << std::flush;
}

inline void check_flutter_boundary_options(const flutter_boundary_options& o, const std::vector<double>& machs,
                                           const std::string& where) {
  require(!machs.empty(), where, ": no Mach numbers");
  for (std::size_t k = 0; k < machs.size(); ++k) {
    require(std::isfinite(machs[k]) && machs[k] > 0, where, ": Mach number ", k, " is ", machs[k]);
    require(k == 0 || machs[k] > machs[k - 1] + 1e-9, where, ": the Mach numbers must increase (", machs[k - 1],
            " then ", machs[k], ")");
  }
  require(std::isfinite(o.start_mu) && o.start_mu != 0, where, ": start_mu must be finite and non-zero (got ",
          o.start_mu, ")");
  require(std::isfinite(o.start_omega) && o.start_omega > 0, where, ": start_omega must be finite and > 0 (got ",
          o.start_omega, ")");
  if (o.start_point) {
    require(std::isfinite(o.start_point->mu) && o.start_point->mu != 0, where,
            ": start_point.mu must be finite and non-zero (got ", o.start_point->mu, ")");
    require(std::isfinite(o.start_point->omega) && o.start_point->omega > 0, where,
            ": start_point.omega must be finite and > 0 (got ", o.start_point->omega, ")");
    require(o.start_point->p.size() > 0 && o.start_point->p.allFinite() && o.start_point->p.norm() > 0, where,
            ": start_point.p must be a finite non-zero vector (size ", o.start_point->p.size(), ")");
    require(o.start_point_restart >= 1, where, ": start_point_restart must be >= 1 (got ", o.start_point_restart, ")");
  }
  require(o.tolerance > 0 && std::isfinite(o.tolerance), where, ": tolerance must be > 0 (got ", o.tolerance, ")");
  require(!std::isnan(o.mu_min) && o.mu_min < INFINITY, where, ": mu_min must be a number below infinity (got ",
          o.mu_min, ")");
  require(o.fill_level >= 0, where, ": fill_level must be >= 0 (got ", o.fill_level, ")");
  require(o.max_iterations >= 1, where, ": max_iterations must be >= 1 (got ", o.max_iterations, ")");
  require(o.start_restart >= 1, where, ": start_restart must be >= 1 (got ", o.start_restart, ")");
  require(std::isfinite(o.start_eigen_tolerance) && o.start_eigen_tolerance > 0 && o.start_eigen_tolerance < 1, where,
          ": start_eigen_tolerance must lie in (0, 1) (got ", o.start_eigen_tolerance, ")");
  require(o.same_mode_cosine > 0 && o.same_mode_cosine < 1, where, ": same_mode_cosine must lie in (0, 1) (got ",
          o.same_mode_cosine, ")");
  require(o.min_step_divisor >= 1, where, ": min_step_divisor must be >= 1 (got ", o.min_step_divisor, ")");
  require(o.frozen_secant_iterations >= 0 && o.frozen_secant_max_step > 0, where,
          ": frozen_secant_iterations must be >= 0 and frozen_secant_max_step > 0 (got ", o.frozen_secant_iterations,
          ", ", o.frozen_secant_max_step, ")");
  require(o.scan_from > 0 && o.scan_lead_step > 0 && o.scan_step > 0 && o.scan_fine_from >= o.scan_from &&
              o.scan_to > o.scan_fine_from + o.scan_step && o.scan_delta > 0 && o.scan_delta < 0.5 * o.scan_step &&
              o.scan_fine_from < 1 - o.scan_step && o.scan_tolerance > 0 && o.scan_min_overlap >= 0 &&
              o.scan_min_overlap <= 1,
          where,
          ": V-g scans need 0 < scan_from <= scan_fine_from < 1 - scan_step, scan_to > scan_fine_from + scan_step, "
          "steps > 0, 0 < scan_delta < scan_step / 2, scan_tolerance > 0, scan_min_overlap in [0, 1] (got scan_from ",
          o.scan_from, ", scan_fine_from ", o.scan_fine_from, ", scan_to ", o.scan_to, ", scan_step ", o.scan_step,
          ", scan_delta ", o.scan_delta, ")");
  check_hopf_krylov_options(o.krylov, where);
}

}  // namespace internal

/// The mode test: structural_cosine (nonlinear/aeroelastic_system.hpp) of the structural parts
/// of two eigenvectors. The flow part is no test: shock motion rotates it (full cosine 0.16-0.45
/// along one NACA 0012 branch).
template <flutter_family F>
double structural_cosine(const F& family, const vec<std::complex<double>>& p0, const vec<std::complex<double>>& p1) {
  return structural_cosine<std::complex<double>>(family.structure_part(p0), family.structure_part(p1));
}

namespace internal {

/// The equilibrium of s at mu from w0, the one at mu0: the family's equilibrium_from where it has
/// one (continuation in mu from a nearby state), else its equilibrium from scratch.
template <flutter_family F>
vec<double> family_equilibrium_near(const F& f, const typename F::system_type& s, const vec<double>& w0, double mu0,
                                    double mu) {
  if constexpr (requires { f.equilibrium_from(s, w0, mu0, mu); })
    return f.equilibrium_from(s, w0, mu0, mu);
  else
    return f.equilibrium(s, mu);
}

/// The Hopf solve of a point: the family's own `solve_hopf(s, guess, hopf_options,
/// hopf_krylov_options)` where it has one (e.g. on MPI ranks: distributed/mpi_aerofoil_family.hpp),
/// else solve_hopf_krylov with the family's block size.
template <flutter_family F>
hopf_result family_solve_hopf(const F& f, const typename F::system_type& s, const hopf_point& guess,
                              const hopf_options& ho, const hopf_krylov_options& ko) {
  if constexpr (requires {
                  { f.solve_hopf(s, guess, ho, ko) } -> std::convertible_to<hopf_result>;
                })
    return f.solve_hopf(s, guess, ho, ko);
  else
    return solve_hopf_krylov<F::block_size>(s, guess, ho, ko);
}

/// The inverse-power start at (w, mu), shift i omega: the family's own `hopf_start(s, w, mu, omega,
/// hopf_start_krylov_options, eigen_pair*)` where it has one, else hopf_start_krylov.
template <flutter_family F>
hopf_point family_hopf_start(const F& f, const typename F::system_type& s, const vec<double>& w, double mu,
                             double omega, const hopf_start_krylov_options& so, eigen_pair* info) {
  if constexpr (requires {
                  { f.hopf_start(s, w, mu, omega, so, info) } -> std::convertible_to<hopf_point>;
                })
    return f.hopf_start(s, w, mu, omega, so, info);
  else
    return hopf_start_krylov<F::block_size>(s, w, mu, omega, so, info);
}

struct moving_scan_result {
  vg_result vg;
  std::map<double, vec<double>> equilibria;  ///< every equilibrium the scan solved, by mu
  const vg_flutter_point* lowest = nullptr;  ///< the lowest rising zero of g (in vg.flutter), if any
  double seconds = 0;
};

/// A family whose `scan_eigen(s, vg_krylov_options)` returns the V-g scan's inverse power,
/// eig(w, mu, shift, start, inverse_power_options) -> eigen_pair (the vector whole; failures as
/// convergence_error or singular_matrix_error), in place of vg_krylov_solvers on s (above
/// flutter_boundary_options::scan_direct_max_unknowns; below, the sparse LU as for any family).
template <class F>
concept has_scan_eigen = requires(const F& f, const typename F::system_type& s, const vg_krylov_options& ko,
                                  const vec<double>& w, double mu, std::complex<double> shift,
                                  const vec<std::complex<double>>* start, const inverse_power_options& po) {
  { f.scan_eigen(s, ko)(w, mu, shift, start, po) } -> std::convertible_to<eigen_pair>;
};

/// V-g scan of s over mus (increasing), from the oscillatory modes of the structural block of
/// A_ss at mus.front() (file comment of vg_diagram.hpp; flutter_boundary_options::scan_from).
/// The equilibrium is the family's from scratch at mus.front() (w_first if the caller has it),
/// continued up along mus: below the static divergence the static equilibrium is unique, past it
/// not (NACA 0012 coarse, alpha_0 = 1 deg, M = 0.70, Ubar = 2.14: +0.154 rad continued up from
/// Ubar = 1, -0.052 rad from rest in one step), so the scan follows the branch reached by a
/// rising speed. Ends where the tracking or the equilibrium is lost and, with
/// stop_after_flutter, one parameter after the first rising zero of g.
template <flutter_family F>
moving_scan_result moving_vg_scan(const F& f, const typename F::system_type& s, const std::vector<double>& mus,
                                  const flutter_boundary_options& o, bool stop_after_flutter,
                                  const vec<double>* w_first = nullptr) {
  using S = typename F::system_type;
  constexpr int B = F::block_size;
  const auto t0 = std::chrono::steady_clock::now();
  moving_scan_result r;
  if constexpr (!is_sparse_matrix_v<jacobian_t<S>>) {
    throw input_error(o.label + ": the V-g scan of a moving equilibrium needs Eigen sparse Jacobians (vg_krylov_solvers)");
  } else {
    vec<double> w = w_first ? *w_first : f.equilibrium(s, mus.front());
    double mu_w = mus.front();
    r.equilibria[mu_w] = w;
    // Continued from the last equilibrium; a step the solve fails on is split in halves, down
    // to 1/8 (NACA 0012 medium, alpha_0 = 1 deg, M = 0.65: the static pitch doubles between
    // 0.95 and 1.0 Ubar*, and Newton-Krylov met negative densities over a step of 0.03 Ubar*).
    auto equilibrium = [&](double mu) {
      if (const auto it = r.equilibria.find(mu); it != r.equilibria.end()) return it->second;
      const double from = mu_w;
      for (int parts = 1;; parts *= 2) {
        try {
          vec<double> v = w;
          double at = from;
          for (int k = 1; k <= parts; ++k) {
            const double next = k == parts ? mu : from + (mu - from) * k / parts;
            v = family_equilibrium_near(f, s, v, at, next);
            at = next;
          }
          w = std::move(v);
          break;
        } catch (const convergence_error&) {
          if (parts >= 8) throw;
        }
      }
      mu_w = mu;
      r.equilibria[mu] = w;
      return w;
    };
    const vec<double>& w1 = r.equilibria.begin()->second;
    const Eigen::Index ns = s.structure_size();
    const Eigen::MatrixXd a_ss =
        krylov_exact_jacobian<B>(s, w1, mus.front(), o.label + " V-g scan").structure().bottomRightCorner(ns, ns);
    const std::vector<vg_mode_start> starts = vg_mode_starts(a_ss);
    if (starts.empty())
      throw convergence_error(concat(o.label, " V-g scan: the structural block at mu = ", mus.front(),
                                     " has no oscillatory mode to trace"));
    vg_options vo;
    vo.inverse_power.tolerance = o.scan_tolerance;
    vo.min_overlap = o.scan_min_overlap;
    vo.partial_on_lost_tracking = true;
    vo.stop_after_flutter = stop_after_flutter;
    vo.log = o.log;
    vo.verbose = o.verbose;
    vg_krylov_options ko;
    ko.fill_level = o.fill_level;
    ko.krylov.relative_tolerance = 0.1 * o.scan_tolerance;
    if (s.size() <= o.scan_direct_max_unknowns) {
      r.vg = vg_diagram(s, equilibrium, mus, starts, vo);
    } else if constexpr (has_scan_eigen<F>) {
      // the family's own inverse powers (e.g. on MPI ranks): eig(w, mu, shift, start, options);
      // it assembles what it needs itself, so nothing is made per parameter here
      auto eig = f.scan_eigen(s, ko);
      r.vg = vg_trace(
          s, equilibrium, mus, starts, vo, [](const vec<double>&, double) { return nullptr; },
          [&](std::nullptr_t, const vec<double>& w, double mu, std::complex<double> shift,
              const vec<std::complex<double>>* start) { return eig(w, mu, shift, start, vo.inverse_power); });
    } else {
      r.vg = vg_diagram(s, equilibrium, mus, starts, vo, vg_krylov_solvers<B>(s, ko));
    }
    for (const auto& x : r.vg.flutter)
      if (!r.lowest || x.mu < r.lowest->mu) r.lowest = &x;
  }
  r.seconds = flutter_seconds_since(t0);
  return r;
}

/// Options of an inverse-power start by BILU-GMRES (hopf_start_krylov) to the eigen-residual
/// `tolerance`, each GMRES solve 10x tighter, with the driver's BILU fill and GMRES restart.
inline hopf_start_krylov_options krylov_start_options(const flutter_boundary_options& o, double tolerance) {
  hopf_start_krylov_options so;
  so.fill_level = o.fill_level;
  so.single_precision_factors = o.krylov.single_precision_factors;
  so.krylov.restart = o.start_restart;
  so.krylov.relative_tolerance = 0.1 * tolerance;
  so.inverse_power.tolerance = tolerance;
  return so;
}

/// The real parts of the critical eigenvalue just below and above a Hopf point h of a moving
/// equilibrium, at (1 -+ scan_delta) |h.mu|: the equilibrium continued there from h.w
/// (family_equilibrium_near), the eigenvalue nearest i h.omega by inverse power with BILU-GMRES
/// (hopf_start_krylov) to the eigen-residual scan_tolerance. A flutter onset (g rising through
/// zero) has below < 0 < above; a restabilisation the reverse.
template <flutter_family F>
std::pair<double, double> moving_crossing_sides(const F& f, const typename F::system_type& s, const hopf_point& h,
                                                const flutter_boundary_options& o) {
  require(h.w.size() == s.size(), o.label, ": crossing sides: the Hopf point's equilibrium has ", h.w.size(),
          " entries for a system of ", s.size());
  const hopf_start_krylov_options so = krylov_start_options(o, o.scan_tolerance);
  const double mu = std::abs(h.mu);
  auto re_at = [&](double m) {
    const vec<double> w = family_equilibrium_near(f, s, h.w, mu, m);
    eigen_pair ep;
    internal::family_hopf_start(f, s, w, m, h.omega, so, &ep);
    return ep.lambda.real();
  };
  return {re_at((1 - o.scan_delta) * mu), re_at((1 + o.scan_delta) * mu)};
}

/// The parameters of a V-g scan about mu (flutter_boundary_options::scan_from): scan_from to
/// scan_fine_from in lead steps, then in scan_step up to `to` (all times |mu|); with `check`,
/// up to (1 - scan_step) and then 1 -+ scan_delta instead.
inline std::vector<double> scan_values(double mu, const flutter_boundary_options& o, double to, bool check) {
  std::vector<double> v;
  const double a = std::abs(mu);
  for (double x = o.scan_from; x < o.scan_fine_from - 1e-9; x += o.scan_lead_step) v.push_back(a * x);
  const double end = check ? 1 - o.scan_step : to;
  for (int k = 0; o.scan_fine_from + k * o.scan_step <= end + 1e-9; ++k) v.push_back(a * (o.scan_fine_from + k * o.scan_step));
  if (check) {
    v.push_back(a * (1 - o.scan_delta));
    v.push_back(a * (1 + o.scan_delta));
  }
  return v;
}

/// The state of one trace_flutter_boundary call (its lambdas made members).
template <flutter_family F>
class flutter_boundary_tracer {
 public:
  using S = typename F::system_type;
  using cplx = std::complex<double>;
  using clk = std::chrono::steady_clock;
  static constexpr int B = F::block_size;

  flutter_boundary_tracer(const F& family, int level, const std::vector<double>& machs, const flutter_boundary* coarser,
                          const flutter_boundary_options& opt)
      : f_(family), level_(level), machs_(machs), coarser_(coarser), o_(opt), log_(opt.log) {
    b_.label = opt.label;
    b_.level = level;
  }

  flutter_boundary run();

 private:
  struct solved_flow {
    double mach;
    double mu;  ///< the parameter the equilibrium w was solved at (it moves with mu in moving_equilibrium mode)
    vec<double> w;
    double seconds = 0;
    bool charged = false;  ///< its seconds were added to rejected_ (an attempt there was rejected)
    /// ... and a written point has taken them since: booked as lost work for good
    bool settled = false;
  };

  const F& f_;
  int level_;
  const std::vector<double>& machs_;
  const flutter_boundary* coarser_;
  const flutter_boundary_options& o_;
  std::ostream* log_;
  flutter_boundary b_;
  std::vector<flutter_boundary_point>& pts_ = b_.points;
  std::size_t branch_start_ = 0;
  double rejected_ = 0;
  std::deque<solved_flow> flows_;  // references stay valid as it grows
  std::map<double, std::optional<flutter_boundary_point>> restarts_;
  std::string scan_failure_;  // why the last moving_jump found no point

  double cosine(const hopf_point& a, const hopf_point& b) const { return structural_cosine(f_, a.p, b.p); }
  std::string label_at(double m) const { return o_.label + " M=" + flutter_fixed(m, 4); }

  hopf_options hopf_opts(const std::string& label, bool fixed = true) const {
    hopf_options ho;
    ho.fixed_equilibrium = fixed;
    ho.label = label;
    ho.newton.abs_tolerance = o_.tolerance;
    ho.newton.max_iterations = o_.max_iterations;
    ho.newton.max_contraction = o_.max_contraction;
    ho.newton.divergence_factor = o_.divergence_factor;
    ho.verbose = o_.verbose;
    ho.log = log_ ? log_ : &std::cout;
    if (!log_) ho.verbose = false;
    return ho;
  }

  hopf_start_krylov_options start_options() const { return krylov_start_options(o_, o_.start_eigen_tolerance); }

  void record(double m, const char* kind, std::string outcome, double seconds) {
    b_.attempts.push_back({m, kind, std::move(outcome), seconds});
  }

  std::optional<flutter_boundary_point> hopf_at(const S& s, double mach, const solved_flow& st, const hopf_point& guess,
                                                const std::string& label, const char* kind,
                                                bool from_start_point = false) {
    hopf_point g = guess;
    g.w = st.w;
    hopf_krylov_options ko = o_.krylov;
    ko.fill_level = o_.fill_level;
    if (o_.moving_equilibrium) {
      ko.full_system = true;
      ko.start_iterations = 0;
    }
    hopf_options ho = hopf_opts(label, !o_.moving_equilibrium);
    if (from_start_point) {  // flutter_boundary_options::start_point
      ho.newton.divergence_factor = std::numeric_limits<double>::infinity();
      ko.krylov.restart = std::max(ko.krylov.restart, o_.start_point_restart);
      ko.krylov.deflation = 0;
      ko.krylov.reorthogonalize = true;  // a long basis: one Gram-Schmidt pass loses orthogonality
    }
    const auto t0 = clk::now();
    try {
      hopf_result h = o_.moving_equilibrium ? full_hopf(s, g, st.mu, ho, ko, label)
                                            : internal::family_solve_hopf(f_, s, g, ho, ko);
      if (o_.parameter_even) h.point.mu = std::abs(h.point.mu);
      if (!(h.point.mu >= o_.mu_min))
        throw convergence_error(concat(label, ": converged to mu* = ", h.point.mu, " (omega* = ", h.point.omega,
                                       "), below the admissible mu_min = ", o_.mu_min));
      if (o_.verbose)
        flutter_say(log_, "    %s: setup (assembly + BILU) %.3f s, GMRES %.3f s, residuals %.3f s\n", label.c_str(),
                    h.setup_seconds, h.linear_seconds, h.residual_seconds);
      flutter_boundary_point p;
      p.mach = mach;
      p.mu = h.point.mu;
      p.omega = h.point.omega;
      p.newton_iterations = h.report.iterations;
      p.linear_iterations = h.linear_iterations;
      p.hopf_seconds = flutter_seconds_since(t0);
      p.steady_seconds = st.seconds;
      p.point = h.point;
      record(mach, kind, "converged", p.hopf_seconds);
      return p;
    } catch (const error& e) {
      flutter_say(log_, "    %s failed: %s\n", label.c_str(), e.what());
      record(mach, kind, std::string("failed: ") + e.what(), flutter_seconds_since(t0));
      return std::nullopt;
    }
  }

  /// The full Hopf system from the continued guess; where that fails, once more from the fixed
  /// point of the FROZEN-FLOW MAP mu -> mu'(mu), the fixed-equilibrium Hopf parameter of
  /// A(w_s(mu)) with w_s(mu) the equilibrium at mu (continued from g.w, the one at mu_w): at its
  /// fixed point the fixed-equilibrium Hopf point is the full one. Secant iteration on
  /// mu'(mu) - mu, each step at most frozen_secant_max_step |mu|, to |mu' - mu| <= 1e-6 |mu|;
  /// then the full system from there. A continued eigenvector is far off where shocks move
  /// (||F|| 25-36 and a first step through negative densities, NACA 0012 coarse at alpha_0 = 1
  /// deg, M > 0.66); the frozen-flow map is a smooth function of one variable there.
  hopf_result full_hopf(const S& s, hopf_point g, double mu_w, const hopf_options& ho, const hopf_krylov_options& ko,
                        const std::string& label) {
    try {
      return internal::family_solve_hopf(f_, s, g, ho, ko);
    } catch (const error& e) {
      flutter_say(log_, "    %s: %s\n    -> again from the fixed point of the frozen-flow map (secant)\n", label.c_str(),
                  e.what());
    }
    hopf_options fo = hopf_opts(label + " (frozen flow)", true);
    fo.newton.abs_tolerance = std::max(o_.tolerance, 1e-6);
    fo.equilibrium_tolerance = 1e300;  // w is the equilibrium at another mu than the point's
    hopf_krylov_options kf = o_.krylov;
    kf.fill_level = o_.fill_level;
    // mu'(mu) at g.w = w_s(mu): g's eigenvector and frequency are updated as a start for the next
    auto frozen = [&](hopf_point& h) {
      const hopf_result r = internal::family_solve_hopf(f_, s, h, fo, kf);
      h.p = r.point.p;
      h.omega = r.point.omega;
      return o_.parameter_even ? std::abs(r.point.mu) : r.point.mu;
    };
    const double max_step = o_.frozen_secant_max_step;
    auto clamp_step = [&](double from, double to) {
      const double d = max_step * std::abs(from);
      return std::clamp(to, from - d, from + d);
    };
    double mu0 = mu_w;
    double r0 = frozen(g) - mu0;
    double mu1 = clamp_step(mu0, mu0 + r0);
    g.w = equilibrium_near(s, g.w, mu0, mu1);
    for (int it = 1; it <= o_.frozen_secant_iterations; ++it) {
      g.mu = mu1;
      const double r1 = frozen(g) - mu1;
      if (o_.verbose)
        flutter_say(log_, "    %s: frozen-flow secant %d: mu = %.9f, mu' - mu = %+.3e\n", label.c_str(), it, mu1, r1);
      if (std::abs(r1) <= 1e-6 * std::abs(mu1)) break;
      const double mu2 = clamp_step(mu1, r1 != r0 ? mu1 - r1 * (mu1 - mu0) / (r1 - r0) : mu1 + r1);
      mu0 = mu1;
      r0 = r1;
      g.w = equilibrium_near(s, g.w, mu1, mu2);
      mu1 = mu2;
    }
    g.mu = mu1;
    hopf_result h = internal::family_solve_hopf(f_, s, g, ho, ko);
    // The frozen-flow map leads to the Hopf point nearest its start, which can be one where g
    // FALLS through zero (NACA 0012 medium, alpha_0 = 1 deg, M = 0.65: Ubar = 1.57627, above the
    // onset at 1.5151 where g rises): not a flutter onset, so a failed attempt.
    hopf_point q = h.point;
    if (o_.parameter_even) q.mu = std::abs(q.mu);
    const auto [below, above] = moving_crossing_sides(f_, s, q, o_);
    flutter_say(log_, "    %s: Re(lambda) %+.3e at (1 - %g) mu*, %+.3e at (1 + %g) mu*\n", label.c_str(), below,
                o_.scan_delta, above, o_.scan_delta);
    if (!(below < 0 && above > 0))
      throw convergence_error(concat(label, ": the Hopf point reached by the frozen-flow secant (mu = ", q.mu,
                                     ", omega = ", q.omega, ") is no flutter onset: Re(lambda) = ", below, " at (1 - ",
                                     o_.scan_delta, ") mu, ", above, " at (1 + ", o_.scan_delta, ") mu"));
    return h;
  }

  /// The equilibrium at mu from w0, the one at mu0: the family's equilibrium_from where it has
  /// one (continuation in mu from a nearby state), else its equilibrium from scratch.
  vec<double> equilibrium_near(const S& s, const vec<double>& w0, double mu0, double mu) const {
    return family_equilibrium_near(f_, s, w0, mu0, mu);
  }

  /// Moving equilibrium, where the branch ends before the listed Mach number m: the lowest
  /// rising zero of g of a V-g scan at m (flutter_boundary_options::scan_from) starts the full
  /// Hopf solve (inverse power at the equilibrium there for the eigenvector). The scan's time is
  /// the point's.
  std::optional<flutter_boundary_point> moving_jump(double m) {
    const auto t0 = clk::now();
    const S s = f_.system(level_, m);
    const std::string label = label_at(m) + " (V-g scan)";
    auto fail = [&](std::string why) -> std::optional<flutter_boundary_point> {
      scan_failure_ = std::move(why);
      flutter_say(log_, "    %s: %s\n", label.c_str(), scan_failure_.c_str());
      record(m, "V-g scan", "failed: " + scan_failure_, flutter_seconds_since(t0));
      rejected_ += flutter_seconds_since(t0);
      return std::nullopt;
    };
    try {
      const std::vector<double> mus = scan_values(pts_.back().mu, o_, o_.scan_to, false);
      const solved_flow& st = flow_at(s, m, mus.front());  // the cost unit; the scan's start if solved there
      const moving_scan_result r = moving_vg_scan(f_, s, mus, o_, true, st.mu == mus.front() ? &st.w : nullptr);
      flutter_say(log_, "    %s: Ubar %.4f .. %.4f: %d inverse powers, %ld GMRES, %zu equilibria, %.2f s%s%s\n",
                  label.c_str(), mus.front(), r.vg.points.empty() ? NAN : r.vg.points.back().mu, r.vg.inverse_powers,
                  r.vg.linear_iterations, r.equilibria.size(), r.seconds, r.vg.complete ? "" : "; ",
                  r.vg.stop_reason.c_str());
      if (!r.lowest)
        return fail(concat("no rising zero of g for Ubar in ", mus.front(), " .. ",
                           r.vg.points.empty() ? NAN : r.vg.points.back().mu,
                           r.vg.complete ? std::string() : " (" + r.vg.stop_reason + ")"));
      const double mu_c = r.lowest->mu, omega_c = r.lowest->frequency;
      auto below = r.equilibria.upper_bound(mu_c);
      if (below != r.equilibria.begin()) --below;
      const vec<double> wc = equilibrium_near(s, below->second, below->first, mu_c);
      eigen_pair ep;
      hopf_point guess = internal::family_hopf_start(f_, s, wc, mu_c, omega_c, start_options(), &ep);
      guess.mu = mu_c;
      flutter_say(log_, "    %s: lowest rising zero of g (mode %d) at mu = %.5f, omega = %.5f; inverse power there: "
                  "lambda = %+.6f %+.6fi\n", label.c_str(), r.lowest->mode, mu_c, omega_c, ep.lambda.real(), ep.lambda.imag());
      const solved_flow sc{m, mu_c, wc, st.seconds, false, false};
      auto p = hopf_at(s, m, sc, guess, label, "V-g scan");
      if (!p) return fail(concat("the Hopf solve from the scan's zero of g at Ubar = ", mu_c, " failed"));
      p->hopf_seconds = flutter_seconds_since(t0);
      return p;
    } catch (const error& e) {
      return fail(e.what());
    }
  }

  void write(flutter_boundary_point p, double cos, bool jump = false) {
    p.hopf_seconds += std::exchange(rejected_, 0.0);
    p.cosine = cos;
    p.jump = jump;
    for (auto& fl : flows_) fl.settled = fl.settled || fl.charged;
    pts_.push_back(p);
    flutter_say(log_,
                "  %-14s M = %.4f  mu* = %.6f  omega* = %.6f  Newton %d  GMRES %5ld  hopf %.2f s  steady %.2f s  (ratio "
                "%.2f)  mode cosine %s\n",
                o_.label.c_str(), p.mach, p.mu, p.omega, p.newton_iterations, p.linear_iterations, p.hopf_seconds,
                p.steady_seconds, p.hopf_seconds / p.steady_seconds,
                std::isfinite(cos) ? flutter_fixed(cos, 3).c_str() : "-");
  }

  /// Newton-Krylov from the two nearest solved flows; empty if it fails. ||f||_2 <= 1e-10: the
  /// free-stream solve ends at 1e-10 .. 3e-8 (NACA 0012 coarse and medium grids); from the
  /// interpolated flow the shock moves in 5-15 damped steps before the quadratic ones.
  vec<double> warm_flow(const S& s, double m, double mu) {
    std::vector<const solved_flow*> near;
    for (const auto& fl : flows_) near.push_back(&fl);
    std::sort(near.begin(), near.end(),
              [&](const solved_flow* a, const solved_flow* e) { return std::abs(a->mach - m) < std::abs(e->mach - m); });
    vec<double> w0 = near[0]->w;
    if (near.size() > 1) w0 += (m - near[0]->mach) / (near[1]->mach - near[0]->mach) * (near[1]->w - near[0]->w);
    const std::string label = o_.label + " steady Newton-Krylov at M = " + flutter_fixed(m, 5);
    try {
      equilibrium_krylov_options eo;
      eo.fill_level = o_.fill_level;
      eo.newton.abs_tolerance = 1e-10;
      eo.newton.max_iterations = 25;
      const auto r = solve_equilibrium_krylov<B>(s, mu, std::move(w0), eo, label);
      flutter_say(log_, "    %s (from M = %.5f%s): %d Newton iterations, %ld GMRES, ||f|| %.2e -> %.2e, %.2f s\n",
                  label.c_str(), near[0]->mach, near.size() > 1 ? (" and " + flutter_fixed(near[1]->mach, 5)).c_str() : "",
                  r.report.iterations, r.linear_iterations, r.report.residual_history.front(), r.report.final_residual(),
                  r.seconds);
      return r.w;
    } catch (const error& e) {
      flutter_say(log_, "    %s failed: %s\n", label.c_str(), e.what());
      return {};
    }
  }

  /// A listed Mach number gets the equilibrium from scratch (the unit of cost) and keeps it; an
  /// intermediate one (a halved step) a Newton-Krylov solve from the neighbouring flows, which is
  /// also the fallback where the solve from scratch fails (e.g. ends on a lifting flow).
  solved_flow& flow_at(const S& s, double m, double mu) {
    for (auto& fl : flows_)
      if (std::abs(fl.mach - m) < 1e-12) return fl;
    const auto t0 = clk::now();
    solved_flow fl{m, mu, {}, 0, false, false};
    if (!flutter_listed(machs_, m) && !flows_.empty()) fl.w = warm_flow(s, m, mu);
    if (fl.w.size() == 0) {
      try {
        fl.w = f_.equilibrium(s, mu);
      } catch (const convergence_error& e) {
        if (flows_.empty()) throw;
        flutter_say(log_, "    M = %.5f: %s\n    -> the equilibrium by Newton-Krylov from the neighbouring Mach numbers\n",
                    m, e.what());
        fl.w = warm_flow(s, m, mu);
        if (fl.w.size() == 0) throw;
      }
    }
    fl.seconds = flutter_seconds_since(t0);  // with the failed attempts, if any
    flows_.push_back(std::move(fl));
    return flows_.back();
  }

  /// charged: an attempt at m was rejected, its flow is lost work. A listed Mach number's steady
  /// solve is never charged: it is the unit of cost of the point written there in the end.
  void set_charged(double m, bool charged) {
    if (flutter_listed(machs_, m)) return;
    for (auto& fl : flows_)
      if (std::abs(fl.mach - m) < 1e-12 && fl.charged != charged) {
        if (!fl.settled) rejected_ += charged ? fl.seconds : -fl.seconds;
        fl.charged = charged;
      }
  }

  const flutter_boundary_point* coarse_at(double m) const {
    if (!coarser_) return nullptr;
    const auto cp = std::find_if(coarser_->points.begin(), coarser_->points.end(),
                                 [&](const flutter_boundary_point& q) { return std::abs(q.mach - m) < 1e-9; });
    return cp == coarser_->points.end() ? nullptr : &*cp;
  }

  /// The coarser boundary's point at m as a start on this level (its mu*, omega*, the
  /// eigenvector prolonged).
  std::optional<hopf_point> coarse_guess(const S& s, double m) const {
    const flutter_boundary_point* cp = coarse_at(m);
    if (!cp) return std::nullopt;
    return prolonged(s, *cp, coarser_->level);
  }
  /// The point cp of level `coarse` (at s's Mach number) as a start on s's level.
  hopf_point prolonged(const S& s, const flutter_boundary_point& cp, int coarse) const {
    hopf_point guess = cp.point;
    guess.p = f_.prolong(s, f_.system(coarse, cp.mach), cp.point.p);
    return guess;
  }

  /// Grid sequencing at a listed Mach number where the start from the previous point failed;
  /// tried once per Mach number (a second call reuses the result at no cost).
  std::optional<flutter_boundary_point> coarse_restart(const S& s, double m, const solved_flow& st,
                                                       const std::string& label) {
    if (const auto it = restarts_.find(m); it != restarts_.end()) {
      if (!it->second) return std::nullopt;
      flutter_boundary_point q = *it->second;
      q.hopf_seconds = 0;  // charged when it was solved
      flutter_say(log_, "    %s: the coarse-grid restart found before: mu* = %.6f, omega* = %.6f\n", label.c_str(), q.mu,
                  q.omega);
      return q;
    }
    const auto t0 = clk::now();
    const std::optional<hopf_point> guess = coarse_guess(s, m);
    if (!guess) return std::nullopt;
    flutter_say(log_, "    %s: restart from the coarse-grid point (mu* = %.6f, omega* = %.6f)\n", label.c_str(), guess->mu,
                guess->omega);
    auto q = hopf_at(s, m, st, *guess, label + " (coarse-grid restart)", "coarse restart");
    if (q) q->hopf_seconds = flutter_seconds_since(t0);
    restarts_[m] = q;
    return q;
  }

  /// Secant and coarse-increment predictor of the start at m from the branch (class comment).
  hopf_point predict(const S& s, double m, const solved_flow& st, const std::string& label) const;

  std::vector<flutter_boundary_point> arclength_bridge(const flutter_boundary_point& from);
  std::optional<flutter_boundary_point> coarser_level_bridge(const flutter_boundary_point& from, double mach);
};

template <flutter_family F>
hopf_point flutter_boundary_tracer<F>::predict(const S& s, double m, const solved_flow& st,
                                               const std::string& label) const {
  hopf_point guess = pts_.back().point;
  // secant in M for mu, omega and the eigenvector, over a base no shorter than a tenth of the
  // step: after an arclength stretch the last two points can lie 4e-5 apart in M, and a secant
  // extrapolated 250 times its base is no predictor
  const double min_base = 0.1 * (m - pts_.back().mach);
  std::optional<std::size_t> i1;
  for (std::size_t i = pts_.size() - 1; i-- > branch_start_;)
    if (pts_.back().mach - pts_[i].mach >= min_base) {
      i1 = i;
      break;
    }
  if (i1) {
    const auto& p1 = pts_[*i1];
    const auto& p2 = pts_.back();
    const double t = (m - p2.mach) / (p2.mach - p1.mach);
    guess.mu = o_.positive_parameter && p1.mu > 0 && p2.mu > 0 ? p2.mu * std::pow(p2.mu / p1.mu, t)
                                                                : p2.mu + t * (p2.mu - p1.mu);
    guess.omega = p2.omega + t * (p2.omega - p1.omega);
    // p1 in the normalisation of p2 (same value at p2's largest component), then the secant
    Eigen::Index k = 0;
    p2.point.p.cwiseAbs().maxCoeff(&k);
    if (std::abs(p1.point.p[k]) > 0) {
      const vec<cplx> q1 = p1.point.p * (p2.point.p[k] / p1.point.p[k]);
      guess.p = p2.point.p + t * (p2.point.p - q1);
    }
  }
  // Coarse-increment predictor (a finer level, where the coarser boundary has points of one mode
  // at both Mach numbers): the previous point plus the coarser boundary's change between them.
  // Transonic boundaries wiggle as shocks cross cells, the same way on both grids (NACA 0012
  // heavy, M 0.87 -> 0.88: coarse -0.513, medium -0.524 in Ubar*), which no secant can follow.
  if (coarser_ && o_.predictor != coarse_predictor::off) {
    const auto c0 = coarse_at(pts_.back().mach), c1 = coarse_at(m);
    if (c0 && c1 && cosine(c0->point, c1->point) >= o_.same_mode_cosine) {
      const flutter_boundary_point& p2 = pts_.back();
      guess.mu = o_.positive_parameter && c0->mu > 0 && c1->mu > 0 ? p2.mu * (c1->mu / c0->mu)
                                                                   : p2.mu + (c1->mu - c0->mu);
      guess.omega = p2.omega + (c1->omega - c0->omega);
      // the eigenvector from the coarser increment: always (full), never (values), or (automatic)
      // where the secant eigenvector's Hopf residual at the predicted mu, omega exceeds the start
      // refinement threshold (one inverse iteration takes the increment's to 3e-4 .. 5e-2, the
      // secant one's to 2e-2 .. 6e-1, measured)
      bool use_increment = o_.predictor == coarse_predictor::full;
      if (o_.predictor == coarse_predictor::automatic) {
        hopf_point h = guess;
        h.w = st.w;
        const hopf_problem<S> pr(s, h, hopf_opts(label + " predictor"), "predictor");
        const double f_secant = pr.residual(pr.start()).norm();
        use_increment = !(f_secant <= o_.krylov.start_residual_threshold);
        if (o_.verbose)
          flutter_say(log_, "    %s: predictor ||F|| %.3e with the secant eigenvector: %s\n", label.c_str(), f_secant,
                      use_increment ? "the coarser increment's instead" : "kept");
      }
      if (use_increment) {
        Eigen::Index kc = 0, k = 0;
        c0->point.p.cwiseAbs().maxCoeff(&kc);
        p2.point.p.cwiseAbs().maxCoeff(&k);
        const S sc = f_.system(coarser_->level, m);
        const vec<cplx> d = c1->point.p * (c0->point.p[kc] / c1->point.p[kc]) - c0->point.p;
        const vec<cplx> q0 = f_.prolong(s, sc, c0->point.p);
        if (std::abs(q0[k]) > 0) guess.p = p2.point.p + (p2.point.p[k] / q0[k]) * f_.prolong(s, sc, d);
      }
    }
  }
  return guess;
}

/// Where natural continuation stops short of the listed Mach number `mach` on a level without a
/// coarser boundary: the boundary is traced from `from` to `mach` on the family's next coarser
/// level (coarser_level(level); a sub-trace with these options, which may bridge again on a
/// still coarser level or hand over to the tracer there), and this level is restarted at `mach`
/// from the coarser point (grid sequencing, as coarse_restart). Accepted if the sub-trace starts
/// on the mode of `from` and ends at `mach`, and the restarted point keeps the mode of the coarser
/// one; the whole work of the sub-trace is charged to the point. Empty (nothing written) otherwise.
template <flutter_family F>
std::optional<flutter_boundary_point> flutter_boundary_tracer<F>::coarser_level_bridge(const flutter_boundary_point& from,
                                                                                      double mach) {
  if constexpr (!requires { f_.coarser_level(level_); }) {
    return std::nullopt;
  } else {
    const std::optional<int> lc = f_.coarser_level(level_);
    if (!lc || !f_.refines(*lc, level_)) return std::nullopt;
    const auto t0 = clk::now();
    const std::string what = concat("bridge on the ", f_.level_name(*lc), " level from M = ", flutter_fixed(from.mach, 5),
                                    " to M = ", flutter_fixed(mach, 4));
    double flow_seconds = 0;  // this level's steady solve at mach: the unit of cost, never charged
    auto fail = [&](const std::string& why) -> std::optional<flutter_boundary_point> {
      flutter_say(log_, "    %s: %s failed: %s\n", o_.label.c_str(), what.c_str(), why.c_str());
      const double spent = flutter_seconds_since(t0) - flow_seconds;
      record(mach, "coarser-level bridge", "failed: " + why, spent);
      rejected_ += spent;
      return std::nullopt;
    };
    flutter_say(log_, "    %s: %s (start: inverse power at mu = %.5f, omega = %.5f)\n", o_.label.c_str(), what.c_str(),
                from.mu, from.omega);
    flutter_boundary_options so = o_;
    so.start_mu = from.mu;
    so.start_omega = from.omega;
    so.check_crossings = false;
    so.label = o_.label + " [" + f_.level_name(*lc) + " bridge]";
    // a user's steady start takes only M, so it is one of this level's states: the sub-trace's
    // tracer gets the family's equilibrium on its own level instead (arclength_bridge)
    so.fixed_equilibrium.equilibrium_start = nullptr;
    const std::vector<double> ms = {from.mach, mach};
    flutter_boundary cb;
    try {
      flutter_boundary_tracer<F> sub(f_, *lc, ms, nullptr, so);
      cb = sub.run();
    } catch (const error& e) {
      return fail(e.what());
    }
    if (!cb.complete || cb.points.empty() || std::abs(cb.points.back().mach - mach) > 1e-9)
      return fail("the coarser boundary does not reach M = " + flutter_fixed(mach, 4) + " (" + cb.stop_reason + ")");
    const double c_start = cosine(cb.points.front().point, from.point);
    if (!(c_start >= o_.same_mode_cosine))
      return fail(concat("its first point is another mode (structural cosine ", c_start, ")"));
    for (std::size_t k = 1; k < cb.points.size(); ++k)
      if (cb.points[k].jump) return fail(concat("it jumps to another mode at M = ", cb.points[k].mach));
    const flutter_boundary_point& c_end = cb.points.back();
    const S s = f_.system(level_, mach);
    const auto t_flow = clk::now();
    const solved_flow& st = flow_at(s, mach, c_end.mu);
    flow_seconds = flutter_seconds_since(t_flow);
    const hopf_point guess = prolonged(s, c_end, *lc);
    const std::string label = label_at(mach) + " (restart from the " + f_.level_name(*lc) + " bridge)";
    auto q = hopf_at(s, mach, st, guess, label, "bridge restart");
    if (!q) return fail("the restart from its point at M = " + flutter_fixed(mach, 4) + " did not converge");
    const double c_end_cos = cosine(q->point, c_end.point);
    if (!(c_end_cos >= o_.same_mode_cosine))
      return fail(concat("the restart converged to another mode (structural cosine ", c_end_cos, " to the coarser point)"));
    q->hopf_seconds = flutter_seconds_since(t0) - flow_seconds;
    record(mach, "coarser-level bridge", concat("accepted: ", cb.points.size(), " points on the coarser level"),
           q->hopf_seconds);
    return q;
  }
}

/// Hand-over where natural continuation stops (a steep stretch where no Mach step lands in
/// Newton's basin: NACA 0012 heavy coarse, M = 0.826-0.828, Ubar* peaks at ~6.1 while omega*
/// moves from 0.20 to 0.41). The fixed-equilibrium tracer follows the curve from `from` up to
/// the first listed Mach number above it that it lands on, or stops earlier where the curve
/// turns back in M by more than fold_tolerance (the boundary is then another mode), retraces
/// itself at a kink, or fails. Returns its points with M > from.mach in M order, the stretch's
/// whole time charged to them.
template <flutter_family F>
std::vector<flutter_boundary_point> flutter_boundary_tracer<F>::arclength_bridge(const flutter_boundary_point& from) {
  hopf_curve_options ho = o_.curve;
  fixed_equilibrium_hopf_curve_options so = o_.fixed_equilibrium;
  ho.nu_min = from.mach - 1e-9;
  ho.nu_max = machs_.back();
  ho.nu_targets.clear();
  for (double m : machs_)
    if (m > from.mach + 1e-9) ho.nu_targets.push_back(m);
  ho.max_points = o_.handover_max_points;
  ho.label = o_.label + " arclength";
  ho.start.newton.abs_tolerance = o_.tolerance;
  ho.newton.abs_tolerance = o_.tolerance;
  ho.throw_on_failure = false;
  ho.verbose = log_ != nullptr;
  if (log_) ho.log = log_;
  if (o_.verbose && log_) ho.newton.observer = newton_progress("      corrector", *log_);
  so.fill_level = o_.fill_level;
  if (!so.equilibrium_start) {
    const F& fam = f_;
    const int lev = level_;
    const double mu0 = from.mu;
    so.equilibrium_start = [&fam, lev, mu0](double mach) { return vec<double>(fam.equilibrium(fam.system(lev, mach), mu0)); };
  }
  double m_hi = from.mach;
  std::vector<flutter_boundary_point> out;
  so.observer = [&](const hopf_curve_point& p, const fixed_equilibrium_hopf_curve_stats& st) {
    if (p.nu <= m_hi + 1e-9) return;  // the start, or a point back in M
    m_hi = p.nu;
    hopf_point q = p.point();
    if (o_.parameter_even) q.mu = std::abs(q.mu);
    flutter_boundary_point bp;
    bp.mach = p.nu;
    bp.mu = q.mu;
    bp.omega = p.omega;
    bp.newton_iterations = p.newton_iterations;
    bp.linear_iterations = st.linear_iterations;
    bp.hopf_seconds = p.seconds;
    bp.steady_seconds = from.steady_seconds;
    bp.point = std::move(q);
    bp.own_steady = false;
    out.push_back(std::move(bp));
  };
  // A fold in M smaller than fold_tolerance is traced through (its points back in M are not
  // boundary points). A RETRACE is different: at a kink the corrector can turn round and follow
  // the curve back (NACA 0012 medium, M = 0.8276: 18 points with M falling by 1e-5 each): stop
  // when a point comes within retrace_distance of the polyline of the trail before its last
  // three points. A genuine fold moves away from it in omega (there: >= 0.7).
  std::vector<Eigen::Vector3d> trail;
  std::string why = "landed";
  ho.stop_after = [&](const hopf_curve_point& p) {
    const Eigen::Vector3d y(std::abs(p.mu) / ho.mu_scale, p.nu / ho.nu_scale, p.omega / ho.omega_scale);
    const std::size_t n_old = trail.size() >= 3 ? trail.size() - 3 : 0;
    double d = n_old > 0 ? (trail[0] - y).norm() : INFINITY;
    for (std::size_t k = 0; k + 1 < n_old; ++k) {
      const Eigen::Vector3d a = trail[k], e = trail[k + 1] - a;
      const double t = e.squaredNorm() > 0 ? std::clamp((y - a).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
      d = std::min(d, (a + t * e - y).norm());
    }
    trail.push_back(y);
    if (d < o_.retrace_distance) {
      why = "retrace: the trace turned back along the curve at a kink";
      return true;
    }
    if (p.nu < m_hi - o_.fold_tolerance) {
      why = "the curve turns back in M by more than " + flutter_fixed(o_.fold_tolerance, 3);
      return true;
    }
    return p.landed && p.nu > from.mach + 1e-9;
  };
  const F& fam = f_;
  const int lev = level_;
  auto family = [&fam, lev](double mach) { return fam.system(lev, mach); };
  flutter_say(log_,
              "    hand-over to pseudo-arclength continuation of the Hopf curve from M = %.5f (mu* = %.5f, omega* = "
              "%.5f) up to the next listed Mach number\n",
              from.mach, from.mu, from.omega);
  fixed_equilibrium_hopf_curve_result r;
  const auto t_bridge = clk::now();
  // the stretch's time not in its points' own steps (the re-solved start, points back in M, the
  // step past the landed Mach number) goes to its last point
  auto charge_rest = [&] {
    if (out.empty()) return;
    double own = 0;
    for (const auto& q : out) own += q.hopf_seconds;
    out.back().hopf_seconds += std::max(0.0, flutter_seconds_since(t_bridge) - own);
  };
  try {
    r = trace_fixed_equilibrium_hopf_curve<B>(family, from.mach, from.point, ho, +1, so);
  } catch (const error& e) {  // e.g. the start's nested steady solve: keep what was traced
    flutter_say(log_, "    arclength failed: %s\n", e.what());
    charge_rest();
    record(from.mach, "arclength", std::string("failed: ") + e.what(), flutter_seconds_since(t_bridge));
    return out;
  }
  charge_rest();
  long gmres_hopf = 0, gmres_steady = 0;
  for (const auto& st : r.stats) {
    gmres_hopf += st.linear_iterations;
    gmres_steady += st.steady_linear_iterations;
  }
  const std::string stop = r.stop == hopf_curve_stop::requested ? why : r.stop_reason;
  flutter_say(log_,
              "    arclength (%s corrector): %zu points (%zu beyond M = %.5f), %d failed correctors, %d steps at fixed M "
              "or mu, %d nested steady solves, %d flow Newton steps (%.2f s with dw0/dnu), GMRES %ld Hopf + %ld "
              "steady and dw0/dnu, %.2f s; stop: %s\n",
              so.joint_equilibrium ? "joint" : "nested", r.points.size(), out.size(), from.mach, r.failed_correctors,
              r.kink_steps, r.steady_solves, r.steady_iterations, r.steady_seconds, gmres_hopf, gmres_steady, r.seconds,
              stop.c_str());
  record(from.mach, "arclength", std::to_string(out.size()) + " points; stop: " + stop, flutter_seconds_since(t_bridge));
  return out;
}

template <flutter_family F>
flutter_boundary flutter_boundary_tracer<F>::run() {
  const std::vector<double>& machs = machs_;
  for (double mach : machs) {
    const double m_done = pts_.empty() ? mach : pts_.back().mach;
    const double full_step = mach - m_done;
    double step = full_step;
    // the other mode's points found in this search (falling steps, so falling M), and the
    // structural cosine of the last one to the branch's last point
    std::vector<flutter_boundary_point> others;
    double other_cosine = NAN;
    while (pts_.empty() || pts_.back().mach < mach - 1e-9) {
      if (!pts_.empty()) step = std::min(step, mach - pts_.back().mach);
      const double m = pts_.empty() || step >= mach - pts_.back().mach ? mach : pts_.back().mach + step;
      const S s = f_.system(level_, m);
      const solved_flow* stp = nullptr;
      try {
        stp = &flow_at(s, m, pts_.empty() ? o_.start_mu : pts_.back().mu);
      } catch (const error& e) {  // no equilibrium at m: a failed attempt, as a failed Hopf solve
        if (pts_.empty()) throw;
        flutter_say(log_, "    %s: no equilibrium: %s\n", label_at(m).c_str(), e.what());
        record(m, "equilibrium", std::string("failed: ") + e.what(), 0.0);
        if (step < full_step / o_.min_step_divisor + 1e-12) {
          b_.stop_reason = "no equilibrium at M = " + flutter_fixed(m, 5) + ": " + e.what();
          return std::move(b_);
        }
        step *= 0.5;
        continue;
      }
      const solved_flow& st = *stp;
      hopf_point guess;
      const std::string label = label_at(m);
      const auto t0 = clk::now();
      // Coarse-guided restart: at the first attempt of a listed step across which the coarser
      // boundary changes mode AND its branch ends within 1/4 of the step, the coarse-grid
      // restart is solved at once (NACA 0012 heavy medium M = 0.90 -> 0.91: the start from the
      // previous point took 7 Newton iterations to reach the other mode, the restart 3).
      bool preempted = false;
      if (o_.coarse_guided_restart && o_.coarse_restart && coarser_ && !pts_.empty() && std::abs(m - mach) < 1e-12 &&
          std::abs(pts_.back().mach - m_done) < 1e-12 && flutter_listed(machs, m)) {
        const flutter_boundary_point* c0 = coarse_at(m_done);
        const flutter_boundary_point* c1 = coarse_at(m);
        if (c0 && c1 && cosine(c0->point, c1->point) < o_.same_mode_cosine) {
          double m_end = m_done;  // the coarser boundary's last point of c0's mode before m
          for (const auto& q : coarser_->points)
            if (q.mach > m_done + 1e-9 && q.mach < m - 1e-9 && cosine(c0->point, q.point) >= o_.same_mode_cosine)
              m_end = std::max(m_end, q.mach);
          preempted = m_end - m_done < 0.25 * full_step + 1e-12;
          if (preempted)
            flutter_say(log_,
                        "    %s: the coarser boundary's branch ends at M = %.5f and it changes mode before M = %.4f: "
                        "restart from its point first\n",
                        label.c_str(), m_end, m);
        }
      }
      const char* kind = "continued";
      bool from_start_point = false;
      if (preempted) {
        // the coarse-grid restart below is this attempt
      } else if (!pts_.empty()) {
        guess = predict(s, m, st, label);
      } else if (o_.start_point) {  // continuation in a structural parameter on this level
        require(o_.start_point->p.size() == s.size(), o_.label, ": start_point.p has size ", o_.start_point->p.size(),
                " but the level's system has ", s.size(), " unknowns");
        guess = *o_.start_point;
        flutter_say(log_, "    %s: Newton from the given point (mu = %.6g, omega = %.6g)\n", label.c_str(), guess.mu,
                    guess.omega);
        kind = "start point";
        from_start_point = true;
      } else if (coarser_) {  // grid sequencing from the coarser boundary at this Mach number
        auto cg = coarse_guess(s, m);
        require(cg.has_value(), o_.label, ": no coarse-grid point at M = ", m, " to start this level from");
        guess = std::move(*cg);
        kind = "first";
      } else {
        eigen_pair ep;
        const auto ts = clk::now();
        guess = internal::family_hopf_start(f_, s, st.w, o_.start_mu, o_.start_omega, start_options(), &ep);
        flutter_say(log_, "    inverse power (BILU(%d)-GMRES): lambda = %+.6f %+.6fi, %d iterations, %ld GMRES, %.2f s\n",
                    o_.fill_level, ep.lambda.real(), ep.lambda.imag(), ep.iterations, ep.linear_iterations,
                    flutter_seconds_since(ts));
        guess.mu = o_.start_mu;
        kind = "first";
      }
      const double start_seconds = flutter_seconds_since(t0);
      auto p = preempted ? std::nullopt : hopf_at(s, m, st, guess, label, kind, from_start_point);
      auto t_attempt = t0;  // start of the attempt whose time a failure charges to rejected_
      if (p) p->hopf_seconds += start_seconds;
      const bool restarted = !p && o_.coarse_restart && coarser_ && !pts_.empty() && flutter_listed(machs, m);
      if (restarted) {
        set_charged(m, true);
        rejected_ += flutter_seconds_since(t0);
        t_attempt = clk::now();
        p = coarse_restart(s, m, st, label);
      }
      double cos = NAN;
      if (p && !pts_.empty()) cos = cosine(pts_.back().point, p->point);
      if (!p) {
        set_charged(m, true);
        rejected_ += flutter_seconds_since(t_attempt);
      }
      if (p && pts_.size() > branch_start_ && cos < o_.same_mode_cosine) {
        set_charged(m, true);
        rejected_ += p->hopf_seconds;  // taken back if it becomes the jump point
        flutter_say(log_,
                    "    %s: Hopf point mu* = %.4f, omega* = %.4f belongs to another mode (structural cosine %.3f to "
                    "the point at M = %.4f)\n",
                    label.c_str(), p->mu, p->omega, cos, pts_.back().mach);
        b_.attempts.back().outcome = "other mode";
        others.push_back(std::move(*p));
        other_cosine = cos;
        p.reset();
      }
      if (p) {
        set_charged(m, false);
        b_.attempts.back().outcome = "accepted";
        write(*p, cos);
        others.clear();  // this branch goes on: the other mode's points above it are not boundary points
        step = std::min(2.0 * step, full_step);
        continue;
      }
      if (pts_.empty())
        throw convergence_error(concat(o_.label, ": no Hopf point at the first Mach number ", m));
      if (step < full_step / o_.min_step_divisor + 1e-12) {
        if (!others.empty()) {
          flutter_say(log_,
                      "    %s: the branch continued from M = %.4f ends before M = %.4f (no Hopf point of its mode "
                      "within 1/%d of the Mach step); the boundary jumps to the other mode's Hopf point found there\n",
                      label.c_str(), pts_.back().mach, others.back().mach, o_.min_step_divisor);
          branch_start_ = pts_.size();
          // the other mode's points found at the larger steps lie on the new branch up to this
          // listed Mach number: kept (not solved again) while each continues the branch
          std::vector<std::pair<const flutter_boundary_point*, double>> kept = {{&others.back(), other_cosine}};
          for (auto q = std::next(others.rbegin()); q != others.rend(); ++q) {
            const flutter_boundary_point& last = *kept.back().first;
            const double cq = cosine(last.point, q->point);
            if (q->mach <= last.mach + 1e-9 || cq < o_.same_mode_cosine) break;
            kept.emplace_back(&*q, cq);
          }
          for (const auto& [q, cq] : kept) {
            rejected_ -= q->hopf_seconds;
            set_charged(q->mach, false);
          }
          bool first = true;
          for (const auto& [q, cq] : kept) {
            write(*q, cq, first);
            first = false;
          }
          others.clear();
          step = std::min(2.0 * step, full_step);
          continue;
        }
        flutter_say(log_, "    %s: no convergence from M = %.4f even with 1/%d of the Mach step\n", label.c_str(),
                    pts_.back().mach, o_.min_step_divisor);
        const double m_before = pts_.back().mach;
        if (o_.moving_equilibrium) {  // the tracer assumes a fixed equilibrium: the V-g scan at the listed Mach number
          if (auto q = moving_jump(mach)) {
            const double cq = cosine(pts_.back().point, q->point);
            branch_start_ = pts_.size();
            write(*q, cq, true);
            step = full_step;
            continue;
          }
          // no point at this listed Mach number: on to the next one (from the same last point)
          flutter_say(log_, "    %s: no flutter point (%s); on to the next listed Mach number\n",
                      label_at(mach).c_str(), scan_failure_.c_str());
          b_.skipped.emplace_back(mach, scan_failure_);
          break;
        }
        std::optional<flutter_boundary_point> bridged;
        if (o_.coarser_level_bridge && !coarser_) bridged = coarser_level_bridge(pts_.back(), mach);
        if (bridged) {
          // no secant across the stretch (the mode turns within it): the next start is this point
          const double cb = cosine(pts_.back().point, bridged->point);
          branch_start_ = pts_.size();
          write(*bridged, cb);
        } else if (o_.handover) {
          for (auto& q : arclength_bridge(pts_.back())) {
            const double cq = cosine(pts_.back().point, q.point);
            write(q, cq);
          }
        }
        if (pts_.back().mach <= m_before + 1e-9) {
          flutter_say(log_, "    the boundary is not continued past M = %.5f (natural and arclength continuation failed)\n",
                      m_before);
          b_.stop_reason = "not continued past M = " + flutter_fixed(m_before, 5) +
                           " (natural continuation down to 1/" + std::to_string(o_.min_step_divisor) +
                           " of the step and the arclength hand-over failed)";
          return std::move(b_);
        }
        step = full_step;  // natural continuation resumes from the stretch's last point
        continue;
      }
      // Jump search from the bottom: where the start from the previous point CONVERGED to the
      // other mode at the full listed step, the branch has most likely ended just past its last
      // point, so the smallest step is tried first (NACA 0012: the branch ended within 1/8 of
      // the step at two of the three such jumps). Where the start FAILED, the step is halved.
      if (o_.jump_search_bottom && (!restarted || preempted) && !others.empty() &&
          std::abs(others.back().mach - m) < 1e-12 && step > 0.5 * full_step) {
        step = full_step / o_.min_step_divisor;
        flutter_say(log_, "    the other mode at the full step: retrying with the smallest Mach step %g\n", step);
        continue;
      }
      step *= 0.5;
      flutter_say(log_, "    retrying with Mach step %g\n", step);
    }
  }
  b_.complete = true;
  if (!b_.skipped.empty()) {
    b_.stop_reason = "no point at M =";
    for (const auto& [m, why] : b_.skipped) b_.stop_reason += " " + flutter_fixed(m, 4) + " (" + why + ")";
  }
  return std::move(b_);
}

}  // namespace internal

/// The crossing check of one boundary point: every imaginary-axis crossing of A0 + q(mu) B
/// (axis_crossings.hpp) with omega in [omega_min, factor omega*]; PASS iff the lowest one in mu
/// (the aerofoil's speed, largest q = 1/mu^2; the wing's density, q = mu) above
/// crossing_min_fraction mu* is the point itself. Needs the equilibrium independent of mu.
template <flutter_family F>
crossing_check_record check_flutter_crossing(const F& family, int level, const flutter_boundary_point& p,
                                             const std::string& what, const flutter_boundary_options& o) {
  const auto s = family.system(level, p.mach);
  const vec<double>& w0 = p.point.w;
  const double u1 = p.mu, u2 = 0.5 * p.mu;
  const int ns = static_cast<int>(s.structure_size());
  const affine_split sp = split_affine(s.jacobian(w0, u1), family.stiffness_factor(u1), s.jacobian(w0, u2),
                                       family.stiffness_factor(u2), ns, o.label + " crossing check");
  axis_crossing_options ao;
  ao.omega_min = o.crossing_omega_min;
  ao.omega_max = o.crossing_omega_factor * p.omega;
  ao.samples = std::max(100, static_cast<int>(std::ceil((ao.omega_max - ao.omega_min) / 0.02)));
  ao.context = o.label + " crossing check";
  const axis_crossing_result r = imaginary_axis_crossings(sp, ao);
  crossing_check_record c;
  c.mach = p.mach;
  c.mu = p.mu;
  c.omega = p.omega;
  c.what = what;
  c.crossings = r.crossings.size();
  const axis_crossing* lowest = nullptr;
  for (const auto& x : r.crossings) {
    if (!(x.q > 0)) continue;
    const double u = family.parameter_of_factor(x.q);
    c.all.emplace_back(u, x.omega);
    if (u >= o.crossing_min_fraction * p.mu && (!lowest || u < c.lowest_mu)) {  // lowest in mu, not in q
      lowest = &x;
      c.lowest_mu = u;
    }
  }
  c.lowest_omega = lowest ? lowest->omega : NAN;
  c.pass = lowest && std::abs(c.lowest_mu - p.mu) <= o.crossing_mu_tolerance * p.mu &&
           std::abs(c.lowest_omega - p.omega) <= o.crossing_omega_tolerance;
  return c;
}

/// The crossing check of one boundary point of a moving equilibrium: a V-g scan
/// (internal::moving_vg_scan) up to (1 - scan_delta) mu* and one value above, (1 + scan_delta)
/// mu*, the equilibrium continued from the point's, stopped after the first rising zero of g;
/// PASS iff that lowest zero lies between the last two values (flutter_boundary_options::scan_from).
template <flutter_family F>
crossing_check_record check_flutter_crossing_scan(const F& family, int level, const flutter_boundary_point& p,
                                                  const std::string& what, const flutter_boundary_options& o) {
  const auto s = family.system(level, p.mach);
  const std::vector<double> mus = internal::scan_values(p.mu, o, 1.0, true);
  const internal::moving_scan_result r = internal::moving_vg_scan(family, s, mus, o, true);
  crossing_check_record c;
  c.mach = p.mach;
  c.mu = p.mu;
  c.omega = p.omega;
  c.what = what;
  c.crossings = r.vg.flutter.size();
  for (const auto& x : r.vg.flutter) c.all.emplace_back(x.mu, x.frequency);
  if (r.lowest) {
    c.lowest_mu = r.lowest->mu;
    c.lowest_omega = r.lowest->frequency;
  }
  c.pass = r.lowest && c.lowest_mu >= mus[mus.size() - 2] && c.lowest_mu <= mus.back() &&
           std::abs(c.lowest_omega - p.omega) <= o.scan_step * p.omega;
  return c;
}

/// The points of a boundary whose lowest-crossing property is checked: the jumps (marked so, or
/// structural cosine below same_mode_cosine to the previous point), the first point past a
/// skipped Mach number (continued across a Mach number without flutter, the branch it lands on
/// need not be the lowest one) and the last point.
template <flutter_family F>
std::vector<std::pair<std::size_t, const char*>> flutter_check_points(const F& family, const flutter_boundary& b,
                                                                      double same_mode_cosine = 0.9) {
  std::vector<std::pair<std::size_t, const char*>> at;
  const auto& p = b.points;
  for (std::size_t k = 1; k < p.size(); ++k) {
    const bool across_skip = std::any_of(b.skipped.begin(), b.skipped.end(), [&](const auto& s) {
      return s.first > p[k - 1].mach && s.first < p[k].mach;
    });
    if (p[k].jump || structural_cosine(family, p[k - 1].point.p, p[k].point.p) < same_mode_cosine)
      at.emplace_back(k, "jump");
    else if (across_skip)
      at.emplace_back(k, "past a skipped Mach number");
  }
  if (!p.empty() && (at.empty() || at.back().first != p.size() - 1)) at.emplace_back(p.size() - 1, "last point");
  return at;
}

/// The flutter boundary of `family` on `level` at the listed Mach numbers (file comment).
/// coarser: the boundary of a coarser level that family.refines(coarser->level, level), for grid
/// sequencing (nullptr: none). Throws convergence_error if there is no Hopf point at the first
/// Mach number; otherwise returns what it reached (complete, stop_reason) with the crossing
/// checks of every jump and of the last point when opt.check_crossings.
template <flutter_family F>
flutter_boundary trace_flutter_boundary(const F& family, int level, const std::vector<double>& machs,
                                        const flutter_boundary* coarser = nullptr,
                                        const flutter_boundary_options& opt = {}) {
  internal::check_flutter_boundary_options(opt, machs, opt.label);
  if (coarser && !family.refines(coarser->level, level)) coarser = nullptr;
  internal::flutter_boundary_tracer<F> t(family, level, machs, coarser, opt);
  flutter_boundary b = t.run();
  if (opt.check_crossings)
    for (const auto& [k, what] : flutter_check_points(family, b, opt.same_mode_cosine)) {
      const auto t0 = std::chrono::steady_clock::now();
      crossing_check_record c;
      try {
        c = opt.moving_equilibrium ? check_flutter_crossing_scan(family, level, b.points[k], what, opt)
                                   : check_flutter_crossing(family, level, b.points[k], what, opt);
      } catch (const error& e) {  // a check that cannot be made fails
        c.mach = b.points[k].mach;
        c.mu = b.points[k].mu;
        c.omega = b.points[k].omega;
        c.what = std::string(what) + " (check failed: " + e.what() + ")";
      }
      internal::flutter_say(opt.log,
                            "    crossing check M = %.4f (%s)  mu* = %.5f omega* = %.4f: %zu crossings, lowest mu = %.5f at "
                            "omega = %.4f -> %s  (%.1f s)\n",
                            c.mach, c.what.c_str(), c.mu, c.omega, c.crossings, c.lowest_mu, c.lowest_omega,
                            c.pass ? "lowest crossing (PASS)" : "FAIL", internal::flutter_seconds_since(t0));
      b.checks.push_back(std::move(c));
    }
  return b;
}

/// Cost per unit steady solve of a boundary (pure function of its points): the first point (with
/// the inverse-power start) is left out of hopf_per_steady.
inline flutter_boundary_costs boundary_costs(const flutter_boundary& b, const std::vector<double>& listed) {
  flutter_boundary_costs c;
  double hopf = 0, st = 0, extra = 0;
  for (std::size_t k = 0; k < b.points.size(); ++k) {
    const auto& q = b.points[k];
    c.work_seconds += q.hopf_seconds + (q.own_steady ? q.steady_seconds : 0.0);
    if (k == 0) continue;
    hopf += q.hopf_seconds;
    st += q.steady_seconds;
    if (internal::flutter_listed(listed, q.mach)) {
      c.listed_steady_seconds += q.steady_seconds;
      ++c.listed;
    } else if (q.own_steady) {
      extra += q.steady_seconds;  // a steady solve at an intermediate Mach number
    }
  }
  c.continued = b.points.size() > 0 ? b.points.size() - 1 : 0;
  c.beyond_steady_seconds = hopf + extra;
  if (c.continued > 0) c.hopf_per_steady = hopf / st;
  if (c.listed > 0) c.hopf_per_steady_listed = c.beyond_steady_seconds / c.listed_steady_seconds;
  return c;
}

/// The same per listed steady solve of `fine`, with the coarser boundary's whole work charged.
inline double boundary_cost_with_coarser(const flutter_boundary& fine, const flutter_boundary& coarse,
                                         const std::vector<double>& listed) {
  const flutter_boundary_costs f = boundary_costs(fine, listed);
  return (f.beyond_steady_seconds + boundary_costs(coarse, listed).work_seconds) / f.listed_steady_seconds;
}

}  // namespace aerohopf
