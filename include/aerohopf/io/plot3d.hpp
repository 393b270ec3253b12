#pragma once
// Plot3D grid files (multi-block, whole, i.e. no IBLANK), 2D or 3D, ASCII or binary.
//
// Layout: number of blocks; the point counts of every block (Dim integers each); then per
// block all x, all y (, all z), index 0 fastest. Binary files are written as Fortran
// unformatted sequential records (int32 record markers, int32 sizes, float64 coordinates),
// which is what ParaView's and most CFD codes' Plot3D readers expect.
//
// Reading accepts
//  - text: whitespace-separated tokens, an optional UTF-8 byte order mark, Fortran D/d
//    exponents (1.0D+00) and Fortran's E format without exponent letter (1.0-100);
//  - binary: Fortran records with 4- or 8-byte markers, or a plain C stream without markers;
//    either byte order; float64 or float32 coordinates (int32 sizes always).
// Text vs binary is decided by the first four bytes: every valid binary layout starts with an
// integer below 2^24 (a block count or a record length), so one of those bytes is zero, while a
// text file starts with a digit, a sign or whitespace. Everything after that is judged token by
// token (text) or against the file length (binary), so a malformed file gets the message of
// the reader it was meant for. The binary layout is the one whose headers, record markers (every
// begin/end pair) and coordinate lengths add up to exactly the file length; candidates are
// tried in the order Fortran 4-byte, Fortran 8-byte, C stream, native byte order first, and a
// file fitting none is refused with the failure of the candidate that matched the most bytes.
//
// Every size is checked against the file length with overflow-safe products before anything
// is allocated for it (a text value needs at least two bytes: one character and one
// separator), so a header claiming a huge grid is refused in time and memory proportional to
// the header. Coordinates must be finite, and so must the cell volumes and face areas of the
// grid, which must be positive (validate_grid). Every exception leaving the readers is an
// aerohopf::input_error whose message names the file (and, where it applies, block and point).
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "../error.hpp"
#include "../flow/metrics.hpp"
#include "../flow/structured_grid.hpp"
#include "text_numbers.hpp"

namespace aerohopf::io {

enum class plot3d_format { ascii, binary };

namespace internal {

using aerohopf::internal::concat;

/// r = a * b unless that overflows 64 bits.
inline bool checked_mul(std::uint64_t a, std::uint64_t b, std::uint64_t& r) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return false;
  r = a * b;
  return true;
}

/// Points of a block with sizes n (each >= 2), or false if the count exceeds `limit`: the
/// product is formed factor by factor against the limit, so it cannot wrap.
template <int Dim>
bool points_within(const flow::index_d<Dim>& n, std::uint64_t limit, std::uint64_t& r) {
  r = 1;
  for (int d = 0; d < Dim; ++d)
    if (!checked_mul(r, static_cast<std::uint64_t>(n[d]), r) || r > limit) return false;
  return true;
}

template <int Dim>
std::string sizes_text(const flow::index_d<Dim>& n) {
  std::string s;
  for (int d = 0; d < Dim; ++d) {
    if (d) s += " x ";
    s += std::to_string(n[d]);
  }
  return s;
}

/// "point k (i,j,k)" of a block with the given sizes.
template <int Dim>
std::string point_text(std::size_t k, const flow::index_d<Dim>& n) {
  const auto i = flow::unravel<Dim>(k, n);
  std::string s = "point " + std::to_string(k) + " (";
  for (int d = 0; d < Dim; ++d) {
    if (d) s += ',';
    s += std::to_string(i[d]);
  }
  s += ')';
  return s;
}

/// A token as it may appear in a message: at most 32 characters, non-printables as '?'.
inline std::string printable(std::string_view t) {
  std::string r;
  for (char c : t.substr(0, 32)) r += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (t.size() > 32) r += "...";
  return r;
}

// ----------------------------------------------------------------------------------------------
// Text

struct text_tokens {
  std::string_view s;
  std::size_t pos = 0;
  std::size_t line = 1;

