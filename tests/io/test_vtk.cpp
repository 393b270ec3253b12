// VTK output: the file parses back to the right numbers of points and cells, every cell
// references valid points, and a free-stream field gives Cp = 0 and the free-stream Mach number;
// plate modes come back as written; a wing's wall surface has one quad per wall face with the
// model's wall Cp.
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/wing_grid.hpp>
#include <aerohopf/io/vtk.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

using namespace aerohopf;
using namespace aerohopf::flow;

TEST(vtk, free_stream_field_round_trip) {
  const auto g = coarsen(naca_cgrid(), 8);
  euler_model<2> m(g, {.mach = 0.7, .alpha_rad = 0.1});
  const std::string path = ::testing::TempDir() + "/field.vtk";
  io::write_vtk<2>(path, m, m.free_stream_vector());
  std::ifstream in(path);
  std::string word;
  std::size_t npts = 0, ncells = 0, total = 0;
  while (in >> word && word != "POINTS") {}
  in >> npts >> word;
  std::size_t expected_pts = 0;
  for (const auto& b : g.points.blocks) expected_pts += b.n_points();
  EXPECT_EQ(npts, expected_pts);
  for (std::size_t k = 0; k < 3 * npts; ++k) in >> word;
  in >> word >> ncells >> total;
  EXPECT_EQ(word, "CELLS");
  EXPECT_EQ(ncells, m.n_cells());
  EXPECT_EQ(total, 5 * ncells);
  for (std::size_t c = 0; c < ncells; ++c) {
    int n = 0;
    in >> n;
    ASSERT_EQ(n, 4);
    for (int k = 0; k < 4; ++k) {
      std::size_t id = 0;
      in >> id;
      EXPECT_LT(id, npts);
    }
  }
  while (in >> word && word != "cp") {}
  in >> word >> word >> word >> word;  // double 1 LOOKUP_TABLE default
  for (std::size_t c = 0; c < ncells; ++c) {
    double cp = 1.0;
    in >> cp;
    EXPECT_NEAR(cp, 0.0, 1e-12);
  }
  while (in >> word && word != "mach") {}
  in >> word >> word >> word >> word;
  double mach = 0.0;
  in >> mach;
  EXPECT_NEAR(mach, 0.7, 1e-12);
}

TEST(vtk, refuses_non_finite_or_wrongly_sized_state_before_opening_the_file) {
  const auto g = coarsen(naca_cgrid(), 8);
  euler_model<2> m(g, {.mach = 0.7, .alpha_rad = 0.1});
  const std::string path = ::testing::TempDir() + "/refused_field.vtk";
  std::remove(path.c_str());
  vec<double> w = m.free_stream_vector();
  w[4 * 7 + 2] = std::nan("");  // cell 7
  try {
    io::write_vtk<2>(path, m, w);
    ADD_FAILURE() << "a NaN state was written";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("write_vtk: state entry 30"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::ifstream(path).good()) << "the refused state left a file behind";
  const vec<double> short_w = m.free_stream_vector().head(m.size() - 1);
  EXPECT_THROW(io::write_vtk<2>(path, m, short_w), input_error);
  EXPECT_FALSE(std::ifstream(path).good());
}

TEST(vtk, plate_modes_round_trip) {
  using namespace aerohopf::structure;
  const plate_mesh mesh = structured_plate_mesh(
      4, 3, [](double s, double r) { return Eigen::Vector2d(s, 0.5 * r); }, [](double, double) { return 0.01; });
  plate_constraints c(mesh.nodes.size());
  for (int j = 0; j <= 3; ++j) c.clamp(5 * j);
  const plate_modes md = plate_modes_of(mesh, isotropic_material(1e9, 0.3, 1000), c, {.count = 2});
  const std::string path = ::testing::TempDir() + "/plate_modes.vtk";
  io::write_vtk_plate_modes(path, mesh, md);
  std::ifstream in(path);
  std::string line, word;
  std::size_t n = 0;
  bool found = false;
  while (std::getline(in, line)) {
    if (line.rfind("POINTS", 0) == 0) {
      std::istringstream(line) >> word >> n;
      EXPECT_EQ(n, mesh.nodes.size());
    }
    if (line == "SCALARS mode_2_w double 1") {
      found = true;
      std::getline(in, line);  // lookup table
      for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
        double w = 0;
        in >> w;
        EXPECT_NEAR(w, md.shapes(static_cast<Eigen::Index>(3 * i), 1), 1e-10 * md.shapes.cwiseAbs().maxCoeff());
      }
      break;
    }
  }
  EXPECT_TRUE(found) << "mode 2 deflection not in the file";
  plate_modes bad = md;
  bad.shapes.conservativeResize(bad.shapes.rows() - 3, Eigen::NoChange);
  EXPECT_THROW(io::write_vtk_plate_modes(path, mesh, bad), input_error);
}

TEST(vtk, wing_wall_surface_has_every_wing_face) {
  const auto g = coarsen(wing_cgrid(agard445_6()), 8);
  euler_model<3> m(g, {.mach = 0.5, .alpha_rad = 0.02}, {.force_tag = "wing"});
  const vec<double> w = m.free_stream_vector();
  const std::string path = ::testing::TempDir() + "/wing_surface.vtk";
  io::write_vtk_wall_surface(path, m, w);
  std::ifstream in(path);
  std::string line, word;
  std::size_t cells = 0;
  double cp_sum = 0;
  while (std::getline(in, line)) {
    if (line.rfind("CELLS", 0) == 0) std::istringstream(line) >> word >> cells;
    if (line == "SCALARS cp double 1") {
      std::getline(in, line);
      for (std::size_t c = 0; c < cells; ++c) {
        double v = 0;
        in >> v;
        cp_sum += v;
      }
      break;
    }
  }
  const auto faces = m.wall_faces(w);
  EXPECT_EQ(cells, faces.size());
  const wing_grid_options o;
  EXPECT_EQ(cells, static_cast<std::size_t>(2 * o.section_cells / 8 * o.span_cells / 8));
  double want = 0;
  for (const auto& f : faces) want += f.cp;
  EXPECT_NEAR(cp_sum, want, 1e-9 * (1 + std::abs(want)));
  vec<double> bad = w;
  bad[3] = NAN;
  EXPECT_THROW(io::write_vtk_wall_surface(path, m, bad), input_error);
}
