// Plate finite elements (MITC4, orthotropic): the constitutive rotation against its invariants,
// rigid-body motions in the stiffness null space, a clamped strip against Euler-Bernoulli beam
// frequencies (thick and thin: no shear locking), simply supported isotropic and specially
// orthotropic plates against the closed forms, invariance under a rotation of mesh and fibre,
// the subspace iteration against a dense generalised eigensolver, mass normalisation, and
// refusals of bad input.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/structure/plate_fe.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <numbers>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::structure;

namespace {
constexpr double pi = std::numbers::pi;

plate_mesh rectangle(int ni, int nj, double a, double b, double t) {
  return structured_plate_mesh(
      ni, nj, [&](double s, double r) { return Eigen::Vector2d(a * s, b * r); }, [&](double, double) { return t; });
}

/// Every boundary node of a structured (ni x nj) mesh simply supported (w = 0).
plate_constraints simply_supported(int ni, int nj) {
  plate_constraints c(static_cast<std::size_t>((ni + 1) * (nj + 1)));
  for (int j = 0; j <= nj; ++j)
    for (int i = 0; i <= ni; ++i)
      if (i == 0 || j == 0 || i == ni || j == nj) c.support(i + (ni + 1) * j);
  return c;
}

/// The nodes of the edge s = 0 clamped.
plate_constraints clamped_at_x0(int ni, int nj) {
  plate_constraints c(static_cast<std::size_t>((ni + 1) * (nj + 1)));
  for (int j = 0; j <= nj; ++j) c.clamp((ni + 1) * j);
  return c;
}

orthotropic_material mahogany() {  // spec 06, fibre along x
  orthotropic_material m = agard445_6_mahogany(flow::agard445_6().planform);
  m.fibre_angle = 0;
  return m;
}
}  // namespace

TEST(PlateFe, ConstitutiveRotationKeepsInvariants) {
  orthotropic_material m = mahogany();
  const Eigen::Matrix3d q0 = plane_stress_stiffness(m);
  const double den = 1 - m.nu12 * m.nu12 * m.e2 / m.e1;
  EXPECT_NEAR(q0(0, 0), m.e1 / den, 1e-6 * m.e1);
  EXPECT_NEAR(q0(1, 1), m.e2 / den, 1e-6 * m.e1);
  EXPECT_NEAR(q0(0, 1), m.nu12 * m.e2 / den, 1e-6 * m.e1);
  EXPECT_NEAR(q0(2, 2), m.g12, 1e-6 * m.e1);
  EXPECT_NEAR(q0(0, 2), 0.0, 1e-6 * m.e1);
  m.fibre_angle = pi / 2;  // fibre along y: the two directions swap
  const Eigen::Matrix3d q90 = plane_stress_stiffness(m);
  EXPECT_NEAR(q90(0, 0), q0(1, 1), 1e-6 * m.e1);
  EXPECT_NEAR(q90(1, 1), q0(0, 0), 1e-6 * m.e1);
  for (double a : {0.3, pi / 4, 1.2}) {  // U1-type invariants of the rotated lamina
    m.fibre_angle = a;
    const Eigen::Matrix3d q = plane_stress_stiffness(m);
    EXPECT_NEAR(q(0, 0) + q(1, 1) + 2 * q(0, 1), q0(0, 0) + q0(1, 1) + 2 * q0(0, 1), 1e-9 * m.e1);
    EXPECT_NEAR(q(2, 2) - q(0, 1), q0(2, 2) - q0(0, 1), 1e-9 * m.e1);
    EXPECT_NEAR((q - q.transpose()).norm(), 0.0, 1e-9 * m.e1);
    const Eigen::Matrix2d s = transverse_shear_stiffness(m);
    EXPECT_NEAR(s.trace(), 2 * m.shear_correction * m.g12, 1e-9 * m.g12);
  }
  const orthotropic_material iso = isotropic_material(70e9, 0.3, 2700);
  orthotropic_material iso_rot = iso;
  iso_rot.fibre_angle = 0.7;
  EXPECT_NEAR((plane_stress_stiffness(iso) - plane_stress_stiffness(iso_rot)).norm(), 0.0, 1e-12 * 70e9);
}

