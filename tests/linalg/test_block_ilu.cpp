// BILU(k): fill patterns against an independent dense evaluation of the level-of-fill rule and
// against hand-derived counts; BILU with enough fill against a dense LU solve (it must be
// exact); filters against the exact solve of the filtered matrix; RCM against a bandwidth
// check; error cases (singular pivot, NaN, pattern change); single-precision factors against the
// double ones (rounding-sized difference, same GMRES convergence).
#include <gtest/gtest.h>

#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <set>

using namespace aerohopf;
using cd = std::complex<double>;
using pattern_t = std::vector<std::pair<Eigen::Index, Eigen::Index>>;

namespace {

// Dense KIJ evaluation of the level rule: lev_ij = min(lev_ij, lev_ik + lev_kj + 1) over
// kept (lev <= k_fill) entries; returns the set of kept positions.
std::set<std::pair<int, int>> dense_level_pattern(int n, const pattern_t& p, int k_fill) {
  const int inf = 1 << 20;
  std::vector<std::vector<int>> lev(n, std::vector<int>(n, inf));
  for (auto [i, j] : p) lev[i][j] = 0;
  for (int i = 0; i < n; ++i) lev[i][i] = 0;
  for (int k = 0; k < n; ++k)
    for (int i = k + 1; i < n; ++i) {
      if (lev[i][k] > k_fill) continue;
      for (int j = k + 1; j < n; ++j)
        if (lev[k][j] <= k_fill) lev[i][j] = std::min(lev[i][j], lev[i][k] + lev[k][j] + 1);
    }
  std::set<std::pair<int, int>> kept;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (lev[i][j] <= k_fill) kept.emplace(i, j);
  return kept;
}

template <class S, int B>
block_ilu<S, B> factor(const block_sparse_matrix<S, B>& a, int k, bool rcm = false, coupling_filter f = {}) {
  block_ilu_options o;
  o.fill_level = k;
  o.reorder_rcm = rcm;
  o.filter = std::move(f);
  block_ilu<S, B> m(o);
  m.compute(a);
  return m;
}

std::set<std::pair<int, int>> factor_pattern(const std::vector<int>& ptr, const std::vector<int>& col) {
  std::set<std::pair<int, int>> s;
  for (int i = 0; i + 1 < static_cast<int>(ptr.size()); ++i)
    for (int p = ptr[i]; p < ptr[i + 1]; ++p) s.emplace(i, col[p]);
  return s;
}

// Block matrix on a pattern with random off-diagonal blocks and dominant diagonal blocks.
template <class S, int B>
block_sparse_matrix<S, B> random_on_pattern(Eigen::Index n, const pattern_t& p, Eigen::Index bs, unsigned seed,
                                            double diag = 8.0) {
  std::srand(seed);
  block_sparse_matrix<S, B> a(bs);
  pattern_t q = p;
  for (Eigen::Index i = 0; i < n; ++i) q.emplace_back(i, i);
  a.set_pattern(n, n, q);
  for (auto [i, j] : q) a.block(i, j) = Eigen::Matrix<S, B, B>::Random(bs, bs);
  for (Eigen::Index i = 0; i < n; ++i) a.block(i, i) += S(diag) * Eigen::Matrix<S, B, B>::Identity(bs, bs);
  return a;
}

pattern_t grid_pattern(int nx, int ny) {  // 5-point stencil
  pattern_t p;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const int c = x + nx * y;
      if (x > 0) p.emplace_back(c, c - 1);
      if (x + 1 < nx) p.emplace_back(c, c + 1);
      if (y > 0) p.emplace_back(c, c - nx);
      if (y + 1 < ny) p.emplace_back(c, c + nx);
    }
  return p;
}

}  // namespace

TEST(BlockIlu, FillPatternMatchesDenseLevelRule) {
  // a 2D grid graph and a random unsymmetric graph, k = 0..3
  std::mt19937 gen(5);
  pattern_t rnd;
  for (int e = 0; e < 40; ++e) rnd.emplace_back(gen() % 20, gen() % 20);
  for (const auto& [n, p] : {std::pair<int, pattern_t>{20, grid_pattern(5, 4)}, std::pair<int, pattern_t>{20, rnd}}) {
    const auto a = random_on_pattern<double, 2>(n, p, 2, 1);
    for (int k = 0; k <= 3; ++k) {
      const auto m = factor(a, k);
      EXPECT_EQ(factor_pattern(m.factor_row_ptr(), m.factor_col_index()), dense_level_pattern(n, p, k)) << "k=" << k;
    }
  }
}

