#pragma once
// The reduced (fixed-equilibrium) Hopf system solved by BORDERING on the complex matrix, so that the
// only linear systems are n x n complex ones with the sparsity of A, which a BILU(k)-Krylov
// solver handles (the original scheme of the flutter method) instead of a sparse LU of the
// real (2n+2) system, whose fill grows too fast for CFD grids.
//
// Symmetric case (spec 02): the equilibrium w does not depend on mu, unknowns p = p_r + i p_i,
// mu, omega with
//     G(p, mu, omega) = (A(mu) - i omega I) p = 0,      s^T p = i        (s real, fixed).
// Newton with a left-hand-side matrix L ~ A (L = A: quadratic convergence; L = the modified-
// order Jacobian: the original scheme, linear convergence, but C = L - i omega I stays
// invertible at the Hopf point and is well conditioned for BILU):
//     C dp + (A_mu p) dmu - i p domega = -G,      s^T dp = i - s^T p.
// With C x = -G, C y = A_mu p, C z = -i p, dp = x - y dmu - z domega, and the two real
// unknowns follow from the complex border equation s^T dp = i - s^T p, i.e. the 2x2 real system
//     [Re s.y  Re s.z; Im s.y  Im s.z] [dmu; domega] = [Re(s.x - r); Im(s.x - r)],  r = i - s^T p.
// G is always evaluated exactly and matrix-free (jacobian_product through the templated
// residual), so the converged point is the exact Hopf point whatever L and the linear
// tolerance are; they change only the rate of convergence.
//
// Cost per Newton iteration: one complex factorisation (or BILU) and three complex solves. The
// solver type is a template parameter with the compute/solve interface of direct.hpp:
// direct_solver<Eigen::SparseMatrix<std::complex<double>>> (sparse LU) or
// krylov_solver<Eigen::SparseMatrix<std::complex<double>>, B> (BILU(k) + GMRES); Krylov
// iterations are summed into hopf_result::linear_iterations.
//
// With exact L and a Krylov solver C is nearly singular close to convergence (that is what a
// Hopf point is): use the approximate L with Krylov solvers, the exact one with direct solvers.
//
// solve_hopf_krylov (below) avoids both the fill of a direct solver and the slow linear rate of
// the approximate left-hand side: Newton with the EXACT real (2n+2) bordered matrix
//     J = [[A, omega I, A_mu p_r, p_i], [-omega I, A, A_mu p_i, -p_r], [s^T, 0, 0, 0], [0, s^T, 0, 0]]
// applied matrix-free (two real SpMVs with the exact Jacobian), solved by right-preconditioned
// GMRES. The preconditioner is the exact inverse of the same bordered matrix with
// A - i omega I replaced by its BILU(k) factors of the MODIFIED-ORDER L - i omega I (complex,
// block size B): block elimination of the two border unknowns (bordered_preconditioner), so one
// complex BILU application per GMRES iteration. J itself is non-singular at a simple Hopf
// point, so GMRES does not meet the near-singularity of A - i omega I.
//
// Measured on the NACA 0012 pitch-plunge (light case, M = 0.5, one core; examples/aerofoil_flutter):
//   coarse grid (4,100 unknowns), 4 Newton iterations from the same inverse-power start:
//     solve_hopf (real (2n+2) sparse LU)        5.7 s
//     solve_hopf_bordered (complex sparse LU)   1.9 s
//     solve_hopf_krylov, BILU(0/1/2)            0.28 / 0.22 / 0.20 s (120 / 94 / 86 GMRES iterations)
//     the original scheme (modified-order L, bordering, BILU-GMRES): linear rate ~0.85, not
//     converged in 80 iterations -- why the exact operator is used here;
//   medium grid (16,388 unknowns): 0.6-0.9 s per Hopf point continued from the previous Mach
//   number (4 Newton iterations, ~30 GMRES iterations each), 1.3-1.5 x the steady solve.
//   Preconditioning with BILU(k) of the EXACT shifted matrix (precondition_exact) needs fewer
//   GMRES iterations at k = 3 but costs more per Hopf point (2.0 x the steady solve at k = 1..3).
//
// Full formulation (hopf_krylov_options::full_system; hopf_options::fixed_equilibrium = false): the
// equilibrium moves with mu (an asymmetric section or a mean incidence: the static aeroelastic
// deflection depends on Ubar), unknowns [w, p_r, p_i, mu, omega] (3n + 2) with the augmented
// system of hopf.hpp. The flow update is eliminated inside the Newton step: with
//     A dw0 = -f,   A dw1 = -f_mu   (real GMRES on the exact A, preconditioned by the real BILU(k)
//                                    of L; A is regular at a Hopf point),
// dw = dw0 + dmu dw1, and the eigen-equation rows become the fixed-equilibrium bordered system
// above with the right-hand side -G - (A_w p) dw0 and the mu column A_mu p + (A_w p) dw1, solved
// by the same bordered GMRES. (A_w p) x = B(p, x) is a second-derivative product
// (internal::second_derivative_product: the system's jacobian_directional, else two
// taylor<double, 2> passes, else central differences of Jacobian-vector products; by default
// central differences of jet<double, 2> Jacobian products, hopf_krylov_options::
// exact_second_derivatives), four per step. So a Newton step costs two real and one bordered complex BILU-GMRES solve plus one
// assembly and two factorisations: about a fixed-equilibrium step plus two steady Newton steps.
// The three solves share the inexact-Newton forcing; F is exact, so the converged point is.
#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <complex>
#include <concepts>
#include <iomanip>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "../error.hpp"
#include "../linalg/block_ilu.hpp"
#include "../linalg/block_sparse_matrix.hpp"
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

