#pragma once
// jet<T, N>: a first-order multi-direction jet, x = v + sum_{k<N} d_k eps_k with eps_j eps_k = 0.
//
// Why (and why not taylor<T, 1> N times): the structural columns of the aerofoil Jacobian
// (A_fs) need the derivative of the WHOLE residual (moved grid, metrics, Euler fluxes, loads)
// along each of the N structural unknowns. taylor<T, 1> carries one direction, so N passes
// repeat every value computation (the exp/log/sqrt of each Osher flux) N times; a jet carries
// all N directional derivatives of one pass, so the values are computed once and every
// derivative costs one multiply-add per direction. This is forward-mode AD in the sense of
// Ceres' Jet (Griewank & Walther, "Evaluating Derivatives", ch. 3): an elementary function g
// maps (v, d) to (g(v), g'(v) d), a product to (a b, a_v d_b + b_v d_a).
//
// Only first derivatives: for the 2nd and 3rd derivative products of the centre-manifold
// reduction use taylor<T, K> (one direction, high order).
// Comparisons look at the value only, so branches (limiters, upwinding, min/max) follow the
// plain evaluation and the jet differentiates that branch, as taylor<> does. Per direction k,
// the derivatives are exactly what taylor<T, 1>::variable(x0, v_k) would give, including at
// non-smooth points: abs at value 0 gives the one-sided directional derivative |d_k| in every
// direction (taylor's "sign of the first non-zero coefficient"), and sqrt of value 0 gives
// derivative 0 in a direction with d_k = 0 (and d_k / 0, +-inf in double, elsewhere), as taylor.
//
// Usage (the whole public API):
//   using J = jet<double, 4>;
//   J x = J::variable(x0, k);           // x0 + eps_k (direction k of N seeded with 1)
//   J y = J::variable(y0, {dy_0, ..});  // y0 + sum dy_k eps_k
//   J z = f(x, y);                      // any generic f: `using std::exp; exp(x)` finds
//                                       // aerohopf::exp by ADL, as do sqrt, log, pow, abs, ...
//   z.value(); z.derivative(k);         // f and its derivative along direction k
//   z.derivatives();                    // std::array<T, N> of all of them
//   x.chain(g(v), g'(v));               // a user-supplied elementary function g of x
// Constants: jet * 2, 2.0 * jet, jet / 3, 1 - jet, jet < 0.5 work for every T; built-in constants
// go through double, which is exact. For T = dd_real write non-dyadic constants as ratios in T
// (T(1.0) / T(3.0)), never as decimal double literals, or the result is only double-accurate.
// Storage is std::array: no allocation, N fixed at compile time.
// Eigen: Matrix<jet<T, N>, ...> works (NumTraits below, dummy_precision in T's precision so that
// isApprox is not exact equality); matrix * scalar works for scalars of type jet<T, N> and T.
#include <Eigen/Core>

#include <array>
#include <cmath>
#include <concepts>
#include <ostream>
#include <type_traits>

#include "traits.hpp"

namespace aerohopf {

template <class T, int N>
class jet {
  static_assert(N >= 1, "jet<T, N> needs N >= 1 directions");

 public:
  using value_type = T;
  static constexpr int directions = N;

  jet() : v_(T(0.0)) { d_.fill(T(0.0)); }
  /// A constant (all derivatives zero).
  jet(const T& v) : v_(v) { d_.fill(T(0.0)); }  // NOLINT(google-explicit-constructor): scalars promote
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  jet(U v) : jet(T(static_cast<double>(v))) {}  // NOLINT(google-explicit-constructor)
  jet(const T& v, const std::array<T, N>& d) : d_(d), v_(v) {}

  /// x0 + eps_k: the independent variable along direction k (0 <= k < N).
  static jet variable(const T& x0, int k) {
    jet r(x0);
    r.d_[static_cast<std::size_t>(k)] = T(1.0);
    return r;
  }
  // variable(x0, 1.0) would silently seed direction 1: a real second argument is an error.
  template <class U>
    requires std::is_floating_point_v<U>
  static jet variable(const T& x0, U) = delete;
  /// x0 + sum_k dx_k eps_k.
  static jet variable(const T& x0, const std::array<T, N>& dx) { return jet(x0, dx); }

  const T& value() const { return v_; }
  T& value() { return v_; }
  const T& derivative(int k) const { return d_[static_cast<std::size_t>(k)]; }
  T& derivative(int k) { return d_[static_cast<std::size_t>(k)]; }
  const std::array<T, N>& derivatives() const { return d_; }
  std::array<T, N>& derivatives() { return d_; }

