#pragma once
// All crossings of the imaginary axis by eigenvalues of A(q) = A0 + q B over a frequency band,
// when the parameter enters only a small trailing set of rows: B is zero outside its last m rows
// (the aerofoil: q = 1/Ubar^2 enters only the structural stiffness, B confined to the trailing
// m x m block, spec 05; the wing: q = mu = rho c^3 multiplies the generalised forces, whose rows
// are structural but whose columns include the wall cells' flow unknowns). It needs sparse LU
// solves with the large block and no eigen-decomposition of A, so it checks on grids where a
// dense spectrum is out of reach that a Hopf point found by Newton or continuation is the
// LOWEST crossing (the flutter boundary) and not a later one.
//
// Split the unknowns into f (first n - m) and s (last m), B = [0 0; B_sf B_ss]. With
// X(w) = i w I - A_ff and Y(w) = X(w)^{-1} A_fs,
//     det(i w I - A(q)) = det X(w) det(E(w) - q H(w)),
//     E(w) = i w I - A_ss - A_sf Y(w),   H(w) = B_ss + B_sf Y(w)      (m x m),
// so, where X(w) is regular, i w is an eigenvalue of A(q) iff det(E(w) - q H(w)) = 0: q is the
// reciprocal of a nonzero eigenvalue of E(w)^{-1} H(w) (rank [B_sf B_ss] = r such roots q_k(w),
// as [Y; I] has full column rank). A crossing at a REAL q is a zero of Im q_k(w) along a root
// branch. The band [omega_min, omega_max] is sampled (one complex sparse LU of X(w) per sample:
// A_ff does not depend on q), the r roots are matched from sample to sample (nearest
// permutation), and every sign change of Im q_k is refined by the Illinois (modified regula
// falsi) iteration on w until the bracket is shorter than omega_tolerance. A sign change through
// a pole (|q| -> infinity) is not a crossing: a refined root must have |Im q| <= real_tolerance
// (1 + |q|), else it is dropped and counted in `rejected`. Not covered: w = 0 (static
// divergence: real q with det(E(0) - q H(0)) = 0, see `divergence_roots`) and crossings whose
// frequency lies outside the band or between two samples twice (two crossings of one branch
// closer than the sample spacing). Cost: one sparse LU of the flow block per sample, so in 3D
// it is for small grids (the 3D fill of a direct factorisation).
#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <complex>
#include <initializer_list>
#include <numeric>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"

