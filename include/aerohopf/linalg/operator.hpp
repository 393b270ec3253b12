#pragma once
// Linear operators and preconditioners as concepts, so that one Krylov implementation serves
// an assembled block-sparse matrix, an Eigen matrix, a matrix-free Jacobian-vector product
// (a lambda), a shifted operator A - sigma I and a bordered Hopf operator alike.
//
// An operator on vectors of scalar S is anything that can compute y = A x for
// vec<S> x, y of the operator's size, in one of these spellings (tried in this order):
//   op.apply(x, y);          // member, y already sized; our own classes use this
//   op(x, y);                // a callable, e.g. [&](const vec<S>& x, vec<S>& y) { ... }
//   y = op * x;              // an Eigen dense or sparse matrix (never treated as callable)
// A preconditioner is the same thing for z = M^{-1} r (identity_preconditioner, block_ilu,
// bordered_preconditioner). The Krylov methods only ever call apply_operator().
//
// Sizes: an operator that knows its size (rows(), and cols() where it has them: Eigen matrices,
// block_sparse_matrix, block_ilu, bordered operators) is checked against the vectors once per
// call (require_operator_size at the Krylov entry; apply_operator for Eigen products, whose
// own assertions are off in Release builds). A lambda cannot be asked: the Krylov methods
// check the size of what it returns instead.
#include <Eigen/Core>

#include <complex>
#include <concepts>
#include <string_view>
#include <type_traits>
#include <utility>

#include "../error.hpp"
#include "../scalar/complex.hpp"
#include "direct.hpp"

namespace aerohopf {

template <class Op, class S>
concept member_apply_operator = requires(const Op& op, const vec<S>& x, vec<S>& y) { op.apply(x, y); };

// Eigen matrices are excluded from the callable spelling: op(x, y) would compile as Eigen 3.4
// slicing (an indexed view), not as a product.
template <class Op>
inline constexpr bool is_eigen_object_v = std::is_base_of_v<Eigen::EigenBase<Op>, Op>;

template <class Op, class S>
concept callable_operator =
    !is_eigen_object_v<Op> && requires(const Op& op, const vec<S>& x, vec<S>& y) { op(x, y); };

template <class Op, class S>
concept product_operator = requires(const Op& op, const vec<S>& x, vec<S>& y) { y = op * x; };

/// Anything that maps vec<S> to vec<S> linearly in one of the three spellings above.
template <class Op, class S>
concept linear_operator = member_apply_operator<Op, S> || callable_operator<Op, S> || product_operator<Op, S>;

/// Operators that report their size.
template <class Op>
concept sized_rows = requires(const Op& op) {
  { op.rows() } -> std::convertible_to<Eigen::Index>;
};
template <class Op>
concept sized_cols = requires(const Op& op) {
  { op.cols() } -> std::convertible_to<Eigen::Index>;
};

/// An operator on a vector distributed over processes (distributed/mpi_euler.hpp): each process
/// holds its part, and op.global_sum(p, n) replaces the n partial sums at p by their sums over
/// all processes (MPI_Allreduce). The Krylov methods form every inner product and norm through
/// it, so their iterates are the same on every process.
template <class Op, class S>
concept distributed_operator = requires(const Op& op, S* p, int n) { op.global_sum(p, n); };

/// Throws input_error unless op (where it reports its size) maps vectors of n entries to
/// vectors of n entries: "<where>: <what> (rows) has .. entries, expected n". No-op for an
/// operator that does not know its size (a lambda, identity_preconditioner).
template <class Op>
void require_operator_size(const Op& op, Eigen::Index n, std::string_view where, std::string_view what) {
  if constexpr (sized_rows<Op>) {
    const Eigen::Index r = op.rows();
    if (r != n) require_size(r, n, where, internal::concat(what, " (rows)"));
  }
  if constexpr (sized_cols<Op>) {
    const Eigen::Index c = op.cols();
    if (c != n) require_size(c, n, where, internal::concat(what, " (columns)"));
  }
}

/// y = op(x); y must already have the operator's size. An Eigen product checks x against the
/// matrix's columns (one comparison per call) and sizes y to its rows.
template <class S, class Op>
  requires linear_operator<Op, S>
void apply_operator(const Op& op, const vec<S>& x, vec<S>& y) {
  if constexpr (member_apply_operator<Op, S>) {
    op.apply(x, y);
  } else if constexpr (callable_operator<Op, S>) {
    op(x, y);
  } else {
    if constexpr (sized_cols<Op>) {
      if (op.cols() != x.size()) require_size(x.size(), op.cols(), "apply_operator", "x (matrix columns)");
    }
    y.noalias() = op * x;
  }
}

/// M = I: the "no preconditioning" case.
struct identity_preconditioner {
  template <class S>
  void apply(const vec<S>& r, vec<S>& z) const { z = r; }
};

/// A - sigma I for any operator A (matrix-free shift; the assembled form is shifted() in
/// block_sparse_matrix.hpp). sigma = i omega gives the complex inverse-power/Hopf operator.
template <class Op, class S>
class shifted_operator {
 public:
  shifted_operator(const Op& a, S sigma) : a_(&a), sigma_(sigma) {}
  void apply(const vec<S>& x, vec<S>& y) const {
    apply_operator<S>(*a_, x, y);
    if (y.size() != x.size()) require_size(y.size(), x.size(), "shifted_operator::apply", "A x");
    y -= sigma_ * x;
  }
  Eigen::Index rows() const
    requires sized_rows<Op>
  {
    return a_->rows();
  }
  Eigen::Index cols() const
    requires sized_cols<Op>
  {
    return a_->cols();
  }

 private:
  const Op* a_;
  S sigma_;
};

}  // namespace aerohopf
