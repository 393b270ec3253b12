#pragma once
// Generator of CFD-like block Jacobians for the linear-solver benchmark (bench_linear_solver).
//
// WHY a generator rather than stored matrices: the benchmark needs matrices of any size (from
// in-cache to far larger than the last-level cache) with the structure of a real flow
// Jacobian: b x b blocks (b = 4 in 2D, 5 in 3D), upwind (non-symmetric) couplings, acoustic
// and convective eigenvalues, optional second-order (MUSCL-type) stencil, grid blocks and a few
// structural unknowns coupled to the "wall" cells, so the fluid-structure and multi-block
// preconditioner variants of spec 07 can be exercised.
//
// The operator is the first-order upwind linearisation of a flux F(w) = A_n w per face on a
// structured nx x ny (x nz) grid with unit cells: A_n = R_d diag(lambda) R_d^{-1} per direction
// d, lambda = (u_n - c, u_n, ..., u_n, u_n + c) with a smoothly varying Mach-0.5 state, and the
// face flux F = A+ w_L + A- w_R (A+- = R diag(max/min(lambda, 0)) R^{-1}). The residual
// derivative J = dR/dw sums the face contributions (far-field boundary faces add their outgoing
// part to the diagonal). The second-order variant extrapolates the face states from two cells
// (w_L = 1.5 w_i - 0.5 w_{i-1}), giving the 9-point (2D) / 13-point (3D) stencil.
// The dynamical-systems Jacobian is A = -J (spec convention) and the structural block row (last
// block, padded to b unknowns) couples to every cell of the j = 0 wall layer both ways.
#include <aerohopf/linalg/block_sparse_matrix.hpp>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace aerohopf::bench {

struct cfd_grid {
  int nx = 32, ny = 32, nz = 1;  ///< nz = 1: 2D
  int blocks_per_direction = 2;  ///< grid blocks per direction (method 3 drops couplings across them)
  bool second_order = false;     ///< 9/13-point MUSCL-type stencil
  bool structure = true;         ///< add one structural block row coupled to the wall cells
  unsigned seed = 1;
  int dim() const { return nz > 1 ? 3 : 2; }
  long cells() const { return long(nx) * ny * nz; }
  std::string name() const {
    return std::string(dim() == 3 ? "euler3d" : "euler2d") + (second_order ? "_o2_" : "_o1_") + std::to_string(nx) +
           "x" + std::to_string(ny) + (dim() == 3 ? "x" + std::to_string(nz) : "");
  }
};

/// Grid block of each block row (structural row: -1), for coupling_filter::for_method.
inline std::vector<int> grid_blocks(const cfd_grid& g) {
  std::vector<int> lab(g.cells() + (g.structure ? 1 : 0), -1);
  const int p = g.blocks_per_direction;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const int bi = i * p / g.nx, bj = j * p / g.ny, bk = g.dim() == 3 ? k * p / g.nz : 0;
        lab[i + long(g.nx) * (j + long(g.ny) * k)] = bi + p * (bj + p * bk);
      }
  return lab;
}