  static bool separator(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }
  /// The next whitespace-delimited token; empty at the end of the text.
  std::string_view next() {
    while (pos < s.size() && separator(s[pos])) line += s[pos++] == '\n';
    const std::size_t b = pos;
    while (pos < s.size() && !separator(s[pos])) ++pos;
    return s.substr(b, pos - b);
  }
  std::size_t remaining() const { return s.size() - pos; }
};

template <int Dim>
flow::multiblock_points<double, Dim> read_ascii(std::string_view text, const std::string& name) {
  text_tokens in{text};
  const std::string file = "plot3d '" + name + "'";
  auto tok = in.next();
  long long nb = 0;
  require(parse_integer(tok, nb) && nb >= 1, file, ": the first token '", printable(tok),
          "' is not a positive number of blocks");
  // Every block size is a token of at least one character after at least one separator.
  require(static_cast<unsigned long long>(nb) <= in.remaining() / (2 * Dim), file, ": ", nb,
          " blocks claimed, but the ", in.remaining(), " bytes after the block count cannot hold their ", Dim,
          " sizes each");
  std::vector<flow::index_d<Dim>> dims(static_cast<std::size_t>(nb));
  for (std::size_t b = 0; b < dims.size(); ++b)
    for (int d = 0; d < Dim; ++d) {
      tok = in.next();
      require(!tok.empty(), file, ": the file ends in the sizes of block ", b);
      long long v = 0;
      const char* hint = Dim == 3 && d == 2 ? " (a 2D file read as 3D?)" : "";
      require(parse_integer(tok, v), file, ": block ", b, ": size along axis ", d, " '", printable(tok), "' (line ",
              in.line, ") is not an integer", hint);
      require(v >= 2, file, ": block ", b, " has ", v, " points along axis ", d, " (need at least 2)", hint);
      require(v <= std::numeric_limits<int>::max(), file, ": block ", b, " has ", v, " points along axis ", d,
              " (more than ", std::numeric_limits<int>::max(), ")");
      dims[b][d] = static_cast<int>(v);
    }
  // Every coordinate is a token of at least one character after at least one separator.
  const std::uint64_t limit = in.remaining() / 2;
  std::uint64_t values = 0;
  for (std::size_t b = 0; b < dims.size(); ++b) {
    std::uint64_t n = 0;
    require(points_within<Dim>(dims[b], limit / Dim, n) && (values += Dim * n) <= limit, file, ": block ", b,
            " (", sizes_text<Dim>(dims[b]), " points) does not fit: the ", in.remaining(),
            " bytes after the sizes hold at most ", limit, " values (wrong sizes or truncated file)");
  }
  flow::multiblock_points<double, Dim> g;
  g.blocks.resize(dims.size());
  for (std::size_t b = 0; b < dims.size(); ++b) {
    auto& blk = g.blocks[b];
    blk.points = dims[b];
    blk.x.resize(blk.n_points());
    for (int d = 0; d < Dim; ++d)
      for (std::size_t k = 0; k < blk.x.size(); ++k) {
        // (messages are built only on failure: this loop runs once per coordinate)
        tok = in.next();
        if (tok.empty())
          throw input_error(concat(file, ": block ", b, ": the file ends at coordinate ", d, " of ",
                                   point_text<Dim>(k, blk.points), " (truncated file or wrong sizes)"));
        double& x = blk.x[k][d];
        const auto st = parse_real(tok, x);
        if (st != real_status::ok || !std::isfinite(x))
          throw input_error(concat(file, ": block ", b, " ", point_text<Dim>(k, blk.points), ": coordinate ", d, " '",
                                   printable(tok), "' (line ", in.line, ") ",
                                   st == real_status::not_a_number   ? "is not a number"
                                   : st == real_status::out_of_range ? "is out of the range of double"
                                                                     : "is not a finite number"));
      }
  }
  tok = in.next();
  require(tok.empty(), file, ": unexpected trailing data '", printable(tok), "' at line ", in.line,
          Dim == 2 ? " (wrong block sizes, or a 3D file read as 2D?)" : " (wrong block sizes?)");
  return g;
}

// ----------------------------------------------------------------------------------------------
// Binary

struct binary_layout {
  int marker = 4;        // bytes of each Fortran record marker: 4, 8, or 0 (C stream)
  bool swapped = false;  // byte order opposite to this machine's
  int real = 8;          // bytes per coordinate: 8 (float64) or 4 (float32)
};

inline std::string layout_text(const binary_layout& l) {
  std::string s = l.marker ? "Fortran records with " + std::to_string(l.marker) + "-byte markers" : "C stream without record markers";
  s += l.swapped ? ", opposite byte order" : ", native byte order";
  return s;
}

struct byte_cursor {
  std::string_view bytes;
  bool swapped = false;
  std::size_t pos = 0;

