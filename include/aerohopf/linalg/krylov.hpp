#pragma once
// Preconditioned Krylov methods for the non-symmetric (real or complex) systems of spec 07:
// GCR(m), GMRES(m), TFQMR and BiCGSTAB, all RIGHT-preconditioned (A M^{-1} u = b, x = M^{-1} u)
// so the residual they minimise or monitor is the true, unpreconditioned one, comparable
// across preconditioners and forms.
//
// WHY several methods: the original work used GCR (one operator product per step, cheap
// restarts) and Aztec's GMRES/TFQMR; GMRES minimises the residual at the price of the Arnoldi
// basis; TFQMR and BiCGSTAB use O(1) vectors (memory matters at a million cells, complex).
//
//   krylov_options opt;  opt.relative_tolerance = 1e-8;  opt.restart = 60;
//   krylov_report rep = gmres(A, M, b, x, opt);   // x: initial guess in, solution out
// A: any linear_operator (operator.hpp): block_sparse_matrix, Eigen matrix, lambda,
// shifted_operator, bordered_operator. M: identity_preconditioner{}, block_ilu, ... .
// Scalar: from b; complex scalars use the conjugating inner product <u, v> = sum conj(u_i) v_i.
// Distributed: for an A with global_sum (distributed_operator, operator.hpp), b, x and M act on
// this process's part, and GMRES sums every inner product and norm over the processes (the
// other methods refuse such an A at compile time).
// Convergence: ||b - A x|| <= max(relative_tolerance * ||b||, absolute_tolerance), judged on
// the TRUE residual (recomputed at restarts and at the end; reported as relative_residual).
// Failure is returned in the report (converged = false, reason); with throw_on_failure a
// convergence_error with the context, method, iteration and residual is thrown instead.
// Input is checked at the entry, before x is touched (input_error naming the option, vector
// or operator): options (validate_krylov_options), the sizes of b, x0 and of the operator and
// preconditioner where they report them (require_operator_size), finite b and x0; a matrix-free
// operator's or preconditioner's result is checked for size after every application.
// b = 0: x = 0 is the exact solution of every linear system, returned at once (no iteration,
// reason "zero right-hand side ...").
//
// Iteration counts: GCR/GMRES count one step per operator product; TFQMR and BiCGSTAB count
// one iteration per TWO operator products (operator_applications gives the comparable cost).
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>
#include <string_view>
#include <vector>

#include "../error.hpp"
#include "../scalar/complex.hpp"
#include "operator.hpp"

