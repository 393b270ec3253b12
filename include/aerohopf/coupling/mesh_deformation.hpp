#pragma once
// Volume-grid motion of a wing C-H grid (flow/wing_grid.hpp) from the structure's modes (spec
// 06): the modes' displacements at the structural points are splined (surface_spline.hpp) to
// the wing's points on the grid's inner face j = 0, carried unchanged along the wake cut (each
// wake point moves with the trailing edge of its station) and along the cut beyond the tip (each
// point there moves with the tip point of its chordwise index), and interpolated through the
// volume along each j-line (transfinite interpolation between the inner face and the fixed outer
// boundary):
//     dx_ijk = psi_ijk dx_a,i'k',    psi = 1 - s_ijk / s_i(nj-1)k,
// s the arc length along the rest grid's j-line and (i', k') the wing point that (i, k) follows.
// The cuts move rigidly along their length, so their thin cells (the first cell height) are not
// sheared by a displacement that varies along the cut; a motion faded out along the wake folds
// them at a few percent of the chord (measured: a 5 % tip deflection, coarse level). The outer
// boundary stays fixed and a point's displacement is linear in the modal coordinates, x = x_0 +
// sum_m a_m Psi_m, so the grid and its point speeds (sum_m a_m' Psi_m, the same interpolation) are
// templates over the scalar: with jets for a_m one residual pass gives the derivatives along every
// mode (A_fs). The metrics are GCL-exact for any motion (flow/metrics.hpp), so a uniform flow
// stays uniform on the moving grid.
//
// Units: grid in root chords, structural points in metres (length_scale = the root chord in
// metres converts); with mass-normalised shapes phi (kg^-1/2) and the coordinate a_hat = a / c of
// modal_structure.hpp, the displacement in root chords is phi a_hat: Psi_m holds phi's values.
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "../error.hpp"
#include "../flow/structured_grid.hpp"
#include "../flow/wing_grid.hpp"
#include "../structure/modal_data.hpp"
#include "surface_spline.hpp"

namespace aerohopf::coupling {

/// psi of every point of a block: 1 at j = 0, 0 at j = nj - 1, linear in the arc length along the
/// j-line of the block as given (the rest grid).
inline std::vector<double> j_line_weights(const flow::grid_block<double, 3>& b) {
  const auto n = b.points;
  std::vector<double> psi(b.n_points());
  for (int k = 0; k < n[2]; ++k)
    for (int i = 0; i < n[0]; ++i) {
      std::vector<double> s(static_cast<std::size_t>(n[1]), 0.0);
      for (int j = 1; j < n[1]; ++j) {
        const auto &p = b.at({i, j, k}), &q = b.at({i, j - 1, k});
        s[static_cast<std::size_t>(j)] =
            s[static_cast<std::size_t>(j - 1)] + std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                                           (p[2] - q[2]) * (p[2] - q[2]));
      }
      const double total = s.back();
      require(total > 0, "j_line_weights: the j-line at i = ", i, ", k = ", k, " has zero length");
      for (int j = 0; j < n[1]; ++j)
        psi[flow::linear_index<3>({i, j, k}, n)] = 1.0 - s[static_cast<std::size_t>(j)] / total;
    }
  return psi;
}

struct wing_motion_options {
  double length_scale = 1.0;  ///< metres per grid unit (the root chord)
  flow::wing_grid_options grid;  ///< the options the grid was made with (strides divide its counts)
  int stride = 1;             ///< the grid's level: coarsen(fine, stride)
};

