#pragma once
// Limit cycles of dw/dt = f(w, mu) by harmonic balance (time-spectral collocation), continued in
// amplitude from a Hopf point, and their stability by Hill's method.
//
// Unknowns: the states w_j = w(tau_j) at the N = 2 H + 1 phases tau_j = 2 pi j / N of one period
// (tau = omega t, H harmonics), the angular frequency omega, the parameter mu and the amplitude a.
// Equations (N n + 2):
//   G_j = f(w_j, mu) - omega sum_k D_jk w_k = 0                     j = 0 .. N-1
//   phase:      (2/N) sum_j <e, w_j> sin tau_j = 0
//   amplitude:  (2/N) sum_j <e, w_j> cos tau_j - a = 0
// D is the Fourier differentiation matrix of odd N, D_jk = (-1)^(j-k) / (2 sin(pi (j-k) / N))
// for j != k, D_jj = 0 (exact on trigonometric polynomials of degree <= H), and e the probe, a
// linear functional of the state (a structural coordinate, an outlet temperature): a is the
// cosine coefficient of the probe's first harmonic, and its sine coefficient is zero (the phase).
// One more row closes the system: mu fixed, a fixed, or the curve stepper's row on x = (W,
// omega, mu, a) with its metric on (mu, a) only, so that the branch passes folds in mu.
//
// Newton with the exact Jacobian
//   dG_j/dw_k = delta_jk A(w_j, mu) - omega D_jk I,   dG_j/domega = -(D W)_j,   dG_j/dmu = f_mu(w_j, mu),
// its linear systems solved by a strategy: hb_direct (the default: assembled sparse, sparse LU)
// or hb_krylov<B> (GMRES with the harmonic preconditioner, for CFD-sized systems; see there).
// Converged when ||F||_inf <= tolerance for all N n + 3 rows (the state rows are f's units).
// Failures (convergence_error): no convergence in max_iterations, a non-finite residual, omega
// leaving (0, inf); the message names the iteration, ||F||_inf, H, omega, mu and a. The input
// (the guess, the probe) is checked and never modified.
//
// Stability (hill_floquet): the eigenvalues of Hill's matrix in the time domain, blockdiag(A(w_j))
// - omega D (x) I, are the Floquet exponents sigma + i k omega (k = -H .. H) of the cycle. For
// each eigenvector the energy-weighted mean index kbar of its discrete Fourier coefficients over
// k = -H .. H is formed, and the n eigenvalues with the smallest |kbar| are taken: the
// eigenvector of sigma itself is centred on harmonic 0, its shifted copies on k (the symmetry
// criterion of Lazarus & Thomas, C. R. Mecanique 338, 2010). The trivial exponent (the phase
// shift, exactly 0 for the continuous problem: its distance from 0 measures the truncation) is
// the one nearest 0, and the cycle is stable when every other exponent has Re < 0. Dense: for
// N n up to hill_options::max_size; hill_floquet_krylov<B> finds the exponents nearest 0 of
// CFD-sized cycles by shift-invert Arnoldi without forming the matrix (see there).
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "../bifurcation/curve_stepper.hpp"
#include "../bifurcation/equilibrium_krylov.hpp"
#include "../bifurcation/hopf_point.hpp"
#include "../error.hpp"
#include "../linalg/bordered_block_matrix.hpp"
#include "../linalg/direct.hpp"
#include "../linalg/krylov.hpp"
#include "../nonlinear/block_system.hpp"
#include "../nonlinear/system.hpp"

namespace aerohopf {

/// Fourier differentiation matrix of N (odd) equally spaced phases on [0, 2 pi).
inline Eigen::MatrixXd fourier_differentiation_matrix(int n) {
  require(n >= 1 && n % 2 == 1, "fourier_differentiation_matrix: the number of phases must be odd and >= 1 (got ", n,
          ")");
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k)
      if (j != k) {
        const int m = j - k;
        d(j, k) = ((m % 2 == 0) ? 0.5 : -0.5) / std::sin(std::numbers::pi * m / n);
      }
  return d;
}

/// A periodic orbit in harmonic-balance form.
struct lco_solution {
  int harmonics = 0;           ///< H (N = 2 H + 1 instances)
  Eigen::MatrixXd instances;   ///< n x N: column j is w(tau_j), tau_j = 2 pi j / N
  double omega = 0;            ///< angular frequency
  double mu = 0;               ///< parameter
  double amplitude = 0;        ///< first-harmonic cosine coefficient of the probe
  int newton_iterations = 0;
  int linear_iterations = 0;   ///< Krylov iterations of the solve (0 for the direct strategy)
  double residual = 0;         ///< ||F||_inf at the solution
  double seconds = 0;          ///< wall time of the solve
  std::size_t linear_bytes = 0;  ///< memory of the Krylov strategy's matrices, factors and basis (0: direct)

  int instance_count() const { return 2 * harmonics + 1; }
  Eigen::Index state_size() const { return instances.rows(); }
  double period() const { return 2 * std::numbers::pi / omega; }
  /// Complex Fourier coefficients c_k, k = 0 .. H (n x (H + 1)): w(tau) = c_0 + 2 Re sum c_k e^{i k tau}.
  Eigen::MatrixXcd fourier() const {
    const int nn = instance_count();
    Eigen::MatrixXcd c = Eigen::MatrixXcd::Zero(instances.rows(), harmonics + 1);
    for (int k = 0; k <= harmonics; ++k)
      for (int j = 0; j < nn; ++j)
        c.col(k) += instances.col(j).cast<std::complex<double>>() *
                    std::polar(1.0 / nn, -2 * std::numbers::pi * k * j / nn);
    return c;
  }
  /// The trigonometric interpolant at phase tau.
  vec<double> state(double tau) const {
    const Eigen::MatrixXcd c = fourier();
    vec<double> w = c.col(0).real();
    for (int k = 1; k <= harmonics; ++k) w += 2 * (c.col(k) * std::polar(1.0, k * tau)).real();
    return w;
  }
  /// The mean state (harmonic 0).
  vec<double> mean() const { return instances.rowwise().mean(); }
};

/// Half the peak-to-peak excursion of <probe, w(tau)> over the cycle (the trigonometric
/// interpolant's maximum and minimum, each refined by Newton on its derivative): the amplitude a
/// time-marching run measures from its signal's peaks.
inline double probe_peak_amplitude(const lco_solution& s, const vec<double>& probe) {
  require_size(probe.size(), s.state_size(), "probe_peak_amplitude", "probe");
  const Eigen::MatrixXcd c = s.fourier();
  const Eigen::VectorXcd pc = c.transpose() * probe.cast<std::complex<double>>();  // probe's coefficients
  auto value = [&](double t, int deriv) {
    double v = deriv == 0 ? pc[0].real() : 0.0;
    for (int k = 1; k <= s.harmonics; ++k) {
      const std::complex<double> ik = std::pow(std::complex<double>(0, k), deriv);
      v += 2 * (pc[k] * ik * std::polar(1.0, k * t)).real();
    }
    return v;
  };
  const int samples = 64 * s.instance_count();
  double tmax = 0, tmin = 0, vmax = -INFINITY, vmin = INFINITY;
  for (int m = 0; m < samples; ++m) {
    const double t = 2 * std::numbers::pi * m / samples, v = value(t, 0);
    if (v > vmax) vmax = v, tmax = t;
    if (v < vmin) vmin = v, tmin = t;
  }
  auto refine = [&](double t) {
    const double h = 2 * std::numbers::pi / samples;
    const double lo = t - h, hi = t + h;
    for (int it = 0; it < 20; ++it) {
      const double d2 = value(t, 2);
      if (d2 == 0) break;
      const double tn = std::clamp(t - value(t, 1) / d2, lo, hi);
      if (std::abs(tn - t) < 1e-15) break;
      t = tn;
    }
    return value(t, 0);
  };
  return 0.5 * (std::max(vmax, refine(tmax)) - std::min(vmin, refine(tmin)));
}

