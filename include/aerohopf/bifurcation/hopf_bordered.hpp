#pragma once
// The bordered linear strategies of the Hopf Newton driver (hopf.hpp: hopf_problem, hopf_newton),
// so that the only linear systems are n x n ones with the sparsity of A: complex ones with
// A - i omega I (or the left-hand-side matrix L - i omega I) and, in the full formulation, real
// ones with A for the flow update, which a BILU(k)-Krylov solver handles (the original scheme of
// the flutter method) instead of a sparse LU of the real (2n+2) or (3n+2) system, whose fill grows
// too fast for CFD grids.
//
// In the notation of spec 02 the eigen-equations are G(p, mu, omega) = (A(mu) - i omega I) p = 0
// with p = p_r + i p_i and the normalisation s^T p = i (s real, fixed). G is always evaluated
// exactly and matrix-free (jacobian_product_pair: A p_r and A p_i in one jet pass through the
// templated residual), so the converged point is the exact Hopf point whatever L and the linear
// tolerance are; they change only the rate of convergence.
//
//  * bordered_hopf_step: the block elimination of the border unknowns (and of the flow update in
//    the full formulation), written once against a strategy that solves with A (real) and with
//    the bordered A - i omega I (complex);
//  * hopf_bordered_direct: those solves by a complex solver of L - i omega I (sparse LU, or a
//    Krylov solver) and the real LU of L;
//  * hopf_bordered_krylov: those solves by GMRES on the exact matrices, preconditioned by BILU(k)
//    of the modified-order L (bordered for the eigen-equations);
//  * solve_hopf_bordered, solve_hopf_krylov: hopf_newton with one of them; hopf_start_krylov:
//    the inverse-power start at CFD sizes.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <complex>
#include <iomanip>
#include <string>
#include <tuple>
#include <utility>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/block_sparse_matrix.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "../linalg/direct.hpp"
#include "../linalg/krylov.hpp"
#include "../linalg/operator.hpp"
#include "../nonlinear/block_system.hpp"
#include "../nonlinear/newton.hpp"
#include "../nonlinear/system.hpp"
#include "../scalar/jet.hpp"
#include "../scalar/taylor.hpp"
#include "hopf.hpp"