namespace aerohopf {

struct krylov_options {
  double relative_tolerance = 1e-8;  ///< on ||b - A x|| / ||b||
  double absolute_tolerance = 0.0;   ///< on ||b - A x||
  int max_iterations = 1000;         ///< Krylov iterations in total (over restarts)
  int restart = 60;                  ///< m of GCR(m) and GMRES(m)
  bool throw_on_failure = false;     ///< throw convergence_error instead of returning a failed report
  bool record_history = true;        ///< keep the residual history
  std::string context = "Krylov";    ///< prefix of error messages
  /// GMRES: classical Gram-Schmidt with a second pass where needed (true) or once (false). The
  /// second pass keeps the basis orthogonal to rounding (as modified Gram-Schmidt); once halves
  /// the passes over the basis, which dominate long cycles of cheap operators, and loses
  /// orthogonality only as the preconditioned operator's conditioning demands: GMRES then
  /// converges later but never falsely, since every cycle ends with the TRUE residual b - A x.
  bool reorthogonalize = true;
  /// The second pass runs only where the first left less than this fraction of ||A M^-1 v_j||
  /// (the Daniel-Gragg-Kaufman-Stewart test, "twice is enough": a vector that kept 1/sqrt(2) of
  /// its norm is orthogonal to the basis to rounding after one pass; PETSc's CGS refinement "if
  /// needed"). 1 gives the second pass always.
  double reorthogonalization_threshold = 0.70710678118654752;
  /// GMRES only: k of GMRES-DR(m, k) (Morgan, SIAM J. Sci. Comput. 24, 2002). At each restart
  /// the k harmonic Ritz vectors of A M^{-1} of smallest harmonic Ritz value (for a real A, the
  /// real span of the selected pairs: k + 1 where a pair is split) and the residual are kept, so
  /// the eigenvalues nearest the origin that a restart would forget stay deflated; 0 = plain
  /// restarted GMRES(m). Memory n (m + k + 3) scalars instead of n (m + 1). Needs k + 2 <= m.
  int deflation = 0;
};

/// The GMRES options of inexact Newton corrections (the equilibrium and Hopf Newton solvers):
/// GMRES-DR(80, 20), at most 2000 iterations, no history kept; the relative tolerance is the
/// caller's forcing. GMRES(50) stagnated on the AGARD coarse grid where GMRES(80) converged; the
/// deflated restarts took the AGARD medium Hopf point (M = 0.96, 0.5 % damping, 2 ranks) from
/// 1,477 GMRES iterations to 990.
inline krylov_options newton_correction_krylov_options() {
  krylov_options o;
  o.max_iterations = 2000;
  o.restart = 80;
  o.deflation = 20;
  o.record_history = false;
  return o;
}

struct krylov_report {
  std::string method;
  bool converged = false;
  std::string reason;                   ///< why the iteration stopped
  int iterations = 0;
  int operator_applications = 0;
  int preconditioner_applications = 0;
  double rhs_norm = 0.0;                ///< ||b||
  double initial_residual = 0.0;        ///< ||b - A x0|| / ||b||
  double relative_residual = 0.0;       ///< final TRUE ||b - A x|| / ||b||
  std::vector<double> residual_history; ///< relative residual (estimate) after each iteration, [0] initial
};

/// Throws input_error("<where>: <option> <value> must be ...") for an option out of range:
/// tolerances finite and >= 0 (an infinite one accepts any x), restart >= 1, max_iterations >= 0,
/// reorthogonalization_threshold in [0, 1].
inline void validate_krylov_options(const krylov_options& opt, std::string_view where) {
  require(std::isfinite(opt.relative_tolerance) && opt.relative_tolerance >= 0, where, ": relative_tolerance ",
          opt.relative_tolerance, " must be finite and >= 0");
  require(std::isfinite(opt.absolute_tolerance) && opt.absolute_tolerance >= 0, where, ": absolute_tolerance ",
          opt.absolute_tolerance, " must be finite and >= 0");
  require(opt.restart >= 1, where, ": restart ", opt.restart, " must be >= 1");
  require(opt.max_iterations >= 0, where, ": max_iterations ", opt.max_iterations, " must be >= 0");
  require(opt.reorthogonalization_threshold >= 0 && opt.reorthogonalization_threshold <= 1, where,
          ": reorthogonalization_threshold ", opt.reorthogonalization_threshold, " must be in [0, 1]");
  require(opt.deflation >= 0 && (opt.deflation == 0 || opt.deflation + 2 <= opt.restart), where, ": deflation ",
          opt.deflation, " must be 0 or in [1, restart - 2] (restart ", opt.restart, ")");
}

namespace internal {

/// Basis length of GCR(m)/GMRES(m): restart, but never more than the iterations allowed (the
/// same iterates; a huge restart would allocate n (restart + 1) scalars for nothing).
inline int krylov_basis_size(const krylov_options& o) { return std::min(o.restart, std::max(o.max_iterations, 1)); }

/// Shared bookkeeping of the four methods: counting, history, stopping test, final report.
template <class S, class Op, class Pre>
struct krylov_state {
  using real = real_of_t<S>;
  const Op& a;
  const Pre& m;
  const vec<S>& b;
  vec<S>& x;
  const krylov_options& opt;
  krylov_report rep;
  double target = 0.0;

  std::string where;  // "<context>: <method>"

  /// Sums over the processes of a distributed operator (no-op otherwise).
  template <class Derived>
  void global_sum(Eigen::MatrixBase<Derived>& v) const {
    if constexpr (distributed_operator<Op, S>) {
      static_assert(Derived::InnerStrideAtCompileTime == 1, "global_sum: contiguous values");
      a.global_sum(v.derived().data(), static_cast<int>(v.size()));
    }
  }
  real global_sum(real v) const {
    if constexpr (distributed_operator<Op, real>) a.global_sum(&v, 1);
    return v;
  }
  /// v == 0 everywhere (on every process: the answer is the same on all)
  bool all_zero(const vec<S>& v) const {
    if constexpr (distributed_operator<Op, real>) return global_sum(real(v.isZero(0.0) ? 0 : 1)) == real(0);
    else return v.isZero(0.0);
  }
  /// ||v|| of the whole (distributed) vector: sqrt of the summed squares, bitwise v.norm() for a
  /// local operator.
  real norm(const vec<S>& v) const {
    if constexpr (distributed_operator<Op, real>) return std::sqrt(global_sum(v.squaredNorm()));
    else return v.norm();
  }

