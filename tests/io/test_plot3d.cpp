// Plot3D read/write: exact round trips (2D and 3D, ASCII and binary with and without record
// markers) and clear input_errors for malformed files, wrong sizes and folded grids; hostile
// inputs (wrapping or huge sizes, non-finite tokens, truncation, unpaired markers) and the
// unusual but valid layouts (BOM, Fortran D exponents, 8-byte markers, either byte order,
// float32, C streams with 4 blocks).
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/io/plot3d.hpp>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <sstream>
#include <string>
#include <string_view>

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

// ---------------------------------------------------------------------------------------------
// Hostile and unusual inputs. Every outcome is classified so that an exception other than
// aerohopf::input_error (std::bad_alloc, std::length_error, ...) fails the test instead of
// aborting it.
namespace {
struct outcome {
  enum kind_t { ok, input, other } kind = ok;
  std::string message;
};

template <int Dim>
outcome read_outcome(const std::string& content, multiblock_points<double, Dim>* out = nullptr) {
  std::istringstream in(content);
  try {
    auto g = io::read_plot3d<Dim>(in, "hostile.xyz");
    if (out) *out = g;
    return {};
  } catch (const input_error& e) {
    return {outcome::input, e.what()};
  } catch (const std::exception& e) {
    return {outcome::other, e.what()};
  }
}

// Largest single request to the global operator new while `armed`; an independent witness that
// a reader refuses a huge header before allocating for it.
std::atomic<bool> armed{false};
std::atomic<std::size_t> largest_request{0};

template <class T>
void put_raw(std::string& s, T v, bool swap = false) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

// Fortran unformatted sequential records with `marker`-byte markers (0: plain C stream), the
// given byte order and coordinate precision, written independently of io::write_plot3d.
template <int Dim, class Marker = std::int32_t, class Real = double>
std::string fortran_file(const multiblock_points<double, Dim>& g, bool markers, bool swap = false) {
  std::string s;
  auto record = [&](const std::string& body) {
    if (markers) put_raw(s, static_cast<Marker>(body.size()), swap);
    s += body;
    if (markers) put_raw(s, static_cast<Marker>(body.size()), swap);
  };
  std::string body;
  put_raw(body, std::int32_t(g.blocks.size()), swap);
  record(body);
  body.clear();
  for (const auto& b : g.blocks)
    for (int d = 0; d < Dim; ++d) put_raw(body, std::int32_t(b.points[d]), swap);
  record(body);
  for (const auto& b : g.blocks) {
    body.clear();
    for (int d = 0; d < Dim; ++d)
      for (const auto& x : b.x) put_raw(body, static_cast<Real>(x[d]), swap);
    record(body);
  }
  return s;
}

template <int Dim>
multiblock_points<double, Dim> blocks_of(int nb) {
  multiblock_points<double, Dim> g;
  for (int b = 0; b < nb; ++b) {
    grid_block<double, Dim> blk;
    for (int d = 0; d < Dim; ++d) blk.points[d] = 2 + (b + d) % 3;
    blk.x.resize(blk.n_points());
    for (std::size_t k = 0; k < blk.x.size(); ++k) {
      const auto i = unravel<Dim>(k, blk.points);
      for (int d = 0; d < Dim; ++d) blk.x[k][d] = 4.0 * b + 0.5 * i[d] + 0.125 * i[(d + 1) % Dim];
    }
    g.blocks.push_back(blk);
  }
  return g;
}

bool mentions(const outcome& o, const std::string& what) { return o.message.find(what) != std::string::npos; }
}  // namespace

