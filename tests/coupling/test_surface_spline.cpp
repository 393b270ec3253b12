// Surface spline: rigid translations and rotations reproduced exactly (the linear part), the
// structural values interpolated, virtual work conserved to rounding (f_s = S^T f_a), a smooth
// field converging under refinement of the structural points, the 3D kernel, and refusals.
#include <gtest/gtest.h>

#include <aerohopf/coupling/surface_spline.hpp>
#include <aerohopf/error.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::coupling;

namespace {
std::vector<Eigen::Vector3d> plate_points(int n, double skew) {  // a swept, tapered planform's grid
  std::vector<Eigen::Vector3d> p;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double y = 0.8 * j / n, x = skew * y + (1 - 0.3 * y) * i / n;
      p.emplace_back(x, y, 0.0);
    }
  return p;
}
std::vector<Eigen::Vector3d> surface_points(int count, unsigned seed) {  // on both sides of a thin wing
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < count; ++k) {
    const double y = 0.8 * u(rng), x = 1.0 * y + (1 - 0.3 * y) * u(rng);
    p.emplace_back(x, y, (k % 2 ? 1 : -1) * 0.02 * u(rng));
  }
  return p;
}
}  // namespace

TEST(SurfaceSpline, RigidMotionsAreExact) {
  const auto xs = plate_points(8, 1.0), xa = surface_points(300, 1);
  const surface_spline s(xs, xa);
  Eigen::MatrixXd u(static_cast<Eigen::Index>(xs.size()), 3);
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    u(r, 0) = 0.3;                                       // translation
    u(r, 1) = 0.1 * xs[i].x() - 0.2;                     // rotation about y (pitch)
    u(r, 2) = -0.05 * xs[i].y() + 0.02 * xs[i].x() + 1;  // roll plus pitch plus heave
  }
  const Eigen::MatrixXd ua = s.transfer(u);
  for (std::size_t k = 0; k < xa.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(k);
    EXPECT_NEAR(ua(r, 0), 0.3, 1e-12);
    EXPECT_NEAR(ua(r, 1), 0.1 * xa[k].x() - 0.2, 1e-12);
    EXPECT_NEAR(ua(r, 2), -0.05 * xa[k].y() + 0.02 * xa[k].x() + 1, 1e-12);
  }
}

TEST(SurfaceSpline, InterpolatesAndConservesVirtualWork) {
  const auto xs = plate_points(7, 0.8);
  const surface_spline at_nodes(xs, xs);
  EXPECT_LT((at_nodes.matrix() - Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(xs.size()),
                                                            static_cast<Eigen::Index>(xs.size())))
                .cwiseAbs()
                .maxCoeff(),
            1e-9);
  const auto xa = surface_points(250, 2);
  const surface_spline s(xs, xa);
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  Eigen::MatrixXd us(static_cast<Eigen::Index>(xs.size()), 2), fa(static_cast<Eigen::Index>(xa.size()), 2);
  for (Eigen::Index i = 0; i < us.size(); ++i) us.data()[i] = g(rng);
  for (Eigen::Index i = 0; i < fa.size(); ++i) fa.data()[i] = g(rng);
  const Eigen::MatrixXd ua = s.transfer(us), fs = s.transfer_transpose(fa);
  for (int c = 0; c < 2; ++c) {
    const double wa = ua.col(c).dot(fa.col(c)), ws = us.col(c).dot(fs.col(c));
    EXPECT_NEAR(wa, ws, 1e-12 * (ua.col(c).norm() * fa.col(c).norm()));
  }
  // and the matrix form agrees with both
  const Eigen::MatrixXd sm = s.matrix();
  EXPECT_LT((sm * us - ua).cwiseAbs().maxCoeff(), 1e-11);
  EXPECT_LT((sm.transpose() * fa - fs).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(SurfaceSpline, SmoothFieldConvergesUnderRefinement) {
  const auto xa = surface_points(200, 4);
  auto field = [](const Eigen::Vector3d& p) { return std::sin(2 * p.x()) * std::cos(3 * p.y()); };
  double err_prev = 0;
  for (int n : {4, 8, 16}) {
    const auto xs = plate_points(n, 1.0);
    Eigen::MatrixXd u(static_cast<Eigen::Index>(xs.size()), 1);
    for (std::size_t i = 0; i < xs.size(); ++i) u(static_cast<Eigen::Index>(i), 0) = field(xs[i]);
    const Eigen::MatrixXd ua = surface_spline(xs, xa).transfer(u);
    double err = 0;
    for (std::size_t k = 0; k < xa.size(); ++k) err = std::max(err, std::abs(ua(static_cast<Eigen::Index>(k), 0) - field(xa[k])));
    if (n > 4) {
      EXPECT_LT(err, 0.35 * err_prev) << n;
    }
    err_prev = err;
  }
  EXPECT_LT(err_prev, 2e-3);
}

TEST(SurfaceSpline, ThreeDimensionalKernelReproducesRigidMotion) {
  std::vector<Eigen::Vector3d> xs;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) xs.emplace_back(i * 0.25, j * 0.3, k * 0.1 + 0.02 * i);
  const auto xa = surface_points(100, 5);
  const surface_spline s(xs, xa, spline_kind::polyharmonic_3d);
  Eigen::MatrixXd u(static_cast<Eigen::Index>(xs.size()), 1);
  for (std::size_t i = 0; i < xs.size(); ++i) u(static_cast<Eigen::Index>(i), 0) = 1 + xs[i].x() - 2 * xs[i].y() + 3 * xs[i].z();
  const Eigen::MatrixXd ua = s.transfer(u);
  for (std::size_t k = 0; k < xa.size(); ++k)
    EXPECT_NEAR(ua(static_cast<Eigen::Index>(k), 0), 1 + xa[k].x() - 2 * xa[k].y() + 3 * xa[k].z(), 1e-10);
}

TEST(SurfaceSpline, RefusesDegenerateInput) {
  const auto xa = surface_points(10, 6);
  std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_THROW(surface_spline(line, xa), input_error);
  std::vector<Eigen::Vector3d> dup = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0.5}};  // same x-y
  EXPECT_THROW(surface_spline(dup, xa), input_error);
  std::vector<Eigen::Vector3d> flat = plate_points(3, 0.5);
  EXPECT_THROW(surface_spline(flat, xa, spline_kind::polyharmonic_3d), input_error);  // coplanar in 3D
  std::vector<Eigen::Vector3d> nan = plate_points(3, 0.5);
  nan[2].x() = NAN;
  EXPECT_THROW(surface_spline(nan, xa), input_error);
  const surface_spline s(plate_points(3, 0.5), xa);
  EXPECT_THROW(s.transfer(Eigen::MatrixXd::Zero(3, 1)), input_error);
  EXPECT_THROW(s.transfer_transpose(Eigen::MatrixXd::Zero(3, 1)), input_error);
}