/// A = -dR/dw for the grid above, with B = 4 (2D) or 5 (3D) unknowns per cell.
template <int B>
block_sparse_matrix<double, B> cfd_jacobian(const cfd_grid& g) {
  static_assert(B == 4 || B == 5, "cfd_jacobian: B = 4 (2D) or 5 (3D)");
  require((B == 4) == (g.dim() == 2), "cfd_jacobian: block size ", B, " does not match a ", g.dim(), "D grid");
  using block = Eigen::Matrix<double, B, B>;
  const int dim = g.dim();
  const long n = g.cells();
  const long nb = n + (g.structure ? 1 : 0);
  auto cell = [&](int i, int j, int k) { return i + long(g.nx) * (j + long(g.ny) * k); };
  const int ext[3] = {g.nx, g.ny, g.nz};

  // eigenvectors per direction: well-conditioned random perturbations of the identity
  std::mt19937 gen(g.seed);
  std::uniform_real_distribution<double> u01(-1.0, 1.0);
  std::array<block, 3> r, rinv;
  for (int d = 0; d < 3; ++d) {
    for (int a = 0; a < B; ++a)
      for (int b = 0; b < B; ++b) r[d](a, b) = (a == b ? 1.0 : 0.0) + 0.35 * u01(gen);
    rinv[d] = r[d].inverse();
  }
  const double vel[3] = {0.5, 0.12, 0.05};  // Mach 0.5 mostly along x (c = 1)
  auto split = [&](int d, double x, double y, double z, block& ap, block& am) {
    const double var = 1.0 + 0.15 * std::sin(0.7 * x + 0.3 * y) * std::cos(0.5 * z + 0.2 * x);
    const double c = 1.0 * var, un = vel[d] * (2.0 - var);
    Eigen::Matrix<double, B, 1> lp, lm;
    for (int a = 0; a < B; ++a) {
      const double lam = a == 0 ? un - c : (a == B - 1 ? un + c : un * (1.0 + 0.1 * a));
      lp(a) = std::max(lam, 0.0);
      lm(a) = std::min(lam, 0.0);
    }
    ap.noalias() = r[d] * lp.asDiagonal() * rinv[d];
    am.noalias() = r[d] * lm.asDiagonal() * rinv[d];
  };

  // pattern: neighbours (and second neighbours for second order) + structure couplings
  std::vector<std::pair<long, long>> pattern;
  const int reach = g.second_order ? 2 : 1;
  pattern.reserve(nb * (1 + 2 * dim * reach) + 4 * g.nx * g.nz);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const long c = cell(i, j, k);
        pattern.emplace_back(c, c);
        for (int d = 0; d < dim; ++d)
          for (int s = -reach; s <= reach; ++s) {
            if (s == 0) continue;
            int q[3] = {i, j, k};
            q[d] += s;
            if (q[d] >= 0 && q[d] < ext[d]) pattern.emplace_back(c, cell(q[0], q[1], q[2]));
          }
      }
  if (g.structure) {
    pattern.emplace_back(n, n);
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        pattern.emplace_back(cell(i, 0, k), n);
        pattern.emplace_back(n, cell(i, 0, k));
      }
  }
  block_sparse_matrix<double, B> jac;
  jac.set_pattern(nb, nb, pattern);
  pattern.clear();
  pattern.shrink_to_fit();

  // faces: J_row(L) += dF/dw, J_row(R) -= dF/dw (outward normal from L to R)
  block ap, am;
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        for (int d = 0; d < dim; ++d) {
          int q[3] = {i, j, k};
          const long c = cell(i, j, k);
          split(d, i + 0.5 * (d == 0), j + 0.5 * (d == 1), k + 0.5 * (d == 2), ap, am);
          if (q[d] == 0) {  // far-field face on the low side: outgoing part -A- (normal -e_d)
            jac.block(c, c) -= am;
          }
          q[d] += 1;
          if (q[d] == ext[d]) {  // far-field face on the high side
            jac.block(c, c) += ap;
            continue;
          }
          const long rr = cell(q[0], q[1], q[2]);
          // contributions dF/dw_m with weights; first order: (c: A+, rr: A-)
          auto add = [&](long m, const block& dfdw) {
            jac.block(c, m) += dfdw;
            jac.block(rr, m) -= dfdw;
          };
          int ql[3] = {i, j, k}, qr[3] = {q[0], q[1], q[2]};
          ql[d] -= 1;
          qr[d] += 1;
          const bool has_l = g.second_order && ql[d] >= 0, has_r = g.second_order && qr[d] < ext[d];
          add(c, (has_l ? 1.5 : 1.0) * ap);
          if (has_l) add(cell(ql[0], ql[1], ql[2]), -0.5 * ap);
          add(rr, (has_r ? 1.5 : 1.0) * am);
          if (has_r) add(cell(qr[0], qr[1], qr[2]), -0.5 * am);
        }
  // structure: the wall layer feels the structural displacement, the structure the wall load
  if (g.structure) {
    block ks = block::Identity() * 2.0;
    ks(0, 1) = 0.3;
    ks(1, 0) = -0.3;
    jac.block(n, n) = ks;
    const double w = 1.0 / (g.nx * g.nz);
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        block fs = block::Zero(), sf = block::Zero();
        fs.col(0).setConstant(0.05);
        fs.col(1).setConstant(-0.02 * (1 + 0.1 * i));
        sf.row(0).setConstant(w);
        sf.row(1).setConstant(0.5 * w * i / g.nx);
        jac.block(cell(i, 0, k), n) = fs;
        jac.block(n, cell(i, 0, k)) = sf;
      }
    // only the first 2 structural unknowns are real; the rest of the block row is padding
    jac.set_logical_size(n * B + 2, n * B + 2);
    for (int e = 2; e < B; ++e) {
      jac.block(n, n).row(e).setZero();
      jac.block(n, n).col(e).setZero();
      jac.block(n, n)(e, e) = 1.0;
    }
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        jac.block(cell(i, 0, k), n).rightCols(B - 2).setZero();
        jac.block(n, cell(i, 0, k)).bottomRows(B - 2).setZero();
      }
  }
  for (auto& v : jac.values()) v = -v;  // A = -J (Re lambda < 0 stable)
  // restore the identity on the padded unknowns (negated above)
  if (g.structure)
    for (int e = 2; e < B; ++e) jac.block(n, n)(e, e) = 1.0;
  return jac;
}

}  // namespace aerohopf::bench
