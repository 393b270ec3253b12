#pragma once
// Plate finite elements that make a wing's structural modes (spec 06: the AGARD 445.6 mode shapes
// are not published in a usable form, so they are computed from the planform, the section's
// thickness and the orthotropic properties of the laminated mahogany).
//
// Element: the 4-node Reissner-Mindlin quadrilateral with mixed interpolation of the transverse
// shear strains (MITC4, Bathe and Dvorkin 1985). Per node three unknowns (w, beta_x, beta_y):
// the deflection and the rotations of the normal, u = z beta_x, v = z beta_y, so that the
// Kirchhoff limit is beta = -grad w. Curvatures kappa = (beta_x,x, beta_y,y, beta_x,y + beta_y,x)
// and shear strains gamma = grad w + beta. The covariant shear strains are sampled at the edge
// midpoints and interpolated across the element: without that, a bilinear element locks in
// shear as the plate gets thin (a wing section of 4 % thickness is thin).
//
// Material: an orthotropic lamina with its fibre direction 1 at fibre_angle from the x axis in
// the plate plane. Bending stiffness D = t^3/12 Qbar with Qbar = T^T Q T (T maps engineering
// strains to the fibre frame), shear stiffness k t R^T diag(G13, G23) R (k = 5/6). The thickness
// is given per node and interpolated bilinearly, so a tapered, thin-edged wing is one mesh.
// Consistent mass: rho t for w, rho t^3/12 for the rotations; 2x2 Gauss everywhere.
//
// Modes: the lowest eigenpairs of K phi = omega^2 M phi with the constrained unknowns removed,
// by subspace iteration on a sparse LDL^T factorisation of K (Bathe's method), each converged
// pair checked by its residual; mass-normalised, phi^T M phi = 1.
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "../error.hpp"

namespace aerohopf::structure {

/// Orthotropic lamina (plane stress) with transverse shear moduli; SI units or any consistent set.
struct orthotropic_material {
  double e1 = 1, e2 = 1;      ///< Young's moduli along and across the fibre
  double g12 = 0.5;           ///< in-plane shear modulus
  double nu12 = 0;            ///< major Poisson ratio (nu21 = nu12 e2 / e1)
  double g13 = 0, g23 = 0;    ///< transverse shear moduli (0: g12)
  double density = 1;
  double fibre_angle = 0;     ///< radians from the x axis to the fibre direction 1
  double shear_correction = 5.0 / 6.0;

  void validate(const std::string& who) const {
    for (double v : {e1, e2, g12, density})
      require(std::isfinite(v) && v > 0, who, ": moduli and density must be finite and > 0 (E1 ", e1, ", E2 ", e2,
              ", G12 ", g12, ", rho ", density, ")");
    require(std::isfinite(g13) && g13 >= 0 && std::isfinite(g23) && g23 >= 0, who,
            ": transverse shear moduli must be >= 0 (0: G12)");
    require(std::isfinite(nu12) && nu12 * nu12 * e2 / e1 < 1, who, ": nu12 = ", nu12,
            " makes the lamina indefinite (need nu12^2 E2/E1 < 1)");
    require(std::isfinite(fibre_angle), who, ": fibre angle is not finite");
    require(shear_correction > 0 && shear_correction <= 1, who, ": shear correction must lie in (0, 1]");
  }
};

/// Isotropic material: E, nu, rho (G = E / (2 (1 + nu)) in and out of plane).
inline orthotropic_material isotropic_material(double e, double nu, double density) {
  orthotropic_material m;
  m.e1 = m.e2 = e;
  m.nu12 = nu;
  m.g12 = m.g13 = m.g23 = e / (2 * (1 + nu));
  m.density = density;
  return m;
}

/// Plane-stress stiffness Qbar in the x-y frame (engineering shear strain), Qbar = T^T Q T.
inline Eigen::Matrix3d plane_stress_stiffness(const orthotropic_material& m) {
  const double nu21 = m.nu12 * m.e2 / m.e1, den = 1 - m.nu12 * nu21;
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  q(0, 0) = m.e1 / den;
  q(1, 1) = m.e2 / den;
  q(0, 1) = q(1, 0) = m.nu12 * m.e2 / den;
  q(2, 2) = m.g12;
  const double c = std::cos(m.fibre_angle), s = std::sin(m.fibre_angle);
  Eigen::Matrix3d t;  // [eps_11, eps_22, gamma_12] = T [eps_xx, eps_yy, gamma_xy]
  t << c * c, s * s, c * s, s * s, c * c, -c * s, -2 * c * s, 2 * c * s, c * c - s * s;
  return t.transpose() * q * t;
}

/// Transverse shear stiffness per unit thickness in the x-y frame, k R^T diag(G13, G23) R.
inline Eigen::Matrix2d transverse_shear_stiffness(const orthotropic_material& m) {
  const double g13 = m.g13 > 0 ? m.g13 : m.g12, g23 = m.g23 > 0 ? m.g23 : m.g12;
  const double c = std::cos(m.fibre_angle), s = std::sin(m.fibre_angle);
  Eigen::Matrix2d r;  // [gamma_1z, gamma_2z] = R [gamma_xz, gamma_yz]
  r << c, s, -s, c;
  return m.shear_correction * r.transpose() * Eigen::Vector2d(g13, g23).asDiagonal() * r;
}

/// Quadrilateral plate mesh: nodes in the plate plane, thickness per node, quads counter-clockwise.
struct plate_mesh {
  std::vector<Eigen::Vector2d> nodes;
  std::vector<double> thickness;
  std::vector<std::array<int, 4>> quads;

