// The flutter boundary Ubar(M) of the pitch-plunge NACA 0012 (spec 05) traced from ONE start by
// pseudo-arclength continuation of the fixed-equilibrium Hopf curve with Krylov linear algebra, the
// steady flow an unknown of the corrector (or a nested steady solve per Mach number)
// (trace_fixed_equilibrium_hopf_curve, bifurcation/hopf_curve_fixed_equilibrium.hpp): through the steep transonic branches of the heavy case (M ~ 0.83
// and 0.89) where natural continuation in M stops, at grid sizes where the full-system tracer
// (hopf_curve.hpp, sparse LU) is too expensive.
//
// Usage: aerofoil_branch [--grid very_coarse|coarse|medium] [--case heavy|light]
//                        [--mach-min 0.78] [--mach-max 0.95] [--out out/aerofoil_flutter]
//                        [--fill k] [--max-points N] [--max-step ds]
//                        [--mu-scale s] [--nu-scale s] [--omega-scale s]   (metric, default 0.5 0.01 0.05)
//                        [--corrector joint|nested]   (default joint; nested: a steady solve at every M the
//                        corrector visits; joint: the flow as an unknown of the corrector, one steady
//                        Newton step per iteration, nested after a failed attempt)
// Start: steady flow at mach-min from the free stream, inverse power at the case's (Ubar, omega)
// guess, solve_hopf_krylov (as main.cpp). Every crossing of M = 0.01 k is landed exactly.
// Output: <out>/hopf_curve_sym_<case>_<grid>.csv
//   mach,ubar,omega,newton_iterations,linear_iterations,step,seconds,landed
// and a summary: points, turning points of the curve in M (and extrema of Ubar), cost per
// point against one steady solve from the free stream.
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_curve_fixed_equilibrium.hpp>
#include <aerohopf/io/csv.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "../common/cli.hpp"
#include "setup.hpp"

using namespace aerohopf;
using namespace aerofoil_example;