TEST(BlockIlu, FillOfACycleGrowsByTwoBlocksPerLevel) {
  // Cycle 0-1-...-(n-1)-0: eliminating node m creates (m+1, n-1) and (n-1, m+1) at level m+1
  // (hand derivation), so BILU(k) stores 3n + 2k blocks.
  const int n = 10;
  pattern_t p;
  for (int i = 0; i < n; ++i) {
    p.emplace_back(i, (i + 1) % n);
    p.emplace_back((i + 1) % n, i);
  }
  const auto a = random_on_pattern<double, 3>(n, p, 3, 2);
  for (int k = 0; k <= 3; ++k) {
    const auto m = factor(a, k);
    EXPECT_EQ(m.nonzero_blocks(), 3 * n + 2 * k) << "k=" << k;
    for (int j = 1; j <= k; ++j) {
      EXPECT_TRUE(factor_pattern(m.factor_row_ptr(), m.factor_col_index()).count({j, n - 1}));
      EXPECT_TRUE(factor_pattern(m.factor_row_ptr(), m.factor_col_index()).count({n - 1, j}));
    }
  }
  // the 5-point grid with BILU(0) keeps exactly the matrix pattern
  const auto g = random_on_pattern<double, 4>(12, grid_pattern(4, 3), 4, 3);
  EXPECT_EQ(factor(g, 0).nonzero_blocks(), g.nonzero_blocks());
}

template <class S, int B>
void check_exact_with_full_fill(Eigen::Index bs, bool rcm) {
  const int nx = 6, ny = 5, n = nx * ny;
  const auto a = random_on_pattern<S, B>(n, grid_pattern(nx, ny), bs, 4, 3.0);
  const auto m = factor(a, n, rcm);  // k >= n: no block dropped, BILU = block LU
  const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> d(a.to_sparse());
  const vec<S> b = vec<S>::Random(n * bs);
  vec<S> z(n * bs);
  m.apply(b, z);
  const vec<S> x = d.partialPivLu().solve(b);
  EXPECT_LT((z - x).norm(), 1e-11 * x.norm());
  // BILU(0) is an approximation only: not exact here
  const auto m0 = factor(a, 0, rcm);
  m0.apply(b, z);
  EXPECT_GT((z - x).norm(), 1e-6 * x.norm());
}

TEST(BlockIlu, LargeFillIsExactLuReal4) { check_exact_with_full_fill<double, 4>(4, false); }
TEST(BlockIlu, LargeFillIsExactLuComplex5) { check_exact_with_full_fill<cd, 5>(5, false); }
TEST(BlockIlu, LargeFillIsExactLuComplex5Rcm) { check_exact_with_full_fill<cd, 5>(5, true); }
TEST(BlockIlu, LargeFillIsExactLuDynamic3Rcm) { check_exact_with_full_fill<double, Eigen::Dynamic>(3, true); }

TEST(BlockIlu, TridiagonalBilu0IsExact) {
  pattern_t p;
  const int n = 15;
  for (int i = 0; i + 1 < n; ++i) {
    p.emplace_back(i, i + 1);
    p.emplace_back(i + 1, i);
  }
  const auto a = random_on_pattern<cd, 4>(n, p, 4, 8, 2.0);
  const auto m = factor(a, 0);
  const vec<cd> b = vec<cd>::Random(4 * n);
  vec<cd> z(4 * n);
  m.apply(b, z);
  const Eigen::MatrixXcd d(a.to_sparse());
  EXPECT_LT((d * z - b).norm(), 1e-12 * b.norm());
}

TEST(BlockIlu, RcmReducesBandwidthOfAShuffledGrid) {
  const int nx = 12, ny = 10, n = nx * ny;
  std::vector<int> shuffle(n);
  std::iota(shuffle.begin(), shuffle.end(), 0);
  std::shuffle(shuffle.begin(), shuffle.end(), std::mt19937(3));
  pattern_t p;
  for (auto [i, j] : grid_pattern(nx, ny)) p.emplace_back(shuffle[i], shuffle[j]);
  block_sparse_matrix<double, 1> a;
  for (int i = 0; i < n; ++i) p.emplace_back(i, i);
  a.set_pattern(n, n, p);
  const auto perm = reverse_cuthill_mckee(a.row_ptr(), a.col_index());
  const auto inv = inverse_permutation(perm);  // throws if not a permutation
  EXPECT_GT(pattern_bandwidth(a.row_ptr(), a.col_index()), 3 * nx);
  EXPECT_LE(pattern_bandwidth(a.row_ptr(), a.col_index(), inv), nx + 1);  // RCM of a grid: ~ its width
}