namespace aerohopf {

namespace internal {

/// The real split form of (A + dmu A_mu) - i omega I acting on v = [x_re; x_im] (n each):
///   r = [(A + dmu A_mu) x_re + omega x_im;  (A + dmu A_mu) x_im - omega x_re].
/// A is a block matrix, bordered (rows() == n) or padded (rows() >= n, padding zero); A_mu (any
/// matrix with a product) is used only when dmu != 0. The inner operator of every bordered
/// Krylov Hopf solve.
/// For a real block_sparse_matrix A the shifted product is one fused pass over A on the complex
/// vector x_re + i x_im (block_sparse_matrix::apply_shifted): half the matrix traffic of two real
/// products; other matrix types take the two real products.
template <class BlockMatrix, class Amu = Eigen::SparseMatrix<double>>
struct real_split_shifted_operator {
  using C = std::complex<double>;
  static constexpr bool fused = requires(const BlockMatrix& m, const vec<C>& x, vec<C>& y) {
    m.apply_shifted(C(), x, y);
  };
  const BlockMatrix& a;
  double omega;
  Eigen::Index n;
  const Amu* amu = nullptr;
  double dmu = 0.0;
  mutable vec<double> xin, xout, tmp;
  mutable vec<C> xc, yc;
  real_split_shifted_operator(const BlockMatrix& a_, double omega_, Eigen::Index n_, const Amu* amu_ = nullptr,
                              double dmu_ = 0.0)
      : a(a_), omega(omega_), n(n_), amu(amu_), dmu(dmu_), tmp(n_) {
    if constexpr (fused) {
      xc = vec<C>::Zero(a_.rows());
      yc.resize(a_.rows());
    } else {
      xin = vec<double>::Zero(a_.rows());
      xout.resize(a_.rows());
    }
  }
  void operator()(const vec<double>& v, vec<double>& r) const {
    if constexpr (fused) {
      xc.head(n).real() = v.head(n);
      xc.head(n).imag() = v.tail(n);
      a.apply_shifted(C(0.0, omega), xc, yc);
      r.head(n) = yc.head(n).real();
      r.tail(n) = yc.head(n).imag();
    } else {
      xin.head(n) = v.head(n);
      a.multiply(xin, xout);
      r.head(n) = xout.head(n);
      xin.head(n) = v.tail(n);
      a.multiply(xin, xout);
      r.tail(n) = xout.head(n);
      r.head(n) += omega * v.tail(n);
      r.tail(n) -= omega * v.head(n);
    }
    if (dmu != 0.0 && amu) {
      tmp.noalias() = *amu * v.head(n);
      r.head(n) += dmu * tmp;
      tmp.noalias() = *amu * v.tail(n);
      r.tail(n) += dmu * tmp;
    }
  }
};

/// A complex preconditioner of A - i omega I (apply(rc, zc) on padded complex vectors, e.g. the
/// complex BILU) applied in the real split form [re; im] of real_split_shifted_operator.
template <class ComplexPreconditioner>
struct complex_preconditioner_split_form {
  const ComplexPreconditioner& m;
  Eigen::Index n;
  mutable vec<std::complex<double>> rc, zc;
  complex_preconditioner_split_form(const ComplexPreconditioner& m_, Eigen::Index n_, Eigen::Index padded)
      : m(m_), n(n_), rc(vec<std::complex<double>>::Zero(padded)), zc(padded) {}
  void operator()(const vec<double>& r, vec<double>& z) const {
    rc.head(n).real() = r.head(n);
    rc.head(n).imag() = r.tail(n);
    m.apply(rc, zc);
    z.head(n) = zc.head(n).real();
    z.tail(n) = zc.head(n).imag();
  }
};

}  // namespace internal

/// A system that also assembles its exact and approximate (left-hand-side) Jacobians directly
/// in blocks of block size B (a block_system or bordered_system, e.g. models::aerofoil_system):
/// solve_hopf_krylov then skips the Eigen sparse round trip (triplets, sort, re-blocking), about
/// half of the assembly time on the NACA 0012 grids.
template <class S, int B>
concept has_block_jacobians = block_system_of<S, B>;

namespace internal {
/// The exact Jacobian of sys at (w, mu) as ONE padded block matrix of B (logical size n), the
/// form the fixed-equilibrium Hopf-curve tracer works in (the Krylov strategies of this header
/// take the bordered form, krylov_jacobians): the block_system's own assembly
/// (checked_exact_jacobian; its block size must be B), else from_sparse.
template <int B, dynamical_system S>
block_sparse_matrix<double, B> exact_blocks(const S& sys, const vec<double>& w, double mu, const std::string& who) {
  if constexpr (block_system<S>) {
    require_block_size<B, S>();
    return checked_exact_jacobian(sys, w, mu, who);
  } else {
    return block_sparse_matrix<double, B>::from_sparse(sys.jacobian(w, mu), B);
  }
}
/// (exact Jacobian, lhs_jacobian) in blocks of B, from one block_jacobians call when the system
/// has it (shared coupling blocks), else two from_sparse conversions.
template <int B, dynamical_system S>
std::pair<block_sparse_matrix<double, B>, block_sparse_matrix<double, B>> exact_and_lhs_blocks(
    const S& sys, const vec<double>& w, double mu, const std::string& who) {
  if constexpr (block_system<S>) {
    require_block_size<B, S>();
    auto p = checked_jacobians(sys, w, mu, who);
    return {std::move(p.exact), std::move(p.preconditioning)};
  } else {
    return {block_sparse_matrix<double, B>::from_sparse(sys.jacobian(w, mu), B),
            block_sparse_matrix<double, B>::from_sparse(lhs_jacobian(sys, w, mu), B)};
  }
}
/// The Krylov matrices of sys at (w, mu) in the bordered form: the exact A and, unless A itself
/// preconditions (precondition_exact; l is then left empty), the preconditioning matrix L.
template <int B, dynamical_system S>
void krylov_matrices(const S& sys, const vec<double>& w, double mu, bool precondition_exact, const std::string& who,
                     bordered_block_matrix<double, B>& a, bordered_block_matrix<double, B>& l) {
  if (precondition_exact) {
    a = krylov_exact_jacobian<B>(sys, w, mu, who);
    return;
  }
  bordered_jacobian_pair<B> p = krylov_jacobians<B>(sys, w, mu, who);
  a = std::move(p.exact);
  l = std::move(p.preconditioning);
}
}  // namespace internal

struct hopf_krylov_options {
  int fill_level = 0;               ///< k of the complex BILU(k) of L - i omega I
  /// The BILU factors in single precision (block_ilu_options::single_precision_factors): half
  /// the bytes per GMRES iteration in the preconditioner's sweeps and half its memory, the same
  /// Newton and GMRES iterations (measured on the AGARD 445.6 coarse grid, four Mach numbers:
  /// GMRES time -25 to -30 %, mu* unchanged to 1e-10).
  bool single_precision_factors = true;
  krylov_options krylov = [] {
    krylov_options o = newton_correction_krylov_options();
    o.relative_tolerance = 1e-6;    ///< of each Newton correction, unless adaptive (below)
    // Gram-Schmidt once: the corrections are solved only to eta_k <= 1e-2 and the Newton residual
    // is exact, so the second pass over the basis buys nothing (measured on the NACA 0012 medium
    // grid, heavy case, M 0.55-0.75: identical GMRES and Newton counts, GMRES time -12 to -20 %)
    o.reorthogonalize = false;
    return o;
  }();
  /// Inexact Newton forcing: relative GMRES tolerance eta_k = min(eta_max, ||F_k||), but no
  /// tighter than needed to land below the Newton tolerance, 0.1 abs_tolerance / ||F_k||; keeps
  /// quadratic convergence (eta_k = O(||F_k||)) without over-solving the first and last steps.
  bool adaptive_tolerance = true;
  double eta_max = 1e-2;
  double forcing_exponent = 1.0;     ///< eta_k = ||F_k||^e: 1 quadratic, 0.5 order 1.5 with cheaper solves
  bool precondition_exact = false;   ///< BILU(k) of the exact A - i omega I instead of the modified-order one
  /// Assemble A, L and A_mu once, at the start (mu0, omega0), and use A0 + (mu - mu0) A_mu0 as
  /// the GMRES operator and the BILU of L0 - i omega0 I as the preconditioner at every Newton
  /// iteration. The residual stays exact, so the converged point does not change; the operator
  /// error is O((mu - mu0)^2) (zero when A is affine in mu), which keeps superlinear
  /// convergence from a good start (continuation) and saves the assembly and factorisation
  /// per iteration. Off: everything re-assembled at every iterate.
  bool reuse_matrices = true;
  /// ... but re-assembled once |mu - mu0| > reuse_window (1 + |mu0|) or a Newton step reduced
  /// ||F|| by less than a factor 10 (far start, e.g. a large continuation step).
  double reuse_window = 2e-3;
  /// Inverse iterations on the guess's eigenvector before Newton (0: none). A continuation
  /// guess carries the previous Mach number's eigenvector; where shocks move, its Hopf residual
  /// is O(10) and the first Newton steps wander (measured: 8-10 iterations, or divergence, past
  /// M = 0.85 on the NACA 0012). Each start iteration solves (A - i omega I) y = p with the
  /// Newton operator and preconditioner (GMRES to start_tolerance), p <- y, and takes omega from
  /// the Rayleigh quotient of A. Kept only if it lowers ||F|| at the guess's mu; the report
  /// says whether (hopf_result::start_refined).
  /// A guess already on the eigenvector makes A - i omega I nearly singular on it: GMRES then
  /// cannot reach the tolerance, and start_max_iterations caps each start solve (measured: 35-65
  /// iterations reach 1e-2 on the NACA 0012 medium grid).
  int start_iterations = 0;
  double start_tolerance = 1e-2;
  int start_max_iterations = 100;
  /// Refine only a guess with ||F|| above this (0: always). Measured on the NACA 0012 medium
  /// grid (light case): continued guesses have ||F|| = 3-7 at subsonic Mach numbers, where Newton
  /// needs 3-4 iterations without the refinement and it does not pay, and 37-280 at transonic ones.
  double start_residual_threshold = 0.0;
  /// The FULL Hopf system (3n + 2 unknowns [w, p_r, p_i, mu, omega], the equilibrium moving with
  /// mu: hopf_options::fixed_equilibrium must be false) instead of the fixed-equilibrium one,
  /// solved by eliminating the flow update dw inside the same bordered Krylov solve
  /// (bordered_hopf_step). Matrices and both BILU factorisations are then refreshed at every
  /// Newton iterate (reuse_matrices and reuse_window do not apply: A moves with w), and the start
  /// refinement is not available (start_iterations must be 0).
  bool full_system = false;
  /// Full formulation: the second-derivative products (A_w p) dw exact (eight taylor<double, 2>
  /// passes per Newton step) or, by default, central differences of Jacobian products (four
  /// jet<double, 2> passes, O(h^2); internal::second_derivative_pair). F stays exact either way,
  /// and so does the converged point (measured on the NACA 0012 coarse grid at alpha_0 = 1 deg,
  /// M = 0.5 and 0.8: the same Newton and GMRES counts, 30 % less time per Hopf point).
  bool exact_second_derivatives = false;
};

namespace internal {
/// Throws input_error naming the offending option of solve_hopf_krylov.
inline void check_hopf_krylov_options(const hopf_krylov_options& k, const std::string& where) {
  require(k.fill_level >= 0, where, ": fill_level must be >= 0 (got ", k.fill_level, ")");
  require(k.eta_max > 0 && k.eta_max < 1, where, ": eta_max must lie in (0, 1) (got ", k.eta_max, ")");
  require(std::isfinite(k.forcing_exponent) && k.forcing_exponent > 0, where,
          ": forcing_exponent must be finite and > 0 (got ", k.forcing_exponent, ")");
  require(k.krylov.relative_tolerance >= 0 && k.krylov.relative_tolerance < 1, where,
          ": krylov.relative_tolerance must lie in [0, 1) (got ", k.krylov.relative_tolerance, ")");
  require(k.krylov.max_iterations >= 1 && k.krylov.restart >= 1, where,
          ": krylov.max_iterations and krylov.restart must be >= 1 (got ", k.krylov.max_iterations, ", ",
          k.krylov.restart, ")");
  require(std::isfinite(k.reuse_window) && k.reuse_window >= 0, where,
          ": reuse_window must be finite and >= 0 (got ", k.reuse_window, ")");
  require(k.start_iterations >= 0, where, ": start_iterations must be >= 0 (got ", k.start_iterations, ")");
  require(k.start_tolerance > 0 && k.start_tolerance < 1, where, ": start_tolerance must lie in (0, 1) (got ",
          k.start_tolerance, ")");
  require(k.start_max_iterations >= 1, where, ": start_max_iterations must be >= 1 (got ", k.start_max_iterations,
          ")");
  require(std::isfinite(k.start_residual_threshold) && k.start_residual_threshold >= 0, where,
          ": start_residual_threshold must be finite and >= 0 (got ", k.start_residual_threshold, ")");
}

/// B(u, v) = (A_w u) v = d/de [A(w + e v) u] at e = 0 (the second-derivative product of the full
/// Hopf Jacobian): the system's jacobian_directional if it has one; else exact by polarisation
/// of two taylor<double, 2> residual passes, B(u, v) = |u||v|/4 [B(a + b, a + b) - B(a - b, a - b)]
/// with the unit directions a = u/|u|, b = v/|v|; else central differences of exact
/// Jacobian-vector products, [A(w + h v) u - A(w - h v) u] / 2h (O(h^2), h = eps^(1/3) max(1,
/// ||w||_inf) / ||v||_inf), which changes only the rate of Newton's convergence.
template <dynamical_system S>
vec<double> second_derivative_product(const S& sys, const vec<double>& w, double mu, const vec<double>& u,
                                      const vec<double>& v) {
  using T2 = taylor<double, 2>;
  const double nu = u.norm(), nv = v.norm();
  if (nu == 0 || nv == 0) return vec<double>::Zero(w.size());
  if constexpr (has_jacobian_directional<S>) {
    return vec<double>(jacobian_directional(sys, w, mu, u) * v);
  } else if constexpr (system_over<S, T2>) {
    auto b_vv = [&](const vec<double>& d) {
      vec<T2> wj(w.size());
      for (Eigen::Index i = 0; i < w.size(); ++i) wj[i] = T2::variable(w[i], d[i]);
      const vec<T2> fj = sys.residual(wj, T2(mu));
      vec<double> r(fj.size());
      for (Eigen::Index i = 0; i < fj.size(); ++i) r[i] = 2.0 * fj[i][2];
      return r;
    };
    const vec<double> a = u / nu, b = v / nv;
    return (0.25 * nu * nv) * (b_vv(vec<double>(a + b)) - b_vv(vec<double>(a - b)));
  } else {
    const double h = std::cbrt(Eigen::NumTraits<double>::epsilon()) *
                     std::max(1.0, w.template lpNorm<Eigen::Infinity>()) / v.template lpNorm<Eigen::Infinity>();
    return (jacobian_product(sys, vec<double>(w + h * v), mu, u) - jacobian_product(sys, vec<double>(w - h * v), mu, u)) /
           (2 * h);
  }
}

/// The pair (B(p_r, x), B(p_i, x)) of the full Newton step. exact: second_derivative_product
/// twice; else central differences of the Jacobian products along x, [A(w + h x) - A(w - h x)]
/// [p_r, p_i] / 2h with h = eps^(1/3) max(1, ||w||_inf) / ||x||_inf: one jet<double, 2> residual
/// pass per side when the residual takes jets (about a quarter of the cost of the four taylor<
/// double, 2> passes), O(h^2) accurate, which changes only the rate of Newton's convergence.
template <dynamical_system S>
std::pair<vec<double>, vec<double>> second_derivative_pair(const S& sys, const vec<double>& w, double mu,
                                                          const vec<double>& pr, const vec<double>& pi,
                                                          const vec<double>& x, bool exact) {
  using J2 = jet<double, 2>;
  const Eigen::Index n = w.size();
  const double xn = x.template lpNorm<Eigen::Infinity>();
  if (exact || xn == 0 || has_jacobian_directional<S>)
    return {second_derivative_product(sys, w, mu, pr, x), second_derivative_product(sys, w, mu, pi, x)};
  const double h = std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, w.template lpNorm<Eigen::Infinity>()) / xn;
  if constexpr (system_over<S, J2>) {
    std::pair<vec<double>, vec<double>> r{vec<double>::Zero(n), vec<double>::Zero(n)};
    for (const double sign : {1.0, -1.0}) {
      vec<J2> wj(n);
      for (Eigen::Index i = 0; i < n; ++i) wj[i] = J2::variable(w[i] + sign * h * x[i], {pr[i], pi[i]});
      const vec<J2> fj = sys.residual(wj, J2(mu));
      for (Eigen::Index i = 0; i < n; ++i) {
        r.first[i] += sign * fj[i].derivative(0);
        r.second[i] += sign * fj[i].derivative(1);
      }
    }
    r.first /= 2 * h;
    r.second /= 2 * h;
    return r;
  } else {
    const vec<double> wp = w + h * x, wm = w - h * x;
    return {(jacobian_product(sys, wp, mu, pr) - jacobian_product(sys, wm, mu, pr)) / (2 * h),
            (jacobian_product(sys, wp, mu, pi) - jacobian_product(sys, wm, mu, pi)) / (2 * h)};
  }
}
}  // namespace internal

