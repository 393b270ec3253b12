// Block-sparse matrix: assembly (triplets, pattern + fill), products and conversions checked
// against the same matrix held densely by Eigen; the shifted builders against the dense complex
// matrix A - i omega I; the bordered operator against its dense assembly.
#include <gtest/gtest.h>

#include <aerohopf/linalg/block_sparse_matrix.hpp>
#include <aerohopf/scalar/qd.hpp>

#include <random>

using namespace aerohopf;
using cd = std::complex<double>;

namespace {

template <class S, int B>
std::vector<block_triplet<S, B>> random_triplets(Eigen::Index nb, Eigen::Index bs, int per_row, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_int_distribution<Eigen::Index> col(0, nb - 1);
  std::vector<block_triplet<S, B>> t;
  for (Eigen::Index i = 0; i < nb; ++i)
    for (int k = 0; k < per_row; ++k) {
      block_triplet<S, B> tr;
      tr.row = i;
      tr.col = k == 0 ? i : col(gen);
      tr.value = Eigen::Matrix<S, B, B>::Random(bs, bs);
      t.push_back(tr);
    }
  // a duplicate of the first triplet: must be summed
  t.push_back(t.front());
  return t;
}

template <class S, int B>
Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> dense_of(const std::vector<block_triplet<S, B>>& t, Eigen::Index nb,
                                                           Eigen::Index bs) {
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> d = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Zero(nb * bs, nb * bs);
  for (const auto& tr : t) d.block(tr.row * bs, tr.col * bs, bs, bs) += tr.value;
  return d;
}

template <class S, int B>
void check_products(Eigen::Index bs) {
  const Eigen::Index nb = 13;
  const auto t = random_triplets<S, B>(nb, bs, 4, 7);
  const auto a = block_sparse_matrix<S, B>::from_triplets(nb, nb, t, bs);
  const auto d = dense_of(t, nb, bs);
  EXPECT_LT((Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>(a.to_sparse()) - d).norm(), 1e-13);
  const vec<S> x = vec<S>::Random(nb * bs);
  vec<S> y(nb * bs);
  a.apply(x, y);
  EXPECT_LT((y - d * x).norm(), 1e-12 * (d * x).norm());
  vec<S> z = vec<S>::Random(nb * bs), z0 = z;
  a.multiply_add(S(2.5), x, z);
  EXPECT_LT((z - z0 - S(2.5) * d * x).norm(), 1e-12 * z.norm());
  a.multiply_transpose(x, y);
  EXPECT_LT((y - d.transpose() * x).norm(), 1e-12 * y.norm());
  a.multiply_transpose(x, y, true);
  EXPECT_LT((y - d.adjoint() * x).norm(), 1e-12 * y.norm());
  // round trip through Eigen::SparseMatrix
  const auto b = block_sparse_matrix<S, B>::from_sparse(a.to_sparse(), bs);
  EXPECT_EQ(b.nonzero_blocks(), a.nonzero_blocks());
  EXPECT_LT((Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>(b.to_sparse()) - d).norm(), 1e-13);
}

}  // namespace

TEST(BlockSparseMatrix, ProductsRealFixed4) { check_products<double, 4>(4); }
TEST(BlockSparseMatrix, ProductsRealFixed5) { check_products<double, 5>(5); }
TEST(BlockSparseMatrix, ProductsComplexFixed5) { check_products<cd, 5>(5); }
TEST(BlockSparseMatrix, ProductsRealDynamic3) { check_products<double, Eigen::Dynamic>(3); }
TEST(BlockSparseMatrix, ProductsComplexDynamic2) { check_products<cd, Eigen::Dynamic>(2); }