  /// Bytes after pos; 0 (not a wrapped difference) if pos has been set past the end.
  std::size_t remaining() const { return pos < bytes.size() ? bytes.size() - pos : 0; }
  template <class T>
  bool get(T& v) {
    if (remaining() < sizeof(T)) return false;
    char b[sizeof(T)];
    std::memcpy(b, bytes.data() + pos, sizeof(T));
    if (swapped) std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
    pos += sizeof(T);
    return true;
  }
  /// A record marker of `width` bytes (signed, as Fortran writes them).
  bool marker(int width, std::int64_t& v) {
    if (width == 8) return get(v);
    std::int32_t m = 0;
    const bool ok = get(m);
    v = m;
    return ok;
  }
};

/// Whether the whole file is consistent with one layout, and its block sizes if so.
template <int Dim>
struct binary_scan {
  binary_layout layout;
  std::vector<flow::index_d<Dim>> dims;
  std::size_t data_begin = 0;  // offset of the first coordinate record (its marker)
  std::string failure;         // empty if consistent
};

template <int Dim>
binary_scan<Dim> scan_binary(std::string_view bytes, int marker, bool swapped) {
  binary_scan<Dim> r;
  r.layout.marker = marker;
  r.layout.swapped = swapped;
  byte_cursor c{bytes, swapped};
  auto fail = [&](const std::string& why) {
    r.failure = why;
    r.dims.clear();
    return r;
  };
  std::int64_t m = 0;
  auto begin_record = [&](std::int64_t expect, const std::string& what, std::string& why) {
    if (!marker) return true;
    if (!c.marker(marker, m)) why = "the file ends in the record marker of " + what;
    else if (m != expect) why = concat("the record of ", what, " has length ", m, ", expected ", expect);
    return why.empty();
  };
  auto end_record = [&](std::int64_t expect, const std::string& what, std::string& why) {
    if (!marker) return true;
    if (!c.marker(marker, m)) why = "the file ends in the end marker of the record of " + what;
    else if (m != expect) why = concat("the end marker of the record of ", what, " is ", m, ", its begin marker ", expect);
    return why.empty();
  };
  std::string why;
  if (!begin_record(4, "the block count", why)) return fail(why);
  std::int32_t nb = 0;
  if (!c.get(nb)) return fail("the file ends in the block count");
  if (nb < 1) return fail(concat("bad number of blocks ", nb));
  if (!end_record(4, "the block count", why)) return fail(why);
  const std::uint64_t size_bytes = std::uint64_t(4) * Dim * static_cast<std::uint64_t>(nb);
  if (size_bytes > c.remaining())
    return fail(concat(nb, " blocks claimed, but the ", c.remaining(), " bytes after the block count cannot hold their ",
                       size_bytes, " bytes of sizes"));
  if (marker) {
    if (!c.marker(marker, m)) return fail("the file ends in the record marker of the block sizes");
    if (m != static_cast<std::int64_t>(size_bytes)) {
      const char* hint = m == std::int64_t(4) * (5 - Dim) * nb ? (Dim == 2 ? " (a 3D file read as 2D?)" : " (a 2D file read as 3D?)") : "";
      return fail(concat("the record of the block sizes has length ", m, ", expected ", size_bytes, " for ", nb,
                         " blocks of ", Dim, " sizes", hint));
    }
  }
  r.dims.resize(static_cast<std::size_t>(nb));  // bounded by the file length, checked above
  for (std::size_t b = 0; b < r.dims.size(); ++b)
    for (int d = 0; d < Dim; ++d) {
      std::int32_t v = 0;
      if (!c.get(v)) return fail("the file ends in the block sizes");
      if (v < 2)
        return fail(concat("block ", b, " has ", v, " points along axis ", d, " (need at least 2)",
                           Dim == 3 && d == 2 ? " (a 2D file read as 3D?)" : ""));
      r.dims[b][d] = v;
    }
  if (!end_record(static_cast<std::int64_t>(size_bytes), "the block sizes", why)) return fail(why);
  r.data_begin = c.pos;
  if (marker) {
    // One record per block; its length says the precision, which all blocks share.
    for (std::size_t b = 0; b < r.dims.size(); ++b) {
      std::uint64_t n = 0;
      if (!points_within<Dim>(r.dims[b], c.remaining() / (4 * Dim), n))
        return fail(concat("block ", b, " (", sizes_text<Dim>(r.dims[b]), " points) needs more coordinate bytes than the ",
                           c.remaining(), " left in the file (wrong sizes or truncated file)"));
      const auto what = "block " + std::to_string(b) + " coordinates";
      if (!c.marker(marker, m)) return fail("the file ends in the record marker of " + what);
      const auto n8 = static_cast<std::int64_t>(8 * Dim * n), n4 = static_cast<std::int64_t>(4 * Dim * n);
      if (b == 0 && (m == n8 || m == n4)) r.layout.real = m == n8 ? 8 : 4;
      const auto expect = r.layout.real == 8 ? n8 : n4;
      if (m != expect)
        return fail(concat("the record of ", what, " (", sizes_text<Dim>(r.dims[b]), " points) has length ", m,
                           ", expected ", expect, b == 0 ? concat(" (float64) or ", n4, " (float32)") : std::string()));
      if (static_cast<std::uint64_t>(m) > c.remaining())
        return fail(concat("the file ends in block ", b, " coordinates: ", m, " bytes needed, ", c.remaining(), " left"));
      c.pos += static_cast<std::size_t>(m);
      if (!end_record(m, what, why)) return fail(why);
    }
    if (c.remaining())
      return fail(concat(c.remaining(), " unexpected trailing bytes after the last block (wrong block sizes?)"));
  } else {
    // The coordinates fill the rest of the file exactly, in float64 or float32.
    std::uint64_t total = 0;
    const std::uint64_t limit = c.remaining() / (4 * Dim);
    for (std::size_t b = 0; b < r.dims.size(); ++b) {
      std::uint64_t n = 0;
      if (!points_within<Dim>(r.dims[b], limit, n) || (total += n) > limit)
        return fail(concat("block ", b, " (", sizes_text<Dim>(r.dims[b]), " points) needs more coordinate bytes than the ",
                           c.remaining(), " left in the file (wrong sizes or truncated file)"));
    }
    const std::uint64_t n8 = 8 * Dim * total, n4 = 4 * Dim * total;
    if (c.remaining() != n8 && c.remaining() != n4)
      return fail(concat("the ", c.remaining(), " bytes after the sizes are neither the ", n8, " of float64 nor the ", n4,
                         " of float32 coordinates of ", total, " points (truncated file, trailing data or wrong sizes)"));
    r.layout.real = c.remaining() == n8 ? 8 : 4;
  }
  return r;
}

/// The layout a binary file was most likely meant to have, judged by its first bytes only (for
/// the message when no layout fits): Fortran 4-byte records if it starts with the block-count
/// record (4, n, 4), Fortran 8-byte records if it starts with an 8-byte 4, a C stream if it
/// starts with a plausible block count; native byte order unless only the other one fits.
inline binary_layout likely_layout(std::string_view bytes) {
  for (bool swapped : {false, true}) {
    byte_cursor c{bytes, swapped};
    std::int32_t f32 = 0, t32 = 0;
    std::int64_t f64 = 0;
    const bool has32 = c.get(f32);
    c.pos = 0;
    const bool has64 = c.get(f64);
    c.pos = 8;
    const bool has_third = c.get(t32);
    if (has32 && f32 == 4 && has_third && t32 == 4) return {4, swapped};
    if (has64 && f64 == 4) return {8, swapped};
    if (has32 && f32 == 4) return {4, swapped};
    if (has32 && f32 >= 1 && f32 < (1 << 24)) return {0, swapped};
  }
  return {0, false};
}

template <int Dim>
flow::multiblock_points<double, Dim> read_binary(std::string_view bytes, const std::string& name) {
  const std::string file = "plot3d '" + name + "'";
  binary_scan<Dim> best;
  bool found = false;
  for (bool swapped : {false, true})
    for (int marker : {4, 8, 0})
      if (!found) {
        best = scan_binary<Dim>(bytes, marker, swapped);
        found = best.failure.empty();
      }
  if (!found) {
    // A C stream of 4 blocks starts like Fortran records (with 4): give both failures then.
    const auto likely = likely_layout(bytes);
    const auto primary = scan_binary<Dim>(bytes, likely.marker, likely.swapped);
    std::string also;
    if (likely.marker == 4) {
      const auto stream = scan_binary<Dim>(bytes, 0, likely.swapped);
      also = std::string("; read as a C stream of 4 blocks (") + (likely.swapped ? "opposite" : "native") +
             " byte order): " + stream.failure;
    }
    throw input_error(concat(file, ": not a valid binary Plot3D file; read as ", layout_text(primary.layout), ": ",
                             primary.failure, also));
  }
  byte_cursor c{bytes, best.layout.swapped, best.data_begin};
  flow::multiblock_points<double, Dim> g;
  g.blocks.resize(best.dims.size());
  for (std::size_t b = 0; b < best.dims.size(); ++b) {
    auto& blk = g.blocks[b];
    blk.points = best.dims[b];
    blk.x.resize(blk.n_points());
    c.pos += static_cast<std::size_t>(best.layout.marker);
    for (int d = 0; d < Dim; ++d)
      for (std::size_t k = 0; k < blk.x.size(); ++k) {
        double x = 0.0;
        bool ok = true;
        if (best.layout.real == 8) {
          ok = c.get(x);
        } else {
          float f = 0.0f;
          ok = c.get(f);
          x = f;
        }
        // (messages are built only on failure: this loop runs once per coordinate)
        if (!ok) throw input_error(concat(file, ": internal error: block ", b, " coordinates end early"));
        if (!std::isfinite(x))
          throw input_error(concat(file, ": block ", b, " ", point_text<Dim>(k, blk.points), ": coordinate ", d,
                                   " is ", x, ", not a finite number"));
        blk.x[k][d] = x;
      }
    c.pos += static_cast<std::size_t>(best.layout.marker);
  }
  return g;
}

}  // namespace internal