/// Progress line per Newton iteration of a Hopf solve with N unknowns, mu and omega last (with
/// the running linear-iteration count); only with opt.verbose and no observer of the caller's.
inline void add_hopf_progress(newton_options& nopt, const hopf_options& opt, Eigen::Index N,
                              const long& linear_iterations) {
  if (!opt.verbose || !opt.log || nopt.observer) return;
  std::ostream& os = *opt.log;
  nopt.observer = [&os, label = opt.label, N, &linear_iterations](const newton_step_info& i) {
    os << label << " it " << std::setw(2) << i.iteration << "  |F| " << std::scientific << std::setprecision(3)
       << i.residual << "  mu " << std::setprecision(12) << std::defaultfloat << (*i.x)[N - 2] << "  omega "
       << (*i.x)[N - 1] << "  linear its " << linear_iterations << (i.relaxation < 1 ? "  (relaxed)" : "") << "\n";
  };
}

/// Unknowns y = [p_r, p_i, mu, omega] of the fixed-equilibrium Hopf system, with its exact residual
/// (matrix-free) and the unpacking of the converged point; shared by the bordered solvers.
template <dynamical_system S>
struct fixed_equilibrium_hopf_problem {
  const S& sys;
  vec<double> w, s;
  Eigen::Index n, N;

  fixed_equilibrium_hopf_problem(const S& system, const hopf_point& guess, const hopf_options& opt, const char* who,
                         vec<double>& y0)
      : sys(system), w(guess.w), n(system.size()), N(2 * system.size() + 2) {
    require(opt.fixed_equilibrium, who, ": only the fixed-equilibrium system is implemented; set hopf_options::fixed_equilibrium");
    check_hopf_guess(sys, guess, who);
    check_hopf_options(opt, who);
    vec<std::complex<double>> p0 = guess.p;
    s = hopf_normalise(p0, resolve_normalisation<jacobian_t<S>>(opt.normalisation));
    y0.resize(N);
    y0.head(n) = p0.real();
    y0.segment(n, n) = p0.imag();
    y0[N - 2] = guess.mu;
    y0[N - 1] = guess.omega;
  }

  vec<double> residual(const vec<double>& y) const {
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> pr = y.head(n), pi = y.segment(n, n);
    vec<double> f(N);
    f.head(n) = jacobian_product(sys, w, mu, pr) + om * pi;
    f.segment(n, n) = jacobian_product(sys, w, mu, pi) - om * pr;
    f[N - 2] = s.dot(pr);
    f[N - 1] = s.dot(pi) - 1.0;
    return f;
  }

  /// Progress line per Newton iteration (with the running linear-iteration count).
  void add_progress(newton_options& nopt, const hopf_options& opt, const long& linear_iterations) const {
    add_hopf_progress(nopt, opt, N, linear_iterations);
  }

  /// The converged point with omega > 0, after the post-checks of hopf.hpp (w is fixed: the
  /// equilibrium is verified at mu*).
  hopf_result result(newton_result&& nr, long linear_iterations, const hopf_options& opt) const {
    hopf_result res;
    res.s = s;
    res.report = std::move(nr.report);
    res.linear_iterations = linear_iterations;
    const vec<double>& y = nr.x;
    res.point.w = w;
    res.point.mu = y[N - 2];
    res.point.omega = y[N - 1];
    res.point.p = vec<std::complex<double>>(n);
    res.point.p.real() = y.head(n);
    res.point.p.imag() = y.segment(n, n);
    if (res.report.converged && res.point.omega < 0) {
      res.point.omega = -res.point.omega;
      res.point.p = res.point.p.conjugate().eval();
    }
    hopf_accept(sys, res, opt, true);
    return res;
  }
};