/// The first guess of a cycle of amplitude a near a Hopf point: w_j = w* + Re(eps p e^{i tau_j})
/// with eps = a / <e, p> (so <e, w(tau)> = <e, w*> + a cos tau), omega*, and mu (mu* unless the
/// centre-manifold model gives a better value).
inline lco_solution lco_guess_from_hopf(const hopf_point& hp, const vec<double>& probe, double a, int harmonics,
                                        std::optional<double> mu = std::nullopt) {
  const char* who = "lco_guess_from_hopf";
  require(harmonics >= 1, who, ": harmonics must be >= 1 (got ", harmonics, ")");
  require_size(probe.size(), hp.w.size(), who, "probe");
  require_size(hp.p.size(), hp.w.size(), who, "eigenvector p");
  require_finite(probe, who, "probe");
  require(std::isfinite(a) && a > 0, who, ": amplitude must be finite and > 0 (got ", a, ")");
  require(std::isfinite(hp.omega) && hp.omega > 0, who, ": the Hopf frequency must be > 0 (got ", hp.omega, ")");
  const std::complex<double> ep = probe.cast<std::complex<double>>().dot(hp.p);  // conj(probe) . p = probe . p
  require(std::abs(ep) > 1e-12 * probe.norm() * hp.p.norm(), who,
          ": the probe does not see the critical eigenvector (<e, p> = ", std::abs(ep), ")");
  const std::complex<double> eps = a / ep;
  lco_solution s;
  s.harmonics = harmonics;
  const int nn = 2 * harmonics + 1;
  s.instances.resize(hp.w.size(), nn);
  for (int j = 0; j < nn; ++j)
    s.instances.col(j) = hp.w + (eps * hp.p * std::polar(1.0, 2 * std::numbers::pi * j / nn)).real();
  s.omega = hp.omega;
  s.mu = mu.value_or(hp.mu);
  s.amplitude = a;
  return s;
}

/// The same cycle on H' harmonics (trigonometric interpolation; truncation when H' < H).
inline lco_solution resample(const lco_solution& s, int harmonics) {
  require(harmonics >= 1, "resample: harmonics must be >= 1 (got ", harmonics, ")");
  lco_solution r = s;
  r.harmonics = harmonics;
  const int nn = 2 * harmonics + 1;
  const Eigen::MatrixXcd c = s.fourier();
  r.instances.resize(s.state_size(), nn);
  for (int j = 0; j < nn; ++j) {
    const double tau = 2 * std::numbers::pi * j / nn;
    vec<double> w = c.col(0).real();
    for (int k = 1; k <= std::min(harmonics, s.harmonics); ++k) w += 2 * (c.col(k) * std::polar(1.0, k * tau)).real();
    r.instances.col(j) = w;
  }
  r.newton_iterations = 0;
  r.residual = NAN;
  return r;
}

struct harmonic_balance_options {
  double tolerance = 1e-10;  ///< on ||F||_inf
  int max_iterations = 25;
  std::ostream* log = nullptr;  ///< one line per Newton iteration when set
  std::string label = "harmonic balance";
};

/// What closes the harmonic-balance system in solve_lco.
enum class lco_fix { amplitude, parameter };

namespace internal {

/// The harmonic-balance equations of one system, probe and number of harmonics, on x = (w_0 ..
/// w_{N-1}, omega, mu, a).
template <dynamical_system S>
class harmonic_balance_equations {
 public:
  harmonic_balance_equations(const S& sys, const vec<double>& probe, int harmonics)
      : sys_(sys), probe_(probe), h_(harmonics), nn_(2 * harmonics + 1), n_(sys.size()),
        d_(fourier_differentiation_matrix(2 * harmonics + 1)) {
    for (int j = 0; j < nn_; ++j) {
      const double tau = 2 * std::numbers::pi * j / nn_;
      sin_.push_back(2.0 / nn_ * std::sin(tau));
      cos_.push_back(2.0 / nn_ * std::cos(tau));
    }
  }
  Eigen::Index n() const { return n_; }
  int instances() const { return nn_; }
  Eigen::Index unknowns() const { return nn_ * n_ + 3; }
  Eigen::Index omega_index() const { return nn_ * n_; }
  Eigen::Index mu_index() const { return nn_ * n_ + 1; }
  Eigen::Index amplitude_index() const { return nn_ * n_ + 2; }
  const Eigen::MatrixXd& differentiation() const { return d_; }
  /// The phase and amplitude rows' state parts (N n entries).
  vec<double> phase_row() const { return probe_row(sin_); }
  vec<double> amplitude_row() const { return probe_row(cos_); }

  vec<double> pack(const lco_solution& s) const {
    vec<double> x(unknowns());
    for (int j = 0; j < nn_; ++j) x.segment(j * n_, n_) = s.instances.col(j);
    x[omega_index()] = s.omega;
    x[mu_index()] = s.mu;
    x[amplitude_index()] = s.amplitude;
    return x;
  }
  lco_solution unpack(const vec<double>& x) const {
    lco_solution s;
    s.harmonics = h_;
    s.instances.resize(n_, nn_);
    for (int j = 0; j < nn_; ++j) s.instances.col(j) = x.segment(j * n_, n_);
    s.omega = x[omega_index()];
    s.mu = x[mu_index()];
    s.amplitude = x[amplitude_index()];
    return s;
  }

  /// F(x) without the closing row (N n + 2 entries).
  vec<double> residual(const vec<double>& x) const {
    const double omega = x[omega_index()], mu = x[mu_index()];
    vec<double> f(nn_ * n_ + 2);
    const Eigen::Map<const Eigen::MatrixXd> w(x.data(), n_, nn_);
    const Eigen::MatrixXd dw = w * d_.transpose();  // column j = sum_k D_jk w_k
    double ps = 0, pc = 0;
    for (int j = 0; j < nn_; ++j) {
      const vec<double> wj = w.col(j);
      f.segment(j * n_, n_) = sys_.residual(wj, mu) - omega * dw.col(j);
      const double e = probe_.dot(wj);
      ps += sin_[j] * e;
      pc += cos_[j] * e;
    }
    f[nn_ * n_] = ps;
    f[nn_ * n_ + 1] = pc - x[amplitude_index()];
    return f;
  }

  /// The exact Jacobian of (F, c.x) (square, N n + 3).
  Eigen::SparseMatrix<double> jacobian(const vec<double>& x, const vec<double>& c) const {
    const double omega = x[omega_index()], mu = x[mu_index()];
    const Eigen::Map<const Eigen::MatrixXd> w(x.data(), n_, nn_);
    const Eigen::MatrixXd dw = w * d_.transpose();
    std::vector<Eigen::Triplet<double>> t;
    const Eigen::Index ow = omega_index(), om = mu_index(), oa = amplitude_index();
    const Eigen::Index rp = nn_ * n_, ra = rp + 1, rc = rp + 2;
    for (int j = 0; j < nn_; ++j) {
      const vec<double> wj = w.col(j);
      add_block(t, sys_.jacobian(wj, mu), j * n_, j * n_);
      for (int k = 0; k < nn_; ++k)
        if (k != j)
          for (Eigen::Index i = 0; i < n_; ++i) t.emplace_back(j * n_ + i, k * n_ + i, -omega * d_(j, k));
      const vec<double> fmu = residual_d_mu(sys_, wj, mu);
      for (Eigen::Index i = 0; i < n_; ++i) {
        if (dw(i, j) != 0) t.emplace_back(j * n_ + i, ow, -dw(i, j));
        if (fmu[i] != 0) t.emplace_back(j * n_ + i, om, fmu[i]);
        if (probe_[i] != 0) {
          t.emplace_back(rp, j * n_ + i, sin_[j] * probe_[i]);
          t.emplace_back(ra, j * n_ + i, cos_[j] * probe_[i]);
        }
      }
    }
    t.emplace_back(ra, oa, -1.0);
    for (Eigen::Index i = 0; i < c.size(); ++i)
      if (c[i] != 0) t.emplace_back(rc, i, c[i]);
    Eigen::SparseMatrix<double> j(unknowns(), unknowns());
    j.setFromTriplets(t.begin(), t.end());
    return j;
  }

