// Steady Euler flow around the NACA 0012 on the four C-grid levels (spec 05):
//   M = 0.8, alpha = 1.25 deg on very coarse, coarse, medium and fine grids (forces.csv),
//   M = 0.8, alpha = 0 on the medium and fine grids (Cp comparison),
//   M = 0.5, alpha = 0 on the very coarse and medium grids (CL = 0 to rounding).
// Writes, into the output directory (default out/naca0012_steady):
//   forces.csv   grid,cells,mach,alpha_deg,cl,cd,cm,iterations,seconds
//   cp_M<mach>_a<alpha>_<grid>.csv   wall x, y, Cp
//   field_M0.80_a1.25_fine.vtk       the fine-grid field for ParaView
//   naca0012_fine.xyz                the fine grid (Plot3D, binary)
// Then run: /usr/bin/python3 plot_cp.py <output directory>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/io/plot3d.hpp>
#include <aerohopf/io/vtk.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>

using namespace aerohopf;
using namespace aerohopf::flow;

namespace {

struct level {
  const char* name;
  int stride;
};

std::string case_tag(double mach, double alpha_deg) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "M%.2f_a%.2f", mach, alpha_deg);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : "out/naca0012_steady";
  std::filesystem::create_directories(out);
  const auto fine = naca_cgrid();
  io::write_plot3d<2>((out / "naca0012_fine.xyz").string(), fine.points, io::plot3d_format::binary);

  std::ofstream forces(out / "forces.csv");
  forces << "grid,cells,mach,alpha_deg,cl,cd,cm,iterations,seconds\n";
  auto run = [&](const level& lev, double mach, double alpha_deg, bool vtk) {
    const auto grid = coarsen(fine, lev.stride);
    euler_options eo;
    eo.vortex_far_field = true;  // compressible point-vortex far field (see README)
    euler_model<2> model(grid, {.mach = mach, .alpha_rad = alpha_deg * std::numbers::pi / 180.0}, eo);
    auto w = model.free_stream_vector();
    steady_options opt;
    opt.exact_switch_drop = 1e-3;
    opt.log = &std::cout;
    std::cout << "== " << lev.name << " grid (" << model.n_cells() << " cells), M = " << mach
              << ", alpha = " << alpha_deg << " deg\n";
    const auto rep = solve_steady<2>(model, w, opt);
    const auto f = model.forces(w);
    char line[256];
    std::snprintf(line, sizeof line, "%s,%zu,%.3f,%.3f,%.8g,%.8g,%.8g,%d,%.2f\n", lev.name, model.n_cells(), mach,
                  alpha_deg, f.cl, f.cd, f.cm, rep.steps, rep.seconds);
    forces << line << std::flush;
    std::cout << "   CL " << f.cl << "  CD " << f.cd << "  CM " << f.cm << "  (" << rep.steps << " steps, "
              << rep.linear_iterations << " GMRES iterations, " << rep.seconds << " s)\n";
    std::ofstream cp(out / ("cp_" + case_tag(mach, alpha_deg) + "_" + lev.name + ".csv"));
    cp << "x,y,cp\n";
    cp.precision(10);
    for (const auto& wf : model.wall_faces(w)) cp << wf.centre[0] << ',' << wf.centre[1] << ',' << wf.cp << '\n';
    if (vtk) io::write_vtk<2>((out / ("field_" + case_tag(mach, alpha_deg) + "_" + lev.name + ".vtk")).string(), model, w);
  };

  const level very_coarse{"very_coarse", 8}, coarse{"coarse", 4}, medium{"medium", 2}, fine_level{"fine", 1};
  for (const auto& lev : {very_coarse, coarse, medium, fine_level}) run(lev, 0.8, 1.25, lev.stride == 1);
  for (const auto& lev : {medium, fine_level}) run(lev, 0.8, 0.0, false);
  for (const auto& lev : {very_coarse, medium}) run(lev, 0.5, 0.0, false);
  std::cout << "results in " << out << "\n";
  return 0;
}