TEST(BlockSparseMatrix, PatternThenFillWithoutReallocation) {
  const Eigen::Index nb = 6;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pattern;
  for (Eigen::Index i = 0; i < nb; ++i) {
    pattern.emplace_back(i, i);
    if (i > 0) pattern.emplace_back(i, i - 1);
    if (i + 1 < nb) pattern.emplace_back(i, i + 1);
  }
  pattern.emplace_back(2, 2);  // duplicate: merged
  block_sparse_matrix<double, 4> a;
  a.set_pattern(nb, nb, pattern);
  EXPECT_EQ(a.nonzero_blocks(), 3 * nb - 2);
  const double* storage = a.values().data();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(4 * nb, 4 * nb);
  for (int step = 0; step < 2; ++step) {
    a.set_zero();
    d.setZero();
    for (auto [i, j] : pattern) {
      const Eigen::Matrix4d blk = Eigen::Matrix4d::Random();
      a.add_block(i, j, blk);
      d.block(4 * i, 4 * j, 4, 4) += blk;
    }
    EXPECT_EQ(a.values().data(), storage);
    EXPECT_LT((Eigen::MatrixXd(a.to_sparse()) - d).norm(), 1e-14);
  }
  EXPECT_THROW(a.add_block(0, 3, Eigen::Matrix4d::Identity()), input_error);  // not in pattern
  EXPECT_THROW(a.block(0, nb), input_error);                                   // outside
  EXPECT_THROW(a.add_block(0, 0, Eigen::MatrixXd::Identity(3, 3)), input_error);  // wrong block size
  EXPECT_THROW(a.set_pattern(2, 2, std::vector<std::pair<int, int>>{{0, 2}}), input_error);
  vec<double> x(3), y(4 * nb);
  EXPECT_THROW(a.multiply(x, y), input_error);  // size mismatch
}

TEST(BlockSparseMatrix, PaddingOfNonMultipleSizes) {
  // 11 unknowns in blocks of 4: 3 block rows, one padded unknown with identity diagonal.
  const Eigen::Index n = 11;
  Eigen::MatrixXd d = Eigen::MatrixXd::Random(n, n) + 5 * Eigen::MatrixXd::Identity(n, n);
  const Eigen::SparseMatrix<double> s = d.sparseView();
  const auto a = block_sparse_matrix<double, 4>::from_sparse(s);
  EXPECT_EQ(a.rows(), 12);
  EXPECT_EQ(a.logical_rows(), n);
  EXPECT_LT((Eigen::MatrixXd(a.to_sparse()) - d).norm(), 1e-14);
  const Eigen::MatrixXd padded(a.to_sparse(true));
  EXPECT_EQ(padded(11, 11), 1.0);
  EXPECT_EQ(padded.row(11).sum(), 1.0);
  EXPECT_EQ(padded.col(11).sum(), 1.0);
  const vec<double> x = vec<double>::Random(n);
  vec<double> y(12);
  a.apply(pad_vector(x, 12), y);
  EXPECT_LT((unpad_vector(y, n) - d * x).norm(), 1e-13);
  EXPECT_EQ(y(11), 0.0);
}

TEST(BlockSparseMatrix, ShiftedComplexAndRealFormsAgreeWithDense) {
  const Eigen::Index nb = 9, bs = 5;
  const auto t = random_triplets<double, 5>(nb, bs, 3, 3);
  const auto a = block_sparse_matrix<double, 5>::from_triplets(nb, nb, t);
  const double omega = 0.7;
  const Eigen::MatrixXcd dc =
      dense_of(t, nb, bs).cast<cd>() - cd(0, omega) * Eigen::MatrixXcd::Identity(nb * bs, nb * bs);
  const auto c = shifted(a, cd(0, omega));
  EXPECT_LT((Eigen::MatrixXcd(c.to_sparse()) - dc).norm(), 1e-13);
  const vec<cd> x = vec<cd>::Random(nb * bs);
  const vec<cd> y = dc * x;
  for (auto o : {real_form_ordering::split, real_form_ordering::interleaved}) {
    const auto r = real_shifted_form(a, omega, o);
    EXPECT_EQ(r.block_rows(), 2 * nb);
    EXPECT_EQ(r.nonzero_blocks(), 2 * a.nonzero_blocks() + 2 * nb);  // A twice + the omega I couplings
    vec<double> yr(2 * nb * bs);
    r.apply(real_form_vector(x, bs, o), yr);
    EXPECT_LT((complex_from_real_form(yr, bs, o) - y).norm(), 1e-12 * y.norm());
  }
  // the real form in split ordering is literally [[A, omega I], [-omega I, A]]
  const Eigen::MatrixXd ad = dense_of(t, nb, bs);
  const Eigen::Index n = nb * bs;
  Eigen::MatrixXd expected(2 * n, 2 * n);
  expected << ad, omega * Eigen::MatrixXd::Identity(n, n), -omega * Eigen::MatrixXd::Identity(n, n), ad;
  EXPECT_LT((Eigen::MatrixXd(real_shifted_form(a, omega, real_form_ordering::split).to_sparse()) - expected).norm(), 1e-13);
}

