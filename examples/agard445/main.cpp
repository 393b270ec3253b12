// AGARD 445.6 weakened model 3 (spec 06):
//  1. the structural modes from our own plate finite elements (structure/plate_fe.hpp): the
//     planform and NACA 65A004 thickness of flow/wing_geometry.hpp, the orthotropic laminated
//     mahogany with its fibre along the 45 deg quarter-chord line, clamped root; a mesh-convergence
//     table of the first five frequencies against Yates' and the original work's;
//  2. the C-H flow grids (flow/wing_grid.hpp): every level's size and cell quality, Plot3D files;
//  3. the steady flow at M = 0.5, alpha = 0 and 1 deg on one level: CL, the lift slope against
//     lifting-surface theory (vortex lattice, DATCOM), the wall Cp for ParaView;
//  4. the flutter boundary of the flexible wing (four modes, flutter.hpp): flutter speed index
//     and frequency ratio against Mach number per grid level and structural damping, by the
//     library's flutter-boundary driver, against the experiment; the V-g / V-f diagram.
//
// Usage: agard445 [out_dir] [--mesh NI,NJ] [--modes K] [--steady LEVEL] [--fine-grid]
//                 [--flutter LEVELS] [--damping PERCENTS] [--machs LIST] [--vg LEVEL] [--vg-mach M]
//   --mesh NI,NJ   chordwise x spanwise quads of the modal mesh (default 24,24)
//   --modes K      modes written (default 5; the flutter part uses the first four)
//   --steady L     level of the steady solutions: very_coarse, coarse (default), medium, none
//   --fine-grid    also write the fine level's Plot3D file (1.5 M points, 37 MB)
//   --flutter L    boundary levels, e.g. coarse,medium (default; none: no boundaries)
//   --damping P    structural damping ratios in percent on the coarsest level (default 0,0.5,2)
//   --fine-damping P   those of them also run on the finer levels (default 0.5), each from the coarser
//                  level's boundary, or where that fails from this level's at the nearest damping done
//   --machs LIST   Mach numbers of the boundaries (default 0.499,0.678,0.901,0.96, the experiment's)
//   --vg L         V-g / V-f diagram on level L (default none)   --vg-mach M (default 0.96)
//   --march L      time-marching verification at 0.95 / 1.05 mu* on level L at the V-g Mach number
//   --verbose      a line per Newton iteration of the boundaries and per step of their steady solves
// Outputs under out_dir (default out/agard445):
//   modes.csv          mode,frequency_hz,generalised_mass  (generalised mass of the mode scaled to a
//                      largest deflection of 1 m, kg; the shapes are mass-normalised otherwise)
//   mode_shapes.csv    mode,x,y,w  (x streamwise, y spanwise, m; w scaled to a largest |w| of 1)
//   modes.vtk          the mesh with thickness and every mode (ParaView: Warp By Vector)
//   modal_data.csv     the modes in the documented modal CSV (structure/modal_data.hpp)
//   modes.bdf, modes.pch   the same as NASTRAN GRID* bulk data and punch eigenvectors
//   grid_<level>.xyz   Plot3D (binary, whole, 3D, one block) of very_coarse, coarse, medium (fine)
//   grid_quality.csv   level,points,cells,wing_points,min_volume,min_corner_ratio,collinear_cells,tip_min_corner_ratio
//   steady_<level>.csv mach,alpha_deg,cl,cd,steps,gmres_iterations,seconds (CL, CD on the half-wing area)
//   lift_slope.csv     level,mach,euler_per_rad,vortex_lattice_per_rad,datcom_per_rad
//   surface_<level>_M0.50_alpha1.vtk   the wing's wall Cp (ParaView)
//   boundary_<level>_zeta<percent>.csv
//                      mach,fsi,frequency_ratio,mass_ratio,q,omega,newton_iterations,linear_iterations,
//                      hopf_seconds,steady_seconds  (q: flutter dynamic pressure rho U^2 / 2, Pa;
//                      omega: flutter frequency in the flow's time unit c / U)
//   experiment.csv     mach,density,speed,mass_ratio,fsi,frequency_ratio (spec 06)
//   vg_M<mach>_<level>.csv, vg_flutter_M<mach>_<level>.csv   the V-g diagram (parameter mu = rho c^3)
//   costs.csv          level,damping_percent,quantity,value (Hopf work per steady solve, seconds)
//   flutter_mode_<level>_zeta<percent>_M0.96_phase<k>.vtk   the flutter mode at M = 0.96: the wing
//                      deflected (5 % of the root chord at most) and its Cp at phases k pi / 2
//   verification.csv, history_M<mach>_<level>_<factor>.csv   time marching (--march)
// Both exchange formats are read back and compared with the modes written (exit status 1 if not).
// plot_modes.py in this folder turns mode_shapes.csv into modes.png, plot_flutter.py the
// boundaries and the V-g diagram into flutter_boundary.png and vg.png.
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/flow/vortex_lattice.hpp>
#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/io/nastran.hpp>
#include <aerohopf/io/plot3d.hpp>
#include <aerohopf/io/vtk.hpp>
#include <aerohopf/structure/modal_data.hpp>
#include <aerohopf/structure/plate_fe.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "../common/cli.hpp"
#include "flutter.hpp"

