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
#include <Eigen/Core>

#include <complex>
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

/// y = op(x); y must already have the operator's size.
template <class S, class Op>
  requires linear_operator<Op, S>
void apply_operator(const Op& op, const vec<S>& x, vec<S>& y) {
  if constexpr (member_apply_operator<Op, S>) op.apply(x, y);
  else if constexpr (callable_operator<Op, S>) op(x, y);
  else y.noalias() = op * x;
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
    y -= sigma_ * x;
  }

 private:
  const Op* a_;
  S sigma_;
};

}  // namespace aerohopf