/// The modal grid motion of a wing_cgrid level: Psi_m for every mode of `modes` (translations
/// t1 t2 t3 splined by the thin-plate spline in the planform plane).
class wing_modal_motion {
 public:
  wing_modal_motion(const flow::multiblock_grid<3>& grid, const structure::modal_data& modes,
                    const wing_motion_options& o = {})
      : rest_(grid.points.blocks.at(0)) {
    const char* who = "wing_modal_motion";
    modes.validate("wing_modal_motion");
    require(grid.points.blocks.size() == 1, who, ": a one-block wing_cgrid level expected (got ",
            grid.points.blocks.size(), " blocks)");
    require(o.length_scale > 0 && o.stride >= 1, who, ": length_scale must be > 0 and stride >= 1 (got ",
            o.length_scale, ", ", o.stride, ")");
    const auto n = rest_.points;
    const flow::wing_grid_layout l = flow::wing_grid_layout::of(o.grid, o.stride);
    require(n[0] == l.cells[0] + 1 && n[1] == l.cells[1] + 1 && n[2] == l.cells[2] + 1, who,
            ": the grid is not the wing_cgrid level of these options and stride (", n[0], " x ", n[1], " x ", n[2],
            " points)");
    // the wing's points on j = 0 (section indices, root to tip station) and the spline to them
    const int i_lo = l.wing_begin, i_hi = l.wing_end, ks = l.tip, ni_wing = i_hi - i_lo + 1;
    std::vector<Eigen::Vector3d> face;
    for (int k = 0; k <= ks; ++k)
      for (int i = i_lo; i <= i_hi; ++i) {
        const auto& x = rest_.at({i, 0, k});
        face.emplace_back(x[0] * o.length_scale, x[1] * o.length_scale, x[2] * o.length_scale);
      }
    const surface_spline spline(modes.points, face, spline_kind::thin_plate_2d);
    Eigen::MatrixXd shapes(static_cast<Eigen::Index>(modes.size()), 3 * modes.modes());
    for (Eigen::Index m = 0; m < modes.modes(); ++m)
      shapes.middleCols(3 * m, 3) = modes.shapes[static_cast<std::size_t>(m)].leftCols(3);
    const Eigen::MatrixXd on_wing = spline.transfer(shapes);  // wing points x 3 modes
    // the wing point that the j = 0 point (i, k) follows
    auto followed = [&](int i, int k) {
      return static_cast<Eigen::Index>(std::clamp(i, i_lo, i_hi) - i_lo + ni_wing * std::min(k, ks));
    };
    const std::vector<double> psi = j_line_weights(rest_);
    basis_.assign(static_cast<std::size_t>(modes.modes()), std::vector<std::array<double, 3>>(rest_.n_points()));
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const std::size_t p = flow::linear_index<3>({i, j, k}, n);
          const Eigen::Index f = followed(i, k);
          for (Eigen::Index m = 0; m < modes.modes(); ++m)
            for (int d = 0; d < 3; ++d)
              basis_[static_cast<std::size_t>(m)][p][static_cast<std::size_t>(d)] = psi[p] * on_wing(f, 3 * m + d);
        }
  }

  Eigen::Index modes() const { return static_cast<Eigen::Index>(basis_.size()); }
  /// The grid block at rest that the motion moves.
  const flow::grid_block<double, 3>& rest() const { return rest_; }
  /// Psi_m at every point (root chords per unit a_hat_m).
  const std::vector<std::array<double, 3>>& basis(Eigen::Index m) const { return basis_.at(static_cast<std::size_t>(m)); }

  /// The moved points x_0 + sum_m a_m Psi_m (S: double, jets, ...).
  template <class S, class Vec>
  flow::grid_block<S, 3> points(const Vec& a) const {
    require_size(a.size(), modes(), "wing_modal_motion::points", "modal coordinates");
    return combined<S>(a, true);
  }
  /// The point speeds sum_m a_dot_m Psi_m.
  template <class S, class Vec>
  flow::grid_block<S, 3> velocities(const Vec& a_dot) const {
    require_size(a_dot.size(), modes(), "wing_modal_motion::velocities", "modal rates");
    return combined<S>(a_dot, false);
  }

 private:
  /// (x_0 if with_rest) + sum_m c_m Psi_m at every point.
  template <class S, class Vec>
  flow::grid_block<S, 3> combined(const Vec& c, bool with_rest) const {
    flow::grid_block<S, 3> out;
    out.points = rest_.points;
    out.x.resize(rest_.n_points());
    for (std::size_t p = 0; p < rest_.n_points(); ++p)
      for (int d = 0; d < 3; ++d) {
        S v = S(with_rest ? rest_.x[p][static_cast<std::size_t>(d)] : 0.0);
        for (Eigen::Index m = 0; m < modes(); ++m) v += S(c[m]) * basis_[static_cast<std::size_t>(m)][p][static_cast<std::size_t>(d)];
        out.x[p][static_cast<std::size_t>(d)] = v;
      }
    return out;
  }
  flow::grid_block<double, 3> rest_;
  std::vector<std::vector<std::array<double, 3>>> basis_;
};

}  // namespace aerohopf::coupling
