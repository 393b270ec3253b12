#pragma once
// The Hopf (flutter) point of an aeroelastic system on MPI ranks (a model derived from
// distributed_bordered, mpi_bordered.hpp: the pitch-plunge aerofoil with parameter Ubar, the
// modal wing with parameter mu), in both formulations of bifurcation/hopf.hpp:
//  * fixed equilibrium: unknowns [p_r, p_i, mu, omega], w given (the structure at rest at zero
//    incidence, the equilibrium independent of mu);
//  * full: unknowns [w, p_r, p_i, mu, omega], the equilibrium moving with mu (a mean incidence:
//    the static deflection depends on mu).
// F_A as in hopf.hpp, with the normalisation s = e_k, k the largest component of the start's p
// over all ranks (p_k = i), so F_A's border rows are sparse on the ranks too.
//
// Vectors: each rank holds its part of w, p_r and p_i (the model's local order: its flow
// values, then the structure, significant on the root); mu and omega are held by every rank,
// and in the Newton correction, as the structure, on the root only, so that a sum over the
// ranks of local inner products counts every unknown once.
//
// Newton step: the bordered elimination of hopf_bordered.hpp (bordered_hopf_step), every solve
// by GMRES on the ranks.
//  * The eigen-equations and the border: GMRES on the exact real (2n + 2) bordered matrix, its
//    inner operator the complex product with J - i omega I (the Jacobian rows assembled on the
//    ranks, distributed_bordered::multiply), right-preconditioned by the complex block-Jacobi
//    BILU(k) of L - i omega I (L the modified-order rows, the structural border eliminated exactly:
//    basic_distributed_bordered_preconditioner) with the two Hopf border unknowns eliminated
//    around it. The mu column A_mu p is the model's parameter_column.
//  * The full formulation's flow update: dw0 = -A^{-1} f, dw1 = -A^{-1} f_mu by real GMRES on
//    A preconditioned by the real BILU(k) of L; the second-derivative products (A_w p) dw by
//    central differences of the Jacobian rows re-assembled at w +- h dw (O(h^2): the rate of
//    Newton's convergence only).
// F_A is evaluated with the exact Jacobian rows at the iterate. mu enters only the structural
// border (the aerofoil's stiffness, the wing's force scale), so in the fixed-equilibrium
// formulation the rows are assembled once and moved to each iterate's mu exactly (the model's
// set_parameter): the operator of every GMRES solve is the exact Jacobian and the convergence
// is quadratic with inexact solves. The preconditioner is computed at the start and again after
// a step that reduced ||F|| less than tenfold; in the full formulation everything is
// re-assembled at every iterate (A moves with w).
//
// Start refinement (fixed formulation, distributed_hopf_options::start_iterations, as the serial
// solve_hopf_krylov's): a continued guess whose eigenvector is far off (||F|| above a threshold)
// is first improved by inverse iteration at i omega with the Newton preconditioner; omega is then
// the Rayleigh quotient's imaginary part, and the refined start is kept if ||F|| drops.
//
// Stopping and checks (as hopf.hpp, sums over the ranks): ||F_A|| <= abs_tolerance +
// rel_tolerance ||F_A(start)|| (hopf_options::newton; its rounding-floor test is not used);
// failure (convergence_error on every rank, naming the iterate, ||F||, mu and omega) on a
// non-finite or diverging residual (> divergence_factor ||F_0||), a residual that grows more than
// max_contraction-fold in one step from iteration contraction_from on, a GMRES failure, or the
// iteration limit; with newton.throw_on_failure = false the result holds the last iterate
// instead, report.converged = false. A converged point is accepted if the equilibrium holds at
// mu* (fixed formulation: ||f(w, mu*)|| <= max(equilibrium_tolerance, equilibrium_factor
// ||F||)) and omega is resolved (|omega| > 10 ||F|| / ||p||); omega > 0 on return. Messages
// name the parameter as the model does (Ubar, mu).

#include <mpi.h>

#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/bifurcation/hopf_bordered.hpp>
#include <aerohopf/bifurcation/vg_diagram.hpp>
#include <aerohopf/distributed/mpi_bordered.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <iomanip>
#include <limits>
#include <string>
#include <vector>

