#pragma once
// taylor<T, K>: a truncated Taylor polynomial ("jet") scalar, x(t) = sum_{k=0..K} c_k t^k.
//
// Why: the centre-manifold reduction needs the derivative products A v, B(v, v) and
// C(v, v, v) of the residual f. Finite differences lose digits (a 3rd derivative keeps about
// six in double), which is why the original work evaluated the residual in double-double and
// quad-double. Because every aerohopf residual is a template over the scalar type, we can
// instead evaluate it once on the jet w0 + t v: the coefficients of t, t^2, t^3 of the result
// are A v, B(v, v)/2 and C(v, v, v)/6 EXACTLY (to rounding in T), with no step size at all.
//
// Arithmetic is the usual truncated power-series algebra (Griewank & Walther, "Evaluating
// Derivatives", ch. 13): products are Cauchy products, and every elementary function is
// propagated by the recurrence that follows from its differential equation (e.g. e = exp(a)
// satisfies e' = a' e, hence k e_k = sum_{j=1..k} j a_j e_{k-j}). Each recurrence costs
// O(K^2) operations in T. Integer factors are formed as T(double(k)), which is exact in every
// supported T, so dd_real / qd_real jets carry no double-rounded constants.
//
// Comparisons look at the value c_0 only, so branches in a residual (limiters, upwinding,
// min/max) follow the branch the plain evaluation takes and the jet differentiates that
// branch, exactly as a directional derivative of the piecewise-smooth function would.
//
// Usage (the whole public API):
//   using J = taylor<double, 3>;
//   J x = J::variable(x0, dx);          // x0 + dx t
//   J y = f(x);                         // any generic f: `using std::exp; exp(x)` finds
//                                       // aerohopf::exp by ADL, as do sqrt, log, pow, abs, ...
//   y[k] or y.value() == y[0];          // Taylor coefficient: d^k/dt^k f(x0 + dx t) / k!
//   y.derivative(k) == k! * y[k];
// Constants: jet * 2, 2.0 * jet, jet / 3, 1 - jet, jet < 0.5 work for every T; built-in constants
// go through double, which is exact. For T = dd_real / qd_real write non-dyadic constants as
// ratios in T (T(1.0) / T(3.0)), never as decimal double literals, or the residual is only
// double-accurate. Beware QD's own pow(qd_real, int): pow(x, 1.5) on a plain qd_real silently
// computes x^1; on jets the real exponent is kept.
// Eigen: Matrix<taylor<T, K>, ...> works (NumTraits below): arithmetic, norm, PartialPivLU,
// FullPivLU (tested with T = double), inverse; matrix * scalar works for scalars of type
// taylor<T, K> and T (not double when T is dd_real / qd_real).
// Non-smooth points: abs/min/max/comparisons follow the branch of the value (see above); sqrt,
// log and non-integer pow at value 0 give inf/NaN coefficients (an all-zero sqrt gives 0).
#include <Eigen/Core>

#include <array>
#include <cmath>
#include <concepts>
#include <ostream>
#include <type_traits>

#include "traits.hpp"

namespace aerohopf {

template <class T, int K>
class taylor {
  static_assert(K >= 1, "taylor<T, K> needs K >= 1");

 public:
  using value_type = T;
  static constexpr int order = K;

  taylor() { c_.fill(T(0.0)); }
  /// A constant (all higher coefficients zero).
  taylor(const T& v) {  // NOLINT(google-explicit-constructor): scalars must promote implicitly
    c_.fill(T(0.0));
    c_[0] = v;
  }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  taylor(U v) : taylor(T(static_cast<double>(v))) {}  // NOLINT(google-explicit-constructor)

  /// The independent variable x0 + dx t.
  static taylor variable(const T& x0, const T& dx = T(1.0)) {
    taylor r(x0);
    r.c_[1] = dx;
    return r;
  }

  const T& operator[](int k) const { return c_[k]; }
  T& operator[](int k) { return c_[k]; }
  const T& value() const { return c_[0]; }
  /// k-th derivative with respect to t at t = 0 (k! c_k).
  T derivative(int k) const {
    T r = c_[k];
    for (int j = 2; j <= k; ++j) r *= T(static_cast<double>(j));
    return r;
  }