TEST(PlateFe, RigidBodyMotionsCostNoStrainEnergy) {
  // a distorted, tapered mesh of varying thickness
  plate_mesh m = structured_plate_mesh(
      6, 5,
      [](double s, double r) {
        return Eigen::Vector2d(s + 0.4 * r + 0.05 * std::sin(7 * s * r), r * (1 - 0.3 * s) + 0.03 * std::sin(5 * s));
      },
      [](double x, double y) { return 0.01 + 0.005 * x + 0.002 * y; });
  orthotropic_material mat = mahogany();
  mat.fibre_angle = 0.6;
  const plate_matrices km = assemble_plate(m, mat);
  const Eigen::Index n = m.unknowns();
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, 3);
  for (std::size_t k = 0; k < m.nodes.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(3 * k);
    r(i, 0) = 1;                   // translation in z
    r(i, 1) = m.nodes[k].x();      // rotation about y: w = x, beta_x = -1
    r(i + 1, 1) = -1;
    r(i, 2) = m.nodes[k].y();      // rotation about x: w = y, beta_y = -1
    r(i + 2, 2) = -1;
  }
  const double scale = km.stiffness.cwiseAbs().sum() / static_cast<double>(n);
  for (int c = 0; c < 3; ++c)
    EXPECT_LT((km.stiffness * r.col(c)).norm(), 1e-12 * scale * r.col(c).norm()) << "rigid motion " << c;
  // and the free plate has exactly these three zero frequencies: K + M is definite, K is not
  const Eigen::MatrixXd kd(km.stiffness), md(km.mass);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(kd, md);
  const Eigen::VectorXd ev = ges.eigenvalues();
  EXPECT_LT(std::abs(ev[2]), 1e-8 * ev[3]);
  EXPECT_GT(ev[3], 0.0);
}

TEST(PlateFe, ClampedStripMatchesBeamTheoryThickAndThin) {
  // nu = 0: the strip is exactly an Euler-Bernoulli beam (no anticlastic stiffening)
  const double l = 1, b = 0.1, e = 1e9, rho = 1000;
  for (double t : {1e-2, 1e-3}) {
    const plate_mesh m = rectangle(40, 4, l, b, t);
    const plate_modes md = plate_modes_of(m, isotropic_material(e, 0.0, rho), clamped_at_x0(40, 4), {.count = 2});
    const double base = std::sqrt(e * b * t * t * t / 12 / (rho * b * t * l * l * l * l));
    EXPECT_NEAR(md.omega[0] / (std::pow(1.8751040687, 2) * base), 1.0, 3e-4) << "t = " << t;
    EXPECT_NEAR(md.omega[1] / (std::pow(4.6940911330, 2) * base), 1.0, 3e-3) << "t = " << t;
    EXPECT_LT(md.residual.maxCoeff(), 1e-4);
  }
}

TEST(PlateFe, SimplySupportedIsotropicPlateConvergesToTheClosedForm) {
  const double a = 1, t = 0.01, e = 70e9, nu = 0.3, rho = 2700;
  const double d = e * t * t * t / (12 * (1 - nu * nu));
  const double w11 = pi * pi * 2 / (a * a) * std::sqrt(d / (rho * t)), w12 = 2.5 * w11;
  double err_prev = 0;
  for (int nel : {8, 16, 32}) {
    const plate_modes md = plate_modes_of(rectangle(nel, nel, a, a, t), isotropic_material(e, nu, rho),
                                          simply_supported(nel, nel), {.count = 3});
    const double err = std::abs(md.omega[0] / w11 - 1);
    EXPECT_NEAR(md.omega[1], md.omega[2], 1e-6 * md.omega[1]);  // (1,2) and (2,1) coincide
    if (nel == 16) {
      EXPECT_LT(err, 5e-3);
      EXPECT_NEAR(md.omega[1] / w12, 1.0, 2e-2);
    }
    if (nel > 8) {
      EXPECT_LT(err, 0.5 * err_prev) << nel << " x " << nel;
    }
    err_prev = err;
  }
}

TEST(PlateFe, SpeciallyOrthotropicPlateMatchesClosedFormAndIsRotationInvariant) {
  // fibre along x: omega_mn^2 rho t = pi^4 [D11 (m/a)^4 + 2 (D12 + 2 D66) (m n / a b)^2 + D22 (n/b)^4]
  const double a = 1.0, b = 0.6, t = 0.006;
  const orthotropic_material mat = mahogany();
  const Eigen::Matrix3d d = plane_stress_stiffness(mat) * t * t * t / 12;
  auto closed = [&](int m, int n) {
    const double p = m / a, q = n / b;
    return std::sqrt(std::pow(pi, 4) *
                     (d(0, 0) * std::pow(p, 4) + 2 * (d(0, 1) + 2 * d(2, 2)) * p * p * q * q + d(1, 1) * std::pow(q, 4)) /
                     (mat.density * t));
  };
  const plate_modes md = plate_modes_of(rectangle(32, 20, a, b, t), mat, simply_supported(32, 20), {.count = 3});
  std::vector<double> exact = {closed(1, 1), closed(2, 1), closed(3, 1), closed(1, 2), closed(4, 1)};
  std::sort(exact.begin(), exact.end());
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(md.omega[k] / exact[static_cast<std::size_t>(k)], 1.0, 1e-2) << "mode " << k;
  // the same plate turned by 30 degrees with its fibre: the same frequencies
  const double th = pi / 6, c = std::cos(th), s = std::sin(th);
  const plate_mesh turned = structured_plate_mesh(
      32, 20, [&](double u, double v) { return Eigen::Vector2d(c * a * u - s * b * v, s * a * u + c * b * v); },
      [&](double, double) { return t; });
  orthotropic_material mt = mat;
  mt.fibre_angle = th;
  const plate_modes mr = plate_modes_of(turned, mt, simply_supported(32, 20), {.count = 3});
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mr.omega[k], md.omega[k], 1e-7 * md.omega[k]) << "mode " << k;
}

