#pragma once
// Rigid pitch-plunge motion of a whole 2D grid (spec 05): no deformation, the far field moves
// with the aerofoil, so metrics stay valid for any amplitude and the geometric conservation
// law holds trivially (sum of face volume fluxes of a rigid motion is zero).
//     [x; y] = R(alpha) [x0 - x_ea; y0 - y_ea] + [x_ea; y_ea + h],
//     R(alpha) = [cos a, sin a; -sin a, cos a]      (positive alpha: nose up, trailing edge down)
//     grid speed [x_g; y_g] = [ a' (y - y_ea - h); -a' (x - x_ea) + h' ]  (= d/dt of the above)
// Templated on the scalar: with a taylor<> structural state the moved points and speeds are
// jets, so compute_metrics and the Euler residual give exact derivatives with respect to the
// structural unknowns (the A_fs block of the coupled Jacobian) in one pass per direction.
#include <array>
#include <cmath>

#include "../error.hpp"
#include "../flow/structured_grid.hpp"
#include "../scalar/traits.hpp"

namespace aerohopf::coupling {

/// Rigid-body pose of the section (h up, alpha nose-up) and its rates, t in c / U_inf.
template <class S>
struct rigid_pose {
  S h{}, h_dot{}, alpha{}, alpha_dot{};
};

/// R(alpha) applied to rest vectors (point offsets from the axis, edges, area vectors).
template <class S>
struct rigid_rotation {
  S c, s;
  explicit rigid_rotation(const S& alpha) {
    using std::cos;
    using std::sin;
    c = cos(alpha);
    s = sin(alpha);
  }
  std::array<S, 2> apply(const std::array<double, 2>& v) const { return {c * v[0] + s * v[1], c * v[1] - s * v[0]}; }
};

/// Throws input_error naming `who` if a component of the pose is not finite (a NaN pose gives a
/// NaN grid whose metrics and residual are NaN without a word).
template <class S>
void require_finite_pose(const rigid_pose<S>& q, const char* who) {
  require(std::isfinite(to_double(q.h)) && std::isfinite(to_double(q.h_dot)) && std::isfinite(to_double(q.alpha)) &&
              std::isfinite(to_double(q.alpha_dot)),
          who, ": pose is not finite (h ", to_double(q.h), ", h' ", to_double(q.h_dot), ", alpha ", to_double(q.alpha),
          ", alpha' ", to_double(q.alpha_dot), ")");
}

/// Position of one rest point x0 under pose q about the elastic axis ea.
template <class S>
std::array<S, 2> rigid_position(const std::array<double, 2>& x0, const rigid_pose<S>& q, const std::array<double, 2>& ea) {
  const auto r = rigid_rotation<S>(q.alpha).apply({x0[0] - ea[0], x0[1] - ea[1]});
  return {r[0] + ea[0], r[1] + ea[1] + q.h};
}

/// Grid speed at a moved point x.
template <class S>
std::array<S, 2> rigid_speed(const std::array<S, 2>& x, const rigid_pose<S>& q, const std::array<double, 2>& ea) {
  return {q.alpha_dot * (x[1] - ea[1] - q.h), -q.alpha_dot * (x[0] - ea[0]) + q.h_dot};
}

/// Moves every point of the rest grid; fills points and (if non-null) speeds, same shapes.
template <class S>
void rigid_grid_motion(const flow::multiblock_points<double, 2>& rest, const rigid_pose<S>& q,
                       const std::array<double, 2>& ea, flow::multiblock_points<S, 2>& points,
                       flow::multiblock_points<S, 2>* speeds = nullptr) {
  // Checked before points / speeds are touched: a NaN pose or axis would give a NaN grid whose
  // metrics and residual are NaN without a word, and a block whose point list does not match
  // its dimensions would be moved only in part.
  const char* who = "rigid_grid_motion";
  require(std::isfinite(ea[0]) && std::isfinite(ea[1]), who, ": elastic axis (", ea[0], ", ", ea[1], ") is not finite");
  require_finite_pose(q, who);
  for (std::size_t b = 0; b < rest.blocks.size(); ++b)
    require_size(rest.blocks[b].x.size(), rest.blocks[b].n_points(), who,
                 aerohopf::internal::concat("rest grid block ", b, " point list"));
  points.blocks.resize(rest.blocks.size());
  if (speeds) speeds->blocks.resize(rest.blocks.size());
  for (std::size_t b = 0; b < rest.blocks.size(); ++b) {
    const auto& rb = rest.blocks[b];
    auto& pb = points.blocks[b];
    pb.points = rb.points;
    pb.x.resize(rb.x.size());
    if (speeds) {
      speeds->blocks[b].points = rb.points;
      speeds->blocks[b].x.resize(rb.x.size());
    }
    for (std::size_t k = 0; k < rb.x.size(); ++k) {
      pb.x[k] = rigid_position<S>(rb.x[k], q, ea);
      if (speeds) speeds->blocks[b].x[k] = rigid_speed<S>(pb.x[k], q, ea);
    }
  }
}

}  // namespace aerohopf::coupling