using namespace aerohopf;

namespace {

struct options {
  std::filesystem::path out = "out/agard445";
  int ni = 24, nj = 24;
  int modes = 5;
  std::string steady = "coarse";
  bool fine_grid = false;
  agard445_flutter::flutter_options flutter;
};

options parse(int argc, char** argv) {
  options o;
  example_cli::arguments args(argc, argv);
  for (std::string a; args.next(a);) {
    if (agard445_flutter::read_mesh_option(a, args, o.ni, o.nj)) {
      continue;
    } else if (a == "--modes") {
      o.modes = args.integer();
      require(o.modes >= 1 && o.modes <= 20, "--modes must lie in [1, 20] (got ", o.modes, ")");
    } else if (a == "--steady") {
      o.steady = args.value();
      if (o.steady != "none") agard445_flutter::stride_of(o.steady);
    } else if (a == "--fine-grid") {
      o.fine_grid = true;
    } else if (agard445_flutter::read_boundary_option(a, args, o.flutter)) {
      continue;
    } else if (a == "--vg") {
      const std::string l = args.value();
      o.flutter.vg_stride = l == "none" ? 0 : agard445_flutter::stride_of(l);
    } else if (a == "--march") {
      const std::string l = args.value();
      o.flutter.march_stride = l == "none" ? 0 : agard445_flutter::stride_of(l);
    } else if (a == "--vg-mach") {
      o.flutter.vg_mach = args.number();
      require(o.flutter.vg_mach > 0.3 && o.flutter.vg_mach < 1.3, "--vg-mach must lie in (0.3, 1.3)");
    } else if (!a.empty() && a[0] != '-') {
      o.out = a;
    } else {
      throw input_error("unknown option " + a);
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) try {
  const options o = parse(argc, argv);
  const flow::wing_geometry w = flow::agard445_6();
  std::printf("AGARD 445.6 weakened model 3: %s section, root chord %.4f m, tip chord %.4f m, semi-span %.3f m,\n"
              "  quarter-chord sweep %.2f deg, area %.4f m^2, mean aerodynamic chord %.4f m, t/c %.4f\n",
              w.section.name().c_str(), w.planform.root_chord, w.planform.tip_chord, w.planform.semi_span,
              std::atan(w.planform.sweep_tan(0.25)) * 180 / std::numbers::pi, w.planform.area(),
              w.planform.mean_aerodynamic_chord(), w.section.thickness_ratio());
  const double yates[5] = {9.60, 38.17, 48.35, 91.54, 118.11}, original[4] = {9.7, 36.9, 50.3, 90.0};
  const int shown = std::max(o.modes, 5);
  std::printf("\nplate FE (MITC4, orthotropic, clamped root): frequencies in Hz\n");
  std::printf("  %-10s %9s", "mesh", "mass kg");
  for (int k = 1; k <= 5; ++k) std::printf("   mode %d", k);
  std::printf("   seconds\n");
  agard445_flutter::solved chosen;
  for (int n : {6, 12, 24, 48}) {
    const bool is_chosen = n == o.ni && n == o.nj;
    const agard445_flutter::solved s = agard445_flutter::modes_on(w, n, n, shown);
    std::printf("  %-10s %9.4f", (std::to_string(n) + "x" + std::to_string(n)).c_str(), s.mass);
    for (int k = 0; k < 5; ++k) std::printf(" %8.2f", s.modes.frequency_hz(k));
    std::printf(" %9.3f\n", s.seconds);
    if (is_chosen) chosen = s;
  }
  if (chosen.mesh.nodes.empty()) {
    chosen = agard445_flutter::modes_on(w, o.ni, o.nj, shown);
    std::printf("  %-10s %9.4f", (std::to_string(o.ni) + "x" + std::to_string(o.nj)).c_str(), chosen.mass);
    for (int k = 0; k < 5; ++k) std::printf(" %8.2f", chosen.modes.frequency_hz(k));
    std::printf(" %9.3f\n", chosen.seconds);
  }
  std::printf("  %-10s %9s", "Yates", "");
  for (double f : yates) std::printf(" %8.2f", f);
  std::printf("\n  %-10s %9s", "original", "");
  for (double f : original) std::printf(" %8.2f", f);
  std::printf("\n  %-10s %9s", "ratio", "");
  for (int k = 0; k < 5; ++k) std::printf(" %8.3f", chosen.modes.frequency_hz(k) / yates[k]);
  std::printf("   (mesh %dx%d / Yates)\n", o.ni, o.nj);

  std::filesystem::create_directories(o.out);
  csv_writer modes(o.out / "modes.csv", "mode,frequency_hz,generalised_mass");
  csv_writer shapes(o.out / "mode_shapes.csv", "mode,x,y,w");
  for (int k = 0; k < o.modes; ++k) {
    const Eigen::VectorXd wk = chosen.modes.deflection(k);
    const double scale = wk.cwiseAbs().maxCoeff();
    modes.row({static_cast<long long>(k + 1), chosen.modes.frequency_hz(k), 1.0 / (scale * scale)});
    for (std::size_t i = 0; i < chosen.mesh.nodes.size(); ++i)
      shapes.row({static_cast<long long>(k + 1), chosen.mesh.nodes[i].x(), chosen.mesh.nodes[i].y(),
                  wk[static_cast<Eigen::Index>(i)] / scale});
  }
  structure::plate_modes written = chosen.modes;
  written.shapes.conservativeResize(Eigen::NoChange, o.modes);
  io::write_vtk_plate_modes((o.out / "modes.vtk").string(), chosen.mesh, written);

  // the exchange formats, written and read back
  const structure::modal_data md = structure::modal_data_from_plate(chosen.mesh, written);
  structure::write_modal_csv(o.out / "modal_data.csv", md);
  io::write_nastran_grid(o.out / "modes.bdf", md);
  io::write_nastran_punch(o.out / "modes.pch", md);
  auto worst_difference = [&](const structure::modal_data& r) {
    double d = 0;
    for (Eigen::Index k = 0; k < md.modes(); ++k) {
      const Eigen::MatrixXd& a = md.shapes[static_cast<std::size_t>(k)];
      d = std::max(d, std::abs(r.omega[k] / md.omega[k] - 1));
      d = std::max(d, (r.shapes[static_cast<std::size_t>(k)] - a).cwiseAbs().maxCoeff() / a.cwiseAbs().maxCoeff());
    }
    return d;
  };
  const double d_csv = worst_difference(structure::read_modal_csv(o.out / "modal_data.csv"));
  const double d_nas = worst_difference(io::read_nastran_modes(o.out / "modes.pch", o.out / "modes.bdf"));
  const bool ok = d_csv <= 1e-14 && d_nas <= 1e-8;
  std::printf("\nexchange formats read back: modal CSV differs by %.1e, NASTRAN punch by %.1e (relative): %s\n", d_csv,
              d_nas, ok ? "PASS" : "FAIL");

  // 2. flow grids: the fine level, the others by coarsening (nested)
  const flow::wing_grid_options go;
  const flow::multiblock_grid<3> fine = flow::wing_cgrid(w, go);
  std::printf("\nC-H flow grids (root chords; far field %.0f root chords; quality: corner det J / mean, "
              "collinear = leading-edge cells of the cut beyond the tip)\n",
              go.far_field);
  std::printf("  %-12s %9s %9s %7s %10s %9s %9s %9s\n", "level", "points", "cells", "wing", "min vol", "min ratio",
              "collinear", "tip ratio");
  csv_writer quality(o.out / "grid_quality.csv",
                     "level,points,cells,wing_points,min_volume,min_corner_ratio,collinear_cells,tip_min_corner_ratio");
  for (const std::string level : {"very_coarse", "coarse", "medium", "fine"}) {
    const int s = agard445_flutter::stride_of(level);
    const flow::multiblock_grid<3> g = s == 1 ? fine : flow::coarsen(fine, s);
    const flow::grid_quality q = flow::hexahedron_quality(g);
    const auto [tip_lo, tip_hi] = flow::wing_grid_layout::of(go, s).tip_cells();
    const flow::grid_quality t = flow::hexahedron_quality(g, 0, tip_lo, tip_hi);
    const auto wing_points = static_cast<long long>(flow::wing_grid_layout::of(go, s).wing_points());
    const auto points = static_cast<long long>(g.points.blocks[0].n_points());
    std::printf("  %-12s %9lld %9zu %7lld %10.2e %9.3f %9zu %9.3f\n", level.c_str(), points, q.cells, wing_points,
                q.min_volume, q.min_corner_ratio, q.collinear_cells, t.min_corner_ratio);
    quality.row({level, points, static_cast<long long>(q.cells), wing_points, q.min_volume, q.min_corner_ratio,
                 static_cast<long long>(q.collinear_cells), t.min_corner_ratio});
    if (s > 1 || o.fine_grid) io::write_plot3d<3>((o.out / ("grid_" + level + ".xyz")).string(), g.points, io::plot3d_format::binary);
  }

  // 3. steady flow at M = 0.5 and the lift slope
  if (o.steady != "none") {
    const int s = agard445_flutter::stride_of(o.steady);
    const flow::multiblock_grid<3> g = s == 1 ? fine : flow::coarsen(fine, s);
    const double mach = 0.5, area = w.planform.area() / (w.planform.root_chord * w.planform.root_chord);
    csv_writer steady(o.out / ("steady_" + o.steady + ".csv"), "mach,alpha_deg,cl,cd,steps,gmres_iterations,seconds");
    std::printf("\nsteady Euler, %s level, M = %.2f (CL, CD on the half-wing area)\n", o.steady.c_str(), mach);
    double cl[2] = {0, 0};
    for (int a = 0; a < 2; ++a) {
      flow::euler_model<3> m(g, {.mach = mach, .alpha_rad = a * std::numbers::pi / 180}, {.force_tag = "wing"});
      vec<double> st = m.free_stream_vector();
      const flow::steady_report rep = flow::solve_steady<3>(m, st, {});
      const auto f = m.forces(st);
      cl[a] = f.cl / area;
      std::printf("  alpha %d deg: CL %.5f  CD %.6f  (%d Newton steps, %d GMRES, ||R|| %.1e -> %.1e, %.1f s)\n", a, cl[a],
                  f.cd / area, rep.steps, rep.linear_iterations, rep.initial_residual, rep.final_residual, rep.seconds);
      steady.row({mach, static_cast<double>(a), cl[a], f.cd / area, static_cast<long long>(rep.steps),
                  static_cast<long long>(rep.linear_iterations), rep.seconds});
      if (a == 1) io::write_vtk_wall_surface((o.out / ("surface_" + o.steady + "_M0.50_alpha1.vtk")).string(), m, st);
    }
    const double euler = (cl[1] - cl[0]) * 180 / std::numbers::pi;
    const double vlm = flow::vortex_lattice_lift_slope(w.planform, mach, 16, 48).lift_slope;
    const double datcom = flow::datcom_lift_slope(w.planform, mach);
    std::printf("  lift slope per radian: Euler %.4f, vortex lattice %.4f (Euler / VLM %.3f), DATCOM %.4f\n", euler, vlm,
                euler / vlm, datcom);
    csv_writer slope(o.out / "lift_slope.csv", "level,mach,euler_per_rad,vortex_lattice_per_rad,datcom_per_rad");
    slope.row({o.steady, mach, euler, vlm, datcom});
  }
  // 4. the flutter boundaries and the V-g diagram (four modes)
  if (!o.flutter.strides.empty() || o.flutter.vg_stride || o.flutter.march_stride) {
    const structure::modal_data four = agard445_flutter::first_four(md);
    csv_writer exp(o.out / "experiment.csv", "mach,density,speed,mass_ratio,fsi,frequency_ratio");
    for (const auto& e : agard445_flutter::experiment())
      exp.row({e.mach, e.density, e.speed, e.mass_ratio, e.fsi, e.frequency_ratio});
    if (!o.flutter.strides.empty()) {
      const auto runs = agard445_flutter::boundaries(
          o.flutter, o.out, w, go, four, [](const models::wing_family& f) -> const models::wing_family& { return f; }, [](auto&& fn) { fn(); },
          &std::cout);
      agard445_flutter::write_costs(o.out / "costs.csv", runs, o.flutter.machs);
    }
    if (o.flutter.vg_stride) agard445_flutter::vg(o.flutter, o.out, w, go, four);
    if (o.flutter.march_stride) agard445_flutter::march(o.flutter, o.flutter.march_stride, o.out, w, go, four);
  }
  std::cout << "\nresults in " << o.out
            << " (modes.csv, mode_shapes.csv, modes.vtk, modal_data.csv, modes.bdf, modes.pch, grid_*.xyz, "
               "grid_quality.csv, steady_*.csv, lift_slope.csv, surface_*.vtk, boundary_*.csv, experiment.csv, costs.csv; "
               "plots: python3 examples/agard445/plot_modes.py "
            << o.out.string() << "; python3 examples/agard445/plot_flutter.py " << o.out.string() << ")\n";
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::cerr << "agard445: " << e.what() << "\n";
  return 2;
}
