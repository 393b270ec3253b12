// NASTRAN modal data: our plate modes written as GRID* bulk data and punch output and read back
// (9 significant digits); hand-written files in the small-field, free-field and large-field GRID
// forms with NASTRAN's real formats (implicit exponent, D exponent, trailing point); and the
// refusals of malformed files, each naming the file and line.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/io/nastran.hpp>

#include <cmath>
#include <fstream>
#include <string>

using namespace aerohopf;
using namespace aerohopf::structure;

namespace {
std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const std::string grid_small =
    "$ three points\n"
    "GRID           1       0      0.      0.      0.\n"
    "GRID           2           1.5-1     2.0      0.\n"
    "GRID,3,,0.25,1.0D-1,-1.\n"
    "GRID*                  4               0 1.000000000E+00 2.000000000E+00\n"
    "*       -3.000000000E-01\n"
    "CQUAD4         1       1       1       2       3       4\n";

const std::string punch_two_modes =
    "$TITLE   = TEST                                                               1\n"
    "$EIGENVECTOR                                                                  2\n"
    "$EIGENVALUE =  3.9478418E+03  MODE =     1                                     3\n"
    "         1       G      0.000000E+00      0.000000E+00      1.000000E+00       4\n"
    "-CONT-                  1.000000E-01      0.000000E+00      0.000000E+00       5\n"
    "         2       G      0.000000E+00      0.000000E+00      5.000000E-01       6\n"
    "-CONT-                  0.000000E+00     -2.000000E-01      0.000000E+00       7\n"
    "         3       G      0.000000E+00      0.000000E+00     -2.500000E-01       8\n"
    "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00       9\n"
    "         4       G      1.000000E-02      0.000000E+00      7.500000E-01      10\n"
    "-CONT-                  0.000000E+00      0.000000E+00      3.000000E-02      11\n"
    "$EIGENVALUE =  1.5791367E+05  MODE =     2                                    12\n"
    "         4       G      0.000000E+00      0.000000E+00     -1.000000E+00      13\n"
    "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00      14\n"
    "         3       G      0.000000E+00      0.000000E+00      1.000000E+00      15\n"
    "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00      16\n"
    "         2       G      0.000000E+00      0.000000E+00      1.000000E+00      17\n"
    "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00      18\n"
    "         1       G      0.000000E+00      0.000000E+00      2.000000E+00      19\n"
    "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00      20\n";

void expect_refused(const std::string& punch, const std::string& bulk, const std::string& fragment) {
  try {
    io::read_nastran_modes(punch, bulk);
    ADD_FAILURE() << "accepted " << punch << " with " << bulk;
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(Nastran, GridFormsAndRealFormats) {
  const auto pts = io::read_nastran_grid(write_file("grid.bdf", grid_small));
  ASSERT_EQ(pts.size(), 4u);
  EXPECT_EQ(pts[1].id, 2);
  EXPECT_DOUBLE_EQ(pts[1].x[0], 0.15);  // 1.5-1
  EXPECT_DOUBLE_EQ(pts[2].x[1], 0.1);   // 1.0D-1, free field
  EXPECT_DOUBLE_EQ(pts[2].x[2], -1.0);
  EXPECT_DOUBLE_EQ(pts[3].x[2], -0.3);  // large field continuation
}

TEST(Nastran, HandWrittenPunchWithGrid) {
  const modal_data d =
      io::read_nastran_modes(write_file("two.pch", punch_two_modes), write_file("grid2.bdf", grid_small));
  ASSERT_EQ(d.modes(), 2);
  EXPECT_NEAR(d.frequency_hz(0), 10.0, 1e-6);  // 3947.8418 = (2 pi 10)^2
  EXPECT_NEAR(d.frequency_hz(1), 63.245553, 1e-5);
  EXPECT_EQ(d.shapes[0](1, 4), -0.2);
  EXPECT_EQ(d.shapes[0](3, 0), 0.01);
  EXPECT_EQ(d.shapes[1](0, 2), 2.0);  // points in bulk order whatever the punch order
  EXPECT_EQ(d.shapes[1](3, 2), -1.0);
  EXPECT_EQ(d.generalised_mass[1], 1.0);
  const modal_data g = io::read_nastran_modes(write_file("two_b.pch", punch_two_modes),
                                              write_file("grid3.bdf", grid_small), {2.0, 3.0});
  EXPECT_EQ(g.generalised_mass[1], 3.0);
}

TEST(Nastran, PlateModesRoundTrip) {
  const plate_mesh mesh = structured_plate_mesh(
      5, 4, [](double s, double r) { return Eigen::Vector2d(s + 0.3 * r, 0.7 * r); },
      [](double x, double) { return 0.01 * (1 - 0.2 * x); });
  plate_constraints c(mesh.nodes.size());
  for (int j = 0; j <= 4; ++j) c.clamp(6 * j);
  const modal_data d =
      modal_data_from_plate(mesh, plate_modes_of(mesh, isotropic_material(2e9, 0.3, 700), c, {.count = 4}));
  const std::string bulk = ::testing::TempDir() + "/plate.bdf", punch = ::testing::TempDir() + "/plate.pch";
  io::write_nastran_grid(bulk, d);
  io::write_nastran_punch(punch, d);
  const modal_data r = io::read_nastran_modes(punch, bulk);
  ASSERT_EQ(r.modes(), d.modes());
  ASSERT_EQ(r.size(), d.size());
  for (Eigen::Index k = 0; k < d.modes(); ++k) {
    EXPECT_NEAR(r.omega[k], d.omega[k], 1e-7 * d.omega[k]);
    const Eigen::MatrixXd& a = d.shapes[static_cast<std::size_t>(k)];
    EXPECT_LT((r.shapes[static_cast<std::size_t>(k)] - a).cwiseAbs().maxCoeff(), 1e-8 * a.cwiseAbs().maxCoeff());
  }
  for (std::size_t i = 0; i < d.size(); ++i) EXPECT_LT((r.points[i] - d.points[i]).norm(), 1e-9);
}

TEST(Nastran, MalformedFilesAreRefusedWithTheirLine) {
  const std::string bulk = write_file("grid_ok.bdf", grid_small);
  expect_refused(write_file("p_none.pch", "$TITLE = nothing\n"), bulk, "no $EIGENVALUE lines");
  // one edit of the good punch file each: what is replaced, by what, and the message expected
  struct edit {
    const char* find;
    std::size_t length;
    const char* replacement;
    const char* message;
  };
  const edit edits[] = {
      {"-CONT-                  0.000000E+00     -2.0", 6, "     9", "line 7:"},
      {"         3       G      0.000000E+00      0.000000E+00     -2.5", 10, "        77", "point 77 has no GRID entry"},
      {"3.9478418E+03", 13, "-3.9478418E+3", "negative eigenvalue"},
      {"5.000000E-01", 12, "5.00000xE-01", "line 6: translations T1 T2 T3 value '5.00000xE-01'"},
      {"         2       G      0.000000E+00      0.000000E+00      1.0", 18, "         2       S", "type 'S'"},
  };
  int n = 0;
  for (const edit& e : edits) {
    std::string p = punch_two_modes;
    const auto at = p.find(e.find);
    ASSERT_NE(at, std::string::npos) << e.find;
    p.replace(at, e.length, e.replacement);
    expect_refused(write_file("p_edit" + std::to_string(n++) + ".pch", p), bulk, e.message);
  }
  // a mode that misses a point
  const std::string p =
      punch_two_modes.substr(0, punch_two_modes.find("         1       G      0.000000E+00      0.000000E+00      2.0"));
  expect_refused(write_file("p_missing.pch", p), bulk, "mode 2 has no values for GRID 1");
  expect_refused(write_file("p_ok.pch", punch_two_modes),
                 write_file("grid_cp.bdf", "GRID           1       5      0.      0.      0.\n"),
                 "coordinate system CP = 5");
  expect_refused(write_file("p_ok2.pch", punch_two_modes), write_file("grid_bad.bdf", "GRID           1       0      0.   abc      0.\n"),
                 "line 1: GRID 1 coordinate X2 'abc'");
  expect_refused(write_file("p_ok3.pch", punch_two_modes), write_file("grid_none.bdf", "CQUAD4 1 2 3\n"), "no GRID entries");
  EXPECT_THROW(io::read_nastran_modes(write_file("p_ok4.pch", punch_two_modes), bulk, {1.0}), input_error);
}