TEST(BlockIlu, FiltersDropTheRequestedCouplings) {
  // 2 grid blocks of 10 cells + 1 structural block row coupled to everything
  const int n = 21;
  std::vector<int> grid_block(n);
  for (int i = 0; i < n; ++i) grid_block[i] = i < 10 ? 0 : (i < 20 ? 1 : -1);
  pattern_t p;
  for (int i = 0; i + 1 < 20; ++i) {
    p.emplace_back(i, i + 1);
    p.emplace_back(i + 1, i);
  }
  for (int i = 0; i < 20; ++i) {
    p.emplace_back(i, 20);
    p.emplace_back(20, i);
  }
  const auto a = random_on_pattern<cd, 3>(n, p, 3, 9, 6.0);
  for (int method = 1; method <= 3; ++method) {
    const auto f = coupling_filter::for_method(method, grid_block);
    // reference: the filtered matrix solved exactly
    block_sparse_matrix<cd, 3> af = a;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (a.contains(i, j) && !f.keep(i, j)) af.block(i, j).setZero();
    const auto m = factor(a, n, false, f);
    const vec<cd> b = vec<cd>::Random(3 * n);
    vec<cd> z(3 * n);
    m.apply(b, z);
    const vec<cd> x = Eigen::MatrixXcd(af.to_sparse()).partialPivLu().solve(b);
    EXPECT_LT((z - x).norm(), 1e-11 * x.norm()) << "method " << method;
    // tridiagonal fluid part + arrow to the structure: no fill even in the full LU
    const Eigen::Index expected_blocks = method == 1 ? 58 + 40 + 1 : (method == 2 ? 58 + 1 : 56 + 1);
    EXPECT_EQ(m.nonzero_blocks(), expected_blocks) << "method " << method;
  }
  EXPECT_THROW(coupling_filter::for_method(4, grid_block), input_error);
  // filter for the real form duplicates the labels
  const auto fr = coupling_filter::for_method(3, grid_block).for_real_form(real_form_ordering::split);
  EXPECT_TRUE(fr.keep(3, n + 4));
  EXPECT_FALSE(fr.keep(3, n + 14));
}

TEST(BlockIlu, ErrorsNameTheBlock) {
  const int n = 6;
  pattern_t p;
  for (int i = 0; i + 1 < n; ++i) p.emplace_back(i, i + 1);
  auto a = random_on_pattern<double, 2>(n, p, 2, 1);
  a.block(3, 3).setZero();  // singular pivot in block row 3
  block_ilu<double, 2> m;
  try {
    m.compute(a);
    FAIL() << "no exception";
  } catch (const singular_matrix_error& e) {
    EXPECT_NE(std::string(e.what()).find("block row 3"), std::string::npos) << e.what();
  }
  a.block(3, 3) = Eigen::Matrix2d::Identity();
  a.block(2, 3)(0, 1) = std::nan("");
  try {
    m.compute(a);
    FAIL() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("(2, 3)"), std::string::npos) << e.what();
  }
  a.block(2, 3)(0, 1) = 0.0;
  m.compute(a);
  vec<double> r(3), z(3);
  EXPECT_THROW(m.apply(r, z), input_error);  // size mismatch
  auto other = random_on_pattern<double, 2>(n, {}, 2, 1);
  EXPECT_THROW(m.factorize(other), input_error);  // pattern differs from the analysed one
  block_ilu_options o;
  o.fill_level = -1;
  using ilu2 = block_ilu<double, 2>;
  EXPECT_THROW(ilu2{o}, input_error);
}

// A failed factorisation (singular pivot, non-finite block, pattern other than the analysed
// one) leaves the preconditioner refusing apply() with singular_matrix_error naming the
// context, never applying stale factors of an earlier matrix (the old code applied them after
// a refused factorize()); a later successful factorisation makes it usable again.
TEST(BlockIlu, FailedFactorisationLeavesNoUsableFactors) {
  const int n = 6;
  pattern_t p;
  for (int i = 0; i + 1 < n; ++i) p.emplace_back(i, i + 1);
  const auto good = random_on_pattern<double, 2>(n, p, 2, 1);
  auto singular = good;
  singular.block(2, 2).setZero();
  auto non_finite = good;
  non_finite.block(4, 5)(1, 0) = std::numeric_limits<double>::infinity();
  const auto other_pattern = random_on_pattern<double, 2>(n, {}, 2, 1);
  block_ilu_options o;
  o.context = "test BILU";
  block_ilu<double, 2> m(o);
  const vec<double> r = vec<double>::Ones(2 * n);
  vec<double> z(2 * n), z_good(2 * n);
  m.compute(good);
  m.apply(r, z_good);
  auto attempt_singular = [&] { m.factorize(singular); };
  auto attempt_non_finite = [&] { m.factorize(non_finite); };
  auto attempt_other = [&] { m.factorize(other_pattern); };
  for (const std::function<void()>& attempt :
       std::vector<std::function<void()>>{attempt_singular, attempt_non_finite, attempt_other}) {
    EXPECT_THROW(attempt(), error);
    try {
      m.apply(r, z);
      ADD_FAILURE() << "apply after a failed factorisation did not throw";
    } catch (const singular_matrix_error& e) {
      EXPECT_NE(std::string(e.what()).find("test BILU"), std::string::npos) << e.what();
    }
    m.factorize(good);
    m.apply(r, z);
    EXPECT_EQ((z - z_good).norm(), 0.0);
  }
  // apply before any factorisation: an input error (nothing failed, the call is premature)
  block_ilu<double, 2> fresh;
  EXPECT_THROW(fresh.apply(r, z), input_error);
}