namespace aerohopf {

struct axis_crossing {
  double q = 0;      ///< parameter value (real) at which the eigenvalue i omega lies on the axis
  double omega = 0;  ///< frequency of the crossing (> 0; its conjugate crosses at -omega)
  int branch = 0;    ///< root branch k of det(E(w) - q B_ss) = 0
  double residual = 0;  ///< |Im q| at the refined frequency
};

struct axis_crossing_options {
  double omega_min = 1e-3;
  double omega_max = 2.0;
  int samples = 400;               ///< equally spaced frequencies in [omega_min, omega_max]
  double omega_tolerance = 1e-10;  ///< bracket length at which the refinement stops
  int max_refinements = 80;
  double real_tolerance = 1e-6;    ///< |Im q| <= real_tolerance (1 + |q|) for an accepted root
  std::string context = "imaginary-axis crossings";
};

struct axis_crossing_result {
  std::vector<axis_crossing> crossings;  ///< sorted by q, largest first
  std::vector<std::complex<double>> divergence_roots;  ///< the roots q at omega = 0
  int rank = 0;                          ///< number of finite roots (rank of B_ss)
  int factorisations = 0;                ///< complex sparse LU factorisations of X(w)
  int rejected = 0;                      ///< sign changes of Im q through a pole
};

namespace internal {
/// The Schur-complement roots q_k(w) of det(E(w) - q B_ss) = 0 at one frequency (w = 0 allowed).
class axis_crossing_roots {
 public:
  using cplx = std::complex<double>;
  axis_crossing_roots(const Eigen::SparseMatrix<double>& a0, const Eigen::MatrixXd& b_ss,
                      const Eigen::SparseMatrix<double>& b_sf, const std::string& context)
      : m_(b_ss.rows()), nf_(a0.rows() - b_ss.rows()), b_(b_ss), lu_(context + ": sparse LU of i omega I - A_ff") {
    require(a0.rows() == a0.cols(), context, ": A0 is ", a0.rows(), "x", a0.cols(), ", not square");
    require(b_ss.rows() == b_ss.cols() && m_ >= 1 && nf_ >= 1, context, ": B_ss is ", b_ss.rows(), "x", b_ss.cols(),
            " for A0 of size ", a0.rows());
    require(b_ss.allFinite(), context, ": B_ss has non-finite entries");
    require(b_sf.size() == 0 || (b_sf.rows() == m_ && b_sf.cols() == nf_), context, ": B_sf is ", b_sf.rows(), "x",
            b_sf.cols(), ", not ", m_, "x", nf_, " (structural rows by flow columns)");
    std::vector<Eigen::Triplet<double>> tf;
    a_fs_ = Eigen::MatrixXd::Zero(nf_, m_);
    a_sf_ = Eigen::MatrixXd::Zero(m_, nf_);
    a_ss_ = Eigen::MatrixXd::Zero(m_, m_);
    for (int k = 0; k < a0.outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(a0, k); it; ++it) {
        const Eigen::Index i = it.row(), j = it.col();
        require(std::isfinite(it.value()), context, ": A0(", i, ", ", j, ") is not finite");
        if (i < nf_ && j < nf_)
          tf.emplace_back(int(i), int(j), -it.value());
        else if (i < nf_)
          a_fs_(i, j - nf_) = it.value();
        else if (j < nf_)
          a_sf_(i - nf_, j) = it.value();
        else
          a_ss_(i - nf_, j - nf_) = it.value();
      }
    for (Eigen::Index i = 0; i < nf_; ++i) tf.emplace_back(int(i), int(i), 0.0);  // the diagonal, for i w
    Eigen::SparseMatrix<double> minus_aff(nf_, nf_);
    minus_aff.setFromTriplets(tf.begin(), tf.end());
    minus_aff.makeCompressed();
    // X(w) = i w I - A_ff is formed once; per frequency only its diagonal values change
    x_ = minus_aff.cast<cplx>();
    x_.makeCompressed();
    diag_.resize(nf_);
    diag0_.resize(nf_);
    for (Eigen::Index i = 0; i < nf_; ++i) {
      const auto* first = x_.innerIndexPtr() + x_.outerIndexPtr()[i];
      const auto* last = x_.innerIndexPtr() + x_.outerIndexPtr()[i + 1];
      const auto* at = std::lower_bound(first, last, i);
      require(at != last && *at == i, context, ": no diagonal entry in column ", i, " of A_ff");
      diag_[i] = at - x_.innerIndexPtr();
      diag0_[i] = x_.valuePtr()[diag_[i]];
    }
    a_fs_c_ = a_fs_.cast<cplx>();
    a_sf_c_ = a_sf_.cast<cplx>();
    a_ss_c_ = a_ss_.cast<cplx>();
    b_c_ = b_.cast<cplx>();
    // rank of [B_sf B_ss]: its number of nonzero singular values (relative 1e-12), the SVD
    // taken over the columns where B_sf has entries (the wall cells' unknowns for a wing)
    std::vector<Eigen::Index> cols;
    if (b_sf.size() != 0) {
      b_sf_c_ = b_sf.cast<cplx>();
      b_sf_c_.makeCompressed();
      for (int k = 0; k < b_sf.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(b_sf, k); it; ++it) {
          require(std::isfinite(it.value()), context, ": B_sf(", it.row(), ", ", it.col(), ") is not finite");
          if (it.value() != 0) cols.push_back(it.col());
        }
      std::sort(cols.begin(), cols.end());
      cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
    }
    Eigen::MatrixXd rows(m_, m_ + static_cast<Eigen::Index>(cols.size()));
    rows.leftCols(m_) = b_ss;
    for (std::size_t c = 0; c < cols.size(); ++c) rows.col(m_ + static_cast<Eigen::Index>(c)) = b_sf.col(cols[c]);
    const Eigen::BDCSVD<Eigen::MatrixXd> svd(rows);
    const auto& sv = svd.singularValues();
    rank_ = 0;
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      if (sv[i] > 1e-12 * sv[0]) ++rank_;
    require(rank_ >= 1, context, ": B is zero: the parameter does not enter A");
  }
  int rank() const { return rank_; }
  int factorisations() const { return factorisations_; }

