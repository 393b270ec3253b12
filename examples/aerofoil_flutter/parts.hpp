#pragma once
// The verification and output parts of aerofoil_flutter (main.cpp holds the options and the
// boundaries): the very coarse dense spectra at the flutter point, the V-g / V-f diagram, the
// jump check by dense spectra, time marching at straddling points, and the centre-manifold
// reduced model. Each part is library calls and output.
#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/inverse_power.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>
#include <aerohopf/models/aerofoil_family.hpp>
#include <aerohopf/periodic.hpp>
#include <aerohopf/reduction.hpp>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/time/bdf2.hpp>
#include <aerohopf/time/eigenmode_march.hpp>
#include <aerohopf/time/history.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "../common/cli.hpp"
#include "setup.hpp"

namespace aerofoil_example {

using namespace aerohopf;
using namespace aerohopf::flow;
using cplx = std::complex<double>;

struct options {
  std::filesystem::path out = "out/aerofoil_flutter";
  std::vector<structural_case> cases{light_case, heavy_case};
  std::vector<grid_level> grids{level_named("coarse"), level_named("medium")};
  double mach_min = 0.5, mach_max = 0.95, mach_step = 0;
  double incidence_deg = 0;  // mean angle of attack: a moving (static aeroelastic) equilibrium
  int fill = flutter_boundary_options{}.fill_level;
  double contact_smoothing = 0.05;  // of the reduced model's discretisation (osher_flux.hpp)
  bool spectra = true, boundaries = true, jump_check = true, verify = true, reduced = true, quick = false;
  bool lco_march = false;  // BDF2 to the limit cycle against the harmonic-balance cycles
  bool vg = true;
  double vg_mach = 0.80;  // transonic (shocks on both surfaces), as the reduced model
  std::optional<grid_level> vg_grid;  // default: the first of grids
  double vg_from = 0.5, vg_to = 1.4;  // Ubar range of the diagrams, in Ubar*
  // 40 values: steps of 0.023 Ubar*, none of them Ubar* itself, so that the g = 0 crossing is a
  // genuine interpolation (the cubic's error at this step: ~1e-4 relative, test_vg_diagram.cpp)
  int vg_points = 40;
  std::string vg_solver = "auto";  // lu | krylov | auto (LU up to the coarse grid)
  bool crossing_medium = false;  // the crossing check on the medium grid too (~1 s per LU)
  bool crossing_check = true;    // the driver's check of the jumps and last points
  bool verbose = false;
  grid_level verify_grid = level_named("medium");
};

using boundaries = std::map<std::string, flutter_boundary>;  // by "<case>_<grid>"

/// The options both boundary programs read (aerofoil_flutter, aerofoil_flutter_mpi): --case,
/// --grids, --mach-min, --mach-max, --mach-step, --incidence, --verbose and the output folder
/// (a word without a leading '-'); true if `a` was one of them (its value read from args).
inline bool read_boundary_option(const std::string& a, example_cli::arguments& args, options& o) {
  if (a == "--case") {
    const std::string v = args.value();
    o.cases = v == "both" ? std::vector<structural_case>{light_case, heavy_case} : std::vector{case_named(v)};
  } else if (a == "--grids") {
    o.grids.clear();
    for (const auto& w : args.words()) o.grids.push_back(level_named(w));
  } else if (a == "--mach-min") {
    o.mach_min = args.number();
  } else if (a == "--mach-max") {
    o.mach_max = args.number();
  } else if (a == "--mach-step") {
    o.mach_step = args.number();
    require(o.mach_step > 0, "--mach-step must be > 0");
  } else if (a == "--incidence") {
    o.incidence_deg = args.number();
    require(std::abs(o.incidence_deg) < 10, "--incidence: a mean angle of attack in degrees, |alpha| < 10 (got ",
            o.incidence_deg, ")");
  } else if (a == "--verbose") {
    o.verbose = true;
  } else if (!a.empty() && a[0] != '-') {
    o.out = a;
  } else {
    return false;
  }
  return true;
}

/// The Mach range read: 0 < mach_min <= mach_max < 1.
inline void check_mach_range(const options& o) {
  require(o.mach_min > 0 && o.mach_max >= o.mach_min && o.mach_max < 1, "need 0 < --mach-min <= --mach-max < 1 (got ",
          o.mach_min, ", ", o.mach_max, ")");
}

/// The listed Mach numbers: 0.50 .. 0.80 step 0.05, 0.81 .. 0.95 step 0.01 (spec 05), within
/// [mach_min, mach_max]; or one uniform step.
inline std::vector<double> mach_list(const options& o) {
  std::vector<double> m;
  if (o.mach_step > 0) {
    for (int k = 0;; ++k) {
      const double x = o.mach_min + k * o.mach_step;
      if (x > o.mach_max + 1e-9) break;
      m.push_back(std::round(x * 1e4) / 1e4);
    }
    return m;
  }
  for (int k = 0; k <= 6; ++k) m.push_back(0.5 + 0.05 * k);
  for (int k = 1; k <= 15; ++k) m.push_back(0.80 + 0.01 * k);
  std::vector<double> r;
  for (double x : m)
    if (x >= o.mach_min - 1e-9 && x <= o.mach_max + 1e-9) r.push_back(std::round(x * 1e4) / 1e4);
  return r;
}

/// The inverse-power start of the single points (as the boundary driver's first point).
inline hopf_start_krylov_options start_options(const options& o) {
  hopf_start_krylov_options so;
  so.fill_level = o.fill;
  so.krylov.restart = flutter_boundary_options{}.start_restart;
  return so;
}

/// Hopf options of the single points (very coarse check, V-g fallback, reduced model): ||F|| <= 1e-10.
inline hopf_options point_options(const options& o, const std::string& label) {
  hopf_options ho;
  ho.fixed_equilibrium = true;
  ho.label = label;
  ho.newton.abs_tolerance = 1e-10;
  ho.newton.max_iterations = 20;
  ho.verbose = o.verbose;
  return ho;
}

/// One Hopf point from the inverse-power start at the case's guess.
inline std::optional<flutter_boundary_point> single_hopf_point(const options& o, const aerofoil_system& s,
                                                               const steady_result& st, const structural_case& c,
                                                               const std::string& label) {
  hopf_point guess = hopf_start_krylov<4>(s, st.w, c.ubar_guess, c.omega_guess, start_options(o));
  guess.mu = c.ubar_guess;
  guess.w = st.w;
  hopf_krylov_options ko;
  ko.fill_level = o.fill;
  try {
    hopf_result h = solve_hopf_krylov<4>(s, guess, point_options(o, label), ko);
    flutter_boundary_point p;
    p.mach = s.flow().conditions().mach;
    p.mu = std::abs(h.point.mu);
    p.omega = h.point.omega;
    p.point = h.point;
    p.point.mu = p.mu;
    return p;
  } catch (const error& e) {
    std::cout << "    " << label << " failed: " << e.what() << "\n";
    return std::nullopt;
  }
}

/// The driver's options: the family's (aerofoil_family::boundary_options) with the case's start
/// guess and the user's choices.
inline flutter_boundary_options driver_options(const options& o, const structural_case& c, const grid_level& g,
                                               const models::aerofoil_family& family) {
  flutter_boundary_options fo = family.boundary_options();
  fo.start_mu = c.ubar_guess;
  fo.start_omega = c.omega_guess;
  fo.fill_level = o.fill;
  fo.verbose = o.verbose;
  fo.label = c.name + " " + g.name;
  // the crossing check factorises i omega I - A_ff at every sampled frequency: ~1 s per LU on
  // the medium grid, so there only with --crossing-medium; at an incidence it is a V-g scan
  // (inverse powers by sparse LU up to 20,000 unknowns), on every grid
  fo.check_crossings = o.crossing_check && (g.stride >= 4 || (g.stride == 2 && o.crossing_medium) ||
                                            family.alpha() != 0.0);
  return fo;
}

/// boundary_<case>_<grid>.csv (at an incidence boundary_<case>_<grid>_alpha<DEG>.csv with the
/// static pitch deflection) of boundary b.
inline void write_boundary(const options& o, const structural_case& c, const grid_level& g, const flutter_boundary& b) {
  const bool moving = o.incidence_deg != 0.0;
  char tag[64] = "";
  if (moving) std::snprintf(tag, sizeof tag, "_alpha%g", o.incidence_deg);
  csv_writer csv(o.out / ("boundary_" + c.name + "_" + g.name + tag + ".csv"),
                 std::string("mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds") +
                     (moving ? ",static_alpha" : ""));
  for (const auto& p : b.points) {
    // the pitch unknown of the equilibrium at the flutter point (h, h', alpha, alpha' last)
    const double static_alpha = p.point.w[p.point.w.size() - 2];
    if (moving)
      csv.row({p.mach, p.mu, p.omega, static_cast<long long>(p.newton_iterations),
               static_cast<long long>(p.linear_iterations), p.hopf_seconds, p.steady_seconds, static_alpha});
    else
      csv.row({p.mach, p.mu, p.omega, static_cast<long long>(p.newton_iterations),
               static_cast<long long>(p.linear_iterations), p.hopf_seconds, p.steady_seconds});
  }
}

/// The boundary of case c on grid g (main.cpp), from the coarser grid's if given.
flutter_boundary boundary_on(const options& o, const structural_case& c, const grid_level& g,
                             const flutter_boundary* coarser);

// ---------------------------------------------------------------------------------------------
// Part 1: very coarse grid, light case, M = 0.5: Hopf point and the dense spectra around it.

inline void spectra_part(const options& o) {
  std::cout << "\n=== very coarse grid, light case, M = 0.5: flutter point and dense spectra ===\n";
  const auto s = make_system(level_named("very_coarse"), 0.5, light_case.mu_s);
  const auto st = steady(s);
  hopf_options ho = point_options(o, "hopf very coarse");
  ho.verbose = true;
  const hopf_result h = solve_hopf_krylov<4>(s, hopf_start_krylov<4>(s, st.w, light_case.ubar_guess, light_case.omega_guess, start_options(o)), ho);
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
// Part 2a: V-g / V-f diagrams at one Mach number (bifurcation/vg_diagram.hpp): damping
// g = 2 Re/|Im| and frequency of the plunge and pitch modes against Ubar, traced from the
// in-vacuo modes at the lowest Ubar by shift-invert inverse power and tracked by the structural
// part of the eigenvector; g = 0 from below is the flutter point, checked against the Hopf point.

inline void vg_part(const options& o, const boundaries& all) {
  const grid_level g = o.vg_grid ? *o.vg_grid : o.grids.front();
  for (const auto& c : o.cases) {
    std::cout << "\n=== V-g / V-f diagram: " << c.name << " case, " << g.name << " grid, M = " << fixed(o.vg_mach, 2)
              << " ===\n";
    try {
      const auto t0 = clk::now();
      const auto family = family_of(c, o.incidence_deg * std::numbers::pi / 180);
      const auto s = family.system(g.stride, o.vg_mach);
      // the Hopf point of this run's boundary at vg_mach, else one Hopf solve from the inverse-power start
      std::optional<flutter_boundary_point> hp;
      if (const auto it = all.find(c.name + "_" + g.name); it != all.end())
        for (const auto& q : it->second.points)
          if (std::abs(q.mach - o.vg_mach) < 1e-9) hp = q;
      require(hp.has_value() || family.fixed_equilibrium(), "no boundary point at M = ", o.vg_mach,
              " at this incidence (the V-g diagram's range is set by it)");
      const steady_result st = family.fixed_equilibrium() ? steady(s) : steady_result{};
      if (!hp) hp = single_hopf_point(o, s, st, c, c.name + " " + g.name + " V-g Hopf point");
      require(hp.has_value(), "no Hopf point at M = ", o.vg_mach, " to set the Ubar range");
      std::vector<double> ubars;
      for (int k = 0; k < o.vg_points; ++k)
        ubars.push_back(hp->mu * (o.vg_from + (o.vg_to - o.vg_from) * k / std::max(1, o.vg_points - 1)));
      vg_options vo;
      vo.tracked_offset = s.flow_size();  // the structural unknowns (h, h', alpha, alpha')
      vo.tracked_size = aerofoil_system::n_structure;
      vo.inverse_power.tolerance = 1e-10;
      const auto starts = vg_mode_starts(s.structure().in_vacuo_matrix(ubars.front()));  // plunge, pitch
      // symmetric section at zero incidence: one flow for every Ubar; else the static aeroelastic
      // equilibrium at each Ubar (the root locus then includes the aerostatic deflection)
      const auto equilibrium = [&](double ubar) {
        return family.fixed_equilibrium() ? st.w : family.static_equilibrium(s, ubar, o.fill);
      };
      vg_result r;
      const bool lu = o.vg_solver == "lu" || (o.vg_solver == "auto" && g.stride >= 4);
      if (lu) {  // sparse LU of A - sigma I
        r = vg_diagram(s, equilibrium, ubars, starts, vo);
      } else {  // GMRES on the exact A - sigma I, BILU(k) of the modified-order L - sigma I
        vo.inverse_power.tolerance = 1e-9;  // inexact inverse iteration: GMRES below it (inverse_power.hpp)
        vg_krylov_options ko;
        ko.fill_level = o.fill;
        r = vg_diagram(s, equilibrium, ubars, starts, vo, vg_krylov_solvers<4>(s, ko));
      }
      const std::string tag = c.name + "_" + g.name + "_M" + fixed(o.vg_mach, 2);
      csv_writer csv(o.out / ("vg_" + tag + ".csv"), "mode,parameter,damping_g,frequency,re,im");
      for (const auto& p : r.points)
        csv.row({static_cast<long long>(p.mode), p.mu, p.damping, p.frequency, p.lambda.real(), p.lambda.imag()});
      csv_writer fc(o.out / ("vg_flutter_" + tag + ".csv"), "mode,parameter,frequency,hopf_parameter,hopf_frequency");
      const char* names[] = {"plunge", "pitch"};
      for (const auto& f : r.flutter) {
        fc.row({static_cast<long long>(f.mode), f.mu, f.frequency, hp->mu, hp->omega});
        std::printf("  g = 0 (rising): mode %d (%s) at Ubar = %.6f, frequency %.6f; Hopf point Ubar* = %.6f, omega* = %.6f "
                    "(%+.1e, %+.1e relative)\n",
                    f.mode, f.mode < 2 ? names[f.mode] : "?", f.mu, f.frequency, hp->mu, hp->omega, f.mu / hp->mu - 1,
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

/// Returns the number of failed points.
inline int jump_check_part(const options& o, const boundaries& all) {
  const grid_level g = level_named("very_coarse");
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
    const flutter_boundary b = known != all.end() ? known->second : boundary_on(o, c, g, nullptr);
    for (const auto& [k, what] : flutter_check_points(family_of(c), b)) {
      const auto& p = b.points[k];
      const auto s = make_system(g, p.mach, c.mu_s);
      const vec<double>& w0 = p.point.w;  // the steady flow at this Mach number (fixed-equilibrium Hopf point)
      bool ok = true;
      double worst_below = -1e300, lowest_unstable = NAN;
      for (double f : factors) {
        const double ubar = f * p.mu;
        Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(s.jacobian(w0, ubar)), false);
        cplx top = es.eigenvalues()[0];
        for (const auto& l : es.eigenvalues())
          if (l.real() > top.real()) top = l;
        out.row({c.name, p.mach, p.mu, ubar, top.real(), std::abs(top.imag())});
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
      std::printf("    M = %.4f  Ubar* = %.5f: max Re lambda over 0.2 .. 0.995 Ubar* = %+.3e -> %s\n", p.mach, p.mu,
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
  return failed;
}

// ---------------------------------------------------------------------------------------------
// Part 3: time marching at 0.97 and 1.03 Ubar* (implicit BDF2, dual time, dt = 0.125).

struct march_result : eigenmode_march_result {
  double ubar = 0, steady_seconds = 0;
};

/// The inner solver of the BDF2 runs: BILU(0)-GMRES to 1e-2 (three orders per step need no more).
inline krylov_solver<Eigen::SparseMatrix<double>, 4> bdf2_inner_solver() {
  krylov_solver_options ko;
  ko.fill_level = 0;
  ko.krylov.relative_tolerance = 1e-2;
  ko.krylov.max_iterations = 400;
  ko.krylov.record_history = false;
  return krylov_solver<Eigen::SparseMatrix<double>, 4>(ko, "BDF2 inner BILU(0)-GMRES");
}

/// Writes the plunge and pitch histories of a run to history_<tag>.csv, with progress.
struct history_writer {
  csv_writer csv;
  std::string tag;
  Eigen::Index ih, ia;
  void operator()(const bdf2_step_info& i, const vec<double>& w) {
    csv.row({i.t, w[ih], w[ia]});
    if (i.step > 0 && i.step % 100 == 0)
      std::printf("    %s: step %ld  t = %.2f  alpha = %+.5e  inner iterations %d\n", tag.c_str(), i.step, i.t, w[ia],
                  i.inner_iterations);
  }
};
inline history_writer history_to(const aerofoil_system& s, const std::string& tag, const options& o) {
  return {csv_writer(o.out / ("history_" + tag + ".csv"), "t,h,alpha"), tag, s.flow_size(), s.flow_size() + 2};
}

/// BDF2 (dt = 0.125) of system s at ubar from the equilibrium w plus the eigenmode ep scaled
/// to a pitch amplitude (march_eigenmode on the pitch angle), writing history_<tag>.csv.
inline eigenmode_march_result march_pitch_mode(const aerofoil_system& s, double ubar, const vec<double>& w,
                                               const eigen_pair& ep, double amplitude, double cycles,
                                               const std::string& tag, const options& o) {
  eigenmode_march_options mo;
  mo.coordinate = s.flow_size() + 2;  // the pitch angle
  mo.amplitude = amplitude;
  mo.cycles = cycles;
  mo.dt = 0.125;
  auto solver = bdf2_inner_solver();
  return march_eigenmode(s, ubar, w, ep, mo, solver, history_to(s, tag, o));
}

/// BDF2 (cfd_bdf2_options, dt = 0.125 unless given) of system s at ubar from w0 to t_end: the pitch history.
struct march_history {
  std::vector<double> t, alpha;
  double seconds = 0;
};
inline march_history march(const aerofoil_system& s, double ubar, const vec<double>& w0, double t_end,
                           const std::string& tag, const options& o, double dt = 0.125) {
  auto solver = bdf2_inner_solver();
  auto write = history_to(s, tag, o);
  march_history r;
  const auto t0 = clk::now();
  integrate_bdf2(
      s, ubar, w0, 0.0, t_end, cfd_bdf2_options(dt),
      [&](const bdf2_step_info& i, const vec<double>& w) {
        r.t.push_back(i.t);
        r.alpha.push_back(w[write.ia]);
        write(i, w);
      },
      solver);
  r.seconds = seconds_since(t0);
  return r;
}

/// BDF2 run of the coupled system at Ubar = factor Ubar*, started on the critical eigenvector
/// at that Ubar (pitch amplitude 0.01 rad), its growth rate against the real part of that
/// eigenvalue (march_eigenmode, dt = 0.125).
inline march_result time_march(const structural_case& c, const grid_level& g, const flutter_boundary_point& bp, double factor,
                        double cycles, const options& o) {
  march_result r;
  const auto s = make_system(g, bp.mach, c.mu_s);
  const auto st = steady(s);
  r.steady_seconds = st.seconds;
  r.ubar = factor * bp.mu;
  // the critical eigenpair at this Ubar (shift-invert from the Hopf eigenvalue)
  vec<cplx> p0 = bp.point.p.size() == s.size() ? bp.point.p : vec<cplx>();
  const eigen_pair ep = inverse_power(s.jacobian(st.w, r.ubar), cplx(0.0, bp.omega), {}, p0.size() ? &p0 : nullptr);
  const std::string tag = c.name + "_" + g.name + "_M" + fixed(bp.mach, 2) + "_" + fixed(factor, 2);
  static_cast<eigenmode_march_result&>(r) = march_pitch_mode(s, r.ubar, st.w, ep, 0.01, cycles, tag, o);
  return r;
}

inline void verification_part(const options& o, const boundaries& all, std::vector<double>& march_costs) {
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
    const auto p = std::find_if(it->second.points.begin(), it->second.points.end(),
                                [&](const flutter_boundary_point& q) { return std::abs(q.mach - m) < 1e-9; });
    if (p == it->second.points.end()) {
      std::cout << "  no boundary point at M = " << m << "\n";
      continue;
    }
    for (double f : {0.97, 1.03}) {
      const march_result r = time_march(c, o.verify_grid, *p, f, o.quick ? 3.0 : 4.0, o);
      csv.row({c.name, o.verify_grid.name, m, p->mu, f, r.ubar, r.growth_rate, r.re_lambda, r.im_lambda,
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

/// The LCO branch of the full system by harmonic balance (Newton-Krylov), continued in pitch
/// amplitude from the Hopf point, landing on 1.001 .. 1.05 Ubar*, for 1, 2, 3 and 5 harmonics;
/// the reduced model beside it. Stability: Floquet exponents nearest 0 by Hill's method with
/// shift-invert Arnoldi (hill_floquet_krylov) at the landed points from H = 2 on (with one
/// harmonic the trivial exponent is -2e-4 at 1.01 Ubar*, as far from 0 as the radial one, and
/// the pair does not separate at 1.02); between them a cycle is
/// marked stable where Ubar grows with the amplitude (exchange of stability with the stable
/// equilibrium below Ubar*), which the landed points check.
/// Returns the number of landed points where the two stability verdicts disagree or Hill's
/// method fails.
inline int lco_branch_part(const options& o, const aerofoil_system& s, const steady_result& st, const hopf_point& hp,
                           const centre_manifold_model& model, Eigen::Index ia, double side) {
  std::cout << "\n  LCO branch by harmonic balance (Newton-Krylov, BILU(" << o.fill
            << ") per harmonic), pitch amplitude against Ubar:\n";
  const vec<double> probe = vec<double>::Unit(s.size(), ia);
  const std::string name = "lco_branch_heavy_coarse_M0.80.csv";
  csv_writer lc(o.out / name, "harmonics,ubar,omega,alpha_amplitude,stable,newton_iterations,seconds,steady_seconds");
  csv_writer fc(o.out / "lco_floquet_heavy_coarse_M0.80.csv",
                "harmonics,ubar,alpha_amplitude,trivial_exponent,radial_exponent,radius,stable,linear_solves,"
                "linear_iterations,seconds,steady_seconds");
  std::vector<double> factors = {1.001, 1.002, 1.005, 1.01, 1.02, 1.05};
  if (o.quick) factors = {1.002, 1.01};
  std::vector<double> targets;
  for (double f : factors) targets.push_back(hp.mu * (1 + side * (f - 1)));
  if (side < 0) std::reverse(targets.begin(), targets.end());
  std::vector<lco_solution> cycles;  // the landed cycles of the last H
  std::vector<double> exponents;     // and their radial Floquet exponents
  int disagreements = 0;
  for (int h : o.quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 3, 5}) {
    hb_krylov<4> kr;
    kr.fill_level = o.fill;
    harmonic_balance_options ho;
    ho.tolerance = 1e-10;
    ho.label = "harmonic balance H = " + std::to_string(h);
    const auto t0 = clk::now();
    // first cycle: pitch amplitude 2e-4 rad (first harmonic) from the critical eigenvector
    const lco_solution start =
        solve_lco(s, lco_guess_from_hopf(hp, probe, 2e-4, h), probe, lco_fix::amplitude, std::nullopt, ho, kr);
    lco_branch_options bo;
    bo.newton = ho;
    bo.mu_scale = 0.01 * hp.mu;
    bo.amplitude_scale = 0.01;
    bo.step = 0.1;
    bo.max_step = 0.5;
    bo.mu_targets = targets;
    bo.mu_min = hp.mu * 0.9;
    bo.mu_max = hp.mu * 1.06;
    bo.amplitude_max = 0.2;
    bo.max_points = 80;
    bo.stability = false;  // Hill's dense matrix is out of reach: the Krylov form at the landed points
    std::optional<double> last_mu;
    int landed = 0;
    cycles.clear();
    exponents.clear();
    const lco_branch b = trace_lco_branch(
        s, start, probe, bo,
        [&](const lco_branch_point& p) {
          bool stable = last_mu ? side * (p.cycle.mu - *last_mu) > 0 : true;
          last_mu = p.cycle.mu;
          if (p.landed) {
            ++landed;
            cycles.push_back(p.cycle);
            const double dmu = p.cycle.mu - hp.mu;
            const auto l = model.lco(dmu);
            const double reduced = l.exists ? model.component_amplitude(ia, dmu).first : NAN;
            std::printf("    H = %d  Ubar = %.6f (%.3f Ubar*)  pitch amplitude %.6f rad (reduced model %.6f, %+.1f %%)  "
                        "omega %.6f (Hopf %.6f)  Newton %d, GMRES %d  %.1f s = %.2f steady solves; %.1f MB per instance\n",
                        h, p.cycle.mu, p.cycle.mu / hp.mu, p.probe_amplitude, reduced,
                        100 * (reduced / p.probe_amplitude - 1), p.cycle.omega, hp.omega, p.cycle.newton_iterations,
                        p.cycle.linear_iterations, p.cycle.seconds, p.cycle.seconds / st.seconds,
                        double(p.cycle.linear_bytes) / p.cycle.instance_count() / 1e6);
            if (h == 1) {
              exponents.push_back(NAN);  // truncation: the trivial exponent is as far from 0 as the radial one
            } else {
              hill_krylov_options fo;
              fo.fill_level = o.fill;
              const auto tf = clk::now();
              try {
                const floquet_result f = hill_floquet_krylov<4>(s, p.cycle, fo);
                const double fs = seconds_since(tf);
                exponents.push_back(f.max_real);
                if (f.stable != stable) ++disagreements;
                stable = f.stable;
                fc.row({(long long)h, p.cycle.mu, p.probe_amplitude, f.trivial.real(), f.max_real, f.radius,
                        (long long)f.stable, (long long)f.linear_solves, (long long)f.linear_iterations, fs,
                        st.seconds});
                std::printf("           Floquet (Hill, Krylov): radial exponent %+.4e (trivial %+.1e) %s, %d GMRES solves"
                            " (%d iterations) %.1f s = %.1f steady solves\n",
                            f.max_real, f.trivial.real(), f.stable ? "stable" : "UNSTABLE", f.linear_solves,
                            f.linear_iterations, fs, fs / st.seconds);
              } catch (const convergence_error& e) {
                std::printf("    FAILED: H = %d, Ubar = %.6f: %s\n", h, p.cycle.mu, e.what());
                ++disagreements;
                exponents.push_back(NAN);
              }
            }
          }
          lc.row({(long long)h, p.cycle.mu, p.cycle.omega, p.probe_amplitude, (long long)stable,
                  (long long)p.cycle.newton_iterations, p.cycle.seconds, st.seconds});
          return landed == int(targets.size());
        },
        kr);
    std::printf("    H = %d: %zu points, %d landed, %.1f s in all (%s)\n", h, b.points.size(), landed, seconds_since(t0),
                b.stop_reason.empty() ? "all targets landed" : b.stop_reason.c_str());
  }
  std::printf("    one steady solve: %.2f s; wrote %s and lco_floquet_heavy_coarse_M0.80.csv\n", st.seconds, name.c_str());
  if (disagreements > 0)
    std::printf("    FAILED: at %d landed points Hill's Floquet exponents and the branch direction disagree on stability\n",
                disagreements);
  if (!o.lco_march) return disagreements;
  // BDF2 to the limit cycle from inside and outside it: the cycle's state at phase 0 with its
  // displacement from the mean scaled by 0.9 and 1.1, marched for `periods` periods; amplitude
  // (half swing of the pitch) and period over the last three cycles (last_cycles), and the cycle
  // both runs approach (limit_cycle_from_envelopes). dt = 0.125 (210 steps per period) damps
  // the oscillation by O((omega dt)^4) per step, about 1e-6 per unit time: 4 % of the growth
  // rate at 1.001 Ubar*, so dt is halved below 1.003 Ubar*.
  std::cout << "\n  BDF2 to the limit cycle against harmonic balance (H = " << cycles.front().harmonics << "):\n";
  // start_scale 0: the cycle where the envelopes' growth rate vanishes (both runs' samples)
  csv_writer mc(o.out / "lco_march_heavy_coarse_M0.80.csv",
                "ubar,hb_amplitude,hb_omega,hb_exponent,start_scale,march_amplitude,march_omega,march_exponent,periods,"
                "dt,seconds");
  const int periods = o.quick ? 20 : 60;
  for (std::size_t q = 0; q < cycles.size(); ++q) {
    const lco_solution& c = cycles[q];
    if (o.quick && std::abs(c.mu / hp.mu - 1 - side * 0.01) > 1e-9) continue;
    const double hb_amp = probe_peak_amplitude(c, probe);
    const double dt = std::abs(c.mu / hp.mu - 1) < 0.003 ? 0.0625 : 0.125;
    std::vector<std::vector<amplitude_sample>> envelopes;
    for (double scale : {0.9, 1.1}) {
      const vec<double> w0 = c.mean() + scale * (c.state(0.0) - c.mean());
      const auto mh = march(s, c.mu, w0, periods * c.period(),
                            "lco_" + fixed(c.mu / hp.mu, 3) + "_" + fixed(scale, 1), o, dt);
      const cycle_measure last = last_cycles(mh.t, mh.alpha, 3);
      const double amp = last.amplitude, om = 2 * std::numbers::pi / last.period;
      envelopes.push_back(amplitude_envelope(mh.t, mh.alpha, 1.5 * c.period()));
      mc.row({c.mu, hb_amp, c.omega, exponents[q], scale, amp, om, NAN, (long long)periods, dt, mh.seconds});
      std::printf("    Ubar = %.6f (%.3f Ubar*), start %.1f x the cycle: after %d periods amplitude %.6f rad (HB %.6f, %+.2f %%),"
                  " omega %.6f (HB %.6f, %+.3f %%), dt %.4f, %.0f s\n",
                  c.mu, c.mu / hp.mu, scale, periods, amp, hb_amp, 100 * (amp / hb_amp - 1), om, c.omega,
                  100 * (om / c.omega - 1), dt, mh.seconds);
    }
    const envelope_cycle e = limit_cycle_from_envelopes(envelopes);
    mc.row({c.mu, hb_amp, c.omega, exponents[q], 0.0, e.amplitude, NAN, e.exponent, (long long)periods, dt, 0.0});
    std::printf("    Ubar = %.6f: the envelopes' growth rate vanishes at amplitude %.6f rad (HB %.6f, %+.2f %%; %d samples%s);"
                " radial exponent %+.4e (Hill %+.4e, %+.1f %%)\n",
                c.mu, e.amplitude, hb_amp, 100 * (e.amplitude / hb_amp - 1), e.samples,
                e.bracketed ? "" : ", NOT bracketed", e.exponent, exponents[q], 100 * (e.exponent / exponents[q] - 1));
  }
  return disagreements;
}

/// Returns the number of failed checks (lco_branch_part).
inline int reduced_part(const options& o, const boundaries& all) {
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
  // the unit of cost of the LCO points: the faster of two steady solves from the free stream (the
  // first one in the process also pays the first touch of its memory, up to half as much again)
  auto st = steady(s);
  st.seconds = std::min(st.seconds, steady(s).seconds);
  hopf_point guess;
  const auto it = all.find(c.name + "_" + g.name);
  const flutter_boundary_point* bp = nullptr;
  if (it != all.end())
    for (const auto& q : it->second.points)
      if (std::abs(q.mach - mach) < 1e-9) bp = &q;
  if (bp) {
    guess = bp->point;
  } else {
    std::cout << "  (no " << c.name << " " << g.name << " boundary point at M = " << mach
              << " in this run: inverse-power start)\n";
    guess = hopf_start_krylov<4>(s, st.w, c.ubar_guess, c.omega_guess, start_options(o));
  }
  guess.w = st.w;
  hopf_krylov_options hk;
  hk.fill_level = o.fill;
  hopf_result h = solve_hopf_krylov<4>(s, guess, point_options(o, "reduced-model Hopf point"), hk);
  h.point.mu = std::abs(h.point.mu);
  const hopf_point& hp = h.point;
  std::printf("  Hopf point (smoothed): Ubar* = %.8f, omega* = %.8f", hp.mu, hp.omega);
  if (bp) std::printf("  (exact switch: %.8f, %.8f: smoothing moves Ubar* by %+.2e)", bp->mu, bp->omega, hp.mu / bp->mu - 1);
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
      // four cycles: three leave one envelope sample after the 1.5-period transient
      const auto mh = march_pitch_mode(s, ubar, st.w, ep, 1e-4, 4.0, "heavy_coarse_M0.80_0.97_smoothed", o);
      // mean envelope growth rate after the start transient (1.5 periods)
      const auto env = amplitude_envelope(mh.t, mh.y, 1.5 * period);
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
  const int failed = lco_branch_part(o, s, st, hp, model, ia, side);
  if (!o.verify) return failed;

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
  return failed;
}


}  // namespace aerofoil_example
