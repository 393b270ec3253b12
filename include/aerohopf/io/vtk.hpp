#pragma once
// Legacy-VTK output for ParaView: a multi-block flow field (all blocks in one UNSTRUCTURED_GRID
// file, quads in 2D, hexahedra in 3D, with cell data density, velocity, pressure, Mach number
// and Cp), the wall surface of a 3D flow (quads with the wall pressure and Cp), and a plate mesh
// with its structural modes (point data: thickness, each mode's deflection as a scalar and as a
// displacement vector for ParaView's Warp By Vector). Legacy ASCII is chosen because it needs no
// XML/base64 machinery and every ParaView version reads it.
#include <fstream>
#include <iomanip>
#include <map>
#include <string>

#include "../error.hpp"
#include "../flow/euler_model.hpp"
#include "../structure/plate_fe.hpp"

namespace aerohopf::io {

template <int Dim>
void write_vtk(const std::string& path, const flow::euler_model<Dim>& m, const vec<double>& w) {
  using namespace flow;
  constexpr int nv = Dim + 2;
  // Both checks come before the file is opened, so a refused state leaves no file behind. A
  // non-finite state is refused (the entry index names the cell: entry / (Dim + 2)) rather than
  // written as "nan", which the legacy-VTK reader does not parse.
  require_size(w.size(), m.size(), "write_vtk", "state");
  require_finite(w, "write_vtk", "state");
  std::ofstream out(path);
  require(out.good(), "write_vtk: cannot write '", path, "'");
  const auto& pts = m.grid().points;
  std::size_t npts = 0;
  for (const auto& b : pts.blocks) npts += b.n_points();
  out << "# vtk DataFile Version 3.0\naerohopf flow field\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << npts << " double\n" << std::setprecision(12);
  for (const auto& b : pts.blocks)
    for (const auto& x : b.x) out << x[0] << ' ' << x[1] << ' ' << (Dim == 3 ? x[Dim - 1] : 0.0) << '\n';
  const std::size_t nc = m.n_cells();
  constexpr int corners = Dim == 2 ? 4 : 8;
  out << "CELLS " << nc << ' ' << nc * (corners + 1) << '\n';
  std::size_t base = 0;
  for (const auto& b : pts.blocks) {
    const auto cells = b.cells();
    for (std::size_t c = 0; c < b.n_cells(); ++c) {
      const auto i = unravel<Dim>(c, cells);
      auto id = [&](int di, int dj, int dk) {
        index_d<Dim> p = i;
        p[0] += di;
        p[1] += dj;
        if constexpr (Dim == 3) p[2] += dk;
        return base + linear_index<Dim>(p, b.points);
      };
      out << corners;
      if constexpr (Dim == 2) {
        out << ' ' << id(0, 0, 0) << ' ' << id(1, 0, 0) << ' ' << id(1, 1, 0) << ' ' << id(0, 1, 0);
      } else {
        for (int k = 0; k < 2; ++k)
          out << ' ' << id(0, 0, k) << ' ' << id(1, 0, k) << ' ' << id(1, 1, k) << ' ' << id(0, 1, k);
      }
      out << '\n';
    }
    base += b.n_points();
  }
  out << "CELL_TYPES " << nc << '\n';
  for (std::size_t c = 0; c < nc; ++c) out << (Dim == 2 ? 9 : 12) << '\n';
  out << "CELL_DATA " << nc << '\n';
  auto prim = [&](std::size_t c) {
    state<double, Dim> s;
    for (int v = 0; v < nv; ++v) s[v] = w[static_cast<Eigen::Index>(c * nv + v)];
    return to_primitive<double, Dim>(s);
  };
  const double pinf = m.conditions().pressure();
  out << "SCALARS density double 1\nLOOKUP_TABLE default\n";
  for (std::size_t c = 0; c < nc; ++c) out << prim(c).rho << '\n';
  out << "SCALARS pressure double 1\nLOOKUP_TABLE default\n";
  for (std::size_t c = 0; c < nc; ++c) out << prim(c).p << '\n';
  out << "SCALARS cp double 1\nLOOKUP_TABLE default\n";
  for (std::size_t c = 0; c < nc; ++c) out << 2.0 * (prim(c).p - pinf) << '\n';
  out << "SCALARS mach double 1\nLOOKUP_TABLE default\n";
  for (std::size_t c = 0; c < nc; ++c) {
    const auto q = prim(c);
    out << std::sqrt(dot<double, Dim>(q.u, q.u)) / sound_speed(q) << '\n';
  }
  out << "VECTORS velocity double\n";
  for (std::size_t c = 0; c < nc; ++c) {
    const auto q = prim(c);
    out << q.u[0] << ' ' << q.u[1] << ' ' << (Dim == 3 ? q.u[Dim - 1] : 0.0) << '\n';
  }
  require(out.good(), "write_vtk: error while writing '", path, "'");
}

/// The plate mesh in its plane (z = 0) with point data thickness, mode_<k>_w (deflection of mode
/// k, k from 1) and mode_<k> (displacement vector (0, 0, w)). Modes as plate_modes_of returns them
/// (3 unknowns per node); checked before the file is opened.
inline void write_vtk_plate_modes(const std::string& path, const structure::plate_mesh& mesh,
                                  const structure::plate_modes& modes) {
  const char* who = "write_vtk_plate_modes";
  mesh.validate(who);
  require_size(modes.shapes.rows(), mesh.unknowns(), who, "mode shapes (rows)");
  require(modes.shapes.allFinite(), who, ": a mode shape is not finite");
  std::ofstream out(path);
  require(out.good(), who, ": cannot write '", path, "'");
  const std::size_t np = mesh.nodes.size(), nc = mesh.quads.size();
  out << "# vtk DataFile Version 3.0\naerohopf plate modes\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << np << " double\n" << std::setprecision(12);
  for (const auto& p : mesh.nodes) out << p.x() << ' ' << p.y() << " 0\n";
  out << "CELLS " << nc << ' ' << nc * 5 << '\n';
  for (const auto& q : mesh.quads) out << "4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
  out << "CELL_TYPES " << nc << '\n';
  for (std::size_t c = 0; c < nc; ++c) out << "9\n";
  out << "POINT_DATA " << np << "\nSCALARS thickness double 1\nLOOKUP_TABLE default\n";
  for (double t : mesh.thickness) out << t << '\n';
  for (Eigen::Index k = 0; k < modes.shapes.cols(); ++k) {
    out << "SCALARS mode_" << k + 1 << "_w double 1\nLOOKUP_TABLE default\n";
    for (std::size_t i = 0; i < np; ++i) out << modes.shapes(static_cast<Eigen::Index>(3 * i), k) << '\n';
    out << "VECTORS mode_" << k + 1 << " double\n";
    for (std::size_t i = 0; i < np; ++i) out << "0 0 " << modes.shapes(static_cast<Eigen::Index>(3 * i), k) << '\n';
  }
  require(out.good(), who, ": error while writing '", path, "'");
}

/// The walls of a 3D flow whose force tag is the model's (euler_options::force_tag; all walls if
/// empty) as quads with cell data cp and pressure (the Osher star pressure of the wall flux,
/// euler_model::wall_faces). Checked before the file is opened.
inline void write_vtk_wall_surface(const std::string& path, const flow::euler_model<3>& m, const vec<double>& w) {
  using namespace flow;
  const char* who = "write_vtk_wall_surface";
  require_size(w.size(), m.size(), who, "state");
  require_finite(w, who, "state");
  // wall_faces in a map by face centre (computed by the same function below: exact keys)
  std::map<std::array<double, 3>, std::pair<double, double>> at;
  for (const auto& f : m.wall_faces(w)) at[f.centre] = {f.cp, f.pressure};
  const auto& g = m.grid();
  const std::string& tag = m.options().force_tag;
  struct quad {
    std::array<std::array<double, 3>, 4> x;
    double cp, p;
  };
  std::vector<quad> quads;
  for (const auto& pt : g.topology.patches) {
    if (pt.kind != boundary_kind::wall || (!tag.empty() && pt.tag != tag)) continue;
    const auto& blk = g.points.blocks[static_cast<std::size_t>(pt.block)];
    const int d = pt.face / 2, side = pt.face % 2, a = (d + 1) % 3, b = (d + 2) % 3;
    const auto cells = blk.cells();
    for (int u = pt.begin[a]; u < pt.end[a]; ++u)
      for (int v = pt.begin[b]; v < pt.end[b]; ++v) {
        index_d<3> p{};
        p[d] = side ? cells[d] : 0;
        p[a] = u;
        p[b] = v;
        const auto c = flow::internal::face_centre<double, 3>(blk, d, p);
        const auto it = at.find(c);
        require(it != at.end(), who, ": wall face of block ", pt.block, " at (", p[0], ", ", p[1], ", ", p[2],
                ") not among the model's wall faces");
        quad q;
        for (int corner = 0; corner < 4; ++corner) {
          index_d<3> r = p;
          r[a] += corner == 1 || corner == 2;
          r[b] += corner >= 2;
          q.x[static_cast<std::size_t>(corner)] = blk.at(r);
        }
        q.cp = it->second.first;
        q.p = it->second.second;
        quads.push_back(q);
      }
  }
  require(!quads.empty(), who, ": no wall faces", tag.empty() ? std::string() : " tagged '" + tag + "'");
  std::ofstream out(path);
  require(out.good(), who, ": cannot write '", path, "'");
  out << "# vtk DataFile Version 3.0\naerohopf wall surface\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << 4 * quads.size() << " double\n" << std::setprecision(12);
  for (const auto& q : quads)
    for (const auto& x : q.x) out << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
  out << "CELLS " << quads.size() << ' ' << 5 * quads.size() << '\n';
  for (std::size_t c = 0; c < quads.size(); ++c)
    out << "4 " << 4 * c << ' ' << 4 * c + 1 << ' ' << 4 * c + 2 << ' ' << 4 * c + 3 << '\n';
  out << "CELL_TYPES " << quads.size() << '\n';
  for (std::size_t c = 0; c < quads.size(); ++c) out << "9\n";
  out << "CELL_DATA " << quads.size() << "\nSCALARS cp double 1\nLOOKUP_TABLE default\n";
  for (const auto& q : quads) out << q.cp << '\n';
  out << "SCALARS pressure double 1\nLOOKUP_TABLE default\n";
  for (const auto& q : quads) out << q.p << '\n';
  require(out.good(), who, ": error while writing '", path, "'");
}

}  // namespace aerohopf::io
