// Block-row kernels of SpMV and the BILU sweeps (linalg/block_kernels.hpp) against Eigen's dense
// products, for the block sizes with hand-written kernels (4, 5) and one without (3), real and
// complex, both signs, rows of 0..9 blocks with repeated and scattered columns; blocks stored in
// single precision against the same values widened to double. This file is
// compiled twice when AEROHOPF_NATIVE is on: with -march=native (AVX2 + FMA kernels where the CPU
// has them) and without (SSE2 / plain loops), so both paths are checked on every machine.
#include <gtest/gtest.h>

#include <aerohopf/linalg/block_kernels.hpp>

#include <complex>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

using namespace aerohopf;
using cd = std::complex<double>;

namespace {

template <class S>
S random_value(std::mt19937& g) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  if constexpr (std::is_same_v<S, cd>) return cd(u(g), u(g));
  else return u(g);
}

/// n values drawn by random_value, in order.
template <class S>
std::vector<S> random_values(std::mt19937& g, std::size_t n) {
  std::vector<S> v(n);
  for (auto& e : v) e = random_value<S>(g);
  return v;
}

template <class S, int B, int Sign>
void check_rows() {
  std::mt19937 gen(1234 + B * 10 + Sign);
  const int n_seg = 11;  // segments of x
  const std::vector<S> x = random_values<S>(gen, n_seg * B);
  std::uniform_int_distribution<int> col(0, n_seg - 1);
  for (int count = 0; count <= 9; ++count) {
    const std::vector<S> a = random_values<S>(gen, std::size_t(count) * B * B);
    std::vector<int> cols(count);
    for (auto& c : cols) c = col(gen);
    if (count >= 2) cols[1] = cols[0];  // a repeated column
    std::vector<S> acc = random_values<S>(gen, B);
    // reference: acc0 + Sign * sum A_q x_q with Eigen
    Eigen::Matrix<S, B, 1> ref = Eigen::Map<const Eigen::Matrix<S, B, 1>>(acc.data());
    double scale = ref.norm();
    for (int q = 0; q < count; ++q) {
      const Eigen::Map<const Eigen::Matrix<S, B, B>> aq(a.data() + std::size_t(q) * B * B);
      const Eigen::Map<const Eigen::Matrix<S, B, 1>> xq(x.data() + std::size_t(cols[q]) * B);
      const Eigen::Matrix<S, B, 1> p = aq * xq;
      ref += double(Sign) * p;
      scale += aq.norm() * xq.norm();
    }
    internal::block_row_gemv<Sign, B>(a.data(), cols.data(), count, x.data(), acc.data());
    const Eigen::Map<const Eigen::Matrix<S, B, 1>> got(acc.data());
    EXPECT_LE((got - ref).norm(), 1e-15 * scale) << "B " << B << " sign " << Sign << " blocks " << count;
  }
  // single-block product
  const std::vector<S> a1 = random_values<S>(gen, B * B), x1 = random_values<S>(gen, B);
  std::vector<S> y1 = random_values<S>(gen, B);
  Eigen::Matrix<S, B, 1> ref = Eigen::Map<const Eigen::Matrix<S, B, 1>>(y1.data());
  ref += double(Sign) * (Eigen::Map<const Eigen::Matrix<S, B, B>>(a1.data()) * Eigen::Map<const Eigen::Matrix<S, B, 1>>(x1.data()));
  internal::block_gemv<Sign, B>(a1.data(), x1.data(), y1.data());
  EXPECT_LE((Eigen::Map<const Eigen::Matrix<S, B, 1>>(y1.data()) - ref).norm(), 1e-14 * (1 + ref.norm()));
}

template <class S, int B>
void check_both_signs() {
  check_rows<S, B, 1>();
  check_rows<S, B, -1>();
}

// real block row times a complex vector (the fused shifted product of a real matrix)
template <int B>
void check_real_complex_rows() {
  std::mt19937 gen(99 + B);
  const int n_seg = 9;
  const std::vector<cd> x = random_values<cd>(gen, n_seg * B);
  std::uniform_int_distribution<int> col(0, n_seg - 1);
  for (int count = 0; count <= 8; ++count) {
    const std::vector<double> a = random_values<double>(gen, std::size_t(count) * B * B);
    internal::real_complex_row_accumulator<B> t;
    Eigen::Matrix<cd, B, 1> ref = Eigen::Matrix<cd, B, 1>::Zero();
    double scale = 0.0;
    for (int q = 0; q < count; ++q) {
      const int c = q == 1 ? 0 : col(gen);
      const Eigen::Map<const Eigen::Matrix<double, B, B>> aq(a.data() + std::size_t(q) * B * B);
      const Eigen::Map<const Eigen::Matrix<cd, B, 1>> xq(x.data() + std::size_t(c) * B);
      ref += aq.template cast<cd>() * xq;
      scale += aq.norm() * xq.norm();
      t.add(a.data() + std::size_t(q) * B * B, x.data() + std::size_t(c) * B);
    }
    std::vector<cd> got(B, cd(7.0, 7.0));  // store() overwrites
    t.store(got.data());
    EXPECT_LE((Eigen::Map<const Eigen::Matrix<cd, B, 1>>(got.data()) - ref).norm(), 1e-15 * (scale + 1e-300))
        << "B " << B << " blocks " << count;
  }
}

