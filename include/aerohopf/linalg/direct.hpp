#pragma once
// Direct linear solvers behind one small interface, for the dense (Eigen::Matrix) and sparse
// (Eigen::SparseMatrix) back ends of the nonlinear and bifurcation algorithms:
//
//   direct_solver<Matrix> s;  s.compute(A);  x = s.solve(b);
//
// Scalar may be real or complex. A singular or non-finite matrix throws singular_matrix_error
// naming the caller's context. The preconditioned Krylov solvers of linalg/ implement the same
// compute/solve interface, so every algorithm can switch to them without change.
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <complex>
#include <string>
#include <type_traits>

#include "../error.hpp"

namespace aerohopf {

template <class T>
using vec = Eigen::Matrix<T, Eigen::Dynamic, 1>;

template <class M>
struct is_sparse_matrix : std::is_base_of<Eigen::SparseMatrixBase<M>, M> {};
template <class M>
inline constexpr bool is_sparse_matrix_v = is_sparse_matrix<M>::value;

template <class Matrix, class Enable = void>
class direct_solver;

/// Dense: LU with partial pivoting; singularity judged by the reciprocal condition estimate.
template <class Matrix>
class direct_solver<Matrix, std::enable_if_t<!is_sparse_matrix_v<Matrix>>> {
 public:
  using scalar = typename Matrix::Scalar;
  explicit direct_solver(std::string context = "dense LU") : context_(std::move(context)) {}
  direct_solver& compute(const Matrix& a) {
    require(a.rows() == a.cols(), context_, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
    if (!a.allFinite()) throw singular_matrix_error(context_ + ": matrix has non-finite entries");
    lu_.compute(a);
    const double rc = static_cast<double>(std::abs(lu_.rcond()));
    if (!(rc > Eigen::NumTraits<double>::epsilon()) && a.rows() > 0)
      throw singular_matrix_error(internal::concat(context_, ": matrix is singular to working precision (rcond ",
                                                   rc, ")"));
    return *this;
  }
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    require(b.rows() == lu_.rows(), context_, ": right-hand side has ", b.rows(), " rows, matrix ", lu_.rows());
    return lu_.solve(b).eval();
  }
  Eigen::Index rows() const { return lu_.rows(); }

 private:
  std::string context_;
  Eigen::PartialPivLU<Eigen::Matrix<scalar, Eigen::Dynamic, Eigen::Dynamic>> lu_;
};

/// Sparse: SuperLU-style supernodal LU with COLAMD ordering (Eigen::SparseLU).
template <class Matrix>
class direct_solver<Matrix, std::enable_if_t<is_sparse_matrix_v<Matrix>>> {
 public:
  using scalar = typename Matrix::Scalar;
  using sparse = Eigen::SparseMatrix<scalar, Eigen::ColMajor, int>;
  explicit direct_solver(std::string context = "sparse LU") : context_(std::move(context)) {}
  direct_solver& compute(const Matrix& a) {
    require(a.rows() == a.cols(), context_, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
    sparse m = a;
    m.makeCompressed();
    for (Eigen::Index k = 0; k < m.nonZeros(); ++k)
      if (!std::isfinite(std::abs(m.valuePtr()[k])))
        throw singular_matrix_error(context_ + ": matrix has non-finite entries");
    if (!analysed_ || m.rows() != n_ || m.nonZeros() != nnz_) {
      lu_.analyzePattern(m);
      analysed_ = true;
      n_ = m.rows();
      nnz_ = m.nonZeros();
    }
    lu_.factorize(m);
    if (lu_.info() != Eigen::Success)
      throw singular_matrix_error(context_ + ": sparse LU failed: " + lu_.lastErrorMessage());
    return *this;
  }
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    require(b.rows() == n_, context_, ": right-hand side has ", b.rows(), " rows, matrix ", n_);
    Eigen::Matrix<scalar, Eigen::Dynamic, Rhs::ColsAtCompileTime> x = lu_.solve(b);
    if (!x.allFinite()) throw singular_matrix_error(context_ + ": solution is not finite (singular matrix?)");
    return x;
  }
  Eigen::Index rows() const { return n_; }

 private:
  std::string context_;
  Eigen::SparseLU<sparse, Eigen::COLAMDOrdering<int>> lu_;
  bool analysed_ = false;
  Eigen::Index n_ = 0, nnz_ = 0;
};

/// The identity of the same kind (dense or sparse) and size as a, in scalar S.
template <class S, class Matrix>
auto identity_like(const Matrix& a) {
  if constexpr (is_sparse_matrix_v<Matrix>) {
    Eigen::SparseMatrix<S> i(a.rows(), a.cols());
    i.setIdentity();
    return i;
  } else {
    return Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Identity(a.rows(), a.cols()).eval();
  }
}

/// A - sigma I for a complex shift sigma, dense or sparse as A is.
template <class Matrix>
auto shifted(const Matrix& a, std::complex<double> sigma) {
  using C = std::complex<double>;
  if constexpr (is_sparse_matrix_v<Matrix>) {
    Eigen::SparseMatrix<C> m = a.template cast<C>();
    Eigen::SparseMatrix<C> i = identity_like<C>(a);
    return Eigen::SparseMatrix<C>(m - sigma * i);
  } else {
    Eigen::Matrix<C, Eigen::Dynamic, Eigen::Dynamic> m = a.template cast<C>();
    m.diagonal().array() -= sigma;
    return m;
  }
}

}  // namespace aerohopf