// ---- the bordered Newton step, written once for both formulations and both bordered
// strategies ----
//
// Fixed equilibrium: with C = L - i omega I (L ~ A; L = A: quadratic convergence) the eigen rows
// and the border rows of J_A dW = -F_A are
//     C dp + (A_mu p) dmu - i p domega = -G,      s^T dp = i - s^T p,      G = (A - i omega I) p,
// and with C x = -G, C y = A_mu p, C z = -i p, dp = x - y dmu - z domega; the two real unknowns
// follow from the complex border equation s^T dp = i - s^T p, the 2x2 real system
//     [Re s.y  Re s.z; Im s.y  Im s.z] [dmu; domega] = [Re(s.x - r); Im(s.x - r)],  r = i - s^T p.
//
// Full formulation (the equilibrium moves with mu: an asymmetric section or a mean incidence, the
// static aeroelastic deflection depending on Ubar): the flow update is eliminated first. With
//     A dw0 = -f,   A dw1 = -f_mu                                  (A is regular at a Hopf point)
// dw = dw0 + dmu dw1, and the eigen-equation rows become the fixed-equilibrium bordered system
// above with the right-hand side -G - (A_w p) dw0 and the mu column A_mu p + (A_w p) dw1.
// (A_w p) x = B(p, x) is a second-derivative product (second_derivative_pair), four per step. So
// a full step costs two real solves with A and one bordered complex solve: about a
// fixed-equilibrium step plus two steady Newton steps. F is exact, so the converged point is
// whatever the linear solves' accuracy.
//
// A bordered strategy provides, at the iterate set up by setup(prob, w, mu, omega, ||F||, it):
//   a_mu(v)                          A_mu v
//   solve_flow(b, what, it)          x with A x = b (real; full formulation only)
//   solve_bordered(mu_column, p_r, p_i, s, rhs, it)
//       d = [dp_r, dp_i, dmu, domega] with, in the real split form,
//       [[A - i omega I, mu_column, [p_i; -p_r]], [s^T rows, 0]] d = rhs.
namespace internal {
template <class Strategy, dynamical_system S>
vec<double> bordered_hopf_step(Strategy& st, const hopf_problem<S>& prob, const vec<double>& y, const vec<double>& f,
                               int it, bool exact_second_derivatives) {
  const S& sys = prob.system();
  const Eigen::Index n = prob.size(), N = prob.unknowns(), off = prob.eigen_offset();
  const vec<double> w = prob.w(y), pr = prob.p_re(y), pi = prob.p_im(y);
  const double mu = prob.mu(y), om = prob.omega(y);
  st.setup(prob, w, mu, om, f.norm(), it);
  vec<double> mu_column(2 * n), rhs = -f.tail(2 * n + 2);
  mu_column << st.a_mu(pr), st.a_mu(pi);
  vec<double> dw0, dw1;
  if (!prob.fixed_equilibrium()) {
    // the model's derivatives inside a step: non-finite is a failed step (convergence_error,
    // newton.hpp names the last accepted iterate), not bad input to the linear solvers
    const auto finite_or_fail = [it](const vec<double>& v, const char* what) {
      if (!v.allFinite())
        throw convergence_error(aerohopf::internal::concat(what, " is not finite at Newton iteration ", it));
    };
    dw0 = st.solve_flow(vec<double>(-f.head(n)), "dw0 = -f", it);
    const vec<double> f_mu = residual_d_mu(sys, w, mu);
    finite_or_fail(f_mu, "f_mu (the residual's derivative in mu)");
    dw1 = st.solve_flow(vec<double>(-f_mu), "dw1 = -f_mu", it);
    const auto t0 = hopf_clock::now();
    const auto [b0r, b0i] = second_derivative_pair(sys, w, mu, pr, pi, dw0, exact_second_derivatives);
    const auto [b1r, b1i] = second_derivative_pair(sys, w, mu, pr, pi, dw1, exact_second_derivatives);
    st.stats.residual_seconds += seconds_since(t0);
    for (const vec<double>* b : {&b0r, &b0i, &b1r, &b1i}) finite_or_fail(*b, "a second-derivative product B(p, dw)");
    mu_column.head(n) += b1r;
    mu_column.tail(n) += b1i;
    rhs.head(n) -= b0r;
    rhs.segment(n, n) -= b0i;
  }
  const vec<double> d = st.solve_bordered(mu_column, pr, pi, prob.s(), rhs, it);
  vec<double> dx(N);
  if (!prob.fixed_equilibrium()) dx.head(n) = dw0 + d[2 * n] * dw1;
  dx.segment(off, 2 * n + 2) = d;
  return dx;
}
}  // namespace internal