  /// The rank() roots q_k at frequency w, in no particular order.
  std::vector<cplx> at(double w) {
    for (Eigen::Index i = 0; i < nf_; ++i) x_.valuePtr()[diag_[i]] = diag0_[i] + cplx(0.0, w);
    lu_.compute(x_);
    ++factorisations_;
    const Eigen::MatrixXcd y = lu_.solve(a_fs_c_);
    Eigen::MatrixXcd e = -a_ss_c_ - a_sf_c_ * y;
    e.diagonal().array() += cplx(0.0, w);
    const Eigen::PartialPivLU<Eigen::MatrixXcd> elu(e);
    Eigen::MatrixXcd h = b_c_;  // H(w) = B_ss + B_sf Y(w)
    if (b_sf_c_.size() != 0) h += b_sf_c_ * y;
    const Eigen::MatrixXcd mb = elu.solve(h);
    const Eigen::ComplexEigenSolver<Eigen::MatrixXcd> es(mb, false);
    std::vector<cplx> nu(es.eigenvalues().data(), es.eigenvalues().data() + m_);
    std::sort(nu.begin(), nu.end(), [](cplx a, cplx b) { return std::abs(a) > std::abs(b); });
    std::vector<cplx> q;
    for (int k = 0; k < rank_; ++k) q.push_back(std::abs(nu[k]) > 0 ? 1.0 / nu[k] : cplx(INFINITY, 0.0));
    return q;
  }