/// The real split form of (A + dmu A_mu) - i omega I acting on v = [x_re; x_im] (n each):
///   r = [(A + dmu A_mu) x_re + omega x_im;  (A + dmu A_mu) x_im - omega x_re].
/// A is a padded block matrix (rows() >= n, padding zero); A_mu (any matrix with a product) is
/// used only when dmu != 0. The inner operator of every bordered Krylov Hopf solve.
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

/// Newton on the reduced Hopf system by bordering (see the file comment). opt.fixed_equilibrium must be
/// set (w = guess.w stays fixed); opt.approximate_lhs selects L; opt.normalisation as in
/// solve_hopf (automatic: largest component for sparse Jacobians).
template <dynamical_system S, class ComplexSolver>
hopf_result solve_hopf_bordered(const S& sys, const hopf_point& guess, const hopf_options& opt,
                                ComplexSolver& solver) {
  using C = std::complex<double>;
  using M = jacobian_t<S>;
  vec<double> x;
  const internal::fixed_equilibrium_hopf_problem<S> prob(sys, guess, opt, "solve_hopf_bordered", x);
  const Eigen::Index n = prob.n, N = prob.N;
  const vec<double>& w = prob.w;
  const vec<double>& s = prob.s;
  auto residual = [&](const vec<double>& y) { return prob.residual(y); };
  long linear_iterations = 0;
  auto count = [&] {
    if constexpr (requires { solver.last_report().iterations; }) linear_iterations += solver.last_report().iterations;
  };
  internal::hopf_iterate_log last(x, N - 2, N - 1);
  auto step = [&](const vec<double>& y, const vec<double>& f, int it) {
    last.record(y, f, it);
    const double mu = y[N - 2], om = y[N - 1];
    vec<C> p(n), g(n);
    p.real() = y.head(n);
    p.imag() = y.segment(n, n);
    g.real() = f.head(n);
    g.imag() = f.segment(n, n);
    const C r = C(-f[N - 2], -f[N - 1]);  // i - s^T p
    const M l = opt.approximate_lhs ? lhs_jacobian(sys, w, mu) : M(sys.jacobian(w, mu));
    const M amu = jacobian_d_mu(sys, w, mu);
    solver.compute(shifted(l, C(0.0, om)));
    vec<C> amu_p(n);
    amu_p.real() = amu * vec<double>(y.head(n));
    amu_p.imag() = amu * vec<double>(y.segment(n, n));
    const vec<C> xs = solver.solve(vec<C>(-g));
    count();
    const vec<C> ys = solver.solve(amu_p);
    count();
    const vec<C> zs = solver.solve(vec<C>(C(0.0, -1.0) * p));
    count();
    const vec<C> sc = s.template cast<C>();  // real: dot() conjugates nothing
    const C sx = sc.dot(xs), sy = sc.dot(ys), sz = sc.dot(zs);
    Eigen::Matrix2d b;
    b << sy.real(), sz.real(), sy.imag(), sz.imag();
    const Eigen::Vector2d rhs(sx.real() - r.real(), sx.imag() - r.imag());
    const double det = b.determinant();
    if (!(std::abs(det) > 1e-300) || !std::isfinite(det))
      throw singular_matrix_error(internal::concat(opt.label, ": bordered 2x2 system singular at Newton iteration ", it,
                                                   " (det ", det, "): mu and omega not determined"));
    const Eigen::Vector2d d = b.partialPivLu().solve(rhs);
    const vec<C> dp = xs - d[0] * ys - d[1] * zs;
    vec<double> dx(N);
    dx.head(n) = dp.real();
    dx.segment(n, n) = dp.imag();
    dx[N - 2] = d[0];
    dx[N - 1] = d[1];
    return dx;
  };
  newton_options nopt = opt.newton;
  prob.add_progress(nopt, opt, linear_iterations);
  newton_result nr = internal::run_hopf_newton(
      [&] { return newton_iterate(residual, step, x, nopt, opt.label + " (bordered Hopf system)"); }, last, opt);
  return prob.result(std::move(nr), linear_iterations, opt);
}

/// A system that also assembles its exact and approximate (left-hand-side) Jacobians directly
/// as block matrices of block size B, padded to a multiple of B with logical size n (e.g.
/// models::aerofoil_system): solve_hopf_krylov then skips the Eigen sparse round trip
/// (triplets, sort, re-blocking), about half of the assembly time on the NACA 0012 grids.
/// block_jacobians(w, mu) gives both (exact, approximate) at once, sharing what they have in common.
template <class S, int B>
concept has_block_jacobians = block_system_of<S, B>;

namespace internal {
/// The exact Jacobian of sys at (w, mu) in blocks of B (padded to a multiple of B, logical size
/// n): the block_system's own assembly (checked_exact_jacobian; its block size must be B), else
/// from_sparse.
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
}  // namespace internal