/// Linear strategy (b), bordered direct: the bordered step above with a complex solver of
/// C = L - i omega I (compute/solve interface of direct.hpp, e.g. direct_solver<
/// Eigen::SparseMatrix<std::complex<double>>>, or a krylov_solver, whose iterations are counted)
/// and, in the full formulation, the real LU of L for the flow update. L = A, or the system's
/// approximate Jacobian with opt.approximate_lhs (linear convergence; C then stays invertible at
/// the Hopf point and well conditioned for BILU). With exact L and a Krylov solver C is nearly
/// singular close to convergence (that is what a Hopf point is): use the approximate L with
/// Krylov solvers, the exact one with direct solvers. Per Newton iteration: one complex
/// factorisation and three complex solves (full: also one real factorisation, two real solves).
template <dynamical_system S, class ComplexSolver>
class hopf_bordered_direct {
 public:
  using C = std::complex<double>;
  using M = jacobian_t<S>;
  static constexpr bool reports_linear_iterations = true;
  hopf_linear_stats stats;
  /// Full formulation: the second-derivative products exact (as hopf_krylov_options).
  bool exact_second_derivatives = false;

  hopf_bordered_direct(const hopf_options& opt, ComplexSolver& solver)
      : solver_(solver), approximate_lhs_(opt.approximate_lhs), label_(opt.label),
        flow_(opt.label + ": LU of A (flow update)") {}
  std::string description(const hopf_problem<S>& prob) const {
    return prob.fixed_equilibrium() ? "bordered Hopf system" : "full Hopf system, bordered";
  }
  vec<double> newton_step(const hopf_problem<S>& prob, const vec<double>& y, const vec<double>& f, int it) {
    return internal::bordered_hopf_step(*this, prob, y, f, it, exact_second_derivatives);
  }

