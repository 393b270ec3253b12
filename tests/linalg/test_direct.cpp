// direct_solver: dense and sparse LU against independent references; a failed factorisation
// is reported by compute() and leaves the solver refusing to solve (it never returns the
// garbage of a broken factorisation, nor the solution of the matrix before).
#include <gtest/gtest.h>

#include <aerohopf/linalg/direct.hpp>

#include <limits>
#include <string>
#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using cd = std::complex<double>;

namespace {

Eigen::SparseMatrix<double> sparse_of(const Eigen::MatrixXd& a) { return a.sparseView(); }

}  // namespace

TEST(direct_solver, dense_and_sparse_solve_real_and_complex_systems) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(9, 9) + 4.0 * Eigen::MatrixXd::Identity(9, 9);
  const vec<double> b = vec<double>::Random(9);
  direct_solver<Eigen::MatrixXd> dense;
  const vec<double> x = dense.compute(a).solve(b);
  EXPECT_LT((a * x - b).norm(), 1e-13 * b.norm());
  direct_solver<Eigen::SparseMatrix<double>> sparse;
  const vec<double> y = sparse.compute(sparse_of(a)).solve(b);
  EXPECT_LT((y - x).norm(), 1e-12 * x.norm());
  const Eigen::MatrixXcd ac = a.cast<cd>() + cd(0, 0.7) * Eigen::MatrixXcd::Identity(9, 9);
  const vec<cd> bc = vec<cd>::Random(9);
  direct_solver<Eigen::MatrixXcd> densec;
  EXPECT_LT((ac * densec.compute(ac).solve(bc) - bc).norm(), 1e-13 * bc.norm());
}

// Dense: the old solver, after compute() had thrown on a singular matrix, solved with the
// broken LU and returned [-inf inf]; after a good factorisation and a failed one it could
// return the solution of the previous matrix. Both are refused now, naming the context.
TEST(direct_solver, dense_solver_refuses_to_solve_after_a_failed_factorisation) {
  Eigen::MatrixXd singular(2, 2);
  singular << 1.0, 2.0, 2.0, 4.0;
  const vec<double> b = vec<double>::Ones(2);
  direct_solver<Eigen::MatrixXd> s("flutter LU");
  EXPECT_TRUE(contains(test::error_of<singular_matrix_error>([&] { s.compute(singular); }), "flutter LU"));
  EXPECT_TRUE(contains(test::error_of<singular_matrix_error>([&] { (void)s.solve(b); }), "flutter LU"));

  Eigen::MatrixXd good(2, 2);
  good << 2.0, 1.0, 1.0, 3.0;
  s.compute(good);
  EXPECT_LT((good * s.solve(b) - b).norm(), 1e-14);
  Eigen::MatrixXd nan_matrix = good;
  nan_matrix(1, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(s.compute(nan_matrix), singular_matrix_error);
  EXPECT_THROW((void)s.solve(b), singular_matrix_error);
  EXPECT_THROW(s.compute(singular), singular_matrix_error);
  EXPECT_THROW((void)s.solve(b), singular_matrix_error);
  // a later good factorisation makes it usable again
  s.compute(good);
  EXPECT_LT((good * s.solve(b) - b).norm(), 1e-14);
}

// Sparse: the same contract (structurally singular matrix: a zero column).
TEST(direct_solver, sparse_solver_refuses_to_solve_after_a_failed_factorisation) {
  Eigen::MatrixXd good = Eigen::MatrixXd::Identity(4, 4) * 2.0;
  good(0, 3) = 1.0;
  good(2, 1) = -1.0;
  Eigen::MatrixXd singular = good;
  singular.col(2).setZero();
  const vec<double> b = vec<double>::Ones(4);
  direct_solver<Eigen::SparseMatrix<double>> s("sparse flutter LU");
  EXPECT_TRUE(contains(test::error_of<singular_matrix_error>([&] { s.compute(sparse_of(singular)); }), "sparse flutter LU"));
  EXPECT_TRUE(contains(test::error_of<singular_matrix_error>([&] { (void)s.solve(b); }), "sparse flutter LU"));
  s.compute(sparse_of(good));
  EXPECT_LT((good * vec<double>(s.solve(b)) - b).norm(), 1e-14);
  EXPECT_THROW(s.compute(sparse_of(singular)), singular_matrix_error);
  EXPECT_THROW((void)s.solve(b), singular_matrix_error);
}

TEST(direct_solver, wrong_sizes_are_input_errors) {
  direct_solver<Eigen::MatrixXd> d;
  EXPECT_THROW(d.compute(Eigen::MatrixXd::Identity(3, 2)), input_error);
  d.compute(Eigen::MatrixXd::Identity(3, 3));
  EXPECT_THROW((void)d.solve(vec<double>::Ones(4)), input_error);
  direct_solver<Eigen::SparseMatrix<double>> s;
  s.compute(sparse_of(Eigen::MatrixXd::Identity(3, 3)));
  EXPECT_THROW((void)s.solve(vec<double>::Ones(2)), input_error);
}
