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
// A model whose structure is not one block (a modal wing: 5 x 5 flow blocks, 2m structural
// unknowns) declares the BORDERED form instead (bordered_system), or besides (the aerofoil):
//   static constexpr int block_size;                               // B > 0
//   bordered_jacobian_pair<block_size> bordered_jacobians(const vec<double>& w, double mu) const;
//       // flow part in blocks of B (whole cells, no padding) + dense border of the structural
//       // unknowns, any number of them (linalg/bordered_block_matrix.hpp); both of size()
//   bordered_block_matrix<double, block_size> bordered_jacobian(w, mu) const;   // optional: exact alone
//
// The Krylov algorithms take every system through ONE form, the bordered one: krylov_jacobians<B>
// and krylov_exact_jacobian<B> return the model's bordered matrices, or view the others as
// bordered: a padded block_system's matrices and a plain dynamical_system's Eigen sparse ones
// are split into whole blocks of B and a border of the last krylov_border_size<B>(sys) unknowns
// (the structure of an aeroelastic_system plus what of its flow part does not fill a block;
// otherwise the last 1..B unknowns, where the padded convention keeps what is not a flow cell).
// So a system reaches the same matrices through any of its interfaces, and the border is
// eliminated exactly around the BILU of the flow part (bordered_block_ilu).
//
// The block size is part of the type: an algorithm written for blocks of B states it with
// block_system_of<S, B> (a constraint) or require_block_size<B, S>() (a static_assert with a
// message), so a model of another block size is a compile-time error, never a silent
// conversion of its matrices.
#include <Eigen/Core>

#include <concepts>
#include <string>
#include <type_traits>
#include <utility>

#include "../error.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "aeroelastic_system.hpp"
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

/// The exact Jacobian and the preconditioning matrix in the bordered form, at one (w, mu).
template <int B>
struct bordered_jacobian_pair {
  static_assert(B > 0, "bordered_jacobian_pair: the block size must be a positive compile-time constant");
  bordered_block_matrix<double, B> exact;
  bordered_block_matrix<double, B> preconditioning;
};

/// A model that assembles its Jacobians as flow blocks + a dense structural border (file comment).
template <class S>
concept bordered_system = dynamical_system<S> && internal::declares_block_size<S> &&
                          requires(const S& s, const vec<double>& w, double mu) {
                            { s.bordered_jacobians(w, mu) } -> std::same_as<bordered_jacobian_pair<S::block_size>>;
                          };

/// Optional member of a bordered_system: bordered_jacobian(w, mu), the exact matrix alone.
template <class S>
concept has_exact_bordered_jacobian = bordered_system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.bordered_jacobian(w, mu) } -> std::same_as<bordered_block_matrix<double, S::block_size>>;
};

/// A block_system or bordered_system whose block size is B: the constraint of an algorithm
/// written for blocks of B.
template <class S, int B>
concept block_system_of = (block_system<S> || bordered_system<S>) && (S::block_size == B);

template <class S>
  requires block_system<S> || bordered_system<S>
inline constexpr int block_size_of = S::block_size;

