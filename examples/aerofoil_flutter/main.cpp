// Flutter of the pitch-plunge NACA 0012 (spec 05): direct Hopf-point stability boundaries
// Ubar(M) by the library's flutter-boundary driver (bifurcation/flutter_boundary.hpp), their
// verification by dense spectra, by every imaginary-axis crossing and by time marching, the
// V-g / V-f diagram, and the centre-manifold reduced model at a transonic Mach number.
//
// Usage: aerofoil_flutter [out_dir] [options]
//   --case light|heavy|both     structural case (mu_s = 10 / 100), default both
//   --grids coarse,medium       grid levels of the boundaries (very_coarse, coarse, medium, fine);
//                               each finer one starts from and uses the one before it
//   --mach-min M --mach-max M   Mach range (default 0.5 .. 0.95; steps 0.05, and 0.01 from 0.80)
//   --mach-step d               one uniform step instead of the default list
//   --incidence DEG             mean angle of attack (default 0): the equilibrium is then the static
//                               aeroelastic one and moves with Ubar, each point a FULL Hopf system
//                               (Krylov, the flow update by block elimination); writes
//                               boundary_<case>_<grid>_alpha<DEG>.csv with the static pitch deflection
//   --skip-spectra --skip-boundaries --skip-vg --skip-jump-check --skip-verify --skip-reduced   parts to leave out
//                               (--skip-jump-check: also the driver's crossing check)
//   --vg-mach M                 Mach number of the V-g / V-f diagrams (default 0.80)
//   --vg-grid g                 their grid (default the first of --grids)
//   --vg-solver lu|krylov|auto  linear algebra of the diagrams' inverse powers (auto: LU up to the coarse grid)
//   --vg-range a,b --vg-points n   Ubar from a Ubar* to b Ubar* in n values (default 0.5,1.4 and 40)
//   --verify-grid g             grid of the time-marching verification (default medium)
//   --contact-smoothing d       contact-switch smoothing of the reduced-model part (default 0.05)
//   --crossing-medium           the crossing check on the medium grid too (default: coarse and coarser)
//   --lco-march                 BDF2 runs to the limit cycle at 1.001 .. 1.05 Ubar* (from 0.9 and 1.1
//                               times the harmonic-balance cycle, 60 periods each) against harmonic balance
//   --quick                     coarse grid, M = 0.5 .. 0.8 step 0.1, shorter time marching
//   --verbose                   a line per Hopf Newton iteration
//
// Outputs under out_dir (default out/aerofoil_flutter):
//   boundary_<case>_<grid>.csv  mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds
//                               (at --incidence: boundary_<case>_<grid>_alpha<DEG>.csv, plus static_alpha:
//                               the static pitch deflection at the flutter point, radians)
//   crossing_check.csv (case,grid,mach,ubar_star,omega_star,ubar,omega)   every imaginary-axis crossing at
//                               the jumps and last points (the library driver's check; at --incidence
//                               the rising zeros of g of a V-g scan from 0.5 Ubar*)
//   flutter_point_very_coarse.txt, spectra.csv (ubar,re,im)     very coarse, light, M = 0.5
//   jump_check.csv              boundary jumps checked by dense spectra on the very coarse grid
//   vg_<case>_<grid>_M<mach>.csv  mode,parameter,damping_g,frequency,re,im (parameter Ubar; mode 0
//                               plunge, 1 pitch); vg_flutter_<case>_<grid>_M<mach>.csv its g = 0 crossings
//   verification.csv, history_<case>_M<mach>_<factor>.csv       time marching at 0.97 / 1.03 Ubar*
//   costs.csv                                                   cost ratios to the steady solve
//   lco_branch_heavy_coarse_M0.80.csv    the LCO branch by harmonic balance (1, 2, 3, 5 harmonics), heavy case,
//                               coarse grid, M = 0.8 (harmonics,ubar,omega,alpha_amplitude,stable,
//                               newton_iterations,seconds,steady_seconds); lco_floquet_heavy_coarse_M0.80.csv
//                               the Floquet exponents nearest 0 at the landed points (Hill, Krylov);
//                               lco_march_heavy_coarse_M0.80.csv the BDF2 runs of --lco-march
//   reduced_coefficients.csv, reduced_damping.csv, reduced_lco.csv, reduced_envelope.csv   reduced model
// plot.py in this folder turns them into PNGs. Exit status 1 if a check fails.
#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/io/csv.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "../common/cli.hpp"
#include "parts.hpp"
#include "setup.hpp"