  void setup(const hopf_problem<S>& prob, const vec<double>& w, double mu, double om, double, int) {
    const auto t0 = internal::hopf_clock::now();
    const S& sys = prob.system();
    const M l = approximate_lhs_ ? lhs_jacobian(sys, w, mu) : M(sys.jacobian(w, mu));
    amu_ = jacobian_d_mu(sys, w, mu);
    solver_.compute(shifted(l, C(0.0, om)));
    if (!prob.fixed_equilibrium()) flow_.compute(l);
    stats.setup_seconds += internal::seconds_since(t0);
  }
  vec<double> a_mu(const vec<double>& v) const { return amu_ * v; }
  vec<double> solve_flow(const vec<double>& b, const char*, int) {
    const auto t0 = internal::hopf_clock::now();
    vec<double> x = flow_.solve(b);
    stats.linear_seconds += internal::seconds_since(t0);
    return x;
  }
  vec<double> solve_bordered(const vec<double>& mu_column, const vec<double>& pr, const vec<double>& pi,
                             const vec<double>& s, const vec<double>& rhs, int it) {
    const auto t0 = internal::hopf_clock::now();
    const Eigen::Index n = pr.size();
    vec<C> g(n), u(n), ip(n);
    g.real() = rhs.head(n);
    g.imag() = rhs.segment(n, n);
    u.real() = mu_column.head(n);
    u.imag() = mu_column.tail(n);
    ip.real() = pi;  // -i p
    ip.imag() = -pr;
    const vec<C> xs = solve(g), ys = solve(u), zs = solve(ip);
    const C r(rhs[2 * n], rhs[2 * n + 1]);
    const vec<C> sc = s.template cast<C>();  // real: dot() conjugates nothing
    const C sx = sc.dot(xs), sy = sc.dot(ys), sz = sc.dot(zs);
    Eigen::Matrix2d b;
    b << sy.real(), sz.real(), sy.imag(), sz.imag();
    const Eigen::Vector2d b_rhs(sx.real() - r.real(), sx.imag() - r.imag());
    const double det = b.determinant();
    if (!(std::abs(det) > 1e-300) || !std::isfinite(det))
      throw singular_matrix_error(internal::concat(label_, ": bordered 2x2 system singular at Newton iteration ", it,
                                                   " (det ", det, "): mu and omega not determined"));
    const Eigen::Vector2d dm = b.partialPivLu().solve(b_rhs);
    const vec<C> dp = xs - dm[0] * ys - dm[1] * zs;
    vec<double> d(2 * n + 2);
    d << dp.real(), dp.imag(), dm[0], dm[1];
    stats.linear_seconds += internal::seconds_since(t0);
    return d;
  }

 private:
  vec<C> solve(const vec<C>& b) {
    vec<C> x = solver_.solve(b);
    if constexpr (requires { solver_.last_report().iterations; }) stats.linear_iterations += solver_.last_report().iterations;
    return x;
  }
  ComplexSolver& solver_;
  bool approximate_lhs_;
  std::string label_;
  direct_solver<M> flow_;
  M amu_;
};

/// Linear strategy (c), bordered Krylov: Newton with the EXACT real (2n+2) bordered matrix
///     J = [[A, omega I, A_mu p_r, p_i], [-omega I, A, A_mu p_i, -p_r], [s^T, 0, 0, 0], [0, s^T, 0, 0]]
/// (the mu column gets (A_w p) dw1 in the full formulation) applied matrix-free (the fused
/// shifted block product of the exact Jacobian), solved by right-preconditioned GMRES. The
/// preconditioner is the exact inverse of the same bordered matrix with A - i omega I replaced by
/// its preconditioner built from the MODIFIED-ORDER L - i omega I: complex BILU(k) of the flow
/// part (block size B), the structural border eliminated exactly (bordered_block_ilu); then block
/// elimination of the two Hopf border unknowns (bordered_preconditioner), so one complex BILU
/// application per GMRES iteration. J itself is non-singular at a simple Hopf point, so GMRES does
/// not meet the near-singularity of A - i omega I. This avoids both the fill of a direct solver
/// and the slow linear rate of the approximate left-hand side (the original scheme: modified-order
/// L, bordering, BILU-GMRES converges at a linear rate ~0.85 on the NACA 0012 coarse grid).
/// The full formulation's flow update is real GMRES on the exact A, preconditioned by the real
/// bordered BILU(k) of L; the three solves share the inexact-Newton forcing. Matrices and
/// factorisations: fixed equilibrium, reused from (mu0, omega0) while hopf_krylov_options::reuse_matrices
/// allows; full formulation, refreshed at every iterate (A moves with w).
///
/// Measured on the NACA 0012 pitch-plunge (light case, M = 0.5, one core; examples/aerofoil_flutter),
/// coarse grid (4,100 unknowns), 4 Newton iterations from the same inverse-power start:
///     hopf_augmented_lu (real (2n+2) sparse LU)       5.7 s
///     hopf_bordered_direct (complex sparse LU)        1.9 s
///     hopf_bordered_krylov, BILU(0/1/2)               0.28 / 0.22 / 0.20 s (120 / 94 / 86 GMRES iterations)
///   medium grid (16,388 unknowns): 0.6-0.9 s per Hopf point continued from the previous Mach
///   number (4 Newton iterations, ~30 GMRES iterations each), 1.3-1.5 x the steady solve.
///   Preconditioning with BILU(k) of the EXACT shifted matrix (precondition_exact) needs fewer
///   GMRES iterations at k = 3 but costs more per Hopf point (2.0 x the steady solve at k = 1..3).
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
class hopf_bordered_krylov {
 public:
  using C = std::complex<double>;
  static constexpr bool reports_linear_iterations = true;
  hopf_linear_stats stats;

