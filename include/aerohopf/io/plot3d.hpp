#pragma once
// Plot3D grid files (multi-block, whole, i.e. no IBLANK), 2D or 3D, ASCII or binary.
//
// Layout: number of blocks; the point counts of every block (Dim integers each); then per
// block all x, all y (, all z), index 0 fastest. Binary files are written as Fortran
// unformatted sequential records (int32 record markers, int32 sizes, float64 coordinates),
// which is what ParaView's and most CFD codes' Plot3D readers expect; reading detects ASCII,
// Fortran records, or a plain C stream without markers.
// Every read is validated: a malformed or truncated file, non-positive sizes, trailing data, or
// a grid with a non-positive cell volume throws aerohopf::input_error naming the file, the
// block and (for volumes) the cell.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../flow/metrics.hpp"
#include "../flow/structured_grid.hpp"

namespace aerohopf::io {

enum class plot3d_format { ascii, binary };

namespace internal {

template <int Dim>
void check_block_sizes(const std::vector<flow::index_d<Dim>>& dims, const std::string& name) {
  for (std::size_t b = 0; b < dims.size(); ++b)
    for (int d = 0; d < Dim; ++d)
      require(dims[b][d] >= 2 && dims[b][d] < (1 << 24), "plot3d '", name, "': block ", b,
              " has ", dims[b][d], " points along axis ", d, " (need at least 2)");
}

template <int Dim>
flow::multiblock_points<double, Dim> read_ascii(std::istream& in, const std::string& name) {
  long long nb = 0;
  require(static_cast<bool>(in >> nb) && nb >= 1 && nb < 1000000, "plot3d '", name,
          "': cannot read a positive number of blocks");
  std::vector<flow::index_d<Dim>> dims(static_cast<std::size_t>(nb));
  for (long long b = 0; b < nb; ++b)
    for (int d = 0; d < Dim; ++d)
      require(static_cast<bool>(in >> dims[b][d]), "plot3d '", name, "': cannot read the size of block ", b);
  check_block_sizes<Dim>(dims, name);
  flow::multiblock_points<double, Dim> g;
  g.blocks.resize(dims.size());
  for (std::size_t b = 0; b < dims.size(); ++b) {
    auto& blk = g.blocks[b];
    blk.points = dims[b];
    blk.x.resize(blk.n_points());
    for (int d = 0; d < Dim; ++d)
      for (std::size_t k = 0; k < blk.x.size(); ++k)
        require(static_cast<bool>(in >> blk.x[k][d]), "plot3d '", name, "': block ", b,
                ": cannot read coordinate ", d, " of point ", k, " (file truncated or malformed)");
  }
  std::string rest;
  require(!(in >> rest), "plot3d '", name, "': unexpected trailing data '", rest, "'");
  return g;
}

struct byte_reader {
  const std::vector<char>& bytes;
  std::size_t pos = 0;
  const std::string& name;
  template <class T>
  T get(const char* what) {
    require(pos + sizeof(T) <= bytes.size(), "plot3d '", name, "': file ends while reading ", what);
    T v;
    std::memcpy(&v, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
};

template <int Dim>
flow::multiblock_points<double, Dim> read_binary(const std::vector<char>& bytes, const std::string& name) {
  byte_reader r{bytes, 0, name};
  // Fortran records begin with the record length in bytes: 4 for the block-count record.
  const bool markers = bytes.size() >= 12 && r.get<std::int32_t>("header") == 4;
  r.pos = 0;
  auto begin_record = [&](std::int64_t expect, const char* what) {
    if (!markers) return;
    const auto len = r.get<std::int32_t>(what);
    require(len == expect, "plot3d '", name, "': record of ", what, " has length ", len,
            ", expected ", expect);
  };
  auto end_record = [&](std::int64_t expect, const char* what) {
    if (!markers) return;
    const auto len = r.get<std::int32_t>(what);
    require(len == expect, "plot3d '", name, "': record end marker of ", what, " is ", len,
            ", expected ", expect);
  };
  begin_record(4, "the block count");
  const auto nb = r.get<std::int32_t>("the block count");
  require(nb >= 1 && nb < 1000000, "plot3d '", name, "': bad number of blocks ", nb);
  end_record(4, "the block count");
  std::vector<flow::index_d<Dim>> dims(static_cast<std::size_t>(nb));
  begin_record(std::int64_t(4) * Dim * nb, "the block sizes");
  for (int b = 0; b < nb; ++b)
    for (int d = 0; d < Dim; ++d) dims[b][d] = r.get<std::int32_t>("the block sizes");
  end_record(std::int64_t(4) * Dim * nb, "the block sizes");
  check_block_sizes<Dim>(dims, name);
  flow::multiblock_points<double, Dim> g;
  g.blocks.resize(dims.size());
  for (std::size_t b = 0; b < dims.size(); ++b) {
    auto& blk = g.blocks[b];
    blk.points = dims[b];
    const std::size_t n = blk.n_points();
    require(r.pos + 8 * Dim * n <= bytes.size(), "plot3d '", name, "': block ", b, " needs ",
            8 * Dim * n, " bytes of coordinates, file is too short (wrong sizes?)");
    blk.x.resize(n);
    const auto rec = std::int64_t(8) * Dim * static_cast<std::int64_t>(n);
    begin_record(rec, "block coordinates");
    for (int d = 0; d < Dim; ++d)
      for (std::size_t k = 0; k < n; ++k) blk.x[k][d] = r.get<double>("coordinates");
    end_record(rec, "block coordinates");
  }
  require(r.pos == bytes.size(), "plot3d '", name, "': ", bytes.size() - r.pos,
          " unexpected trailing bytes (wrong block sizes?)");
  return g;
}

}  // namespace internal

/// Checks finiteness and positive volumes; throws input_error naming block and cell.
template <int Dim>
void validate_grid(const flow::multiblock_points<double, Dim>& g, const std::string& name) {
  for (std::size_t b = 0; b < g.blocks.size(); ++b)
    for (std::size_t k = 0; k < g.blocks[b].x.size(); ++k)
      for (int d = 0; d < Dim; ++d)
        require(std::isfinite(g.blocks[b].x[k][d]), "grid '", name, "': block ", b, " point ", k,
                " has a non-finite coordinate");
  try {
    (void)flow::compute_metrics<double, Dim>(g);
  } catch (const input_error& e) {
    throw input_error(aerohopf::internal::concat("grid '", name, "': ", e.what()));
  }
}

/// Reads a whole multi-block Plot3D grid (format detected) and validates it.
template <int Dim>
flow::multiblock_points<double, Dim> read_plot3d(std::istream& in, const std::string& name = "stream") {
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  require(!bytes.empty(), "plot3d '", name, "': empty file");
  bool text = true;
  for (std::size_t k = 0; k < std::min<std::size_t>(bytes.size(), 64); ++k) {
    const auto c = static_cast<unsigned char>(bytes[k]);
    if (!(std::isspace(c) || std::isdigit(c) || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E'))
      text = false;
  }
  flow::multiblock_points<double, Dim> g;
  if (text) {
    std::istringstream s(std::string(bytes.begin(), bytes.end()));
    g = internal::read_ascii<Dim>(s, name);
  } else {
    g = internal::read_binary<Dim>(bytes, name);
  }
  validate_grid<Dim>(g, name);
  return g;
}

template <int Dim>
flow::multiblock_points<double, Dim> read_plot3d(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  require(in.good(), "plot3d: cannot open '", path, "'");
  return read_plot3d<Dim>(in, path);
}

template <int Dim>
void write_plot3d(std::ostream& out, const flow::multiblock_points<double, Dim>& g, plot3d_format fmt) {
  const auto nb = static_cast<std::int32_t>(g.blocks.size());
  if (fmt == plot3d_format::ascii) {
    out << nb << '\n';
    for (const auto& b : g.blocks) {
      for (int d = 0; d < Dim; ++d) out << b.points[d] << (d + 1 < Dim ? ' ' : '\n');
    }
    out << std::setprecision(17);
    for (const auto& b : g.blocks)
      for (int d = 0; d < Dim; ++d)
        for (std::size_t k = 0; k < b.x.size(); ++k) out << b.x[k][d] << ((k + 1) % 4 ? ' ' : '\n');
    out << '\n';
    return;
  }
  auto put = [&](auto v) { out.write(reinterpret_cast<const char*>(&v), sizeof(v)); };
  put(std::int32_t(4));
  put(nb);
  put(std::int32_t(4));
  put(std::int32_t(4 * Dim * nb));
  for (const auto& b : g.blocks)
    for (int d = 0; d < Dim; ++d) put(std::int32_t(b.points[d]));
  put(std::int32_t(4 * Dim * nb));
  for (const auto& b : g.blocks) {
    const auto rec = static_cast<std::int32_t>(8 * Dim * b.x.size());
    put(rec);
    for (int d = 0; d < Dim; ++d)
      for (const auto& x : b.x) put(double(x[d]));
    put(rec);
  }
}

template <int Dim>
void write_plot3d(const std::string& path, const flow::multiblock_points<double, Dim>& g, plot3d_format fmt) {
  std::ofstream out(path, fmt == plot3d_format::binary ? std::ios::binary : std::ios::out);
  require(out.good(), "plot3d: cannot write '", path, "'");
  write_plot3d<Dim>(out, g, fmt);
}

}  // namespace aerohopf::io
