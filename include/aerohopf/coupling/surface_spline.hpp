#pragma once
// Transfer between a structural model's points and the aerodynamic surface (spec 06): the
// linearised spline S with dx_a = S dx_s (displacements and speeds at the surface points from
// those at the structural points) and the forces back by virtual work, f_s = S^T f_a, so that
// the work of the aerodynamic forces on any structural motion is the same on both sides,
// f_s . dx_s = f_a . (S dx_s), to rounding.
//
// Choice: a radial-basis-function spline with a linear polynomial part (the thin-plate or
// infinite-plate spline of Harder and Desmarais, AIAA J. Aircraft 9, 1972, for a planar
// structure; the polyharmonic r kernel in 3D), u(x) = sum_i a_i phi(|x - x_i|) + b_0 + b . x,
// with sum_i a_i = 0 and sum_i a_i x_i = 0. The polynomial part makes rigid translations and
// rotations exact (a linear field is reproduced), the spline interpolates the structural values
// at the structural points, and it is the smoothest such field (minimal bending energy for the
// thin-plate kernel). It needs no connectivity, so modal data from any source (our plate
// elements, NASTRAN points on a beam or box) go through it. Each displacement component is
// splined independently with the same S.
//
//   thin_plate_2d:   phi(r) = r^2 log r in the projection onto the x-y plane (a wing's plate or
//                    planform structure: upper and lower surface points get the same value);
//                    needs three structural points not on one line.
//   polyharmonic_3d: phi(r) = r in 3D (biharmonic in 3D); needs four points not in one plane.
#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "../error.hpp"

namespace aerohopf::coupling {

enum class spline_kind { thin_plate_2d, polyharmonic_3d };

class surface_spline {
 public:
  /// structural: the points carrying the structural motion; surface: the aerodynamic points.
  surface_spline(const std::vector<Eigen::Vector3d>& structural, const std::vector<Eigen::Vector3d>& surface,
                 spline_kind kind = spline_kind::thin_plate_2d)
      : kind_(kind), ns_(static_cast<Eigen::Index>(structural.size())), na_(static_cast<Eigen::Index>(surface.size())) {
    const char* who = "surface_spline";
    const int dim = kind == spline_kind::thin_plate_2d ? 2 : 3;
    m_ = dim + 1;
    require(ns_ >= m_, who, ": need at least ", m_, " structural points for the linear part (got ", ns_, ")");
    require(na_ >= 1, who, ": no surface points");
    for (Eigen::Index i = 0; i < ns_; ++i)
      require(structural[static_cast<std::size_t>(i)].allFinite(), who, ": structural point ", i, " is not finite");
    for (Eigen::Index i = 0; i < na_; ++i)
      require(surface[static_cast<std::size_t>(i)].allFinite(), who, ": surface point ", i, " is not finite");
    // coordinates relative to the structural centroid, scaled by its extent: conditioning
    Eigen::Vector3d lo = structural[0], hi = structural[0];
    for (const auto& p : structural) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    centre_ = 0.5 * (lo + hi);
    scale_ = (hi - lo).head(dim).maxCoeff();
    require(scale_ > 0, who, ": the structural points coincide");
    auto local = [&](const Eigen::Vector3d& p) {
      Eigen::Vector3d q = (p - centre_) / scale_;
      if (dim == 2) q.z() = 0;
      return q;
    };
    std::vector<Eigen::Vector3d> xs(static_cast<std::size_t>(ns_));
    for (Eigen::Index i = 0; i < ns_; ++i) xs[static_cast<std::size_t>(i)] = local(structural[static_cast<std::size_t>(i)]);
    for (Eigen::Index i = 0; i < ns_; ++i)
      for (Eigen::Index j = 0; j < i; ++j)
        require((xs[static_cast<std::size_t>(i)] - xs[static_cast<std::size_t>(j)]).norm() > 1e-12, who,
                ": structural points ", j, " and ", i, " coincide", dim == 2 ? " in the x-y projection" : "");
    const Eigen::Index n = ns_ + m_;
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
    for (Eigen::Index i = 0; i < ns_; ++i) {
      const auto& xi = xs[static_cast<std::size_t>(i)];
      for (Eigen::Index j = 0; j < ns_; ++j) k(i, j) = phi((xi - xs[static_cast<std::size_t>(j)]).norm());
      k(i, ns_) = k(ns_, i) = 1;
      for (int d = 0; d < dim; ++d) k(i, ns_ + 1 + d) = k(ns_ + 1 + d, i) = xi[d];
    }
    // the linear part must be determined by the points (not all on a line / in a plane)
    Eigen::MatrixXd p = k.topRightCorner(ns_, m_);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(p);
    const auto sv = svd.singularValues();
    require(sv[m_ - 1] > 1e-9 * sv[0], who, ": the structural points lie ",
            dim == 2 ? "on one line" : "in one plane", ": the linear part is not determined (use ",
            dim == 2 ? "more spread points" : "thin_plate_2d for a planar structure", ")");
    lu_.compute(k);
    const double rc = lu_.rcond();
    if (!(rc > 1e3 * std::numeric_limits<double>::epsilon()))
      throw singular_matrix_error(aerohopf::internal::concat(who, ": the spline system is singular (rcond ", rc, ")"));
    a_.resize(na_, n);
    for (Eigen::Index r = 0; r < na_; ++r) {
      const Eigen::Vector3d x = local(surface[static_cast<std::size_t>(r)]);
      for (Eigen::Index j = 0; j < ns_; ++j) a_(r, j) = phi((x - xs[static_cast<std::size_t>(j)]).norm());
      a_(r, ns_) = 1;
      for (int d = 0; d < dim; ++d) a_(r, ns_ + 1 + d) = x[d];
    }
  }

  Eigen::Index structural_points() const { return ns_; }
  Eigen::Index surface_points() const { return na_; }

  /// Surface values (na x c) of structural values (ns x c): each column splined.
  Eigen::MatrixXd transfer(const Eigen::MatrixXd& u_s) const {
    require(u_s.rows() == ns_, "surface_spline::transfer: ", u_s.rows(), " rows, expected the ", ns_,
            " structural points");
    require(u_s.allFinite(), "surface_spline::transfer: a structural value is not finite");
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(ns_ + m_, u_s.cols());
    rhs.topRows(ns_) = u_s;
    return a_ * lu_.solve(rhs);
  }
  /// Structural loads (ns x c) of surface loads (na x c) by virtual work: S^T f_a.
  Eigen::MatrixXd transfer_transpose(const Eigen::MatrixXd& f_a) const {
    require(f_a.rows() == na_, "surface_spline::transfer_transpose: ", f_a.rows(), " rows, expected the ", na_,
            " surface points");
    require(f_a.allFinite(), "surface_spline::transfer_transpose: a surface value is not finite");
    const Eigen::MatrixXd g = a_.transpose() * f_a;
    return lu_.solve(g).topRows(ns_);  // the spline system is symmetric: K^-T = K^-1
  }
  /// S itself (na x ns), for small problems and checks.
  Eigen::MatrixXd matrix() const { return transfer(Eigen::MatrixXd::Identity(ns_, ns_)); }

 private:
  double phi(double r) const {
    if (kind_ == spline_kind::polyharmonic_3d) return r;
    return r > 0 ? r * r * std::log(r) : 0.0;
  }
  spline_kind kind_;
  Eigen::Index ns_, na_;
  int m_ = 3;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  double scale_ = 1;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::MatrixXd a_;  // surface rows of [phi, 1, x]: na x (ns + m)
};

}  // namespace aerohopf::coupling