namespace aerohopf::distributed {

struct distributed_hopf_options {
  /// Newton tolerances and limits, formulation (fixed_equilibrium), acceptance, progress and
  /// label, as for the serial solvers (normalisation and approximate_lhs do not apply).
  hopf_options hopf;
  int fill_level = 0;  ///< k of the block-Jacobi BILU(k)
  bool single_precision_factors = true;  ///< as hopf_krylov_options
  /// GMRES of each correction: relative tolerance eta_k = min(eta_max, max(||F_k||, 0.1
  /// abs_tolerance / ||F_k||)) (inexact Newton, quadratic), restart and iteration limit.
  krylov_options krylov = newton_correction_krylov_options();
  double eta_max = 1e-2;
  /// Start refinement (fixed formulation; as hopf_krylov_options): where ||F(guess)|| >
  /// start_residual_threshold, start_iterations inverse iterations at i omega from the guess's p
  /// (complex GMRES to start_tolerance, at most start_max_iterations, with the Newton
  /// preconditioner), omega from the Rayleigh quotient; the refined start is kept if its ||F|| is
  /// smaller. 0: off.
  int start_iterations = 0;
  double start_tolerance = 1e-2;
  int start_max_iterations = 100;
  double start_residual_threshold = 0.0;
};

/// A Hopf point's guess or result on the ranks: this rank's parts of w and p.
struct distributed_hopf_point {
  vec<double> w;                   ///< this rank's part of the equilibrium
  double mu = NAN, omega = NAN;    ///< the parameter (Ubar, mu) and omega (every rank)
  vec<std::complex<double>> p;     ///< this rank's part of the eigenvector
};

struct distributed_hopf_result {
  distributed_hopf_point point;  ///< p with p_k = i at the normalisation's component k
  newton_report report;
  long linear_iterations = 0;    ///< GMRES iterations over all solves
  double setup_seconds = 0, linear_seconds = 0, residual_seconds = 0;
  bool start_refined = false;    ///< the start refinement (start_iterations) was kept
};

namespace internal {

/// The real (2n + 2) bordered matrix of the eigen-equations in the real split form on the ranks:
/// v = [x_r, x_i, a, b] (each rank its parts of x_r and x_i; a, b on the root) ->
///   [(J x)_r + omega x_i + a m_r + b p_i;  (J x)_i - omega x_r + a m_i - b p_r;  s.x_r;  s.x_i]
/// with m = the mu column and s the normalisation (sums over the ranks, rows on the root).
template <int Dim>
class hopf_bordered_operator {
 public:
  using C = std::complex<double>;
  hopf_bordered_operator(distributed_bordered<Dim>& d, const bordered_rows<Dim>& j, double omega,
                         vec<double> mu_column, const vec<double>& pr, const vec<double>& pi, const vec<double>& s)
      : d_(&d), j_(&j), omega_(omega), n_(d.local_size()), mu_col_(std::move(mu_column)), om_col_(2 * n_), s_(&s) {
    om_col_ << pi, -pr;
  }
  Eigen::Index rows() const { return 2 * n_ + 2; }
  Eigen::Index cols() const { return 2 * n_ + 2; }
  const vec<double>& mu_column() const { return mu_col_; }
  const vec<double>& omega_column() const { return om_col_; }
  const vec<double>& s() const { return *s_; }
  void apply(const vec<double>& v, vec<double>& y) const {
    std::array<double, 2> ab{v[2 * n_], v[2 * n_ + 1]};  // the root's, summed: the others hold zeros
    d_->sum(ab.data(), 2);
    vec<C> x(n_);
    x.real() = v.head(n_);
    x.imag() = v.segment(n_, n_);
    const vec<C> jx = d_->multiply(*j_, x);
    y.resize(rows());
    y.head(n_) = jx.real() + omega_ * v.segment(n_, n_);
    y.segment(n_, n_) = jx.imag() - omega_ * v.head(n_);
    y.head(2 * n_) += ab[0] * mu_col_ + ab[1] * om_col_;
    std::array<double, 2> sx{s_->dot(v.head(n_)), s_->dot(v.segment(n_, n_))};
    d_->sum(sx.data(), 2);
    y[2 * n_] = d_->rank() == distributed_bordered<Dim>::root ? sx[0] : 0.0;
    y[2 * n_ + 1] = d_->rank() == distributed_bordered<Dim>::root ? sx[1] : 0.0;
  }
  void global_sum(double* p, int n) const { d_->sum(p, n); }

