// Modal data: plate modes into the common form (t3 = w, right-handed rotations), the documented
// CSV written and read back exactly, mass normalisation, and the refusals of malformed files and
// inconsistent data, each naming the file, line or entry.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/structure/modal_data.hpp>

#include <cmath>
#include <fstream>
#include <string>

using namespace aerohopf;
using namespace aerohopf::structure;

namespace {
modal_data small_plate_modes() {
  const plate_mesh mesh = structured_plate_mesh(
      4, 3, [](double s, double r) { return Eigen::Vector2d(s + 0.2 * r, 0.6 * r); },
      [](double x, double) { return 0.01 * (1 - 0.3 * x); });
  plate_constraints c(mesh.nodes.size());
  for (int j = 0; j <= 3; ++j) c.clamp(5 * j);
  return modal_data_from_plate(mesh, plate_modes_of(mesh, isotropic_material(1e9, 0.3, 800), c, {.count = 3}));
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

void expect_refused(const std::string& path, const std::string& fragment) {
  try {
    read_modal_csv(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(ModalData, PlateModesMapToTranslationsAndRightHandedRotations) {
  const plate_mesh mesh = structured_plate_mesh(
      2, 2, [](double s, double r) { return Eigen::Vector2d(s, r); }, [](double, double) { return 0.01; });
  plate_modes m;
  m.omega = Eigen::VectorXd::Constant(1, 10.0);
  m.shapes = Eigen::MatrixXd::Zero(mesh.unknowns(), 1);
  m.shapes(3 * 4, 0) = 2.0;      // w at node 4
  m.shapes(3 * 4 + 1, 0) = 0.5;  // beta_x: u = z beta_x, a rotation about +y
  m.shapes(3 * 4 + 2, 0) = 0.25; // beta_y: v = z beta_y, a rotation about -x
  const modal_data d = modal_data_from_plate(mesh, m);
  EXPECT_EQ(d.point_ids[4], 5);
  EXPECT_EQ(d.shapes[0](4, 2), 2.0);
  EXPECT_EQ(d.shapes[0](4, 3), -0.25);
  EXPECT_EQ(d.shapes[0](4, 4), 0.5);
  EXPECT_EQ(d.generalised_mass[0], 1.0);
}

TEST(ModalData, CsvRoundTripIsExact) {
  modal_data d = small_plate_modes();
  d.generalised_mass[1] = 2.5;  // a shape not mass-normalised
  const std::string path = ::testing::TempDir() + "/modal.csv";
  write_modal_csv(path, d);
  const modal_data r = read_modal_csv(path);
  ASSERT_EQ(r.modes(), d.modes());
  ASSERT_EQ(r.size(), d.size());
  for (Eigen::Index k = 0; k < d.modes(); ++k) {
    EXPECT_NEAR(r.omega[k], d.omega[k], 1e-15 * d.omega[k]);  // through Hz and back
    EXPECT_EQ(r.generalised_mass[k], d.generalised_mass[k]);
    EXPECT_EQ(r.shapes[static_cast<std::size_t>(k)], d.shapes[static_cast<std::size_t>(k)]);
  }
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_EQ(r.point_ids[i], d.point_ids[i]);
    EXPECT_EQ(r.points[i], d.points[i]);
  }
  const modal_data n = r.mass_normalised();
  EXPECT_EQ(n.generalised_mass[1], 1.0);
  EXPECT_NEAR((n.shapes[1] - d.shapes[1] / std::sqrt(2.5)).norm(), 0.0, 1e-15 * d.shapes[1].norm());
}

TEST(ModalData, MalformedCsvIsRefusedWithItsLine) {
  const std::string h = std::string(modal_csv_header) + "\n";
  expect_refused(write_file("m_header.csv", "mode,frequency,gm\n"), "line 1: header");
  expect_refused(write_file("m_empty.csv", ""), "empty file");
  expect_refused(write_file("m_nopoints.csv", h), "no structural points");
  expect_refused(write_file("m_fields.csv", h + "1,10,1,1,0,0,0,0,0,1,0,0\n"), "line 2: 12 fields");
  expect_refused(write_file("m_number.csv", h + "1,10,1,1,0,0,0,0,0,abc,0,0,0\n"), "line 2: field 10 ('abc')");
  expect_refused(write_file("m_order.csv", h + "2,10,1,1,0,0,0,0,0,1,0,0,0\n"), "line 2: mode 2 follows mode 0");
  expect_refused(write_file("m_points.csv", h + "1,10,1,1,0,0,0,0,0,1,0,0,0\n1,10,1,2,1,0,0,0,0,1,0,0,0\n"
                                               "2,20,1,2,1,0,0,0,0,1,0,0,0\n"),
                 "line 4: mode 2 point 2 is not point 1");
  expect_refused(write_file("m_count.csv", h + "1,10,1,1,0,0,0,0,0,1,0,0,0\n1,10,1,2,1,0,0,0,0,1,0,0,0\n"
                                              "2,20,1,1,0,0,0,0,0,1,0,0,0\n"),
                 "mode 2 has 1 points, mode 1 has 2");
  expect_refused(write_file("m_mass.csv", h + "1,10,0,1,0,0,0,0,0,1,0,0,0\n"), "generalised mass 0");
  expect_refused(write_file("m_dup.csv", h + "1,10,1,1,0,0,0,0,0,1,0,0,0\n1,10,1,1,1,0,0,0,0,1,0,0,0\n"),
                 "point id 1 appears twice");
  expect_refused(write_file("m_zero.csv", h + "1,10,1,1,0,0,0,0,0,0,0,0,0\n"), "zero shape");
  expect_refused(write_file("m_nan.csv", h + "1,10,1,1,0,0,nan,0,0,1,0,0,0\n"), "line 2: field 7");
  EXPECT_THROW(read_modal_csv(::testing::TempDir() + "/no_such_file.csv"), input_error);
}

TEST(ModalData, InconsistentDataIsNotWritten) {
  modal_data d = small_plate_modes();
  d.shapes[2].conservativeResize(d.shapes[2].rows() - 1, Eigen::NoChange);
  const std::string path = ::testing::TempDir() + "/modal_refused.csv";
  std::remove(path.c_str());
  EXPECT_THROW(write_modal_csv(path, d), input_error);
  EXPECT_FALSE(std::ifstream(path).good());
}