/// Checks that the coordinates are finite and that every cell volume and face area vector is
/// finite and every volume positive; throws input_error naming the grid, block and point or cell.
template <int Dim>
void validate_grid(const flow::multiblock_points<double, Dim>& g, const std::string& name) {
  const std::string where = "grid '" + name + "'";
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    const auto& blk = g.blocks[b];
    for (std::size_t k = 0; k < blk.x.size(); ++k)
      if (!std::all_of(blk.x[k].begin(), blk.x[k].end(), [](double v) { return std::isfinite(v); }))
        require_finite(blk.x[k], where,
                       internal::concat("block ", b, " ", internal::point_text<Dim>(k, blk.points), " coordinates"));
  }
  flow::grid_metrics<double, Dim> m;
  try {
    m = flow::compute_metrics<double, Dim>(g);
  } catch (const input_error& e) {
    throw input_error(internal::concat(where, ": ", e.what()));
  }
  // Coordinates near the overflow threshold give infinite areas and volumes.
  for (std::size_t b = 0; b < m.blocks.size(); ++b) {
    const auto& mb = m.blocks[b];
    for (std::size_t k = 0; k < mb.volume.size(); ++k)
      if (!std::isfinite(mb.volume[k])) {
        const auto c = flow::unravel<Dim>(k, mb.cells);
        std::string cell;
        for (int d = 0; d < Dim; ++d) {
          if (d) cell += ',';
          cell += std::to_string(c[d]);
        }
        throw input_error(internal::concat(where, ": block ", b, " cell (", cell, "): volume ", mb.volume[k],
                                 " is not finite (coordinates too large)"));
      }
    for (int d = 0; d < Dim; ++d)
      for (std::size_t k = 0; k < mb.normal[d].size(); ++k)
        if (!std::all_of(mb.normal[d][k].begin(), mb.normal[d][k].end(), [](double v) { return std::isfinite(v); }))
          throw input_error(internal::concat(where, ": block ", b, ": the area vector of face ", k, " normal to axis ", d,
                                   " is not finite (coordinates too large)"));
  }
}