void* operator new(std::size_t n) {
  if (armed.load(std::memory_order_relaxed)) {
    std::size_t cur = largest_request.load();
    while (n > cur && !largest_request.compare_exchange_weak(cur, n)) {
    }
  }
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
// The pair malloc/free is this replacement's own; GCC cannot see that operator new above is it.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

TEST(plot3d, sizes_whose_product_wraps_are_refused) {
  // 2^22 * 2^22 * 2^20 = 2^64 points wraps to 0 in size_t.
  const std::string ascii = "1\n4194304 4194304 1048576\n0 1 0 1 0 0 1 1\n";
  auto o = read_outcome<3>(ascii);
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "hostile.xyz") && mentions(o, "block 0")) << o.message;
  std::string bin;
  put_raw(bin, std::int32_t(4));
  put_raw(bin, std::int32_t(1));
  put_raw(bin, std::int32_t(4));
  put_raw(bin, std::int32_t(12));
  for (std::int32_t n : {4194304, 4194304, 1048576}) put_raw(bin, n);
  put_raw(bin, std::int32_t(12));
  put_raw(bin, std::int32_t(0));
  put_raw(bin, std::int32_t(0));
  o = read_outcome<3>(bin);
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "hostile.xyz") && mentions(o, "block 0")) << o.message;
}

TEST(plot3d, huge_header_is_refused_before_allocating) {
  // 2.8e14 points: no allocation of that size can succeed, so the old reader's bad_alloc shows.
  auto o = read_outcome<2>("1\n16777215 16777215\n0 1 0 1\n");
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "hostile.xyz")) << o.message;
  // 4e6 points (64 MB of coordinates) claimed by a 30-byte file: refused without allocating.
  for (const std::string& content : {std::string("1\n2000 2000\n0 1 0 1 0 0 1 1\n"), std::string("300000\n2 2\n")}) {
    largest_request = 0;
    armed = true;
    o = read_outcome<2>(content);
    armed = false;
    EXPECT_EQ(o.kind, outcome::input) << o.message;
    EXPECT_LT(largest_request.load(), std::size_t(4096)) << o.message;
  }
  // binary: a C stream claiming 2000 x 2000 points
  std::string bin;
  put_raw(bin, std::int32_t(1));
  put_raw(bin, std::int32_t(2000));
  put_raw(bin, std::int32_t(2000));
  put_raw(bin, 1.0);
  largest_request = 0;
  armed = true;
  o = read_outcome<2>(bin);
  armed = false;
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_LT(largest_request.load(), std::size_t(4096)) << o.message;
}

TEST(plot3d, text_with_bom_fortran_exponents_and_long_headers) {
  const auto g = blocks_of<2>(1);  // 2 x 3 points
  const std::string body = "1\n2 3\n0.0D+00 5.0D-01 1.25d-1 0.625D0 0.25E0 +7.5D-1\n0.0 0.125 0.5 0.625 1.0 1.125\n";
  for (const std::string& content : {"\xEF\xBB\xBF" + body, body, std::string(100, ' ') + body}) {
    multiblock_points<double, 2> r;
    const auto o = read_outcome<2>(content, &r);
    ASSERT_EQ(o.kind, outcome::ok) << o.message;
    expect_equal<2>(g, r);
  }
  // Fortran's E format drops the exponent letter for three-digit exponents (1.0-300 = 1e-300)
  multiblock_points<double, 2> r;
  auto o = read_outcome<2>("1\n2 2\n0 1 0 1.0+000\n0 0 1 1.0-000\n", &r);
  ASSERT_EQ(o.kind, outcome::ok) << o.message;
  EXPECT_EQ(r.blocks[0].x[3][0], 1.0);
  EXPECT_EQ(r.blocks[0].x[3][1], 1.0);
}

TEST(plot3d, non_finite_text_coordinates_name_block_and_point) {
  for (const std::string tok : {"nan", "inf", "-Infinity", "NaN", "1e999"}) {
    // block 1, point 2 (i = 0, j = 1), y coordinate
    const std::string content = "2\n2 2\n2 2\n0 1 0 1 0 0 1 1\n0 1 0 1 0 0 " + tok + " 1\n";
    const auto o = read_outcome<2>(content);
    EXPECT_EQ(o.kind, outcome::input) << o.message;
    EXPECT_TRUE(mentions(o, "hostile.xyz") && mentions(o, "block 1") && mentions(o, "point 2")) << o.message;
    EXPECT_TRUE(mentions(o, tok)) << o.message;
  }
  // ... and the same as the first token of the data (what the old 64-byte detection saw)
  const auto o = read_outcome<2>("1\n2 2\nnan 1 0 1 0 0 1 1\n");
  EXPECT_TRUE(mentions(o, "block 0") && mentions(o, "point 0") && mentions(o, "not a finite")) << o.message;
}