  /// w -= V (V^H w) by classical Gram-Schmidt, the second pass where the first cancelled most of
  /// w (the DGKS test, krylov_options): as stable as modified Gram-Schmidt, and matrix-vector
  /// passes over the basis instead of one dot/axpy pair per column. hj gets V^H w (h2: scratch of
  /// its size); returns ||w|| after.
  template <class Basis, class Coef>
  real orthogonalize(const Basis& vj, vec<S>& w, Coef hj, Coef h2) {
    const real before = opt.reorthogonalize ? norm(w) : real(0);
    hj.noalias() = vj.adjoint() * w;
    global_sum(hj);
    w.noalias() -= vj * hj;
    real hn = norm(w);
    if (opt.reorthogonalize && !(hn > real(opt.reorthogonalization_threshold) * before)) {
      h2.noalias() = vj.adjoint() * w;
      global_sum(h2);
      w.noalias() -= vj * h2;
      hj += h2;
      hn = norm(w);
    }
    return hn;
  }

  /// End of a GMRES cycle of j steps: y = R^{-1} g (R the leading j x j upper triangle of the
  /// rotated Hessenberg matrix), x += M^{-1} V y, r = b - A x and beta = ||r||; returns y.
  template <class Mat>
  vec<S> cycle_update(const Mat& rmat, const vec<S>& g, const Mat& v, int j, vec<S>& r, vec<S>& w, vec<S>& z,
                      double& beta) {
    const vec<S> y = rmat.topLeftCorner(j, j).template triangularView<Eigen::Upper>().solve(g.head(j));
    w.noalias() = v.leftCols(j) * y;
    pre(w, z);
    x += z;
    beta = true_residual(r, w);
    return y;
  }