  /// Hill's matrix blockdiag(A(w_j)) - omega D (x) I (dense).
  Eigen::MatrixXd hill_matrix(const lco_solution& s) const {
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(nn_ * n_, nn_ * n_);
    for (int j = 0; j < nn_; ++j) {
      const vec<double> wj = s.instances.col(j);
      m.block(j * n_, j * n_, n_, n_) = Eigen::MatrixXd(sys_.jacobian(wj, s.mu));
      for (int k = 0; k < nn_; ++k)
        if (k != j) m.block(j * n_, k * n_, n_, n_).diagonal().array() -= s.omega * d_(j, k);
    }
    return m;
  }

 private:
  vec<double> probe_row(const std::vector<double>& weight) const {
    vec<double> r(nn_ * n_);
    for (int j = 0; j < nn_; ++j) r.segment(j * n_, n_) = weight[std::size_t(j)] * probe_;
    return r;
  }
  template <class M>
  static void add_block(std::vector<Eigen::Triplet<double>>& t, const M& a, Eigen::Index r0, Eigen::Index c0) {
    if constexpr (is_sparse_matrix_v<M>) {
      for (Eigen::Index k = 0; k < a.outerSize(); ++k)
        for (typename M::InnerIterator it(a, k); it; ++it) t.emplace_back(r0 + it.row(), c0 + it.col(), it.value());
    } else {
      for (Eigen::Index q = 0; q < a.cols(); ++q)
        for (Eigen::Index p = 0; p < a.rows(); ++p)
          if (a(p, q) != 0) t.emplace_back(r0 + p, c0 + q, a(p, q));
    }
  }

  const S& sys_;
  vec<double> probe_;
  int h_, nn_;
  Eigen::Index n_;
  Eigen::MatrixXd d_;
  std::vector<double> sin_, cos_;
};

struct hb_newton_outcome {
  vec<double> x;
  int iterations = 0;
  int linear_iterations = 0;
  double residual = 0;
  std::size_t linear_bytes = 0;
};

/// Newton on (F(x), c.x - value) = 0 from x0 with the linear solver `lin` (lin(x, c, rhs) =
/// [F_x; c^T]^{-1} rhs; an iterative one may take lin.newton_step(||F||_2, tolerance) before each
/// Newton solve to choose its forcing); throws convergence_error on failure.
template <dynamical_system S, class Linear>
hb_newton_outcome hb_newton(const harmonic_balance_equations<S>& eq, vec<double> x, const vec<double>& c,
                            double value, const harmonic_balance_options& o, const char* who, Linear& lin) {
  const auto describe = [&](int it, double fn) {
    return concat(who, " (", o.label, "): Newton iteration ", it, ": ||F||_inf = ", fn, " (H = ", (eq.instances() - 1) / 2,
                  ", omega = ", x[eq.omega_index()], ", mu = ", x[eq.mu_index()], ", a = ", x[eq.amplitude_index()],
                  ")");
  };
  const int linear_before = lin.iterations();
  for (int it = 0;; ++it) {
    vec<double> f(eq.unknowns());
    f.head(eq.unknowns() - 1) = eq.residual(x);
    f[eq.unknowns() - 1] = c.dot(x) - value;
    const double fn = f.cwiseAbs().maxCoeff();
    if (o.log) *o.log << o.label << ": iteration " << it << "  ||F||_inf " << fn << "  omega " << x[eq.omega_index()]
                      << "  mu " << x[eq.mu_index()] << "  a " << x[eq.amplitude_index()] << "\n";
    if (!std::isfinite(fn)) throw convergence_error(describe(it, fn) + ": the residual is not finite");
    if (fn <= o.tolerance) return {std::move(x), it, lin.iterations() - linear_before, fn, lin.bytes()};
    if (it >= o.max_iterations)
      throw convergence_error(describe(it, fn) + concat(": not converged to ", o.tolerance, " in ", o.max_iterations,
                                                        " iterations"));
    if constexpr (requires { lin.newton_step(fn, o.tolerance); })
      lin.newton_step(static_cast<double>(f.norm()), o.tolerance);  // the next solve's forcing
    try {
      x -= lin(x, c, f);
    } catch (...) {
      rethrow_with_context(describe(it, fn) + ": ");
    }
    if (!x.allFinite()) throw convergence_error(describe(it + 1, NAN) + ": the Newton update is not finite");
    if (!(x[eq.omega_index()] > 0))
      throw convergence_error(describe(it + 1, fn) + ": the frequency left (0, inf): no cycle near the guess");
  }
}

inline void check_hb_options(const harmonic_balance_options& o, const char* who) {
  require(std::isfinite(o.tolerance) && o.tolerance > 0, who, ": tolerance must be finite and > 0 (got ", o.tolerance,
          ")");
  require(o.max_iterations >= 1, who, ": max_iterations must be >= 1 (got ", o.max_iterations, ")");
}

template <dynamical_system S>
void check_guess(const S& sys, const lco_solution& g, const vec<double>& probe, const char* who) {
  require(g.harmonics >= 1, who, ": the guess has ", g.harmonics, " harmonics (>= 1 needed)");
  require(g.instances.rows() == sys.size() && g.instances.cols() == 2 * g.harmonics + 1, who, ": the guess has ",
          g.instances.rows(), " x ", g.instances.cols(), " instances, the system needs ", sys.size(), " x ",
          2 * g.harmonics + 1);
  require(g.instances.allFinite(), who, ": the guess has non-finite states");
  require(std::isfinite(g.omega) && g.omega > 0, who, ": the guess's frequency must be finite and > 0 (got ", g.omega,
          ")");
  require(std::isfinite(g.mu) && std::isfinite(g.amplitude), who, ": the guess's mu and amplitude must be finite");
  require_size(probe.size(), sys.size(), who, "probe");
  require_finite(probe, who, "probe");
  require(probe.norm() > 0, who, ": the probe is zero");
}
}  // namespace internal

/// The linear solver of the harmonic-balance Newton iterations by sparse LU of the assembled
/// Jacobian (any system; the default).
struct hb_direct {
  template <dynamical_system S>
  struct solver {
    const internal::harmonic_balance_equations<S>* eq;
    direct_solver<Eigen::SparseMatrix<double>> lu{"harmonic balance: sparse LU of the Jacobian"};
    vec<double> operator()(const vec<double>& x, const vec<double>& c, const vec<double>& rhs) {
      lu.compute(eq->jacobian(x, c));
      return lu.solve(rhs);
    }
    int iterations() const { return 0; }
    std::size_t bytes() const { return 0; }
  };
  template <dynamical_system S>
  solver<S> make(const internal::harmonic_balance_equations<S>& eq, const S&, const char*) const {
    return solver<S>{&eq};
  }
};

/// The matrix P of the harmonic preconditioner (hb_krylov, hill_floquet_krylov): the
/// preconditioning matrix at the cycle's mean state, or the mean of the instances' preconditioning
/// matrices (the zeroth Fourier coefficient of P(w(tau)): the harmonic-space block diagonal of the
/// Jacobian, which keeps a travelling shock smeared over its excursion instead of sharp at its
/// mean position; it costs N preconditioning assemblies instead of one).
enum class hb_preconditioner_state { mean_state, mean_jacobian };

namespace internal {

/// Hill's operator with a real shift, blockdiag(A(w_j)) - omega D (x) I - sigma I on N n
/// unknowns, by the exact bordered Jacobians of the instances, and its harmonic preconditioner:
/// the exact inverse of blockdiag(P) - omega D (x) I - sigma I, by a discrete Fourier transform
/// over the instances to P - (sigma + i k omega) I for harmonics k = 0 .. H, each by a complex
/// bordered BILU(k). The BILUs keep their symbolic phase from one build to the next.
template <int B, dynamical_system S>
class hill_operator {
 public:
  using C = std::complex<double>;

