#pragma once
// Part 4 of the AGARD 445.6 example: the flutter boundary of the flexible wing (models/wing.hpp,
// models/wing_family.hpp) by the library's driver (trace_flutter_boundary), per grid level and
// structural damping, against the experiment of spec 06; and the V-g / V-f diagram at M = 0.96.
//
// Flight conditions: the wind tunnel's speed of sound at each test point, a = V / M (345.6,
// 341.3, 329.3, 323.9 m/s at M = 0.499, 0.678, 0.901, 0.960), linear in M between them; the
// density at flutter is what the Hopf solve finds. The flutter speed index uses the experiment's
// wing mass, 1.866 kg (mass ratio x density x frustum volume, the same in every row of spec 06's
// table: our plate model weighs 1.716 kg), the root semichord 0.2794 m and omega_alpha = 239.3 rad/s.
#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/linalg/krylov_solver.hpp>
#include <aerohopf/time/eigenmode_march.hpp>
#include <aerohopf/models/wing_family.hpp>
#include <aerohopf/models/wing_vtk.hpp>
#include <aerohopf/structure/plate_fe.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "../common/cli.hpp"

namespace agard445_flutter {

using namespace aerohopf;

/// Spec 06: the AGARD 445.6 weakened model 3 flutter points in air.
struct experiment_point {
  double mach, density, speed, mass_ratio, fsi, frequency_ratio;
};
inline const std::vector<experiment_point>& experiment() {
  static const std::vector<experiment_point> e = {{0.499, 0.4278, 172.46, 33.465, 0.4459, 0.5353},
                                                  {0.678, 0.2082, 231.37, 68.753, 0.4174, 0.4722},
                                                  {0.901, 0.0995, 296.69, 143.920, 0.3700, 0.4225},
                                                  {0.960, 0.0634, 310.96, 225.820, 0.3095, 0.3673}};
  return e;
}

inline models::speed_of_sound_schedule tunnel_schedule() {
  models::speed_of_sound_schedule s;
  for (const auto& p : experiment()) {
    s.mach.push_back(p.mach);
    s.speed_of_sound.push_back(p.speed / p.mach);
  }
  return s;
}

inline models::flutter_reference agard_reference(const flow::wing_planform& p) {
  models::flutter_reference r;
  r.frustum_volume = models::flutter_reference::frustum_of(p);
  const auto& e = experiment().front();
  r.wing_mass = e.mass_ratio * e.density * r.frustum_volume;
  r.semichord = 0.2794;
  r.omega_alpha = 239.3;
  return r;
}

struct flutter_options {
  std::vector<int> strides{4, 2};           ///< boundary levels, coarse to fine (grid sequencing)
  std::vector<double> damping_percent{0, 0.5, 2};  ///< on the coarsest level
  std::vector<double> fine_damping_percent{0.5};   ///< on the finer levels (those also in damping_percent)
  std::vector<double> machs{0.499, 0.678, 0.901, 0.96};
  int vg_stride = 0;                        ///< 0: no V-g diagram
  double vg_mach = 0.96;
  int vg_points = 9;
  int march_stride = 0;                     ///< 0: no time-marching verification
  bool verbose = false;
};

/// The grid stride of a level name.
inline int stride_of(const std::string& level) {
  if (level == "very_coarse") return 8;
  if (level == "coarse") return 4;
  if (level == "medium") return 2;
  if (level == "fine") return 1;
  throw input_error("unknown grid level '" + level + "' (very_coarse, coarse, medium, fine)");
}

/// --mesh NI,NJ (the plate's chordwise x spanwise quads); false if `a` is another option.
inline bool read_mesh_option(const std::string& a, example_cli::arguments& args, int& ni, int& nj) {
  if (a != "--mesh") return false;
  const std::string v = args.value();
  const auto comma = v.find(',');
  require(comma != std::string::npos, "--mesh takes NI,NJ (chordwise,spanwise quads), not ", v);
  try {
    ni = std::stoi(v.substr(0, comma));
    nj = std::stoi(v.substr(comma + 1));
  } catch (const std::exception&) {
    throw input_error("--mesh takes two integers NI,NJ, not '" + v + "'");
  }
  require(ni >= 2 && nj >= 2 && ni <= 400 && nj <= 400, "--mesh: NI and NJ in [2, 400] (got ", ni, ",", nj, ")");
  return true;
}

/// The boundary options both programs read (--flutter, --damping, --fine-damping, --machs,
/// --verbose); false if `a` is another option.
inline bool read_boundary_option(const std::string& a, example_cli::arguments& args, flutter_options& f) {
  if (a == "--flutter") {
    f.strides.clear();
    for (const auto& l : args.words())
      if (l != "none") f.strides.push_back(stride_of(l));
    std::sort(f.strides.begin(), f.strides.end(), std::greater<>());
  } else if (a == "--damping" || a == "--fine-damping") {
    auto& list = a == "--damping" ? f.damping_percent : f.fine_damping_percent;
    list = args.numbers();
    for (double z : list) require(z >= 0 && z < 50, a, ": percentages in [0, 50) (got ", z, ")");
  } else if (a == "--machs") {
    f.machs = args.numbers();
    for (std::size_t k = 0; k < f.machs.size(); ++k)
      require(f.machs[k] > 0.3 && f.machs[k] < 1.3 && (k == 0 || f.machs[k] > f.machs[k - 1]),
              "--machs: increasing Mach numbers in (0.3, 1.3)");
  } else if (a == "--verbose") {
    f.verbose = true;
  } else {
    return false;
  }
  return true;
}

/// The plate model's modes on an ni x nj mesh (count of them), with its mass and the time taken.
struct solved {
  structure::plate_mesh mesh;
  structure::plate_modes modes;
  double mass = 0, seconds = 0;
};
inline solved modes_on(const flow::wing_geometry& w, int ni, int nj, int count) {
  const auto t0 = std::chrono::steady_clock::now();
  solved s;
  s.mesh = structure::wing_plate_mesh(w, ni, nj);
  const structure::plate_matrices km = structure::assemble_plate(s.mesh, structure::agard445_6_mahogany(w.planform));
  s.mass = structure::plate_mass(km);
  structure::plate_mode_options mo;
  mo.count = count;
  s.modes = structure::plate_modes_of(km, structure::clamped_root(s.mesh, ni), mo);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

/// The first four modes of md: the flutter part's structure.
inline structure::modal_data first_four(const structure::modal_data& md) {
  require(md.modes() >= 4, "the flutter part needs four modes (--modes 4 or more)");
  structure::modal_data four = md;
  four.omega.conservativeResize(4);
  four.generalised_mass.conservativeResize(4);
  four.shapes.resize(4);
  return four;
}

inline std::string damping_tag(double percent) {
  char b[32];
  std::snprintf(b, sizeof b, "zeta%g", percent);
  return b;
}

/// The start of a boundary: the experiment's flutter density and frequency at the first Mach
/// number (interpolated in M), as (mu, omega) of the family.
inline std::pair<double, double> experimental_start(const models::wing_family& f, double mach) {
  const auto& e = experiment();
  std::size_t k = 0;
  while (k + 2 < e.size() && mach > e[k + 1].mach) ++k;
  const double t = std::clamp((mach - e[k].mach) / (e[k + 1].mach - e[k].mach), 0.0, 1.0);
  const double rho = (1 - t) * e[k].density + t * e[k + 1].density;
  const double ratio = (1 - t) * e[k].frequency_ratio + t * e[k + 1].frequency_ratio;
  const double c = f.planform().root_chord;
  return {rho * c * c * c, ratio * 239.3 * c / f.sound().speed(mach)};
}

struct boundary_run {
  int stride = 0;
  double damping = 0;
  flutter_boundary b;
  double seconds = 0;
};

/// Every boundary of o (levels x dampings), written as boundary_<grid>_zeta<percent>.csv.
/// wrap(models::wing_family) gives the family the driver runs on (the serial one itself, or
/// distributed::wing_family on MPI ranks); output(fn) runs the printing and writing fn (under
/// MPI: on rank 0, its failure thrown on every rank: distributed::on_root); log: the driver's
/// progress (nullptr on the other ranks). Every rank runs the driver alike.
template <class Wrap, class Output>
std::vector<boundary_run> boundaries(const flutter_options& o, const std::filesystem::path& out,
                                     const flow::wing_geometry& wing, const flow::wing_grid_options& grid,
                                     const structure::modal_data& modes, Wrap&& wrap, Output&& output,
                                     std::ostream* log) {
  std::vector<boundary_run> runs;
  runs.reserve(o.strides.size() * o.damping_percent.size());  // `coarser` points into it
  const models::flutter_reference ref = agard_reference(wing.planform);
  std::vector<int> strides = o.strides;
  if (o.vg_stride) strides.push_back(o.vg_stride);
  // the finer levels' dampings first, in their listed order: on a finer level each starts from
  // the coarser boundary (grid sequencing), and where that fails (e.g. lands on the trivial Hopf
  // point mu = 0, below the family's mu_min) from the same level's boundary at the nearest
  // damping done (continuation in damping, flutter_boundary_options::start_point)
  std::vector<double> order;
  for (double z : o.fine_damping_percent)
    if (std::find(o.damping_percent.begin(), o.damping_percent.end(), z) != o.damping_percent.end() &&
        std::find(order.begin(), order.end(), z) == order.end())
      order.push_back(z);
  for (double z : o.damping_percent)
    if (std::find(order.begin(), order.end(), z) == order.end()) order.push_back(z);
  for (double zeta : order) {
    models::wing_family serial(wing, grid, strides, modes, Eigen::VectorXd::Constant(1, zeta / 100),
                               tunnel_schedule());
    if (o.verbose) serial.steady_options().log = log;  // a line per steady step (rank 0 only on the ranks)
    decltype(auto) family = wrap(serial);  // a reference to `serial` itself, or a new family
    const flutter_boundary* coarser = nullptr;
    for (int s : o.strides) {
      const bool finer = s != o.strides.front();
      if (finer && std::find(o.fine_damping_percent.begin(), o.fine_damping_percent.end(), zeta) ==
                       o.fine_damping_percent.end())
        continue;
      const std::string name = models::wing_family::level_name(s);
      output([&] {
        std::printf("\n=== flutter boundary: %s grid, structural damping %g %%, %zu Mach numbers ===\n", name.c_str(),
                    zeta, o.machs.size());
        std::fflush(stdout);
      });
      flutter_boundary_options fo = family.boundary_options();
      std::tie(fo.start_mu, fo.start_omega) = experimental_start(serial, o.machs.front());
      fo.verbose = o.verbose && log;
      fo.log = log;
      fo.label = name + " " + damping_tag(zeta);
      const boundary_run* neighbour = nullptr;  // this level's boundary at the nearest damping done
      for (const boundary_run& q : runs)
        if (finer && q.stride == s && !q.b.points.empty() && std::abs(q.b.points.front().mach - o.machs.front()) < 1e-9 &&
            (!neighbour || std::abs(q.damping - zeta) < std::abs(neighbour->damping - zeta)))
          neighbour = &q;
      const auto t0 = std::chrono::steady_clock::now();
      boundary_run r{s, zeta, {}, 0};
      try {
        r.b = trace_flutter_boundary(family, s, o.machs, coarser, fo);
      } catch (const convergence_error& e) {  // thrown alike on every rank (the same decisions everywhere)
        if (!neighbour) throw;
        output([&] {
          std::printf("  %s\n  first point by Newton from the %g %% boundary's on this grid instead\n", e.what(),
                      neighbour->damping);
        });
        fo.start_point = neighbour->b.points.front().point;
        r.b = trace_flutter_boundary(family, s, o.machs, coarser, fo);
      }
      r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      output([&] {
        csv_writer csv(out / ("boundary_" + name + "_" + damping_tag(zeta) + ".csv"),
                       "mach,fsi,frequency_ratio,mass_ratio,q,omega,newton_iterations,linear_iterations,hopf_seconds,"
                       "steady_seconds");
        std::printf("  %6s %8s %8s %9s %9s %9s %9s %7s %7s | %8s %8s\n", "M", "FSI", "w/wa", "mass rat", "q Pa", "rho",
                    "omega", "Hopf s", "steady", "exp FSI", "exp w/wa");
        for (const auto& p : r.b.points) {
          const models::flutter_numbers n = serial.numbers(p.mach, p.mu, p.omega, ref);
          csv.row({p.mach, n.fsi, n.frequency_ratio, n.mass_ratio, n.dynamic_pressure, p.omega,
                   static_cast<long long>(p.newton_iterations), static_cast<long long>(p.linear_iterations),
                   p.hopf_seconds, p.steady_seconds});
          std::printf("  %6.3f %8.4f %8.4f %9.2f %9.1f %9.5f %9.5f %7.1f %7.1f", p.mach, n.fsi, n.frequency_ratio,
                      n.mass_ratio, n.dynamic_pressure, n.density, p.omega, p.hopf_seconds, p.steady_seconds);
          for (const auto& e : experiment())
            if (std::abs(e.mach - p.mach) < 1e-9) std::printf(" | %8.4f %8.4f", e.fsi, e.frequency_ratio);
          std::printf("\n");
        }
        if (!r.b.complete) std::printf("  boundary incomplete: %s\n", r.b.stop_reason.c_str());
        for (const auto& p : r.b.points)  // the flutter mode at M = 0.96
          if (std::abs(p.mach - 0.96) < 1e-9) {
            const models::flutter_mode_frames f = models::write_flutter_mode_vtk(
                serial.system(s, p.mach), p.point, (out / ("flutter_mode_" + name + "_" + damping_tag(zeta) + "_M0.96")).string());
            if (f.displacement < 0.05)
              std::printf("  flutter mode VTK at M = 0.96: largest deflection %.2g root chords (0.05 made the flow unphysical)\n",
                          f.displacement);
          }
        const flutter_boundary_costs c = boundary_costs(r.b, o.machs);
        if (c.continued == 0)  // the first point alone: its cost is in the table above
          std::printf("  %zu point(s) in %.1f s; no continued points, so no Hopf work per steady solve\n",
                      r.b.points.size(), r.seconds);
        else
          std::printf("  %zu points in %.1f s; Hopf work per steady solve %.2f (continued points), %.2f (all work "
                      "beyond one steady solve per listed Mach number)\n",
                      r.b.points.size(), r.seconds, c.hopf_per_steady, c.hopf_per_steady_listed);
        std::fflush(stdout);
      });
      runs.push_back(std::move(r));
      coarser = &runs.back().b;
    }
  }
  return runs;
}

/// costs.csv: level,damping_percent,quantity,value (the Hopf work per steady solve of each
/// boundary, its mean steady solve and its wall time, seconds).
inline void write_costs(const std::filesystem::path& file, const std::vector<boundary_run>& runs,
                        const std::vector<double>& machs) {
  csv_writer costs(file, "level,damping_percent,quantity,value");
  for (const auto& r : runs) {
    const flutter_boundary_costs c = boundary_costs(r.b, machs);
    const std::string level = models::wing_family::level_name(r.stride);
    double steady_mean = 0;
    for (const auto& p : r.b.points) steady_mean += p.steady_seconds / double(r.b.points.size());
    costs.row({level, r.damping, "hopf_per_steady_continued", c.hopf_per_steady});
    costs.row({level, r.damping, "hopf_per_steady_listed", c.hopf_per_steady_listed});
    costs.row({level, r.damping, "steady_seconds_mean", steady_mean});
    costs.row({level, r.damping, "boundary_seconds", r.seconds});
  }
}

/// The Hopf point of one family member from the experiment's start (inverse power to 1e-3 as
/// the driver's first point, then Newton-Krylov), with the system and its equilibrium.
struct single_point {
  models::wing_system s;
  vec<double> w;
  hopf_result h;
  double steady_seconds = 0, hopf_seconds = 0;
};
inline single_point hopf_at(const models::wing_family& family, int stride, double mach) {
  const auto t0 = std::chrono::steady_clock::now();
  models::wing_system s = family.system(stride, mach);
  vec<double> w = family.equilibrium(s, 0.0);
  const auto t1 = std::chrono::steady_clock::now();
  const auto [mu0, omega0] = experimental_start(family, mach);
  const flutter_boundary_options fo = family.boundary_options();
  hopf_start_krylov_options so;  // the driver's start: inverse power to 1e-3, each solve 10x tighter
  so.fill_level = fo.fill_level;
  so.krylov.restart = fo.start_restart;
  so.inverse_power.tolerance = fo.start_eigen_tolerance;
  so.krylov.relative_tolerance = 0.1 * fo.start_eigen_tolerance;
  const hopf_point start = hopf_start_krylov<5>(s, w, mu0, omega0, so);
  hopf_options ho;
  ho.fixed_equilibrium = true;
  ho.newton.abs_tolerance = fo.tolerance;
  hopf_krylov_options hk = fo.krylov;
  hk.fill_level = fo.fill_level;
  hopf_result h = solve_hopf_krylov<5>(s, start, ho, hk);
  const auto t2 = std::chrono::steady_clock::now();
  return {std::move(s), std::move(w), std::move(h), std::chrono::duration<double>(t1 - t0).count(),
          std::chrono::duration<double>(t2 - t1).count()};
}

/// V-g / V-f of the four modes at o.vg_mach on level o.vg_stride (no structural damping), over
/// mu* x [0.4, 1.2] about its Hopf point (found first, from the experiment's start): written as
/// vg_M<mach>_<grid>.csv (mode,parameter,damping_g,frequency,re,im; parameter mu = rho c^3,
/// frequency in the flow's time unit c / U) and vg_flutter_M<mach>_<grid>.csv.
inline void vg(const flutter_options& o, const std::filesystem::path& out, const flow::wing_geometry& wing,
               const flow::wing_grid_options& grid, const structure::modal_data& modes) {
  const std::string name = models::wing_family::level_name(o.vg_stride);
  char mtag[16];
  std::snprintf(mtag, sizeof mtag, "M%.2f", o.vg_mach);
  std::printf("\n=== V-g / V-f diagram: %s grid, M = %.3f, no structural damping ===\n", name.c_str(), o.vg_mach);
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  const models::wing_family family(wing, grid, {o.vg_stride}, modes, Eigen::VectorXd::Zero(1), tunnel_schedule());
  const single_point sp = hopf_at(family, o.vg_stride, o.vg_mach);
  const models::wing_system& s = sp.s;
  const vec<double>& w = sp.w;
  const hopf_result& h = sp.h;
  const flutter_boundary_options fo = family.boundary_options();
  std::printf("  Hopf point mu* = %.6f, omega* = %.6f (%d Newton iterations)\n", h.point.mu, h.point.omega,
              h.report.iterations);
  std::vector<double> mus;
  for (int k = 0; k < o.vg_points; ++k) mus.push_back(h.point.mu * (0.4 + 0.8 * k / std::max(1, o.vg_points - 1)));
  vg_options vo;
  vo.inverse_power.tolerance = fo.scan_tolerance;  // 1e-7, each GMRES solve 10x tighter (the driver's scans)
  vo.verbose = o.verbose;
  vg_krylov_options ko;
  ko.fill_level = fo.fill_level;
  ko.krylov.relative_tolerance = 0.1 * fo.scan_tolerance;
  ko.krylov.restart = fo.start_restart;  // GMRES(50) stagnates on the wing (wing_family::boundary_options)
  ko.krylov.max_iterations = 4000;
  // starts at the in-vacuo eigenvalues WITHOUT their shapes as start vectors: from a purely
  // structural start vector the bordered BILU-GMRES solves stagnated (relative residual 0.99
  // after 4,000 iterations, coarse grid, mu = 0.4 mu*), from the default start they converge
  std::vector<vg_mode_start> starts = vg_mode_starts(s.structure().a_ss());
  for (auto& st : starts) st.tracked = {};
  const vg_result r = vg_diagram(s, [&](double) { return w; }, mus, starts, vo, vg_krylov_solvers<5>(s, ko));
  csv_writer csv(out / ("vg_" + std::string(mtag) + "_" + name + ".csv"), "mode,parameter,damping_g,frequency,re,im");
  for (const auto& p : r.points)
    csv.row({static_cast<long long>(p.mode), p.mu, p.damping, p.frequency, p.lambda.real(), p.lambda.imag()});
  csv_writer fc(out / ("vg_flutter_" + std::string(mtag) + "_" + name + ".csv"),
                "mode,parameter,frequency,hopf_parameter,hopf_frequency");
  for (const auto& f : r.flutter) {
    fc.row({static_cast<long long>(f.mode), f.mu, f.frequency, h.point.mu, h.point.omega});
    std::printf("  g = 0 (rising): mode %d at mu = %.6f, frequency %.5f; Hopf point %+.1e, %+.1e relative\n", f.mode + 1,
                f.mu, f.frequency, f.mu / h.point.mu - 1, f.frequency / h.point.omega - 1);
  }
  if (r.flutter.empty()) std::printf("  no rising zero of g in mu = %.5f .. %.5f\n", mus.front(), mus.back());
  std::printf("  %d modes x %zu values: %d inverse powers, %ld GMRES iterations, %.1f s\n", r.modes, mus.size(),
              r.inverse_powers, r.linear_iterations,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

/// Time-marching verification (BDF2: three orders of the unsteady residual per step, the exact
/// Jacobian frozen over a step, BILU(0)-GMRES with the structure bordered) at
/// 0.95 and 1.05 mu* of the Hopf point at o.vg_mach on level `stride`, no structural damping:
/// started on the critical eigenvector at that mu, 4 periods at 48 steps per period; the growth
/// rate of the first modal coordinate against Re(lambda). verification.csv and
/// history_M<mach>_<level>_<factor>.csv (t,a1,a2,a3,a4).
inline void march(const flutter_options& o, int stride, const std::filesystem::path& out,
                  const flow::wing_geometry& wing, const flow::wing_grid_options& grid,
                  const structure::modal_data& modes) {
  const std::string name = models::wing_family::level_name(stride);
  std::printf("\n=== time marching at 0.95 / 1.05 mu*: %s grid, M = %.3f, no structural damping ===\n", name.c_str(),
              o.vg_mach);
  std::fflush(stdout);
  const models::wing_family family(wing, grid, {stride}, modes, Eigen::VectorXd::Zero(1), tunnel_schedule());
  const single_point sp = hopf_at(family, stride, o.vg_mach);
  const Eigen::Index nf = sp.s.flow_size();
  std::printf("  Hopf point mu* = %.6f, omega* = %.6f (steady %.1f s, Hopf %.1f s)\n", sp.h.point.mu, sp.h.point.omega,
              sp.steady_seconds, sp.hopf_seconds);
  csv_writer csv(out / "verification.csv",
                 "grid,mach,mu_star,factor,mu,growth_rate,re_lambda,im_lambda,bdf2_rate,steps,march_seconds,"
                 "steady_seconds");
  const flutter_boundary_options fo = family.boundary_options();
  for (double factor : {0.95, 1.05}) {
    const double mu = factor * sp.h.point.mu;
    // the critical eigenpair at this mu (inverse power from the Hopf eigenvalue and vector)
    hopf_start_krylov_options so;
    so.fill_level = fo.fill_level;
    so.krylov.restart = fo.start_restart;
    so.inverse_power.tolerance = 1e-8;
    so.krylov.relative_tolerance = 1e-9;
    eigen_pair ep;
    (void)hopf_start_krylov<5>(sp.s, sp.w, mu, sp.h.point.omega, so, &ep);
    eigenmode_march_options mo;
    mo.coordinate = nf;  // the first modal coordinate (first bending)
    mo.amplitude = 1e-4;
    mo.cycles = 4;
    mo.steps_per_period = 48;
    // the inner matrix: the EXACT Jacobian, frozen over a step. With the modified-order one the
    // chord iteration stalled (very coarse grid, dt = 0.77: ||R|| 8e-7 after 40 iterations);
    // the time step of a wing's slow modes is large against the flow's.
    mo.bdf2.approximate_jacobian = false;
    krylov_solver_options ko;
    ko.fill_level = 0;
    ko.krylov.relative_tolerance = 1e-2;
    ko.krylov.max_iterations = 400;
    ko.krylov.record_history = false;
    bordered_krylov_solver<Eigen::SparseMatrix<double>, 5> solver(sp.s.structure_size(), ko, "BDF2 inner BILU(0)-GMRES");
    char tag[64];
    std::snprintf(tag, sizeof tag, "M%.2f_%s_%.2f", o.vg_mach, name.c_str(), factor);
    csv_writer hist(out / ("history_" + std::string(tag) + ".csv"), "t,a1,a2,a3,a4");
    const auto t0 = std::chrono::steady_clock::now();
    const eigenmode_march_result r =
        march_eigenmode(sp.s, mu, sp.w, ep, mo, solver, [&](const bdf2_step_info& i, const vec<double>& w) {
          hist.row({i.t, w[nf], w[nf + 1], w[nf + 2], w[nf + 3]});
          if (i.step % 24 == 0) {
            std::printf("    t = %7.2f  step %4ld  a1 = %+.4e  inner %d  ||R|| %.1e\n", i.t, i.step, w[nf], i.inner_iterations,
                        i.inner_residual);
            std::fflush(stdout);
          }
        });
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    csv.row({name, o.vg_mach, sp.h.point.mu, factor, mu, r.growth_rate, r.re_lambda, r.im_lambda, r.bdf2_rate,
             static_cast<long long>(r.steps), sec, sp.steady_seconds});
    std::printf("  %.2f mu*: %s, growth rate %+.6f (%d peaks) vs Re(lambda) %+.6f (BDF2 at this dt: %+.6f); %ld steps, "
                "%.1f s = %.0f steady solves\n",
                factor, r.growth_rate < 0 ? "decays" : "grows", r.growth_rate, r.peaks, r.re_lambda, r.bdf2_rate, r.steps,
                sec, sec / sp.steady_seconds);
    std::fflush(stdout);
  }
}

}  // namespace agard445_flutter
