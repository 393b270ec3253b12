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

  friend dual sqrt(const dual& a) {
    dual r;
    r.v = std::sqrt(a.v);
    const double f = 0.5 / r.v;
    for (int k = 0; k < N; ++k) r.d[k] = f * a.d[k];
    return r;
  }
  friend dual exp(const dual& a) {
    dual r;
    r.v = std::exp(a.v);
    for (int k = 0; k < N; ++k) r.d[k] = r.v * a.d[k];
    return r;
  }
  friend dual log(const dual& a) {
    dual r;
    r.v = std::log(a.v);
    const double f = 1.0 / a.v;
    for (int k = 0; k < N; ++k) r.d[k] = f * a.d[k];
    return r;
  }
};

}  // namespace aerohopf::flow