  void build(const S& sys, const Eigen::Ref<const Eigen::MatrixXd>& w, double mu, double omega, double sigma,
             const Eigen::MatrixXd& d, int fill_level, bool single_precision_factors, hb_preconditioner_state state,
             const char* who) {
    n_ = w.rows();
    nn_ = int(w.cols());
    h_ = (nn_ - 1) / 2;
    omega_ = omega;
    sigma_ = sigma;
    d_ = &d;
    exact_.clear();
    std::optional<bordered_block_matrix<double, B>> p;
    if (state == hb_preconditioner_state::mean_jacobian) {
      typename bordered_block_matrix<double, B>::flow_matrix ff;
      typename bordered_block_matrix<double, B>::dense_matrix fs, sf, ss;
      for (int j = 0; j < nn_; ++j) {
        auto pair = krylov_jacobians<B>(sys, vec<double>(w.col(j)), mu, who);
        exact_.push_back(std::move(pair.exact));
        const auto& pj = pair.preconditioning;
        if (j == 0) {
          ff = pj.flow();
          fs = pj.flow_structure();
          sf = pj.structure_flow();
          ss = pj.structure();
          continue;
        }
        if (pj.flow().row_ptr() == ff.row_ptr() && pj.flow().col_index() == ff.col_index()) {
          auto& v = ff.values();
          for (std::size_t q = 0; q < v.size(); ++q) v[q] += pj.flow().values()[q];
        } else {  // patterns differ (entries that vanish at some instances): the union
          const Eigen::SparseMatrix<double> sum = ff.to_sparse() + pj.flow().to_sparse();
          ff = bordered_block_matrix<double, B>::flow_matrix::from_sparse(sum, B);
        }
        fs += pj.flow_structure();
        sf += pj.structure_flow();
        ss += pj.structure();
      }
      for (double& v : ff.values()) v /= nn_;
      p.emplace(std::move(ff), fs / nn_, sf / nn_, ss / nn_, who);
    } else {
      for (int j = 0; j < nn_; ++j) exact_.push_back(krylov_exact_jacobian<B>(sys, vec<double>(w.col(j)), mu, who));
      p.emplace(krylov_jacobians<B>(sys, vec<double>(w.rowwise().mean()), mu, who).preconditioning);
    }
    if (int(ilu_.size()) != h_ + 1 || fill_level != fill_level_ || single_precision_factors != single_) {
      ilu_.clear();
      for (int k = 0; k <= h_; ++k) {
        block_ilu_options bo;
        bo.fill_level = fill_level;
        bo.single_precision_factors = single_precision_factors;
        bo.context = concat(who, ": BILU(", fill_level, ") of P - (sigma + i ", k, " omega) I");
        ilu_.emplace_back(bo);
      }
      fill_level_ = fill_level;
      single_ = single_precision_factors;
    }
    for (int k = 0; k <= h_; ++k) ilu_[std::size_t(k)].compute(*p, C(sigma, k * omega));
    // the real DFT pair: R fwd_ = [Re c_0 .. Re c_H, Im c_1 .. Im c_H] of c_k = (1/N) sum_j r_j
    // e^{-i k tau_j}, and [Re z_0 .. Re z_H, Im z_1 .. Im z_H] inv_ = sum_k' z_k' e^{i k' tau_j}
    // over k' = -H .. H with z_{-k} = conj(z_k): two matrix products instead of complex loops
    fwd_.setZero(nn_, nn_);
    inv_.setZero(nn_, nn_);
    for (int j = 0; j < nn_; ++j)
      for (int k = 0; k <= h_; ++k) {
        const double t = 2 * std::numbers::pi * k * j / nn_;
        fwd_(j, k) = std::cos(t) / nn_;
        inv_(k, j) = (k == 0 ? 1.0 : 2.0) * std::cos(t);
        if (k > 0) {
          fwd_(j, h_ + k) = -std::sin(t) / nn_;
          inv_(h_ + k, j) = -2.0 * std::sin(t);
        }
      }
  }
  Eigen::Index rows() const { return nn_ * n_; }

  /// y = (Hill - sigma I) v, v and y of N n entries.
  void apply(const vec<double>& v, vec<double>& y) {
    const Eigen::Map<const Eigen::MatrixXd> vm(v.data(), n_, nn_);
    Eigen::Map<Eigen::MatrixXd> ym(y.data(), n_, nn_);
    ym.noalias() = -omega_ * (vm * d_->transpose());
    if (sigma_ != 0) ym -= sigma_ * vm;
    for (int j = 0; j < nn_; ++j) {
      in_ = vm.col(j);
      out_.resize(n_);
      exact_[std::size_t(j)].apply(in_, out_);
      ym.col(j) += out_;
    }
  }
  /// z = M^{-1} r (the harmonic preconditioner), r and z of N n entries.
  void precondition(const vec<double>& r, vec<double>& z) {
    const Eigen::Map<const Eigen::MatrixXd> rm(r.data(), n_, nn_);
    Eigen::Map<Eigen::MatrixXd> zm(z.data(), n_, nn_);
    spec_.noalias() = rm * fwd_;
    rk_.resize(n_);
    zk_.resize(n_);
    for (int k = 0; k <= h_; ++k) {
      if (k == 0) rk_.real() = spec_.col(0), rk_.imag().setZero();
      else rk_.real() = spec_.col(k), rk_.imag() = spec_.col(h_ + k);
      ilu_[std::size_t(k)].apply(rk_, zk_);
      spec_.col(k) = zk_.real();
      if (k > 0) spec_.col(h_ + k) = zk_.imag();
    }
    zm.noalias() = spec_ * inv_;
  }
  /// Bytes held: the instances' exact Jacobians and the per-harmonic factors.
  std::size_t bytes() const {
    std::size_t b = 0;
    for (const auto& a : exact_) {
      b += a.flow().values().size() * sizeof(double) +
           (a.flow().col_index().size() + a.flow().row_ptr().size()) * sizeof(int);
      b += std::size_t(a.flow_structure().size() + a.structure_flow().size() + a.structure().size()) * sizeof(double);
    }
    for (const auto& f : ilu_) {
      const auto& l = f.flow_preconditioner();
      b += l.factor_col_index().size() * (std::size_t(B * B) * sizeof(C) + 2 * sizeof(int)) +
           l.factor_row_ptr().size() * sizeof(int);
      b += std::size_t(2 * f.structure_size()) * std::size_t(n_) * sizeof(C);
    }
    return b;
  }

 private:
  Eigen::Index n_ = 0;
  int nn_ = 0, h_ = 0, fill_level_ = -1;
  bool single_ = false;
  double omega_ = 0, sigma_ = 0;
  const Eigen::MatrixXd* d_ = nullptr;
  std::vector<bordered_block_matrix<double, B>> exact_;
  std::vector<bordered_block_ilu<C, B>> ilu_;
  Eigen::MatrixXd fwd_, inv_, spec_;
  vec<double> in_, out_;
  vec<C> rk_, zk_;
};

}  // namespace internal

