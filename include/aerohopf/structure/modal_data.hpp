#pragma once
// Modal data of a structure as users have them: structural points (id and position) and, per
// mode, the circular frequency, the generalised mass of the shape as stored, and the shape at
// every point as six components (translations T1..T3, rotations R1..R3, the NASTRAN order).
// The wing coupling takes the translations at the points into the surface spline; the
// frequencies and generalised masses make the modal equations (modal_structure.hpp).
//
// Sources: our own plate elements (modal_data_from_plate), the documented CSV below, and
// NASTRAN punch output (io/nastran.hpp). Every reader ends in modal_data::validate, so a file
// that parses but makes no sense (a mode without points, a non-finite entry, a negative
// frequency, duplicate point ids) is refused with its name and the offending entry.
//
// CSV (read_modal_csv / write_modal_csv): header exactly
//     mode,frequency_hz,generalised_mass,point,x,y,z,t1,t2,t3,r1,r2,r3
// one row per mode and point, modes numbered from 1 in order, every mode over the same points in
// the same order, frequency and generalised mass repeated on each row of a mode.
#include <Eigen/Dense>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <istream>
#include <ostream>
#include <numbers>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "../error.hpp"
#include "plate_fe.hpp"

namespace aerohopf::structure {

struct modal_data {
  std::vector<long long> point_ids;
  std::vector<Eigen::Vector3d> points;
  Eigen::VectorXd omega;             ///< circular frequencies, rad/s
  Eigen::VectorXd generalised_mass;  ///< phi^T M phi of each shape as stored
  std::vector<Eigen::MatrixXd> shapes;  ///< per mode: points x 6 (t1 t2 t3 r1 r2 r3)

  Eigen::Index modes() const { return omega.size(); }
  std::size_t size() const { return points.size(); }
  double frequency_hz(Eigen::Index k) const { return omega[k] / (2 * std::numbers::pi); }

  /// Throws input_error naming `source` and the first inconsistent entry.
  void validate(const std::string& source) const {
    const std::string who = "modal data (" + source + ")";
    require(!points.empty(), who, ": no structural points");
    require(omega.size() > 0, who, ": no modes");
    require_size(point_ids.size(), points.size(), who, "point ids");
    require_size(generalised_mass.size(), omega.size(), who, "generalised masses");
    require_size(shapes.size(), omega.size(), who, "mode shapes");
    std::unordered_set<long long> seen;
    for (std::size_t i = 0; i < points.size(); ++i) {
      require(points[i].allFinite(), who, ": point ", point_ids[i], " has a non-finite coordinate");
      require(seen.insert(point_ids[i]).second, who, ": point id ", point_ids[i], " appears twice");
    }
    for (Eigen::Index k = 0; k < omega.size(); ++k) {
      require(std::isfinite(omega[k]) && omega[k] >= 0, who, ": mode ", k + 1, " has frequency ", omega[k],
              " rad/s (must be finite and >= 0)");
      require(std::isfinite(generalised_mass[k]) && generalised_mass[k] > 0, who, ": mode ", k + 1,
              " has generalised mass ", generalised_mass[k], " (must be finite and > 0)");
      const Eigen::MatrixXd& s = shapes[static_cast<std::size_t>(k)];
      require(s.rows() == static_cast<Eigen::Index>(points.size()) && s.cols() == 6, who, ": mode ", k + 1,
              " shape is ", s.rows(), " x ", s.cols(), ", expected ", points.size(), " x 6");
      require(s.allFinite(), who, ": mode ", k + 1, " has a non-finite shape entry");
      require(s.cwiseAbs().maxCoeff() > 0, who, ": mode ", k + 1, " has a zero shape");
    }
  }

  /// The same modes scaled to unit generalised mass (phi^T M phi = 1).
  modal_data mass_normalised() const {
    modal_data r = *this;
    for (Eigen::Index k = 0; k < omega.size(); ++k) {
      r.shapes[static_cast<std::size_t>(k)] /= std::sqrt(generalised_mass[k]);
      r.generalised_mass[k] = 1;
    }
    return r;
  }
};

/// Plate modes (plate_fe.hpp) at the mesh nodes, z = 0: t3 = w, rotations r1 = -beta_y, r2 =
/// beta_x (right-handed rotations about x and y: u = z beta_x = z r2, v = z beta_y = -z r1),
/// generalised mass 1 (plate_modes are mass-normalised). Point ids are node index + 1.
inline modal_data modal_data_from_plate(const plate_mesh& mesh, const plate_modes& modes) {
  require_size(modes.shapes.rows(), mesh.unknowns(), "modal_data_from_plate", "mode shapes (rows)");
  modal_data d;
  const std::size_t n = mesh.nodes.size();
  for (std::size_t i = 0; i < n; ++i) {
    d.point_ids.push_back(static_cast<long long>(i) + 1);
    d.points.emplace_back(mesh.nodes[i].x(), mesh.nodes[i].y(), 0.0);
  }
  d.omega = modes.omega;
  d.generalised_mass = Eigen::VectorXd::Ones(modes.omega.size());
  for (Eigen::Index k = 0; k < modes.omega.size(); ++k) {
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), 6);
    for (std::size_t i = 0; i < n; ++i) {
      const auto r = static_cast<Eigen::Index>(i), b = static_cast<Eigen::Index>(3 * i);
      s(r, 2) = modes.shapes(b, k);
      s(r, 3) = -modes.shapes(b + 2, k);
      s(r, 4) = modes.shapes(b + 1, k);
    }
    d.shapes.push_back(std::move(s));
  }
  d.validate("plate modes");
  return d;
}

