// taylor<T, K> jets: every elementary function's coefficients against closed forms, a composed
// (reactor-type) residual against high-order finite differences evaluated in qd_real, mixed
// arithmetic with built-in constants, and jets flowing through Eigen (norm, dense LU solve
// checked against the independently derived Taylor series of A(t)^{-1} b).
//
// Closed-form constants are computed in T, so a dd/qd jet that lost a double-rounded constant
// somewhere in a recurrence fails at the 1e-30 / 1e-60 level.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/scalar/taylor.hpp>

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

namespace {

using aerohopf::taylor;

template <class T>
T unit_roundoff() { return Eigen::NumTraits<T>::epsilon(); }

template <class T>
T factorial(int k) {
  T f(1.0);
  for (int j = 2; j <= k; ++j) f *= T(static_cast<double>(j));
  return f;
}

// x^k in T by repeated multiplication (no reliance on pow overloads of T).
template <class T>
T ipow(const T& x, int k) {
  T p(1.0);
  for (int j = 0; j < k; ++j) p *= x;
  return p;
}

// Generalised binomial coefficient binom(r, k) in T.
template <class T>
T binomial(const T& r, int k) {
  T b(1.0);
  for (int j = 0; j < k; ++j) b = b * (r - T(static_cast<double>(j))) / T(static_cast<double>(j + 1));
  return b;
}

// |got - want| <= rel * max(|want|, floor): relative, with an absolute floor for zeros.
template <class T>
::testing::AssertionResult close_rel(const T& got, const T& want, const T& rel, double floor = 0.0) {
  using std::abs;
  T scale = abs(want);
  if (scale < T(floor)) scale = T(floor);
  const T err = abs(got - want);
  if (err <= rel * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << aerohopf::to_double(got) << " want "
                                       << aerohopf::to_double(want) << " rel err "
                                       << aerohopf::to_double(err / scale) << " > "
                                       << aerohopf::to_double(rel);
}

template <class T>
class TaylorTyped : public ::testing::Test {};
using ScalarTypes = ::testing::Types<double, dd_real, qd_real>;
TYPED_TEST_SUITE(TaylorTyped, ScalarTypes);

constexpr int kOrder = 6;

// ---------------------------------------------------------------- arithmetic and API

TYPED_TEST(TaylorTyped, ApiAndCauchyProduct) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  static_assert(J::order == kOrder);
  static_assert(std::is_same_v<typename J::value_type, T>);
  const J x = J::variable(T(0.0));
  J p(T(1.0));
  for (int i = 0; i < kOrder; ++i) p *= (x + T(1.0));  // (1 + t)^6: binomial coefficients exactly
  for (int k = 0; k <= kOrder; ++k) EXPECT_TRUE(p[k] == binomial(T(6.0), k)) << k;
  EXPECT_TRUE(p.value() == T(1.0));
  // derivative(k) = k! c_k; exp(t) has all derivatives 1.
  const J e = exp(x);
  for (int k = 0; k <= kOrder; ++k) EXPECT_TRUE(close_rel(e.derivative(k), T(1.0), T(8.0) * unit_roundoff<T>())) << k;
  const J y = J::variable(T(2.0), T(3.0));
  EXPECT_TRUE(y[0] == T(2.0) && y[1] == T(3.0) && y[2] == T(0.0));
  J z;
  for (int k = 0; k <= kOrder; ++k) EXPECT_TRUE(z[k] == T(0.0));
  z[2] = T(5.0);
  EXPECT_TRUE(z.derivative(2) == T(10.0));
}

TYPED_TEST(TaylorTyped, ReciprocalKeepsFullPrecision) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  const J t = J::variable(T(0.0));
  const T tol = T(16.0) * unit_roundoff<T>();
  // 1 / (3 + t) = sum (-1)^k t^k / 3^{k+1}, written four ways (int, double, T, jet constants).
  const std::array<J, 4> forms = {1 / (3 + t), 1.0 / (3.0 + t), T(1.0) / (T(3.0) + t), J(T(1.0)) / (J(T(3.0)) + t)};
  for (const J& r : forms) {
    T pow3(3.0);
    for (int k = 0; k <= kOrder; ++k) {
      const T want = (k % 2 ? T(-1.0) : T(1.0)) / pow3;
      EXPECT_TRUE(close_rel(r[k], want, tol)) << "k = " << k;
      pow3 *= T(3.0);
    }
  }
  if constexpr (std::is_same_v<T, dd_real>) {
    const taylor<dd_real, 3> r3 = 1 / (3 + taylor<dd_real, 3>::variable(dd_real(0.0)));
    EXPECT_LT(abs(r3[3] * dd_real(81.0) + dd_real(1.0)), dd_real(1e-30));
  }
}