  hopf_bordered_krylov(const hopf_options& opt, const hopf_krylov_options& kopt)
      : kopt_(kopt), label_(opt.label), abs_tolerance_(opt.newton.abs_tolerance), ilu_(ilu_options("complex", "L - i omega I")),
        ilu_real_(ilu_options("real", "L (flow update)")) {}
  std::string description(const hopf_problem<S>& prob) const {
    return prob.fixed_equilibrium() ? "Hopf system, BILU-GMRES" : "full Hopf system, BILU-GMRES";
  }
  vec<double> newton_step(const hopf_problem<S>& prob, const vec<double>& y, const vec<double>& f, int it) {
    return internal::bordered_hopf_step(*this, prob, y, f, it, kopt_.exact_second_derivatives);
  }

  void setup(const hopf_problem<S>& prob, const vec<double>& w, double mu, double om, double fn, int it) {
    const bool full = !prob.fixed_equilibrium();
    const bool slow = it > 1 && fn > 0.1 * last_norm_;
    if (full || !assembled_ || !kopt_.reuse_matrices ||
        (it > 1 && (slow || std::abs(mu - mu0_) > kopt_.reuse_window * (1 + std::abs(mu0_)))))
      refresh(prob, w, mu, om);
    last_norm_ = fn;
    mu_ = mu;
    om_ = om;
    ko_ = kopt_.krylov;
    if (kopt_.adaptive_tolerance)
      ko_.relative_tolerance =
          std::min(kopt_.eta_max, std::max(std::pow(fn, kopt_.forcing_exponent), 0.1 * abs_tolerance_ / fn));
    ko_.throw_on_failure = true;
    full_ = full;
  }
  vec<double> a_mu(const vec<double>& v) const { return amu_ * v; }
  vec<double> solve_flow(const vec<double>& b, const char* what, int it) {
    const auto t0 = internal::hopf_clock::now();
    vec<double> d = vec<double>::Zero(b.size());
    ko_.context = internal::concat(label_, ": GMRES on A ", what, " at Newton iteration ", it);
    stats.linear_iterations += gmres<double>(a_, ilu_real_, b, d, ko_).iterations;
    stats.linear_seconds += internal::seconds_since(t0);
    return d;
  }
  vec<double> solve_bordered(const vec<double>& mu_column, const vec<double>& pr, const vec<double>& pi,
                             const vec<double>& s, const vec<double>& rhs, int it) {
    const auto t0 = internal::hopf_clock::now();
    const Eigen::Index n = pr.size();
    // inner operator: the real form of A - i omega I on (x_re, x_im), A = A0 + (mu - mu0) A_mu0;
    // its preconditioner: the complex BILU solve in the same form
    const internal::real_split_shifted_operator<bordered_block_matrix<double, B>, jacobian_t<S>> inner(a_, om_, n, &amu_,
                                                                                                     mu_ - mu0_);
    const internal::complex_preconditioner_split_form<bordered_block_ilu<C, B>> inner_pre(ilu_, n, a_.rows());
    Eigen::MatrixXd u(2 * n, 2), vt = Eigen::MatrixXd::Zero(2, 2 * n);
    u.col(0) = mu_column;
    u.col(1) << pi, -pr;
    vt.row(0).head(n) = s.transpose();
    vt.row(1).tail(n) = s.transpose();
    const bordered_operator<decltype(inner), double> jop(inner, 2 * n, std::move(u), std::move(vt),
                                                         Eigen::MatrixXd::Zero(2, 2));
    const bordered_preconditioner<decltype(inner_pre), double> jpre(jop, inner_pre);
    ko_.context = full_ ? internal::concat(label_, ": GMRES on the bordered eigen-equations at Newton iteration ", it)
                        : internal::concat(label_, ": GMRES at Newton iteration ", it);
    vec<double> d = vec<double>::Zero(2 * n + 2);
    stats.linear_iterations += gmres<double>(jop, jpre, rhs, d, ko_).iterations;
    stats.linear_seconds += internal::seconds_since(t0);
    return d;
  }

