#pragma once
// NASTRAN modal data: the structural points from the bulk data (GRID entries, small field, large
// field GRID* with its continuation, or free field) and the eigenvectors from punch output (SOL
// 103 with DISP(PUNCH) = ALL), into structure::modal_data; and the same two formats written, so
// that our own finite-element modes go through the reader a user's NASTRAN modes take.
//
// Punch output, per mode:
//     $EIGENVALUE =  0.3638206E+04  MODE =     1
//              1       G      0.000000E+00      0.000000E+00      1.000000E+00
//     -CONT-                  0.000000E+00      2.000000E-01      0.000000E+00
// (the grid id, G, T1 T2 T3; the continuation R1 R2 R3; columns 73-80 hold a line count and are
// ignored; other $ lines are titles). The eigenvalue is omega^2 (rad/s)^2. Punch files do not
// carry the generalised mass: NASTRAN's default normalisation (NORM = MASS) makes it 1, which is
// assumed unless the caller passes the masses (NORM = MAX shapes).
// GRID: ID, CP, X1, X2, X3 in the basic coordinate system (CP blank or 0; others are refused,
// export in the basic system). Real fields in NASTRAN's forms (1.5, 1.5E-3, 1.5D-3, 1.5-3, 7.).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <istream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../structure/modal_data.hpp"
#include "text_numbers.hpp"

namespace aerohopf::io {

namespace internal {
inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

/// A NASTRAN real field: 1.5, 1.5E-3, 1.5D-3, 1.5-3 (implicit exponent), 7. (nullopt if not a
/// finite real number).
inline std::optional<double> nastran_real(const std::string& field) {
  double v = 0;
  if (parse_real(trim(field), v) != real_status::ok || !std::isfinite(v)) return std::nullopt;
  return v;
}

inline std::optional<long long> nastran_int(const std::string& field) {
  long long v = 0;
  if (!parse_integer(trim(field), v)) return std::nullopt;
  return v;
}

/// Fixed-width field k (0-based, after the 8-character name field) of a small- or large-field card.
inline std::string fixed_field(const std::string& line, std::size_t k, std::size_t width) {
  const std::size_t b = 8 + k * width;
  if (b >= line.size()) return "";
  return line.substr(b, std::min(width, line.size() - b));
}
}  // namespace internal

struct nastran_grid_point {
  long long id = 0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
};

/// GRID entries of bulk data from a stream (`name` in every message), in order; throws
/// input_error with the name, line and field of the first malformed entry.
inline std::vector<nastran_grid_point> read_nastran_grid(std::istream& in, const std::string& name) {
  std::vector<nastran_grid_point> pts;
  std::string line;
  long long ln = 0;
  auto coordinates = [&](long long at, const std::string& id, const std::string& cp, const std::string& x1,
                         const std::string& x2, const std::string& x3) {
    nastran_grid_point p;
    const auto i = internal::nastran_int(id);
    require(i.has_value() && *i > 0, name, ": line ", at, ": GRID id '", internal::trim(id),
            "' is not a positive integer");
    p.id = *i;
    const std::string c = internal::trim(cp);
    require(c.empty() || c == "0", name, ": line ", at, ": GRID ", p.id, " is given in coordinate system CP = ", c,
            "; only the basic system (CP blank or 0) is supported: export the points in the basic system");
    const std::string xs[3] = {x1, x2, x3};
    for (int k = 0; k < 3; ++k) {
      const std::string t = internal::trim(xs[k]);
      const auto v = t.empty() ? std::optional<double>(0.0) : internal::nastran_real(t);
      require(v.has_value(), name, ": line ", at, ": GRID ", p.id, " coordinate X", k + 1, " '", t,
              "' is not a real number");
      p.x[k] = *v;
    }
    pts.push_back(p);
  };
  while (std::getline(in, line)) {
    ++ln;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("GRID*", 0) == 0) {  // large field: 16-character fields, then a '*' continuation
      std::string cont;
      const long long at = ln;
      require(static_cast<bool>(std::getline(in, cont)), name, ": line ", at, ": GRID* without its continuation line");
      ++ln;
      if (!cont.empty() && cont.back() == '\r') cont.pop_back();
      require(!cont.empty() && cont[0] == '*', name, ": line ", ln, ": the continuation of GRID* must start with '*'");
      coordinates(at, internal::fixed_field(line, 0, 16), internal::fixed_field(line, 1, 16),
                  internal::fixed_field(line, 2, 16), internal::fixed_field(line, 3, 16),
                  internal::fixed_field(cont, 0, 16));
    } else if (line.rfind("GRID,", 0) == 0) {  // free field
      std::vector<std::string> f;
      std::stringstream ss(line);
      for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
      f.resize(std::max<std::size_t>(f.size(), 6));
      coordinates(ln, f[1], f[2], f[3], f[4], f[5]);
    } else if (line.rfind("GRID", 0) == 0 && (line.size() == 4 || line[4] == ' ')) {  // small field
      coordinates(ln, internal::fixed_field(line, 0, 8), internal::fixed_field(line, 1, 8),
                  internal::fixed_field(line, 2, 8), internal::fixed_field(line, 3, 8),
                  internal::fixed_field(line, 4, 8));
    }
  }
  require(!pts.empty(), name, ": no GRID entries");
  return pts;
}