  Eigen::Index unknowns() const { return 3 * static_cast<Eigen::Index>(nodes.size()); }

  /// Throws input_error naming the first bad entry: sizes, finite coordinates, thickness >= 0,
  /// node indices in range, positive Jacobian at the element's Gauss points (convex, counter-
  /// clockwise), and a positive thickness somewhere in each element.
  void validate(const std::string& who) const {
    require(!nodes.empty() && !quads.empty(), who, ": empty mesh (", nodes.size(), " nodes, ", quads.size(),
            " quads)");
    require_size(thickness.size(), nodes.size(), who, "thickness");
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      require(nodes[i].allFinite(), who, ": node ", i, " has a non-finite coordinate");
      require(std::isfinite(thickness[i]) && thickness[i] >= 0, who, ": thickness at node ", i, " is ", thickness[i],
              " (must be finite and >= 0)");
    }
    for (std::size_t e = 0; e < quads.size(); ++e) {
      double tsum = 0;
      for (int a : quads[e]) {
        require(a >= 0 && static_cast<std::size_t>(a) < nodes.size(), who, ": quad ", e, " refers to node ", a, " of ",
                nodes.size());
        tsum += thickness[static_cast<std::size_t>(a)];
      }
      require(tsum > 0, who, ": quad ", e, " has zero thickness at all four nodes");
      for (double xi : {-1.0, 1.0})
        for (double eta : {-1.0, 1.0}) {
          const double det = jacobian(e, xi / std::sqrt(3.0), eta / std::sqrt(3.0)).determinant();
          require(det > 0, who, ": quad ", e, " is inverted, degenerate or clockwise (det J = ", det, ")");
        }
    }
  }

  /// d(x, y)/d(xi, eta) of quad e: rows d/dxi and d/deta.
  Eigen::Matrix2d jacobian(std::size_t e, double xi, double eta) const {
    Eigen::Matrix2d j = Eigen::Matrix2d::Zero();
    for (int a = 0; a < 4; ++a) {
      const auto [dxi, deta] = shape_derivatives(a, xi, eta);
      const Eigen::Vector2d& p = nodes[static_cast<std::size_t>(quads[e][static_cast<std::size_t>(a)])];
      j.row(0) += dxi * p.transpose();
      j.row(1) += deta * p.transpose();
    }
    return j;
  }

  static constexpr double node_xi[4] = {-1, 1, 1, -1};
  static constexpr double node_eta[4] = {-1, -1, 1, 1};
  static double shape(int a, double xi, double eta) { return 0.25 * (1 + xi * node_xi[a]) * (1 + eta * node_eta[a]); }
  static std::pair<double, double> shape_derivatives(int a, double xi, double eta) {
    return {0.25 * node_xi[a] * (1 + eta * node_eta[a]), 0.25 * node_eta[a] * (1 + xi * node_xi[a])};
  }
};

