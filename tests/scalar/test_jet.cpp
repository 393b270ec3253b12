// jet<T, N> (first-order, N directions): API and arithmetic, every elementary function against
// its closed-form derivative, a composed multi-variable function against central differences
// evaluated in qd_real and against taylor<T, 1> one direction at a time, the non-smooth points
// (abs, sqrt at 0, min/max) as taylor<T, 1> sees them, and jets flowing through Eigen (NumTraits,
// isApprox, dense LU solve against the derivative of A(p)^{-1} b). Over double and dd_real:
// closed-form constants are computed in T, so a dd jet that went through a double somewhere
// fails at the 1e-30 level.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <aerohopf/scalar/jet.hpp>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/scalar/taylor.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>

namespace {

using aerohopf::jet;
using aerohopf::taylor;

template <class T>
T unit_roundoff() { return Eigen::NumTraits<T>::epsilon(); }

// |got - want| <= rel * max(|want|, floor).
template <class T>
::testing::AssertionResult close_rel(const T& got, const T& want, const T& rel, double floor = 0.0) {
  using std::abs;
  T scale = abs(want);
  if (scale < T(floor)) scale = T(floor);
  const T err = abs(got - want);
  if (err <= rel * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << aerohopf::to_double(got) << " want " << aerohopf::to_double(want)
                                       << " rel err " << aerohopf::to_double(err / scale) << " > "
                                       << aerohopf::to_double(rel);
}

template <class T>
class JetTyped : public ::testing::Test {};
using ScalarTypes = ::testing::Types<double, dd_real>;
TYPED_TEST_SUITE(JetTyped, ScalarTypes);

// ---------------------------------------------------------------- API and arithmetic

TYPED_TEST(JetTyped, ApiSeedsAndAccessors) {
  using T = TypeParam;
  using J = jet<T, 3>;
  static_assert(J::directions == 3);
  static_assert(std::is_same_v<typename J::value_type, T>);
  static_assert(aerohopf::is_jet_v<J> && !aerohopf::is_jet_v<T>);
  static_assert(std::is_trivially_copyable_v<jet<double, 4>>);  // no allocation, plain storage
  // a real second argument would silently pick a direction: it does not compile
  static_assert(!requires { J::variable(T(1.0), 1.0); });
  static_assert(requires { J::variable(T(1.0), 1); });
  const J z;
  EXPECT_TRUE(z.value() == T(0.0));
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(z.derivative(k) == T(0.0));
  const J x = J::variable(T(2.0), 1);
  EXPECT_TRUE(x.value() == T(2.0) && x.derivative(0) == T(0.0) && x.derivative(1) == T(1.0) && x.derivative(2) == T(0.0));
  const J y = J::variable(T(3.0), {T(1.0), T(-2.0), T(0.5)});
  EXPECT_TRUE(y.derivatives()[1] == T(-2.0));
  const J c = 5;  // constants promote
  EXPECT_TRUE(c.value() == T(5.0) && c.derivative(2) == T(0.0));
  J m = y;
  m.derivative(2) = T(7.0);
  m.value() = T(1.0);
  EXPECT_TRUE(m.value() == T(1.0) && m.derivative(2) == T(7.0));
  EXPECT_TRUE(aerohopf::to_double(y) == 3.0);
  EXPECT_EQ(aerohopf::scalar_traits<J>::epsilon(), aerohopf::scalar_traits<T>::epsilon());
}

TYPED_TEST(JetTyped, ProductQuotientAndMixedConstants) {
  using T = TypeParam;
  using J = jet<T, 2>;
  const J x = J::variable(T(0.5), {T(1.0), T(2.0)});
  const J y = J::variable(T(3.0), {T(-1.0), T(4.0)});
  const T third = T(1.0) / T(3.0);
  const T tol = T(4.0) * unit_roundoff<T>();
  // product rule, quotient rule
  const J p = x * y, q = x / y;
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(p.derivative(k) == x.value() * y.derivative(k) + y.value() * x.derivative(k)) << k;
    const T want = (x.derivative(k) * y.value() - x.value() * y.derivative(k)) / (y.value() * y.value());
    EXPECT_TRUE(close_rel(q.derivative(k), want, tol)) << k;
  }
  EXPECT_TRUE(close_rel(q.value(), T(0.5) * third, tol));
  // built-in constants on either side, T constants, jet constants
  const J a = x * 2.0, b = 2 * x, c = x / 3, d = 2.0f * x, e = x + 1, f = 1 - x, g = 3 / x, h = x - 0.25;
  EXPECT_TRUE(a.value() == T(1.0) && a.derivative(1) == T(4.0));
  EXPECT_TRUE(b.value() == T(1.0) && b.derivative(0) == T(2.0));
  EXPECT_TRUE(d.value() == T(1.0) && d.derivative(1) == T(4.0));
  EXPECT_TRUE(close_rel(c.value(), third / T(2.0), tol) && close_rel(c.derivative(1), T(2.0) * third, tol));
  EXPECT_TRUE(e.value() == T(1.5) && e.derivative(0) == T(1.0));
  EXPECT_TRUE(f.value() == T(0.5) && f.derivative(1) == T(-2.0));
  EXPECT_TRUE(h.value() == T(0.25) && h.derivative(1) == T(2.0));
  // 3 / x: value 6, derivative -3 / x^2 dx = -12 dx
  EXPECT_TRUE(close_rel(g.value(), T(6.0), tol) && close_rel(g.derivative(0), T(-12.0), tol) &&
              close_rel(g.derivative(1), T(-24.0), tol));
  const J t1 = T(2.0) * x + T(1.0) - x / T(4.0), t2 = T(1.0) / y, t3 = T(1.0) - y;
  EXPECT_TRUE(close_rel(t1.derivative(1), T(3.5), tol));
  EXPECT_TRUE(close_rel(t2.derivative(1), T(-4.0) / T(9.0), tol));
  EXPECT_TRUE(t3.derivative(0) == T(1.0));
  // compound operators, including the aliasing x op= x
  J m = x;
  m *= 4;
  m /= T(2.0);
  m += T(1.0);
  m -= J(T(1.0));
  m *= J(T(2.0));
  m /= J(T(4.0));
  m += 1;
  m -= 1.0;
  EXPECT_TRUE(close_rel(m.value(), x.value(), tol) && close_rel(m.derivative(1), x.derivative(1), tol));
  J s = x;
  s *= s;  // x^2: derivative 2 x dx
  EXPECT_TRUE(s.value() == T(0.25) && s.derivative(1) == T(2.0));
  J r = x;
  const J& r_alias = r;  // the aliased operand through a reference (clang flags a literal r /= r)
  r /= r_alias;          // identically 1
  EXPECT_TRUE(r.value() == T(1.0) && r.derivative(0) == T(0.0) && r.derivative(1) == T(0.0));
  J u = x;
  u += u;
  EXPECT_TRUE(u.value() == T(1.0) && u.derivative(1) == T(4.0));
  const J& u_alias = u;
  u -= u_alias;
  EXPECT_TRUE(u.value() == T(0.0) && u.derivative(1) == T(0.0));
  const J n = -x;
  EXPECT_TRUE(n.value() == T(-0.5) && n.derivative(1) == T(-2.0) && (+x).derivative(1) == T(2.0));
}

TYPED_TEST(JetTyped, ComparisonsLookAtTheValueOnly) {
  using T = TypeParam;
  using J = jet<T, 2>;
  const J a = J::variable(T(1.0), 0), b = J::variable(T(1.0), 1), c = J(T(2.0));
  EXPECT_TRUE(a == b && !(a != b) && a <= b && a >= b && !(a < b) && !(a > b));
  EXPECT_TRUE(a < c && c > a && a != c);
  EXPECT_TRUE(a < 2 && 2 > a && a <= 1.0 && 1.0 >= a && a == 1 && 1 == a && a != 3 && 0.5 < a && 0 <= a && a > 0);
  EXPECT_TRUE(a < T(1.5) && T(1.5) > a && a == T(1.0) && T(0.5) <= a);
}

// ---------------------------------------------------------------- elementary functions

// f(x0 + sum d_k eps_k) = f(x0) + f'(x0) sum d_k eps_k for each function, closed form in T.
TYPED_TEST(JetTyped, ElementaryFunctionsMatchClosedFormDerivatives) {
  using T = TypeParam;
  using J = jet<T, 3>;
  const T tol = T(16.0) * unit_roundoff<T>();
  const std::array<T, 3> dir = {T(1.0), T(-2.0), T(0.375)};
  using std::acos;
  using std::asin;
  using std::atan;
  using std::cos;
  using std::cosh;
  using std::exp;
  using std::log;
  using std::pow;
  using std::sin;
  using std::sinh;
  using std::sqrt;
  using std::tan;
  using std::tanh;
  struct fn {
    const char* name;
    std::function<J(const J&)> f;
    std::function<T(const T&)> value, derivative;
  };
  const T x0 = T(3.0) / T(10.0);
  const T ln2 = log(T(2.0));
  const std::vector<fn> fns = {
      {"sqrt", [](const J& x) { return sqrt(x); }, [](const T& x) { return sqrt(x); },
       [](const T& x) { return T(0.5) / sqrt(x); }},
      {"exp", [](const J& x) { return exp(x); }, [](const T& x) { return exp(x); }, [](const T& x) { return exp(x); }},
      {"log", [](const J& x) { return log(x); }, [](const T& x) { return log(x); },
       [](const T& x) { return T(1.0) / x; }},
      {"sin", [](const J& x) { return sin(x); }, [](const T& x) { return sin(x); }, [](const T& x) { return cos(x); }},
      {"cos", [](const J& x) { return cos(x); }, [](const T& x) { return cos(x); }, [](const T& x) { return -sin(x); }},
      {"tan", [](const J& x) { return tan(x); }, [](const T& x) { return tan(x); },
       [](const T& x) { return T(1.0) / (cos(x) * cos(x)); }},
      {"asin", [](const J& x) { return asin(x); }, [](const T& x) { return asin(x); },
       [](const T& x) { return T(1.0) / sqrt(T(1.0) - x * x); }},
      {"acos", [](const J& x) { return acos(x); }, [](const T& x) { return acos(x); },
       [](const T& x) { return T(-1.0) / sqrt(T(1.0) - x * x); }},
      {"atan", [](const J& x) { return atan(x); }, [](const T& x) { return atan(x); },
       [](const T& x) { return T(1.0) / (T(1.0) + x * x); }},
      {"sinh", [](const J& x) { return sinh(x); }, [](const T& x) { return sinh(x); },
       [](const T& x) { return cosh(x); }},
      {"cosh", [](const J& x) { return cosh(x); }, [](const T& x) { return cosh(x); },
       [](const T& x) { return sinh(x); }},
      {"tanh", [](const J& x) { return tanh(x); }, [](const T& x) { return tanh(x); },
       [](const T& x) { return T(1.0) / (cosh(x) * cosh(x)); }},
      {"pow 2.5", [](const J& x) { return pow(x, T(2.5)); }, [](const T& x) { return exp(T(2.5) * log(x)); },
       [](const T& x) { return T(2.5) * exp(T(1.5) * log(x)); }},
      {"pow double -0.75", [](const J& x) { return pow(x, -0.75); }, [](const T& x) { return exp(T(-0.75) * log(x)); },
       [](const T& x) { return T(-0.75) * exp(T(-1.75) * log(x)); }},
      {"pow int 3", [](const J& x) { return pow(x, 3); }, [](const T& x) { return x * x * x; },
       [](const T& x) { return T(3.0) * x * x; }},
      {"pow int -2", [](const J& x) { return pow(x, -2); }, [](const T& x) { return T(1.0) / (x * x); },
       [](const T& x) { return T(-2.0) / (x * x * x); }},
      {"pow int 0", [](const J& x) { return pow(x, 0); }, [](const T&) { return T(1.0); },
       [](const T&) { return T(0.0); }},
      {"pow integral T 4", [](const J& x) { return pow(x, T(4.0)); }, [](const T& x) { return x * x * x * x; },
       [](const T& x) { return T(4.0) * x * x * x; }},
      {"2^x", [](const J& x) { return pow(T(2.0), x); }, [ln2](const T& x) { return exp(x * ln2); },
       [ln2](const T& x) { return ln2 * exp(x * ln2); }},
      {"x^x", [](const J& x) { return pow(x, x); }, [](const T& x) { return exp(x * log(x)); },
       [](const T& x) { return exp(x * log(x)) * (log(x) + T(1.0)); }},
      {"abs", [](const J& x) { return abs(x); }, [](const T& x) { return x; }, [](const T&) { return T(1.0); }},
      {"abs of -x", [](const J& x) { return fabs(-x); }, [](const T& x) { return x; }, [](const T&) { return T(1.0); }},
      {"hypot(x, 1 - x)", [](const J& x) { return hypot(x, 1 - x); },
       [](const T& x) { return sqrt(x * x + (T(1.0) - x) * (T(1.0) - x)); },
       [](const T& x) { return (T(2.0) * x - T(1.0)) / sqrt(x * x + (T(1.0) - x) * (T(1.0) - x)); }},
  };
  const J x = J::variable(x0, dir);
  for (const auto& f : fns) {
    const J y = f.f(x);
    EXPECT_TRUE(close_rel(y.value(), f.value(x0), tol)) << f.name;
    const T fp = f.derivative(x0);
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(close_rel(y.derivative(k), fp * dir[k], tol, 1e-300)) << f.name << " k " << k;
  }
  // atan2 in all four quadrants: d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
  for (const auto& [xv, yv] : std::array<std::pair<double, double>, 4>{{{0.5, 0.25}, {-0.5, 0.25}, {-0.5, -0.75}, {2.0, -1.0}}}) {
    const J xx = J::variable(T(xv), {T(1.0), T(0.0), T(2.0)});
    const J yy = J::variable(T(yv), {T(0.0), T(1.0), T(-1.0)});
    const J a = atan2(yy, xx);
    using std::atan2;
    EXPECT_TRUE(close_rel(a.value(), atan2(T(yv), T(xv)), tol));
    const T r2 = T(xv) * T(xv) + T(yv) * T(yv);
    for (int k = 0; k < 3; ++k) {
      const T want = (T(xv) * yy.derivative(k) - T(yv) * xx.derivative(k)) / r2;
      EXPECT_TRUE(close_rel(a.derivative(k), want, tol, 1e-300)) << xv << " " << yv << " k " << k;
    }
  }
}

// Integer powers of a negative base take the multiplication path (a real pow would be NaN).
TYPED_TEST(JetTyped, IntegerPowersOfNegativeBase) {
  using T = TypeParam;
  using J = jet<T, 2>;
  const J x = J::variable(T(-1.5), {T(1.0), T(2.0)});
  const J c = pow(x, 3), d = pow(x, T(3.0)), e = pow(x, -1), f = pow(x, 2.0);
  const T tol = T(8.0) * unit_roundoff<T>();
  EXPECT_TRUE(close_rel(c.value(), T(-3.375), tol) && close_rel(c.derivative(1), T(2.0) * T(3.0) * T(2.25), tol));
  EXPECT_TRUE(close_rel(d.derivative(0), T(6.75), tol));
  EXPECT_TRUE(close_rel(e.value(), T(-2.0) / T(3.0), tol) && close_rel(e.derivative(0), T(-1.0) / T(2.25), tol));
  EXPECT_TRUE(close_rel(f.value(), T(2.25), tol) && close_rel(f.derivative(1), T(-6.0), tol));
}

// ---------------------------------------------------------------- composition

template <class S>
S power15(const S& y) {
  if constexpr (aerohopf::is_jet_v<S>) {
    return pow(y, 1.5);
  } else {
    using std::exp;
    using std::log;
    return exp(S(1.5) * log(y));  // not pow: QD's pow(qd_real, 1.5) would round the exponent
  }
}

// A reactor/flux-like function of three variables with every kind of operation the residuals
// use (exp/log/sqrt, quotients, branches on the value, min/max).
template <class S>
S kitchen_sink(const S& x, const S& y, const S& z) {
  using std::atan2;
  using std::cos;
  using std::exp;
  using std::log;
  using std::max;
  using std::min;
  using std::sin;
  using std::sqrt;
  using std::tanh;
  const S one(1.0), two(2.0);
  S r = exp(x * y) / sqrt(one + z * z) + log(two + sin(x)) * power15(y) - atan2(z, x) + tanh(y - z) * cos(z);
  const S lim = x < y ? S(x * z) : S(y * z);  // a value branch
  r += max(lim, S(-1.0)) - min(x * x, y) / (one + exp(two * z));
  return r;
}

TEST(JetComposition, MatchesCentralDifferencesInQd) {
  // reference: 2nd-order central differences in qd_real with h = 1e-12, truncation ~1e-24,
  // rounding ~1e-52: far below the double and dd roundoff of the jets.
  const std::array<double, 3> p = {0.4, 0.7, -0.3};
  const qd_real h(1e-12);
  std::array<qd_real, 3> ref;
  for (int k = 0; k < 3; ++k) {
    std::array<qd_real, 3> pp, pm;
    for (int i = 0; i < 3; ++i) pp[i] = pm[i] = qd_real(p[i]);
    pp[k] += h;
    pm[k] -= h;
    ref[k] = (kitchen_sink(pp[0], pp[1], pp[2]) - kitchen_sink(pm[0], pm[1], pm[2])) / (qd_real(2.0) * h);
  }
  {
    using J = jet<double, 3>;
    const J r = kitchen_sink(J::variable(p[0], 0), J::variable(p[1], 1), J::variable(p[2], 2));
    EXPECT_NEAR(r.value(), to_double(kitchen_sink(qd_real(p[0]), qd_real(p[1]), qd_real(p[2]))), 1e-15);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.derivative(k), to_double(ref[k]), 1e-14 * std::abs(to_double(ref[k]))) << k;
  }
  {
    using J = jet<dd_real, 3>;
    const J r = kitchen_sink(J::variable(dd_real(p[0]), 0), J::variable(dd_real(p[1]), 1), J::variable(dd_real(p[2]), 2));
    for (int k = 0; k < 3; ++k) {
      const qd_real err = abs(qd_real(r.derivative(k).x[0]) + qd_real(r.derivative(k).x[1]) - ref[k]);
      EXPECT_LT(to_double(err), 1e-22 * std::abs(to_double(ref[k]))) << k;  // double-rounded constants give 1e-17
    }
  }
}