/// The linear solver by GMRES with the harmonic preconditioner, for CFD-sized systems: the exact
/// Jacobians A(w_j) of every instance in bordered block form (krylov_exact_jacobian<B>, flow
/// blocks of B plus the structural border), and as preconditioner the exact inverse of
/// blockdiag(P) - omega D (x) I (internal::hill_operator: per harmonic k a complex bordered
/// BILU(k) of P - i k omega I, the shifted solves of the Hopf path), P by hb_preconditioner_state;
/// the three border unknowns (omega, mu, a) with their rows are eliminated exactly around it (a
/// 3 x 3 Schur complement). Near onset the instances differ little from their mean and GMRES
/// needs few iterations; they grow with the amplitude.
template <int B>
struct hb_krylov {
  int fill_level = 1;                  ///< k of each BILU(k)
  /// Each BILU's factors in single precision (block_ilu_options::single_precision_factors). Off:
  /// it pays where the factors stream from memory (3D grids); on the coarse aerofoil's branch
  /// (4,100 unknowns, H = 5) the GMRES iterations within one and no time saved.
  bool single_precision_factors = false;
  /// The GMRES: krylov.relative_tolerance is that of the solves outside Newton (the curve
  /// stepper's tangents), and of the Newton solves when adaptive_tolerance is false (1e-6); at
  /// most 400 iterations; GMRES(50) (against 100: a quarter less time for the coarse aerofoil's
  /// branch, half the basis); krylov.deflation = k gives GMRES-DR(50, k) (the coarse aerofoil's
  /// H = 5 branch to 1.05 Ubar*: 3,839 GMRES iterations with 10 against 4,023, the same time: a
  /// solve rarely restarts, 55-90 iterations per Newton step).
  krylov_options krylov{.relative_tolerance = 1e-6, .max_iterations = 400, .restart = 50, .record_history = false};
  /// Inexact-Newton forcing of the Newton solves, eta = min(0.5, eta_max, max(||F||_2, 0.1
  /// tolerance / ||F||_2)) (as solve_equilibrium_krylov): loose while the predictor's error
  /// dominates, no tighter than the Newton test needs at the last step. On the coarse aerofoil's
  /// branch to 1.05 Ubar* (H = 5) 156 GMRES iterations per point against 239 at 1e-6, for 0.3 more
  /// Newton iterations per point.
  bool adaptive_tolerance = true;
  double eta_max = 1e-2;
  /// A GMRES solve that stops at max_iterations is still used as the Newton step when its
  /// relative residual is below this (the Newton residual test decides convergence).
  double accept_tolerance = 1e-3;
  /// mean_jacobian: on the coarse aerofoil (H = 5, GMRES to 1e-6) 255 / 370 GMRES iterations per
  /// point at 1.02 / 1.05 Ubar* against 566 / 1200 with mean_state, equal near onset.
  hb_preconditioner_state preconditioner = hb_preconditioner_state::mean_jacobian;

  template <dynamical_system S>
  class solver {
   public:
    solver(const hb_krylov& o, const internal::harmonic_balance_equations<S>& eq, const S& sys, const char* who)
        : o_(o), eq_(&eq), sys_(&sys), who_(who) {}
    int iterations() const { return iterations_; }
    /// Bytes of the last solve's matrices, factors and GMRES basis (0 before the first).
    std::size_t bytes() const { return bytes_; }
    /// hb_newton's report before a Newton solve: sets the next solve's relative tolerance.
    void newton_step(double residual_norm, double tolerance) {
      if (o_.adaptive_tolerance) next_tolerance_ = internal::inexact_forcing(residual_norm, tolerance, o_.eta_max);
    }

    vec<double> operator()(const vec<double>& x, const vec<double>& c, const vec<double>& rhs) {
      const auto& eq = *eq_;
      const int nn = eq.instances();
      const Eigen::Index n = eq.n(), m = nn * n;
      const double omega = x[eq.omega_index()], mu = x[eq.mu_index()];
      const Eigen::Map<const Eigen::MatrixXd> w(x.data(), n, nn);
      hill_.build(*sys_, w, mu, omega, 0.0, eq.differentiation(), o_.fill_level, o_.single_precision_factors,
                  o_.preconditioner, who_);
      // the full operator [[Hill, U], [V, corner]]
      const Eigen::MatrixXd dw = w * eq.differentiation().transpose();
      // the border rows stored as columns (vt = V^T is m x 3): V z as three dot products
      Eigen::MatrixXd u = Eigen::MatrixXd::Zero(m, 3), vt = Eigen::MatrixXd::Zero(m, 3), corner = Eigen::MatrixXd::Zero(3, 3);
      for (int j = 0; j < nn; ++j) {
        const vec<double> wj = w.col(j);
        u.block(j * n, 0, n, 1) = -dw.col(j);
        u.block(j * n, 1, n, 1) = residual_d_mu(*sys_, wj, mu);
      }
      vt.col(0) = eq.phase_row();
      vt.col(1) = eq.amplitude_row();
      vt.col(2) = c.head(m);
      corner(1, 2) = -1;
      corner.row(2) = c.tail(3).transpose();
      state_in_.resize(m);
      state_out_.resize(m);
      auto op = [&](const vec<double>& z, vec<double>& y) {  // allocation-free: member buffers
        state_in_ = z.head(m);
        hill_.apply(state_in_, state_out_);
        y.head(m) = state_out_;
        y.head(m).noalias() += u * z.tail(3);
        y.tail(3).noalias() = vt.transpose() * z.head(m);
        y.tail(3).noalias() += corner * z.tail(3);
      };
      auto state_pre = [&](const vec<double>& r, vec<double>& z) { hill_.precondition(r, z); };
      internal::border_elimination<double> border;
      border.compute(state_pre, m, u, vt.transpose(), corner, internal::concat(who_, ": harmonic-balance border"));
      auto pre_full = [&](const vec<double>& r, vec<double>& z) { border.apply(state_pre, r, z); };
      const krylov_options ko = o_.gmres_options(next_tolerance_.value_or(o_.krylov.relative_tolerance), who_);
      next_tolerance_.reset();
      vec<double> dx = vec<double>::Zero(rhs.size());
      const krylov_report rep = gmres<double>(op, pre_full, rhs, dx, ko);
      iterations_ += rep.iterations;
      bytes_ = hill_.bytes() + std::size_t(internal::krylov_basis_size(ko) + 1 + 6 +
                                           (ko.deflation > 0 ? ko.deflation + 2 : 0)) *
                                   std::size_t(m + 3) * sizeof(double);
      if (!rep.converged && !(rep.relative_residual <= std::max(o_.accept_tolerance, ko.relative_tolerance)))
        throw convergence_error(internal::concat(ko.context, ": not converged in ", rep.iterations,
                                                 " iterations (relative residual ", rep.relative_residual, ", ",
                                                 rep.reason, ")"));
      return dx;
    }

   private:
    hb_krylov o_;
    const internal::harmonic_balance_equations<S>* eq_;
    const S* sys_;
    const char* who_;
    internal::hill_operator<B, S> hill_;
    vec<double> state_in_, state_out_;
    std::optional<double> next_tolerance_;
    int iterations_ = 0;
    std::size_t bytes_ = 0;
  };
  /// The GMRES options of a solve to relative tolerance tol.
  krylov_options gmres_options(double tol, const char* who) const {
    krylov_options ko = krylov;
    ko.relative_tolerance = tol;
    ko.context = internal::concat(who, ": GMRES on the harmonic-balance Jacobian");
    return ko;
  }
  template <dynamical_system S>
  solver<S> make(const internal::harmonic_balance_equations<S>& eq, const S& sys, const char* who) const {
    const double tol = krylov.relative_tolerance;
    require(fill_level >= 0 && std::isfinite(tol) && tol > 0 && std::isfinite(accept_tolerance) &&
                accept_tolerance >= tol && krylov.max_iterations >= 1 && eta_max > 0 && eta_max < 1,
            who, ": hb_krylov options out of range (fill_level ", fill_level, ", krylov.relative_tolerance ", tol,
            ", accept_tolerance ", accept_tolerance, ", eta_max ", eta_max, ", krylov.max_iterations ",
            krylov.max_iterations, ")");
    validate_krylov_options(krylov, internal::concat(who, ": hb_krylov::krylov"));  // restart, deflation
    return solver<S>(*this, eq, sys, who);
  }
};