  /// Checks everything the caller passed (x untouched until they pass); x empty = zero guess.
  krylov_state(const char* name, const Op& a_, const Pre& m_, const vec<S>& b_, vec<S>& x_, const krylov_options& o)
      : a(a_), m(m_), b(b_), x(x_), opt(o), where(concat(o.context, ": ", name)) {
    rep.method = name;
    validate_krylov_options(opt, where);
    const Eigen::Index n = b.size();
    require_operator_size(a, n, where, "operator");
    require_operator_size(m, n, where, "preconditioner");
    require_finite(b, where, "right-hand side");
    if (x.size() != 0) {
      require_size(x.size(), n, where, "initial guess");
      require_finite(x, where, "initial guess");
    }
    rep.rhs_norm = static_cast<double>(norm(b));
    require(std::isfinite(rep.rhs_norm), where, ": right-hand side norm overflows (", rep.rhs_norm, ")");
    if (x.size() == 0) x = vec<S>::Zero(n);
    target = std::max(opt.relative_tolerance * rep.rhs_norm, opt.absolute_tolerance);
  }
  double scale() const { return rep.rhs_norm > 0 ? rep.rhs_norm : 1.0; }
  int basis_size() const { return krylov_basis_size(opt); }
  void op(const vec<S>& in, vec<S>& out) {
    apply_operator<S>(a, in, out);
    ++rep.operator_applications;
    if (out.size() != in.size()) require_size(out.size(), in.size(), where, "operator result");
  }
  void pre(const vec<S>& in, vec<S>& out) {
    apply_operator<S>(m, in, out);
    ++rep.preconditioner_applications;
    if (out.size() != in.size()) require_size(out.size(), in.size(), where, "preconditioner result");
  }
  /// b = 0: x = 0 solves A x = b exactly for any A. Reports ||A x0|| as the initial residual.
  bool zero_rhs() const { return rep.rhs_norm == 0.0; }
  krylov_report zero_solution() {
    if (!all_zero(x)) {
      vec<S> ax(b.size());
      op(x, ax);
      rep.initial_residual = static_cast<double>(norm(ax));
    }
    x.setZero();
    record(rep.initial_residual);
    rep.relative_residual = 0.0;
    rep.converged = true;
    rep.reason = "converged (zero right-hand side: x = 0 is the exact solution)";
    return rep;
  }
  /// r = b - A x; returns ||r||.
  double true_residual(vec<S>& r, vec<S>& tmp) {
    op(x, tmp);
    r = b - tmp;
    return static_cast<double>(norm(r));
  }
  void record(double rnorm) {
    if (opt.record_history) rep.residual_history.push_back(rnorm / scale());
  }
  bool out_of_iterations() const { return rep.iterations >= opt.max_iterations; }
  /// Final true residual, reason and (optionally) throw.
  krylov_report finish(vec<S>& r, vec<S>& tmp, std::string reason) {
    const double rn = true_residual(r, tmp);
    rep.relative_residual = rn / scale();
    rep.converged = std::isfinite(rn) && rn <= target * (1 + 1e-10);
    if (rep.converged) reason = "converged";
    else if (reason.empty()) reason = out_of_iterations() ? "maximum number of iterations reached" : "stopped";
    rep.reason = reason;
    if (!rep.converged && opt.throw_on_failure)
      throw convergence_error(concat(opt.context, ": ", rep.method, " did not converge (", rep.reason, ") after ",
                                     rep.iterations, " iterations, relative residual ", rep.relative_residual,
                                     ", target ", target / scale()));
    return rep;
  }
};

}  // namespace internal

namespace internal {

/// Plane rotation [c s; -conj(s) c] with c real: zeroes b under a, a <- (a/|a|) sqrt(|a|^2+|b|^2).
template <class S>
struct krylov_rotation {
  Eigen::Index row = 0;  // acts on rows (row, row + 1)
  real_of_t<S> c{};
  S s{};
  template <class V>
  void apply(V&& v) const {
    const S t = c * v(row) + s * v(row + 1);
    v(row + 1) = -Eigen::numext::conj(s) * v(row) + c * v(row + 1);
    v(row) = t;
  }
  /// The rotation zeroing v(row + 1) against v(row), applied to v; false if both are zero.
  static bool make(Eigen::Index row, S& a, S& b, krylov_rotation& out) {
    using real = real_of_t<S>;
    using std::abs;
    using std::sqrt;
    const real aa = abs(a), ab = abs(b), nu = sqrt(aa * aa + ab * ab);
    out.row = row;
    if (nu == real(0)) return false;
    if (aa == real(0)) {
      out.c = real(0);
      out.s = Eigen::numext::conj(b) / S(ab);
      a = S(ab);
    } else {
      out.c = aa / nu;
      out.s = (a / S(aa)) * Eigen::numext::conj(b) / S(nu);
      a = (a / S(aa)) * S(nu);
    }
    b = S(0.0);
    return true;
  }
};

template <class S>
std::complex<double> to_complex_double(const S& v) {
  return {static_cast<double>(Eigen::numext::real(v)), static_cast<double>(Eigen::numext::imag(v))};
}

/// The orthonormal basis (columns of q, m x kept) of the real (real S) or complex span of the
/// harmonic Ritz vectors of the k smallest harmonic Ritz values of the Arnoldi relation
/// A M^{-1} V_m = V_{m+1} hbar, i.e. the eigenvectors of H_m + |h_{m+1,m}|^2 H_m^{-H} e_m e_m^T.
/// The small eigenproblem is solved in complex double (it only chooses the subspace; the
/// projected matrices are formed in S). Returns 0 where H_m is singular or nothing is found.
template <class S>
int harmonic_ritz_basis(const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>& hbar, int m, int k, int kmax,
                        Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>& q) {
  using cd = std::complex<double>;
  using cmat = Eigen::Matrix<cd, Eigen::Dynamic, Eigen::Dynamic>;
  using real = real_of_t<S>;
  cmat hm(m, m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < m; ++i) hm(i, j) = to_complex_double(hbar(i, j));
  const double hlast = std::abs(to_complex_double(hbar(m, m - 1)));
  const Eigen::PartialPivLU<cmat> lu(hm.adjoint());
  if (!(std::abs(lu.determinant()) > 0.0) || !(lu.rcond() > 1e-14)) return 0;
  Eigen::VectorXcd em = Eigen::VectorXcd::Zero(m);
  em(m - 1) = 1.0;
  const Eigen::VectorXcd f = lu.solve(em);
  cmat g = hm;
  g.col(m - 1) += (hlast * hlast) * f;
  if (!g.allFinite()) return 0;
  const Eigen::ComplexEigenSolver<cmat> es(g);
  if (es.info() != Eigen::Success) return 0;
  std::vector<int> order(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) order[static_cast<std::size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(es.eigenvalues()(a)) < std::abs(es.eigenvalues()(b)); });
  // candidates: the selected eigenvectors, or for a real S their real and imaginary parts
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> cand(m, 2 * k);
  int nc = 0;
  for (int t = 0; t < k; ++t) {
    const Eigen::VectorXcd e = es.eigenvectors().col(order[static_cast<std::size_t>(t)]);
    if constexpr (is_complex_v<S>) {
      for (int i = 0; i < m; ++i) cand(i, nc) = S(real(e(i).real()), real(e(i).imag()));
      ++nc;
    } else {
      for (int i = 0; i < m; ++i) cand(i, nc) = S(e(i).real());
      ++nc;
      if (e.imag().norm() > 1e-12 * e.norm()) {
        for (int i = 0; i < m; ++i) cand(i, nc) = S(e(i).imag());
        ++nc;
      }
    }
  }
  // orthonormalise (Gram-Schmidt twice), dropping dependent candidates (a pair's partner adds
  // nothing to the real span), at most kmax vectors
  q.resize(m, kmax);
  int kept = 0;
  for (int t = 0; t < nc && kept < kmax; ++t) {
    auto v = cand.col(t);
    const real before = v.norm();
    if (!(before > real(0))) continue;
    for (int pass = 0; pass < 2; ++pass) v -= q.leftCols(kept) * (q.leftCols(kept).adjoint() * v);
    const real after = v.norm();
    if (!(after > real(1e-8) * before)) continue;
    q.col(kept++) = v / S(after);
  }
  return kept;
}

/// GMRES-DR(m, k) (krylov_options::deflation): GMRES(m) whose restarts keep the harmonic Ritz
/// vectors of the k smallest harmonic Ritz values. Cycle: the basis V_{kk+1} carried over (kk = 0
/// at the start and after a plain restart) with A M^{-1} V_kk = V_{kk+1} H_kk (dense (kk+1) x kk),
/// extended by Arnoldi to m columns; the least squares problem by Givens rotations (the dense
/// leading block first, then one rotation per step); x += M^{-1} V y; then with P_k the
/// orthonormal harmonic Ritz basis and P_{k+1} = [P_k; 0] plus the residual coordinates
/// c - hbar y, the new V_{k+1} = V_{m+1} P_{k+1}, H_k = P_{k+1}^H hbar P_k and right-hand side
/// P_{k+1}^H (c - hbar y) are exact (the harmonic Ritz residuals are parallel to the GMRES
/// residual). Convergence is judged on the true residual after every cycle as in gmres; where
/// the coordinate residual disagrees with the true one (lost orthogonality) or H_m is singular,
/// the restart is a plain one from the true residual.
template <class S, class Op, class Pre>
krylov_report gmres_deflated(const Op& a, const Pre& m_pre, const vec<S>& b, vec<S>& x, const krylov_options& opt) {
  internal::krylov_state<S, Op, Pre> st("GMRES-DR", a, m_pre, b, x, opt);
  if (st.zero_rhs()) return st.zero_solution();
  using real = real_of_t<S>;
  using mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Index n = b.size();
  const int m = st.basis_size();
  const int k = opt.deflation;
  const int kmax = std::min(k + 1, m - 2);  // a real S keeps a split pair whole
  vec<S> r(n), w(n), z(n);
  double beta = st.true_residual(r, w);
  st.rep.initial_residual = beta / st.scale();
  st.record(beta);
  mat v(n, m + 1), vk(n, kmax + 1);
  mat hbar = mat::Zero(m + 1, m), rr = mat::Zero(m + 1, m), q, p(m + 1, kmax + 1);
  vec<S> c = vec<S>::Zero(m + 1), g(m + 1), hc(m + 1), hc2(m + 1), res(m + 1);
  std::vector<krylov_rotation<S>> rot;
  rot.reserve(static_cast<std::size_t>(kmax * (kmax + 1) / 2 + m));
  std::string reason;
  int kk = 0;  // carried-over columns with a known H block
  bool fresh = true;
  while (true) {
    if (!std::isfinite(beta)) {
      reason = "non-finite residual";
      break;
    }
    if (beta <= st.target || st.out_of_iterations()) break;
    if (fresh) {  // plain (re)start from the true residual
      kk = 0;
      v.col(0) = r / S(beta);
      c.setZero();
      c(0) = S(beta);
      hbar.setZero();
    }
    // QR of the carried-over (kk+1) x kk block by rotations, bottom-up in each column
    rot.clear();
    rr.setZero();
    rr.topLeftCorner(kk + 1, kk) = hbar.topLeftCorner(kk + 1, kk);
    g = c;
    for (int i = 0; i < kk; ++i)
      for (int row = kk - 1; row >= i; --row) {
        krylov_rotation<S> rt;
        if (!krylov_rotation<S>::make(row, rr(row, i), rr(row + 1, i), rt)) continue;
        for (int j = i + 1; j < kk; ++j) rt.apply(rr.col(j));
        rt.apply(g);
        rot.push_back(rt);
      }
    int j = kk;
    bool breakdown = false;
    while (j < m && !st.out_of_iterations()) {
      z = v.col(j);
      st.pre(z, r);  // r as scratch: M^{-1} v_j
      st.op(r, w);
      const real hn = st.orthogonalize(v.leftCols(j + 1), w, hc.head(j + 1), hc2.head(j + 1));
      hbar.col(j).head(j + 1) = hc.head(j + 1);
      hbar(j + 1, j) = S(hn);
      auto col = rr.col(j);
      col.head(j + 2) = hbar.col(j).head(j + 2);
      for (const auto& rt : rot) rt.apply(col);
      krylov_rotation<S> rt;
      if (!krylov_rotation<S>::make(j, col(j), col(j + 1), rt)) {  // singular
        breakdown = true;
        break;
      }
      rt.apply(g);
      rot.push_back(rt);
      ++st.rep.iterations;
      const double est = static_cast<double>(std::abs(g(j + 1)));
      st.record(est);
      ++j;
      if (!std::isfinite(est)) break;
      if (hn == real(0)) {
        breakdown = true;
        break;
      }
      if (est <= st.target) break;
      v.col(j) = w / S(hn);
    }
    if (j == 0) {  // A M^{-1} v_0 = 0 at the first step
      reason = "breakdown (singular preconditioned operator?)";
      break;
    }
    const vec<S> y = st.cycle_update(rr, g, v, j, r, w, z, beta);
    if (breakdown && beta > st.target) {
      reason = "breakdown (singular preconditioned operator?)";
      break;
    }
    fresh = true;
    if (j < m || beta <= st.target || st.out_of_iterations() || !std::isfinite(beta)) continue;
    // deflated restart
    res = c;
    res.noalias() -= hbar * y;
    if (!(std::abs(static_cast<double>(res.norm()) - beta) <= 1e-6 * beta)) continue;  // lost orthogonality
    if constexpr (distributed_operator<Op, real>) {
      // the same small matrices on every process (their reductions may differ in the last bits
      // between processes, and the choice of Ritz vectors is discrete): the processes' mean
      const real processes = st.global_sum(real(1));
      st.global_sum(hbar);
      hbar /= S(processes);
      st.global_sum(res);
      res /= S(processes);
    }
    const int kn = harmonic_ritz_basis(hbar, m, k, kmax, q);
    if (kn == 0) continue;
    p.setZero();
    p.topLeftCorner(m, kn) = q.leftCols(kn);
    auto pr = p.col(kn);
    pr = res;
    for (int pass = 0; pass < 2; ++pass) pr -= p.leftCols(kn) * (p.leftCols(kn).adjoint() * pr);
    const real prn = pr.norm();
    if (!(prn > real(1e-12) * res.norm())) continue;
    pr /= S(prn);
    const auto pk1 = p.leftCols(kn + 1);
    const mat hnew = pk1.adjoint() * hbar * p.topLeftCorner(m, kn);
    c.setZero();
    c.head(kn + 1) = pk1.adjoint() * res;
    vk.leftCols(kn + 1).noalias() = v * pk1;
    v.leftCols(kn + 1) = vk.leftCols(kn + 1);
    hbar.setZero();
    hbar.topLeftCorner(kn + 1, kn) = hnew;
    kk = kn;
    fresh = false;
  }
  return st.finish(r, w, reason);
}

}  // namespace internal