TEST(PlateFe, SubspaceIterationEqualsDenseEigensolverAndModesAreMassNormalised) {
  const plate_mesh m = structured_plate_mesh(
      7, 5, [](double s, double r) { return Eigen::Vector2d(s + 0.3 * r, 0.8 * r * (1 - 0.2 * s)); },
      [](double x, double) { return 0.02 * (1 - 0.5 * x); });
  orthotropic_material mat = mahogany();
  mat.fibre_angle = 0.4;
  const plate_matrices km = assemble_plate(m, mat);
  const plate_constraints c = clamped_at_x0(7, 5);
  const plate_modes md = plate_modes_of(km, c, {.count = 5});
  // dense reference on the free unknowns
  std::vector<int> dof;
  for (int i = 0; i < km.stiffness.rows(); ++i)
    if (!c.fixed[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)]) dof.push_back(i);
  const auto nf = static_cast<Eigen::Index>(dof.size());
  const Eigen::MatrixXd kd(km.stiffness), mdn(km.mass);
  Eigen::MatrixXd kf(nf, nf), mf(nf, nf);
  for (Eigen::Index i = 0; i < nf; ++i)
    for (Eigen::Index j = 0; j < nf; ++j) {
      kf(i, j) = kd(dof[static_cast<std::size_t>(i)], dof[static_cast<std::size_t>(j)]);
      mf(i, j) = mdn(dof[static_cast<std::size_t>(i)], dof[static_cast<std::size_t>(j)]);
    }
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(kf, mf);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(md.omega[k], std::sqrt(ges.eigenvalues()[k]), 1e-9 * md.omega[k]);
  const Eigen::MatrixXd g = md.shapes.transpose() * (km.mass * md.shapes);
  EXPECT_LT((g - Eigen::MatrixXd::Identity(5, 5)).norm(), 1e-9);
  const Eigen::MatrixXd kg = md.shapes.transpose() * (km.stiffness * md.shapes);
  EXPECT_LT((kg - Eigen::MatrixXd(md.omega.array().square().matrix().asDiagonal())).norm(), 1e-7 * kg.norm());
  for (int k = 0; k < 5; ++k) {  // clamped unknowns are zero
    EXPECT_EQ(md.shapes(0, k), 0.0);
    EXPECT_GT(md.deflection(k).maxCoeff(), -md.deflection(k).minCoeff() - 1e-12);  // largest deflection positive
  }
  // mass: rho times the volume (thickness linear in x, so bilinear interpolation is exact)
  double volume = 0;
  for (std::size_t e = 0; e < m.quads.size(); ++e) {
    const double g3 = 1 / std::sqrt(3.0);
    for (double xi : {-g3, g3})
      for (double eta : {-g3, g3}) {
        double t = 0;
        for (int a = 0; a < 4; ++a) t += plate_mesh::shape(a, xi, eta) * m.thickness[static_cast<std::size_t>(m.quads[e][static_cast<std::size_t>(a)])];
        volume += t * m.jacobian(e, xi, eta).determinant();
      }
  }
  EXPECT_NEAR(plate_mass(km), mat.density * volume, 1e-12 * mat.density * volume);
}

TEST(PlateFe, RefusesBadInput) {
  plate_mesh m = rectangle(2, 2, 1, 1, 0.01);
  const orthotropic_material mat = isotropic_material(1e9, 0.3, 1000);
  {
    plate_mesh bad = m;
    bad.thickness[4] = -1e-3;
    EXPECT_THROW(assemble_plate(bad, mat), input_error);
  }
  {
    plate_mesh bad = m;
    std::swap(bad.quads[0][1], bad.quads[0][3]);  // clockwise
    EXPECT_THROW(assemble_plate(bad, mat), input_error);
  }
  {
    plate_mesh bad = m;
    bad.nodes[2].x() = NAN;
    EXPECT_THROW(assemble_plate(bad, mat), input_error);
  }
  {
    plate_mesh bad = m;
    bad.quads[1][2] = 99;
    EXPECT_THROW(assemble_plate(bad, mat), input_error);
  }
  {
    plate_mesh bad = m;
    bad.thickness.pop_back();
    EXPECT_THROW(assemble_plate(bad, mat), input_error);
  }
  orthotropic_material bad_mat = mat;
  bad_mat.nu12 = 1.5;
  EXPECT_THROW(assemble_plate(m, bad_mat), input_error);
  // one supported node leaves rigid rotations: refused as a mechanism, not a wrong mode
  plate_constraints few(m.nodes.size());
  few.support(0);
  EXPECT_THROW(plate_modes_of(m, mat, few), singular_matrix_error);
  EXPECT_THROW(plate_modes_of(m, mat, plate_constraints(3)), input_error);  // constraint size
  plate_constraints c = clamped_at_x0(2, 2);
  EXPECT_THROW(plate_modes_of(m, mat, c, {.count = 0}), input_error);
  EXPECT_THROW(plate_modes_of(m, mat, c, {.count = 100}), input_error);
}
