#pragma once
// block_system: a dynamical_system (system.hpp) that assembles its Jacobians directly as block
// sparse matrices, the form the Krylov path (BILU(k) + GMRES) works in.
//
// Why a concept of its own: a CFD model's natural matrix is blocks of its unknowns per cell
// (4 in 2D, 5 in 3D). Going through Eigen::SparseMatrix (triplets, sort, re-blocking) costs
// about as much as the assembly itself, and the exact and the preconditioning (modified-order)
// matrices share most of their work (coupling blocks, pattern). So the model returns both at
// once, like PETSc's Amat/Pmat, and the algorithms never need an Eigen sparse copy.
//
// A model provides, besides dynamical_system:
//   static constexpr int block_size;                               // B > 0
//   block_jacobian_pair<block_size> jacobians(const vec<double>& w, double mu) const;
//       // exact:          A = f_w, the matrix whose action is differentiated (Newton, Hopf)
//       // preconditioning: the left-hand-side matrix a preconditioner is built from (e.g. the
//       //                  modified-order CFD Jacobian; the exact one again if there is none)
//       // both padded to a multiple of B rows, logical size size() (block_sparse_matrix.hpp).
//
// The block size is part of the type: an algorithm written for blocks of B states it with
// block_system_of<S, B> (a constraint) or require_block_size<B, S>() (a static_assert with a
// message), so a model of another block size is a compile-time error, never a silent
// conversion of its matrices.
#include <Eigen/Core>

#include <concepts>
#include <string>
#include <type_traits>

#include "../error.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "system.hpp"

namespace aerohopf {

/// The exact Jacobian and the matrix a preconditioner is built from, at one (w, mu).
template <int B>
struct block_jacobian_pair {
  static_assert(B > 0, "block_jacobian_pair: the block size must be a positive compile-time constant");
  block_sparse_matrix<double, B> exact;
  block_sparse_matrix<double, B> preconditioning;
};

namespace internal {
/// S declares a positive compile-time block size (a constant expression, not a run-time member).
template <class S>
concept declares_block_size = requires {
  typename std::integral_constant<int, S::block_size>;
} && (S::block_size > 0);
}  // namespace internal

template <class S>
concept block_system = dynamical_system<S> && internal::declares_block_size<S> &&
                       requires(const S& s, const vec<double>& w, double mu) {
                         { s.jacobians(w, mu) } -> std::same_as<block_jacobian_pair<S::block_size>>;
                       };

/// A block_system whose block size is B: the constraint of an algorithm written for blocks of B.
template <class S, int B>
concept block_system_of = block_system<S> && (S::block_size == B);

template <block_system S>
inline constexpr int block_size_of = S::block_size;

/// Compile-time check of an algorithm's block size against the model's: instantiating it with
/// a model that is no block_system, or has another block size, stops the build with this
/// message (the caller's B and the model's are in the instantiation trace).
template <int B, class S>
constexpr void require_block_size() {
  static_assert(B > 0, "require_block_size: the algorithm's block size B must be positive");
  if constexpr (!block_system<S>) {
    static_assert(block_system<S>,
                  "require_block_size: the model is not a block_system (static constexpr int block_size and "
                  "jacobians(w, mu) returning block_jacobian_pair<block_size>)");
  } else {
    static_assert(S::block_size == B,
                  "require_block_size: the model's block_size differs from the block size B the algorithm was "
                  "instantiated with (choose B = block_size_of<S>)");
  }
}

/// Optional member of a block_system: block_jacobian(w, mu), the exact matrix alone, for callers
/// that need no preconditioning matrix (e.g. one built from the exact Jacobian), saving its assembly.
template <class S>
concept has_exact_block_jacobian = block_system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.block_jacobian(w, mu) } -> std::same_as<block_sparse_matrix<double, S::block_size>>;
};

namespace internal {
template <int B>
void check_block_jacobian_size(const block_sparse_matrix<double, B>& m, Eigen::Index n, const char* which,
                               const std::string& who) {
  const Eigen::Index padded = padded_block_count(n, B) * B;
  require(m.rows() == padded && m.cols() == padded && m.logical_rows() == n && m.logical_cols() == n, who, ": ", which,
          " block Jacobian is ", m.logical_rows(), "x", m.logical_cols(), " (padded ", m.rows(), "x", m.cols(),
          "), system has ", n, " unknowns (padded ", padded, ")");
}
}  // namespace internal

/// The model's pair at (w, mu), checked: both matrices square with the padded size of the system
/// and logical size size() (a model's own assembly is plain data; a wrong size would otherwise
/// surface as an out-of-range access in the Krylov solver). who names the caller in the message.
template <block_system S>
block_jacobian_pair<S::block_size> checked_jacobians(const S& sys, const vec<double>& w, double mu,
                                                     const std::string& who) {
  block_jacobian_pair<S::block_size> p = sys.jacobians(w, mu);
  internal::check_block_jacobian_size(p.exact, sys.size(), "exact", who);
  internal::check_block_jacobian_size(p.preconditioning, sys.size(), "preconditioning", who);
  return p;
}

/// The exact matrix alone, checked like checked_jacobians: block_jacobian(w, mu) if the model
/// has it (has_exact_block_jacobian), else jacobians(w, mu).exact.
template <block_system S>
block_sparse_matrix<double, S::block_size> checked_exact_jacobian(const S& sys, const vec<double>& w, double mu,
                                                                  const std::string& who) {
  if constexpr (has_exact_block_jacobian<S>) {
    block_sparse_matrix<double, S::block_size> a = sys.block_jacobian(w, mu);
    internal::check_block_jacobian_size(a, sys.size(), "exact", who);
    return a;
  } else {
    return checked_jacobians(sys, w, mu, who).exact;
  }
}

}  // namespace aerohopf