  taylor& operator+=(const taylor& b) {
    for (int k = 0; k <= K; ++k) c_[k] += b.c_[k];
    return *this;
  }
  taylor& operator-=(const taylor& b) {
    for (int k = 0; k <= K; ++k) c_[k] -= b.c_[k];
    return *this;
  }
  taylor& operator*=(const taylor& b) { return *this = *this * b; }
  taylor& operator/=(const taylor& b) { return *this = *this / b; }
  taylor& operator+=(const T& b) {
    c_[0] += b;
    return *this;
  }
  taylor& operator-=(const T& b) {
    c_[0] -= b;
    return *this;
  }
  taylor& operator*=(const T& b) {
    for (auto& x : c_) x *= b;
    return *this;
  }
  taylor& operator/=(const T& b) {
    for (auto& x : c_) x /= b;
    return *this;
  }

  // Built-in constants (x *= 2 with T = dd_real would otherwise be ambiguous between the T and
  // taylor overloads); the constant goes through double, which is exact for every T.
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  taylor& operator+=(U b) { return *this += T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  taylor& operator-=(U b) { return *this -= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  taylor& operator*=(U b) { return *this *= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  taylor& operator/=(U b) { return *this /= T(static_cast<double>(b)); }

  taylor operator-() const {
    taylor r;
    for (int k = 0; k <= K; ++k) r.c_[k] = -c_[k];
    return r;
  }
  taylor operator+() const { return *this; }

  // ---- binary arithmetic (hidden friends: found by ADL, so Eigen expressions find them) ----
  friend taylor operator+(taylor a, const taylor& b) { return a += b; }
  friend taylor operator-(taylor a, const taylor& b) { return a -= b; }
  friend taylor operator*(const taylor& a, const taylor& b) {
    taylor r;
    for (int k = 0; k <= K; ++k) {
      T s = a.c_[0] * b.c_[k];
      for (int j = 1; j <= k; ++j) s += a.c_[j] * b.c_[k - j];
      r.c_[k] = s;
    }
    return r;
  }
  friend taylor operator/(const taylor& a, const taylor& b) {
    // c = a / b  <=>  b c = a:  c_k = (a_k - sum_{j=1..k} b_j c_{k-j}) / b_0
    taylor r;
    for (int k = 0; k <= K; ++k) {
      T s = a.c_[k];
      for (int j = 1; j <= k; ++j) s -= b.c_[j] * r.c_[k - j];
      r.c_[k] = s / b.c_[0];
    }
    return r;
  }
  friend taylor operator+(taylor a, const T& b) { return a += b; }
  friend taylor operator+(const T& a, taylor b) { return b += a; }
  friend taylor operator-(taylor a, const T& b) { return a -= b; }
  friend taylor operator-(const T& a, const taylor& b) {
    taylor r = -b;
    r.c_[0] += a;
    return r;
  }
  friend taylor operator*(taylor a, const T& b) { return a *= b; }
  friend taylor operator*(const T& a, taylor b) { return b *= a; }
  friend taylor operator/(taylor a, const T& b) { return a /= b; }
  friend taylor operator/(const T& a, const taylor& b) { return taylor(a) / b; }

  // Built-in arithmetic constants (2.0 * x, x / 3): exact matches beat the conversions above.
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator+(const taylor& a, U b) { return a + T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator+(U a, const taylor& b) { return T(static_cast<double>(a)) + b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator-(const taylor& a, U b) { return a - T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator-(U a, const taylor& b) { return T(static_cast<double>(a)) - b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator*(const taylor& a, U b) { return a * T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator*(U a, const taylor& b) { return T(static_cast<double>(a)) * b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator/(const taylor& a, U b) { return a / T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend taylor operator/(U a, const taylor& b) { return T(static_cast<double>(a)) / b; }

  // ---- comparisons: by value (c_0) ----
  friend bool operator==(const taylor& a, const taylor& b) { return a.c_[0] == b.c_[0]; }
  friend bool operator!=(const taylor& a, const taylor& b) { return a.c_[0] != b.c_[0]; }
  friend bool operator<(const taylor& a, const taylor& b) { return a.c_[0] < b.c_[0]; }
  friend bool operator<=(const taylor& a, const taylor& b) { return a.c_[0] <= b.c_[0]; }
  friend bool operator>(const taylor& a, const taylor& b) { return a.c_[0] > b.c_[0]; }
  friend bool operator>=(const taylor& a, const taylor& b) { return a.c_[0] >= b.c_[0]; }
  friend bool operator==(const taylor& a, const T& b) { return a.c_[0] == b; }
  friend bool operator!=(const taylor& a, const T& b) { return a.c_[0] != b; }
  friend bool operator<(const taylor& a, const T& b) { return a.c_[0] < b; }
  friend bool operator<=(const taylor& a, const T& b) { return a.c_[0] <= b; }
  friend bool operator>(const taylor& a, const T& b) { return a.c_[0] > b; }
  friend bool operator>=(const taylor& a, const T& b) { return a.c_[0] >= b; }
  friend bool operator==(const T& a, const taylor& b) { return a == b.c_[0]; }
  friend bool operator!=(const T& a, const taylor& b) { return a != b.c_[0]; }
  friend bool operator<(const T& a, const taylor& b) { return a < b.c_[0]; }
  friend bool operator<=(const T& a, const taylor& b) { return a <= b.c_[0]; }
  friend bool operator>(const T& a, const taylor& b) { return a > b.c_[0]; }
  friend bool operator>=(const T& a, const taylor& b) { return a >= b.c_[0]; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<(const taylor& a, U b) { return a.c_[0] < T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>(const taylor& a, U b) { return a.c_[0] > T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<=(const taylor& a, U b) { return a.c_[0] <= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>=(const taylor& a, U b) { return a.c_[0] >= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator==(const taylor& a, U b) { return a.c_[0] == T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator!=(const taylor& a, U b) { return a.c_[0] != T(static_cast<double>(b)); }

  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<(U a, const taylor& b) { return T(static_cast<double>(a)) < b.c_[0]; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>(U a, const taylor& b) { return T(static_cast<double>(a)) > b.c_[0]; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<=(U a, const taylor& b) { return T(static_cast<double>(a)) <= b.c_[0]; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>=(U a, const taylor& b) { return T(static_cast<double>(a)) >= b.c_[0]; }

  friend std::ostream& operator<<(std::ostream& os, const taylor& a) {
    os << "[";
    for (int k = 0; k <= K; ++k) os << (k ? ", " : "") << a.c_[k];
    return os << "]";
  }

 private:
  std::array<T, K + 1> c_;
};

namespace internal {
template <class T>
T kconst(int k) { return T(static_cast<double>(k)); }

/// t-derivative series of a: (a')_k = (k+1) a_{k+1}; the top coefficient is unknown (0).
template <class T, int K>
taylor<T, K> t_derivative(const taylor<T, K>& a) {
  taylor<T, K> d;
  for (int k = 0; k < K; ++k) d[k] = a[k + 1] * kconst<T>(k + 1);
  return d;
}
/// r with r_0 = r0 and r' = d (d's top coefficient is not used).
template <class T, int K>
taylor<T, K> t_integral(const T& r0, const taylor<T, K>& d) {
  taylor<T, K> r(r0);
  for (int k = 1; k <= K; ++k) r[k] = d[k - 1] / kconst<T>(k);
  return r;
}
}  // namespace internal

template <class T>
struct is_taylor : std::false_type {};
template <class T, int K>
struct is_taylor<taylor<T, K>> : std::true_type {};
template <class T>
inline constexpr bool is_taylor_v = is_taylor<T>::value;

template <class T, int K>
struct scalar_traits<taylor<T, K>> {
  static constexpr std::string_view name() { return "taylor"; }
  static constexpr double epsilon() { return scalar_traits<T>::epsilon(); }
  static constexpr int digits10 = scalar_traits<T>::digits10;
  static double to_double(const taylor<T, K>& x) { return scalar_traits<T>::to_double(x.value()); }
};

// ---- elementary functions (found by ADL from generic code that writes `using std::exp;`) ----

template <class T, int K>
taylor<T, K> sqrt(const taylor<T, K>& a) {
  using std::sqrt;
  taylor<T, K> s;
  if (a[0] == T(0.0)) {
    // sqrt of an identically zero jet (e.g. the norm of a zero vector) is zero; otherwise the
    // square root is not differentiable at 0 and the recurrence below yields inf/NaN.
    bool all_zero = true;
    for (int k = 1; k <= K; ++k) all_zero = all_zero && a[k] == T(0.0);
    if (all_zero) return s;
  }
  s[0] = sqrt(a[0]);
  const T two_s0 = s[0] + s[0];
  for (int k = 1; k <= K; ++k) {
    T acc = a[k];
    for (int j = 1; j < k; ++j) acc -= s[j] * s[k - j];
    s[k] = acc / two_s0;
  }
  return s;
}

template <class T, int K>
taylor<T, K> exp(const taylor<T, K>& a) {
  using std::exp;
  taylor<T, K> e;
  e[0] = exp(a[0]);
  for (int k = 1; k <= K; ++k) {
    T acc = T(0.0);
    for (int j = 1; j <= k; ++j) acc += internal::kconst<T>(j) * a[j] * e[k - j];
    e[k] = acc / internal::kconst<T>(k);
  }
  return e;
}

template <class T, int K>
taylor<T, K> log(const taylor<T, K>& a) {
  using std::log;
  taylor<T, K> l;
  l[0] = log(a[0]);
  for (int k = 1; k <= K; ++k) {
    // a l' = a'  =>  l_k = (a_k - (1/k) sum_{j=1..k-1} j l_j a_{k-j}) / a_0
    T acc = T(0.0);
    for (int j = 1; j < k; ++j) acc += internal::kconst<T>(j) * l[j] * a[k - j];
    l[k] = (a[k] - acc / internal::kconst<T>(k)) / a[0];
  }
  return l;
}

template <class T, int K>
taylor<T, K> pow(const taylor<T, K>& a, int n);

/// a^r for a real exponent r; a_0 must be positive unless r is an integer. Integer r (|r| <= 64)
/// takes the repeated-multiplication path, so negative and zero bases work there.
template <class T, int K>
taylor<T, K> pow(const taylor<T, K>& a, const T& r) {
  using std::abs;
  using std::floor;
  using std::pow;
  if (floor(r) == r && abs(r) <= T(64.0)) return pow(a, static_cast<int>(aerohopf::to_double(r)));
  taylor<T, K> p;
  p[0] = pow(a[0], r);
  for (int k = 1; k <= K; ++k) {
    // a p' = r a' p  =>  k a_0 p_k = sum_{j=1..k} (r j - (k - j)) a_j p_{k-j}
    T acc = T(0.0);
    for (int j = 1; j <= k; ++j)
      acc += (r * internal::kconst<T>(j) - internal::kconst<T>(k - j)) * a[j] * p[k - j];
    p[k] = acc / (internal::kconst<T>(k) * a[0]);
  }
  return p;
}

template <class T, int K>
taylor<T, K> pow(const taylor<T, K>& a, int n) {
  if (n < 0) return taylor<T, K>(T(1.0)) / pow(a, -n);
  taylor<T, K> result(T(1.0)), base = a;
  while (n > 0) {
    if (n & 1) result = result * base;
    n >>= 1;
    if (n > 0) base = base * base;
  }
  return result;
}

template <class T, int K, class U>
  requires(std::is_floating_point_v<U> && !std::is_same_v<U, T>)
taylor<T, K> pow(const taylor<T, K>& a, U r) {
  return pow(a, T(static_cast<double>(r)));
}

template <class T, int K>
taylor<T, K> pow(const taylor<T, K>& a, const taylor<T, K>& b) {
  return exp(b * log(a));
}

template <class T, int K>
taylor<T, K> abs(const taylor<T, K>& a) {
  // Sign of the first non-zero coefficient: |a| is smooth wherever a(t) does not change sign.
  for (int k = 0; k <= K; ++k) {
    if (a[k] > T(0.0)) return a;
    if (a[k] < T(0.0)) return -a;
  }
  return a;
}
template <class T, int K>
taylor<T, K> fabs(const taylor<T, K>& a) { return abs(a); }

template <class T, int K>
void sincos(const taylor<T, K>& a, taylor<T, K>& s, taylor<T, K>& c) {
  using std::cos;
  using std::sin;
  s[0] = sin(a[0]);
  c[0] = cos(a[0]);
  for (int k = 1; k <= K; ++k) {
    // s' = c a', c' = -s a'
    T as = T(0.0), ac = T(0.0);
    for (int j = 1; j <= k; ++j) {
      as += internal::kconst<T>(j) * a[j] * c[k - j];
      ac += internal::kconst<T>(j) * a[j] * s[k - j];
    }
    s[k] = as / internal::kconst<T>(k);
    c[k] = -ac / internal::kconst<T>(k);
  }
}
template <class T, int K>
taylor<T, K> sin(const taylor<T, K>& a) {
  taylor<T, K> s, c;
  sincos(a, s, c);
  return s;
}
template <class T, int K>
taylor<T, K> cos(const taylor<T, K>& a) {
  taylor<T, K> s, c;
  sincos(a, s, c);
  return c;
}
template <class T, int K>
taylor<T, K> tan(const taylor<T, K>& a) {
  taylor<T, K> s, c;
  sincos(a, s, c);
  return s / c;
}
template <class T, int K>
taylor<T, K> atan(const taylor<T, K>& a) {
  using std::atan;
  return internal::t_integral(T(atan(a[0])), internal::t_derivative(a) / (T(1.0) + a * a));
}
template <class T, int K>
taylor<T, K> atan2(const taylor<T, K>& y, const taylor<T, K>& x) {
  using std::atan2;
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
  const auto d = (x * internal::t_derivative(y) - y * internal::t_derivative(x)) / (x * x + y * y);
  return internal::t_integral(T(atan2(y[0], x[0])), d);
}
template <class T, int K>
taylor<T, K> tanh(const taylor<T, K>& a) {
  using std::cosh;
  using std::tanh;
  // th' = u a' with u = 1 - th^2. Not (e^{2a} - 1)/(e^{2a} + 1), which overflows to NaN for
  // large |a|; u_0 = sech^2(a_0) avoids the cancellation in 1 - th_0^2 when |th_0| ~ 1.
  taylor<T, K> th, u;
  th[0] = tanh(a[0]);
  const T sech = T(1.0) / cosh(a[0]);
  u[0] = sech * sech;
  for (int k = 1; k <= K; ++k) {
    if (k >= 2) {  // u_{k-1} = -sum_{i=0..k-1} th_i th_{k-1-i}
      T acc = T(0.0);
      for (int i = 0; i <= k - 1; ++i) acc += th[i] * th[k - 1 - i];
      u[k - 1] = -acc;
    }
    T acc = T(0.0);
    for (int j = 1; j <= k; ++j) acc += internal::kconst<T>(j) * a[j] * u[k - j];
    th[k] = acc / internal::kconst<T>(k);
  }
  return th;
}

// By value (not std::min's reference), so min(x * x, y) cannot leave a dangling reference.
template <class T, int K>
taylor<T, K> min(const taylor<T, K>& a, const taylor<T, K>& b) { return b < a ? b : a; }
template <class T, int K>
taylor<T, K> max(const taylor<T, K>& a, const taylor<T, K>& b) { return a < b ? b : a; }
template <class T, int K>
taylor<T, K> fmin(const taylor<T, K>& a, const taylor<T, K>& b) { return min(a, b); }
template <class T, int K>
taylor<T, K> fmax(const taylor<T, K>& a, const taylor<T, K>& b) { return max(a, b); }

template <class T, int K>
bool isfinite(const taylor<T, K>& a) {
  using std::isfinite;
  for (int k = 0; k <= K; ++k)
    if (!isfinite(a[k])) return false;
  return true;
}
template <class T, int K>
bool isnan(const taylor<T, K>& a) {
  using std::isnan;
  for (int k = 0; k <= K; ++k)
    if (isnan(a[k])) return true;
  return false;
}
template <class T, int K>
bool isinf(const taylor<T, K>& a) {
  return !isfinite(a) && !isnan(a);
}

// Eigen's generic code calls real/imag/conj/abs2 on scalars.
template <class T, int K>
const taylor<T, K>& real(const taylor<T, K>& a) { return a; }
template <class T, int K>
taylor<T, K> imag(const taylor<T, K>&) { return taylor<T, K>(); }
template <class T, int K>
const taylor<T, K>& conj(const taylor<T, K>& a) { return a; }
template <class T, int K>
taylor<T, K> abs2(const taylor<T, K>& a) { return a * a; }

}  // namespace aerohopf

namespace Eigen {

template <class T, int K>
struct NumTraits<aerohopf::taylor<T, K>> : GenericNumTraits<aerohopf::taylor<T, K>> {
  using Self = aerohopf::taylor<T, K>;
  using Real = Self;
  using NonInteger = Self;
  using Literal = Self;
  using Nested = Self;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (K + 1) * NumTraits<T>::ReadCost,
    AddCost = (K + 1) * NumTraits<T>::AddCost,
    MulCost = (K + 1) * (K + 2) / 2 * (NumTraits<T>::MulCost + NumTraits<T>::AddCost),
  };
  static inline Self epsilon() { return Self(NumTraits<T>::epsilon()); }
  static inline Self dummy_precision() { return Self(NumTraits<T>::dummy_precision()); }
  static inline Self highest() { return Self(NumTraits<T>::highest()); }
  static inline Self lowest() { return Self(NumTraits<T>::lowest()); }
  static inline Self infinity() { return Self(NumTraits<T>::infinity()); }
  static inline Self quiet_NaN() { return Self(NumTraits<T>::quiet_NaN()); }
  static inline int digits10() { return NumTraits<T>::digits10(); }
  static inline int digits() { return NumTraits<T>::digits(); }
};

template <class T, int K, class BinaryOp>
struct ScalarBinaryOpTraits<aerohopf::taylor<T, K>, T, BinaryOp> {
  using ReturnType = aerohopf::taylor<T, K>;
};
template <class T, int K, class BinaryOp>
struct ScalarBinaryOpTraits<T, aerohopf::taylor<T, K>, BinaryOp> {
  using ReturnType = aerohopf::taylor<T, K>;
};

}  // namespace Eigen