// The fused real-matrix shifted product (A - sigma I) x on complex x against the dense complex
// matrix and against the assembled shifted(A, sigma); B = 4, 5 (the vector kernels), a dynamic
// block size (the portable loop) and a padded matrix (padded unknowns are not shifted).
template <int B>
void check_real_shifted_product(Eigen::Index bs, const cd sigma) {
  const Eigen::Index nb = 11;
  const auto t = random_triplets<double, B>(nb, bs, 5, 21);
  const auto a = block_sparse_matrix<double, B>::from_triplets(nb, nb, t, bs);
  const Eigen::Index n = nb * bs;
  const Eigen::MatrixXcd dc = dense_of(t, nb, bs).template cast<cd>() - sigma * Eigen::MatrixXcd::Identity(n, n);
  const vec<cd> x = vec<cd>::Random(n), x0 = x;
  vec<cd> y(n), yc(n);
  a.apply_shifted(sigma, x, y);
  EXPECT_LT((y - dc * x).norm(), 1e-13 * (dc * x).norm()) << "B = " << bs;
  shifted(a, sigma).apply(x, yc);
  EXPECT_LT((y - yc).norm(), 1e-14 * yc.norm()) << "B = " << bs;
  const shifted_operator<block_sparse_matrix<double, B>, cd> op(a, sigma);
  vec<cd> yo(n);
  apply_operator<cd>(op, x, yo);
  EXPECT_EQ((yo - y).norm(), 0.0);
  vec<cd> y0(n);
  a.apply(x, y0);  // sigma = 0
  EXPECT_LT((y0 - y - sigma * x).norm(), 1e-13 * y0.norm());
  EXPECT_EQ(x, x0);  // input untouched
  vec<cd> shorter(n - 1);
  EXPECT_THROW(a.apply_shifted(sigma, shorter, y), input_error);
  EXPECT_THROW(a.apply_shifted(sigma, x, shorter), input_error);
}

TEST(BlockSparseMatrix, RealShiftedProductOnComplexVectorsMatchesTheAssembledShiftedMatrix) {
  check_real_shifted_product<4>(4, cd(0.0, 0.83));
  check_real_shifted_product<5>(5, cd(0.1, -1.7));
  check_real_shifted_product<Eigen::Dynamic>(3, cd(0.0, 0.4));
  // padded: 11 unknowns in blocks of 4; the padded unknown keeps its identity row (not shifted)
  const Eigen::Index n = 11;
  Eigen::MatrixXd d = Eigen::MatrixXd::Random(n, n) + 5 * Eigen::MatrixXd::Identity(n, n);
  const auto a = block_sparse_matrix<double, 4>::from_sparse(Eigen::SparseMatrix<double>(d.sparseView()));
  const cd sigma(0.0, 0.9);
  const vec<cd> x = vec<cd>::Random(n);
  vec<cd> y(12), yc(12);
  a.apply_shifted(sigma, pad_vector(x, 12), y);
  shifted(a, sigma).apply(pad_vector(x, 12), yc);
  EXPECT_LT((unpad_vector(y, n) - (d.cast<cd>() - sigma * Eigen::MatrixXcd::Identity(n, n)) * x).norm(), 1e-13);
  EXPECT_LT((y - yc).norm(), 1e-14);
  EXPECT_EQ(y(11), cd(0.0));
}