struct hopf_krylov_options {
  int fill_level = 0;               ///< k of the complex BILU(k) of L - i omega I
  krylov_options krylov = [] {
    krylov_options o;
    o.relative_tolerance = 1e-6;    ///< of each Newton correction, unless adaptive (below)
    o.max_iterations = 2000;
    o.restart = 80;
    o.record_history = false;
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
  /// mu: hopf_options::fixed_equilibrium must be false) instead of the fixed-equilibrium one, solved by
  /// eliminating the flow update dw inside the same bordered Krylov solve ("Full formulation" in
  /// the file comment). Matrices and both BILU factorisations are then refreshed at every Newton
  /// iterate (reuse_matrices and reuse_window do not apply: A moves with w), and the start
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

/// Unknowns y = [w, p_r, p_i, mu, omega] of the full Hopf system (3n + 2), with its exact
/// residual (matrix-free eigen-equations) and the unpacking of the converged point.
template <dynamical_system S>
struct full_hopf_problem {
  const S& sys;
  vec<double> s;
  Eigen::Index n, N;

  full_hopf_problem(const S& system, const hopf_point& guess, const hopf_options& opt, const char* who,
                    vec<double>& y0)
      : sys(system), n(system.size()), N(3 * system.size() + 2) {
    require(!opt.fixed_equilibrium, who,
            ": hopf_krylov_options::full_system solves the full formulation (the equilibrium as unknown); "
            "hopf_options::fixed_equilibrium must be false");
    check_hopf_guess(sys, guess, who);
    check_hopf_options(opt, who);
    vec<std::complex<double>> p0 = guess.p;
    s = hopf_normalise(p0, resolve_normalisation<jacobian_t<S>>(opt.normalisation));
    y0.resize(N);
    y0.head(n) = guess.w;
    y0.segment(n, n) = p0.real();
    y0.segment(2 * n, n) = p0.imag();
    y0[N - 2] = guess.mu;
    y0[N - 1] = guess.omega;
  }

  vec<double> residual(const vec<double>& y) const {
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> w = y.head(n), pr = y.segment(n, n), pi = y.segment(2 * n, n);
    vec<double> f(N);
    f.head(n) = sys.residual(w, mu);
    f.segment(n, n) = jacobian_product(sys, w, mu, pr) + om * pi;
    f.segment(2 * n, n) = jacobian_product(sys, w, mu, pi) - om * pr;
    f[N - 2] = s.dot(pr);
    f[N - 1] = s.dot(pi) - 1.0;
    return f;
  }

  /// The converged point with omega > 0, after the post-checks of hopf.hpp (full formulation).
  hopf_result result(newton_result&& nr, long linear_iterations, const hopf_options& opt) const {
    hopf_result res;
    res.s = s;
    res.report = std::move(nr.report);
    res.linear_iterations = linear_iterations;
    const vec<double>& y = nr.x;
    res.point.w = y.head(n);
    res.point.mu = y[N - 2];
    res.point.omega = y[N - 1];
    res.point.p = vec<std::complex<double>>(n);
    res.point.p.real() = y.segment(n, n);
    res.point.p.imag() = y.segment(2 * n, n);
    if (res.report.converged && res.point.omega < 0) {
      res.point.omega = -res.point.omega;
      res.point.p = res.point.p.conjugate().eval();
    }
    hopf_accept(sys, res, opt, false);
    return res;
  }
};

/// solve_hopf_krylov with hopf_krylov_options::full_system ("Full formulation", file comment).
template <int B, dynamical_system S>
hopf_result solve_hopf_krylov_full(const S& sys, const hopf_point& guess, const hopf_options& opt,
                                   const hopf_krylov_options& kopt) {
  using C = std::complex<double>;
  using clock = std::chrono::steady_clock;
  auto since = [](clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); };
  vec<double> x;
  const full_hopf_problem<S> prob(sys, guess, opt, "solve_hopf_krylov (full system)", x);
  check_hopf_krylov_options(kopt, "solve_hopf_krylov (full system)");
  require(kopt.start_iterations == 0,
          "solve_hopf_krylov (full system): the start refinement (hopf_krylov_options::start_iterations = ",
          kopt.start_iterations, ") is available only in the fixed-equilibrium formulation; set it to 0");
  const Eigen::Index n = prob.n, N = prob.N;
  const Eigen::Index padded = padded_block_count(n, B) * B;
  const vec<double>& s = prob.s;
  double setup_seconds = 0, linear_seconds = 0, residual_seconds = 0;
  block_ilu_options io;
  io.fill_level = kopt.fill_level;
  io.context = opt.label + ": complex BILU(" + std::to_string(kopt.fill_level) + ") of L - i omega I";
  block_ilu<C, B> ilu(io);
  io.context = opt.label + ": real BILU(" + std::to_string(kopt.fill_level) + ") of L (flow update)";
  block_ilu<double, B> ilu_real(io);
  auto residual = [&](const vec<double>& y) {
    const auto t0 = clock::now();
    vec<double> f = prob.residual(y);
    residual_seconds += since(t0);
    return f;
  };
  long linear_iterations = 0;
  internal::hopf_iterate_log last(x, N - 2, N - 1);
  auto step = [&](const vec<double>& y, const vec<double>& f, int it) {
    last.record(y, f, it);
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> w = y.head(n), pr = y.segment(n, n), pi = y.segment(2 * n, n);
    const double fn = f.norm();
    // A, L, A_mu, f_mu at the iterate and the two BILU factorisations (A moves with w)
    auto t0 = clock::now();
    block_sparse_matrix<double, B> a, l;
    if (kopt.precondition_exact) a = internal::exact_blocks<B>(sys, w, mu, opt.label);
    else std::tie(a, l) = internal::exact_and_lhs_blocks<B>(sys, w, mu, opt.label);
    const jacobian_t<S> amu = jacobian_d_mu(sys, w, mu);
    const vec<double> fmu = residual_d_mu(sys, w, mu);
    const block_sparse_matrix<double, B>& pm = kopt.precondition_exact ? a : l;
    ilu.compute(shifted(pm, C(0.0, om)));
    ilu_real.compute(pm);
    setup_seconds += since(t0);
    krylov_options ko = kopt.krylov;
    if (kopt.adaptive_tolerance) {
      ko.relative_tolerance =
          std::min(kopt.eta_max, std::max(std::pow(fn, kopt.forcing_exponent), 0.1 * opt.newton.abs_tolerance / fn));
    }
    ko.throw_on_failure = true;
    // flow update dw = dw0 + dmu dw1 with A dw0 = -f, A dw1 = -f_mu (real BILU-GMRES)
    t0 = clock::now();
    auto flow_solve = [&](const vec<double>& b, const char* what) {
      vec<double> rhs = vec<double>::Zero(padded), d = vec<double>::Zero(padded);
      rhs.head(n) = b;
      ko.context = internal::concat(opt.label, ": GMRES on A dw", what, " at Newton iteration ", it);
      linear_iterations += gmres<double>(a, ilu_real, rhs, d, ko).iterations;
      return vec<double>(d.head(n));
    };
    const vec<double> dw0 = flow_solve(vec<double>(-f.head(n)), "0 = -f");
    const vec<double> dw1 = flow_solve(vec<double>(-fmu), "1 = -f_mu");
    linear_seconds += since(t0);
    // the second-derivative products (A_w p) dw0, (A_w p) dw1
    t0 = clock::now();
    const auto [b0r, b0i] = second_derivative_pair(sys, w, mu, pr, pi, dw0, kopt.exact_second_derivatives);
    const auto [b1r, b1i] = second_derivative_pair(sys, w, mu, pr, pi, dw1, kopt.exact_second_derivatives);
    residual_seconds += since(t0);
    // the fixed-equilibrium bordered system with the corrected right-hand side and mu column
    const internal::real_split_shifted_operator<block_sparse_matrix<double, B>> inner(a, om, n);
    const internal::complex_preconditioner_split_form<block_ilu<C, B>> inner_pre(ilu, n, padded);
    Eigen::MatrixXd u(2 * n, 2), vt = Eigen::MatrixXd::Zero(2, 2 * n);
    u.col(0) << amu * pr + b1r, amu * pi + b1i;
    u.col(1) << pi, -pr;
    vt.row(0).head(n) = s.transpose();
    vt.row(1).tail(n) = s.transpose();
    const bordered_operator<decltype(inner), double> jop(inner, 2 * n, std::move(u), std::move(vt),
                                                         Eigen::MatrixXd::Zero(2, 2));
    const bordered_preconditioner<decltype(inner_pre), double> jpre(jop, inner_pre);
    vec<double> rhs(2 * n + 2);
    rhs << -(f.segment(n, n) + b0r), -(f.segment(2 * n, n) + b0i), -f[N - 2], -f[N - 1];
    vec<double> d = vec<double>::Zero(2 * n + 2);
    ko.context = internal::concat(opt.label, ": GMRES on the bordered eigen-equations at Newton iteration ", it);
    t0 = clock::now();
    linear_iterations += gmres<double>(jop, jpre, rhs, d, ko).iterations;
    linear_seconds += since(t0);
    vec<double> dx(N);
    dx.head(n) = dw0 + d[2 * n] * dw1;
    dx.segment(n, 2 * n) = d.head(2 * n);
    dx[N - 2] = d[2 * n];
    dx[N - 1] = d[2 * n + 1];
    return dx;
  };
  newton_options nopt = opt.newton;
  add_hopf_progress(nopt, opt, N, linear_iterations);
  newton_result nr = internal::run_hopf_newton(
      [&] { return newton_iterate(residual, step, x, nopt, opt.label + " (full Hopf system, BILU-GMRES)"); }, last,
      opt);
  hopf_result res = prob.result(std::move(nr), linear_iterations, opt);
  res.setup_seconds = setup_seconds;
  res.linear_seconds = linear_seconds;
  res.residual_seconds = residual_seconds;
  return res;
}
}  // namespace internal