  /// hopf_krylov_options::start_iterations inverse iterations on the guess's eigenvector (fixed
  /// equilibrium): (A - i omega I) y = p by GMRES with the Newton operator and preconditioner at
  /// the guess (to start_tolerance), p <- y, omega from the Rayleigh quotient of A. prob is
  /// replaced by the refined guess's problem if that lowers ||F|| at the guess's mu; returns
  /// whether it was.
  bool refine_start(hopf_problem<S>& prob, const hopf_point& guess, const hopf_options& opt, const std::string& who) {
    const Eigen::Index n = prob.size();
    const vec<double>& x = prob.start();
    auto t1 = internal::hopf_clock::now();
    const double f_old = prob.residual(x).norm();
    stats.residual_seconds += internal::seconds_since(t1);
    if (!(f_old > kopt_.start_residual_threshold)) return false;
    if (!assembled_ || !kopt_.reuse_matrices) refresh(prob, guess.w, prob.mu(x), prob.omega(x));
    const auto t0 = internal::hopf_clock::now();
    const double om = prob.omega(x);
    const internal::real_split_shifted_operator<bordered_block_matrix<double, B>> shifted_a(a_, om, n);
    const internal::complex_preconditioner_split_form<bordered_block_ilu<C, B>> pre(ilu_, n, a_.rows());
    vec<double> v(2 * n), y(2 * n), av(2 * n);
    v << prob.p_re(x), prob.p_im(x);
    krylov_options ko = kopt_.krylov;
    ko.relative_tolerance = kopt_.start_tolerance;
    ko.max_iterations = std::min(ko.max_iterations, kopt_.start_max_iterations);
    ko.throw_on_failure = false;
    ko.context = label_ + ": start refinement";
    long its = 0;
    bool ok = true, kept = false;
    for (int k = 0; k < kopt_.start_iterations && ok; ++k) {
      y.setZero();
      its += gmres<double>(shifted_a, pre, vec<double>(v / v.norm()), y, ko).iterations;
      ok = y.allFinite() && y.norm() > 0;
      if (ok) v = y / y.norm();
    }
    stats.linear_iterations += its;
    if (ok) {
      hopf_point g = guess;
      g.p.real() = v.head(n);
      g.p.imag() = v.tail(n);
      // Rayleigh quotient of A: omega estimate (A real: lambda = (p^H A p) / (p^H p))
      const internal::real_split_shifted_operator<bordered_block_matrix<double, B>> plain_a(a_, 0.0, n);
      plain_a(v, av);
      const C pap = C(v.head(n).dot(av.head(n)) + v.tail(n).dot(av.tail(n)),
                      v.head(n).dot(av.tail(n)) - v.tail(n).dot(av.head(n)));
      if (pap.imag() * om > 0) g.omega = pap.imag();
      hopf_problem<S> refined(prob.system(), g, opt, who);
      t1 = internal::hopf_clock::now();
      const double f_new = refined.residual(refined.start()).norm();
      stats.residual_seconds += internal::seconds_since(t1);
      if (std::isfinite(f_new) && f_new < f_old) {
        prob = std::move(refined);
        kept = true;
      }
      if (opt.verbose && opt.log)
        *opt.log << opt.label << " start: " << kopt_.start_iterations << " inverse iteration(s), " << its
                 << " GMRES iterations, ||F|| " << std::scientific << std::setprecision(3) << f_old << " -> " << f_new
                 << std::defaultfloat << (kept ? " (kept)" : " (discarded)") << ", omega " << g.omega << "\n";
    }
    stats.linear_seconds += internal::seconds_since(t0);
    return kept;
  }

 private:
  block_ilu_options ilu_options(const char* kind, const char* of) const {
    block_ilu_options io;
    io.fill_level = kopt_.fill_level;
    io.single_precision_factors = kopt_.single_precision_factors;
    io.context = internal::concat(label_, ": ", kind, " BILU(", kopt_.fill_level, ") of ", of);
    return io;
  }
  /// A (bordered, blocked for a fast SpMV), A_mu and the bordered BILU of L - i omega I (and of
  /// L, full formulation) at (w, mu, omega); the exact Jacobian also serves as L when
  /// precondition_exact.
  void refresh(const hopf_problem<S>& prob, const vec<double>& w, double mu, double om) {
    const auto t0 = internal::hopf_clock::now();
    const S& sys = prob.system();
    bordered_block_matrix<double, B> l;
    internal::krylov_matrices<B>(sys, w, mu, kopt_.precondition_exact, label_, a_, l);
    amu_ = jacobian_d_mu(sys, w, mu);
    mu0_ = mu;
    const bordered_block_matrix<double, B>& pm = kopt_.precondition_exact ? a_ : l;
    ilu_.compute(pm, C(0.0, om));
    if (!prob.fixed_equilibrium()) ilu_real_.compute(pm);
    assembled_ = true;
    stats.setup_seconds += internal::seconds_since(t0);
  }

  hopf_krylov_options kopt_;
  std::string label_;
  double abs_tolerance_;
  bordered_block_ilu<C, B> ilu_;
  bordered_block_ilu<double, B> ilu_real_;
  bordered_block_matrix<double, B> a_;
  jacobian_t<S> amu_;
  bool assembled_ = false, full_ = false;
  double mu0_ = 0, mu_ = 0, om_ = 0, last_norm_ = 0;
  krylov_options ko_;
};

/// Newton on the Hopf system by bordering with a complex solver of L - i omega I
/// (hopf_bordered_direct); opt.fixed_equilibrium picks the formulation (the full one also
/// factorises L for the flow update), opt.approximate_lhs selects L, opt.normalisation as in
/// solve_hopf (automatic: largest component for sparse Jacobians).
template <dynamical_system S, class ComplexSolver>
hopf_result solve_hopf_bordered(const S& sys, const hopf_point& guess, const hopf_options& opt,
                                ComplexSolver& solver) {
  const hopf_problem<S> prob(sys, guess, opt, "solve_hopf_bordered");
  hopf_bordered_direct<S, ComplexSolver> strategy(opt, solver);
  return hopf_newton(prob, strategy, opt);
}

/// Newton on the Hopf system with the exact bordered matrix, GMRES and the bordered
/// complex-BILU(k) preconditioner of the modified-order matrix (hopf_bordered_krylov). B is the
/// block size of the system's flow unknowns (4 for 2D Euler); the rest is the structural border
/// (krylov_jacobians, nonlinear/block_system.hpp). The formulation: fixed equilibrium (opt.fixed_equilibrium must be set), or
/// the full one with kopt.full_system (opt.fixed_equilibrium must not be set; no start
/// refinement). opt.approximate_lhs is ignored (the preconditioner always uses lhs_jacobian, the
/// operator always the exact Jacobian).
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
hopf_result solve_hopf_krylov(const S& sys, const hopf_point& guess, const hopf_options& opt,
                              const hopf_krylov_options& kopt = {}) {
  const std::string who = kopt.full_system ? "solve_hopf_krylov (full system)" : "solve_hopf_krylov";
  if (kopt.full_system)
    require(!opt.fixed_equilibrium, who,
            ": hopf_krylov_options::full_system solves the full formulation (the equilibrium as unknown); "
            "hopf_options::fixed_equilibrium must be false");
  else
    require(opt.fixed_equilibrium,
            "solve_hopf_krylov: hopf_options::fixed_equilibrium = false (the equilibrium moves with mu) needs the full "
            "formulation: set hopf_krylov_options::full_system (or hopf_options::fixed_equilibrium for a fixed "
            "equilibrium)");
  hopf_problem<S> prob(sys, guess, opt, who);
  internal::check_hopf_krylov_options(kopt, who);
  require(!kopt.full_system || kopt.start_iterations == 0, who,
          ": the start refinement (hopf_krylov_options::start_iterations = ", kopt.start_iterations,
          ") is available only in the fixed-equilibrium formulation; set it to 0");
  hopf_bordered_krylov<B, S> strategy(opt, kopt);
  const bool refined = kopt.start_iterations > 0 && strategy.refine_start(prob, guess, opt, who);
  hopf_result r = hopf_newton(prob, strategy, opt);
  r.start_refined = refined;
  return r;
}

