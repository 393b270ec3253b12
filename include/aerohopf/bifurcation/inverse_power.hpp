#pragma once
// Shift-invert inverse power iteration with a complex shift (spec 02):
//
//     (A - sigma I) y^t = x^{t-1},    x^t = y^t / ||y^t||
//
// converges to the eigenvector whose eigenvalue is nearest sigma, at the rate
// |lambda_1 - sigma| / |lambda_2 - sigma|. It is used (a) to start the Hopf Newton iteration from
// a structural frequency, (b) to trace an aeroelastic eigenvalue along mu (root locus, the
// previous eigenvalue as the next shift) and (c) for the adjoint eigenvector q of the
// centre-manifold reduction. The shifted matrix is factored once and reused every iteration.
// The complex form A - sigma I is preferred over the real 2n form: it keeps the sparsity of A.
//
// Eigenvalue estimate: with C = A - sigma I and C y = x, the Rayleigh quotient of C on y is
// <y, C y>/<y, y> = <y, x>/<y, y>, so lambda = sigma + <y, x>/<y, y>.
// Convergence: ||A x - lambda x||_2 <= max(tolerance max(1, |lambda|), 100 eps ||A||_inf) with
// ||x||_2 = 1: the residual cannot drop below about eps ||A|| (stiff discretisations have a
// large ||A||, e.g. 1/h^2).
//
// Solver: the shifted matrix is factored by direct_solver (sparse or dense LU) unless a solver
// of the same compute/solve interface is passed: krylov_solver<Eigen::SparseMatrix<complex>, B>
// (complex BILU(k) of A - sigma I + GMRES, linalg/krylov_solver.hpp) is the route for CFD
// sizes, whose LU fills in beyond memory (krylov_solver::precondition_with: BILU of the
// cheaper modified-order L - sigma I, operator exact). Its solves are inexact (relative
// tolerance tau of the Krylov options). The residual test above is evaluated exactly, so a
// returned pair always meets the stated tolerance, but inexact inverse iteration with a FIXED
// tau stagnates at a residual of order tau ||A||-ish: measured on the medium aerofoil grid,
// tau = 1e-4 stalls at 2e-6, so tau must be set below the outer tolerance (1e-8 for 1e-8).
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <limits>

#include "../error.hpp"
#include "../linalg/direct.hpp"