// Per direction, the jet is exactly what taylor<T, 1> computes one direction at a time.
TYPED_TEST(JetTyped, AgreesWithTaylorPerDirection) {
  using T = TypeParam;
  using J = jet<T, 4>;
  using K = taylor<T, 1>;
  const std::array<T, 3> p = {T(0.4), T(0.7), T(-0.3)};
  // four directions in the 3 variables (one of them a combination)
  const std::array<std::array<T, 3>, 4> v = {{{T(1.0), T(0.0), T(0.0)},
                                              {T(0.0), T(1.0), T(0.0)},
                                              {T(0.25), T(-0.5), T(2.0)},
                                              {T(0.0), T(0.0), T(0.0)}}};
  std::array<J, 3> xj;
  for (int i = 0; i < 3; ++i) xj[i] = J::variable(p[i], {v[0][i], v[1][i], v[2][i], v[3][i]});
  const J r = kitchen_sink(xj[0], xj[1], xj[2]);
  for (int k = 0; k < 4; ++k) {
    const K t = kitchen_sink(K::variable(p[0], v[k][0]), K::variable(p[1], v[k][1]), K::variable(p[2], v[k][2]));
    EXPECT_TRUE(close_rel(r.value(), t[0], T(4.0) * unit_roundoff<T>()));
    EXPECT_TRUE(close_rel(r.derivative(k), t[1], T(64.0) * unit_roundoff<T>(), 1e-300)) << k;
  }
  EXPECT_TRUE(r.derivative(3) == T(0.0));
}