using namespace aerohopf;
using namespace aerofoil_example;

namespace aerofoil_example {

flutter_boundary boundary_on(const options& o, const structural_case& c, const grid_level& g,
                             const flutter_boundary* coarser) {
  const auto machs = mach_list(o);
  const auto family = family_of(c, o.incidence_deg * std::numbers::pi / 180);
  flutter_boundary b = trace_flutter_boundary(family, g.stride, machs, coarser, driver_options(o, c, g, family));
  write_boundary(o, c, g, b);
  if (!b.complete) std::cout << "  " << b.label << ": boundary incomplete: " << b.stop_reason << "\n";
  if (b.complete && !b.skipped.empty()) std::cout << "  " << b.label << ": " << b.stop_reason << "\n";
  return b;
}

}  // namespace aerofoil_example

namespace {

boundaries boundaries_part(const options& o, csv_writer& crossings) {
  boundaries all;
  const auto machs = mach_list(o);
  for (const auto& c : o.cases) {
    const flutter_boundary* coarser = nullptr;
    for (const auto& g : o.grids) {
      std::cout << "\n=== stability boundary: " << c.name << " case (mu_s = " << c.mu_s << "), " << g.name << " grid, "
                << machs.size() << " Mach numbers ===\n";
      const auto t0 = clk::now();
      flutter_boundary b = boundary_on(o, c, g, coarser);
      double hopf = 0, steady_total = 0;
      for (const auto& p : b.points) {
        hopf += p.hopf_seconds;
        steady_total += p.steady_seconds;
      }
      std::printf("  %s %s: %zu points in %.1f s (Hopf %.1f s + steady %.1f s); Hopf / steady = %.2f\n", c.name.c_str(),
                  g.name.c_str(), b.points.size(), seconds_since(t0), hopf, steady_total, hopf / steady_total);
      for (const auto& x : b.checks)
        for (const auto& [u, om] : x.all) crossings.row({c.name, g.name, x.mach, x.mu, x.omega, u, om});
      const std::string key = c.name + "_" + g.name;
      all[key] = std::move(b);
      coarser = &all[key];
    }
  }
  return all;
}

/// The cost table: per unit steady solve, from the boundaries' points (boundary_costs).
void cost_part(const options& o, const boundaries& all, const std::vector<double>& march_costs) {
  csv_writer csv(o.out / "costs.csv", "case,grid,quantity,ratio_to_steady");
  std::cout << "\n=== cost per unit steady solve (same run, same machine) ===\n";
  const std::vector<double> listed = mach_list(o);
  for (const auto& [key, b] : all) {
    const flutter_boundary_costs k = boundary_costs(b, listed);
    if (k.continued > 0) {
      std::printf("  %-22s Hopf point / steady solve = %.2f (mean over %zu continued points)\n", key.c_str(),
                  k.hopf_per_steady, k.continued);
      csv.row({key, std::string(""), std::string("hopf_per_steady"), k.hopf_per_steady});
    }
    if (k.listed > 0) {
      std::printf("  %-22s all Hopf work / steady solve = %.2f (per listed Mach number, %zu continued)\n", key.c_str(),
                  k.hopf_per_steady_listed, k.listed);
      csv.row({key, std::string(""), std::string("hopf_per_steady_listed"), k.hopf_per_steady_listed});
    }
  }
  // a finer boundary starts from and uses the coarser one: the same with all of that charged too
  for (const auto& c : o.cases)
    for (std::size_t i = 1; i < o.grids.size(); ++i) {
      if (o.grids[i - 1].stride != 2 * o.grids[i].stride) continue;
      const auto fine = all.find(c.name + "_" + o.grids[i].name), coarse = all.find(c.name + "_" + o.grids[i - 1].name);
      if (fine == all.end() || coarse == all.end() || boundary_costs(fine->second, listed).listed == 0) continue;
      const double ratio = boundary_cost_with_coarser(fine->second, coarse->second, listed);
      std::printf("  %-22s all Hopf work + the whole %s boundary / steady solve = %.2f (per listed Mach number)\n",
                  fine->first.c_str(), o.grids[i - 1].name.c_str(), ratio);
      csv.row({fine->first, std::string(""), std::string("hopf_and_coarser_per_steady_listed"), ratio});
    }
  for (double r : march_costs) {
    std::printf("  time-marching run (4 cycles) / steady solve = %.1f\n", r);
    csv.row({std::string("light"), o.verify_grid.name, std::string("march_per_steady"), r});
  }
}

options parse(int argc, char** argv) {
  options o;
  example_cli::arguments args(argc, argv);
  for (std::string a; args.next(a);) {
    auto next = [&] { return args.value(); };
    auto number = [&] { return args.number(); };
    if (read_boundary_option(a, args, o)) {
      continue;
    } else if (a == "--contact-smoothing") {
      o.contact_smoothing = number();
      require(o.contact_smoothing >= 0, "--contact-smoothing must be >= 0");
    } else if (a == "--verify-grid") {
      o.verify_grid = level_named(next());
    } else if (a == "--skip-spectra") {
      o.spectra = false;
    } else if (a == "--skip-boundaries") {
      o.boundaries = false;
    } else if (a == "--skip-vg") {
      o.vg = false;
    } else if (a == "--skip-jump-check") {
      o.jump_check = o.crossing_check = false;
    } else if (a == "--skip-verify") {
      o.verify = false;
    } else if (a == "--skip-reduced") {
      o.reduced = false;
    } else if (a == "--lco-march") {
      o.lco_march = true;
    } else if (a == "--vg-mach") {
      o.vg_mach = number();
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
      o.vg_points = static_cast<int>(number());
      require(o.vg_points >= 2, "--vg-points must be >= 2");
    } else if (a == "--crossing-medium") {
      o.crossing_medium = true;
    } else if (a == "--quick") {
      o.quick = true;
    } else {
      throw input_error("unknown option " + a);
    }
  }
  check_mach_range(o);
  if (o.incidence_deg != 0.0 && (o.spectra || o.jump_check || o.verify || o.reduced)) {
    std::cout << "(--incidence: the spectra, dense jump check, time marching and reduced-model parts assume zero "
                 "incidence; skipped; the driver's crossing check is a V-g scan)\n";
    o.spectra = o.jump_check = o.verify = o.reduced = false;
  }
  if (o.quick) {
    o.jump_check = o.crossing_check = false;
    o.grids = {level_named("coarse")};
    o.verify_grid = level_named("coarse");
    o.mach_step = o.mach_step > 0 ? o.mach_step : 0.1;
    o.mach_max = std::min(o.mach_max, 0.8);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines appear as they are printed
  std::cout << std::unitbuf;
  try {
    const options o = parse(argc, argv);
    std::filesystem::create_directories(o.out);
    const auto t0 = clk::now();
    if (o.spectra) spectra_part(o);
    boundaries all;
    int failed_checks = 0, checks = 0;
    if (o.boundaries) {
      csv_writer crossings(o.out / "crossing_check.csv", "case,grid,mach,ubar_star,omega_star,ubar,omega");
      all = boundaries_part(o, crossings);
      for (const auto& [key, b] : all)
        for (const auto& x : b.checks) {
          ++checks;
          failed_checks += x.pass ? 0 : 1;
        }
      std::printf("  crossing check: %d points checked, %d failed\n", checks, failed_checks);
    }
    if (o.vg) vg_part(o, all);
    if (o.jump_check) failed_checks += jump_check_part(o, all);
    std::vector<double> march_costs;
    if (o.verify) verification_part(o, all, march_costs);
    if (o.reduced) failed_checks += reduced_part(o, all);
    cost_part(o, all, march_costs);
    std::cout << "\ntotal " << seconds_since(t0) << " s; results in " << o.out << "\n";
    if (failed_checks > 0) {
      std::cerr << "aerofoil_flutter: " << failed_checks << " check(s) FAILED\n";
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "aerofoil_flutter: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
