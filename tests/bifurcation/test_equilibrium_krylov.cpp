// Newton-Krylov equilibrium solve from a nearby state (bifurcation/equilibrium_krylov.hpp):
//  * a sparse test system with a closed-form equilibrium, an approximate Jacobian as the
//    preconditioner (so BILU is not the exact inverse): converges to the closed form, and
//    quadratically (||f_{k+1}|| <= C ||f_k||^2);
//  * the heavy-case aerofoil on the very coarse grid at M = 0.80 from the steady flow at
//    M = 0.79: the same state as the independent pseudo-transient solve from the free stream;
//  * bad input and non-convergence: clear exceptions, the caller's start untouched.
#include <gtest/gtest.h>

#include "support/aerofoil_cases.hpp"

#include <aerohopf/bifurcation/equilibrium_krylov.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

using namespace aerohopf;

namespace {

/// f(w) = -(K z + z.^3 + 0.2 z.^2 .* shift(z)), z = w - w*, K = tridiag(-1, 2.5, -1):
/// equilibrium w* (closed form), unique near it; Jacobian sparse (tridiagonal + diagonal),
/// approximate Jacobian = -(K + 3 diag(z.^2)) without the coupling term (a preconditioner that
/// is close, not exact).
class shifted_cubic_system {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;
  explicit shifted_cubic_system(Eigen::Index n) : n_(n) {}
  Eigen::Index size() const { return n_; }
  vec<double> equilibrium() const {
    vec<double> w(n_);
    for (Eigen::Index i = 0; i < n_; ++i) w[i] = 1.0 + 0.5 * std::sin(0.7 * static_cast<double>(i));
    return w;
  }
  template <class T>
  vec<T> residual(const vec<T>& w, const T& /*mu*/) const {
    const vec<double> we = equilibrium();
    vec<T> z(n_);
    for (Eigen::Index i = 0; i < n_; ++i) z[i] = w[i] - T(we[i]);
    vec<T> f(n_);
    for (Eigen::Index i = 0; i < n_; ++i) {
      T kz = T(2.5) * z[i];
      if (i > 0) kz -= z[i - 1];
      if (i + 1 < n_) kz -= z[i + 1];
      const T next = i + 1 < n_ ? z[i + 1] : T(0.0);
      f[i] = -(kz + z[i] * z[i] * z[i] + T(0.2) * z[i] * z[i] * next);
    }
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return assemble(w, mu, true); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const { return assemble(w, mu, false); }

 private:
  jacobian_type assemble(const vec<double>& w, double, bool exact) const {
    const vec<double> z = w - equilibrium();
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index i = 0; i < n_; ++i) {
      const double next = i + 1 < n_ ? z[i + 1] : 0.0;
      double d = 2.5 + 3.0 * z[i] * z[i];
      if (exact) d += 0.4 * z[i] * next;
      t.emplace_back(i, i, -d);
      if (i > 0) t.emplace_back(i, i - 1, 1.0);
      if (i + 1 < n_) t.emplace_back(i, i + 1, 1.0 - (exact ? 0.2 * z[i] * z[i] : 0.0));
    }
    jacobian_type a(n_, n_);
    a.setFromTriplets(t.begin(), t.end());
    return a;
  }
  Eigen::Index n_;
};

}  // namespace

TEST(equilibrium_krylov, closed_form_equilibrium_quadratic_convergence) {
  const shifted_cubic_system sys(42);  // not a multiple of the block size 4: padding is exercised
  vec<double> w0 = sys.equilibrium();
  for (Eigen::Index i = 0; i < w0.size(); ++i) w0[i] += 0.3 * std::cos(1.3 * static_cast<double>(i));
  const vec<double> w0_copy = w0;
  equilibrium_krylov_options o;
  o.fill_level = 0;
  o.newton.abs_tolerance = 1e-13;
  const auto r = solve_equilibrium_krylov<4>(sys, 0.0, w0, o, "cubic");
  EXPECT_EQ(w0, w0_copy);  // the caller's start is not touched
  EXPECT_TRUE(r.report.converged);
  EXPECT_LT((r.w - sys.equilibrium()).lpNorm<Eigen::Infinity>(), 1e-13);
  EXPECT_GT(r.linear_iterations, 0);
  const auto& h = r.report.residual_history;
  ASSERT_GE(h.size(), 3u);
  EXPECT_LE(r.report.iterations, 7);
  // quadratic once in the basin: ||f_{k+1}|| <= C ||f_k||^2 with a modest C
  int checked = 0;
  for (std::size_t k = 0; k + 1 < h.size(); ++k)
    if (h[k] < 1e-2 && h[k + 1] > 1e-14) {
      EXPECT_LT(h[k + 1], 10.0 * h[k] * h[k]) << "step " << k;
      ++checked;
    }
  EXPECT_GE(checked, 1);
}

TEST(equilibrium_krylov, bad_input_and_non_convergence) {
  const shifted_cubic_system sys(12);
  vec<double> w0 = sys.equilibrium();
  w0.array() += 0.5;
  EXPECT_THROW(solve_equilibrium_krylov<4>(sys, 0.0, vec<double>(w0.head(11))), input_error);
  vec<double> bad = w0;
  bad[3] = NAN;
  EXPECT_THROW(solve_equilibrium_krylov<4>(sys, 0.0, bad), input_error);
  EXPECT_THROW(solve_equilibrium_krylov<4>(sys, NAN, w0), input_error);
  equilibrium_krylov_options o;
  o.newton.max_iterations = 1;
  try {
    solve_equilibrium_krylov<4>(sys, 0.0, w0, o, "one-step solve");
    FAIL() << "no convergence_error";
  } catch (const convergence_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("one-step solve"), std::string::npos) << msg;
    EXPECT_NE(msg.find("no convergence in 1 iterations"), std::string::npos) << msg;
  }
  o = {};
  o.eta_max = 1.5;
  EXPECT_THROW(solve_equilibrium_krylov<4>(sys, 0.0, w0, o), input_error);
}

