// QD dd_real / qd_real as aerohopf and Eigen scalars.
//
// The finite-difference derivative products of the reduction layer evaluate residuals in dd and
// qd and push them through Eigen (vectors, norms, dense LU). These tests check that nothing on
// that path silently falls back to double: NumTraits constants live in the QD type and are
// exact, isApprox works at QD precision, generic code finds QD's math functions by ADL, and a
// dense LU solve reaches residuals near the QD unit roundoff.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <aerohopf/scalar/qd.hpp>

#include <cmath>
#include <type_traits>

namespace {

template <class T>
class QdScalar : public ::testing::Test {};
using QdTypes = ::testing::Types<dd_real, qd_real>;
TYPED_TEST_SUITE(QdScalar, QdTypes);

template <class T>
int mantissa_bits();
template <>
int mantissa_bits<dd_real>() { return 104; }
template <>
int mantissa_bits<qd_real>() { return 209; }

// A generic routine written the way aerohopf residuals are: `using std::f;` then unqualified.
template <class S>
S generic_mix(const S& x) {
  using std::exp;
  using std::log;
  using std::sqrt;
  using std::abs;
  return sqrt(x) * exp(log(x)) + abs(-x);
}

template <class T>
using Mat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
template <class T>
using Vec = Eigen::Matrix<T, Eigen::Dynamic, 1>;

// Deterministic, well conditioned test matrix (diagonally dominant) with exactly representable
// entries, so the same matrix exists in double, dd and qd.
template <class T>
Mat<T> test_matrix(int n) {
  Mat<T> a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double v = std::sin(1.0 + 3.0 * i + 7.0 * j);  // any double is exact in T
      a(i, j) = T(v);
    }
  for (int i = 0; i < n; ++i) a(i, i) += T(static_cast<double>(n));
  return a;
}

TYPED_TEST(QdScalar, NumTraitsConstantsAreExactAndInTheQdType) {
  using T = TypeParam;
  using NT = Eigen::NumTraits<T>;
  static_assert(std::is_same_v<decltype(NT::epsilon()), T>);
  static_assert(std::is_same_v<decltype(NT::dummy_precision()), T>);
  static_assert(std::is_same_v<typename NT::Real, T>);
  static_assert(!NT::IsInteger && !NT::IsComplex && NT::IsSigned && NT::RequireInitialization);
  const T eps = NT::epsilon();
  EXPECT_TRUE(eps == ldexp(T(1.0), -mantissa_bits<T>()));
  EXPECT_EQ(aerohopf::scalar_traits<T>::epsilon(), std::ldexp(1.0, -mantissa_bits<T>()));
  // 1 + eps is a different number in T, but eps is far below double's resolution.
  EXPECT_TRUE(T(1.0) + eps != T(1.0));
  EXPECT_TRUE(eps < T(1e-30));
  const T dummy = NT::dummy_precision();
  EXPECT_TRUE(dummy > T(1000.0) * eps);
  EXPECT_TRUE(dummy < T(1e-25));
  EXPECT_EQ(NT::digits(), mantissa_bits<T>());
  EXPECT_GE(NT::digits10(), 31);
  EXPECT_TRUE(NT::highest() > T(1e300));
  EXPECT_TRUE(NT::lowest() < T(-1e300));
  EXPECT_TRUE(isnan(NT::quiet_NaN()));
  EXPECT_TRUE(isinf(NT::infinity()));
}

TYPED_TEST(QdScalar, ScalarTraits) {
  using T = TypeParam;
  using tr = aerohopf::scalar_traits<T>;
  const T third = T(1.0) / T(3.0);
  EXPECT_EQ(tr::to_double(third), 1.0 / 3.0);
  EXPECT_EQ(aerohopf::to_double(third), 1.0 / 3.0);
  EXPECT_EQ(tr::name(), (std::is_same_v<T, dd_real> ? "dd" : "qd"));
  EXPECT_TRUE(aerohopf::make_constant<T>(0.5) == T(1.0) / T(2.0));
}

TYPED_TEST(QdScalar, IsApproxWorksAtQdPrecision) {
  using T = TypeParam;
  const T eps = Eigen::NumTraits<T>::epsilon();
  Vec<T> v(3);
  v << T(1.0) / T(3.0), T(2.0), sqrt(T(2.0));
  const Vec<T> tiny_change = v * (T(1.0) + T(64.0) * eps);
  const Vec<T> double_level_change = v * (T(1.0) + T(1e-17));
  EXPECT_TRUE(v.isApprox(tiny_change));
  EXPECT_FALSE(v.isApprox(double_level_change));  // would pass if dummy_precision were double's
  EXPECT_TRUE(v.isApprox(v));
  // Rounding the vector through double is visible.
  Vec<T> through_double(3);
  for (int i = 0; i < 3; ++i) through_double(i) = T(aerohopf::to_double(v(i)));
  EXPECT_FALSE(v.isApprox(through_double));
}