// blocks stored in single precision (the BILU factors' option), sums in double: the kernel must
// give the double product of the stored values widened exactly, not a float product
template <class S, int B, int Sign>
void check_single_precision_rows() {
  using F = internal::single_precision_t<S>;
  std::mt19937 gen(777 + B * 10 + Sign);
  const int n_seg = 7;
  const std::vector<S> x = random_values<S>(gen, n_seg * B);
  std::uniform_int_distribution<int> col(0, n_seg - 1);
  for (int count = 0; count <= 6; ++count) {
    const std::vector<S> a = random_values<S>(gen, std::size_t(count) * B * B);
    std::vector<F> af(a.size());
    std::vector<S> widened(a.size());
    for (std::size_t e = 0; e < a.size(); ++e) {
      af[e] = F(a[e]);
      widened[e] = S(af[e]);
    }
    std::vector<int> cols(count);
    for (auto& c : cols) c = col(gen);
    std::vector<S> acc = random_values<S>(gen, B), acc_wide = acc;
    internal::block_row_gemv<Sign, B>(af.data(), cols.data(), count, x.data(), acc.data());
    internal::block_row_gemv<Sign, B>(widened.data(), cols.data(), count, x.data(), acc_wide.data());
    double change = 0.0;
    for (int r = 0; r < B; ++r)
      EXPECT_LE(std::abs(acc[r] - acc_wide[r]), 1e-15 * (1.0 + std::abs(acc_wide[r]))) << "B " << B << " row " << r;
    // and the rounding to float really happened (the stored values differ from a's)
    for (std::size_t e = 0; e < a.size(); ++e) change = std::max(change, std::abs(widened[e] - a[e]));
    if (count > 0) {
      EXPECT_GT(change, 0.0);
    }
  }
  const std::vector<S> a1 = random_values<S>(gen, B * B), x1 = random_values<S>(gen, B);
  std::vector<F> a1f(a1.size());
  std::vector<S> a1w(a1.size());
  for (std::size_t e = 0; e < a1.size(); ++e) a1w[e] = S(a1f[e] = F(a1[e]));
  std::vector<S> y = random_values<S>(gen, B), yw = y;
  internal::block_gemv<Sign, B>(a1f.data(), x1.data(), y.data());
  internal::block_gemv<Sign, B>(a1w.data(), x1.data(), yw.data());
  for (int r = 0; r < B; ++r) EXPECT_LE(std::abs(y[r] - yw[r]), 1e-15 * (1.0 + std::abs(yw[r])));
}

template <class S, int B>
void check_single_precision_both_signs() {
  check_single_precision_rows<S, B, 1>();
  check_single_precision_rows<S, B, -1>();
}

}  // namespace

TEST(block_kernels, single_precision_blocks_give_the_double_product_of_their_values) {
  check_single_precision_both_signs<double, 3>();
  check_single_precision_both_signs<double, 4>();
  check_single_precision_both_signs<double, 5>();
  check_single_precision_both_signs<cd, 3>();
  check_single_precision_both_signs<cd, 4>();
  check_single_precision_both_signs<cd, 5>();
}

TEST(block_kernels, real_matrix_complex_vector_rows_match_eigen) {
  check_real_complex_rows<3>();
  check_real_complex_rows<4>();
  check_real_complex_rows<5>();
}

TEST(block_kernels, real_rows_match_eigen) {
  std::cout << "block kernel instruction set: " << internal::block_kernel_isa() << "\n";
  check_both_signs<double, 3>();
  check_both_signs<double, 4>();
  check_both_signs<double, 5>();
}

TEST(block_kernels, complex_rows_match_eigen) {
  check_both_signs<cd, 3>();
  check_both_signs<cd, 4>();
  check_both_signs<cd, 5>();
}

TEST(block_kernels, nan_propagates) {
  // the kernels must not hide a NaN of the matrix (the solvers' NaN checks rely on it)
  std::vector<double> a(25, 1.0), x(5, 1.0), acc(5, 0.0);
  a[12] = std::numeric_limits<double>::quiet_NaN();
  const int col = 0;
  internal::block_row_gemv<1, 5>(a.data(), &col, 1, x.data(), acc.data());
  EXPECT_TRUE(std::isnan(acc[2]));
  std::vector<cd> ac(25, cd(1.0, 0.5)), xc(5, cd(0.5, 1.0)), accc(5, cd(0.0));
  ac[7] = cd(std::numeric_limits<double>::quiet_NaN(), 0.0);
  internal::block_row_gemv<-1, 5>(ac.data(), &col, 1, xc.data(), accc.data());
  EXPECT_TRUE(std::isnan(accc[2].real()) || std::isnan(accc[2].imag()));
}
