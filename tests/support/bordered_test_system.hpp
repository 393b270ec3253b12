#pragma once
// modal_block_system: the shape of a modal wing in a few dozen unknowns (5 per cell, 3 modes so
// 6 structural unknowns: the structure is no flow block), in the bordered form. Not a test itself
// (tests/CMakeLists.txt builds only tests/<layer>/test_*.cpp).
// Unknowns: u per cell, modal displacements q, modal velocities v. Flow rows: a stable block
// tridiagonal -D on z = u - u0, a cubic -0.1 z^3, the modal forcing G q and a constant load b.
// Structural rows: q' = v, v' = -K q - (C - mu) v + P z with K = diag(1, 2.25, 4) and
// C = diag(0.6, 0.9, 1.2). The equilibrium has v = 0 for every mu (fixed-equilibrium Hopf
// applies) and the weak coupling puts the first mode's Hopf point near mu = 0.6, omega = 1.
// The preconditioning Jacobian drops the cubic term, as a modified-order flow Jacobian differs
// from the exact one. sparse_view<S> shows the same system through Eigen sparse Jacobians only.
#include <aerohopf/linalg/bordered_block_matrix.hpp>
#include <aerohopf/nonlinear/aeroelastic_system.hpp>
#include <aerohopf/nonlinear/block_system.hpp>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <cmath>
#include <vector>

namespace aerohopf::test_support {

class modal_block_system {
 public:
  static constexpr int block_size = 5;  // unknowns per cell
  static constexpr int modes = 3;       // 2 * modes structural unknowns
  using jacobian_type = Eigen::SparseMatrix<double>;

  explicit modal_block_system(Eigen::Index cells = 12) : nc_(cells), nf_(cells * block_size) {
    auto pseudo = [](double a, double b) { return std::sin(12.9898 * a + 78.233 * b); };
    for (Eigen::Index i = 0; i < nc_; ++i)
      for (int d = -1; d <= 1; ++d) {
        const Eigen::Index j = i + d;
        if (j < 0 || j >= nc_) continue;
        Eigen::Matrix<double, 5, 5> blk;
        for (int r = 0; r < 5; ++r)
          for (int c = 0; c < 5; ++c) blk(r, c) = 0.2 * pseudo(double(i * 5 + r), double(j * 5 + c + 3 * d));
        if (d == 0) blk += 3.0 * Eigen::Matrix<double, 5, 5>::Identity();
        else blk -= 0.5 * Eigen::Matrix<double, 5, 5>::Identity();
        d_.push_back({i, j, blk});
      }
    g_.resize(nf_, modes);
    p_.resize(modes, nf_);
    u0_.resize(nf_);
    b_.resize(nf_);
    for (Eigen::Index k = 0; k < nf_; ++k) {
      for (int m = 0; m < modes; ++m) {
        g_(k, m) = 0.05 * pseudo(double(k), 100.0 + m);
        p_(m, k) = 0.02 * pseudo(200.0 + m, double(k));
      }
      u0_[k] = 1.0 + 0.2 * pseudo(double(k), 7.0);
      b_[k] = 0.3 * pseudo(double(k), 11.0);
    }
  }

  Eigen::Index size() const { return nf_ + 2 * modes; }
  Eigen::Index flow_size() const { return nf_; }
  Eigen::Index structure_size() const { return 2 * modes; }
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    require_size(v.size(), size(), "modal_block_system::structure_part", "vector");
    return v.tail(2 * modes);
  }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    require_size(w.size(), size(), "modal_block_system::residual", "state");
    vec<T> z(nf_), f(size());
    for (Eigen::Index k = 0; k < nf_; ++k) z[k] = w[k] - T(u0_[k]);
    for (Eigen::Index k = 0; k < nf_; ++k) f[k] = T(b_[k]) - T(0.1) * z[k] * z[k] * z[k];
    for (const auto& t : d_)
      for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 5; ++c) f[t.row * 5 + r] -= T(t.value(r, c)) * z[t.col * 5 + c];
    for (Eigen::Index k = 0; k < nf_; ++k)
      for (int m = 0; m < modes; ++m) f[k] += T(g_(k, m)) * w[nf_ + m];
    for (int m = 0; m < modes; ++m) {
      const T q = w[nf_ + m], v = w[nf_ + modes + m];
      f[nf_ + m] = v;
      T load = T(0.0);
      for (Eigen::Index k = 0; k < nf_; ++k) load += T(p_(m, k)) * z[k];
      f[nf_ + modes + m] = T(-stiffness(m)) * q - (T(damping(m)) - mu) * v + load;
    }
    return f;
  }

  jacobian_type jacobian(const vec<double>& w, double mu) const { return assemble(w, mu, true).to_sparse(); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    return assemble(w, mu, false).to_sparse();
  }
  bordered_jacobian_pair<block_size> bordered_jacobians(const vec<double>& w, double mu) const {
    return {assemble(w, mu, true), assemble(w, mu, false)};
  }

 private:
  static double stiffness(int m) { return (1.0 + 0.5 * m) * (1.0 + 0.5 * m); }
  static double damping(int m) { return 0.6 + 0.3 * m; }

  bordered_block_matrix<double, block_size> assemble(const vec<double>& w, double mu, bool exact) const {
    require_size(w.size(), size(), "modal_block_system::jacobians", "state");
    auto blocks = d_;
    for (auto& t : blocks) t.value = -t.value;
    if (exact)
      for (Eigen::Index i = 0; i < nc_; ++i) {
        block_triplet<double, block_size> t{i, i, Eigen::Matrix<double, 5, 5>::Zero()};
        for (int r = 0; r < 5; ++r) {
          const double z = w[i * 5 + r] - u0_[i * 5 + r];
          t.value(r, r) = -0.3 * z * z;
        }
        blocks.push_back(t);
      }
    Eigen::MatrixXd fs = Eigen::MatrixXd::Zero(nf_, 2 * modes), sf = Eigen::MatrixXd::Zero(2 * modes, nf_),
                    ss = Eigen::MatrixXd::Zero(2 * modes, 2 * modes);
    fs.leftCols(modes) = g_;
    sf.bottomRows(modes) = p_;
    for (int m = 0; m < modes; ++m) {
      ss(m, modes + m) = 1.0;
      ss(modes + m, m) = -stiffness(m);
      ss(modes + m, modes + m) = mu - damping(m);
    }
    return {block_sparse_matrix<double, block_size>::from_triplets(nc_, nc_, blocks), std::move(fs), std::move(sf),
            std::move(ss), "modal_block_system"};
  }

  Eigen::Index nc_, nf_;
  std::vector<block_triplet<double, block_size>> d_;
  Eigen::MatrixXd g_, p_;
  vec<double> u0_, b_;
};

/// S seen only as a dynamical_system with Eigen sparse Jacobians (and, if S has it, its
/// aeroelastic layout): the Krylov path then views its sparse matrices as bordered.
template <class S>
struct sparse_view {
  S s;
  using jacobian_type = Eigen::SparseMatrix<double>;
  Eigen::Index size() const { return s.size(); }
  Eigen::Index flow_size() const { return s.flow_size(); }
  Eigen::Index structure_size() const { return s.structure_size(); }
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    return s.structure_part(v);
  }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    return s.template residual<T>(w, mu);
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s.jacobian(w, mu); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const { return s.approximate_jacobian(w, mu); }
};

}  // namespace aerohopf::test_support