/// Newton on the fixed-equilibrium Hopf system with the exact bordered matrix, GMRES and the bordered
/// complex-BILU(k) preconditioner of the modified-order matrix (file comment). B is the block
/// size of the system's unknowns (4 for 2D Euler + pitch-plunge); n must be a multiple of B or
/// is padded. opt.fixed_equilibrium must be set; opt.approximate_lhs is ignored (the preconditioner
/// always uses lhs_jacobian, the operator always the exact Jacobian).
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
hopf_result solve_hopf_krylov(const S& sys, const hopf_point& guess, const hopf_options& opt,
                              const hopf_krylov_options& kopt = {}) {
  if (kopt.full_system) return internal::solve_hopf_krylov_full<B>(sys, guess, opt, kopt);
  require(opt.fixed_equilibrium,
          "solve_hopf_krylov: hopf_options::fixed_equilibrium = false (the equilibrium moves with mu) needs the full "
          "formulation: set hopf_krylov_options::full_system (or hopf_options::fixed_equilibrium for a fixed equilibrium)");
  using C = std::complex<double>;
  using M = jacobian_t<S>;
  vec<double> x;
  // validates the guess (sizes, finiteness, fixed_equilibrium option); rebuilt below if the start is refined
  std::optional<internal::fixed_equilibrium_hopf_problem<S>> prob_storage;
  prob_storage.emplace(sys, guess, opt, "solve_hopf_krylov", x);
  internal::check_hopf_krylov_options(kopt, "solve_hopf_krylov");
  const Eigen::Index n = prob_storage->n, N = prob_storage->N;
  const vec<double>& w = guess.w;  // the equilibrium (prob.w is a copy)
  double setup_seconds = 0, linear_seconds = 0, residual_seconds = 0;
  using clock = std::chrono::steady_clock;
  auto since = [](clock::time_point t0) { return std::chrono::duration<double>(clock::now() - t0).count(); };

  block_ilu_options io;
  io.fill_level = kopt.fill_level;
  io.context = opt.label + ": complex BILU(" + std::to_string(kopt.fill_level) + ") of L - i omega I";
  block_ilu<C, B> ilu(io);
  const Eigen::Index padded = padded_block_count(n, B) * B;
  M amu;
  block_sparse_matrix<double, B> a;  // exact Jacobian, blocked for a fast SpMV
  double mu0 = x[N - 2], last_norm = 0;
  // A, A_mu and the BILU of L - i omega I at (mu, omega); the exact Jacobian is assembled once
  // and also serves as L when precondition_exact.
  auto refresh = [&](double mu, double om) {
    const auto t0 = clock::now();
    block_sparse_matrix<double, B> l;
    if (kopt.precondition_exact) a = internal::exact_blocks<B>(sys, w, mu, opt.label);
    else std::tie(a, l) = internal::exact_and_lhs_blocks<B>(sys, w, mu, opt.label);
    amu = jacobian_d_mu(sys, w, mu);
    mu0 = mu;
    ilu.compute(shifted(kopt.precondition_exact ? a : l, C(0.0, om)));
    setup_seconds += since(t0);
  };
  if (kopt.reuse_matrices) refresh(x[N - 2], x[N - 1]);
  long start_linear_iterations = 0;
  bool start_refined = false;
  double f_guess = 0.0;
  if (kopt.start_iterations > 0) {
    const auto t1 = clock::now();
    f_guess = prob_storage->residual(x).norm();
    residual_seconds += since(t1);
  }
  if (kopt.start_iterations > 0 && f_guess > kopt.start_residual_threshold) {
    // inverse iteration with the shift i omega of the guess (see hopf_krylov_options)
    if (!kopt.reuse_matrices) refresh(x[N - 2], x[N - 1]);  // otherwise assembled above
    const auto t0 = clock::now();
    const double om = x[N - 1];
    const internal::real_split_shifted_operator<std::decay_t<decltype(a)>> shifted_a(a, om, n);
    const internal::complex_preconditioner_split_form<std::decay_t<decltype(ilu)>> pre(ilu, n, padded);
    hopf_point g = guess;
    vec<double> v(2 * n), y(2 * n), av(2 * n);
    v << x.head(n), x.segment(n, n);
    krylov_options ko = kopt.krylov;
    ko.relative_tolerance = kopt.start_tolerance;
    ko.max_iterations = std::min(ko.max_iterations, kopt.start_max_iterations);
    ko.throw_on_failure = false;
    ko.context = opt.label + ": start refinement";
    bool ok = true;
    for (int k = 0; k < kopt.start_iterations && ok; ++k) {
      y.setZero();
      const krylov_report rep = gmres<double>(shifted_a, pre, vec<double>(v / v.norm()), y, ko);
      start_linear_iterations += rep.iterations;
      ok = y.allFinite() && y.norm() > 0;
      if (ok) v = y / y.norm();
    }
    if (ok) {
      g.p.real() = v.head(n);
      g.p.imag() = v.tail(n);
      // Rayleigh quotient of A: omega estimate (A real: lambda = (p^H A p) / (p^H p))
      const internal::real_split_shifted_operator<std::decay_t<decltype(a)>> plain_a(a, 0.0, n);
      plain_a(v, av);
      const C pap = C(v.head(n).dot(av.head(n)) + v.tail(n).dot(av.tail(n)),
                      v.head(n).dot(av.tail(n)) - v.tail(n).dot(av.head(n)));
      if (pap.imag() * om > 0) g.omega = pap.imag();
      vec<double> xg;
      internal::fixed_equilibrium_hopf_problem<S> refined(sys, g, opt, "solve_hopf_krylov", xg);
      const auto t1 = clock::now();
      const double f_old = f_guess, f_new = refined.residual(xg).norm();
      residual_seconds += since(t1);
      if (std::isfinite(f_new) && f_new < f_old) {
        prob_storage.emplace(std::move(refined));
        x = std::move(xg);
        start_refined = true;
      }
      if (opt.verbose && opt.log)
        *opt.log << opt.label << " start: " << kopt.start_iterations << " inverse iteration(s), "
                 << start_linear_iterations << " GMRES iterations, ||F|| " << std::scientific << std::setprecision(3)
                 << f_old << " -> " << f_new << std::defaultfloat << (start_refined ? " (kept)" : " (discarded)")
                 << ", omega " << g.omega << "\n";
    }
    linear_seconds += since(t0);
  }
  const internal::fixed_equilibrium_hopf_problem<S>& prob = *prob_storage;
  const vec<double>& s = prob.s;
  auto residual = [&](const vec<double>& y) {
    const auto t0 = clock::now();
    vec<double> f = prob.residual(y);
    residual_seconds += since(t0);
    return f;
  };
  long linear_iterations = start_linear_iterations;
  internal::hopf_iterate_log last(x, N - 2, N - 1);
  auto step = [&](const vec<double>& y, const vec<double>& f, int it) {
    last.record(y, f, it);
    const double mu = y[N - 2], om = y[N - 1];
    const vec<double> pr = y.head(n), pi = y.segment(n, n);
    const double fn = f.norm();
    const bool slow = it > 1 && fn > 0.1 * last_norm;
    if (!kopt.reuse_matrices || (it > 1 && (slow || std::abs(mu - mu0) > kopt.reuse_window * (1 + std::abs(mu0)))))
      refresh(mu, om);
    last_norm = fn;
    const double dmu = mu - mu0;
    // inner operator: the real form of A - i omega I on (x_re, x_im), A = A0 + dmu A_mu0;
    // its preconditioner: the complex BILU solve in the same form
    const internal::real_split_shifted_operator<std::decay_t<decltype(a)>, std::decay_t<decltype(amu)>> inner(
        a, om, n, &amu, dmu);
    const internal::complex_preconditioner_split_form<std::decay_t<decltype(ilu)>> inner_pre(ilu, n, padded);
    Eigen::MatrixXd u(2 * n, 2), vt = Eigen::MatrixXd::Zero(2, 2 * n);
    u.col(0) << amu * pr, amu * pi;
    u.col(1) << pi, -pr;
    vt.row(0).head(n) = s.transpose();
    vt.row(1).tail(n) = s.transpose();
    const bordered_operator<decltype(inner), double> jop(inner, 2 * n, std::move(u), std::move(vt),
                                                         Eigen::MatrixXd::Zero(2, 2));
    const bordered_preconditioner<decltype(inner_pre), double> jpre(jop, inner_pre);
    krylov_options ko = kopt.krylov;
    if (kopt.adaptive_tolerance) {
      ko.relative_tolerance =
          std::min(kopt.eta_max, std::max(std::pow(fn, kopt.forcing_exponent), 0.1 * opt.newton.abs_tolerance / fn));
    }
    ko.context = internal::concat(opt.label, ": GMRES at Newton iteration ", it);
    ko.throw_on_failure = true;
    vec<double> dx = vec<double>::Zero(N);
    const vec<double> rhs = -f;
    const auto t0 = clock::now();
    const krylov_report rep = gmres<double>(jop, jpre, rhs, dx, ko);
    linear_seconds += since(t0);
    linear_iterations += rep.iterations;
    return dx;
  };
  newton_options nopt = opt.newton;
  prob.add_progress(nopt, opt, linear_iterations);
  newton_result nr = internal::run_hopf_newton(
      [&] { return newton_iterate(residual, step, x, nopt, opt.label + " (Hopf system, BILU-GMRES)"); }, last, opt);
  hopf_result res = prob.result(std::move(nr), linear_iterations, opt);
  res.setup_seconds = setup_seconds;
  res.linear_seconds = linear_seconds;
  res.residual_seconds = residual_seconds;
  res.start_refined = start_refined;
  return res;
}