// Single-precision factors: the elimination in double rounded once. With full fill (the exact
// block LU) the apply is the exact solve up to the rounding, so its error is of float rounding
// (not zero, not more) and half the factor bytes; GMRES preconditioned by them reaches the same
// true residual as with double factors in (nearly) the same iterations; a refactorisation gives
// the same preconditioner again; types without fast kernels refuse the option.
template <class S, int B>
void check_single_precision_factors(Eigen::Index bs) {
  const int nx = 7, ny = 6, n = nx * ny;
  const auto a = random_on_pattern<S, B>(n, grid_pattern(nx, ny), bs, 11, 3.0);
  block_ilu_options o;
  o.fill_level = n;
  const block_ilu<S, B> full_double = factor(a, n);
  o.single_precision_factors = true;
  block_ilu<S, B> full_single(o);
  full_single.compute(a);
  EXPECT_EQ(2 * full_single.factor_bytes(), full_double.factor_bytes());
  const vec<S> b = vec<S>::Random(n * bs);
  vec<S> zd(n * bs), zs(n * bs);
  full_double.apply(b, zd);
  full_single.apply(b, zs);
  const double err = (zs - zd).norm() / zd.norm();
  EXPECT_LT(err, 1e-5);
  EXPECT_GT(err, 1e-12);  // the factors really are rounded
  // refactorising (the double working copy released in between) gives the same factors
  full_single.factorize(a);
  vec<S> zs2(n * bs);
  full_single.apply(b, zs2);
  EXPECT_EQ(zs2, zs);

  // BILU(1) as a GMRES preconditioner: same true residual, iterations within one
  o.fill_level = 1;
  block_ilu<S, B> m_single(o);
  m_single.compute(a);
  const block_ilu<S, B> m_double = factor(a, 1);
  krylov_options ko;
  ko.relative_tolerance = 1e-10;
  ko.restart = 30;
  vec<S> xd, xs;
  const auto rd = gmres(a, m_double, b, xd, ko);
  const auto rs = gmres(a, m_single, b, xs, ko);
  ASSERT_TRUE(rd.converged && rs.converged) << rd.reason << " / " << rs.reason;
  EXPECT_LE(rs.relative_residual, 1e-10);
  EXPECT_LE(std::abs(rs.iterations - rd.iterations), 1) << rd.iterations << " vs " << rs.iterations;
  EXPECT_LT((xs - xd).norm(), 1e-8 * xd.norm());
}

TEST(BlockIlu, SinglePrecisionFactorsReal5) { check_single_precision_factors<double, 5>(5); }
TEST(BlockIlu, SinglePrecisionFactorsComplex5) { check_single_precision_factors<cd, 5>(5); }
TEST(BlockIlu, SinglePrecisionFactorsComplex4Rcm) {
  check_single_precision_factors<cd, 4>(4);
  // with reordering, the permuted sweeps read the single-precision factors too
  const int nx = 6, ny = 5, n = nx * ny;
  const auto a = random_on_pattern<cd, 4>(n, grid_pattern(nx, ny), 4, 12, 3.0);
  block_ilu_options o;
  o.fill_level = 1;
  o.reorder_rcm = true;
  block_ilu<cd, 4> d(o);
  d.compute(a);
  o.single_precision_factors = true;
  block_ilu<cd, 4> s(o);
  s.compute(a);
  const vec<cd> b = vec<cd>::Random(4 * n);
  vec<cd> zd(4 * n), zs(4 * n);
  d.apply(b, zd);
  s.apply(b, zs);
  EXPECT_LT((zs - zd).norm(), 1e-5 * zd.norm());
}

TEST(BlockIlu, SinglePrecisionFactorsNeedAFastKernelType) {
  block_ilu_options o;
  o.single_precision_factors = true;
  o.context = "dynamic BILU";
  try {
    block_ilu<double, Eigen::Dynamic> m(o);
    ADD_FAILURE() << "a runtime block size accepted single-precision factors";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("dynamic BILU"), std::string::npos) << e.what();
  }
}
