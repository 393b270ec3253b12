#pragma once
// C-H grid around a swept, tapered wing (wing_geometry.hpp; symmetric or cambered sections, a
// cambered one's cut beyond the tip on the tip's camber line) with a symmetry plane at the root
// and a closed, rounded tip: one block, generated as the finest level of a family from which
// coarsen() makes the others (strides 2, 4, 8: nested levels for grid sequencing).
//
// Topology: at every spanwise station a 2D C-grid in the x-z plane (grid_marching.hpp) around
// the local section: i runs from the upper outflow upstream along the upper side of the wake cut,
// round the section (upper surface trailing edge to leading edge, then lower), and out along the
// lower side of the wake; j runs outward; k runs spanwise from the root (y = 0) past the tip to
// the far span. (e_i, e_j, e_k) is right-handed. The section thickness is scaled by a tip factor
// that closes it over a rounded cap, sqrt(1 - ((y - y_c)/(b - y_c))^2) on y in [y_c, b] with b -
// y_c the tip cap radius (the tip half-thickness), and beyond the tip every station is the tip's
// section at zero thickness: a cut, like the wake. So the tip edge has no singular line: the
// cells that wrap the cap are ordinary hexahedra, whose quality the generator reports.
//
// Coordinates are in root chords (the flow solver's unit of length, spec 06), the planform's
// leading edge at the root at the origin.
//
// Boundaries: the wing (j = 0, section cells, root to tip) is a wall tagged "wing"; the wake cut
// and the cut beyond the tip are interfaces of the block with itself (i reversed); the root plane
// k = 0 is a slip wall tagged "symmetry"; the outer C (j max), the outflow ends (i min, i max) and
// the far-span plane (k max) are far field.
//
// Sizes: the defaults make the fine level (289 x 65 x 81 points, 1.5 M); stride 2 gives the
// medium one (145 x 33 x 41, 196,000 points, 3,500 on the wing), stride 4 the coarse one
// (73 x 17 x 21, 26,000 points, 900 on the wing), stride 8 a very coarse one (2,900 cells).
// All cell counts are multiples of 8 so that every level keeps every patch.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "grid_marching.hpp"
#include "structured_grid.hpp"
#include "wing_geometry.hpp"

namespace aerohopf::flow {

struct wing_grid_options {
  int wake_cells = 40;       ///< along each side of the wake cut
  int section_cells = 104;   ///< along each surface, leading to trailing edge
  int normal_cells = 64;     ///< wall to outer boundary
  int span_cells = 64;       ///< root to tip
  int outboard_cells = 16;   ///< tip to far span
  double far_field = 10.0;   ///< outer boundary, wake length and far span, in root chords
  double first_height = 0.002;  ///< first cell height at the wall, in root chords
  double clustering = 0.7;   ///< chordwise: 0 uniform in arc length, -> 1 clustered at both edges
  double span_clustering = 0.5;  ///< spanwise: 0 uniform, 1 sine clustering at the tip
  double smoothing = 8.0;
  int redistribution_passes = 20;
  /// Bound of each layer's tangential redistribution in the wake, in steps
  /// (internal::march_c_layers; 0: none): the wake's lines lean at most 45 deg per layer.
  /// Unbounded, the far wake's thin layers (the AGARD medium grid's cells at the cut 2.6 root
  /// chords long and 0.004 thick) leaned their i = const lines almost along the cut, and the
  /// medium steady flow at M = 0.96 stalled in Newton (GMRES at a relative residual of 0.92
  /// after 1,000 iterations); bounded, it converges in 24 steps.
  double max_shift = 1.0;
  int multiple = 8;          ///< every cell count must divide by this (coarsest stride)
};

/// Where the wing and the cuts lie in the cell indices of a wing_cgrid level (stride 1: the fine
/// grid wing_cgrid makes, s: coarsen(fine, s)). Point index i = wing_begin is the upper trailing
/// edge, leading_edge the leading edge, wing_end the lower trailing edge; point k = tip the tip
/// station. Cells [wing_begin, wing_end) x [0, tip) of the face j = 0 are the wing.
struct wing_grid_layout {
  int wing_begin = 0, leading_edge = 0, wing_end = 0, tip = 0;
  index_d<3> cells{};