/// Right-preconditioned restarted GMRES(m) (Arnoldi with classical Gram-Schmidt, twice where needed,
/// complex Givens rotations). The solution update M^{-1}(V y) is formed once per cycle, so no preconditioned
/// basis is stored (n (m+1) scalars of memory).
template <class S, class Op, class Pre>
krylov_report gmres(const Op& a, const Pre& m_pre, const vec<S>& b, vec<S>& x, const krylov_options& opt = {}) {
  if (opt.deflation > 0 && opt.deflation + 2 <= internal::krylov_basis_size(opt))
    return internal::gmres_deflated(a, m_pre, b, x, opt);
  internal::krylov_state<S, Op, Pre> st("GMRES", a, m_pre, b, x, opt);
  if (st.zero_rhs()) return st.zero_solution();
  using real = real_of_t<S>;
  const Eigen::Index n = b.size();
  const int m = st.basis_size();
  vec<S> r(n), w(n), z(n);
  double beta = st.true_residual(r, w);
  st.rep.initial_residual = beta / st.scale();
  st.record(beta);
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> v(n, m + 1), h = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Zero(m + 1, m);
  vec<S> g(m + 1), hc(m + 1), hc2(m + 1);
  std::vector<internal::krylov_rotation<S>> rot;
  rot.reserve(static_cast<std::size_t>(m));
  std::string reason;
  while (true) {
    if (!std::isfinite(beta)) {
      reason = "non-finite residual";
      break;
    }
    if (beta <= st.target || st.out_of_iterations()) break;
    v.col(0) = r / S(beta);
    g.setZero();
    g(0) = S(beta);
    rot.clear();
    int j = 0;
    bool breakdown = false;
    while (j < m && !st.out_of_iterations()) {
      z = v.col(j);
      st.pre(z, r);  // r used as scratch: M^{-1} v_j
      st.op(r, w);
      const real hn = st.orthogonalize(v.leftCols(j + 1), w, hc.head(j + 1), hc2.head(j + 1));
      auto col = h.col(j);  // rotated in place: R of the cycle's QR
      col.head(j + 1) = hc.head(j + 1);
      col(j + 1) = S(hn);
      for (const auto& rt : rot) rt.apply(col);
      internal::krylov_rotation<S> rt;
      if (!internal::krylov_rotation<S>::make(j, col(j), col(j + 1), rt)) {
        breakdown = true;  // A M^{-1} v_j in span(v_0..v_{j-1}) and h_jj = 0: singular
        break;
      }
      rt.apply(g);
      rot.push_back(rt);
      ++st.rep.iterations;
      const double est = static_cast<double>(std::abs(g(j + 1)));
      st.record(est);
      ++j;
      if (!std::isfinite(est)) break;
      if (hn == real(0)) {
        breakdown = true;  // invariant subspace: the solution is in the current space
        break;
      }
      if (est <= st.target) break;
      v.col(j) = w / S(hn);
    }
    st.cycle_update(h, g, v, j, r, w, z, beta);
    if (breakdown && beta > st.target) {
      reason = "breakdown (singular preconditioned operator?)";
      break;
    }
  }
  return st.finish(r, w, reason);
}