TEST(BlockSparseMatrix, BorderedOperatorMatchesDenseAssembly) {
  const Eigen::Index nb = 7, bs = 4, n = nb * bs, k = 2;
  const auto t = random_triplets<cd, 4>(nb, bs, 3, 11);
  const auto a = block_sparse_matrix<cd, 4>::from_triplets(nb, nb, t);
  const Eigen::MatrixXcd u = Eigen::MatrixXcd::Random(n, k), vt = Eigen::MatrixXcd::Random(k, n),
                         corner = Eigen::MatrixXcd::Random(k, k);
  bordered_operator<block_sparse_matrix<cd, 4>, cd> op(a, n, u, vt, corner);
  Eigen::MatrixXcd full(n + k, n + k);
  full << dense_of(t, nb, bs), u, vt, corner;
  const vec<cd> x = vec<cd>::Random(n + k);
  vec<cd> y(n + k);
  op.apply(x, y);
  EXPECT_LT((y - full * x).norm(), 1e-12 * y.norm());
  // with an exact inner "preconditioner" the bordered preconditioner is the exact inverse
  const Eigen::MatrixXcd ainv = dense_of(t, nb, bs).inverse();
  bordered_preconditioner<Eigen::MatrixXcd, cd> pre(op, ainv);
  vec<cd> z(n + k);
  pre.apply(y, z);
  EXPECT_LT((z - x).norm(), 1e-9 * x.norm());
  using bordered = bordered_operator<block_sparse_matrix<cd, 4>, cd>;
  EXPECT_THROW(bordered(a, n, u, vt, Eigen::MatrixXcd::Zero(3, 3)), input_error);
}

TEST(BlockSparseMatrix, DoubleDoubleCompilesAndMultiplies) {
  block_sparse_matrix<dd_real, 4> a;
  a.set_pattern(2, 2, std::vector<std::pair<int, int>>{{0, 0}, {1, 1}, {0, 1}});
  a.add_block(0, 0, Eigen::Matrix<dd_real, 4, 4>::Identity());
  a.add_block(1, 1, Eigen::Matrix<dd_real, 4, 4>::Identity() * dd_real(3.0));
  a.add_block(0, 1, Eigen::Matrix<dd_real, 4, 4>::Identity() * dd_real(1e-20));
  vec<dd_real> x = vec<dd_real>::Constant(8, dd_real(1.0)), y(8);
  a.apply(x, y);
  EXPECT_EQ(to_double(y(0) - dd_real(1.0)), 1e-20);  // not representable in double as 1 + 1e-20
  EXPECT_EQ(to_double(y(5)), 3.0);
}

// Products with vectors of the wrong size throw for every product of the matrix, of the
// bordered operator and of the bordered preconditioner (whose apply() the old code ran on
// any sizes, reading past r).
TEST(BlockSparseMatrix, ProductsWithWrongSizeVectorsThrow) {
  const Eigen::Index nb = 5, bs = 4, n = nb * bs, k = 2;
  const auto t = random_triplets<double, 4>(nb, bs, 3, 12);
  const auto a = block_sparse_matrix<double, 4>::from_triplets(nb, nb, t);
  const vec<double> x = vec<double>::Random(n), shorter = vec<double>::Random(n - 1);
  vec<double> y(n), y_short(n - 1);
  EXPECT_THROW(a.apply(shorter, y), input_error);
  EXPECT_THROW(a.apply(x, y_short), input_error);
  EXPECT_THROW(a.multiply_add(1.0, shorter, y), input_error);
  EXPECT_THROW(a.multiply_transpose(x, y_short), input_error);
  vec<cd> xc = vec<cd>::Random(n - 1), yc(n);
  EXPECT_THROW(a.apply_shifted(cd(0, 1), xc, yc), input_error);

  const Eigen::MatrixXd u = Eigen::MatrixXd::Random(n, k), vt = Eigen::MatrixXd::Random(k, n),
                        corner = Eigen::MatrixXd::Random(k, k) + 5.0 * Eigen::MatrixXd::Identity(k, k);
  bordered_operator<block_sparse_matrix<double, 4>, double> op(a, n, u, vt, corner);
  vec<double> yb(n + k);
  EXPECT_THROW(op.apply(x, yb), input_error);
  const Eigen::MatrixXd ainv = dense_of(t, nb, bs).inverse();
  bordered_preconditioner<Eigen::MatrixXd, double> pre(op, ainv);
  const vec<double> rb = vec<double>::Random(n + k);
  vec<double> zb(n + k), z_short(n);
  EXPECT_NO_THROW(pre.apply(rb, zb));
  EXPECT_EQ(pre.rows(), n + k);
  EXPECT_THROW(pre.apply(x, zb), input_error);
  EXPECT_THROW(pre.apply(rb, z_short), input_error);
}
