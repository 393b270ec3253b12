// Bordered block matrix (linalg/bordered_block_matrix.hpp) against the same matrix held densely
// by Eigen, for block sizes 4 and 5 and borders of 0, 1, 4 and 6 unknowns (a border that is and
// one that is not the block size): J x, (J - sigma I) x (real matrix on complex vectors, fused
// and assembled), J x on complex vectors of a complex J; GMRES preconditioned by the bordered
// BILU (real J, complex J - i omega I) against a dense LU solve; the conversions from Eigen
// sparse and padded block matrices; sizes refused with the sizes in the message.
#include <gtest/gtest.h>

#include <aerohopf/linalg/bordered_block_matrix.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <random>
#include <vector>

#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;
using cd = std::complex<double>;

namespace {

/// A random bordered matrix: a 1D chain of nb cells with neighbour blocks (B x B), diagonally
/// dominant so that BILU(0) is a fair preconditioner, and a dense border of ns unknowns coupled
/// to every cell and to itself (also dominant).
template <int B>
bordered_block_matrix<double, B> random_bordered(Eigen::Index nb, Eigen::Index ns, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random = [&](Eigen::Index r, Eigen::Index c) {
    Eigen::MatrixXd m(r, c);
    for (Eigen::Index j = 0; j < c; ++j)
      for (Eigen::Index i = 0; i < r; ++i) m(i, j) = u(gen);
    return m;
  };
  std::vector<block_triplet<double, B>> t;
  for (Eigen::Index i = 0; i < nb; ++i)
    for (Eigen::Index j : {i - 1, i, i + 1}) {
      if (j < 0 || j >= nb) continue;
      block_triplet<double, B> tr;
      tr.row = i;
      tr.col = j;
      tr.value = random(B, B);
      if (i == j) tr.value += 4.0 * B * Eigen::Matrix<double, B, B>::Identity();
      t.push_back(tr);
    }
  const Eigen::Index nf = nb * B;
  Eigen::MatrixXd ss = random(ns, ns);
  ss.diagonal().array() += 2.0 * double(ns) + 3.0;
  return {block_sparse_matrix<double, B>::from_triplets(nb, nb, t), 0.3 * random(nf, ns), 0.3 * random(ns, nf) / 5.0,
          ss};
}

vec<cd> random_complex(Eigen::Index n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  vec<cd> x(n);
  for (auto& v : x) v = cd(u(gen), u(gen));
  return x;
}

template <int B>
void check_products(Eigen::Index ns) {
  SCOPED_TRACE(testing::Message() << "B = " << B << ", n_s = " << ns);
  const Eigen::Index nb = 9;
  const auto j = random_bordered<B>(nb, ns, 3 + unsigned(ns));
  const Eigen::Index n = nb * B + ns;
  ASSERT_EQ(j.rows(), n);
  ASSERT_EQ(j.flow_size(), nb * B);
  ASSERT_EQ(j.structure_size(), ns);
  const Eigen::MatrixXd d = j.to_dense();
  EXPECT_EQ((Eigen::MatrixXd(j.to_sparse()) - d).norm(), 0.0);
  // real J x
  const vec<cd> xc = random_complex(n, 17);
  const vec<double> x = xc.real();
  vec<double> y(n);
  j.apply(x, y);
  EXPECT_LT((y - d * x).norm(), 1e-13 * (d * x).norm());
  // (J - sigma I) x on complex vectors, fused; and by the assembled complex shifted matrix
  const cd sigma(0.3, 1.7);
  const Eigen::MatrixXcd dc = d.cast<cd>() - sigma * Eigen::MatrixXcd::Identity(n, n);
  vec<cd> yc(n), yc2(n);
  j.apply_shifted(sigma, xc, yc);
  EXPECT_LT((yc - dc * xc).norm(), 1e-13 * (dc * xc).norm());
  const shifted_operator<bordered_block_matrix<double, B>, cd> op(j, sigma);
  op.apply(xc, yc2);
  EXPECT_EQ((yc2 - yc).norm(), 0.0);
  const bordered_block_matrix<cd, B> jc = shifted(j, sigma);
  EXPECT_LT((jc.to_dense() - dc).norm(), 1e-14 * dc.norm());
  jc.apply(xc, yc2);  // a complex J on complex vectors
  EXPECT_LT((yc2 - dc * xc).norm(), 1e-13 * (dc * xc).norm());
  j.apply(xc, yc2);  // sigma = 0
  EXPECT_LT((yc2 - d.cast<cd>() * xc).norm(), 1e-13 * (d * xc).norm());
  // ||J||_inf
  EXPECT_NEAR(j.norm_inf(), d.cwiseAbs().rowwise().sum().maxCoeff(), 1e-12 * j.norm_inf());
}

template <int B>
void check_preconditioned_gmres(Eigen::Index ns) {
  SCOPED_TRACE(testing::Message() << "B = " << B << ", n_s = " << ns);
  const Eigen::Index nb = 40, n = nb * B + ns;
  const auto j = random_bordered<B>(nb, ns, 29 + unsigned(ns));
  const Eigen::MatrixXd d = j.to_dense();
  krylov_options ko;
  ko.relative_tolerance = 1e-14;
  ko.max_iterations = 400;
  ko.throw_on_failure = true;
  // real: J x = b with the bordered BILU(0) of J
  const vec<cd> bc = random_complex(n, 5);
  const vec<double> b = bc.real();
  bordered_block_ilu<double, B> m;
  m.compute(j);
  EXPECT_EQ(m.rows(), n);
  vec<double> x = vec<double>::Zero(n);
  const krylov_report rep = gmres<double>(j, m, b, x, ko);
  const vec<double> xd = d.partialPivLu().solve(b);
  EXPECT_LT((x - xd).norm(), 1e-10 * xd.norm()) << rep.iterations << " GMRES iterations";
  // complex: (J - i omega I) x = b with the bordered complex BILU(1) of J - i omega I
  const cd sigma(0.0, 2.3);
  block_ilu_options io;
  io.fill_level = 1;
  bordered_block_ilu<cd, B> mc(io);
  mc.compute(j, sigma);
  const shifted_operator<bordered_block_matrix<double, B>, cd> op(j, sigma);
  vec<cd> xc = vec<cd>::Zero(n);
  const krylov_report repc = gmres<cd>(op, mc, bc, xc, ko);
  const vec<cd> xcd = (d.cast<cd>() - sigma * Eigen::MatrixXcd::Identity(n, n)).partialPivLu().solve(bc);
  EXPECT_LT((xc - xcd).norm(), 1e-10 * xcd.norm()) << repc.iterations << " GMRES iterations";
  // the border is eliminated exactly: with a block-diagonal flow part (BILU(0) exact) the
  // preconditioner is the inverse and GMRES needs one iteration
  if (ns > 0) {
    std::vector<block_triplet<double, B>> t;
    for (Eigen::Index i = 0; i < nb; ++i) t.push_back({i, i, j.flow().block(i, i)});
    const bordered_block_matrix<double, B> jd(block_sparse_matrix<double, B>::from_triplets(nb, nb, t),
                                              j.flow_structure(), j.structure_flow(), j.structure());
    bordered_block_ilu<double, B> md;
    md.compute(jd);
    vec<double> z(n), r(n);
    jd.apply(b, r);
    md.apply(r, z);
    EXPECT_LT((z - b).norm(), 1e-12 * b.norm());
  }
}

}  // namespace