/// GRID entries of a bulk data file.
inline std::vector<nastran_grid_point> read_nastran_grid(const std::filesystem::path& file) {
  std::ifstream in(file);
  require(in.good(), "read_nastran_grid: cannot open ", file.string());
  return read_nastran_grid(in, file.string());
}

/// Writes the points as large-field GRID* entries (16-character fields: 9 significant digits).
inline void write_nastran_grid(const std::filesystem::path& file, const structure::modal_data& d) {
  d.validate(file.string());
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file);
  require(out.good(), "write_nastran_grid: cannot write ", file.string());
  out << "$ structural points (aerohopf)\n";
  char buf[128];
  for (std::size_t i = 0; i < d.size(); ++i) {
    const Eigen::Vector3d& x = d.points[i];
    std::snprintf(buf, sizeof buf, "GRID*   %16lld%16s%16.9E%16.9E\n*       %16.9E\n", d.point_ids[i], "0", x[0], x[1],
                  x[2]);
    out << buf;
  }
  require(out.good(), "write_nastran_grid: error while writing ", file.string());
}

/// Eigenvectors of punch output from a stream (`name` in every message) over the grid points
/// read from `bulk`: modal_data in grid order (a point missing from a mode's output, a scalar
/// point or a point without a GRID entry is an error). generalised_masses: one per mode, or
/// empty for 1.
inline structure::modal_data read_nastran_modes(std::istream& in, const std::string& name,
                                                const std::vector<nastran_grid_point>& grid, const std::string& bulk,
                                                const std::vector<double>& generalised_masses = {}) {
  std::map<long long, std::size_t> index;
  structure::modal_data d;
  for (const auto& p : grid) {
    require(index.emplace(p.id, d.points.size()).second, bulk, ": GRID ", p.id, " appears twice");
    d.point_ids.push_back(p.id);
    d.points.push_back(p.x);
  }
  std::vector<double> omega;
  std::vector<std::vector<bool>> seen;
  std::string line;
  long long ln = 0, pending = -1;  // pending: row of the point whose continuation comes next
  auto numbers3 = [&](const std::string& rest, const char* what) {
    std::istringstream ss(rest);
    std::string tok;
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      require(static_cast<bool>(ss >> tok), name, ": line ", ln, ": ", what, " needs 3 values");
      const auto x = internal::nastran_real(tok);
      require(x.has_value(), name, ": line ", ln, ": ", what, " value '", tok, "' is not a real number");
      v[k] = *x;
    }
    return v;
  };
  while (std::getline(in, line)) {
    ++ln;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() > 72) line.resize(72);  // columns 73-80: line count
    const std::string t = internal::trim(line);
    if (t.empty()) continue;
    if (t[0] == '$') {
      const auto e = t.find("EIGENVALUE");
      if (e == std::string::npos) continue;
      const auto eq = t.find('=', e), mo = t.find("MODE", e);
      require(eq != std::string::npos && mo != std::string::npos && mo > eq, name, ": line ", ln,
              ": malformed $EIGENVALUE line: '", t, "'");
      const auto lambda = internal::nastran_real(t.substr(eq + 1, mo - eq - 1));
      require(lambda.has_value(), name, ": line ", ln, ": eigenvalue '", internal::trim(t.substr(eq + 1, mo - eq - 1)),
              "' is not a real number");
      // a rigid-body mode's eigenvalue can be slightly negative by rounding
      require(*lambda > -1e-3, name, ": line ", ln, ": negative eigenvalue ", *lambda, " of mode ", omega.size() + 1);
      require(pending < 0, name, ": line ", ln, ": the previous mode's last point lacks its -CONT- line");
      omega.push_back(std::sqrt(std::max(*lambda, 0.0)));
      d.shapes.push_back(Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d.size()), 6));
      seen.emplace_back(d.size(), false);
      continue;
    }
    require(!omega.empty(), name, ": line ", ln, ": data before the first $EIGENVALUE line");
    std::istringstream ss(t);
    std::string first, type;
    ss >> first;
    std::string rest;
    if (first == "-CONT-") {
      require(pending >= 0, name, ": line ", ln, ": -CONT- without a point line before it");
      std::getline(ss, rest);
      d.shapes.back().row(pending).tail<3>() = numbers3(rest, "rotations R1 R2 R3").transpose();
      pending = -1;
      continue;
    }
    require(pending < 0, name, ": line ", ln, ": point line where the -CONT- line of the previous point belongs");
    const auto id = internal::nastran_int(first);
    require(id.has_value(), name, ": line ", ln, ": '", first, "' is neither a point id nor -CONT-");
    ss >> type;
    require(type == "G", name, ": line ", ln, ": point ", *id, " has type '", type,
            "' (only grid points, G, carry translations and rotations)");
    const auto it = index.find(*id);
    require(it != index.end(), name, ": line ", ln, ": point ", *id, " has no GRID entry in ", bulk);
    require(!seen.back()[it->second], name, ": line ", ln, ": point ", *id, " appears twice in mode ", omega.size());
    seen.back()[it->second] = true;
    std::getline(ss, rest);
    d.shapes.back().row(static_cast<Eigen::Index>(it->second)).head<3>() =
        numbers3(rest, "translations T1 T2 T3").transpose();
    pending = static_cast<long long>(it->second);
  }
  require(pending < 0, name, ": the last point lacks its -CONT- line");
  require(!omega.empty(), name, ": no $EIGENVALUE lines (not an eigenvector punch file?)");
  for (std::size_t k = 0; k < seen.size(); ++k)
    for (std::size_t i = 0; i < seen[k].size(); ++i)
      require(seen[k][i], name, ": mode ", k + 1, " has no values for GRID ", d.point_ids[i]);
  require(generalised_masses.empty() || generalised_masses.size() == omega.size(), "read_nastran_modes: ",
          generalised_masses.size(), " generalised masses for ", omega.size(), " modes");
  d.omega = Eigen::Map<const Eigen::VectorXd>(omega.data(), static_cast<Eigen::Index>(omega.size()));
  d.generalised_mass = generalised_masses.empty()
                           ? Eigen::VectorXd::Ones(d.omega.size())
                           : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(generalised_masses.data(),
                                                                                static_cast<Eigen::Index>(generalised_masses.size())));
  d.validate(name);
  return d;
}