TEST(plot3d, binary_layouts_are_told_apart_by_the_file_length) {
  for (int nb : {1, 3, 4, 5}) {
    SCOPED_TRACE(nb);
    const auto g2 = blocks_of<2>(nb);
    const auto g3 = blocks_of<3>(nb);
    for (bool swap : {false, true}) {
      multiblock_points<double, 2> r2;
      multiblock_points<double, 3> r3;
      auto o = read_outcome<2>(fortran_file<2>(g2, false, swap), &r2);  // C stream, 4 blocks: first int is 4
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<2>(g2, r2);
      o = read_outcome<3>(fortran_file<3>(g3, false, swap), &r3);
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<3>(g3, r3);
      o = read_outcome<2>(fortran_file<2, std::int64_t>(g2, true, swap), &r2);  // 8-byte markers
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<2>(g2, r2);
      o = read_outcome<3>(fortran_file<3, std::int64_t>(g3, true, swap), &r3);
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<3>(g3, r3);
      o = read_outcome<3>(fortran_file<3>(g3, true, swap), &r3);  // 4-byte markers
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<3>(g3, r3);
      // single precision (every coordinate here is a multiple of 1/8, exact in float)
      o = read_outcome<3>(fortran_file<3, std::int32_t, float>(g3, true, swap), &r3);
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<3>(g3, r3);
      o = read_outcome<2>(fortran_file<2, std::int32_t, float>(g2, false, swap), &r2);
      ASSERT_EQ(o.kind, outcome::ok) << o.message;
      expect_equal<2>(g2, r2);
    }
  }
}

TEST(plot3d, binary_record_markers_must_pair) {
  const auto g = blocks_of<2>(2);
  const std::string good = fortran_file<2>(g, true);
  // The end marker of the block-count record (bytes 8..11), of the block sizes (bytes 32..35)
  // and of the last coordinate record (last 4 bytes) changed to another value.
  for (std::size_t at : {std::size_t(8), std::size_t(32), good.size() - 4}) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] + 8);
    const auto o = read_outcome<2>(bad);
    EXPECT_EQ(o.kind, outcome::input) << o.message;
    EXPECT_TRUE(mentions(o, "hostile.xyz") && mentions(o, "marker")) << o.message;
  }
  // 8-byte markers: the high half of an end marker is not zero
  std::string bad = fortran_file<2, std::int64_t>(g, true);
  bad[bad.size() - 2] = 1;
  const auto o = read_outcome<2>(bad);
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "marker")) << o.message;
}