// Heavy case on the very coarse grid (stride 8): the steady flow at M = 0.80 from the one at
// M = 0.79 (a continuation step of the boundary), against the pseudo-transient solve from the
// free stream driven 13 orders down.
TEST(equilibrium_krylov, aerofoil_next_mach_number_matches_pseudo_transient_solve) {
  using models::aerofoil_system;
  const auto make = test_support::heavy_very_coarse_aerofoil;
  const aerofoil_system s0 = make(0.79), s1 = make(0.80);
  const vec<double> w0 = s0.steady_equilibrium();
  flow::steady_options so;
  so.residual_drop = 1e-13;
  so.max_steps = 500;
  const vec<double> ref = s1.steady_equilibrium(so);
  equilibrium_krylov_options o;
  const auto r = solve_equilibrium_krylov<4>(s1, 4.0, w0, o, "M = 0.80 from M = 0.79");
  std::cout << "M = 0.79 -> 0.80: " << r.report.iterations << " Newton iterations, " << r.linear_iterations
            << " GMRES iterations, ||f|| " << r.report.residual_history.front() << " -> " << r.report.final_residual()
            << "\n";
  EXPECT_TRUE(r.report.converged);
  EXPECT_LE(r.report.final_residual(), 1e-11);
  EXPECT_LE(r.report.iterations, 8);
  EXPECT_LT((r.w - ref).lpNorm<Eigen::Infinity>(), 1e-8);
  // the equilibrium does not depend on Ubar (structure at rest): the same state at another mu
  const auto r2 = solve_equilibrium_krylov<4>(s1, 2.0, w0, o);
  EXPECT_LT((r2.w - r.w).lpNorm<Eigen::Infinity>(), 1e-9);
}

// ---- broken promises and fault injection (reliability) ----
namespace {
/// shifted_cubic_system with a residual that is NaN (entry 2) on call nan_call and an
/// approximate Jacobian that is zero when zero_lhs (BILU breaks down).
struct faulty_cubic {
  using jacobian_type = Eigen::SparseMatrix<double>;
  const shifted_cubic_system& s;
  int nan_call = -1;
  bool zero_lhs = false;
  mutable int calls = 0;
  Eigen::Index size() const { return s.size(); }
  vec<double> residual(const vec<double>& w, double mu) const {
    vec<double> f = s.residual(w, mu);
    if (++calls == nan_call) f[2] = NAN;
    return f;
  }
  jacobian_type jacobian(const vec<double>& w, double mu) const { return s.jacobian(w, mu); }
  jacobian_type approximate_jacobian(const vec<double>& w, double mu) const {
    jacobian_type a = s.approximate_jacobian(w, mu);
    if (zero_lhs) a *= 0.0;
    return a;
  }
};
}  // namespace

// newton.throw_on_failure = false is honoured: a NaN residual at iterate 2 is a result with
// converged = false naming the label, the iterate, ||f|| and mu, w the last good iterate, from
// which a second solve reaches the closed form. Thrown, a BILU breakdown stays
// singular_matrix_error (with the label and the iterate in front).
TEST(equilibrium_krylov, failures_honour_throw_on_failure_and_keep_the_last_good_iterate) {
  const shifted_cubic_system sys(12);
  vec<double> w0 = sys.equilibrium();
  for (Eigen::Index i = 0; i < w0.size(); ++i) w0[i] += 0.3 * std::cos(1.3 * static_cast<double>(i));
  const vec<double> w0_copy = w0;
  equilibrium_krylov_options o;
  o.fill_level = 0;
  o.newton.abs_tolerance = 1e-13;
  o.newton.line_search = false;
  o.newton.throw_on_failure = false;
  faulty_cubic f{sys};
  f.nan_call = 3;  // the trial point of step 2
  const auto r = solve_equilibrium_krylov<4>(f, 0.25, w0, o, "faulty cubic");
  EXPECT_EQ(w0, w0_copy);
  EXPECT_FALSE(r.report.converged);
  EXPECT_NE(r.report.reason.find("faulty cubic: residual not finite at iterate 2"), std::string::npos) << r.report.reason;
  EXPECT_NE(r.report.reason.find("mu = 0.25"), std::string::npos) << r.report.reason;
  EXPECT_NE(r.report.reason.find(internal::concat("iterate 1 (||F|| = ", r.report.final_residual())), std::string::npos)
      << r.report.reason;
  ASSERT_TRUE(r.w.allFinite());
  EXPECT_NEAR(sys.residual(r.w, 0.25).norm(), r.report.final_residual(), 1e-15);
  o.newton.throw_on_failure = true;
  const auto again = solve_equilibrium_krylov<4>(sys, 0.25, r.w, o);
  ASSERT_TRUE(again.report.converged);
  EXPECT_LT((again.w - sys.equilibrium()).lpNorm<Eigen::Infinity>(), 1e-13);

  faulty_cubic z{sys};
  z.zero_lhs = true;
  try {
    solve_equilibrium_krylov<4>(z, 0.25, w0, o, "zero preconditioner");
    FAIL() << "expected singular_matrix_error";
  } catch (const singular_matrix_error& e) {
    EXPECT_NE(std::string(e.what()).find("zero preconditioner: step 1 from iterate 0"), std::string::npos) << e.what();
  }
  o.newton.relaxation = NAN;
  EXPECT_THROW(solve_equilibrium_krylov<4>(sys, 0.25, w0, o), input_error);
}