 private:
  distributed_bordered<Dim>* d_;
  const bordered_rows<Dim>* j_;
  double omega_;
  Eigen::Index n_;
  vec<double> mu_col_, om_col_;
  const vec<double>* s_;
};

/// Its preconditioner: the complex preconditioner M of L - i omega I in the split form, the two
/// border unknowns eliminated around it (W = M^{-1} [m, omega column], 2 x 2 Schur complement
/// -s^T W summed over the ranks): one application of M and one reduction of four values.
template <int Dim>
class hopf_bordered_preconditioner {
 public:
  using C = std::complex<double>;
  hopf_bordered_preconditioner(const basic_distributed_bordered_preconditioner<Dim, std::complex<double>>& m,
                               distributed_bordered<Dim>& d, const hopf_bordered_operator<Dim>& op)
      : m_(&m), d_(&d), n_(d.local_size()), s_(&op.s()), w_(2 * n_, 2) {
    vec<double> z(2 * n_);
    split_apply(op.mu_column(), z);
    w_.col(0) = z;
    split_apply(op.omega_column(), z);
    w_.col(1) = z;
    std::array<double, 4> vw{};
    for (int c = 0; c < 2; ++c) {
      vw[c] = s_->dot(w_.col(c).head(n_));
      vw[2 + c] = s_->dot(w_.col(c).segment(n_, n_));
    }
    d.sum(vw.data(), 4);
    Eigen::Matrix2d schur;
    schur << -vw[0], -vw[1], -vw[2], -vw[3];
    if (!schur.allFinite() || !(std::abs(schur.determinant()) > 0))
      throw singular_matrix_error(aerohopf::internal::concat(
          "distributed Hopf preconditioner: the 2 x 2 Schur complement of the border is singular or not finite (det ",
          schur.determinant(), "): the parameter and omega not determined"));
    schur_inv_ = schur.inverse();
  }
  Eigen::Index rows() const { return 2 * n_ + 2; }
  void apply(const vec<double>& r, vec<double>& z) const {
    vec<double> z1(2 * n_);
    split_apply(r.head(2 * n_), z1);
    const bool root = d_->rank() == distributed_bordered<Dim>::root;  // the border rows: the root's
    std::array<double, 2> t{(root ? r[2 * n_] : 0.0) - s_->dot(z1.head(n_)),
                            (root ? r[2 * n_ + 1] : 0.0) - s_->dot(z1.segment(n_, n_))};
    d_->sum(t.data(), 2);
    // element by element: GCC 12 with AVX-512 warns falsely on fixed 2-vectors mixed with dynamic ones
    const double s0 = schur_inv_(0, 0) * t[0] + schur_inv_(0, 1) * t[1];
    const double s1 = schur_inv_(1, 0) * t[0] + schur_inv_(1, 1) * t[1];
    const std::array<double, 2> sol{s0, s1};
    z.resize(rows());
    z.head(2 * n_) = z1 - s0 * w_.col(0) - s1 * w_.col(1);
    z[2 * n_] = d_->rank() == distributed_bordered<Dim>::root ? sol[0] : 0.0;
    z[2 * n_ + 1] = d_->rank() == distributed_bordered<Dim>::root ? sol[1] : 0.0;
  }