TEST(plot3d, dimension_counts_and_lengths_are_checked) {
  const auto g2 = blocks_of<2>(2);
  const auto g3 = blocks_of<3>(2);
  // a 2D file read as 3D and a 3D file read as 2D say so
  auto o = read_outcome<3>(fortran_file<2>(g2, true));
  EXPECT_TRUE(mentions(o, "2D file read as 3D")) << o.message;
  o = read_outcome<2>(fortran_file<3>(g3, true));
  EXPECT_TRUE(mentions(o, "3D file read as 2D")) << o.message;
  // block counts <= 0 or absurd, sizes <= 1, in text and binary
  for (const std::string content : {"0\n", "-3\n2 2\n", "2147483648\n2 2\n", "6666666667666666666\n2 2\n", "99999999999999999999999\n",
                                    "1\n-2 2\n0 1 0 1\n", "1\n2 0\n", "1\n2 2.5\n0 1 0 1 0 0 1 1\n"}) {
    o = read_outcome<2>(content);
    EXPECT_EQ(o.kind, outcome::input) << content << ": " << o.message;
    EXPECT_TRUE(mentions(o, "hostile.xyz")) << o.message;
  }
  for (std::int32_t nb : {0, -1, 2000000000}) {
    std::string bin;
    put_raw(bin, std::int32_t(4));
    put_raw(bin, nb);
    put_raw(bin, std::int32_t(4));
    o = read_outcome<2>(bin);
    EXPECT_EQ(o.kind, outcome::input) << o.message;
    EXPECT_TRUE(mentions(o, "blocks")) << o.message;
  }
  // every truncation of a valid binary file and trailing garbage after it are refused
  const std::string good = fortran_file<2>(g2, true);
  for (std::size_t n = 0; n < good.size(); ++n) {
    o = read_outcome<2>(good.substr(0, n));
    ASSERT_EQ(o.kind, outcome::input) << n << ": " << o.message;
    ASSERT_TRUE(mentions(o, "hostile.xyz")) << o.message;
  }
  o = read_outcome<2>(good + std::string(3, '\0'));
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "trailing")) << o.message;
  o = read_outcome<2>(fortran_file<2>(g2, false) + "junk");
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  o = read_outcome<2>("1\n2 2\n0 1 0 1 0 0 1 1\n\x01");
  EXPECT_TRUE(mentions(o, "trailing")) << o.message;
}

TEST(plot3d, coordinates_whose_metrics_overflow_are_refused) {
  // A unit square scaled by 1e200: finite coordinates, but the cell volume overflows to inf.
  const auto o = read_outcome<2>("1\n2 2\n0 1e200 0 1e200 0 0 1e200 1e200\n");
  EXPECT_EQ(o.kind, outcome::input) << o.message;
  EXPECT_TRUE(mentions(o, "hostile.xyz") && mentions(o, "block 0") && mentions(o, "finite")) << o.message;
}

namespace {
// A stream buffer failing after a few bytes, as a device error would.
struct failing_buf : std::streambuf {
  std::string data = "1\n2 2\n0 1";
  bool served = false;
  int_type underflow() override {
    if (served) throw std::ios_base::failure("device error");
    served = true;
    setg(data.data(), data.data(), data.data() + data.size());
    return traits_type::to_int_type(data[0]);
  }
};
}  // namespace

TEST(plot3d, every_escaping_exception_is_an_input_error_naming_the_file) {
  failing_buf buf;
  std::istream in(&buf);
  try {
    (void)io::read_plot3d<2>(in, "device.xyz");
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("device.xyz"), std::string::npos) << e.what();
  } catch (...) {
    ADD_FAILURE() << "not an input_error";
  }
  // a directory is not a grid file
  try {
    (void)io::read_plot3d<2>(::testing::TempDir());
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
}

TEST(plot3d, writer_refuses_inconsistent_blocks_before_writing) {
  auto g = blocks_of<2>(2);
  g.blocks[1].x.pop_back();
  std::ostringstream out;
  EXPECT_THROW(io::write_plot3d<2>(out, g, io::plot3d_format::binary), input_error);
  EXPECT_TRUE(out.str().empty());
  const std::string path = ::testing::TempDir() + "/never_written.xyz";
  std::remove(path.c_str());
  EXPECT_THROW(io::write_plot3d<2>(path, g, io::plot3d_format::ascii), input_error);
  EXPECT_FALSE(std::ifstream(path).good());
}

TEST(plot3d, reads_from_memory) {
  const auto g = blocks_of<3>(3);
  std::ostringstream s;
  io::write_plot3d<3>(s, g, io::plot3d_format::binary);
  const std::string bytes = s.str();
  expect_equal<3>(g, io::read_plot3d_bytes<3>(bytes, "memory.xyz"));
  try {
    (void)io::read_plot3d_bytes<3>(std::string_view(bytes).substr(0, 50), "memory.xyz");
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("memory.xyz"), std::string::npos) << e.what();
  }
}
