// AGARD 445.6 weakened model 3 (spec 06): the structural modes from our own plate finite
// elements (structure/plate_fe.hpp): the planform and NACA 65A004 thickness of
// flow/wing_geometry.hpp, the orthotropic laminated mahogany with its fibre along the 45 deg
// quarter-chord line, clamped root. Prints a mesh-convergence table of the first five frequencies
// against Yates' calculated ones and the original work's FE model, and writes the modes.
//
// Usage: agard445 [out_dir] [--mesh NI,NJ] [--modes K]
//   --mesh NI,NJ   chordwise x spanwise quads of the modal mesh (default 24,24)
//   --modes K      modes written (default 5)
// Outputs under out_dir (default out/agard445):
//   modes.csv          mode,frequency_hz,generalised_mass  (generalised mass of the mode scaled to a
//                      largest deflection of 1 m, kg; the shapes are mass-normalised otherwise)
//   mode_shapes.csv    mode,x,y,w  (x streamwise, y spanwise, m; w scaled to a largest |w| of 1)
//   modes.vtk          the mesh with thickness and every mode (ParaView: Warp By Vector)
//   modal_data.csv     the modes in the documented modal CSV (structure/modal_data.hpp)
//   modes.bdf, modes.pch   the same as NASTRAN GRID* bulk data and punch eigenvectors
// Both exchange formats are read back and compared with the modes written (exit status 1 if not).
// plot_modes.py in this folder turns mode_shapes.csv into modes.png.
#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/io/nastran.hpp>
#include <aerohopf/io/vtk.hpp>
#include <aerohopf/structure/modal_data.hpp>
#include <aerohopf/structure/plate_fe.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

using namespace aerohopf;

namespace {

struct options {
  std::filesystem::path out = "out/agard445";
  int ni = 24, nj = 24;
  int modes = 5;
};

options parse(int argc, char** argv) {
  options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      require(i + 1 < argc, "option ", a, " needs a value");
      return argv[++i];
    };
    if (a == "--mesh") {
      const std::string v = next();
      const auto comma = v.find(',');
      require(comma != std::string::npos, "--mesh takes NI,NJ (chordwise,spanwise quads), not ", v);
      try {
        o.ni = std::stoi(v.substr(0, comma));
        o.nj = std::stoi(v.substr(comma + 1));
      } catch (const std::exception&) {
        throw input_error("--mesh takes two integers NI,NJ, not '" + v + "'");
      }
      require(o.ni >= 2 && o.nj >= 2 && o.ni <= 400 && o.nj <= 400, "--mesh: NI and NJ in [2, 400] (got ", o.ni, ",",
              o.nj, ")");
    } else if (a == "--modes") {
      const std::string v = next();
      try {
        o.modes = std::stoi(v);
      } catch (const std::exception&) {
        throw input_error("--modes takes an integer, not '" + v + "'");
      }
      require(o.modes >= 1 && o.modes <= 20, "--modes must lie in [1, 20] (got ", o.modes, ")");
    } else if (!a.empty() && a[0] != '-') {
      o.out = a;
    } else {
      throw input_error("unknown option " + a);
    }
  }
  return o;
}

/// Laminated mahogany of the weakened model 3 (spec 06), fibre along the quarter-chord line.
structure::orthotropic_material mahogany(const flow::wing_planform& p) {
  structure::orthotropic_material m;
  m.e1 = 3.1511e9;
  m.e2 = 0.4162e9;
  m.g12 = 0.4392e9;
  m.nu12 = 0.31;
  m.density = 381.98;
  m.fibre_angle = std::atan(p.sweep_tan(0.25));
  return m;
}

/// Structured mesh over the planform (uniform in chord fraction and span), thickness of the
/// section; the root nodes (j = 0) are clamped.
structure::plate_mesh wing_mesh(const flow::wing_geometry& w, int ni, int nj) {
  return structure::structured_plate_mesh(
      ni, nj,
      [&](double s, double r) {
        const double y = r * w.planform.semi_span;
        return Eigen::Vector2d(w.planform.x_at(s, y), y);
      },
      [&](double x, double y) { return w.thickness(x, y); });
}

struct solved {
  structure::plate_mesh mesh;
  structure::plate_modes modes;
  double mass = 0, seconds = 0;
};

solved modes_on(const flow::wing_geometry& w, int ni, int nj, int count) {
  const auto t0 = std::chrono::steady_clock::now();
  solved s;
  s.mesh = wing_mesh(w, ni, nj);
  structure::plate_constraints c(s.mesh.nodes.size());
  for (int i = 0; i <= ni; ++i) c.clamp(i);
  const structure::plate_matrices km = structure::assemble_plate(s.mesh, mahogany(w.planform));
  s.mass = structure::plate_mass(km);
  structure::plate_mode_options mo;
  mo.count = count;
  s.modes = structure::plate_modes_of(km, c, mo);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
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
  solved chosen;
  for (int n : {6, 12, 24, 48}) {
    const bool is_chosen = n == o.ni && n == o.nj;
    const solved s = modes_on(w, n, n, shown);
    std::printf("  %-10s %9.4f", (std::to_string(n) + "x" + std::to_string(n)).c_str(), s.mass);
    for (int k = 0; k < 5; ++k) std::printf(" %8.2f", s.modes.frequency_hz(k));
    std::printf(" %9.3f\n", s.seconds);
    if (is_chosen) chosen = s;
  }
  if (chosen.mesh.nodes.empty()) {
    chosen = modes_on(w, o.ni, o.nj, shown);
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
  std::cout << "results in " << o.out
            << " (modes.csv, mode_shapes.csv, modes.vtk, modal_data.csv, modes.bdf, modes.pch; plot: python3 "
            << "examples/agard445/plot_modes.py " << o.out.string() << ")\n";
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::cerr << "agard445: " << e.what() << "\n";
  return 2;
}