 private:
  Eigen::Index m_, nf_;
  Eigen::MatrixXd b_, a_fs_, a_sf_, a_ss_;
  Eigen::MatrixXcd a_fs_c_, a_sf_c_, a_ss_c_, b_c_;  // complex copies, made once
  Eigen::SparseMatrix<cplx> b_sf_c_;                // B_sf (empty: B confined to the m x m block)
  Eigen::SparseMatrix<cplx> x_;                     // i w I - A_ff at the last w
  std::vector<Eigen::Index> diag_;                  // positions of its diagonal in valuePtr()
  std::vector<cplx> diag0_;                         // and their values at w = 0
  direct_solver<Eigen::SparseMatrix<cplx>> lu_;
  int rank_ = 0, factorisations_ = 0;
};

/// The permutation of `now` nearest to `before` (sum of distances; r <= 6 by brute force, else greedy).
inline std::vector<std::complex<double>> match_roots(const std::vector<std::complex<double>>& before,
                                                     std::vector<std::complex<double>> now) {
  const std::size_t r = now.size();
  std::vector<std::size_t> perm(r), best;
  std::iota(perm.begin(), perm.end(), 0);
  double best_cost = INFINITY;
  if (r <= 6) {
    do {
      double c = 0;
      for (std::size_t k = 0; k < r; ++k) c += std::abs(now[perm[k]] - before[k]);
      if (c < best_cost) {
        best_cost = c;
        best = perm;
      }
    } while (std::next_permutation(perm.begin(), perm.end()));
  } else {
    std::vector<bool> used(r, false);
    for (std::size_t k = 0; k < r; ++k) {
      std::size_t j_best = 0;
      double d_best = INFINITY;
      for (std::size_t j = 0; j < r; ++j)
        if (!used[j] && std::abs(now[j] - before[k]) < d_best) {
          d_best = std::abs(now[j] - before[k]);
          j_best = j;
        }
      used[j_best] = true;
      best.push_back(j_best);
    }
  }
  std::vector<std::complex<double>> out(r);
  for (std::size_t k = 0; k < r; ++k) out[k] = now[best[k]];
  return out;
}
}  // namespace internal

/// A(q) = A0 + q B from the matrices j1 = A(q1) and j2 = A(q2), q1 != q2, of a matrix affine in q;
/// throws input_error if j1 - j2 has an entry outside the trailing m rows. Affinity itself is the
/// caller's to know (or to check with a third matrix).
struct affine_split {
  Eigen::SparseMatrix<double> a0;    ///< A(0)
  Eigen::MatrixXd b_ss;              ///< the trailing m x m block of dA/dq
  Eigen::SparseMatrix<double> b_sf;  ///< the trailing rows' flow columns of dA/dq (m x (n - m); often zero)
};
inline affine_split split_affine(const Eigen::SparseMatrix<double>& j1, double q1, const Eigen::SparseMatrix<double>& j2,
                                 double q2, Eigen::Index m, const std::string& context = "split_affine") {
  require(j1.rows() == j1.cols() && j2.rows() == j1.rows() && j2.cols() == j1.cols(), context,
          ": matrices of different sizes (", j1.rows(), "x", j1.cols(), ", ", j2.rows(), "x", j2.cols(), ")");
  require(std::isfinite(q1) && std::isfinite(q2) && q1 != q2, context, ": need finite q1 != q2 (got ", q1, ", ", q2, ")");
  const Eigen::Index n = j1.rows();
  require(m >= 1 && m < n, context, ": trailing block size ", m, " for matrices of size ", n);
  // Non-finite entries are refused here: NaN - NaN is not zero, so they would otherwise be
  // reported as a dependence on q outside the trailing rows.
  for (const auto* j : {&j1, &j2})
    for (int k = 0; k < j->outerSize(); ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(*j, k); it; ++it)
        require(std::isfinite(it.value()), context, ": ", j == &j1 ? "j1" : "j2", "(", it.row(), ", ", it.col(),
                ") is not finite (", it.value(), ")");
  const Eigen::SparseMatrix<double> d = j1 - j2;
  const Eigen::Index nf = n - m;
  affine_split out;
  out.b_ss = Eigen::MatrixXd::Zero(m, m);
  std::vector<Eigen::Triplet<double>> b_all, b_sf;
  for (int k = 0; k < d.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(d, k); it; ++it) {
      if (it.value() == 0) continue;
      require(it.row() >= nf, context, ": the matrix depends on q at (", it.row(), ", ", it.col(),
              "), outside the trailing ", m, " rows");
      const double b = it.value() / (q1 - q2);
      b_all.emplace_back(int(it.row()), int(it.col()), b);
      if (it.col() >= nf)
        out.b_ss(it.row() - nf, it.col() - nf) = b;
      else
        b_sf.emplace_back(int(it.row() - nf), int(it.col()), b);
    }
  Eigen::SparseMatrix<double> bm(n, n);
  bm.setFromTriplets(b_all.begin(), b_all.end());
  out.a0 = j1 - q1 * bm;
  out.a0.makeCompressed();
  out.b_sf.resize(m, nf);
  out.b_sf.setFromTriplets(b_sf.begin(), b_sf.end());
  out.b_sf.makeCompressed();
  return out;
}

/// All crossings of the imaginary axis by eigenvalues of A0 + q B, B = [0 0; B_sf B_ss] nonzero
/// only in its trailing m rows (b_sf empty: B confined to the trailing block b_ss), with
/// frequency in [omega_min, omega_max] (file comment).
inline axis_crossing_result imaginary_axis_crossings(const Eigen::SparseMatrix<double>& a0, const Eigen::MatrixXd& b_ss,
                                                     const Eigen::SparseMatrix<double>& b_sf,
                                                     const axis_crossing_options& opt = {}) {
  const std::string& ctx = opt.context;
  require(std::isfinite(opt.omega_max) && opt.omega_min > 0 && opt.omega_max > opt.omega_min && opt.samples >= 2, ctx,
          ": need 0 < omega_min < omega_max and samples >= 2 (got ", opt.omega_min, ", ", opt.omega_max, ", ",
          opt.samples, ")");
  require(std::isfinite(opt.omega_tolerance) && opt.omega_tolerance > 0 && std::isfinite(opt.real_tolerance) &&
              opt.real_tolerance > 0 && opt.max_refinements >= 1,
          ctx, ": tolerances must be finite and > 0 and max_refinements >= 1 (got omega_tolerance ",
          opt.omega_tolerance, ", real_tolerance ", opt.real_tolerance, ", max_refinements ", opt.max_refinements, ")");
  internal::axis_crossing_roots roots(a0, b_ss, b_sf, ctx);
  axis_crossing_result res;
  res.rank = roots.rank();
  res.divergence_roots = roots.at(0.0);
  const double dw = (opt.omega_max - opt.omega_min) / (opt.samples - 1);
  double w_prev = opt.omega_min;
  std::vector<std::complex<double>> q_prev = roots.at(w_prev);
  for (int j = 1; j < opt.samples; ++j) {
    const double w = opt.omega_min + j * dw;
    const std::vector<std::complex<double>> q = internal::match_roots(q_prev, roots.at(w));
    for (int k = 0; k < res.rank; ++k) {
      const double fa0 = q_prev[k].imag(), fb0 = q[k].imag();
      if (!(std::isfinite(fa0) && std::isfinite(fb0)) || fa0 * fb0 > 0 || (fa0 == 0 && fb0 == 0)) continue;
      // Illinois on Im q_k(w); the branch is followed by the root nearest the interpolation of q_k
      double a = w_prev, b = w, fa = fa0, fb = fb0;
      std::complex<double> qa = q_prev[k], qb = q[k];
      int side = 0;
      for (int it = 0; it < opt.max_refinements && b - a > opt.omega_tolerance; ++it) {
        double c = fa == fb ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b)) c = 0.5 * (a + b);
        const double t = (c - a) / (b - a);
        const std::complex<double> guess = qa + t * (qb - qa);
        const std::vector<std::complex<double>> qs = roots.at(c);
        const std::complex<double> qc = *std::min_element(qs.begin(), qs.end(), [&](auto u, auto v) { return std::abs(u - guess) < std::abs(v - guess); });
        const double fc = qc.imag();
        if (fc == 0) {
          a = b = c;
          qa = qb = qc;
          break;
        }
        if (fc * fb < 0) {  // the zero lies in (c, b)
          a = c;
          fa = fc;
          qa = qc;
          if (side == -1) fb *= 0.5;  // b kept twice in a row: Illinois
          side = -1;
        } else {  // in (a, c)
          b = c;
          fb = fc;
          qb = qc;
          if (side == +1) fa *= 0.5;
          side = +1;
        }
      }
      const bool at_a = std::abs(qa.imag()) < std::abs(qb.imag());
      const std::complex<double> qr = at_a ? qa : qb;
      const double wr = at_a ? a : b;
      if (std::isfinite(std::abs(qr)) && std::abs(qr.imag()) <= opt.real_tolerance * (1 + std::abs(qr)))
        res.crossings.push_back({qr.real(), wr, k, std::abs(qr.imag())});
      else
        ++res.rejected;
    }
    q_prev = q;
    w_prev = w;
  }
  std::sort(res.crossings.begin(), res.crossings.end(), [](const auto& u, const auto& v) { return u.q > v.q; });
  res.factorisations = roots.factorisations();
  return res;
}

/// B confined to the trailing m x m block b_ss (the aerofoil).
inline axis_crossing_result imaginary_axis_crossings(const Eigen::SparseMatrix<double>& a0, const Eigen::MatrixXd& b_ss,
                                                     const axis_crossing_options& opt = {}) {
  return imaginary_axis_crossings(a0, b_ss, Eigen::SparseMatrix<double>(), opt);
}

/// The split of split_affine.
inline axis_crossing_result imaginary_axis_crossings(const affine_split& sp, const axis_crossing_options& opt = {}) {
  return imaginary_axis_crossings(sp.a0, sp.b_ss, sp.b_sf, opt);
}

}  // namespace aerohopf