TYPED_TEST(TaylorTyped, MixedOperationsWithBuiltinConstants) {
  using T = TypeParam;
  using J = taylor<T, 3>;
  const J x = J::variable(T(0.5), T(1.0));  // 0.5 + t
  const T third = T(1.0) / T(3.0);
  const T tol = T(4.0) * unit_roundoff<T>();
  const J a = x * 2.0, b = 2 * x, c = x / 3, d = 2.0f * x, e = x + 1, f = 1 - x, g = 3 / x, h = x - 0.25;
  EXPECT_TRUE(a[0] == T(1.0) && a[1] == T(2.0));
  EXPECT_TRUE(b[0] == T(1.0) && b[1] == T(2.0));
  EXPECT_TRUE(d[0] == T(1.0) && d[1] == T(2.0));
  EXPECT_TRUE(close_rel(c[0], third / T(2.0), tol) && close_rel(c[1], third, tol));
  EXPECT_TRUE(e[0] == T(1.5) && e[1] == T(1.0));
  EXPECT_TRUE(f[0] == T(0.5) && f[1] == T(-1.0));
  EXPECT_TRUE(h[0] == T(0.25) && h[1] == T(1.0));
  // 3 / (0.5 + t) = 6 - 12 t + 24 t^2 - 48 t^3
  EXPECT_TRUE(close_rel(g[0], T(6.0), tol) && close_rel(g[1], T(-12.0), tol) && close_rel(g[2], T(24.0), tol) &&
              close_rel(g[3], T(-48.0), tol));
  J m = x;
  m *= 4;
  m /= T(2.0);
  m += T(1.0);
  m -= J(T(1.0));
  m *= J(T(2.0));
  m /= J(T(4.0));
  EXPECT_TRUE(m[0] == T(0.5) && m[1] == T(1.0));
  const J n = -x;
  EXPECT_TRUE(n[0] == T(-0.5) && n[1] == T(-1.0) && (+x)[1] == T(1.0));

  // Comparisons use the value only, with any built-in constant on either side.
  EXPECT_TRUE(x < 1 && x < 1.0 && x > 0 && x <= 0.5 && x >= 0.5 && x == 0.5 && x != 1);
  EXPECT_TRUE(1 > x && 0.0 < x && 0.5 <= x && 0.5 >= x && 0.5 == x && 2 != x);
  EXPECT_TRUE(x == J(T(0.5)) && x < J(T(0.6)) && x == T(0.5) && T(0.5) == x && T(0.4) < x);
}

// ---------------------------------------------------------------- elementary functions vs closed forms