/// Solves the harmonic-balance system from a guess with either the amplitude a or the parameter
/// mu held at `value` (the guess's own value when nullopt). The number of harmonics is the guess's
/// (resample() changes it). Throws convergence_error when Newton fails.
template <dynamical_system S, class Strategy = hb_direct>
lco_solution solve_lco(const S& sys, const lco_solution& guess, const vec<double>& probe, lco_fix fix,
                       std::optional<double> value = std::nullopt, const harmonic_balance_options& o = {},
                       const Strategy& strategy = {}) {
  const char* who = "solve_lco";
  internal::check_hb_options(o, who);
  internal::check_guess(sys, guess, probe, who);
  const auto t0 = std::chrono::steady_clock::now();
  const internal::harmonic_balance_equations<S> eq(sys, probe, guess.harmonics);
  vec<double> x = eq.pack(guess);
  vec<double> c = vec<double>::Zero(eq.unknowns());
  const Eigen::Index j = fix == lco_fix::amplitude ? eq.amplitude_index() : eq.mu_index();
  c[j] = 1;
  const double v = value.value_or(x[j]);
  require(std::isfinite(v), who, ": the fixed value is not finite");
  x[j] = v;
  auto lin = strategy.make(eq, sys, who);
  const auto r = internal::hb_newton(eq, x, c, v, o, who, lin);
  lco_solution s = eq.unpack(r.x);
  s.newton_iterations = r.iterations;
  s.linear_iterations = r.linear_iterations;
  s.linear_bytes = r.linear_bytes;
  s.residual = r.residual;
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

/// Floquet exponents of a cycle by Hill's method (file comment).
struct floquet_result {
  std::vector<std::complex<double>> exponents;  ///< n exponents, by decreasing real part
  std::complex<double> trivial;                 ///< the one nearest 0 (the phase shift)
  double max_real = -INFINITY;                  ///< largest real part without the trivial one
  bool stable = false;                          ///< max_real < 0
  double period = 0;
  /// hill_floquet: every exponent (complete). hill_floquet_krylov: only those whose copies lie
  /// within `radius` of the real `shift` (the exponents near 0, the ones a cycle's stability
  /// turns on next to a Hopf point or a fold); the rest of the spectrum is not seen.
  bool complete = true;
  double shift = 0, radius = INFINITY;
  int linear_solves = 0, linear_iterations = 0;  ///< hill_floquet_krylov's GMRES work
  /// Floquet multipliers exp(sigma T).
  std::vector<std::complex<double>> multipliers() const {
    std::vector<std::complex<double>> m;
    for (const auto& s : exponents) m.push_back(std::exp(s * period));
    return m;
  }
};

namespace internal {
/// The energy-weighted mean harmonic index kbar over k = -H .. H of a vector of Hill's matrix
/// (N blocks of n): the Lazarus-Thomas criterion of the file comment.
inline double mean_harmonic_index(const Eigen::Ref<const Eigen::VectorXcd>& v, Eigen::Index n, int h) {
  const int nn = 2 * h + 1;
  double e = 0, ke = 0;
  Eigen::VectorXcd ck(n);
  for (int k = -h; k <= h; ++k) {
    ck.setZero();
    for (int j = 0; j < nn; ++j) ck += v.segment(j * n, n) * std::polar(1.0, -2 * std::numbers::pi * k * j / nn);
    const double ek = ck.squaredNorm();
    e += ek;
    ke += k * ek;
  }
  return e > 0 ? ke / e : 0.0;
}

/// Sorts by decreasing real part; the trivial exponent (the given one, else the one nearest 0),
/// the largest other real part and the verdict.
inline void classify_exponents(floquet_result& r, std::optional<std::complex<double>> trivial = std::nullopt) {
  std::sort(r.exponents.begin(), r.exponents.end(), [](const auto& a, const auto& b) { return a.real() > b.real(); });
  std::size_t it = 0;
  for (std::size_t m = 1; m < r.exponents.size(); ++m)
    if (trivial ? r.exponents[m] == *trivial : std::abs(r.exponents[m]) < std::abs(r.exponents[it])) it = m;
  r.trivial = r.exponents[it];
  r.max_real = -INFINITY;
  for (std::size_t m = 0; m < r.exponents.size(); ++m)
    if (m != it) r.max_real = std::max(r.max_real, r.exponents[m].real());
  r.stable = r.max_real < 0;
}
}  // namespace internal

struct hill_options {
  Eigen::Index max_size = 6000;  ///< largest N n for the dense eigen-decomposition
};

template <dynamical_system S>
floquet_result hill_floquet(const S& sys, const lco_solution& s, const hill_options& o = {}) {
  const char* who = "hill_floquet";
  internal::check_guess(sys, s, vec<double>::Ones(sys.size()), who);
  const Eigen::Index n = sys.size();
  const int nn = s.instance_count(), h = s.harmonics;
  require(n * nn <= o.max_size, who, ": Hill's matrix would be ", n * nn, " x ", n * nn,
          " (dense), above hill_options::max_size = ", o.max_size);
  const internal::harmonic_balance_equations<S> eq(sys, vec<double>::Ones(n), h);
  Eigen::EigenSolver<Eigen::MatrixXd> es(eq.hill_matrix(s), true);
  require(es.info() == Eigen::Success, who, ": the eigen-decomposition of Hill's matrix failed");
  const Eigen::VectorXcd lam = es.eigenvalues();
  const Eigen::MatrixXcd v = es.eigenvectors();
  struct cand {
    std::complex<double> l;
    double kbar;
  };
  std::vector<cand> cs;
  for (Eigen::Index m = 0; m < lam.size(); ++m)
    cs.push_back({lam[m], internal::mean_harmonic_index(v.col(m), n, h)});
  std::stable_sort(cs.begin(), cs.end(), [](const cand& a, const cand& b) {
    if (std::abs(a.kbar) != std::abs(b.kbar)) return std::abs(a.kbar) < std::abs(b.kbar);
    return std::abs(a.l.imag()) < std::abs(b.l.imag());
  });
  floquet_result r;
  r.period = s.period();
  for (Eigen::Index m = 0; m < n; ++m) r.exponents.push_back(cs[std::size_t(m)].l);
  internal::classify_exponents(r);
  return r;
}

/// Options of hill_floquet_krylov.
struct hill_krylov_options {
  /// real shift of the shift-invert Arnoldi; NaN: 0.01 omega (a shift near 0 separates the two
  /// exponents nearest 0 from the rest: on the coarse aerofoil one pass of 10 instead of three)
  double shift = NAN;
  /// exponents centred on harmonic 0 to converge, nearest the shift first, the trivial one among
  /// them (2: it and the exponent that decides stability next to a Hopf point or a fold)
  int exponents = 2;
  int subspace = 10;          ///< Arnoldi basis size (one GMRES solve per vector)
  int restarts = 4;           ///< explicit restarts from the unconverged Ritz vectors
  double tolerance = 1e-7;    ///< ||Hill x - lambda x|| <= tolerance max(1, |lambda|) ||x||
  int fill_level = 1;         ///< of the per-harmonic BILU(k)
  bool single_precision_factors = false;  ///< as hb_krylov
  hb_preconditioner_state preconditioner = hb_preconditioner_state::mean_jacobian;
  /// The GMRES of each shifted solve: relative tolerance 1e-8, at most 1,000 iterations,
  /// GMRES(100) (GMRES(50) stagnates at 1.05 Ubar* on the coarse aerofoil); krylov.deflation = k
  /// gives GMRES-DR(100, k).
  krylov_options krylov{.relative_tolerance = 1e-8, .max_iterations = 1000, .restart = 100, .record_history = false};
};

/// The Floquet exponents of a cycle nearest 0 by Hill's method without forming Hill's matrix, for
/// CFD-sized systems: shift-invert Arnoldi on Hill's matrix (the exact bordered Jacobians of the
/// instances, blocks of B) at a real shift sigma, each (Hill - sigma I) x = v by GMRES with the
/// harmonic preconditioner of hb_krylov shifted by sigma. The Ritz pairs are taken nearest sigma
/// first while their true residuals meet the tolerance (so that no eigenvalue within the radius
/// of the last one is missed), until `exponents` of them are centred on harmonic 0 (|kbar| <=
/// 1/2, the file comment's criterion) with the trivial one among them, identified by its
/// eigenvector (parallel to dw/dtau: a phase shift of the cycle); explicit restarts from those
/// Ritz vectors otherwise. The verdict is as in hill_floquet. sigma a little right of 0 puts an
/// unstable exponent near 0 nearer than a stable one. The result is partial
/// (floquet_result::complete false, radius = the distance of the farthest converged eigenvalue
/// from sigma): an exponent farther out (a secondary bifurcation far from onset) is not seen.
/// Throws convergence_error when a GMRES solve fails or the Arnoldi passes do not converge.
template <int B, dynamical_system S>
floquet_result hill_floquet_krylov(const S& sys, const lco_solution& s, const hill_krylov_options& o = {}) {
  using C = std::complex<double>;
  const char* who = "hill_floquet_krylov";
  internal::check_guess(sys, s, vec<double>::Ones(sys.size()), who);
  require(o.exponents >= 1 && o.subspace > o.exponents + 2 && o.restarts >= 0 && std::isfinite(o.tolerance) &&
              o.tolerance > 0 && o.fill_level >= 0 && std::isfinite(o.krylov.relative_tolerance) &&
              o.krylov.relative_tolerance > 0 && o.krylov.max_iterations >= 1 && !std::isinf(o.shift),
          who, ": options out of range (exponents ", o.exponents, ", subspace ", o.subspace, " > exponents + 2, restarts ",
          o.restarts, ", tolerance ", o.tolerance, ", fill_level ", o.fill_level, ", krylov.relative_tolerance ",
          o.krylov.relative_tolerance, ", krylov.max_iterations ", o.krylov.max_iterations, ", shift ", o.shift, ")");
  validate_krylov_options(o.krylov, internal::concat(who, ": krylov"));  // restart, deflation
  const Eigen::Index n = sys.size();
  const int h = s.harmonics, nn = s.instance_count();
  const Eigen::Index m = n * nn;
  const double sigma = std::isnan(o.shift) ? 0.01 * s.omega : o.shift;
  const Eigen::MatrixXd d = fourier_differentiation_matrix(nn);
  internal::hill_operator<B, S> hill;
  hill.build(sys, s.instances, s.mu, s.omega, sigma, d, o.fill_level, o.single_precision_factors, o.preconditioner,
             who);
  auto op = [&](const vec<double>& x, vec<double>& y) { hill.apply(x, y); };
  auto pre = [&](const vec<double>& r, vec<double>& z) { hill.precondition(r, z); };
  krylov_options ko = o.krylov;
  ko.context = internal::concat(who, ": GMRES on Hill's matrix - ", sigma, " I");
  int solves = 0, iterations = 0;
  auto solve = [&](const vec<double>& v) {
    vec<double> x = vec<double>::Zero(m);
    const krylov_report rep = gmres<double>(op, pre, v, x, ko);
    ++solves;
    iterations += rep.iterations;
    if (!rep.converged)
      throw convergence_error(internal::concat(ko.context, ": solve ", solves, " not converged in ", rep.iterations,
                                               " iterations (relative residual ", rep.relative_residual, ", ",
                                               rep.reason, ")"));
    return x;
  };
  const int msub = int(std::min<Eigen::Index>(o.subspace, m));
  vec<double> v0(m);
  for (Eigen::Index i = 0; i < m; ++i) v0[i] = 1 + 0.3 * std::sin(0.9 * double(i)) + 0.2 * std::cos(2.3 * double(i));
  std::vector<C> lambda;
  // align: |cos| between the eigenvector and dw/dtau, the trivial one's (the best aligned of the
  // centred ones, at least 1/2: truncation to H harmonics tilts it, most at H = 1)
  std::vector<double> kbar, align;
  vec<double> dw(m);
  Eigen::Map<Eigen::MatrixXd>(dw.data(), n, nn) = s.instances * d.transpose();
  double radius = 0, worst = 0;
  vec<double> tr(m), ti(m);
  for (int pass = 0; pass <= o.restarts; ++pass) {
    Eigen::MatrixXd v(m, msub + 1), hh = Eigen::MatrixXd::Zero(msub + 1, msub);
    v.col(0) = v0.normalized();
    int k = msub;
    for (int j = 0; j < msub; ++j) {
      vec<double> w = solve(v.col(j));
      for (int twice = 0; twice < 2; ++twice)  // classical Gram-Schmidt, twice
        for (int i = 0; i <= j; ++i) {
          const double hij = v.col(i).dot(w);
          hh(i, j) += hij;
          w -= hij * v.col(i);
        }
      hh(j + 1, j) = w.norm();
      if (!(hh(j + 1, j) > 1e-14 * hh.col(j).head(j + 1).norm())) {  // an invariant subspace
        k = j + 1;
        break;
      }
      v.col(j + 1) = w / hh(j + 1, j);
    }
    Eigen::EigenSolver<Eigen::MatrixXd> es(hh.topLeftCorner(k, k), true);
    require(es.info() == Eigen::Success, who, ": the eigen-decomposition of the Arnoldi matrix failed");
    std::vector<int> idx(std::size_t(k), 0);
    for (int i = 0; i < k; ++i) idx[std::size_t(i)] = i;
    std::sort(idx.begin(), idx.end(),
              [&](int a, int b) { return std::abs(es.eigenvalues()[a]) > std::abs(es.eigenvalues()[b]); });
    lambda.clear();
    kbar.clear();
    align.clear();
    radius = worst = 0;
    v0.setZero();
    // the converged prefix of the Ritz values ordered by distance from sigma: complete within its radius
    bool prefix = true;
    int centred = 0;
    bool has_trivial = false;
    for (int r = 0; r < k; ++r) {
      const C theta = es.eigenvalues()[idx[std::size_t(r)]];
      const Eigen::VectorXcd x = v.leftCols(k).cast<C>() * es.eigenvectors().col(idx[std::size_t(r)]);
      const C lam = sigma + 1.0 / theta;
      const vec<double> xr = x.real(), xi = x.imag();
      hill.apply(xr, tr);
      hill.apply(xi, ti);
      const double res = (tr.cast<C>() + C(0, 1) * ti.cast<C>() - x / theta).norm() / x.norm();
      const double rel = res / std::max(1.0, std::abs(lam));
      if (rel <= o.tolerance && prefix) {
        lambda.push_back(lam);
        kbar.push_back(internal::mean_harmonic_index(x, n, h));
        align.push_back(std::abs(dw.cast<C>().dot(x)) / (dw.norm() * x.norm()));
        radius = std::abs(lam - sigma);
        if (std::abs(kbar.back()) <= 0.5) {
          ++centred;
          has_trivial = has_trivial || align.back() >= 0.5;
        }
      } else {
        if (prefix) worst = rel;
        prefix = false;
      }
      v0 += (xr + xi) / x.norm();  // the restart: the Ritz vectors up to the wanted ones
      if (centred >= o.exponents && has_trivial) break;
      if (!prefix && r + 1 >= o.exponents + 2) break;
    }
    if ((centred >= o.exponents && has_trivial) || k < msub) break;
    if (pass == o.restarts)
      throw convergence_error(internal::concat(
          who, ": ", centred, " exponents centred on harmonic 0", has_trivial ? " (the trivial one among them)" : "",
          " in the converged ", lambda.size(), " eigenvalues of Hill's matrix nearest ", sigma, ", ", o.exponents,
          " wanted, after ", o.restarts + 1, " Arnoldi passes of ", msub, " (", solves,
          " GMRES solves; first unconverged relative residual ", worst, ", tolerance ", o.tolerance, ")"));
  }
  floquet_result r;
  r.period = s.period();
  r.complete = false;
  r.shift = sigma;
  r.radius = radius;
  r.linear_solves = solves;
  r.linear_iterations = iterations;
  std::optional<C> trivial;
  double best = 0;
  for (std::size_t q = 0; q < lambda.size(); ++q)
    if (std::abs(kbar[q]) <= 0.5) {
      r.exponents.push_back(lambda[q]);
      if (align[q] > best) best = align[q], trivial = lambda[q];
    }
  require(best >= 0.5, who, ": internal: the trivial exponent was not kept");
  internal::classify_exponents(r, trivial);
  return r;
}

/// One point of an LCO branch.
struct lco_branch_point {
  lco_solution cycle;
  double probe_amplitude = 0;           ///< half peak-to-peak of the probe (probe_peak_amplitude)
  std::optional<floquet_result> floquet;  ///< when stability is computed
  bool landed = false;                  ///< on a listed mu target
  double seconds = 0;                   ///< wall time of the step with the stability (cycle.seconds: without)
};

struct lco_branch_options {
  harmonic_balance_options newton;
  double mu_scale = 1, amplitude_scale = 1;  ///< the metric: (dmu / mu_scale)^2 + (da / amplitude_scale)^2
  double step = 0.05, min_step = 1e-6, max_step = 0.2;  ///< arclength steps in that metric
  /// the step grows (x 1.5) after a corrector of at most this many Newton iterations; 0: 3 for
  /// exact Newton (hb_direct, hb_krylov without adaptive_tolerance), 4 for the inexact Newton of an
  /// adaptive hb_krylov (one iteration more for the same step: with 3 its steps stop growing and
  /// the coarse aerofoil's branch to 1.05 Ubar* takes 38 points instead of 23)
  int fast_iterations = 0;
  int max_points = 60;                  ///< start included
  double amplitude_max = INFINITY;      ///< stop beyond this first-harmonic amplitude
  double mu_min = -INFINITY, mu_max = INFINITY;
  std::vector<double> mu_targets;       ///< landed on exactly (strictly monotone along the branch)
  int mu_direction = 0;                 ///< first step: 0 towards larger amplitude, +1 / -1 towards larger / smaller mu
  bool stability = true;                ///< Hill's method at each point (if N n <= hill.max_size)
  hill_options hill;
  std::ostream* log = nullptr;
};

struct lco_branch {
  std::vector<lco_branch_point> points;
  std::string stop_reason;
};

/// Continues a cycle in (mu, a) by the curve stepper (secant predictor, arclength row in the
/// metric of the options), from a solved start (solve_lco) towards larger amplitude or the
/// options' mu_direction. Points are
/// emitted to `on_point` as they are found (it may return true to stop) and returned.
template <dynamical_system S, class OnPoint, class Strategy = hb_direct>
lco_branch trace_lco_branch(const S& sys, const lco_solution& start, const vec<double>& probe,
                            const lco_branch_options& o, OnPoint&& on_point, const Strategy& strategy = {}) {
  const char* who = "trace_lco_branch";
  internal::check_hb_options(o.newton, who);
  internal::check_guess(sys, start, probe, who);
  require(o.mu_direction >= -1 && o.mu_direction <= 1, who, ": mu_direction must be -1, 0 or +1 (got ", o.mu_direction, ")");
  require(o.fast_iterations >= 0, who, ": fast_iterations must be >= 0 (got ", o.fast_iterations, ")");
  require(std::isfinite(o.mu_scale) && o.mu_scale > 0 && std::isfinite(o.amplitude_scale) && o.amplitude_scale > 0, who,
          ": mu_scale and amplitude_scale must be finite and > 0");
  const internal::harmonic_balance_equations<S> eq(sys, probe, start.harmonics);
  const Eigen::Index nx = eq.unknowns(), im = eq.mu_index(), ia = eq.amplitude_index();
  vec<double> weight = vec<double>::Zero(nx);
  weight[im] = 1 / (o.mu_scale * o.mu_scale);
  weight[ia] = 1 / (o.amplitude_scale * o.amplitude_scale);
  const curve_metric metric(weight);
  const bool hill = o.stability && sys.size() * start.instance_count() <= o.hill.max_size;
  lco_branch out;
  int last_linear = start.linear_iterations;
  std::size_t last_bytes = start.linear_bytes;
  auto record = [&](const vec<double>& x, int iterations, double residual, bool landed, double seconds) {
    const auto t0 = std::chrono::steady_clock::now();
    lco_branch_point p;
    p.cycle = eq.unpack(x);
    p.cycle.newton_iterations = iterations;
    p.cycle.linear_iterations = last_linear;
    p.cycle.linear_bytes = last_bytes;
    p.cycle.residual = residual;
    p.probe_amplitude = probe_peak_amplitude(p.cycle, probe);
    if (hill) p.floquet = hill_floquet(sys, p.cycle, o.hill);
    p.landed = landed;
    p.cycle.seconds = seconds;
    p.seconds = seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.log) {
      *o.log << who << ": point " << out.points.size() << "  mu " << p.cycle.mu << "  a " << p.cycle.amplitude
             << "  peak " << p.probe_amplitude << "  omega " << p.cycle.omega << "  Newton " << iterations;
      if (p.floquet) *o.log << "  max Re(sigma) " << p.floquet->max_real << (p.floquet->stable ? " stable" : " unstable");
      *o.log << (landed ? "  (landed)" : "") << "\n";
    }
    out.points.push_back(std::move(p));
    return on_point(out.points.back());
  };
  struct corrected : curve_corrected {
    double residual = 0;
  };
  double last_residual = start.residual;
  auto lin = strategy.make(eq, sys, who);
  curve_problem prob{
      [&](const curve_request& q, std::string& why) -> std::optional<corrected> {
        try {
          const auto r = internal::hb_newton(eq, q.x0, q.c, q.value, o.newton, who, lin);
          last_linear = r.linear_iterations;
          last_bytes = r.linear_bytes;
          corrected c;
          c.x = r.x;
          c.iterations = r.iterations;
          c.residual = r.residual;
          last_residual = r.residual;
          return c;
        } catch (const convergence_error& e) {
          why = e.what();
        } catch (const singular_matrix_error& e) {
          why = e.what();
        }
        return std::nullopt;
      },
      [&](const vec<double>& x, const vec<double>& c) -> vec<double> {  // [F_x; c^T] t = e_last
        return lin(x, c, vec<double>::Unit(nx, nx - 1));
      },
      [&](const vec<double>& x, const curve_point_info& info) {
        return record(x, info.start ? start.newton_iterations : info.iterations,
                      info.start ? start.residual : last_residual, info.landed, info.seconds);
      }};
  curve_stepper_options so;
  so.step = o.step;
  so.min_step = o.min_step;
  so.max_step = o.max_step;
  so.fast_iterations = o.fast_iterations;
  if (o.fast_iterations == 0) {
    so.fast_iterations = 3;
    if constexpr (requires { strategy.adaptive_tolerance; })
      if (strategy.adaptive_tolerance) so.fast_iterations = 4;
  }
  so.max_points = o.max_points;
  so.label = who;
  so.log = o.log;
  if (!o.mu_targets.empty()) so.targets.push_back({im, o.mu_targets, "mu"});
  so.limits.push_back({im, o.mu_min, o.mu_max});
  so.limits.push_back({ia, -INFINITY, o.amplitude_max});
  // the exact unit tangent at the start, oriented by the options
  const vec<double> x0 = eq.pack(start);
  vec<double> c0 = vec<double>::Zero(nx);
  c0[im] = 1 / o.mu_scale;
  c0[ia] = 1 / o.amplitude_scale;
  vec<double> t0 = prob.tangent(x0, c0);
  require(metric.norm(t0) > 0 && t0.allFinite(), who, ": no tangent at the start (mu and a both stationary)");
  t0 /= metric.norm(t0);
  const double orient = o.mu_direction != 0 ? o.mu_direction * t0[im] : t0[ia];
  if (orient < 0) t0 = -t0;
  const curve_outcome oc = trace_curve(prob, x0, t0, metric, so);
  out.stop_reason = oc.reason;
  return out;
}

/// trace_lco_branch without a callback.
template <dynamical_system S>
lco_branch trace_lco_branch(const S& sys, const lco_solution& start, const vec<double>& probe,
                            const lco_branch_options& o = {}) {
  return trace_lco_branch(sys, start, probe, o, [](const lco_branch_point&) { return false; });
}

}  // namespace aerohopf