inline constexpr const char* modal_csv_header = "mode,frequency_hz,generalised_mass,point,x,y,z,t1,t2,t3,r1,r2,r3";

/// Writes the documented CSV (full precision) to a stream; validates first (`name` in the message).
inline void write_modal_csv(std::ostream& out, const modal_data& d, const std::string& name = "modal CSV") {
  d.validate(name);
  out << modal_csv_header << "\n";
  const auto old = out.precision(17);
  for (Eigen::Index k = 0; k < d.modes(); ++k)
    for (std::size_t i = 0; i < d.size(); ++i) {
      out << k + 1 << ',' << d.frequency_hz(k) << ',' << d.generalised_mass[k] << ',' << d.point_ids[i];
      for (int c = 0; c < 3; ++c) out << ',' << d.points[i][c];
      for (int c = 0; c < 6; ++c) out << ',' << d.shapes[static_cast<std::size_t>(k)](static_cast<Eigen::Index>(i), c);
      out << '\n';
    }
  out.precision(old);
}

/// Writes the documented CSV file. Validates first: nothing is written for bad data.
inline void write_modal_csv(const std::filesystem::path& file, const modal_data& d) {
  d.validate(file.string());
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file);
  require(out.good(), "write_modal_csv: cannot write ", file.string());
  write_modal_csv(out, d, file.string());
  require(out.good(), "write_modal_csv: error while writing ", file.string());
}

/// Reads the documented CSV from a stream (`name` in every message); throws input_error with the
/// name, line and field of the first malformed entry (wrong header, wrong field count, a
/// non-number, modes out of order or over other points than mode 1).
inline modal_data read_modal_csv(std::istream& in, const std::string& name) {
  std::string line;
  require(static_cast<bool>(std::getline(in, line)), name, ": empty file (expected the header ", modal_csv_header, ")");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  require(line == modal_csv_header, name, ": line 1: header must be exactly '", modal_csv_header, "' (got '", line,
          "')");
  modal_data d;
  std::vector<double> om, gm;
  std::vector<std::vector<double>> rows_of_mode;  // current mode's shape rows, 6 each
  long long mode = 0;
  std::size_t point_in_mode = 0;
  auto finish_mode = [&]() {
    if (mode == 0) return;
    require(point_in_mode == d.points.size(), name, ": mode ", mode, " has ", point_in_mode, " points, mode 1 has ",
            d.points.size());
    Eigen::MatrixXd s(static_cast<Eigen::Index>(d.points.size()), 6);
    for (std::size_t i = 0; i < d.points.size(); ++i)
      for (int c = 0; c < 6; ++c) s(static_cast<Eigen::Index>(i), c) = rows_of_mode[i][static_cast<std::size_t>(c)];
    d.shapes.push_back(std::move(s));
    rows_of_mode.clear();
  };
  for (long long ln = 2; std::getline(in, line); ++ln) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    require(f.size() == 13, name, ": line ", ln, ": ", f.size(), " fields, expected 13");
    std::vector<double> v(13);
    for (std::size_t c = 0; c < 13; ++c) {
      std::size_t used = 0;
      try {
        v[c] = std::stod(f[c], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      require(used > 0 && f[c].find_first_not_of(" \t", used) == std::string::npos, name, ": line ", ln, ": field ",
              c + 1, " ('", f[c], "') is not a number");
      require(std::isfinite(v[c]), name, ": line ", ln, ": field ", c + 1, " is not finite");
    }
    // integers: checked before the conversion (a double out of long long's range converts to UB)
    auto integer = [&](std::size_t c, const char* what) {
      require(v[c] == std::floor(v[c]) && std::abs(v[c]) < 9.0e15, name, ": line ", ln, ": ", what, " ", f[c],
              " is not an integer below 9e15");
      return static_cast<long long>(v[c]);
    };
    const long long m = integer(0, "mode number");
    if (m != mode) {
      require(m == mode + 1, name, ": line ", ln, ": mode ", m, " follows mode ", mode, " (modes must run 1, 2, ...)");
      finish_mode();
      mode = m;
      point_in_mode = 0;
      om.push_back(2 * std::numbers::pi * v[1]);
      gm.push_back(v[2]);
    }
    const long long id = integer(3, "point id");
    if (mode == 1) {
      d.point_ids.push_back(id);
      d.points.emplace_back(v[4], v[5], v[6]);
    } else {
      require(point_in_mode < d.points.size() && d.point_ids[point_in_mode] == id, name, ": line ", ln, ": mode ", mode,
              " point ", id, " is not point ", point_in_mode + 1, " of mode 1");
    }
    rows_of_mode.emplace_back(v.begin() + 7, v.end());
    ++point_in_mode;
  }
  finish_mode();
  d.omega = Eigen::Map<const Eigen::VectorXd>(om.data(), static_cast<Eigen::Index>(om.size()));
  d.generalised_mass = Eigen::Map<const Eigen::VectorXd>(gm.data(), static_cast<Eigen::Index>(gm.size()));
  d.validate(name);
  return d;
}

/// Reads the documented CSV file.
inline modal_data read_modal_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  require(in.good(), "read_modal_csv: cannot open ", file.string());
  return read_modal_csv(in, file.string());
}

}  // namespace aerohopf::structure