/// A structured mesh of (ni x nj) quads over the map (s, r) in [0,1]^2 -> (x, y), thickness by
/// a function of (x, y). Nodes are numbered i + (ni + 1) j.
template <class Map, class Thickness>
plate_mesh structured_plate_mesh(int ni, int nj, Map&& map, Thickness&& thickness) {
  require(ni >= 1 && nj >= 1, "structured_plate_mesh: need at least one quad each way (got ", ni, " x ", nj, ")");
  plate_mesh m;
  for (int j = 0; j <= nj; ++j)
    for (int i = 0; i <= ni; ++i) {
      const Eigen::Vector2d p = map(static_cast<double>(i) / ni, static_cast<double>(j) / nj);
      m.nodes.push_back(p);
      m.thickness.push_back(thickness(p.x(), p.y()));
    }
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) {
      const int a = i + (ni + 1) * j;
      m.quads.push_back({a, a + 1, a + 1 + (ni + 1), a + (ni + 1)});
    }
  return m;
}

/// Global stiffness and mass matrices (3 unknowns per node: w, beta_x, beta_y), no constraints.
struct plate_matrices {
  Eigen::SparseMatrix<double> stiffness, mass;
};

namespace internal {
/// The shear-strain row of the covariant component along d/dxi (dir 0) or d/deta (dir 1) at
/// (xi, eta): e = w_,dir + beta . x_,dir, as 12 coefficients of the element unknowns.
inline Eigen::Matrix<double, 1, 12> covariant_shear_row(const plate_mesh& m, std::size_t e, int dir, double xi,
                                                         double eta) {
  const Eigen::Matrix2d j = m.jacobian(e, xi, eta);
  Eigen::Matrix<double, 1, 12> row = Eigen::Matrix<double, 1, 12>::Zero();
  for (int a = 0; a < 4; ++a) {
    const auto [dxi, deta] = plate_mesh::shape_derivatives(a, xi, eta);
    const double n = plate_mesh::shape(a, xi, eta);
    row(3 * a) = dir == 0 ? dxi : deta;
    row(3 * a + 1) = n * j(dir, 0);
    row(3 * a + 2) = n * j(dir, 1);
  }
  return row;
}
}  // namespace internal

/// Element stiffness and mass (12 x 12) of quad e.
inline std::pair<Eigen::Matrix<double, 12, 12>, Eigen::Matrix<double, 12, 12>> plate_element_matrices(
    const plate_mesh& m, std::size_t e, const Eigen::Matrix3d& qbar, const Eigen::Matrix2d& shear, double density) {
  using mat12 = Eigen::Matrix<double, 12, 12>;
  mat12 k = mat12::Zero(), ms = mat12::Zero();
  // tying points of MITC4: e_xi at (0, -1) and (0, 1), e_eta at (-1, 0) and (1, 0)
  const auto exi_a = internal::covariant_shear_row(m, e, 0, 0, -1), exi_c = internal::covariant_shear_row(m, e, 0, 0, 1);
  const auto eeta_d = internal::covariant_shear_row(m, e, 1, -1, 0),
             eeta_b = internal::covariant_shear_row(m, e, 1, 1, 0);
  const double g = 1 / std::sqrt(3.0);
  for (double xi : {-g, g})
    for (double eta : {-g, g}) {
      const Eigen::Matrix2d j = m.jacobian(e, xi, eta);
      const double det = j.determinant();
      const Eigen::Matrix2d jinv = j.inverse();
      double t = 0;
      Eigen::Matrix<double, 3, 12> bb = Eigen::Matrix<double, 3, 12>::Zero();
      Eigen::Matrix<double, 1, 12> nw = Eigen::Matrix<double, 1, 12>::Zero(), nx = nw, ny = nw;
      for (int a = 0; a < 4; ++a) {
        const auto [dxi, deta] = plate_mesh::shape_derivatives(a, xi, eta);
        const Eigen::Vector2d dxy = jinv * Eigen::Vector2d(dxi, deta);  // (N_,x, N_,y)
        const double n = plate_mesh::shape(a, xi, eta);
        t += n * m.thickness[static_cast<std::size_t>(m.quads[e][static_cast<std::size_t>(a)])];
        bb(0, 3 * a + 1) = dxy.x();
        bb(1, 3 * a + 2) = dxy.y();
        bb(2, 3 * a + 1) = dxy.y();
        bb(2, 3 * a + 2) = dxy.x();
        nw(3 * a) = n;
        nx(3 * a + 1) = n;
        ny(3 * a + 2) = n;
      }
      Eigen::Matrix<double, 2, 12> cov;
      cov.row(0) = 0.5 * (1 - eta) * exi_a + 0.5 * (1 + eta) * exi_c;
      cov.row(1) = 0.5 * (1 - xi) * eeta_d + 0.5 * (1 + xi) * eeta_b;
      const Eigen::Matrix<double, 2, 12> bs = jinv * cov;  // [e_xi; e_eta] = J gamma
      const double t3 = t * t * t / 12;
      k += det * (bb.transpose() * (t3 * qbar) * bb + bs.transpose() * (t * shear) * bs);
      ms += det * density * (t * nw.transpose() * nw + t3 * (nx.transpose() * nx + ny.transpose() * ny));
    }
  return {k, ms};
}