TYPED_TEST(TaylorTyped, ExpLogSqrtPowClosedForms) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  using std::exp;
  using std::log;
  using std::pow;
  using std::sqrt;
  const T a = T(3.0) / T(4.0);
  const J x = J::variable(a);  // a + t
  const T tol = T(128.0) * unit_roundoff<T>();

  const J ex = exp(x), lg = log(x), sq = sqrt(x);
  const T r = T(17.0) / T(10.0);
  const J pw = pow(x, r), pw_jet = pow(x, J(r)), pw_neg = pow(x, -3);
  const J e2 = exp(J::variable(T(0.0), T(2.0)));  // exp(2 t) = sum 2^k t^k / k!
  T a_pow_k(1.0);
  for (int k = 0; k <= kOrder; ++k) {
    const T kk = T(static_cast<double>(k));
    EXPECT_TRUE(close_rel(ex[k], exp(a) / factorial<T>(k), tol)) << "exp k=" << k;
    EXPECT_TRUE(close_rel(e2[k], ipow(T(2.0), k) / factorial<T>(k), tol)) << "exp(2t) k=" << k;
    const T log_want = k == 0 ? log(a) : (k % 2 ? T(1.0) : T(-1.0)) / (kk * a_pow_k);
    EXPECT_TRUE(close_rel(lg[k], log_want, tol)) << "log k=" << k;
    EXPECT_TRUE(close_rel(sq[k], sqrt(a) * binomial(T(0.5), k) / a_pow_k, tol)) << "sqrt k=" << k;
    EXPECT_TRUE(close_rel(pw[k], pow(a, r) * binomial(r, k) / a_pow_k, tol)) << "pow k=" << k;
    EXPECT_TRUE(close_rel(pw_jet[k], pw[k], tol)) << "pow(jet, jet) k=" << k;
    EXPECT_TRUE(close_rel(pw_neg[k], binomial(T(-3.0), k) / (a * a * a * a_pow_k), tol)) << "pow(-3) k=" << k;
    a_pow_k *= a;
  }
  // Integer exponent given as a real, with a negative base: (t - 2)^3 = t^3 - 6 t^2 + 12 t - 8.
  const J cube = pow(J::variable(T(-2.0)), T(3.0));
  const J cube_d = pow(J::variable(T(-2.0)), 3.0);
  const std::array<double, 4> cube_want = {-8.0, 12.0, -6.0, 1.0};
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(cube[k] == T(cube_want[k]) && cube_d[k] == T(cube_want[k])) << k;
  EXPECT_TRUE(cube[4] == T(0.0));
  // Zero base, positive integer power: t^2.
  const J sq0 = pow(J::variable(T(0.0)), T(2.0));
  EXPECT_TRUE(sq0[0] == T(0.0) && sq0[1] == T(0.0) && sq0[2] == T(1.0) && sq0[3] == T(0.0));
}

TYPED_TEST(TaylorTyped, TrigonometricClosedForms) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  using std::atan;
  using std::cos;
  using std::sin;
  using std::tan;
  const T a = T(7.0) / T(10.0);
  const J x = J::variable(a);
  const T tol = T(256.0) * unit_roundoff<T>();
  const J s = sin(x), c = cos(x), at = atan(x);
  const std::array<T, 4> sin_cycle = {sin(a), cos(a), -sin(a), -cos(a)};
  const T theta = atan(T(1.0) / a);  // arccot(a); atan^{(k)}(a) = (-1)^{k-1} (k-1)! sin^k(theta) sin(k theta)
  for (int k = 0; k <= kOrder; ++k) {
    EXPECT_TRUE(close_rel(s[k], sin_cycle[k % 4] / factorial<T>(k), tol)) << "sin k=" << k;
    EXPECT_TRUE(close_rel(c[k], sin_cycle[(k + 1) % 4] / factorial<T>(k), tol)) << "cos k=" << k;
    if (k >= 1) {
      const T kk = T(static_cast<double>(k));
      const T want = (k % 2 ? T(1.0) : T(-1.0)) * ipow(sin(theta), k) * sin(kk * theta) / kk;
      EXPECT_TRUE(close_rel(at[k], want, tol)) << "atan k=" << k;
    }
  }
  EXPECT_TRUE(close_rel(at[0], atan(a), tol));
  // tan: tan' = 1 + tan^2, tan'' = 2 tan (1 + tan^2), tan''' = 2 (1 + tan^2)(1 + 3 tan^2).
  const J tn = tan(x);
  const T ta = tan(a), sec2 = T(1.0) + ta * ta;
  EXPECT_TRUE(close_rel(tn[0], ta, tol));
  EXPECT_TRUE(close_rel(tn[1], sec2, tol));
  EXPECT_TRUE(close_rel(tn[2], ta * sec2, tol));
  EXPECT_TRUE(close_rel(tn[3], sec2 * (T(1.0) + T(3.0) * ta * ta) / T(3.0), tol));
}