  /// g(*this) for g with value gv = g(v) and derivative dg = g'(v): the chain rule.
  jet chain(const T& gv, const T& dg) const {
    jet r(gv);
    for (int k = 0; k < N; ++k) r.d_[k] = dg * d_[k];
    return r;
  }

  jet& operator+=(const jet& b) {
    v_ += b.v_;
    for (int k = 0; k < N; ++k) d_[k] += b.d_[k];
    return *this;
  }
  jet& operator-=(const jet& b) {
    v_ -= b.v_;
    for (int k = 0; k < N; ++k) d_[k] -= b.d_[k];
    return *this;
  }
  // b may be *this (x *= x): the values are read before any member is written.
  jet& operator*=(const jet& b) {
    const T av = v_, bv = b.v_;
    for (int k = 0; k < N; ++k) d_[k] = av * b.d_[k] + bv * d_[k];
    v_ = av * bv;
    return *this;
  }
  jet& operator/=(const jet& b) {
    // (a / b)' = (a' - (a / b) b') / b; one division, N multiplications by 1 / b
    const T q = v_ / b.v_, inv = T(1.0) / b.v_;
    for (int k = 0; k < N; ++k) d_[k] = (d_[k] - q * b.d_[k]) * inv;
    v_ = q;
    return *this;
  }
  jet& operator+=(const T& b) {
    v_ += b;
    return *this;
  }
  jet& operator-=(const T& b) {
    v_ -= b;
    return *this;
  }
  jet& operator*=(const T& b) {
    v_ *= b;
    for (auto& x : d_) x *= b;
    return *this;
  }
  jet& operator/=(const T& b) {
    v_ /= b;
    for (auto& x : d_) x /= b;
    return *this;
  }