/// Right-preconditioned restarted GCR(m): u_j = M^{-1} r_j, c_j = A u_j orthonormalised
/// against the previous c_i (the same combination applied to u), then x += <c_j, r> u_j,
/// r -= <c_j, r> c_j. One operator product per step; 2m stored vectors.
template <class S, class Op, class Pre>
krylov_report gcr(const Op& a, const Pre& m_pre, const vec<S>& b, vec<S>& x, const krylov_options& opt = {}) {
  static_assert(!distributed_operator<Op, S>, "gcr: distributed operators are solved by gmres");
  internal::krylov_state<S, Op, Pre> st("GCR", a, m_pre, b, x, opt);
  if (st.zero_rhs()) return st.zero_solution();
  using real = real_of_t<S>;
  const Eigen::Index n = b.size();
  const int m = st.basis_size();
  vec<S> r(n), tmp(n);
  double rn = st.true_residual(r, tmp);
  st.rep.initial_residual = rn / st.scale();
  st.record(rn);
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> u(n, m), c(n, m);
  std::string reason;
  vec<S> uj(n), cj(n);
  while (reason.empty() && std::isfinite(rn) && rn > st.target && !st.out_of_iterations()) {
    for (int j = 0; j < m && !st.out_of_iterations(); ++j) {
      st.pre(r, uj);
      st.op(uj, cj);
      for (int i = 0; i < j; ++i) {
        const S beta = c.col(i).dot(cj);
        cj -= beta * c.col(i);
        uj -= beta * u.col(i);
      }
      const real nc = cj.norm();
      if (!(nc > real(0))) {
        reason = std::isfinite(static_cast<double>(nc)) ? "breakdown (A M^{-1} r = 0)" : "non-finite residual";
        break;
      }
      c.col(j) = cj / S(nc);
      u.col(j) = uj / S(nc);
      const S alpha = c.col(j).dot(r);
      x += alpha * u.col(j);
      r -= alpha * c.col(j);
      ++st.rep.iterations;
      rn = static_cast<double>(r.norm());
      st.record(rn);
      if (!std::isfinite(rn)) {
        reason = "non-finite residual";
        break;
      }
      if (rn <= st.target) break;
    }
    if (reason.empty()) rn = st.true_residual(r, tmp);  // restart from the true residual
  }
  return st.finish(r, tmp, reason);
}

