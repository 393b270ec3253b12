#pragma once
// dual<N>: a forward-mode AD scalar carrying a value and N first derivatives.
//
// Why (and why not taylor<double, 1>): a Jacobian block row needs the derivatives of one face
// flux with respect to all 4 (Dim + 2) stencil unknowns. One pass with N = 4 (Dim + 2)
// derivative directions shares every value computation (the exp/log/sqrt of the Osher path)
// instead of repeating it per direction, which makes the Jacobian assembly several times faster.
// Only first derivatives and the operations used by the flux kernels are provided; comparisons
// use the value, so branches follow the plain evaluation (as for taylor<>).
#include <array>
#include <cmath>

namespace aerohopf::flow {

template <int N>
struct dual {
  double v = 0.0;
  std::array<double, N> d{};

  dual() = default;
  dual(double value) : v(value) {}  // NOLINT(google-explicit-constructor): constants promote
  static dual variable(double value, int k) {
    dual r(value);
    r.d[k] = 1.0;
    return r;
  }

  dual& operator+=(const dual& b) {
    v += b.v;
    for (int k = 0; k < N; ++k) d[k] += b.d[k];
    return *this;
  }
  dual& operator-=(const dual& b) {
    v -= b.v;
    for (int k = 0; k < N; ++k) d[k] -= b.d[k];
    return *this;
  }
  dual& operator*=(const dual& b) { return *this = *this * b; }
  dual& operator/=(const dual& b) { return *this = *this / b; }
  dual operator-() const {
    dual r;
    r.v = -v;
    for (int k = 0; k < N; ++k) r.d[k] = -d[k];
    return r;
  }
  friend dual operator+(dual a, const dual& b) { return a += b; }
  friend dual operator-(dual a, const dual& b) { return a -= b; }
  friend dual operator*(const dual& a, const dual& b) {
    dual r;
    r.v = a.v * b.v;
    for (int k = 0; k < N; ++k) r.d[k] = a.v * b.d[k] + b.v * a.d[k];
    return r;
  }
  friend dual operator/(const dual& a, const dual& b) {
    dual r;
    r.v = a.v / b.v;
    const double inv = 1.0 / b.v;
    for (int k = 0; k < N; ++k) r.d[k] = (a.d[k] - r.v * b.d[k]) * inv;
    return r;
  }
  friend bool operator<(const dual& a, const dual& b) { return a.v < b.v; }
  friend bool operator>(const dual& a, const dual& b) { return a.v > b.v; }
  friend bool operator<=(const dual& a, const dual& b) { return a.v <= b.v; }
  friend bool operator>=(const dual& a, const dual& b) { return a.v >= b.v; }
  friend bool operator==(const dual& a, const dual& b) { return a.v == b.v; }
  friend bool operator!=(const dual& a, const dual& b) { return a.v != b.v; }

  /// g(a) for a function with value gv = g(a.v) and derivative dg = g'(a.v) (chain rule).
  static dual chain(const dual& a, double gv, double dg) {
    dual r;
    r.v = gv;
    for (int k = 0; k < N; ++k) r.d[k] = dg * a.d[k];
    return r;
  }
  friend dual sqrt(const dual& a) {
    const double s = std::sqrt(a.v);
    return chain(a, s, 0.5 / s);
  }
  friend dual exp(const dual& a) {
    const double e = std::exp(a.v);
    return chain(a, e, e);
  }
  friend dual log(const dual& a) { return chain(a, std::log(a.v), 1.0 / a.v); }
};

}  // namespace aerohopf::flow