/// Reads a whole multi-block Plot3D grid from the bytes of a file (format detected, see the top
/// of this header) and validates it. `name` is used in messages.
template <int Dim>
flow::multiblock_points<double, Dim> read_plot3d_bytes(std::string_view bytes, const std::string& name = "buffer") {
  const std::string file = "plot3d '" + name + "'";
  try {
    require(!bytes.empty(), file, ": empty file");
    constexpr std::string_view bom = "\xEF\xBB\xBF";
    bool text = bytes.substr(0, 3) == bom;
    if (text) {
      bytes.remove_prefix(3);
    } else {
      require(!(bytes.size() >= 2 && ((bytes[0] == '\xFF' && bytes[1] == '\xFE') || (bytes[0] == '\xFE' && bytes[1] == '\xFF'))),
              file, ": UTF-16/UTF-32 text is not supported (save the file as ASCII or UTF-8)");
      text = std::all_of(bytes.begin(), bytes.begin() + std::min<std::size_t>(bytes.size(), 4), [](char ch) {
        const auto u = static_cast<unsigned char>(ch);
        return (u >= 0x20 && u < 0x7f) || internal::text_tokens::separator(ch);
      });
    }
    auto g = text ? internal::read_ascii<Dim>(bytes, name) : internal::read_binary<Dim>(bytes, name);
    validate_grid<Dim>(g, name);
    return g;
  } catch (const input_error& e) {
    if (std::string_view(e.what()).find(name) != std::string_view::npos) throw;
    throw input_error(internal::concat(file, ": ", e.what()));
  } catch (const error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw input_error(internal::concat(file, ": out of memory reading a grid from ", bytes.size(), " bytes"));
  } catch (const std::exception& e) {
    throw input_error(internal::concat(file, ": ", e.what()));
  }
}