/// Right-preconditioned BiCGSTAB (van der Vorst); shadow residual = initial residual.
template <class S, class Op, class Pre>
krylov_report bicgstab(const Op& a, const Pre& m_pre, const vec<S>& b, vec<S>& x, const krylov_options& opt = {}) {
  static_assert(!distributed_operator<Op, S>, "bicgstab: distributed operators are solved by gmres");
  internal::krylov_state<S, Op, Pre> st("BiCGSTAB", a, m_pre, b, x, opt);
  if (st.zero_rhs()) return st.zero_solution();
  const Eigen::Index n = b.size();
  vec<S> r(n), tmp(n);
  double rn = st.true_residual(r, tmp);
  st.rep.initial_residual = rn / st.scale();
  st.record(rn);
  std::string reason;
  vec<S> rhat(n), p(n), v(n), phat(n), s(n), shat(n), t(n);
  while (reason.empty() && std::isfinite(rn) && rn > st.target && !st.out_of_iterations()) {
    // (re)start from the current true residual
    const double cycle_start = rn;
    rhat = r;
    S rho(1.0), alpha(1.0), omega(1.0);
    v.setZero();
    p.setZero();
    while (!st.out_of_iterations()) {
      const S rho_new = rhat.dot(r);
      if (rho_new == S(0.0)) break;  // restart with a fresh shadow residual
      const S beta = (rho_new / rho) * (alpha / omega);
      p = r + beta * (p - omega * v);
      st.pre(p, phat);
      st.op(phat, v);
      const S sigma = rhat.dot(v);
      if (sigma == S(0.0)) {
        reason = "breakdown (<r^, A M^{-1} p> = 0)";
        break;
      }
      alpha = rho_new / sigma;
      s = r - alpha * v;
      ++st.rep.iterations;
      const double sn = static_cast<double>(s.norm());
      if (sn <= st.target) {
        x += alpha * phat;
        r = s;
        rn = sn;
        st.record(rn);
        break;
      }
      st.pre(s, shat);
      st.op(shat, t);
      const double tt = static_cast<double>(t.squaredNorm());
      omega = tt > 0 ? S(t.dot(s) / S(tt)) : S(0.0);
      x += alpha * phat + omega * shat;
      r = s - omega * t;
      rho = rho_new;
      rn = static_cast<double>(r.norm());
      st.record(rn);
      if (!std::isfinite(rn)) {
        reason = "non-finite residual";
        break;
      }
      if (rn <= st.target || omega == S(0.0)) break;
    }
    if (reason.empty()) {  // restart from the true residual; give up if a cycle gained nothing
      rn = st.true_residual(r, tmp);
      if (!(rn < cycle_start)) reason = "stagnation";
    }
  }
  return st.finish(r, tmp, reason);
}

