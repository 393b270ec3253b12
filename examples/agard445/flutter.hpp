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
#include <aerohopf/models/wing_family.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

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
  std::vector<int> strides{4};              ///< boundary levels, coarse to fine (grid sequencing)
  std::vector<double> damping_percent{0, 0.5, 2};
  std::vector<double> machs{0.499, 0.678, 0.901, 0.96};
  int vg_stride = 0;                        ///< 0: no V-g diagram
  double vg_mach = 0.96;
  int vg_points = 9;
  bool verbose = false;
};

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
inline std::vector<boundary_run> boundaries(const flutter_options& o, const std::filesystem::path& out,
                                            const flow::wing_geometry& wing, const flow::wing_grid_options& grid,
                                            const structure::modal_data& modes) {
  std::vector<boundary_run> runs;
  runs.reserve(o.strides.size() * o.damping_percent.size());  // `coarser` points into it
  const models::flutter_reference ref = agard_reference(wing.planform);
  std::vector<int> strides = o.strides;
  if (o.vg_stride) strides.push_back(o.vg_stride);
  for (double zeta : o.damping_percent) {
    const models::wing_family family(wing, grid, strides, modes, Eigen::VectorXd::Constant(1, zeta / 100),
                                     tunnel_schedule());
    const flutter_boundary* coarser = nullptr;
    for (int s : o.strides) {
      const std::string name = models::wing_family::level_name(s);
      std::printf("\n=== flutter boundary: %s grid, structural damping %g %%, %zu Mach numbers ===\n", name.c_str(), zeta,
                  o.machs.size());
      std::fflush(stdout);
      flutter_boundary_options fo = family.boundary_options();
      std::tie(fo.start_mu, fo.start_omega) = experimental_start(family, o.machs.front());
      fo.verbose = o.verbose;
      fo.label = name + " " + damping_tag(zeta);
      const auto t0 = std::chrono::steady_clock::now();
      boundary_run r{s, zeta, trace_flutter_boundary(family, s, o.machs, coarser, fo), 0};
      r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      csv_writer csv(out / ("boundary_" + name + "_" + damping_tag(zeta) + ".csv"),
                     "mach,fsi,frequency_ratio,mass_ratio,q,omega,newton_iterations,linear_iterations,hopf_seconds,"
                     "steady_seconds");
      std::printf("  %6s %8s %8s %9s %9s %9s %9s %7s %7s | %8s %8s\n", "M", "FSI", "w/wa", "mass rat", "q Pa", "rho",
                  "omega", "Hopf s", "steady", "exp FSI", "exp w/wa");
      for (const auto& p : r.b.points) {
        const models::flutter_numbers n = family.numbers(p.mach, p.mu, p.omega, ref);
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
      const flutter_boundary_costs c = boundary_costs(r.b, o.machs);
      std::printf("  %zu points in %.1f s; Hopf work per steady solve %.2f (continued points), %.2f (all work beyond "
                  "one steady solve per listed Mach number)\n",
                  r.b.points.size(), r.seconds, c.hopf_per_steady, c.hopf_per_steady_listed);
      std::fflush(stdout);
      runs.push_back(std::move(r));
      coarser = &runs.back().b;
    }
  }
  return runs;
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
  const models::wing_system s = family.system(o.vg_stride, o.vg_mach);
  const vec<double> w = family.equilibrium(s, 0.0);
  const auto [mu0, omega0] = experimental_start(family, o.vg_mach);
  flutter_boundary_options fo = family.boundary_options();
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
  const hopf_result h = solve_hopf_krylov<5>(s, start, ho, hk);
  std::printf("  Hopf point mu* = %.6f, omega* = %.6f (%d Newton iterations)\n", h.point.mu, h.point.omega,
              h.report.iterations);
  std::vector<double> mus;
  for (int k = 0; k < o.vg_points; ++k) mus.push_back(h.point.mu * (0.4 + 0.8 * k / std::max(1, o.vg_points - 1)));
  vg_options vo;
  vo.inverse_power.tolerance = 1e-8;
  vg_krylov_options ko;
  ko.fill_level = fo.fill_level;
  ko.krylov.relative_tolerance = 1e-9;
  const auto starts = vg_mode_starts(s.structure().a_ss());
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

}  // namespace agard445_flutter