/// Options of hopf_start_krylov.
struct hopf_start_krylov_options {
  int fill_level = 1;               ///< k of the complex BILU(k) of L - i omega_guess I
  bool precondition_exact = false;  ///< BILU(k) of the exact A - i omega_guess I instead
  /// GMRES of each inverse iteration: the solves must be tighter than the eigen-residual target
  /// (inexact inverse iteration with a fixed tolerance stagnates near it, inverse_power.hpp).
  krylov_options krylov = [] {
    krylov_options o;
    o.relative_tolerance = 1e-9;
    o.max_iterations = 2000;
    o.restart = 80;
    o.record_history = false;
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
/// (A - sigma I) y = x by complex GMRES on the exact A (the fused shifted block product),
/// right-preconditioned by the complex BILU(k) of L - sigma I, L = lhs_jacobian (the modified-
/// order Jacobian of the aerofoil) or A itself (precondition_exact). The matrices come from the
/// system's block_jacobians when it has them (has_block_jacobians), else from its sparse
/// Jacobians. Convergence as inverse_power: ||A x - lambda x||_2 <= max(tolerance max(1,
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
  block_sparse_matrix<double, B> a, l;
  if (o.precondition_exact) a = internal::exact_blocks<B>(sys, w, mu, who);
  else std::tie(a, l) = internal::exact_and_lhs_blocks<B>(sys, w, mu, who);
  double a_norm = 0;  // ||A||_inf over the logical rows, the scale of the attainable residual
  for (Eigen::Index bi = 0; bi < a.block_rows(); ++bi) {
    Eigen::Matrix<double, B, 1> sums = Eigen::Matrix<double, B, 1>::Zero();
    for (auto k = a.row_ptr()[bi]; k < a.row_ptr()[bi + 1]; ++k) sums += a.block_at(k).cwiseAbs().rowwise().sum();
    for (int r = 0; r < B; ++r)
      if (bi * B + r < n) a_norm = std::max(a_norm, sums[r]);
  }
  block_ilu_options io;
  io.fill_level = o.fill_level;
  io.context = internal::concat(who, ": complex BILU(", o.fill_level, ") of ", o.precondition_exact ? "A" : "L",
                                " - i omega I");
  block_ilu<C, B> ilu(io);
  ilu.compute(shifted(o.precondition_exact ? a : l, sigma));
  const shifted_operator<block_sparse_matrix<double, B>, C> op(a, sigma);
  const Eigen::Index padded = a.rows();
  vec<C> x = vec<C>::Zero(padded), y(padded), r(padded);
  x.head(n) = internal::default_start(n);
  krylov_options ko = o.krylov;
  ko.throw_on_failure = true;
  eigen_pair ep;
  const double floor = 100 * std::numeric_limits<double>::epsilon() * a_norm;
  for (int t = 1; t <= o.inverse_power.max_iterations; ++t) {
    y.setZero();
    ko.context = internal::concat(who, ": GMRES on A - i omega I (omega ", omega_guess, "), inverse iteration ", t);
    ep.linear_iterations += gmres<C>(op, ilu, x, y, ko).iterations;
    const double ny2 = y.head(n).squaredNorm();
    if (!(ny2 > 0) || !std::isfinite(ny2))
      throw convergence_error(internal::concat(who, ": iterate ", t, " is zero or not finite"));
    ep.lambda = sigma + y.head(n).dot(x.head(n)) / ny2;
    x.head(n) = y.head(n) / std::sqrt(ny2);
    a.apply_shifted(ep.lambda, x, r);
    ep.residual = r.head(n).norm();
    ep.iterations = t;
    if (o.inverse_power.verbose && o.inverse_power.log)
      *o.inverse_power.log << who << " it " << t << "  lambda " << ep.lambda << "  residual " << ep.residual << "  GMRES "
                           << ep.linear_iterations << "\n";
    if (ep.residual <= std::max(o.inverse_power.tolerance * std::max(1.0, std::abs(ep.lambda)), floor)) {
      ep.vector = x.head(n);
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