  static wing_grid_layout of(const wing_grid_options& o, int stride = 1) {
    require(stride >= 1 && o.wake_cells % stride == 0 && o.section_cells % stride == 0 && o.normal_cells % stride == 0 &&
                o.span_cells % stride == 0 && o.outboard_cells % stride == 0,
            "wing_grid_layout: stride ", stride, " does not divide the grid's cell counts");
    wing_grid_layout l;
    l.wing_begin = o.wake_cells / stride;
    l.leading_edge = l.wing_begin + o.section_cells / stride;
    l.wing_end = l.leading_edge + o.section_cells / stride;
    l.tip = o.span_cells / stride;
    l.cells = {l.wing_end + o.wake_cells / stride, o.normal_cells / stride, l.tip + o.outboard_cells / stride};
    return l;
  }
  /// Points on the wing surface (both sides, root to tip station).
  std::size_t wing_points() const {
    return static_cast<std::size_t>(wing_end - wing_begin + 1) * static_cast<std::size_t>(tip + 1);
  }
  /// The wall cells round the tip: `stations` either side of the tip station, `layers` off the wall.
  std::pair<index_d<3>, index_d<3>> tip_cells(int stations = 2, int layers = 2) const {
    return {{wing_begin, 0, tip - stations}, {wing_end, layers, tip + stations}};
  }
};

/// Cell-quality figures of hexahedral cells (hexahedron_quality).
struct grid_quality {
  double min_volume = 0, max_volume = 0;
  /// Smallest det J at the 8 corners of a cell over the cell's mean (1 for a parallelepiped,
  /// < 0 folded), over the cells without a collinear corner.
  double min_corner_ratio = 0;
  /// Cells with a corner ratio within 1e-9 of zero (three corner points on a line): in a C-grid,
  /// the two cells at the leading edge of a zero-thickness cut, where the grid turns by 180 deg;
  /// their volume is positive (they are triangles in the section plane).
  std::size_t collinear_cells = 0;
  double min_ratio_all = 0;  ///< the smallest corner ratio of any cell (>= -1e-9 unless folded)
  std::size_t cells = 0;
  std::array<int, 4> worst_cell{};  ///< block, i, j, k of min_corner_ratio
};

namespace internal {
/// Chord fractions of n + 1 points from leading to trailing edge, uniform in the arc length of
/// the section's thickness distribution with clustering a at both ends (as naca_cgrid); the same
/// fractions serve both surfaces of a cambered section.
inline std::vector<double> chord_fractions(const section_ordinates& s, int n, double a) {
  const int nfine = 20001;
  std::vector<double> xi(nfine), arc(nfine, 0.0);
  for (int k = 0; k < nfine; ++k) {
    xi[static_cast<std::size_t>(k)] = 0.5 * (1.0 - std::cos(std::numbers::pi * k / (nfine - 1)));
    if (k) {
      const auto u = static_cast<std::size_t>(k);
      const double dz = s.half_thickness(xi[u]) - s.half_thickness(xi[u - 1]);
      arc[u] = arc[u - 1] + std::hypot(xi[u] - xi[u - 1], dz);
    }
  }
  std::vector<double> out(static_cast<std::size_t>(n) + 1);
  std::size_t seg = 0;
  for (int k = 0; k <= n; ++k) {
    const double u = static_cast<double>(k) / n;
    const double t = arc.back() * (u - a * std::sin(2.0 * std::numbers::pi * u) / (2.0 * std::numbers::pi));
    while (seg + 2 < arc.size() && arc[seg + 1] < t) ++seg;
    const double w = std::clamp((t - arc[seg]) / (arc[seg + 1] - arc[seg]), 0.0, 1.0);
    out[static_cast<std::size_t>(k)] = xi[seg] + w * (xi[seg + 1] - xi[seg]);
  }
  out.front() = 0.0;
  out.back() = 1.0;
  return out;
}
}  // namespace internal

/// The C-H grid of the finest level (see the file comment). Throws input_error for bad options.
inline multiblock_grid<3> wing_cgrid(const wing_geometry& w, const wing_grid_options& o = {}) {
  const char* who = "wing_cgrid";
  w.planform.validate(who);
  for (int c : {o.wake_cells, o.section_cells, o.normal_cells, o.span_cells, o.outboard_cells})
    require(c >= 2 && o.multiple >= 1 && c % o.multiple == 0, who, ": every cell count must be >= 2 and a multiple of ",
            o.multiple, " (wake ", o.wake_cells, ", section ", o.section_cells, ", normal ", o.normal_cells, ", span ",
            o.span_cells, ", outboard ", o.outboard_cells, ")");
  require(o.far_field > 2 && o.first_height > 0 && o.first_height * o.normal_cells < o.far_field, who,
          ": need far_field > 2 root chords and 0 < first_height < far_field / normal_cells (got ", o.far_field, ", ",
          o.first_height, ")");
  require(o.clustering >= 0 && o.clustering < 1 && o.span_clustering >= 0 && o.span_clustering <= 1, who,
          ": clustering in [0, 1) and span_clustering in [0, 1] (got ", o.clustering, ", ", o.span_clustering, ")");
  require(o.max_shift >= 0 && std::isfinite(o.max_shift), who, ": max_shift must be finite and >= 0 (got ", o.max_shift,
          ")");
  const wing_planform& p = w.planform;
  const double cr = p.root_chord, b = p.semi_span;
  const int nw = o.wake_cells, ns = o.section_cells, nj = o.normal_cells + 1;
  const int ni = 2 * nw + 2 * ns + 1, nk = o.span_cells + o.outboard_cells + 1;

  // spanwise stations: blended uniform / sine clustering to the tip, geometric beyond it
  std::vector<double> ys(static_cast<std::size_t>(nk));
  for (int k = 0; k <= o.span_cells; ++k) {
    const double s = static_cast<double>(k) / o.span_cells;
    ys[static_cast<std::size_t>(k)] =
        b * ((1 - o.span_clustering) * s + o.span_clustering * std::sin(0.5 * std::numbers::pi * s));
  }
  const double h_tip = b - ys[static_cast<std::size_t>(o.span_cells - 1)];
  const double r_out = internal::geometric_ratio(h_tip, o.outboard_cells, o.far_field * cr);
  for (int k = 1; k <= o.outboard_cells; ++k)
    ys[static_cast<std::size_t>(o.span_cells + k)] =
        ys[static_cast<std::size_t>(o.span_cells + k - 1)] + h_tip * std::pow(r_out, k - 1);
  ys.back() = b + o.far_field * cr;

  // tip cap: the thickness factor falls from 1 to 0 over a radius of the tip's half-thickness
  const double cap = 0.5 * w.section.thickness_ratio() * p.tip_chord;
  auto thickness_factor = [&](double y) {
    if (y >= b) return 0.0;
    const double yc = b - cap;
    if (y <= yc) return 1.0;
    const double u = (y - yc) / cap;
    return std::sqrt(std::max(0.0, 1 - u * u));
  };

  const std::vector<double> xi = internal::chord_fractions(w.section, ns, o.clustering);
  const double x_exit = p.x_at(1.0, 0.0) + o.far_field * cr;  // one outflow plane for every station
  multiblock_grid<3> g;
  grid_block<double, 3> blk;
  blk.points = {ni, nj, nk};
  blk.x.resize(blk.n_points());
  for (int k = 0; k < nk; ++k) {
    const double y = ys[static_cast<std::size_t>(k)], ys_sec = std::min(y, b);
    const double c = p.chord(ys_sec), xle = p.x_leading_edge(ys_sec), sigma = thickness_factor(y);
    // inner C-curve in (x, z), lower wake exit first (left normals point into the field)
    auto section_point = [&](int m, double side, double sig) -> internal::point2 {
      const double f = xi[static_cast<std::size_t>(m)];
      return {xle + f * c, c * w.section.camber(f) + side * sig * w.section.half_thickness(f) * c};
    };
    const double h_te = std::hypot(c * (xi[static_cast<std::size_t>(ns)] - xi[static_cast<std::size_t>(ns - 1)]),
                                   sigma * c * w.section.half_thickness(xi[static_cast<std::size_t>(ns - 1)]));
    const double x_te = xle + c, z_te = c * w.section.camber(1.0);  // the wake leaves the trailing edge along x
    const double r_wake = internal::geometric_ratio(h_te, nw, x_exit - x_te);
    std::vector<double> wake_x(static_cast<std::size_t>(nw) + 1, x_te);
    for (int m = 1; m <= nw; ++m)
      wake_x[static_cast<std::size_t>(m)] = wake_x[static_cast<std::size_t>(m - 1)] + h_te * std::pow(r_wake, m - 1);
    wake_x.back() = x_exit;
    auto inner_curve = [&](double sig) {
      std::vector<internal::point2> curve(static_cast<std::size_t>(ni));
      std::size_t q = 0;
      for (int m = nw; m >= 0; --m) curve[q++] = {wake_x[static_cast<std::size_t>(m)], z_te};
      --q;  // the trailing edge is shared
      for (int m = ns; m >= 0; --m) curve[q++] = section_point(m, -1.0, sig);
      --q;  // the leading edge is shared
      for (int m = 0; m <= ns; ++m) curve[q++] = section_point(m, +1.0, sig);
      --q;
      for (int m = 0; m <= nw; ++m) curve[q++] = {wake_x[static_cast<std::size_t>(m)], z_te};
      return curve;
    };
    const auto curve = inner_curve(sigma);
    // a section thinner than a tenth of the full one takes its first normals from that tenth
    const auto reference = sigma < 0.1 ? inner_curve(0.1) : std::vector<internal::point2>{};
    const auto layer = internal::march_c_layers(curve, reference, nj, o.first_height * cr, o.far_field * cr,
                                                o.smoothing, o.redistribution_passes, o.max_shift, nw);
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) {
        const auto& q = layer[static_cast<std::size_t>(j)][static_cast<std::size_t>(ni - 1 - i)];  // upper side first
        blk.at({i, j, k}) = {q[0] / cr, y / cr, q[1] / cr};  // in root chords (spec 06)
      }
  }
  g.points.blocks.push_back(std::move(blk));
  const index_d<3> cells = {ni - 1, nj - 1, nk - 1};
  g.topology.cells.push_back(cells);