/// Right-preconditioned transpose-free QMR (Freund 1993), in the two-half-steps form; the
/// QMR bound tau sqrt(m+1) is the stopping estimate, confirmed on the true residual.
template <class S, class Op, class Pre>
krylov_report tfqmr(const Op& a, const Pre& m_pre, const vec<S>& b, vec<S>& x, const krylov_options& opt = {}) {
  static_assert(!distributed_operator<Op, S>, "tfqmr: distributed operators are solved by gmres");
  internal::krylov_state<S, Op, Pre> st("TFQMR", a, m_pre, b, x, opt);
  if (st.zero_rhs()) return st.zero_solution();
  using real = real_of_t<S>;
  const Eigen::Index n = b.size();
  vec<S> r(n), tmp(n);
  double rn = st.true_residual(r, tmp);
  st.rep.initial_residual = rn / st.scale();
  st.record(rn);
  std::string reason;
  vec<S> rhat(n), w(n), y1(n), y2(n), z(n), u1(n), u2(n), v(n), d(n);
  while (reason.empty() && std::isfinite(rn) && rn > st.target && !st.out_of_iterations()) {
    const double cycle_start = rn;
    rhat = r;
    w = r;
    y1 = r;
    st.pre(y1, z);
    st.op(z, u1);
    v = u1;
    d.setZero();
    real theta(0), tau = static_cast<real>(rn);
    S eta(0.0);
    S rho = rhat.dot(r);
    bool done = false;
    for (int k = 1; !st.out_of_iterations() && !done; ++k) {
      const S sigma = rhat.dot(v);
      if (sigma == S(0.0) || rho == S(0.0)) break;  // restart
      const S alpha = rho / sigma;
      for (int j = 1; j <= 2; ++j) {
        if (j == 2) {  // (for j = 1, z = M^{-1} y1 is still there from forming u1)
          y2 = y1 - alpha * v;
          st.pre(y2, z);
          st.op(z, u2);
        }
        w -= alpha * (j == 1 ? u1 : u2);
        d = z + (S(theta * theta) * eta / alpha) * d;  // d lives in x space: M^{-1} of Freund's d
        theta = static_cast<real>(w.norm()) / tau;
        const real c = real(1) / std::sqrt(real(1) + theta * theta);
        tau = tau * theta * c;
        eta = S(c * c) * alpha;
        x += eta * d;
        const double est = static_cast<double>(tau) * std::sqrt(2.0 * k - 2 + j + 1);
        if (!std::isfinite(est)) {
          reason = "non-finite residual";
          done = true;
          break;
        }
        if (est <= st.target) {
          done = true;
          break;
        }
      }
      ++st.rep.iterations;
      st.record(static_cast<double>(tau) * std::sqrt(2.0 * k + 1));
      if (done) break;
      const S rho_new = rhat.dot(w);
      const S beta = rho_new / rho;
      rho = rho_new;
      y1 = w + beta * y2;
      st.pre(y1, z);
      st.op(z, u1);
      v = u1 + beta * (u2 + beta * v);
    }
    if (reason.empty()) {
      rn = st.true_residual(r, tmp);
      if (!(rn < cycle_start)) reason = "stagnation";
    }
  }
  return st.finish(r, tmp, reason);
}

}  // namespace aerohopf