 private:
  template <class V>
  void split_apply(const V& r, vec<double>& z) const {
    vec<C> rc(n_), zc(n_);
    rc.real() = r.head(n_);
    rc.imag() = r.segment(n_, n_);
    m_->apply(rc, zc);
    z.head(n_) = zc.real();
    z.segment(n_, n_) = zc.imag();
  }
  const basic_distributed_bordered_preconditioner<Dim, std::complex<double>>* m_;
  distributed_bordered<Dim>* d_;
  Eigen::Index n_;
  const vec<double>* s_;
  Eigen::MatrixXd w_;
  Eigen::Matrix2d schur_inv_;
};

}  // namespace internal

/// Newton on the Hopf system of a distributed model (distributed_aerofoil, distributed_wing)
/// from `guess` (file comment), the
/// formulation from opt.hopf.fixed_equilibrium. Collective: every rank passes its parts and gets
/// the same mu*, omega* and its part of w* and p*. input_error (every rank) for a guess of the
/// wrong sizes, not finite, a zero eigenvector or bad options; convergence_error or
/// singular_matrix_error (every rank) for a failure, as the file comment says.
template <class D>
distributed_hopf_result solve_hopf(D& d, const distributed_hopf_point& guess,
                                          const distributed_hopf_options& opt = {}) {
  using C = std::complex<double>;
  constexpr int dim = D::nv - 2;
  const hopf_options& ho = opt.hopf;
  const bool fixed = ho.fixed_equilibrium;
  const std::string who = fixed ? "distributed solve_hopf" : "distributed solve_hopf (full system)";
  const std::string label = ho.label;
  const MPI_Comm comm = d.communicator();
  const Eigen::Index n = d.local_size();
  const bool root = d.rank() == D::root;
  const std::string param = d.parameter_name();
  internal::collective(comm, who.c_str(), [&] {
    aerohopf::internal::check_hopf_options(ho, who);
    validate_krylov_options(opt.krylov, who);
    require(opt.fill_level >= 0 && opt.fill_level <= 8, who, ": fill_level must lie in [0, 8] (got ", opt.fill_level,
            ")");
    require(opt.eta_max > 0 && opt.eta_max < 1, who, ": eta_max must lie in (0, 1) (got ", opt.eta_max, ")");
    require(opt.start_iterations >= 0, who, ": start_iterations must be >= 0 (got ", opt.start_iterations, ")");
    require(opt.start_tolerance > 0 && opt.start_tolerance < 1, who, ": start_tolerance must lie in (0, 1) (got ",
            opt.start_tolerance, ")");
    require(opt.start_max_iterations >= 1, who, ": start_max_iterations must be >= 1 (got ", opt.start_max_iterations,
            ")");
    require(std::isfinite(opt.start_residual_threshold) && opt.start_residual_threshold >= 0, who,
            ": start_residual_threshold must be finite and >= 0 (got ", opt.start_residual_threshold, ")");
    require(fixed || opt.start_iterations == 0, who, ": the start refinement (start_iterations = ", opt.start_iterations,
            ") is available only in the fixed-equilibrium formulation; set it to 0");
    require_size(guess.w.size(), n, who, "guess.w (this rank's flow values and the structural ones)");
    require_size(guess.p.size(), n, who, "guess.p (this rank's part of the eigenvector)");
    require_finite(guess.w, who, "guess.w");
    require_finite(guess.p, who, "guess.p");
    require(std::isfinite(guess.mu) && guess.mu != 0, who, ": guess.mu (", param, ") ", guess.mu, " must be finite and non-zero");
    require(std::isfinite(guess.omega), who, ": guess.omega ", guess.omega, " is not finite");
  });
  {
    double agree[2] = {guess.mu, guess.omega}, mx[2], mn[2];
    internal::check_mpi(MPI_Allreduce(agree, mx, 2, MPI_DOUBLE, MPI_MAX, comm), "MPI_Allreduce");
    internal::check_mpi(MPI_Allreduce(agree, mn, 2, MPI_DOUBLE, MPI_MIN, comm), "MPI_Allreduce");
    if (mx[0] != mn[0] || mx[1] != mn[1])
      throw input_error(aerohopf::internal::concat(who, ": guess.mu and guess.omega differ between the ranks"));
  }

  // normalisation: s = e_k at the largest |p_k| over the ranks, p scaled to p_k = i
  vec<double> s(n);
  auto normalise = [&](vec<C>& p) {
    s.setZero();
    struct {
      double value;
      int rank;
    } best{-1.0, d.rank()};
    Eigen::Index k = 0;
    if (n > 0) best.value = p.cwiseAbs().maxCoeff(&k);
    internal::check_mpi(MPI_Allreduce(MPI_IN_PLACE, &best, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm), "MPI_Allreduce");
    if (!(best.value > 0)) throw input_error(who + ": guess.p (eigenvector) is zero");
    C pk = d.rank() == best.rank ? p[k] : C(0.0);
    internal::check_mpi(MPI_Bcast(&pk, 1, MPI_C_DOUBLE_COMPLEX, best.rank, comm), "MPI_Bcast");
    p *= C(0.0, 1.0) / pk;
    if (d.rank() == best.rank) {
      s[k] = 1.0;
      p[k] = C(0.0, 1.0);
    }
  };
  vec<C> p = guess.p;
  normalise(p);

  // the iterate
  vec<double> w = guess.w, pr = p.real(), pi = p.imag();
  double mu = guess.mu, om = guess.omega;
  distributed_hopf_result res;
  typename D::jacobian_rows a, l, ap, am;
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.single_precision_factors = opt.single_precision_factors;
  io.context = aerohopf::internal::concat(label, ": block-Jacobi BILU(", opt.fill_level, ") of L - i omega I");
  basic_distributed_bordered_preconditioner<dim, C> pc(io);
  block_ilu_options ior = io;
  ior.context = aerohopf::internal::concat(label, ": block-Jacobi BILU(", opt.fill_level, ") of L (flow update)");
  basic_distributed_bordered_preconditioner<dim, double> pc_real(ior);
  bool preconditioned = false;

  // F_A at the iterate (local parts; border rows on the root) with the Jacobian rows a at (w, mu)
  auto residual = [&]() {
    const auto t0 = aerohopf::internal::hopf_clock::now();
    const Eigen::Index off = fixed ? 0 : n;
    vec<double> f = vec<double>::Zero(off + 2 * n + 2);
    if (!fixed) f.head(n) = d.residual(w, mu);
    vec<C> pc_(n);
    pc_.real() = pr;
    pc_.imag() = pi;
    const vec<C> ap_ = d.multiply(a, pc_);
    f.segment(off, n) = ap_.real() + om * pi;
    f.segment(off + n, n) = ap_.imag() - om * pr;
    std::array<double, 2> sp{s.dot(pr), s.dot(pi)};
    d.sum(sp.data(), 2);
    if (root) {
      f[off + 2 * n] = sp[0];
      f[off + 2 * n + 1] = sp[1] - 1.0;
    }
    res.residual_seconds += aerohopf::internal::seconds_since(t0);
    return f;
  };
  auto norm = [&](const vec<double>& f) {
    double q = f.allFinite() ? f.squaredNorm() : NAN;
    d.sum(&q, 1);
    return std::sqrt(q);
  };
  auto assemble = [&]() {
    const auto t0 = aerohopf::internal::hopf_clock::now();
    d.jacobians(w, mu, a, l);
    res.setup_seconds += aerohopf::internal::seconds_since(t0);
  };
  auto precondition = [&]() {
    const auto t0 = aerohopf::internal::hopf_clock::now();
    d.set_parameter(l, mu);
    pc.compute(d, l, C(0.0, om));
    if (!fixed) pc_real.compute(d, l, 0.0);
    preconditioned = true;
    res.setup_seconds += aerohopf::internal::seconds_since(t0);
  };

  const newton_options& no = ho.newton;
  auto& rep = res.report;
  const auto t_start = aerohopf::internal::hopf_clock::now();
  auto where = [&](int k, double fk) {
    return aerohopf::internal::concat(" [iterate ", k, ": ||F|| = ", fk, ", ", param, " = ", mu, ", omega = ", om, "]");
  };
  auto fail = [&](const std::string& why, int k, double fk) {
    rep.converged = false;
    rep.reason = label + ": " + why + where(k, fk);
    rep.failed_iteration = k + 1;
    if (no.throw_on_failure) throw convergence_error(rep.reason);
  };
  assemble();
  vec<double> f = residual();
  double fn = norm(f);
  if (fixed && opt.start_iterations > 0 && fn > opt.start_residual_threshold) {
    const auto t0 = aerohopf::internal::hopf_clock::now();
    precondition();
    const distributed_shifted_operator<dim> op(d, a, C(0.0, om));
    krylov_options ko = opt.krylov;
    ko.relative_tolerance = opt.start_tolerance;
    ko.max_iterations = std::min(ko.max_iterations, opt.start_max_iterations);
    ko.throw_on_failure = false;
    ko.context = label + ": start refinement";
    auto global_norm = [&](const vec<C>& v) {
      double q = v.allFinite() ? v.squaredNorm() : NAN;
      d.sum(&q, 1);
      return std::sqrt(q);
    };
    vec<C> v(n), y(n);
    v.real() = pr;
    v.imag() = pi;
    long its = 0;
    bool ok = true;
    for (int k = 0; k < opt.start_iterations && ok; ++k) {
      v /= global_norm(v);
      y.setZero();
      its += gmres<C>(op, pc, v, y, ko).iterations;
      const double ny = global_norm(y);
      ok = std::isfinite(ny) && ny > 0;
      if (ok) v = y / ny;
    }
    res.linear_iterations += its;
    res.linear_seconds += aerohopf::internal::seconds_since(t0);
    if (ok) {
      // the Rayleigh quotient v^H J v / v^H v (local products: every unknown counted once)
      std::array<C, 2> q{v.dot(d.multiply(a, v)), C(v.squaredNorm())};
      d.sum(q.data(), 2);
      const C lambda = q[0] / q[1];
      const vec<double> pr0 = pr, pi0 = pi, s0 = s;
      const double om0 = om;
      normalise(v);
      pr = v.real();
      pi = v.imag();
      if (lambda.imag() * om > 0) om = lambda.imag();
      const vec<double> f1 = residual();
      const double fn1 = norm(f1);
      const bool kept = std::isfinite(fn1) && fn1 < fn;
      if (ho.verbose && ho.log && root)
        *ho.log << label << " start: " << opt.start_iterations << " inverse iteration(s), " << its
                << " GMRES iterations, ||F|| " << std::scientific << std::setprecision(3) << fn << " -> " << fn1
                << std::defaultfloat << (kept ? " (kept)" : " (discarded)") << ", omega " << om << "\n";
      res.start_refined = kept;
      if (kept) {
        f = f1;
        fn = fn1;
      } else {
        pr = pr0;
        pi = pi0;
        s = s0;
        om = om0;
      }
    }
  }
  const double f0 = fn, target = no.abs_tolerance + no.rel_tolerance * f0;
  rep.residual_history.push_back(fn);
  double last = fn;
  if (ho.verbose && ho.log && root)
    *ho.log << label << " it  0  |F| " << std::scientific << std::setprecision(3) << fn << std::defaultfloat
            << "  " << param << " " << std::setprecision(12) << mu << "  omega " << om << "\n";
  for (int k = 0;; ++k) {
    if (!std::isfinite(fn)) {
      fail("the Hopf residual is not finite", k, fn);
      break;
    }
    if (fn <= target) {
      rep.converged = true;
      break;
    }
    if (fn > no.divergence_factor * f0) {
      fail(aerohopf::internal::concat("diverged (||F|| > ", no.divergence_factor, " ||F_0||)"), k, fn);
      break;
    }
    if (k >= no.contraction_from && fn > no.max_contraction * last) {
      fail(aerohopf::internal::concat("not contracting at iterate ", k, ": ||F|| = ", fn, " from ", last, " (ratio ",
                                      fn / last, " > max_contraction ", no.max_contraction, ")"),
           k, fn);
      break;
    }
    if (k >= no.max_iterations) {
      fail(aerohopf::internal::concat("no convergence in ", no.max_iterations, " Newton iterations"), k, fn);
      break;
    }
    // Newton step k + 1
    try {
      if (!fixed) assemble();  // (already current for k = 0)
      if (!preconditioned || !fixed || (k > 0 && fn > 0.1 * last)) precondition();
      krylov_options ko = opt.krylov;
      ko.relative_tolerance = std::min(opt.eta_max, std::max(fn, 0.1 * no.abs_tolerance / fn));
      ko.throw_on_failure = true;
      vec<double> mu_col(2 * n);
      {
        vec<C> pcx(n);
        pcx.real() = pr;
        pcx.imag() = pi;
        const vec<C> mc = d.parameter_column(a, pcx);  // A_mu p at the rows' mu (= mu)
        mu_col.head(n) = mc.real();
        mu_col.tail(n) = mc.imag();
      }
      vec<double> rhs = -f.tail(2 * n + 2);
      vec<double> dw0, dw1;
      if (!fixed) {
        const real_bordered_operator<dim> aop(d, a);
        const auto t0 = aerohopf::internal::hopf_clock::now();
        dw0 = vec<double>::Zero(n);
        dw1 = vec<double>::Zero(n);
        ko.context = aerohopf::internal::concat(label, ": GMRES on A (flow update dw0) at Newton iteration ", k + 1);
        res.linear_iterations += gmres<double>(aop, pc_real, vec<double>(-f.head(n)), dw0, ko).iterations;
        ko.context = aerohopf::internal::concat(label, ": GMRES on A (flow update dw1) at Newton iteration ", k + 1);
        res.linear_iterations +=
            gmres<double>(aop, pc_real, vec<double>(-d.residual_d_parameter(w, mu)), dw1, ko).iterations;
        res.linear_seconds += aerohopf::internal::seconds_since(t0);
        // (A_w p) dw by central differences of the Jacobian rows at w +- h dw
        const auto t1 = aerohopf::internal::hopf_clock::now();
        const double w_inf = internal::max_over_ranks(comm, w.cwiseAbs().maxCoeff());
        for (int which = 0; which < 2; ++which) {
          const vec<double>& x = which == 0 ? dw0 : dw1;
          const double x_inf = internal::max_over_ranks(comm, x.size() ? x.cwiseAbs().maxCoeff() : 0.0);
          if (!(x_inf > 0)) continue;
          const double h = std::cbrt(std::numeric_limits<double>::epsilon()) * std::max(1.0, w_inf) / x_inf;
          d.jacobian(vec<double>(w + h * x), mu, flow::jacobian_kind::exact, ap);
          d.jacobian(vec<double>(w - h * x), mu, flow::jacobian_kind::exact, am);
          vec<C> pcx(n);
          pcx.real() = pr;
          pcx.imag() = pi;
          const vec<C> bp = (d.multiply(ap, pcx) - d.multiply(am, pcx)) / (2 * h);
          if (!internal::on_every_rank(comm, bp.allFinite()))
            throw convergence_error(aerohopf::internal::concat("a second-derivative product is not finite at Newton iteration ", k + 1));
          if (which == 0) {
            rhs.head(n) -= bp.real();
            rhs.segment(n, n) -= bp.imag();
          } else {
            mu_col.head(n) += bp.real();
            mu_col.tail(n) += bp.imag();
          }
        }
        res.residual_seconds += aerohopf::internal::seconds_since(t1);
      }
      const auto t0 = aerohopf::internal::hopf_clock::now();
      const internal::hopf_bordered_operator<dim> op(d, a, om, std::move(mu_col), pr, pi, s);
      const internal::hopf_bordered_preconditioner<dim> bp(pc, d, op);
      vec<double> dx = vec<double>::Zero(2 * n + 2);
      ko.context = aerohopf::internal::concat(label, ": GMRES on the bordered eigen-equations at Newton iteration ", k + 1);
      res.linear_iterations += gmres<double>(op, bp, rhs, dx, ko).iterations;
      res.linear_seconds += aerohopf::internal::seconds_since(t0);
      std::array<double, 2> dm{dx[2 * n], dx[2 * n + 1]};
      d.sum(dm.data(), 2);
      if (!internal::on_every_rank(comm, dx.allFinite()) || !std::isfinite(dm[0]) || !std::isfinite(dm[1]))
        throw convergence_error(aerohopf::internal::concat("the Newton correction is not finite at iteration ", k + 1));
      if (!fixed) w += dw0 + dm[0] * dw1;
      pr += dx.head(n);
      pi += dx.segment(n, n);
      mu += dm[0];
      om += dm[1];
      if (fixed) d.set_parameter(a, mu);
      else assemble();
      last = fn;
      f = residual();
      fn = norm(f);
      rep.iterations = k + 1;
      rep.residual_history.push_back(fn);
      if (ho.verbose && ho.log && root)
        *ho.log << label << " it " << std::setw(2) << k + 1 << "  |F| " << std::scientific << std::setprecision(3) << fn
                << std::defaultfloat << "  " << param << " " << std::setprecision(12) << mu << "  omega " << om << "  linear its "
                << res.linear_iterations << "\n";
    } catch (const input_error&) {
      throw;
    } catch (const error& e) {
      // a failed step (GMRES, a singular preconditioner, a non-finite correction) on every
      // rank: thrown as its own type with the last accepted iterate, or the result holds it
      rep.failed_iteration = k + 1;
      if (no.throw_on_failure) aerohopf::internal::rethrow_with_context(label + ": ", where(k, fn));
      rep.converged = false;
      rep.reason = label + ": " + e.what() + where(k, fn);
      break;
    }
  }
  rep.seconds = aerohopf::internal::seconds_since(t_start);

  // the point, omega > 0, and the post-checks
  res.point.w = w;
  res.point.mu = mu;
  res.point.omega = om;
  res.point.p.resize(n);
  res.point.p.real() = pr;
  res.point.p.imag() = pi;
  if (!rep.converged) return res;
  if (res.point.omega < 0) {
    res.point.omega = -res.point.omega;
    res.point.p = res.point.p.conjugate().eval();
  }
  const double r = std::max(target, fn);
  const double tol_f = fixed ? std::max(ho.equilibrium_tolerance, ho.equilibrium_factor * r) : r;
  const double f_eq = norm(d.residual(w, mu));
  double p_norm2 = res.point.p.squaredNorm();
  d.sum(&p_norm2, 1);
  const double p_norm = std::sqrt(p_norm2);
  std::string why;
  if (!(f_eq <= tol_f))
    why = aerohopf::internal::concat("the equilibrium does not hold at ", param, "* = ", mu, ": ||f(w, ", param, "*)|| = ", f_eq,
                                     " > tolerance ", tol_f,
                                     fixed ? " (fixed-equilibrium formulation: an equilibrium that moves with the "
                                             "parameter needs the full one)"
                                           : "");
  else if (!(std::abs(om) > aerohopf::internal::hopf_frequency_floor(r, p_norm)))
    why = aerohopf::internal::concat("converged to omega = ", om, " at ", param, "* = ", mu,
                                     ", below the resolved frequency: a real eigenvalue (divergence), not a Hopf point");
  if (!why.empty()) {
    rep.converged = false;
    rep.reason = label + ": " + why;
    if (no.throw_on_failure) throw convergence_error(rep.reason);
  }
  return res;
}

namespace internal {

/// GMRES's restart, deflation, iteration limit and Gram-Schmidt passes from a serial caller's
/// options, so that a distributed solve runs the GMRES its serial twin runs (the tolerance is the
/// caller's forcing or its own, set apart).
inline void copy_gmres_shape(const krylov_options& from, krylov_options& to) {
  to.restart = from.restart;
  to.deflation = from.deflation;
  to.max_iterations = from.max_iterations;
  to.reorthogonalize = from.reorthogonalize;
  to.reorthogonalization_threshold = from.reorthogonalization_threshold;
}

/// The distributed Hopf options of a flutter-boundary driver's serial ones (formulation, Newton,
/// BILU fill, GMRES restart, deflation, limit and Gram-Schmidt passes, forcing bound, start refinement):
/// the distributed families' solve_hopf.
inline distributed_hopf_options hopf_options_from(const hopf_options& ho, const hopf_krylov_options& ko) {
  distributed_hopf_options o;
  o.hopf = ho;
  o.fill_level = ko.fill_level;
  o.single_precision_factors = ko.single_precision_factors;
  copy_gmres_shape(ko.krylov, o.krylov);
  o.eta_max = ko.eta_max;
  o.start_iterations = ko.start_iterations;
  o.start_tolerance = ko.start_tolerance;
  o.start_max_iterations = ko.start_max_iterations;
  o.start_residual_threshold = ko.start_residual_threshold;
  return o;
}

/// The distributed inverse-power options of a serial caller's: the eigen-residual target
/// `power`, the BILU fill and the GMRES tolerance, restart, deflation, limit and Gram-Schmidt passes.
inline distributed_inverse_power_options inverse_power_options_from(const inverse_power_options& power, int fill_level,
                                                                    const krylov_options& krylov) {
  distributed_inverse_power_options io;
  io.power = power;
  io.fill_level = fill_level;
  io.krylov.relative_tolerance = krylov.relative_tolerance;
  copy_gmres_shape(krylov, io.krylov);
  return io;
}

/// The distributed inverse-power options of a driver's Hopf start (hopf_start_krylov's).
inline distributed_inverse_power_options inverse_power_options_from(const hopf_start_krylov_options& so) {
  distributed_inverse_power_options io = inverse_power_options_from(so.inverse_power, so.fill_level, so.krylov);
  io.single_precision_factors = so.single_precision_factors;
  return io;
}

/// The distributed inverse-power options of a V-g scan's (vg_krylov_options; the eigen-residual
/// target in `power`).
inline distributed_inverse_power_options inverse_power_options_from(const vg_krylov_options& ko,
                                                                    const inverse_power_options& power) {
  return inverse_power_options_from(power, ko.fill_level, ko.krylov);
}

/// The serial hopf_result of a distributed one, with the whole w and p (gathered by the
/// caller); its normalisation e_k: p_k = i at the largest component.
inline hopf_result hopf_result_from(const distributed_hopf_result& r, vec<double> w, vec<std::complex<double>> p) {
  hopf_result h;
  h.point.w = std::move(w);
  h.point.mu = r.point.mu;
  h.point.omega = r.point.omega;
  h.point.p = std::move(p);
  Eigen::Index k = 0;
  if (h.point.p.size()) h.point.p.cwiseAbs().maxCoeff(&k);
  h.s = vec<double>::Zero(h.point.p.size());
  if (h.s.size()) h.s[k] = 1.0;
  h.report = r.report;
  h.linear_iterations = r.linear_iterations;
  h.setup_seconds = r.setup_seconds;
  h.linear_seconds = r.linear_seconds;
  h.residual_seconds = r.residual_seconds;
  h.start_refined = r.start_refined;
  return h;
}

}  // namespace internal

}  // namespace aerohopf::distributed
