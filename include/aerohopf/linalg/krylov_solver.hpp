#pragma once
// BILU(k)-preconditioned Krylov solver behind the compute/solve interface of direct.hpp, so the
// nonlinear and bifurcation layers can swap
//     direct_solver<Eigen::SparseMatrix<double>> s;   ->   krylov_solver<Eigen::SparseMatrix<double>> s;
//     s.compute(A);  x = s.solve(b);
// without other change. WHY: the sparse LU of a 3D flow Jacobian (or of A - i omega I) fills
// in far beyond memory; BILU(k) + GMRES keeps the storage within a few times the matrix.
//
// The matrix (Eigen sparse or dense, real or complex) is blocked with block size B (compile
// time; Eigen::Dynamic = options.block_size at run time, default 1 = point ILU(k)); sizes that
// are not a multiple of the block size are padded (block_sparse_matrix.hpp). The symbolic
// BILU phase is redone only when the sparsity pattern changes, so a Newton loop pays it once.
// A solve that does not reach the tolerance throws convergence_error (like direct_solver
// throws on a singular matrix); last_report() gives the iteration history either way.
// Options are validated at construction. A factorisation that fails (singular pivot block,
// non-finite entries) throws singular_matrix_error from compute() / precondition_with() and
// leaves the solver refusing solve() (singular_matrix_error) until a factorisation succeeds.
#include <string>

#include "block_ilu.hpp"
#include "block_sparse_matrix.hpp"
#include "bordered_block_matrix.hpp"
#include "krylov.hpp"

namespace aerohopf {

enum class krylov_method { gmres, gcr, tfqmr, bicgstab };

struct krylov_solver_options {
  krylov_method method = krylov_method::gmres;
  Eigen::Index block_size = 1;  ///< used when B == Eigen::Dynamic
  int fill_level = 1;           ///< k of BILU(k)
  bool reorder_rcm = false;
  krylov_options krylov{};      ///< tolerances, restart, max iterations
};

/// Runs the chosen method.
template <class S, class Op, class Pre>
krylov_report krylov_solve(krylov_method method, const Op& a, const Pre& m, const vec<S>& b, vec<S>& x,
                           const krylov_options& opt) {
  switch (method) {
    case krylov_method::gcr: return gcr(a, m, b, x, opt);
    case krylov_method::tfqmr: return tfqmr(a, m, b, x, opt);
    case krylov_method::bicgstab: return bicgstab(a, m, b, x, opt);
    default: return gmres(a, m, b, x, opt);
  }
}

namespace internal {
/// Validates a Krylov solver's options (input_error naming context), gives its Krylov method the
/// context, and returns the options of its BILU(k).
inline block_ilu_options prepare_krylov_solver(krylov_solver_options& opt, const std::string& context) {
  validate_krylov_options(opt.krylov, context);
  opt.krylov.context = context;
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.reorder_rcm = opt.reorder_rcm;
  io.context = context + " BILU(" + std::to_string(opt.fill_level) + ")";
  return io;
}

/// Runs factorise(); if it fails, records why in `failure` (solve() then refuses) and rethrows,
/// non-finite matrix entries (input_error) as singular_matrix_error like direct_solver.
template <class Factorise>
void factor_recording_failure(Factorise&& factorise, std::string& failure) {
  failure.clear();
  try {
    factorise();
  } catch (const input_error& e) {
    failure = e.what();
    throw singular_matrix_error(e.what());
  } catch (const error& e) {
    failure = e.what();
    throw;
  }
}

/// x = A^{-1} b column by column by `method` (zero initial guess, convergence_error on failure)
/// on vectors of the operator's `size` entries (>= the n = b.rows() logical ones, zero padding);
/// refuses after a failed factorisation or before compute(). report: the last column's.
template <class S, class Op, class Pre, class Rhs>
Eigen::Matrix<S, Eigen::Dynamic, Rhs::ColsAtCompileTime> solve_columns(
    const Op& a, const Pre& m, Eigen::Index size, Eigen::Index n, const Eigen::MatrixBase<Rhs>& b,
    krylov_method method, krylov_options o, const std::string& failure, bool computed, const std::string& context,
    krylov_report& report) {
  if (!failure.empty())
    throw singular_matrix_error(concat(context, ": solve() refused: the last factorisation failed (", failure, ")"));
  require(computed, context, ": solve() before compute()");
  require(b.rows() == n, context, ": right-hand side has ", b.rows(), " rows, matrix ", n);
  Eigen::Matrix<S, Eigen::Dynamic, Rhs::ColsAtCompileTime> x(n, b.cols());
  o.throw_on_failure = true;
  vec<S> bp = vec<S>::Zero(size), xp(size);
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    bp.head(n) = b.col(c).template cast<S>();
    xp.setZero();
    report = krylov_solve(method, a, m, bp, xp, o);
    x.col(c) = xp.head(n);
  }
  return x;
}
}  // namespace internal

template <class Matrix, int B = Eigen::Dynamic>
class krylov_solver {
 public:
  using scalar = typename Matrix::Scalar;
  using block_matrix = block_sparse_matrix<scalar, B>;

  explicit krylov_solver(krylov_solver_options options = {}, std::string context = "BILU-Krylov")
      : opt_(std::move(options)), context_(std::move(context)) {
    if (B != Eigen::Dynamic) opt_.block_size = B;
    require(opt_.block_size > 0, context_, ": block size ", opt_.block_size, " <= 0");
    ilu_ = block_ilu<scalar, B>(internal::prepare_krylov_solver(opt_, context_));
  }