TYPED_TEST(TaylorTyped, Atan2FollowsTheAngleInEveryQuadrant) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  const T tol = T(64.0) * unit_roundoff<T>();
  // atan2(r sin(th0 + t), r cos(th0 + t)) = th0 + t for any positive radius r(t).
  for (double th0 : {0.3, 2.5, -2.0, -0.7}) {
    const J angle = J::variable(T(th0));
    const J radius = J::variable(T(2.0), T(-0.5)) * exp(J::variable(T(0.0)));
    const J th = atan2(radius * sin(angle), radius * cos(angle));
    EXPECT_TRUE(close_rel(th[0], T(th0), tol)) << th0;
    EXPECT_TRUE(close_rel(th[1], T(1.0), tol)) << th0;
    for (int k = 2; k <= kOrder; ++k) EXPECT_TRUE(close_rel(th[k], T(0.0), tol, 1.0)) << th0 << " k=" << k;
  }
}

TYPED_TEST(TaylorTyped, TanhClosedFormsAndLargeArguments) {
  using T = TypeParam;
  using J = taylor<T, kOrder>;
  using std::tanh;
  const T tol = T(256.0) * unit_roundoff<T>();
  const T a(0.5);
  const J th = tanh(J::variable(a));
  // Addition theorem with the series tanh t = t - t^3/3 + 2 t^5/15 + O(t^7).
  J tanh_t;
  tanh_t[1] = T(1.0);
  tanh_t[3] = T(-1.0) / T(3.0);
  tanh_t[5] = T(2.0) / T(15.0);
  const T ta = tanh(a);
  const J want = (ta + tanh_t) / (T(1.0) + ta * tanh_t);
  for (int k = 0; k <= kOrder; ++k) EXPECT_TRUE(close_rel(th[k], want[k], tol)) << "tanh k=" << k;
  // Derivative values: tanh' = 1 - th^2, tanh'' = -2 th (1 - th^2).
  EXPECT_TRUE(close_rel(th.derivative(1), T(1.0) - ta * ta, tol));
  EXPECT_TRUE(close_rel(th.derivative(2), T(-2.0) * ta * (T(1.0) - ta * ta), tol));
  // Far in the tails the jet must stay finite (exp(2a) would overflow): tanh -> +-1, derivatives -> 0.
  for (double big : {400.0, -400.0, 30.0}) {
    using std::exp;
    const J tb = tanh(J::variable(T(big)));
    EXPECT_TRUE(isfinite(tb)) << big;
    // tanh a = sign(a) (1 - q) / (1 + q) and tanh' a = 4 q / (1 + q)^2 with q = exp(-2|a|).
    const T q = exp(T(-2.0) * T(std::abs(big)));
    const T sign(big > 0 ? 1.0 : -1.0);
    EXPECT_TRUE(close_rel(tb[0], sign * (T(1.0) - q) / (T(1.0) + q), tol)) << big;
    EXPECT_TRUE(close_rel(tb[1], T(4.0) * q / ((T(1.0) + q) * (T(1.0) + q)), tol, 1e-300)) << big;
    // tanh'' / 2 = -tanh tanh'
    EXPECT_TRUE(close_rel(tb[2], -tb[0] * tb[1], tol, 1e-300)) << big;
  }
}

TYPED_TEST(TaylorTyped, AbsMinMaxFollowTheValueBranch) {
  using T = TypeParam;
  using J = taylor<T, 3>;
  const J x = J::variable(T(-0.5), T(2.0));  // -0.5 + 2 t
  const J ax = abs(x), fx = fabs(x);
  EXPECT_TRUE(ax[0] == T(0.5) && ax[1] == T(-2.0) && fx[1] == T(-2.0));
  // At a zero value the sign of the first non-zero coefficient decides: |0 - t + t^2| = t - t^2.
  J z;
  z[1] = T(-1.0);
  z[2] = T(1.0);
  const J az = abs(z);
  EXPECT_TRUE(az[0] == T(0.0) && az[1] == T(1.0) && az[2] == T(-1.0));
  const J y = J::variable(T(1.0), T(-3.0));
  EXPECT_TRUE(min(x, y)[1] == T(2.0) && max(x, y)[1] == T(-3.0));
  EXPECT_TRUE(fmin(y, x)[1] == T(2.0) && fmax(y, x)[1] == T(-3.0));
  using std::max;
  using std::min;
  const J m = max(x * x, y);  // by value: no dangling reference to the temporary x * x
  EXPECT_TRUE(m[0] == T(1.0) && m[1] == T(-3.0));
  EXPECT_TRUE(min(x * x, y)[1] == T(-2.0));
  EXPECT_FALSE(isnan(x));
  // sqrt of an identically zero jet (norm of a zero vector) is zero, not NaN.
  const J zero_root = sqrt(J(T(0.0)));
  EXPECT_TRUE(isfinite(zero_root) && zero_root[0] == T(0.0) && zero_root[3] == T(0.0));
  const Eigen::Matrix<J, 3, 1> zero_vector = Eigen::Matrix<J, 3, 1>::Zero();
  EXPECT_TRUE(isfinite(zero_vector.norm()) && zero_vector.norm()[1] == T(0.0));
  EXPECT_FALSE(isfinite(sqrt(J::variable(T(0.0)))));  // sqrt(t): not differentiable
  EXPECT_TRUE(isnan(J::variable(Eigen::NumTraits<T>::quiet_NaN())));
  EXPECT_TRUE(isinf(J::variable(Eigen::NumTraits<T>::infinity())));
  EXPECT_FALSE(isinf(J::variable(T(1.0))));
  EXPECT_FALSE(isfinite(J(T(1.0)) / J(T(0.0))));
}