  using bk = boundary_kind;
  auto& pt = g.topology.patches;
  for (int f : {0, 1, 3, 5}) pt.push_back(whole_face<3>(0, f, cells, bk::far_field));
  auto sym = whole_face<3>(0, 4, cells, bk::wall);
  sym.tag = "symmetry";
  pt.push_back(sym);
  const wing_grid_layout l = wing_grid_layout::of(o);
  const int i_lo = l.wing_begin, i_le = l.leading_edge, i_hi = l.wing_end, ks = l.tip, kn = cells[2];
  auto wing = whole_face<3>(0, 2, cells, bk::wall);
  wing.begin = {i_lo, 0, 0};
  wing.end = {i_hi, 0, ks};
  wing.tag = "wing";
  pt.push_back(wing);
  // cuts of the j = 0 face onto themselves, i reversed: [a0, a1) x [k0, k1) <-> [b0, b1) x [k0, k1)
  auto cut = [&](int a0, int a1, int b0, int b1, int k0, int k1) {
    auto c = whole_face<3>(0, 2, cells, bk::interface);
    c.begin = {a0, 0, k0};
    c.end = {a1, 0, k1};
    c.donor_block = 0;
    c.donor_face = 2;
    c.donor_begin = {b0, 0, k0};
    c.donor_end = {b1, 0, k1};
    c.transform = {-1, 0, 3};
    return c;
  };
  pt.push_back(cut(0, i_lo, i_hi, cells[0], 0, kn));  // wake: upper side <-> lower side
  pt.push_back(cut(i_hi, cells[0], 0, i_lo, 0, kn));
  pt.push_back(cut(i_lo, i_le, i_le, i_hi, ks, kn));  // beyond the tip: upper <-> lower surface
  pt.push_back(cut(i_le, i_hi, i_lo, i_le, ks, kn));
  return g;
}

