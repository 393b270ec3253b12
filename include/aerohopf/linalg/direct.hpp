#pragma once
// Direct linear solvers behind one small interface, for the dense (Eigen::Matrix) and sparse
// (Eigen::SparseMatrix) back ends of the nonlinear and bifurcation algorithms:
//
//   direct_solver<Matrix> s;  s.compute(A);  x = s.solve(b);
//
// Scalar may be real or complex. A singular or non-finite matrix throws singular_matrix_error
// naming the caller's context, from compute(); the solver then refuses solve() (the same
// exception) until a later compute() succeeds: a broken factorisation never yields numbers,
// nor does the factorisation of a previous matrix. The preconditioned Krylov solvers of linalg/ implement the same
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

namespace internal {
/// State shared by the direct solvers: whether the current factorisation may be used, and why
/// the last one failed.
class factorisation_state {
 public:
  explicit factorisation_state(std::string context) : context_(std::move(context)) {}
  const std::string& context() const { return context_; }
  void begin() {
    ok_ = false;
    failure_.clear();
  }
  void succeed() { ok_ = true; }
  [[noreturn]] void fail(const std::string& why) {
    failure_ = why;
    throw singular_matrix_error(context_ + ": " + why);
  }
  /// Throws unless a factorisation succeeded last: singular_matrix_error after a failed one,
  /// input_error before any.
  void require_usable() const {
    if (ok_) return;
    if (!failure_.empty())
      throw singular_matrix_error(context_ + ": solve() refused: the last factorisation failed (" + failure_ + ")");
    throw input_error(context_ + ": solve() before compute()");
  }

 private:
  std::string context_;
  bool ok_ = false;
  std::string failure_;
};
}  // namespace internal

/// Dense: LU with partial pivoting; singularity judged by the reciprocal condition estimate.
template <class Matrix>
class direct_solver<Matrix, std::enable_if_t<!is_sparse_matrix_v<Matrix>>> {
 public:
  using scalar = typename Matrix::Scalar;
  explicit direct_solver(std::string context = "dense LU") : state_(std::move(context)) {}
  direct_solver& compute(const Matrix& a) {
    const std::string& context_ = state_.context();
    require(a.rows() == a.cols(), context_, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
    state_.begin();
    if (!a.allFinite()) state_.fail("matrix has non-finite entries");
    lu_.compute(a);
    const double rc = static_cast<double>(std::abs(lu_.rcond()));
    if (!(rc > Eigen::NumTraits<double>::epsilon()) && a.rows() > 0)
      state_.fail(internal::concat("matrix is singular to working precision (rcond ", rc, ")"));
    state_.succeed();
    return *this;
  }
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    state_.require_usable();
    require(b.rows() == lu_.rows(), state_.context(), ": right-hand side has ", b.rows(), " rows, matrix ", lu_.rows());
    return lu_.solve(b).eval();
  }
  Eigen::Index rows() const { return lu_.rows(); }

 private:
  internal::factorisation_state state_;
  Eigen::PartialPivLU<Eigen::Matrix<scalar, Eigen::Dynamic, Eigen::Dynamic>> lu_;
};

/// Sparse: SuperLU-style supernodal LU with COLAMD ordering (Eigen::SparseLU).
template <class Matrix>
class direct_solver<Matrix, std::enable_if_t<is_sparse_matrix_v<Matrix>>> {
 public:
  using scalar = typename Matrix::Scalar;
  using sparse = Eigen::SparseMatrix<scalar, Eigen::ColMajor, int>;
  explicit direct_solver(std::string context = "sparse LU") : state_(std::move(context)) {}
  direct_solver& compute(const Matrix& a) {
    const std::string& context_ = state_.context();
    require(a.rows() == a.cols(), context_, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
    sparse m = a;
    m.makeCompressed();
    state_.begin();
    for (Eigen::Index k = 0; k < m.nonZeros(); ++k)
      if (!std::isfinite(std::abs(m.valuePtr()[k]))) state_.fail("matrix has non-finite entries");
    if (!analysed_ || m.rows() != n_ || m.nonZeros() != nnz_) {
      lu_.analyzePattern(m);
      analysed_ = true;
      n_ = m.rows();
      nnz_ = m.nonZeros();
    }
    lu_.factorize(m);
    if (lu_.info() != Eigen::Success) state_.fail("sparse LU failed: " + lu_.lastErrorMessage());
    state_.succeed();
    return *this;
  }
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    state_.require_usable();
    require(b.rows() == n_, state_.context(), ": right-hand side has ", b.rows(), " rows, matrix ", n_);
    Eigen::Matrix<scalar, Eigen::Dynamic, Rhs::ColsAtCompileTime> x = lu_.solve(b);
    if (!x.allFinite()) throw singular_matrix_error(state_.context() + ": solution is not finite (singular matrix?)");
    return x;
  }
  Eigen::Index rows() const { return n_; }

 private:
  internal::factorisation_state state_;
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