TEST(bordered_block_matrix, products_match_the_dense_matrix) {
  for (const Eigen::Index ns : {0, 1, 4, 6}) {
    check_products<4>(ns);
    check_products<5>(ns);
  }
}

TEST(bordered_block_matrix, preconditioned_gmres_matches_a_dense_lu_solve) {
  for (const Eigen::Index ns : {0, 1, 4, 6}) {
    check_preconditioned_gmres<4>(ns);
    check_preconditioned_gmres<5>(ns);
  }
}

// Eigen sparse and padded block matrices seen as flow blocks + the last unknowns as the border:
// the same matrix entry for entry, and the padded one's flow blocks keep its pattern.
TEST(bordered_block_matrix, conversions_from_sparse_and_padded_matrices) {
  for (const Eigen::Index ns : {0, 1, 4, 6}) {
    SCOPED_TRACE(ns);
    const auto j = random_bordered<5>(7, ns, 41);
    const Eigen::MatrixXd d = j.to_dense();
    const Eigen::SparseMatrix<double> s = j.to_sparse();
    const auto from_sparse = bordered_from_sparse<5>(s, ns);
    EXPECT_EQ((from_sparse.to_dense() - d).norm(), 0.0);
    EXPECT_EQ(from_sparse.flow().col_index(), j.flow().col_index());
    const auto padded = block_sparse_matrix<double, 5>::from_sparse(s);  // 35 + ns, padded to blocks of 5
    const auto from_padded = bordered_from_padded(padded, ns);
    EXPECT_EQ((from_padded.to_dense() - d).norm(), 0.0);
    EXPECT_EQ(from_padded.flow().col_index(), j.flow().col_index());
    EXPECT_EQ(from_padded.flow().values(), j.flow().values());
  }
}