/// Assembles K and M of the whole mesh (validated first).
inline plate_matrices assemble_plate(const plate_mesh& m, const orthotropic_material& mat) {
  const std::string who = "assemble_plate";
  m.validate(who);
  mat.validate(who);
  const Eigen::Matrix3d qbar = plane_stress_stiffness(mat);
  const Eigen::Matrix2d shear = transverse_shear_stiffness(mat);
  std::vector<Eigen::Triplet<double>> kt, mt;
  kt.reserve(m.quads.size() * 144);
  mt.reserve(m.quads.size() * 144);
  for (std::size_t e = 0; e < m.quads.size(); ++e) {
    const auto [k, ms] = plate_element_matrices(m, e, qbar, shear, mat.density);
    for (int a = 0; a < 12; ++a)
      for (int b = 0; b < 12; ++b) {
        const int ga = 3 * m.quads[e][static_cast<std::size_t>(a / 3)] + a % 3;
        const int gb = 3 * m.quads[e][static_cast<std::size_t>(b / 3)] + b % 3;
        kt.emplace_back(ga, gb, k(a, b));
        mt.emplace_back(ga, gb, ms(a, b));
      }
  }
  plate_matrices r;
  const Eigen::Index n = m.unknowns();
  r.stiffness.resize(n, n);
  r.mass.resize(n, n);
  r.stiffness.setFromTriplets(kt.begin(), kt.end());
  r.mass.setFromTriplets(mt.begin(), mt.end());
  return r;
}

/// Constrained unknowns: node k's unknown d (0 w, 1 beta_x, 2 beta_y) held at zero.
struct plate_constraints {
  std::vector<std::array<bool, 3>> fixed;  ///< per node; empty = free

  explicit plate_constraints(std::size_t nodes = 0) : fixed(nodes, {false, false, false}) {}
  void clamp(int node) { fixed.at(static_cast<std::size_t>(node)) = {true, true, true}; }
  /// Simple support (soft): the deflection only.
  void support(int node) { fixed.at(static_cast<std::size_t>(node))[0] = true; }
};

struct plate_mode_options {
  int count = 4;                ///< modes wanted (lowest frequencies)
  int subspace = 0;             ///< subspace dimension (0: max(2 count, count + 8), at most the free unknowns)
  double residual_tolerance = 1e-8;  ///< converged: ||K x - omega^2 M x|| <= this ||K x|| for every wanted mode
  /// ... or the residuals stalled (no halving of the largest in 3 iterations) at or below
  /// stalled_tolerance: the residual of a thin plate stops at the rounding floor of its
  /// ill-conditioned K (shear ~ t, bending ~ t^3; a strip with t/L = 1e-3 stalls at 4e-7, with
  /// omega^2 then converged to 1e-8).
  double stalled_tolerance = 1e-4;
  int max_iterations = 300;
};