/// Eigenvectors of a punch file with the points of a bulk data file.
inline structure::modal_data read_nastran_modes(const std::filesystem::path& punch, const std::filesystem::path& bulk,
                                                const std::vector<double>& generalised_masses = {}) {
  const std::vector<nastran_grid_point> grid = read_nastran_grid(bulk);
  std::ifstream in(punch);
  require(in.good(), "read_nastran_modes: cannot open ", punch.string());
  return read_nastran_modes(in, punch.string(), grid, bulk.string(), generalised_masses);
}

/// Writes the modes as NASTRAN punch output (mass-normalised first, as NORM = MASS would).
inline void write_nastran_punch(const std::filesystem::path& file, const structure::modal_data& data) {
  data.validate(file.string());
  const structure::modal_data d = data.mass_normalised();
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file);
  require(out.good(), "write_nastran_punch: cannot write ", file.string());
  long long seq = 0;
  char buf[160];
  auto put = [&](const std::string& text) {
    std::snprintf(buf, sizeof buf, "%-72s%8lld\n", text.c_str(), ++seq);
    out << buf;
  };
  char t[128];
  for (Eigen::Index k = 0; k < d.modes(); ++k) {
    put("$TITLE   = aerohopf modes");
    put("$EIGENVECTOR");
    put("$REAL OUTPUT");
    std::snprintf(t, sizeof t, "$EIGENVALUE = %14.7E  MODE = %5lld", d.omega[k] * d.omega[k],
                  static_cast<long long>(k + 1));
    put(t);
    const Eigen::MatrixXd& s = d.shapes[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < d.size(); ++i) {
      const auto r = static_cast<Eigen::Index>(i);
      std::snprintf(t, sizeof t, "%10lld       G  %16.9E  %16.9E  %16.9E", d.point_ids[i], s(r, 0), s(r, 1), s(r, 2));
      put(t);
      std::snprintf(t, sizeof t, "-CONT-             %16.9E  %16.9E  %16.9E", s(r, 3), s(r, 4), s(r, 5));
      put(t);
    }
  }
  require(out.good(), "write_nastran_punch: error while writing ", file.string());
}

}  // namespace aerohopf::io