  // Built-in constants (x *= 2 with T = dd_real would otherwise be ambiguous between the T and
  // jet overloads); the constant goes through double, which is exact for every T.
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  jet& operator+=(U b) { return *this += T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  jet& operator-=(U b) { return *this -= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  jet& operator*=(U b) { return *this *= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  jet& operator/=(U b) { return *this /= T(static_cast<double>(b)); }

  jet operator-() const {
    jet r(-v_);
    for (int k = 0; k < N; ++k) r.d_[k] = -d_[k];
    return r;
  }
  jet operator+() const { return *this; }

  // ---- binary arithmetic (hidden friends: found by ADL, so Eigen expressions find them) ----
  friend jet operator+(jet a, const jet& b) { return a += b; }
  friend jet operator-(jet a, const jet& b) { return a -= b; }
  friend jet operator*(jet a, const jet& b) { return a *= b; }
  friend jet operator/(jet a, const jet& b) { return a /= b; }
  friend jet operator+(jet a, const T& b) { return a += b; }
  friend jet operator+(const T& a, jet b) { return b += a; }
  friend jet operator-(jet a, const T& b) { return a -= b; }
  friend jet operator-(const T& a, const jet& b) {
    jet r = -b;
    r.v_ += a;
    return r;
  }
  friend jet operator*(jet a, const T& b) { return a *= b; }
  friend jet operator*(const T& a, jet b) { return b *= a; }
  friend jet operator/(jet a, const T& b) { return a /= b; }
  friend jet operator/(const T& a, const jet& b) {
    // (a / b)' = -(a / b) b' / b
    jet r(a / b.v_);
    const T f = -r.v_ / b.v_;
    for (int k = 0; k < N; ++k) r.d_[k] = f * b.d_[k];
    return r;
  }

  // Built-in arithmetic constants (2.0 * x, x / 3): exact matches beat the conversions above.
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator+(const jet& a, U b) { return a + T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator+(U a, const jet& b) { return T(static_cast<double>(a)) + b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator-(const jet& a, U b) { return a - T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator-(U a, const jet& b) { return T(static_cast<double>(a)) - b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator*(const jet& a, U b) { return a * T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator*(U a, const jet& b) { return T(static_cast<double>(a)) * b; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator/(const jet& a, U b) { return a / T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend jet operator/(U a, const jet& b) { return T(static_cast<double>(a)) / b; }

  // ---- comparisons: by value ----
  friend bool operator==(const jet& a, const jet& b) { return a.v_ == b.v_; }
  friend bool operator!=(const jet& a, const jet& b) { return a.v_ != b.v_; }
  friend bool operator<(const jet& a, const jet& b) { return a.v_ < b.v_; }
  friend bool operator<=(const jet& a, const jet& b) { return a.v_ <= b.v_; }
  friend bool operator>(const jet& a, const jet& b) { return a.v_ > b.v_; }
  friend bool operator>=(const jet& a, const jet& b) { return a.v_ >= b.v_; }
  friend bool operator==(const jet& a, const T& b) { return a.v_ == b; }
  friend bool operator!=(const jet& a, const T& b) { return a.v_ != b; }
  friend bool operator<(const jet& a, const T& b) { return a.v_ < b; }
  friend bool operator<=(const jet& a, const T& b) { return a.v_ <= b; }
  friend bool operator>(const jet& a, const T& b) { return a.v_ > b; }
  friend bool operator>=(const jet& a, const T& b) { return a.v_ >= b; }
  friend bool operator==(const T& a, const jet& b) { return a == b.v_; }
  friend bool operator!=(const T& a, const jet& b) { return a != b.v_; }
  friend bool operator<(const T& a, const jet& b) { return a < b.v_; }
  friend bool operator<=(const T& a, const jet& b) { return a <= b.v_; }
  friend bool operator>(const T& a, const jet& b) { return a > b.v_; }
  friend bool operator>=(const T& a, const jet& b) { return a >= b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator==(const jet& a, U b) { return a.v_ == T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator!=(const jet& a, U b) { return a.v_ != T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<(const jet& a, U b) { return a.v_ < T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<=(const jet& a, U b) { return a.v_ <= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>(const jet& a, U b) { return a.v_ > T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>=(const jet& a, U b) { return a.v_ >= T(static_cast<double>(b)); }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator==(U a, const jet& b) { return T(static_cast<double>(a)) == b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator!=(U a, const jet& b) { return T(static_cast<double>(a)) != b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<(U a, const jet& b) { return T(static_cast<double>(a)) < b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator<=(U a, const jet& b) { return T(static_cast<double>(a)) <= b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>(U a, const jet& b) { return T(static_cast<double>(a)) > b.v_; }
  template <class U>
    requires(std::is_arithmetic_v<U> && !std::is_same_v<U, T>)
  friend bool operator>=(U a, const jet& b) { return T(static_cast<double>(a)) >= b.v_; }

  friend std::ostream& operator<<(std::ostream& os, const jet& a) {
    os << "[" << a.v_ << "; ";
    for (int k = 0; k < N; ++k) os << (k ? ", " : "") << a.d_[k];
    return os << "]";
  }

 private:
  // Derivatives first: measured on the aerofoil residual with jet<double, 4>, the order
  // (value, derivatives) is 2.2 times slower (the 32-byte derivative loads straddle the
  // separate stores of value and derivatives of the temporaries, defeating store forwarding).
  std::array<T, N> d_;
  T v_;
};

template <class T>
struct is_jet : std::false_type {};
template <class T, int N>
struct is_jet<jet<T, N>> : std::true_type {};
template <class T>
inline constexpr bool is_jet_v = is_jet<T>::value;

template <class T, int N>
struct scalar_traits<jet<T, N>> {
  static constexpr std::string_view name() { return "jet"; }
  static constexpr double epsilon() { return scalar_traits<T>::epsilon(); }
  static constexpr int digits10 = scalar_traits<T>::digits10;
  static double to_double(const jet<T, N>& x) { return scalar_traits<T>::to_double(x.value()); }
};

// ---- elementary functions (found by ADL from generic code that writes `using std::exp;`) ----

template <class T, int N>
jet<T, N> sqrt(const jet<T, N>& a) {
  using std::sqrt;
  const T s = sqrt(a.value());
  if (s == T(0.0)) {
    // Not differentiable at 0: per direction the limit of taylor<T, 1>, i.e. 0 along a zero
    // direction (the norm of a zero vector stays 0) and d / 0 (+-inf in double) otherwise.
    jet<T, N> r(s);
    for (int k = 0; k < N; ++k)
      if (a.derivative(k) != T(0.0)) r.derivative(k) = a.derivative(k) / (s + s);
    return r;
  }
  return a.chain(s, T(1.0) / (s + s));
}

template <class T, int N>
jet<T, N> exp(const jet<T, N>& a) {
  using std::exp;
  const T e = exp(a.value());
  return a.chain(e, e);
}

template <class T, int N>
jet<T, N> log(const jet<T, N>& a) {
  using std::log;
  return a.chain(log(a.value()), T(1.0) / a.value());
}

namespace internal {
/// x^n in T by repeated squaring (n >= 0), independent of T's own pow overloads.
template <class T>
T jet_ipow(T x, int n) {
  T r(1.0);
  while (n > 0) {
    if (n & 1) r *= x;
    n >>= 1;
    if (n > 0) x *= x;
  }
  return r;
}
}  // namespace internal

/// a^n for an integer n (any sign of the base; n < 0 needs a non-zero base).
template <class T, int N>
jet<T, N> pow(const jet<T, N>& a, int n) {
  if (n == 0) return jet<T, N>(T(1.0));
  if (n < 0) return T(1.0) / pow(a, -n);
  const T p1 = internal::jet_ipow(a.value(), n - 1);  // a^(n-1)
  return a.chain(p1 * a.value(), T(static_cast<double>(n)) * p1);
}

/// a^r for a real exponent r; the value must be positive unless r is an integer (|r| <= 64),
/// which takes the integer path above (as taylor's pow).
template <class T, int N>
jet<T, N> pow(const jet<T, N>& a, const T& r) {
  using std::abs;
  using std::floor;
  using std::pow;
  if (floor(r) == r && abs(r) <= T(64.0)) return pow(a, static_cast<int>(aerohopf::to_double(r)));
  const T p = pow(a.value(), r);
  // r a^(r-1) = r p / a away from 0; at a = 0 the limit (0 for r > 1, inf for r < 1).
  const T dp = a.value() != T(0.0) ? r * p / a.value() : r * pow(a.value(), r - T(1.0));
  return a.chain(p, dp);
}

template <class T, int N, class U>
  requires(std::is_floating_point_v<U> && !std::is_same_v<U, T>)
jet<T, N> pow(const jet<T, N>& a, U r) {
  return pow(a, T(static_cast<double>(r)));
}

template <class T, int N>
jet<T, N> pow(const jet<T, N>& a, const jet<T, N>& b) {
  return exp(b * log(a));
}

/// r^b for a constant base r > 0.
template <class T, int N>
jet<T, N> pow(const T& r, const jet<T, N>& b) {
  using std::log;
  using std::pow;
  const T p = pow(r, b.value());
  return b.chain(p, p * log(r));
}

template <class T, int N>
jet<T, N> abs(const jet<T, N>& a) {
  if (a.value() > T(0.0)) return a;
  if (a.value() < T(0.0)) return -a;
  // At 0 (or NaN): the one-sided directional derivative |d_k| per direction (see file comment).
  jet<T, N> r(a.value());
  for (int k = 0; k < N; ++k) r.derivative(k) = a.derivative(k) < T(0.0) ? -a.derivative(k) : a.derivative(k);
  return r;
}
template <class T, int N>
jet<T, N> fabs(const jet<T, N>& a) { return abs(a); }

template <class T, int N>
jet<T, N> sin(const jet<T, N>& a) {
  using std::cos;
  using std::sin;
  return a.chain(sin(a.value()), cos(a.value()));
}
template <class T, int N>
jet<T, N> cos(const jet<T, N>& a) {
  using std::cos;
  using std::sin;
  return a.chain(cos(a.value()), -sin(a.value()));
}
template <class T, int N>
jet<T, N> tan(const jet<T, N>& a) {
  using std::tan;
  const T t = tan(a.value());
  return a.chain(t, T(1.0) + t * t);
}
template <class T, int N>
jet<T, N> asin(const jet<T, N>& a) {
  using std::asin;
  using std::sqrt;
  return a.chain(asin(a.value()), T(1.0) / sqrt(T(1.0) - a.value() * a.value()));
}
template <class T, int N>
jet<T, N> acos(const jet<T, N>& a) {
  using std::acos;
  using std::sqrt;
  return a.chain(acos(a.value()), T(-1.0) / sqrt(T(1.0) - a.value() * a.value()));
}
template <class T, int N>
jet<T, N> atan(const jet<T, N>& a) {
  using std::atan;
  return a.chain(atan(a.value()), T(1.0) / (T(1.0) + a.value() * a.value()));
}
template <class T, int N>
jet<T, N> atan2(const jet<T, N>& y, const jet<T, N>& x) {
  using std::atan2;
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2)
  const T r2 = x.value() * x.value() + y.value() * y.value();
  jet<T, N> r(atan2(y.value(), x.value()));
  for (int k = 0; k < N; ++k) r.derivative(k) = (x.value() * y.derivative(k) - y.value() * x.derivative(k)) / r2;
  return r;
}
template <class T, int N>
jet<T, N> sinh(const jet<T, N>& a) {
  using std::cosh;
  using std::sinh;
  return a.chain(sinh(a.value()), cosh(a.value()));
}
template <class T, int N>
jet<T, N> cosh(const jet<T, N>& a) {
  using std::cosh;
  using std::sinh;
  return a.chain(cosh(a.value()), sinh(a.value()));
}
template <class T, int N>
jet<T, N> tanh(const jet<T, N>& a) {
  using std::cosh;
  using std::tanh;
  // sech^2 from cosh, not 1 - tanh^2 (cancellation where |tanh| ~ 1; cosh overflowing to inf
  // gives the correct limit 0).
  const T sech = T(1.0) / cosh(a.value());
  return a.chain(tanh(a.value()), sech * sech);
}
template <class T, int N>
jet<T, N> hypot(const jet<T, N>& x, const jet<T, N>& y) {
  return sqrt(x * x + y * y);
}

// By value (not std::min's reference), so min(x * x, y) cannot leave a dangling reference.
template <class T, int N>
jet<T, N> min(const jet<T, N>& a, const jet<T, N>& b) { return b < a ? b : a; }
template <class T, int N>
jet<T, N> max(const jet<T, N>& a, const jet<T, N>& b) { return a < b ? b : a; }
template <class T, int N>
jet<T, N> fmin(const jet<T, N>& a, const jet<T, N>& b) { return min(a, b); }
template <class T, int N>
jet<T, N> fmax(const jet<T, N>& a, const jet<T, N>& b) { return max(a, b); }

template <class T, int N>
bool isfinite(const jet<T, N>& a) {
  using std::isfinite;
  if (!isfinite(a.value())) return false;
  for (int k = 0; k < N; ++k)
    if (!isfinite(a.derivative(k))) return false;
  return true;
}
template <class T, int N>
bool isnan(const jet<T, N>& a) {
  using std::isnan;
  if (isnan(a.value())) return true;
  for (int k = 0; k < N; ++k)
    if (isnan(a.derivative(k))) return true;
  return false;
}
template <class T, int N>
bool isinf(const jet<T, N>& a) {
  return !isfinite(a) && !isnan(a);
}

// Eigen's generic code calls real/imag/conj/abs2 on scalars.
template <class T, int N>
const jet<T, N>& real(const jet<T, N>& a) { return a; }
template <class T, int N>
jet<T, N> imag(const jet<T, N>&) { return jet<T, N>(); }
template <class T, int N>
const jet<T, N>& conj(const jet<T, N>& a) { return a; }
template <class T, int N>
jet<T, N> abs2(const jet<T, N>& a) { return a * a; }

}  // namespace aerohopf

namespace Eigen {

template <class T, int N>
struct NumTraits<aerohopf::jet<T, N>> : GenericNumTraits<aerohopf::jet<T, N>> {
  using Self = aerohopf::jet<T, N>;
  using Real = Self;
  using NonInteger = Self;
  using Literal = Self;
  using Nested = Self;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (N + 1) * NumTraits<T>::ReadCost,
    AddCost = (N + 1) * NumTraits<T>::AddCost,
    MulCost = NumTraits<T>::MulCost + N * (2 * NumTraits<T>::MulCost + NumTraits<T>::AddCost),
  };
  static inline Self epsilon() { return Self(NumTraits<T>::epsilon()); }
  // In T's precision: GenericNumTraits' default would make isApprox() exact equality.
  static inline Self dummy_precision() { return Self(NumTraits<T>::dummy_precision()); }
  static inline Self highest() { return Self(NumTraits<T>::highest()); }
  static inline Self lowest() { return Self(NumTraits<T>::lowest()); }
  static inline Self infinity() { return Self(NumTraits<T>::infinity()); }
  static inline Self quiet_NaN() { return Self(NumTraits<T>::quiet_NaN()); }
  static inline int digits10() { return NumTraits<T>::digits10(); }
  static inline int digits() { return NumTraits<T>::digits(); }
};

template <class T, int N, class BinaryOp>
struct ScalarBinaryOpTraits<aerohopf::jet<T, N>, T, BinaryOp> {
  using ReturnType = aerohopf::jet<T, N>;
};
template <class T, int N, class BinaryOp>
struct ScalarBinaryOpTraits<T, aerohopf::jet<T, N>, BinaryOp> {
  using ReturnType = aerohopf::jet<T, N>;
};

}  // namespace Eigen