struct plate_modes {
  Eigen::VectorXd omega;     ///< circular frequencies, rad/s (ascending)
  Eigen::MatrixXd shapes;    ///< one column per mode, 3 per node, phi^T M phi = 1, 0 at fixed unknowns
  Eigen::VectorXd residual;  ///< ||K phi - omega^2 M phi|| / ||K phi|| per mode
  int iterations = 0;
  double frequency_hz(Eigen::Index i) const { return omega[i] / (2 * std::numbers::pi); }
  /// Deflection w of mode i at every node.
  Eigen::VectorXd deflection(Eigen::Index i) const {
    Eigen::VectorXd w(shapes.rows() / 3);
    for (Eigen::Index k = 0; k < w.size(); ++k) w[k] = shapes(3 * k, i);
    return w;
  }
};

/// The lowest opt.count modes of K phi = omega^2 M phi with the unknowns in c held at zero, by
/// subspace iteration: X <- K^{-1} M X, Rayleigh-Ritz on span X (dense generalised
/// eigenproblem), until every wanted pair has ||K x - omega^2 M x|| <= residual_tolerance ||K x||
/// or the residuals stall at rounding below stalled_tolerance (thin plates); the wanted pairs
/// converge at the rate omega_j^2 / omega_{q+1}^2 per iteration. plate_modes::residual reports
/// each pair's final residual. Throws singular_matrix_error if the constrained K is not positive
/// definite (a mechanism: too few constraints), convergence_error otherwise.
inline plate_modes plate_modes_of(const plate_matrices& km, const plate_constraints& c,
                                  const plate_mode_options& opt = {}) {
  const std::string who = "plate_modes_of";
  const Eigen::Index n = km.stiffness.rows();
  require(km.stiffness.cols() == n && km.mass.rows() == n && km.mass.cols() == n, who,
          ": stiffness and mass must be square and of one size (", km.stiffness.rows(), "x", km.stiffness.cols(), ", ",
          km.mass.rows(), "x", km.mass.cols(), ")");
  require_size(3 * static_cast<Eigen::Index>(c.fixed.size()), n, who, "constraints (3 per node)");
  std::vector<int> free_of(static_cast<std::size_t>(n), -1), dof;
  for (Eigen::Index i = 0; i < n; ++i)
    if (!c.fixed[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)]) {
      free_of[static_cast<std::size_t>(i)] = static_cast<int>(dof.size());
      dof.push_back(static_cast<int>(i));
    }
  const Eigen::Index nf = static_cast<Eigen::Index>(dof.size());
  require(opt.count >= 1 && opt.count <= nf, who, ": count must lie in [1, ", nf, "] (the free unknowns; got ",
          opt.count, ")");
  require(opt.max_iterations >= 1 && opt.residual_tolerance > 0 && opt.stalled_tolerance >= 0, who,
          ": need max_iterations >= 1, residual_tolerance > 0 and stalled_tolerance >= 0 (got ", opt.max_iterations,
          ", ", opt.residual_tolerance, ", ", opt.stalled_tolerance, ")");
  const Eigen::Index p = opt.count;
  const Eigen::Index q = std::min<Eigen::Index>(nf, opt.subspace > 0 ? std::max<Eigen::Index>(opt.subspace, p)
                                                                     : std::max<Eigen::Index>(2 * p, p + 8));
  auto restrict = [&](const Eigen::SparseMatrix<double>& a) {
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < a.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, k); it; ++it) {
        const int r = free_of[static_cast<std::size_t>(it.row())], cc = free_of[static_cast<std::size_t>(it.col())];
        if (r >= 0 && cc >= 0) t.emplace_back(r, cc, it.value());
      }
    Eigen::SparseMatrix<double> s(nf, nf);
    s.setFromTriplets(t.begin(), t.end());
    return s;
  };
  const Eigen::SparseMatrix<double> k = restrict(km.stiffness), m = restrict(km.mass);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0))
    throw singular_matrix_error(aerohopf::internal::concat(
        who, ": the constrained stiffness matrix is not positive definite (", nf,
        " free unknowns): the constraints leave a rigid-body motion or a mechanism, or the mesh has a zero-thickness "
        "region"));
  // start: the diagonal of M, then random vectors (fixed seed: reproducible modes)
  Eigen::MatrixXd x(nf, q);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1, 1);
  for (Eigen::Index j = 0; j < q; ++j)
    for (Eigen::Index i = 0; i < nf; ++i) x(i, j) = j == 0 ? m.coeff(i, i) : u(rng);
  Eigen::VectorXd lam, res(p);
  double best = std::numeric_limits<double>::infinity();
  int since_best = 0;
  int it = 0;
  for (it = 1; it <= opt.max_iterations; ++it) {
    const Eigen::MatrixXd y = ldlt.solve(Eigen::MatrixXd(m * x));
    const Eigen::MatrixXd kr = y.transpose() * (k * y), mr = y.transpose() * (m * y);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(0.5 * (kr + kr.transpose()),
                                                                  0.5 * (mr + mr.transpose()));
    if (ges.info() != Eigen::Success)
      throw convergence_error(aerohopf::internal::concat(who, ": Rayleigh-Ritz eigenproblem failed at iteration ", it,
                                               " (the subspace lost rank: raise subspace or check the mesh)"));
    x = y * ges.eigenvectors();  // M-orthonormal Ritz vectors, ascending
    lam = ges.eigenvalues().head(p);
    // Rayleigh quotients of a positive definite K are positive: a Ritz value <= 0 means the
    // factorisation went through a rigid-body motion or mechanism on rounding-level pivots
    if (!(ges.eigenvalues()[0] > 0))
      throw singular_matrix_error(aerohopf::internal::concat(
          who, ": the constrained stiffness matrix is not positive definite (Ritz value omega^2 = ",
          ges.eigenvalues()[0], " at iteration ", it,
          "): the constraints leave a rigid-body motion or a mechanism, or the mesh has a zero-thickness region"));
    const Eigen::MatrixXd kx = k * x.leftCols(p), mx = m * x.leftCols(p);
    for (Eigen::Index j = 0; j < p; ++j) res[j] = (kx.col(j) - lam[j] * mx.col(j)).norm() / kx.col(j).norm();
    const double worst = res.maxCoeff();
    since_best = worst < 0.5 * best ? 0 : since_best + 1;
    best = std::min(best, worst);
    const bool stalled = since_best >= 3 && worst <= opt.stalled_tolerance;
    if ((lam.array() > 0).all() && (worst <= opt.residual_tolerance || stalled)) break;
  }
  if (it > opt.max_iterations)
    throw convergence_error(aerohopf::internal::concat(who, ": ", p, " modes not converged in ", opt.max_iterations,
                                             " subspace iterations (subspace ", q, ", residuals ", res.transpose(),
                                             ", omega^2 ", lam.transpose(), ")"));
  plate_modes r;
  r.iterations = it;
  r.omega.resize(p);
  r.residual = res;
  r.shapes = Eigen::MatrixXd::Zero(n, p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const Eigen::VectorXd v = x.col(j);
    r.omega[j] = std::sqrt(lam[j]);
    // sign: largest deflection positive
    Eigen::Index imax = 0;
    double best = 0;
    for (Eigen::Index i = 0; i < nf; ++i)
      if (dof[static_cast<std::size_t>(i)] % 3 == 0 && std::abs(v[i]) > best) {
        best = std::abs(v[i]);
        imax = i;
      }
    const double sgn = v[imax] < 0 ? -1.0 : 1.0;
    for (Eigen::Index i = 0; i < nf; ++i) r.shapes(dof[static_cast<std::size_t>(i)], j) = sgn * v[i];
  }
  return r;
}

/// Modes of a mesh and material with constraints (assembles, then plate_modes_of).
inline plate_modes plate_modes_of(const plate_mesh& mesh, const orthotropic_material& mat, const plate_constraints& c,
                                  const plate_mode_options& opt = {}) {
  require_size(c.fixed.size(), mesh.nodes.size(), "plate_modes_of", "constraints (one entry per node)");
  return plate_modes_of(assemble_plate(mesh, mat), c, opt);
}

/// Total mass of the plate, integral of rho t over the planform (the w-w block of M summed).
inline double plate_mass(const plate_matrices& km) {
  double s = 0;
  for (int k = 0; k < km.mass.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(km.mass, k); it; ++it)
      if (it.row() % 3 == 0 && it.col() % 3 == 0) s += it.value();
  return s;
}

}  // namespace aerohopf::structure