/// Reads a whole multi-block Plot3D grid from a stream (to its end; format detected) and
/// validates it. Failures of the stream itself are reported as input_error too.
template <int Dim>
flow::multiblock_points<double, Dim> read_plot3d(std::istream& in, const std::string& name = "stream") {
  std::string bytes;
  try {
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::bad_alloc&) {
    throw input_error(internal::concat("plot3d '", name, "': out of memory after reading ", bytes.size(), " bytes"));
  } catch (const std::exception& e) {
    throw input_error(internal::concat("plot3d '", name, "': reading failed after ", bytes.size(), " bytes: ", e.what()));
  } catch (...) {
    throw input_error(internal::concat("plot3d '", name, "': reading failed after ", bytes.size(), " bytes"));
  }
  return read_plot3d_bytes<Dim>(bytes, name);
}

template <int Dim>
flow::multiblock_points<double, Dim> read_plot3d(const std::string& path) {
  std::error_code ec;
  require(!std::filesystem::is_directory(path, ec), "plot3d: '", path, "' is a directory, not a grid file");
  std::ifstream in(path, std::ios::binary);
  require(in.good(), "plot3d: cannot open '", path, "'");
  return read_plot3d<Dim>(in, path);
}

namespace internal {
/// What write_plot3d can write: consistent blocks whose sizes and records fit the int32 fields.
template <int Dim>
void check_writable(const flow::multiblock_points<double, Dim>& g) {
  constexpr auto max32 = static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max());
  require(!g.blocks.empty() && g.blocks.size() <= max32 / (4 * Dim), "write_plot3d: ", g.blocks.size(),
          " blocks (need 1 to ", max32 / (4 * Dim), ")");
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    const auto& blk = g.blocks[b];
    for (int d = 0; d < Dim; ++d)
      require(blk.points[d] >= 1, "write_plot3d: block ", b, " has ", blk.points[d], " points along axis ", d);
    std::uint64_t n = 0;
    require(points_within<Dim>(blk.points, max32 / (8 * Dim), n), "write_plot3d: block ", b, " (",
            sizes_text<Dim>(blk.points), " points) exceeds the 2^31-byte limit of a record with 4-byte markers");
    require_size(blk.x.size(), n, "write_plot3d", internal::concat("block ", b, " coordinates"));
  }
}
}  // namespace internal

/// Writes a multi-block grid (format: see the top of this header). Throws input_error, before
/// writing anything, for inconsistent blocks, and after writing if the stream failed.
template <int Dim>
void write_plot3d(std::ostream& out, const flow::multiblock_points<double, Dim>& g, plot3d_format fmt) {
  internal::check_writable<Dim>(g);
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
  } else {
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
  require(out.good(), "write_plot3d: the stream failed while writing");
}

template <int Dim>
void write_plot3d(const std::string& path, const flow::multiblock_points<double, Dim>& g, plot3d_format fmt) {
  internal::check_writable<Dim>(g);
  std::ofstream out(path, fmt == plot3d_format::binary ? std::ios::binary : std::ios::out);
  require(out.good(), "plot3d: cannot write '", path, "'");
  write_plot3d<Dim>(out, g, fmt);
  out.flush();
  require(out.good(), "plot3d: writing '", path, "' failed");
}

}  // namespace aerohopf::io
