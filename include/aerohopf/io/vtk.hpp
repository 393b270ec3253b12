#pragma once
// Legacy-VTK output of a multi-block flow field for ParaView: all blocks in one UNSTRUCTURED_GRID
// file (quads in 2D, hexahedra in 3D) with cell data density, velocity, pressure, Mach number
// and Cp. Legacy ASCII is chosen because it needs no XML/base64 machinery and every ParaView
// version reads it.
#include <fstream>
#include <iomanip>
#include <string>

#include "../error.hpp"
#include "../flow/euler_model.hpp"

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

}  // namespace aerohopf::io