/// Options of hopf_start_krylov.
struct hopf_start_krylov_options {
  int fill_level = 1;               ///< k of the complex BILU(k) of L - i omega_guess I
  bool single_precision_factors = true;  ///< as hopf_krylov_options
  bool precondition_exact = false;  ///< BILU(k) of the exact A - i omega_guess I instead
  /// GMRES of each inverse iteration: the solves must be tighter than the eigen-residual target
  /// (inexact inverse iteration with a fixed tolerance stagnates near it, inverse_power.hpp).
  krylov_options krylov = [] {
    krylov_options o = newton_correction_krylov_options();
    o.relative_tolerance = 1e-9;
    return o;
  }();
  /// Tolerance and iteration limit of the inverse iteration (a start for the Hopf Newton
  /// iteration, which converges the pair exactly: 1e-8 is enough).
  inverse_power_options inverse_power = [] {
    inverse_power_options o;
    o.tolerance = 1e-8;
    return o;
  }();
};

/// Start point for the Hopf Newton iteration at CFD sizes: shift-invert inverse power
/// (inverse_power.hpp) at (w, mu) with the shift sigma = i omega_guess, each solve of
/// (A - sigma I) y = x by complex GMRES on the exact A (the fused shifted bordered product),
/// right-preconditioned by the complex BILU(k) of the flow part of L - sigma I with the
/// structural border eliminated exactly (bordered_block_ilu), L the preconditioning Jacobian
/// (the modified-order Jacobian of the aerofoil) or A itself (precondition_exact). The matrices
/// come from krylov_jacobians (the system's bordered or block Jacobians, else its sparse ones). Convergence as inverse_power: ||A x - lambda x||_2 <= max(tolerance max(1,
/// |lambda|), 100 eps ||A||_inf), ||x||_2 = 1; otherwise convergence_error with the last lambda.
/// info (optional) receives the eigenpair with its iteration and GMRES counts.
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
hopf_point hopf_start_krylov(const S& sys, const vec<double>& w, double mu, double omega_guess,
                             const hopf_start_krylov_options& o = {}, eigen_pair* info = nullptr) {
  using C = std::complex<double>;
  const char* who = "hopf_start_krylov";
  check_state(sys, w, mu, who);
  require(std::isfinite(omega_guess), who, ": omega_guess is not finite (", omega_guess, ")");
  require(o.fill_level >= 0, who, ": fill_level must be >= 0 (got ", o.fill_level, ")");
  validate_krylov_options(o.krylov, who);
  require(o.inverse_power.max_iterations >= 1, who, ": inverse_power.max_iterations must be >= 1 (got ",
          o.inverse_power.max_iterations, ")");
  require(std::isfinite(o.inverse_power.tolerance) && o.inverse_power.tolerance > 0, who,
          ": inverse_power.tolerance must be finite and > 0 (got ", o.inverse_power.tolerance, ")");
  const Eigen::Index n = sys.size();
  const C sigma(0.0, omega_guess);
  bordered_block_matrix<double, B> a, l;
  internal::krylov_matrices<B>(sys, w, mu, o.precondition_exact, who, a, l);
  const double a_norm = a.norm_inf();  // ||A||_inf, the scale of the attainable residual
  block_ilu_options io;
  io.fill_level = o.fill_level;
  io.single_precision_factors = o.single_precision_factors;
  io.context = internal::concat(who, ": complex BILU(", o.fill_level, ") of ", o.precondition_exact ? "A" : "L",
                                " - i omega I");
  bordered_block_ilu<C, B> ilu(io);
  ilu.compute(o.precondition_exact ? a : l, sigma);
  const shifted_operator<bordered_block_matrix<double, B>, C> op(a, sigma);
  vec<C> x = internal::default_start(n), y(n), r(n);
  krylov_options ko = o.krylov;
  ko.throw_on_failure = true;
  eigen_pair ep;
  const double floor = 100 * std::numeric_limits<double>::epsilon() * a_norm;
  for (int t = 1; t <= o.inverse_power.max_iterations; ++t) {
    y.setZero();
    ko.context = internal::concat(who, ": GMRES on A - i omega I (omega ", omega_guess, "), inverse iteration ", t);
    ep.linear_iterations += gmres<C>(op, ilu, x, y, ko).iterations;
    const double ny2 = y.squaredNorm();
    if (!(ny2 > 0) || !std::isfinite(ny2))
      throw convergence_error(internal::concat(who, ": iterate ", t, " is zero or not finite"));
    ep.lambda = sigma + y.dot(x) / ny2;
    x = y / std::sqrt(ny2);
    a.apply_shifted(ep.lambda, x, r);
    ep.residual = r.norm();
    ep.iterations = t;
    if (o.inverse_power.verbose && o.inverse_power.log)
      *o.inverse_power.log << who << " it " << t << "  lambda " << ep.lambda << "  residual " << ep.residual << "  GMRES "
                           << ep.linear_iterations << "\n";
    if (ep.residual <= std::max(o.inverse_power.tolerance * std::max(1.0, std::abs(ep.lambda)), floor)) {
      ep.vector = x;
      internal::normalise_phase(ep.vector);
      if (info) *info = ep;
      return internal::hopf_point_from(w, mu, ep);
    }
  }
  throw convergence_error(internal::concat(who, ": no convergence in ", o.inverse_power.max_iterations,
                                           " inverse iterations (shift ", sigma, ", last lambda ", ep.lambda,
                                           ", residual ", ep.residual, ")"));
}

}  // namespace aerohopf