// ---------------------------------------------------------------- composition vs qd finite differences

constexpr int kFdOrder = 5;

// A residual-like composition (constants via make_constant: QD's pow(qd_real, int) would
// silently take pow(x, 1.5) as pow(x, 1)), generic in the scalar: the Arrhenius factor exp(Gam - Gam/x) of
// the tubular reactor model plus every other elementary function once.
template <class S>
S reactor_rate(const S& x) {
  using std::exp;
  const S gam = aerohopf::make_constant<S>(20.0);
  return exp(gam - gam / x);
}
template <class S>
S kitchen_sink(const S& x) {
  using std::atan;
  using std::atan2;
  using std::cos;
  using std::log;
  using std::pow;
  using std::sin;
  using std::sqrt;
  using std::tanh;
  const S one = aerohopf::make_constant<S>(1.0);
  return reactor_rate(x) * sqrt(x) / (one + x * x) + atan(x) * log(x) + pow(x, aerohopf::make_constant<S>(1.5)) * sin(x) -
         tanh(x) * cos(x) + atan2(x * x, one + x) - abs(x - aerohopf::make_constant<S>(2.0)) / (x + 3);
}

// Taylor coefficients c_0..c_K of f at x0 from the degree-2m polynomial interpolating f at
// x0 + i h, i = -m..m, all in qd: solve the Vandermonde system sum_p i^p d_p = f(x0 + i h),
// then c_k = d_k / h^k. Truncation ~h^{2m+1-k}, rounding ~cond(V) eps_qd / h^k.
template <class F>
std::vector<qd_real> fd_coefficients(F f, const qd_real& x0, const qd_real& h, int m) {
  const int n = 2 * m + 1;
  Eigen::Matrix<qd_real, Eigen::Dynamic, Eigen::Dynamic> v(n, n);
  Eigen::Matrix<qd_real, Eigen::Dynamic, 1> rhs(n);
  for (int row = 0; row < n; ++row) {
    const int i = row - m;
    qd_real ip(1.0);
    for (int p = 0; p < n; ++p) {
      v(row, p) = ip;
      ip *= qd_real(static_cast<double>(i));
    }
    rhs(row) = f(x0 + qd_real(static_cast<double>(i)) * h);
  }
  const Eigen::Matrix<qd_real, Eigen::Dynamic, 1> d = v.partialPivLu().solve(rhs);
  std::vector<qd_real> c(kFdOrder + 1);
  qd_real hk(1.0);
  for (int k = 0; k <= kFdOrder; ++k) {
    c[k] = d(k) / hk;
    hk *= h;
  }
  return c;
}