/// Volumes and corner Jacobians of the hexahedral cells [lo, hi) of block `block` (trilinear
/// map; the corners' edges along +i, +j, +k).
inline grid_quality hexahedron_quality(const multiblock_grid<3>& g, int block, index_d<3> lo, index_d<3> hi) {
  require(block >= 0 && static_cast<std::size_t>(block) < g.points.blocks.size(), "hexahedron_quality: block ", block,
          " of ", g.points.blocks.size());
  const auto& blk = g.points.blocks[static_cast<std::size_t>(block)];
  const auto n = blk.cells();
  for (int d = 0; d < 3; ++d)
    require(lo[d] >= 0 && hi[d] <= n[d] && lo[d] < hi[d], "hexahedron_quality: range [", lo[d], ", ", hi[d],
            ") outside the ", n[d], " cells of axis ", d);
  grid_quality q;
  q.min_volume = q.min_corner_ratio = q.min_ratio_all = std::numeric_limits<double>::infinity();
  using v3 = std::array<double, 3>;
  auto det = [](const v3& a, const v3& b, const v3& c) {
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  };
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int i = lo[0]; i < hi[0]; ++i) {
        std::array<v3, 8> c;
        for (int v = 0; v < 8; ++v) c[static_cast<std::size_t>(v)] = blk.at({i + (v & 1), j + ((v >> 1) & 1), k + ((v >> 2) & 1)});
        auto edge = [&](int v, int bit) {  // from the corner with the bit clear to the one with it set
          const v3& a = c[static_cast<std::size_t>(v & ~bit)];
          const v3& b = c[static_cast<std::size_t>(v | bit)];
          return v3{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        };
        double dmin = std::numeric_limits<double>::infinity(), dsum = 0;
        for (int v = 0; v < 8; ++v) {
          const double d = det(edge(v, 1), edge(v, 2), edge(v, 4));
          dmin = std::min(dmin, d);
          dsum += d;
        }
        const double vol = dsum / 8, ratio = dmin / vol;
        q.min_volume = std::min(q.min_volume, vol);
        q.max_volume = std::max(q.max_volume, vol);
        q.min_ratio_all = std::min(q.min_ratio_all, ratio);
        if (std::abs(ratio) <= 1e-9) {
          ++q.collinear_cells;
        } else if (ratio < q.min_corner_ratio) {
          q.min_corner_ratio = ratio;
          q.worst_cell = {block, i, j, k};
        }
        ++q.cells;
      }
  return q;
}

/// hexahedron_quality of every cell of a single-block grid such as wing_cgrid's.
inline grid_quality hexahedron_quality(const multiblock_grid<3>& g) {
  require(g.points.blocks.size() == 1, "hexahedron_quality: ", g.points.blocks.size(),
          " blocks; give the block and range");
  return hexahedron_quality(g, 0, {0, 0, 0}, g.points.blocks[0].cells());
}

}  // namespace aerohopf::flow