namespace aerohopf {

/// tolerance finite and > 0, max_iterations >= 1 (input_error otherwise); no convergence within
/// max_iterations throws convergence_error with the last eigenvalue and residual.
struct inverse_power_options {
  double tolerance = 1e-12;  ///< on ||A x - lambda x||_2 / max(1, |lambda|), ||x||_2 = 1 (see above)
  int max_iterations = 100;
  bool verbose = false;
  std::ostream* log = &std::cout;
};

struct eigen_pair {
  std::complex<double> lambda;
  vec<std::complex<double>> vector;  ///< unit 2-norm, largest component real and positive
  int iterations = 0;
  double residual = 0;  ///< ||A x - lambda x||_2
  long linear_iterations = 0;  ///< Krylov iterations over all solves (0 with a direct solver)
};

namespace internal {

/// Fix the free phase: largest-magnitude component real and positive.
inline void normalise_phase(vec<std::complex<double>>& x) {
  Eigen::Index imax = 0;
  x.cwiseAbs().maxCoeff(&imax);
  const std::complex<double> a = x[imax];
  x *= std::abs(a) / a;
  x.normalize();
}

/// A deterministic start vector with components in every direction (no accidental
/// orthogonality to the wanted eigenvector in practice).
inline vec<std::complex<double>> default_start(Eigen::Index n) {
  vec<std::complex<double>> x(n);
  for (Eigen::Index i = 0; i < n; ++i)
    x[i] = {1.0 + 0.37 * std::sin(1.3 * double(i) + 0.2), 0.5 * std::cos(0.7 * double(i) + 0.1)};
  return x.normalized();
}

/// The vector operations of the iteration on vectors held whole by the caller. A distributed
/// counterpart (distributed/mpi_eigen.hpp) sums them over the processes.
struct local_vectors {
  double squared_norm(const vec<std::complex<double>>& v) const { return v.squaredNorm(); }
  std::complex<double> dot(const vec<std::complex<double>>& a, const vec<std::complex<double>>& b) const {
    return a.dot(b);
  }
  /// The entry of largest magnitude (the first of equal ones).
  std::complex<double> largest_entry(const vec<std::complex<double>>& x) const {
    Eigen::Index imax = 0;
    x.cwiseAbs().maxCoeff(&imax);
    return x[imax];
  }
};

/// The iteration itself, written once for any vector space (local_vectors or a distributed
/// one): apply(v) = A v, solve(v, its) = (A - shift I)^{-1} v (its += Krylov iterations), x the
/// unit start vector, a_norm = ||A||_inf. Convergence test and errors: file comment.
template <class Space, class Apply, class Solve>
eigen_pair inverse_power_iteration(const Space& space, Apply&& apply, Solve&& solve, std::complex<double> shift,
                                   double a_norm, vec<std::complex<double>> x, const inverse_power_options& opt,
                                   const char* who) {
  using C = std::complex<double>;
  eigen_pair r;
  for (int t = 1; t <= opt.max_iterations; ++t) {
    const vec<C> y = solve(x, r.linear_iterations);
    const double ny2 = space.squared_norm(y);
    if (!(ny2 > 0) || !std::isfinite(ny2))
      throw convergence_error(internal::concat(who, ": iterate ", t, " is zero or not finite"));
    r.lambda = shift + space.dot(y, x) / ny2;
    x = y / std::sqrt(ny2);
    r.residual = std::sqrt(space.squared_norm(vec<C>(apply(x) - r.lambda * x)));
    r.iterations = t;
    if (opt.verbose && opt.log)
      *opt.log << who << " it " << t << "  lambda " << r.lambda << "  residual " << r.residual << "\n";
    const double floor = 100 * std::numeric_limits<double>::epsilon() * a_norm;
    if (r.residual <= std::max(opt.tolerance * std::max(1.0, std::abs(r.lambda)), floor)) {
      // the free phase: largest-magnitude component real and positive, unit norm
      const C big = space.largest_entry(x);
      x *= std::abs(big) / big;
      if (const double z = space.squared_norm(x); z > 0) x /= std::sqrt(z);
      r.vector = std::move(x);
      return r;
    }
  }
  throw convergence_error(internal::concat(who, ": no convergence in ", opt.max_iterations, " iterations (shift ", shift,
                                           ", last lambda ", r.lambda, ", residual ", r.residual, ")"));
}

template <class Matrix, class Solver>
eigen_pair inverse_power_impl(const Matrix& a, std::complex<double> shift, const inverse_power_options& opt,
                              const vec<std::complex<double>>* start, const char* who, Solver& solver) {
  using C = std::complex<double>;
  // Every input is checked before the (costly) factorisation: a NaN in the shift, the start or
  // A would otherwise surface only as a "non-finite iterate", and a zero or NaN start used to be
  // replaced silently by the default one.
  require(a.rows() == a.cols(), who, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
  require(a.rows() >= 1, who, ": matrix is empty");
  require(std::isfinite(shift.real()) && std::isfinite(shift.imag()), who, ": shift ", shift, " is not finite");
  require(opt.max_iterations >= 1, who, ": max_iterations must be >= 1 (got ", opt.max_iterations, ")");
  require(std::isfinite(opt.tolerance) && opt.tolerance > 0, who, ": tolerance must be finite and > 0 (got ",
          opt.tolerance, ")");
  if (start) {
    require_size(start->size(), a.rows(), who, "start vector");
    require_finite(*start, who, "start vector");
    require(start->norm() > 0, who, ": start vector is zero");
  }
  double a_norm = 0;  // ||A||_inf, the scale of the attainable residual
  {
    vec<double> row_sums = vec<double>::Zero(a.rows());
    if constexpr (is_sparse_matrix_v<Matrix>) {
      for (int k = 0; k < a.outerSize(); ++k)
        for (typename Matrix::InnerIterator it(a, k); it; ++it) {
          require(std::isfinite(it.value()), who, ": matrix entry (", it.row(), ", ", it.col(), ") is not finite (",
                  it.value(), ")");
          row_sums[it.row()] += std::abs(it.value());
        }
    } else {
      for (Eigen::Index j = 0; j < a.cols(); ++j)
        for (Eigen::Index i = 0; i < a.rows(); ++i)
          require(std::isfinite(a(i, j)), who, ": matrix entry (", i, ", ", j, ") is not finite (", a(i, j), ")");
      row_sums = a.cwiseAbs().rowwise().sum();
    }
    a_norm = row_sums.maxCoeff();
  }
  // A shift that is an eigenvalue to working precision (e.g. the exact i omega at a Hopf point)
  // makes A - sigma I singular; inverse power only needs it invertible, so nudge the shift.
  for (int attempt = 0;; ++attempt) {
    try {
      solver.compute(shifted(a, shift));
      break;
    } catch (const singular_matrix_error&) {
      if (attempt == 3) throw;
      shift += std::complex<double>(1e-9, 1e-9) * std::max(1.0, std::abs(shift)) * std::pow(10.0, attempt);
    }
  }
  const auto ac = a.template cast<C>();
  return inverse_power_iteration(
      local_vectors{}, [&ac](const vec<C>& v) -> vec<C> { return ac * v; },
      [&solver](const vec<C>& v, long& linear_iterations) -> vec<C> {
        vec<C> y = solver.solve(v);
        if constexpr (requires { solver.last_report().iterations; }) linear_iterations += solver.last_report().iterations;
        return y;
      },
      shift, a_norm, start ? vec<C>(start->normalized()) : default_start(a.rows()), opt, who);
}

}  // namespace internal

/// Eigenpair of A whose eigenvalue is nearest shift (sparse or dense LU of A - shift I).
template <class Matrix>
eigen_pair inverse_power(const Matrix& a, std::complex<double> shift, const inverse_power_options& opt = {},
                         const vec<std::complex<double>>* start = nullptr) {
  direct_solver<decltype(shifted(a, shift))> solver("inverse power (A - sigma I)");
  return internal::inverse_power_impl(a, shift, opt, start, "inverse power", solver);
}

/// The same with a solver of the compute/solve interface for A - shift I (file comment), e.g.
///   krylov_solver<Eigen::SparseMatrix<std::complex<double>>, 4> s(opts, "inverse power");
///   inverse_power(A, {0, omega}, {}, nullptr, s);
template <class Matrix, class Solver>
eigen_pair inverse_power(const Matrix& a, std::complex<double> shift, const inverse_power_options& opt,
                         const vec<std::complex<double>>* start, Solver& solver) {
  return internal::inverse_power_impl(a, shift, opt, start, "inverse power", solver);
}

/// Adjoint eigenpair: eigenvector q of A^T for the eigenvalue nearest conj(shift). For the
/// right pair A p = i omega p (shift i omega) this gives A^T q = -i omega q, i.e. q^H A = i omega q^H.
template <class Matrix>
eigen_pair inverse_power_adjoint(const Matrix& a, std::complex<double> shift, const inverse_power_options& opt = {},
                                 const vec<std::complex<double>>* start = nullptr) {
  const Matrix at = a.transpose();
  direct_solver<decltype(shifted(at, shift))> solver("adjoint inverse power (A^T - sigma I)");
  return internal::inverse_power_impl(at, std::conj(shift), opt, start, "adjoint inverse power", solver);
}

}  // namespace aerohopf