template <class T, class F, class G>
void expect_jet_matches_fd(F f_jet, G f_qd, double x0, double rel, const std::string& what) {
  const std::vector<qd_real> fd = fd_coefficients(f_qd, qd_real(x0), qd_real(1e-5), 6);
  const taylor<T, kFdOrder> jet = f_jet(taylor<T, kFdOrder>::variable(T(x0)));
  double worst = 0.0;
  for (int k = 0; k <= kFdOrder; ++k) {
    const qd_real got = qd_real(jet[k]);
    EXPECT_TRUE(close_rel(got, fd[k], qd_real(rel))) << what << " x0=" << x0 << " k=" << k;
    worst = std::max(worst, to_double(abs(got - fd[k]) / abs(fd[k])));
  }
  std::printf("%-8s x0 = %.2f: max relative coefficient error vs qd FD = %.2e\n", what.c_str(), x0, worst);
}

TEST(TaylorComposition, FiniteDifferencesInQdAreAccurate) {
  // Sanity of the reference itself: FD coefficients of exp(x) at 0.5 are exp(0.5)/k!.
  const std::vector<qd_real> fd = fd_coefficients([](const qd_real& x) { return exp(x); }, qd_real(0.5),
                                                  qd_real(1e-5), 6);
  for (int k = 0; k <= kFdOrder; ++k)
    EXPECT_TRUE(close_rel(fd[k], exp(qd_real(0.5)) / factorial<qd_real>(k), qd_real(1e-27))) << k;
}

TEST(TaylorComposition, ReactorExponentialInDoubleTo1e13) {
  for (double x0 : {0.8, 1.1, 1.7})
    expect_jet_matches_fd<double>([](const auto& x) { return reactor_rate(x); },
                                  [](const qd_real& x) { return reactor_rate(x); }, x0, 1e-13, "reactor");
}

TEST(TaylorComposition, KitchenSinkInEveryPrecision) {
  const auto f_jet = [](const auto& x) { return kitchen_sink(x); };
  const auto f_qd = [](const qd_real& x) { return kitchen_sink(x); };
  for (double x0 : {0.9, 1.3}) {
    expect_jet_matches_fd<double>(f_jet, f_qd, x0, 1e-13, "double");
    expect_jet_matches_fd<dd_real>(f_jet, f_qd, x0, 1e-29, "dd");
    expect_jet_matches_fd<qd_real>(f_jet, f_qd, x0, 1e-30, "qd");
  }
}

// ---------------------------------------------------------------- jets through Eigen

TEST(TaylorEigen, NumTraitsAndVectorOps) {
  using J = taylor<double, 3>;
  static_assert(std::is_same_v<Eigen::NumTraits<J>::Real, J>);
  EXPECT_EQ(Eigen::NumTraits<J>::epsilon()[0], Eigen::NumTraits<double>::epsilon());
  EXPECT_GT(Eigen::NumTraits<J>::dummy_precision()[0], 0.0);
  using JD = taylor<dd_real, 3>;
  EXPECT_TRUE(Eigen::NumTraits<JD>::epsilon()[0] == Eigen::NumTraits<dd_real>::epsilon());
  EXPECT_EQ(aerohopf::scalar_traits<J>::epsilon(), aerohopf::scalar_traits<double>::epsilon());
  EXPECT_EQ(aerohopf::to_double(J::variable(2.5)), 2.5);

  const J t = J::variable(0.0);
  // (1 + t)(cos t, sin t) has norm exactly 1 + t.
  Eigen::Matrix<J, 2, 1> v;
  v << (1.0 + t) * cos(t), (1.0 + t) * sin(t);
  const J nv = v.norm();
  EXPECT_NEAR(nv[0], 1.0, 1e-15);
  EXPECT_NEAR(nv[1], 1.0, 1e-15);
  EXPECT_NEAR(nv[2], 0.0, 1e-15);
  EXPECT_NEAR(nv[3], 0.0, 1e-15);
  const J sq = v.squaredNorm();  // 1 + 2t + t^2
  EXPECT_NEAR(sq[1], 2.0, 1e-15);
  EXPECT_NEAR(sq[2], 1.0, 1e-15);
  // Scaling by plain doubles, sums, dot products, normalisation.
  const Eigen::Matrix<J, 2, 1> w = 2.0 * v + v * 3.0 - v / 5.0;
  EXPECT_NEAR(w.norm()[1], 4.8, 1e-14);
  EXPECT_NEAR(v.dot(w)[2], 4.8, 1e-14);
  const Eigen::Matrix<J, 2, 1> u = v.normalized();  // (cos t, sin t)
  EXPECT_NEAR(u(0)[2], -0.5, 1e-15);
  EXPECT_NEAR(u(1)[3], -1.0 / 6.0, 1e-15);
  EXPECT_TRUE(v.isApprox(v));
  EXPECT_FALSE(v.isApprox(w));
  EXPECT_NEAR(v.sum()[1], 2.0, 1e-15);  // (1 + t)(cos t + sin t) = 1 + 2t + ...
  EXPECT_NEAR(v.cwiseAbs().maxCoeff()[0], 1.0, 1e-15);
}

