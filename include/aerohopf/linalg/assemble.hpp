#pragma once
// block_assembler: builds a bordered/blocked matrix (the pseudo-arclength corrector matrix, the
// augmented Hopf Jacobians) out of n x n system matrices plus dense border rows and columns,
// producing the same kind of matrix (dense Eigen::MatrixXd or Eigen::SparseMatrix<double>) as
// the system's Jacobian so that one direct or Krylov back end serves both.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

#include "../error.hpp"
#include "direct.hpp"

namespace aerohopf {

template <class Matrix>
class block_assembler {
  static constexpr bool sparse = is_sparse_matrix_v<Matrix>;

 public:
  block_assembler(Eigen::Index rows, Eigen::Index cols) : rows_(rows), cols_(cols) {
    if constexpr (!sparse) dense_ = Eigen::MatrixXd::Zero(rows, cols);
  }

  /// Adds scale * block with its (0,0) entry at (i0, j0).
  template <class Block>
  void add(Eigen::Index i0, Eigen::Index j0, const Block& block, double scale = 1.0) {
    require(i0 + block.rows() <= rows_ && j0 + block.cols() <= cols_, "block_assembler: block does not fit");
    if constexpr (sparse) {
      if constexpr (is_sparse_matrix_v<Block>) {
        for (int k = 0; k < block.outerSize(); ++k)
          for (typename Block::InnerIterator it(block, k); it; ++it)
            trip_.emplace_back(int(i0 + it.row()), int(j0 + it.col()), scale * it.value());
      } else {
        for (Eigen::Index j = 0; j < block.cols(); ++j)
          for (Eigen::Index i = 0; i < block.rows(); ++i)
            if (block(i, j) != 0.0) trip_.emplace_back(int(i0 + i), int(j0 + j), scale * block(i, j));
      }
    } else {
      if constexpr (is_sparse_matrix_v<Block>) dense_.block(i0, j0, block.rows(), block.cols()) += scale * Eigen::MatrixXd(block);
      else dense_.block(i0, j0, block.rows(), block.cols()) += scale * block;
    }
  }
  /// Adds scale * I (size n) at (i0, j0).
  void add_identity(Eigen::Index i0, Eigen::Index j0, Eigen::Index n, double scale) {
    for (Eigen::Index i = 0; i < n; ++i) add_entry(i0 + i, j0 + i, scale);
  }
  void add_entry(Eigen::Index i, Eigen::Index j, double v) {
    if (v == 0.0) return;
    if constexpr (sparse) trip_.emplace_back(int(i), int(j), v);
    else dense_(i, j) += v;
  }
  /// Dense column segment v placed at rows i0.., column j.
  void add_column(Eigen::Index i0, Eigen::Index j, const vec<double>& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) add_entry(i0 + i, j, v[i]);
  }
  /// Dense row segment v placed at row i, columns j0...
  void add_row(Eigen::Index i, Eigen::Index j0, const vec<double>& v) {
    for (Eigen::Index j = 0; j < v.size(); ++j) add_entry(i, j0 + j, v[j]);
  }
  Matrix build() const {
    if constexpr (sparse) {
      Matrix m(rows_, cols_);
      m.setFromTriplets(trip_.begin(), trip_.end());
      m.makeCompressed();
      return m;
    } else {
      return dense_;
    }
  }

 private:
  Eigen::Index rows_, cols_;
  Eigen::MatrixXd dense_;
  std::vector<Eigen::Triplet<double>> trip_;
};

}  // namespace aerohopf