/// Compile-time check of an algorithm's block size against the model's: instantiating it with
/// a model that is no block_system (nor bordered_system), or has another block size, stops the
/// build with this message (the caller's B and the model's are in the instantiation trace).
template <int B, class S>
constexpr void require_block_size() {
  static_assert(B > 0, "require_block_size: the algorithm's block size B must be positive");
  if constexpr (!block_system<S> && !bordered_system<S>) {
    static_assert(block_system<S> || bordered_system<S>,
                  "require_block_size: the model is not a block_system (static constexpr int block_size and "
                  "jacobians(w, mu) returning block_jacobian_pair<block_size>) nor a bordered_system "
                  "(bordered_jacobians(w, mu) returning bordered_jacobian_pair<block_size>)");
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

namespace internal {
inline void check_bordered_jacobian_size(const auto& m, Eigen::Index n, const char* which, const std::string& who) {
  require(m.rows() == n, who, ": ", which, " bordered Jacobian is ", m.rows(), "x", m.cols(), " (", m.flow_size(),
          " flow + ", m.structure_size(), " structural unknowns), system has ", n, " unknowns");
}
}  // namespace internal

/// The border the Krylov path gives sys (file comment): for a model's own bordered form, its
/// structure_size() is what it should return; for the views of the other forms, the last
/// n - B floor(flow_size() / B) unknowns of an aeroelastic_system, else the last 1..B unknowns
/// (0 of an empty system).
template <int B, dynamical_system S>
Eigen::Index krylov_border_size(const S& sys) {
  static_assert(B > 0, "krylov_border_size: the block size B must be positive");
  const Eigen::Index n = sys.size();
  if constexpr (aeroelastic_system<S>) {
    check_aeroelastic_layout(sys, "krylov_border_size");
    return n - B * (sys.flow_size() / B);
  } else {
    return n == 0 ? 0 : n - B * ((n - 1) / B);
  }
}

/// The exact and preconditioning Jacobians of sys at (w, mu) in the bordered form with flow
/// blocks of B (file comment): a bordered_system's own (checked against size()), else the
/// padded block_system's pair or the Eigen sparse jacobian / lhs_jacobian split at
/// krylov_border_size<B>(sys). A model of another block size is a compile-time error. who names
/// the caller in the messages.
template <int B, dynamical_system S>
bordered_jacobian_pair<B> krylov_jacobians(const S& sys, const vec<double>& w, double mu, const std::string& who) {
  if constexpr (bordered_system<S>) {
    require_block_size<B, S>();
    bordered_jacobian_pair<B> p = sys.bordered_jacobians(w, mu);
    internal::check_bordered_jacobian_size(p.exact, sys.size(), "exact", who);
    internal::check_bordered_jacobian_size(p.preconditioning, sys.size(), "preconditioning", who);
    return p;
  } else if constexpr (block_system<S>) {
    require_block_size<B, S>();
    const Eigen::Index k = krylov_border_size<B>(sys);
    block_jacobian_pair<B> p = checked_jacobians(sys, w, mu, who);
    return {bordered_from_padded(p.exact, k, who), bordered_from_padded(p.preconditioning, k, who)};
  } else {
    static_assert(is_sparse_matrix_v<jacobian_t<S>>,
                  "krylov_jacobians: a system without block Jacobians needs Eigen sparse ones (jacobian_type)");
    const Eigen::Index k = krylov_border_size<B>(sys);
    return {bordered_from_sparse<B>(sys.jacobian(w, mu), k, who), bordered_from_sparse<B>(lhs_jacobian(sys, w, mu), k, who)};
  }
}

/// The exact matrix of krylov_jacobians alone: the model's bordered_jacobian or
/// block_jacobian where it has one (saving the preconditioning matrix's assembly).
template <int B, dynamical_system S>
bordered_block_matrix<double, B> krylov_exact_jacobian(const S& sys, const vec<double>& w, double mu,
                                                       const std::string& who) {
  if constexpr (has_exact_bordered_jacobian<S>) {
    require_block_size<B, S>();
    bordered_block_matrix<double, B> a = sys.bordered_jacobian(w, mu);
    internal::check_bordered_jacobian_size(a, sys.size(), "exact", who);
    return a;
  } else if constexpr (bordered_system<S>) {
    return krylov_jacobians<B>(sys, w, mu, who).exact;
  } else if constexpr (block_system<S>) {
    require_block_size<B, S>();
    return bordered_from_padded(checked_exact_jacobian(sys, w, mu, who), krylov_border_size<B>(sys), who);
  } else {
    static_assert(is_sparse_matrix_v<jacobian_t<S>>,
                  "krylov_exact_jacobian: a system without block Jacobians needs Eigen sparse ones (jacobian_type)");
    return bordered_from_sparse<B>(sys.jacobian(w, mu), krylov_border_size<B>(sys), who);
  }
}

}  // namespace aerohopf
