// VTK output: the file parses back to the right numbers of points and cells, every cell
// references valid points, and a free-stream field gives Cp = 0 and the free-stream Mach number.
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
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
