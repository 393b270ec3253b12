// Plot3D read/write: exact round trips (2D and 3D, ASCII and binary with and without record
// markers) and clear input_errors for malformed files, wrong sizes and folded grids.
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/io/plot3d.hpp>

#include <cstdint>
#include <sstream>

using namespace aerohopf;
using namespace aerohopf::flow;

namespace {
template <int Dim>
multiblock_points<double, Dim> two_blocks() {
  multiblock_points<double, Dim> g;
  for (int b = 0; b < 2; ++b) {
    grid_block<double, Dim> blk;
    for (int d = 0; d < Dim; ++d) blk.points[d] = 3 + d + b;
    blk.x.resize(blk.n_points());
    for (std::size_t k = 0; k < blk.x.size(); ++k) {
      const auto i = unravel<Dim>(k, blk.points);
      for (int d = 0; d < Dim; ++d) blk.x[k][d] = b * 10.0 + i[d] * (0.1 + 0.3 * d) + 1e-3 / 3.0 * i[(d + 1) % Dim];
    }
    g.blocks.push_back(blk);
  }
  return g;
}

template <int Dim>
void expect_equal(const multiblock_points<double, Dim>& a, const multiblock_points<double, Dim>& b) {
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (std::size_t k = 0; k < a.blocks.size(); ++k) {
    EXPECT_EQ(a.blocks[k].points, b.blocks[k].points);
    EXPECT_EQ(a.blocks[k].x, b.blocks[k].x);  // bit-exact (17 significant digits in ASCII)
  }
}

std::string error_of(const std::string& content) {
  std::istringstream in(content);
  try {
    (void)io::read_plot3d<2>(in, "bad.xyz");
  } catch (const input_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(plot3d, round_trips_2d_3d_ascii_binary) {
  for (auto fmt : {io::plot3d_format::ascii, io::plot3d_format::binary}) {
    const auto g2 = two_blocks<2>();
    std::stringstream s2;
    io::write_plot3d<2>(s2, g2, fmt);
    expect_equal<2>(g2, io::read_plot3d<2>(s2));
    const auto g3 = two_blocks<3>();
    std::stringstream s3;
    io::write_plot3d<3>(s3, g3, fmt);
    expect_equal<3>(g3, io::read_plot3d<3>(s3));
  }
  // The NACA C-grid through a file on disk.
  const auto g = naca_cgrid({.points_around = 129, .points_normal = 33, .wake_cells = 16});
  const std::string path = ::testing::TempDir() + "/naca.xyz";
  io::write_plot3d<2>(path, g.points, io::plot3d_format::binary);
  expect_equal<2>(g.points, io::read_plot3d<2>(path));
}

TEST(plot3d, binary_stream_without_record_markers) {
  const auto g = two_blocks<2>();
  std::stringstream s;
  auto put = [&](auto v) { s.write(reinterpret_cast<const char*>(&v), sizeof(v)); };
  put(std::int32_t(2));
  for (const auto& b : g.blocks) {
    put(std::int32_t(b.points[0]));
    put(std::int32_t(b.points[1]));
  }
  for (const auto& b : g.blocks)
    for (int d = 0; d < 2; ++d)
      for (const auto& x : b.x) put(x[d]);
  expect_equal<2>(g, io::read_plot3d<2>(s));
}

TEST(plot3d, malformed_files_give_clear_errors) {
  // truncated coordinates: names the block
  auto e = error_of("1\n2 2\n0 1 0 1\n0 0\n");
  EXPECT_NE(e.find("block 0"), std::string::npos) << e;
  // size below 2
  e = error_of("2\n2 2\n1 2\n0 1 0 1 0 0 1 1\n0 0\n");
  EXPECT_NE(e.find("block 1"), std::string::npos) << e;
  // trailing data (sizes too small for the data)
  e = error_of("1\n2 2\n0 1 0 1 0 0 1 1 5\n");
  EXPECT_NE(e.find("trailing"), std::string::npos) << e;
  // garbage
  e = error_of("one block\n");
  EXPECT_NE(e.find("number of blocks"), std::string::npos) << e;
  // folded (left-handed) cell: names the block and the cell
  e = error_of("2\n2 2\n2 2\n0 1 0 1 0 0 1 1\n1 0 1 0 0 0 1 1\n");
  EXPECT_NE(e.find("block 1 cell (0,0)"), std::string::npos) << e;
  // binary with a block size that does not match the data
  const auto g = two_blocks<2>();
  std::stringstream s;
  io::write_plot3d<2>(s, g, io::plot3d_format::binary);
  std::string bytes = s.str();
  bytes.resize(bytes.size() - 24);
  e = error_of(bytes);
  EXPECT_NE(e.find("block 1"), std::string::npos) << e;
  EXPECT_THROW(io::read_plot3d<2>("/nonexistent/dir/grid.xyz"), input_error);
}