  krylov_solver& compute(const Matrix& a) {
    require(a.rows() == a.cols(), context_, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
    block_matrix blocks = to_blocks(a);
    if (own_preconditioner_)
      require(ilu_.rows() == blocks.rows(), context_, ": preconditioner matrix (precondition_with) has ", ilu_.rows(),
              " rows, operator ", blocks.rows());
    computed_ = false;  // until the factorisation below has succeeded
    a_ = std::move(blocks);
    n_ = a.rows();
    if (!own_preconditioner_) factor(a_);
    computed_ = true;
    return *this;
  }

  /// Use BILU(k) of m instead of the operator's own for every later compute(): a cheaper or
  /// better-conditioned approximation (the modified-order Jacobian for the exact one, spec 07)
  /// while the Krylov method keeps the exact operator, so the solution is that of the operator.
  krylov_solver& precondition_with(const Matrix& m) {
    require(m.rows() == m.cols(), context_, ": preconditioner matrix is ", m.rows(), "x", m.cols(), ", not square");
    factor(to_blocks(m));
    own_preconditioner_ = true;
    return *this;
  }

  /// Solves A x = b column by column (zero initial guess); throws convergence_error on failure.
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    return internal::solve_columns<scalar>(a_, ilu_, a_.rows(), n_, b, opt_.method, opt_.krylov, failure_, computed_,
                                           context_, report_);
  }

  Eigen::Index rows() const { return n_; }
  const krylov_report& last_report() const { return report_; }
  const block_matrix& blocked_matrix() const { return a_; }
  const block_ilu<scalar, B>& preconditioner() const { return ilu_; }

 private:
  block_matrix to_blocks(const Matrix& a) const {
    if constexpr (is_sparse_matrix_v<Matrix>) return block_matrix::from_sparse(a, opt_.block_size);
    else return block_matrix::from_sparse(a.sparseView(), opt_.block_size);
  }
  /// BILU(k) of m; on failure records why (solve() refuses until a factorisation succeeds).
  void factor(const block_matrix& m) {
    internal::factor_recording_failure([&] { ilu_.compute(m); }, failure_);
  }

  krylov_solver_options opt_;
  std::string context_;
  block_matrix a_{B == Eigen::Dynamic ? opt_.block_size : Eigen::Index(B)};
  block_ilu<scalar, B> ilu_;
  Eigen::Index n_ = 0;
  bool own_preconditioner_ = false;
  bool computed_ = false;   // a_ holds the operator of the last successful compute()
  std::string failure_;     // why the last factorisation failed ("" if it succeeded)
  mutable krylov_report report_;
};

/// The compute/solve interface of krylov_solver for an Eigen sparse matrix in the bordered form
/// (bordered_from_sparse: flow blocks of B and a dense border of the last border_size unknowns,
/// no padding), preconditioned by bordered_block_ilu (BILU(k) of the flow part, the border
/// eliminated exactly): the route for aeroelastic systems, whose structure is no flow block.
/// A failed factorisation throws singular_matrix_error (non-finite entries included, as
/// krylov_solver), and solve() refuses until one succeeds.
template <class Matrix, int B>
  requires is_sparse_matrix_v<Matrix>
class bordered_krylov_solver {
 public:
  using scalar = typename Matrix::Scalar;
  using bordered_matrix = bordered_block_matrix<scalar, B>;

  explicit bordered_krylov_solver(Eigen::Index border_size, krylov_solver_options options = {},
                                  std::string context = "bordered BILU-Krylov")
      : opt_(std::move(options)), context_(std::move(context)), border_(border_size) {
    require(border_ >= 0, context_, ": border size ", border_, " < 0");
    ilu_ = bordered_block_ilu<scalar, B>(internal::prepare_krylov_solver(opt_, context_));
  }

  bordered_krylov_solver& compute(const Matrix& a) {
    bordered_matrix m = bordered_from_sparse<B>(a, border_, context_);
    if (own_preconditioner_)
      require(ilu_.rows() == m.rows(), context_, ": preconditioner matrix (precondition_with) has ", ilu_.rows(),
              " rows, operator ", m.rows());
    computed_ = false;
    a_ = std::move(m);
    if (!own_preconditioner_) factor(a_, scalar(0.0));
    computed_ = true;
    return *this;
  }

  /// M from the bordered BILU of m - sigma I for every later compute() (e.g. the modified-order
  /// Jacobian for the exact one), while the Krylov method keeps the exact operator.
  template <class T>
  bordered_krylov_solver& precondition_with(const bordered_block_matrix<T, B>& m, scalar sigma = scalar(0.0)) {
    factor(m, sigma);
    own_preconditioner_ = true;
    return *this;
  }

  /// Solves A x = b column by column (zero initial guess); throws convergence_error on failure.
  template <class Rhs>
  auto solve(const Eigen::MatrixBase<Rhs>& b) const {
    return internal::solve_columns<scalar>(a_, ilu_, a_.rows(), a_.rows(), b, opt_.method, opt_.krylov, failure_,
                                           computed_, context_, report_);
  }

  Eigen::Index rows() const { return a_.rows(); }
  const krylov_report& last_report() const { return report_; }
  const bordered_matrix& bordered_operator_matrix() const { return a_; }
  const bordered_block_ilu<scalar, B>& preconditioner() const { return ilu_; }

 private:
  template <class T>
  void factor(const bordered_block_matrix<T, B>& m, scalar sigma) {
    internal::factor_recording_failure([&] { ilu_.compute(m, sigma); }, failure_);
  }

  krylov_solver_options opt_;
  std::string context_;
  Eigen::Index border_;
  bordered_matrix a_;
  bordered_block_ilu<scalar, B> ilu_;
  bool own_preconditioner_ = false;
  bool computed_ = false;
  std::string failure_;
  mutable krylov_report report_;
};

}  // namespace aerohopf