TEST(bordered_block_matrix, bad_sizes_are_refused_with_the_sizes) {
  const auto j = random_bordered<4>(3, 2, 7);
  using M = bordered_block_matrix<double, 4>;
  const Eigen::MatrixXd fs = j.flow_structure(), sf = j.structure_flow(), ss = j.structure();
  std::string msg = input_error_of([&] { M(j.flow(), fs.topRows(11), sf, ss, "my model"); });
  EXPECT_TRUE(contains(msg, "my model: border blocks A_fs 11x2")) << msg;
  EXPECT_TRUE(contains(msg, "expected 12x2, 2x12, 2x2")) << msg;
  msg = input_error_of([&] { M(j.flow(), fs, sf, Eigen::MatrixXd::Zero(3, 3)); });
  EXPECT_TRUE(contains(msg, "A_ss 3x3")) << msg;
  // a padded flow part
  auto padded = block_sparse_matrix<double, 4>::from_sparse(Eigen::SparseMatrix<double>(
      Eigen::MatrixXd::Identity(10, 10).sparseView()));
  msg = input_error_of([&] { M(padded, Eigen::MatrixXd(12, 0), Eigen::MatrixXd(0, 12), Eigen::MatrixXd(0, 0)); });
  EXPECT_TRUE(contains(msg, "flow part is padded (logical 10 of 12 rows)")) << msg;
  // products
  vec<double> x(14), y(13);
  msg = input_error_of([&] { j.apply(x, y); });
  EXPECT_TRUE(contains(msg, "bordered_block_matrix::apply: vector sizes x 14, y 13, expected 14 (12 flow + 2 structural")) << msg;
  vec<cd> xc(13), yc(14);
  msg = input_error_of([&] { j.apply_shifted(cd(0, 1), xc, yc); });
  EXPECT_TRUE(contains(msg, "apply_shifted: vector sizes x 13")) << msg;
  // the preconditioner
  block_ilu_options io;
  io.context = "flow BILU";
  bordered_block_ilu<double, 4> m(io);
  msg = input_error_of([&] { m.apply(x, x); });
  EXPECT_TRUE(contains(msg, "flow BILU: apply() before a successful compute()")) << msg;
  m.compute(j);
  vec<double> z(13);
  msg = input_error_of([&] { m.apply(x, z); });
  EXPECT_TRUE(contains(msg, "flow BILU: apply: vector sizes 14, 13, expected 14 (12 flow + 2 structural")) << msg;
  bordered_block_ilu<double, 4> real_m;
  msg = input_error_of([&] { real_m.compute(j, 1.0); });
  EXPECT_TRUE(contains(msg, "a shift needs a complex preconditioner")) << msg;
  // conversions
  msg = input_error_of([&] { (void)bordered_from_sparse<4>(j.to_sparse(), 3, "split"); });
  EXPECT_TRUE(contains(msg, "split: a border of 3 of 14 unknowns leaves a flow part that is not a whole number of blocks of 4"))
      << msg;
  msg = input_error_of([&] { (void)bordered_from_padded(j.flow(), 5); });
  EXPECT_TRUE(contains(msg, "bordered_from_padded: a border of 5 of 12 unknowns")) << msg;
}

// A singular border (Schur complement) is a singular_matrix_error naming the preconditioner.
TEST(bordered_block_matrix, singular_schur_complement_is_reported) {
  const auto j = random_bordered<4>(3, 2, 9);
  const bordered_block_matrix<double, 4> s(j.flow(), Eigen::MatrixXd::Zero(12, 2), Eigen::MatrixXd::Zero(2, 12),
                                           Eigen::MatrixXd::Zero(2, 2));
  block_ilu_options io;
  io.context = "structure BILU";
  bordered_block_ilu<double, 4> m(io);
  try {
    m.compute(s);
    ADD_FAILURE() << "no exception";
  } catch (const singular_matrix_error& e) {
    EXPECT_TRUE(contains(e.what(), "structure BILU: border elimination: singular Schur complement")) << e.what();
  }
}
