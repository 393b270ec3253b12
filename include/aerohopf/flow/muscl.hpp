#pragma once
// MUSCL reconstruction with the differentiable van Albada limiter (chi = 0), spec 05:
//   w_l = w_i     + 1/2 (D- D+ + eps) / (D-^2 + D+^2 + 2 eps) (D- + D+)        at face i+1/2
//   w_r = w_{i+1} - 1/2 (same with the differences at cell i+1)
// applied per component. It is smooth in all arguments (no max/min), so the exact Jacobian and
// the taylor<> derivative products exist everywhere. aerohopf reconstructs the PRIMITIVE
// variables (rho, u, p): this keeps density and pressure positive across strong shocks more
// reliably than conservative reconstruction, and costs nothing in the Jacobians because those
// differentiate the whole face function anyway.
#include "gas.hpp"

namespace aerohopf::flow {

/// Limited half-slope contribution: 1/2 * van Albada average of the differences a, b.
template <class S>
S van_albada_half_slope(const S& a, const S& b, double eps) {
  const S e = S(eps);
  return S(0.5) * (a * b + e) / (a * a + b * b + S(2.0) * e) * (a + b);
}

/// Left state at the face between c0 and c1, from cells cm (c0 - 1), c0 and c1.
template <class S, int Dim>
primitive<S, Dim> muscl_left(const primitive<S, Dim>& cm, const primitive<S, Dim>& c0, const primitive<S, Dim>& c1,
                             double eps) {
  primitive<S, Dim> q;
  q.rho = c0.rho + van_albada_half_slope(c0.rho - cm.rho, c1.rho - c0.rho, eps);
  for (int d = 0; d < Dim; ++d) q.u[d] = c0.u[d] + van_albada_half_slope(c0.u[d] - cm.u[d], c1.u[d] - c0.u[d], eps);
  q.p = c0.p + van_albada_half_slope(c0.p - cm.p, c1.p - c0.p, eps);
  return q;
}

/// Right state at the face between c0 and c1, from cells c0, c1 and cp (c1 + 1).
template <class S, int Dim>
primitive<S, Dim> muscl_right(const primitive<S, Dim>& c0, const primitive<S, Dim>& c1, const primitive<S, Dim>& cp,
                              double eps) {
  primitive<S, Dim> q;
  q.rho = c1.rho - van_albada_half_slope(c1.rho - c0.rho, cp.rho - c1.rho, eps);
  for (int d = 0; d < Dim; ++d) q.u[d] = c1.u[d] - van_albada_half_slope(c1.u[d] - c0.u[d], cp.u[d] - c1.u[d], eps);
  q.p = c1.p - van_albada_half_slope(c1.p - c0.p, cp.p - c1.p, eps);
  return q;
}

}  // namespace aerohopf::flow