namespace {

struct options {
  std::filesystem::path out = "out/aerofoil_flutter";
  grid_level grid = level_named("coarse");
  structural_case scase = heavy_case;
  double mach_min = 0.78, mach_max = 0.95;
  int fill = 1;
  int max_points = 400;
  double mu_scale = 0.5, nu_scale = 0.01, omega_scale = 0.05;  // metric of the arclength
  double max_step = 1.0;
  bool joint = true;  // fixed_equilibrium_hopf_curve_options::joint_equilibrium (--corrector)
};

/// Vertex of the parabola through three points (x_k, y_k): a turning point of y(x)... located
/// by fitting x as a quadratic in y (smooth through a turn of x) and returning (x*, y*).
std::pair<double, double> parabola_vertex(const double* x, const double* y) {
  // x = a + b y + c y^2 through the three points
  const double y0 = y[0], y1 = y[1], y2 = y[2];
  const double d01 = (x[1] - x[0]) / (y1 - y0), d12 = (x[2] - x[1]) / (y2 - y1);
  const double c = (d12 - d01) / (y2 - y0);
  const double b = d01 - c * (y0 + y1);
  if (!(std::abs(c) > 0)) return {x[1], y[1]};
  const double ys = -b / (2 * c);
  return {x[1] + b * (ys - y1) + c * (ys * ys - y1 * y1), ys};
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::cout << std::unitbuf;
  options o;
  try {
    example_cli::arguments args(argc, argv);
    for (std::string a; args.next(a);) {
      if (a == "--grid") o.grid = level_named(args.value());
      else if (a == "--case") o.scase = case_named(args.value());
      else if (a == "--mach-min") o.mach_min = args.number();
      else if (a == "--mach-max") o.mach_max = args.number();
      else if (a == "--out") o.out = args.value();
      else if (a == "--fill") o.fill = args.integer();
      else if (a == "--max-points") o.max_points = args.integer();
      else if (a == "--nu-scale") o.nu_scale = args.number();
      else if (a == "--mu-scale") o.mu_scale = args.number();
      else if (a == "--omega-scale") o.omega_scale = args.number();
      else if (a == "--max-step") o.max_step = args.number();
      else if (a == "--corrector") o.joint = joint_corrector(args.value(), a);
      else throw input_error("unknown option " + a);
    }
    require(o.mach_min < o.mach_max, "--mach-min must be below --mach-max");
    const grid_level& g = o.grid;
    const structural_case& c = o.scase;
    const double m0 = o.mach_min;

    const auto s0 = make_system(g, m0, c.mu_s);
    const steady_result st0 = steady(s0);
    std::printf("%s case (mu_s = %g), %s grid (%ld unknowns), M = %.4f .. %.4f; steady solve from the free stream at "
                "M = %.4f: %.3f s\n",
                c.name.c_str(), c.mu_s, g.name.c_str(), static_cast<long>(s0.size()), m0, o.mach_max, m0, st0.seconds);
    hopf_point guess = hopf_start(s0, st0.w, c.ubar_guess, c.omega_guess);
    guess.mu = c.ubar_guess;

    auto family = [&](double mach) { return make_system(g, mach, c.mu_s); };
    tracer_options to = aerofoil_tracer_options(g, c, m0, o.mach_max, o.fill, o.mu_scale, o.nu_scale, o.omega_scale,
                                                o.max_step);
    hopf_curve_options& ho = to.curve;
    ho.max_points = o.max_points;
    fixed_equilibrium_hopf_curve_options& so = to.fixed_equilibrium;
    so.joint_equilibrium = o.joint;
    csv_writer csv(o.out / ("hopf_curve_sym_" + c.name + "_" + g.name + ".csv"),
                   "mach,ubar,omega,newton_iterations,linear_iterations,step,seconds,landed");
    so.observer = [&](const hopf_curve_point& p, const fixed_equilibrium_hopf_curve_stats& s) {
      // Ubar enters only through 1/Ubar^2 (spec 05): -Ubar is the same point; report |Ubar|
      csv.row({p.nu, std::abs(p.mu), p.omega, static_cast<long long>(p.newton_iterations),
               static_cast<long long>(s.linear_iterations), p.step, p.seconds, static_cast<long long>(p.landed)});
    };
    const auto r = trace_fixed_equilibrium_hopf_curve<4>(family, m0, guess, ho, +1, so);

    // ---- summary ----
    const auto& pts = r.points;
    std::printf("\n%zu points (%s corrector), stop: %s\n%d failed correctors, %d steps at fixed Mach or Ubar (kinks), %ld "
                "GMRES iterations (Hopf system), %d nested steady solves, %d steady Newton steps (%.1f s), total %.1f s\n",
                pts.size(), o.joint ? "joint" : "nested", r.stop_reason.c_str(), r.failed_correctors, r.kink_steps,
                r.linear_iterations, r.steady_solves, r.steady_iterations, r.steady_seconds, r.seconds);
    if (!r.missed_targets.empty()) {
      std::printf("missed Mach targets:");
      for (double m : r.missed_targets) std::printf(" %.4f", m);
      std::printf("\n");
    }
    int turns = 0;
    for (std::size_t k = 1; k + 1 < pts.size(); ++k) {
      const double a = pts[k].nu - pts[k - 1].nu, b = pts[k + 1].nu - pts[k].nu;
      if (a * b < 0) {
        ++turns;
        const double m[3] = {pts[k - 1].nu, pts[k].nu, pts[k + 1].nu};
        const double u[3] = {std::abs(pts[k - 1].mu), std::abs(pts[k].mu), std::abs(pts[k + 1].mu)};
        const auto [mv, uv] = parabola_vertex(m, u);
        std::printf("turning point in M (%s): point %zu M = %.6f Ubar = %.5f omega = %.5f; parabola vertex M = %.6f "
                    "Ubar = %.5f\n",
                    a > 0 ? "maximum" : "minimum", k, pts[k].nu, std::abs(pts[k].mu), pts[k].omega, mv, uv);
      }
      const double ua = std::abs(pts[k].mu) - std::abs(pts[k - 1].mu), ub = std::abs(pts[k + 1].mu) - std::abs(pts[k].mu);
      if (ua * ub < 0)
        std::printf("extremum of Ubar (%s): point %zu M = %.6f Ubar = %.5f omega = %.5f\n", ua > 0 ? "maximum" : "minimum",
                    k, pts[k].nu, std::abs(pts[k].mu), pts[k].omega);
    }
    std::printf("turning points in M: %d\n", turns);
    double secs = 0, steady_secs = 0;
    long lin = 0;
    int steadies = 0;
    for (std::size_t k = 1; k < pts.size(); ++k) {
      secs += pts[k].seconds;
      steady_secs += r.stats[k].steady_seconds;
      lin += r.stats[k].linear_iterations;
      steadies += r.stats[k].steady_solves;
    }
    if (pts.size() > 1) {
      const double np = static_cast<double>(pts.size() - 1);
      std::printf("per point (after the start, including failed attempts): %.3f s = %.2f steady solves from the free "
                  "stream (%.3f s); %.1f GMRES iterations, %.1f nested steady solves (%.3f s)\n",
                  secs / np, secs / np / st0.seconds, st0.seconds, lin / np, steadies / np, steady_secs / np);
    }
    std::printf("curve: %s\n", csv.path().string().c_str());
    return r.stop == hopf_curve_stop::step_failure ? 2 : 0;
  } catch (const std::exception& e) {
    std::cerr << "aerofoil_branch: " << e.what() << "\n";
    return 1;
  }
}
