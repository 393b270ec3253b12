// krylov_solver (BILU(k) + Krylov behind the direct_solver interface): invalid options are
// refused at construction; a failed factorisation (singular pivot block, non-finite matrix)
// throws singular_matrix_error from compute() and leaves the solver refusing to solve until a
// later compute() succeeds. (Accuracy against direct_solver: test_krylov.cpp.)
#include <gtest/gtest.h>

#include <aerohopf/linalg/krylov_solver.hpp>

#include <limits>
#include <string>

using namespace aerohopf;

namespace {

/// Tridiagonal, diagonally dominant n x n.
Eigen::SparseMatrix<double> tridiagonal(int n) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n, n) * 4.0;
  for (int i = 0; i + 1 < n; ++i) {
    a(i, i + 1) = -1.0;
    a(i + 1, i) = -1.5;
  }
  return a.sparseView();
}

}  // namespace

TEST(krylov_solver, refuses_to_solve_after_a_failed_factorisation) {
  const int n = 12;
  const auto good = tridiagonal(n);
  const vec<double> b = vec<double>::LinSpaced(n, 1.0, 2.0);
  Eigen::SparseMatrix<double> singular = good;  // block row 1 (rows 2, 3) of 2x2 blocks: zero pivot block
  for (int k = 0; k < singular.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(singular, k); it; ++it)
      if (it.row() / 2 == 1 && it.col() / 2 == 1) it.valueRef() = 0.0;
  Eigen::SparseMatrix<double> non_finite = good;
  non_finite.coeffRef(5, 5) = std::numeric_limits<double>::infinity();

  krylov_solver_options o;
  o.fill_level = 0;
  o.krylov.relative_tolerance = 1e-12;
  krylov_solver<Eigen::SparseMatrix<double>, 2> s(o, "test BILU");
  for (const auto* bad : {&singular, &non_finite}) {
    EXPECT_THROW(s.compute(*bad), singular_matrix_error);
    try {
      (void)s.solve(b);
      ADD_FAILURE() << "solve after a failed factorisation did not throw";
    } catch (const singular_matrix_error& e) {
      EXPECT_NE(std::string(e.what()).find("test BILU"), std::string::npos) << e.what();
    }
    s.compute(good);  // usable again
    const vec<double> x = s.solve(b);
    EXPECT_LT((good * x - b).norm(), 1e-10 * b.norm());
  }
}

TEST(krylov_solver, invalid_options_are_refused_at_construction) {
  using solver = krylov_solver<Eigen::SparseMatrix<double>, 2>;
  krylov_solver_options o;
  o.krylov.restart = 0;
  EXPECT_THROW(solver{o}, input_error);
  o = {};
  o.krylov.relative_tolerance = std::numeric_limits<double>::infinity();
  EXPECT_THROW(solver{o}, input_error);
  o = {};
  o.krylov.max_iterations = -3;
  EXPECT_THROW(solver{o}, input_error);
  o = {};
  o.fill_level = -1;
  EXPECT_THROW(solver{o}, input_error);
}