// Non-smooth points: the jet gives per direction what taylor<T, 1> gives.
TYPED_TEST(JetTyped, NonSmoothPointsFollowTaylorPerDirection) {
  using T = TypeParam;
  using J = jet<T, 3>;
  using K = taylor<T, 1>;
  const std::array<T, 3> d = {T(2.0), T(-3.0), T(0.0)};
  const J x0 = J::variable(T(0.0), d);
  const J a = abs(x0), s = sqrt(x0 * x0), z = sqrt(J(T(0.0)));
  for (int k = 0; k < 3; ++k) {
    const K t = K::variable(T(0.0), d[k]);
    EXPECT_TRUE(a.derivative(k) == abs(t)[1]) << k;  // |d_k|
    EXPECT_TRUE(z.derivative(k) == T(0.0));
  }
  EXPECT_TRUE(a.derivative(0) == T(2.0) && a.derivative(1) == T(3.0) && a.derivative(2) == T(0.0));
  // sqrt(x^2) at 0 has value 0 and derivatives 0 (x^2 has zero derivatives there)
  EXPECT_TRUE(s.value() == T(0.0) && s.derivative(0) == T(0.0));
  // sqrt(x) at 0 along a non-zero direction: d / 0, not finite (+-inf in double; QD's division
  // by zero gives NaN), exactly as taylor<T, 1>; 0 along the zero direction
  using std::isfinite;
  using std::isinf;
  const J r = sqrt(x0);
  for (int k = 0; k < 2; ++k) {
    EXPECT_FALSE(isfinite(r.derivative(k))) << k;
    EXPECT_FALSE(isfinite(sqrt(K::variable(T(0.0), d[k]))[1])) << k;
  }
  if constexpr (std::is_same_v<T, double>) {
    EXPECT_TRUE(isinf(r.derivative(0)) && r.derivative(0) > 0.0);
    EXPECT_TRUE(isinf(r.derivative(1)) && r.derivative(1) < 0.0);
    EXPECT_TRUE(isinf(r) && !isnan(r));
  }
  EXPECT_TRUE(r.derivative(2) == T(0.0));
  EXPECT_TRUE(!isfinite(r));
  // min/max: the branch of the value; ties take the first argument, as taylor's
  const J u = J::variable(T(1.0), 0), w = J::variable(T(1.0), 1), big = J::variable(T(2.0), 2);
  EXPECT_TRUE(min(u, w).derivative(0) == T(1.0) && max(u, w).derivative(0) == T(1.0));
  EXPECT_TRUE(min(u, big).derivative(0) == T(1.0) && max(u, big).derivative(2) == T(1.0));
  EXPECT_TRUE(fmin(big, u).derivative(0) == T(1.0) && fmax(big, u).derivative(2) == T(1.0));
  EXPECT_TRUE(isnan(J(T(std::numeric_limits<double>::quiet_NaN()))));
  J nan_direction = u;
  nan_direction.derivative(1) = T(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(isnan(nan_direction) && !isfinite(nan_direction));
  EXPECT_TRUE(isfinite(u));
}

// ---------------------------------------------------------------- Eigen

TYPED_TEST(JetTyped, EigenNumTraitsAndIsApprox) {
  using T = TypeParam;
  using J = jet<T, 2>;
  EXPECT_TRUE(Eigen::NumTraits<J>::epsilon().value() == Eigen::NumTraits<T>::epsilon());
  EXPECT_TRUE(Eigen::NumTraits<J>::dummy_precision().value() == Eigen::NumTraits<T>::dummy_precision());
  EXPECT_GT(aerohopf::to_double(Eigen::NumTraits<J>::dummy_precision()), 0.0);
  Eigen::Matrix<J, 3, 1> a, b;
  for (int i = 0; i < 3; ++i) {
    a[i] = J::variable(T(1.0 + i), i % 2);
    b[i] = a[i] * (T(1.0) + T(0.1) * Eigen::NumTraits<T>::dummy_precision());
  }
  EXPECT_TRUE(a.isApprox(b));  // not exact equality
  EXPECT_FALSE(a.isApprox(Eigen::Matrix<J, 3, 1>(a * T(1.001))));
  // norm: sqrt(1 + 4 + 9) with derivatives (x . dx) / |x|
  const J n = a.norm();
  using std::sqrt;
  const T n0 = sqrt(T(14.0));
  const T tol = T(8.0) * unit_roundoff<T>();
  EXPECT_TRUE(close_rel(n.value(), n0, tol));
  EXPECT_TRUE(close_rel(n.derivative(0), T(4.0) / n0, tol));  // entries 0 and 2 seed direction 0
  EXPECT_TRUE(close_rel(n.derivative(1), T(2.0) / n0, tol));
  const Eigen::Matrix<J, 3, 1> zero = Eigen::Matrix<J, 3, 1>::Zero();
  EXPECT_TRUE(zero.norm().value() == T(0.0) && zero.norm().derivative(0) == T(0.0));
  // mixed scalar products
  const Eigen::Matrix<J, 3, 1> c = a * T(2.0), e = T(2.0) * a, f = a * J(T(2.0));
  EXPECT_TRUE(c[2].derivative(0) == T(2.0) && e[1].derivative(1) == T(2.0) && f[0].value() == T(2.0));
}

// A(p, q) y = b with A = A0 + p A1 + q A2: dy/dp = -A^{-1} A1 y, dy/dq = -A^{-1} A2 y.
TYPED_TEST(JetTyped, DenseLuSolveGivesTheDerivativeOfTheSolution) {
  using T = TypeParam;
  using J = jet<T, 2>;
  using MT = Eigen::Matrix<T, 3, 3>;
  using VT = Eigen::Matrix<T, 3, 1>;
  MT a0, a1, a2;
  a0 << T(4.0), T(1.0), T(-1.0), T(2.0), T(5.0), T(1.0), T(0.0), T(1.0), T(3.0);
  a1 << T(1.0), T(0.0), T(2.0), T(0.0), T(-1.0), T(0.0), T(1.0), T(1.0), T(0.0);
  a2 << T(0.0), T(3.0), T(0.0), T(1.0), T(0.0), T(-2.0), T(0.0), T(0.0), T(1.0);
  VT b;
  b << T(1.0), T(-2.0), T(0.5);
  const T p = T(1.0) / T(3.0), q = T(-1.0) / T(7.0);
  const J pj = J::variable(p, 0), qj = J::variable(q, 1);
  Eigen::Matrix<J, 3, 3> aj;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) aj(i, j) = J(a0(i, j)) + pj * a1(i, j) + qj * a2(i, j);
  const Eigen::Matrix<J, 3, 1> yj = aj.partialPivLu().solve(b.template cast<J>());
  const MT a = a0 + p * a1 + q * a2;
  const Eigen::PartialPivLU<MT> lu(a);
  const VT y = lu.solve(b);
  const VT dyp = -lu.solve(VT(a1 * y)), dyq = -lu.solve(VT(a2 * y));
  const T tol = T(64.0) * unit_roundoff<T>();
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(close_rel(yj[i].value(), y[i], tol, 1.0)) << i;
    EXPECT_TRUE(close_rel(yj[i].derivative(0), dyp[i], tol, 1.0)) << i;
    EXPECT_TRUE(close_rel(yj[i].derivative(1), dyq[i], tol, 1.0)) << i;
  }
}

}  // namespace