TYPED_TEST(QdScalar, GenericCodeFindsQdMathByAdl) {
  using T = TypeParam;
  const T eps = Eigen::NumTraits<T>::epsilon();
  const T two(2.0);
  const T r = generic_mix(two);
  static_assert(std::is_same_v<decltype(generic_mix(two)), T>);
  // sqrt(2) * 2 + 2, checked through (r - 2)^2 = 8 which a double sqrt would miss by 1e-16.
  const T s = (r - two) / two;
  EXPECT_LT(abs(s * s - two), T(16.0) * eps);
  EXPECT_LT(abs(exp(log(T(10.0))) - T(10.0)), T(64.0) * eps);
  EXPECT_LT(abs(exp(T(1.0)) - T::_e), T(8.0) * eps);
  EXPECT_LT(abs(T(4.0) * atan(T(1.0)) - T::_pi), T(8.0) * eps);
  EXPECT_LT(abs(pow(T(2.0), T(0.5)) - sqrt(T(2.0))), T(16.0) * eps);
  EXPECT_TRUE(isfinite(r));
}

TYPED_TEST(QdScalar, EigenVectorOpsAndNorm) {
  using T = TypeParam;
  const T eps = Eigen::NumTraits<T>::epsilon();
  Vec<T> v(2);
  v << T(3.0) / T(7.0), T(4.0) / T(7.0);  // norm 5/7
  EXPECT_LT(abs(v.norm() - T(5.0) / T(7.0)), T(8.0) * eps);
  EXPECT_LT(abs(v.squaredNorm() - T(25.0) / T(49.0)), T(8.0) * eps);
  EXPECT_LT(abs(v.dot(v) - T(25.0) / T(49.0)), T(8.0) * eps);
  // Mixed double * QD vector expressions (ScalarBinaryOpTraits).
  const Vec<T> w = v * 7.0;
  const Vec<T> w2 = 7.0 * v;
  EXPECT_LT(abs(w(0) - T(3.0)), T(8.0) * eps);
  EXPECT_LT(abs(w2(1) - T(4.0)), T(8.0) * eps);
  EXPECT_LT(abs(v.template lpNorm<Eigen::Infinity>() - T(4.0) / T(7.0)), T(2.0) * eps);
}

TYPED_TEST(QdScalar, DenseLuSolveReachesQdPrecision) {
  using T = TypeParam;
  const T eps = Eigen::NumTraits<T>::epsilon();
  const int n = 12;
  const Mat<T> a = test_matrix<T>(n);
  Vec<T> x_true(n);
  for (int i = 0; i < n; ++i) x_true(i) = T(1.0) / T(static_cast<double>(i + 1));
  const Vec<T> b = a * x_true;

  const Vec<T> x = a.partialPivLu().solve(b);
  const T rel_residual = (a * x - b).norm() / (a.norm() * x.norm());
  const T rel_error = (x - x_true).norm() / x_true.norm();
  EXPECT_LT(rel_residual, T(64.0) * eps) << "partial pivoting";
  EXPECT_LT(rel_error, T(1e4) * eps) << "partial pivoting";
  if constexpr (std::is_same_v<T, dd_real>) {
    EXPECT_LT(rel_residual, T(1e-30));
  } else {
    EXPECT_LT(rel_residual, T(1e-60));
  }

  // FullPivLU does not compile with QD (it forms RealScalar(Index), ambiguous between QD's
  // int and double constructors); Householder QR is the independent second factorisation.
  const Vec<T> x_qr = a.householderQr().solve(b);
  EXPECT_LT((x_qr - x_true).norm() / x_true.norm(), T(1e4) * eps) << "Householder QR";

  // Independent check of the LU determinant against the double computation.
  const Mat<double> ad = test_matrix<double>(n);
  const double det_d = ad.partialPivLu().determinant();
  const T det = a.partialPivLu().determinant();
  EXPECT_NEAR(aerohopf::to_double(det) / det_d, 1.0, 1e-12);
}

TEST(QdScalar, DdAndQdSolutionsAgreeBeyondDouble) {
  // The same system solved in dd and in qd: they agree to dd precision, far beyond double.
  const int n = 10;
  const Mat<dd_real> a_dd = test_matrix<dd_real>(n);
  const Mat<qd_real> a_qd = test_matrix<qd_real>(n);
  Vec<dd_real> b_dd(n);
  Vec<qd_real> b_qd(n);
  for (int i = 0; i < n; ++i) {
    b_dd(i) = dd_real(1.0 + i);
    b_qd(i) = qd_real(1.0 + i);
  }
  const Vec<dd_real> x_dd = a_dd.partialPivLu().solve(b_dd);
  const Vec<qd_real> x_qd = a_qd.partialPivLu().solve(b_qd);
  qd_real max_diff(0.0);
  for (int i = 0; i < n; ++i) {
    const qd_real d = abs(qd_real(x_dd(i)) - x_qd(i)) / abs(x_qd(i));
    if (d > max_diff) max_diff = d;
  }
  EXPECT_LT(max_diff, qd_real(1e-29));
  const Vec<double> x_d = test_matrix<double>(n).partialPivLu().solve(Vec<double>::LinSpaced(n, 1.0, n));
  double max_diff_d = 0.0;
  for (int i = 0; i < n; ++i)
    max_diff_d = std::max(max_diff_d, std::abs(x_d(i) - to_double(x_qd(i))) / std::abs(to_double(x_qd(i))));
  EXPECT_LT(max_diff_d, 1e-13);
  EXPECT_GT(max_diff_d, 0.0);  // double really is less accurate here, so the dd check means something
}

}  // namespace