// dA/dt-structured system A(t) x(t) = b with A(t) = A0 + t A1: the Taylor coefficients satisfy
// A0 x_k = -A1 x_{k-1}, computed here with double LU as the independent reference.
template <class T>
void check_jet_lu_solve(const T& tol) {
  constexpr int n = 6;
  constexpr int K = 3;
  using J = taylor<T, K>;
  Eigen::Matrix<double, n, n> a0, a1;
  Eigen::Matrix<double, n, 1> b;
  for (int i = 0; i < n; ++i) {
    b(i) = std::cos(0.3 * i + 0.1);
    for (int j = 0; j < n; ++j) {
      a0(i, j) = std::sin(1.0 + 2.0 * i + 5.0 * j) + (i == j ? 4.0 : 0.0);
      a1(i, j) = std::cos(0.5 * i - 1.5 * j);
    }
  }
  Eigen::Matrix<J, n, n> a;
  Eigen::Matrix<J, n, 1> bj;
  for (int i = 0; i < n; ++i) {
    bj(i) = J(T(b(i)));
    for (int j = 0; j < n; ++j) a(i, j) = J::variable(T(a0(i, j)), T(a1(i, j)));
  }
  const Eigen::Matrix<J, n, 1> x = a.partialPivLu().solve(bj);
  const Eigen::Matrix<J, n, 1> x_inv = a.inverse() * bj;

  // Reference series in T (double values exact in T).
  Eigen::Matrix<T, n, n> a0t = a0.template cast<T>(), a1t = a1.template cast<T>();
  const auto lu0 = a0t.partialPivLu();
  Eigen::Matrix<T, n, 1> xk = lu0.solve(b.template cast<T>());
  for (int k = 0; k <= K; ++k) {
    for (int i = 0; i < n; ++i) {
      EXPECT_TRUE(close_rel(x(i)[k], xk(i), tol, 1.0)) << "LU k=" << k << " i=" << i;
      EXPECT_TRUE(close_rel(x_inv(i)[k], xk(i), tol, 1.0)) << "inverse k=" << k << " i=" << i;
    }
    xk = lu0.solve(Eigen::Matrix<T, n, 1>(-(a1t * xk)));
  }
  // And the residual A(t) x(t) - b vanishes as a series.
  const Eigen::Matrix<J, n, 1> res = a * x - bj;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k <= K; ++k) EXPECT_TRUE(close_rel(res(i)[k], T(0.0), tol, 1.0)) << i << " " << k;
}

TEST(TaylorEigen, DenseLuSolveOfParameterisedSystemDouble) { check_jet_lu_solve<double>(1e-13); }
TEST(TaylorEigen, DenseLuSolveOfParameterisedSystemDd) { check_jet_lu_solve<dd_real>(dd_real(1e-29)); }

TEST(TaylorEigen, FullPivLuWithDoubleJets) {
  using J = taylor<double, 2>;
  Eigen::Matrix<J, 2, 2> a;
  // A(t) = [[2 + t, 1], [1, 3]]; x = A^{-1} (1, 0) = (3, -1) / (5 + 3t)
  a << J::variable(2.0), J(1.0), J(1.0), J(3.0);
  Eigen::Matrix<J, 2, 1> b(J(1.0), J(0.0));
  const Eigen::Matrix<J, 2, 1> x = a.fullPivLu().solve(b);
  EXPECT_NEAR(x(0)[0], 0.6, 1e-15);
  EXPECT_NEAR(x(0)[1], -3.0 * 3.0 / 25.0, 1e-15);
  EXPECT_NEAR(x(1)[2], -1.0 * 9.0 / 125.0, 1e-15);
}

}  // namespace
