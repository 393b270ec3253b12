#pragma once
// Osher's approximate Riemann solver (Osher & Chakravarthy, J. Comput. Phys. 50, 1983) with
// the physical ("P") ordering of the subpaths, implemented exactly, for a moving face.
//
//   F(w_L, w_R) = F(w_L) + integral over the path w_L -> w_R of A^-(w) dw,
//
// where the path consists of three integral curves of the eigenvectors of A, taken in the
// order of increasing eigenvalue: u-c (from w_L to w_1/3, along which the entropy, the
// tangential velocity and u + 2c/(gamma-1) are constant), u (from w_1/3 to w_2/3: normal
// velocity and pressure constant) and u+c (from w_2/3 to w_R: entropy, tangential velocity and
// u - 2c/(gamma-1) constant). Along an integral curve A dw = lambda dw, so the integral of A^-
// dw is the flux difference over the part where lambda < 0; lambda is monotone along the
// genuinely non-linear subpaths, so that part ends at the sonic point (lambda = 0) at most.
// The intermediate states follow in closed form from the Riemann invariants:
//   P*^z = (gamma-1)/2 (psi_L - psi_R) / (c_L p_L^-z + c_R p_R^-z),  z = (gamma-1)/(2 gamma),
//   psi_L = u_L + 2 c_L/(gamma-1),  psi_R = u_R - 2 c_R/(gamma-1).
// On a moving face, u is the normal velocity relative to the face (the Riemann structure is
// Galilean invariant) and the flux is the ALE flux of gas.hpp. The function is a template over
// the scalar, so taylor<> jets differentiate exactly the branch that the value takes.
#include <cmath>

#include "gas.hpp"

namespace aerohopf::flow {

namespace internal {
template <class S>
S power(const S& x, double e) {
  using std::exp;
  using std::log;
  return exp(S(e) * log(x));
}

/// A state on the Osher path: the left (or right) state with its normal velocity replaced.
template <class S, int Dim>
primitive<S, Dim> with_normal_velocity(const primitive<S, Dim>& q, const S& un_old, const S& un_new,
                                       const vector_d<S, Dim>& n, const S& rho, const S& p) {
  primitive<S, Dim> r;
  r.rho = rho;
  r.p = p;
  const S du = un_new - un_old;
  for (int d = 0; d < Dim; ++d) r.u[d] = q.u[d] + du * n[d];
  return r;
}
}  // namespace internal

/// Star (intermediate) pressure and relative normal velocity of the Osher path.
template <class S>
struct osher_star {
  S pressure, velocity;
};

/// Osher flux through a face with area vector area (|area| = face area) and face volume flux
/// q_face (= face area times the normal grid speed).
template <class S, int Dim>
state<S, Dim> osher_flux(const primitive<S, Dim>& ql, const primitive<S, Dim>& qr, const vector_d<S, Dim>& area,
                         const S& q_face, osher_star<S>* star = nullptr) {
  using std::sqrt;
  constexpr double g = gamma_gas, gm1 = gamma_gas - 1.0;
  constexpr double z = gm1 / (2.0 * g);
  const S a = sqrt(dot<S, Dim>(area, area));
  vector_d<S, Dim> n;
  for (int d = 0; d < Dim; ++d) n[d] = area[d] / a;
  const S sn = q_face / a;

  const S unl = dot<S, Dim>(ql.u, n), unr = dot<S, Dim>(qr.u, n);
  const S ul = unl - sn, ur = unr - sn;  // relative normal velocities
  const S cl = sound_speed(ql), cr = sound_speed(qr);
  const S psil = ul + S(2.0 / gm1) * cl, psir = ur - S(2.0 / gm1) * cr;
  const S plz = internal::power(ql.p, z), prz = internal::power(qr.p, z);
  S x = S(0.5 * gm1) * (psil - psir) / (cl / plz + cr / prz);  // P*^z
  if (!(x > S(0.0))) x = S(1e-8) * (plz < prz ? plz : prz);   // vacuum would form: clamp
  const S c13 = cl * x / plz, c23 = cr * x / prz;
  const S ustar = psil - S(2.0 / gm1) * c13;
  const S pstar = internal::power(x, 1.0 / z);
  if (star) *star = {pstar, ustar};

  auto flux = [&](const primitive<S, Dim>& q) { return ale_flux<S, Dim>(q, area, q_face); };
  auto state13 = [&] {
    return internal::with_normal_velocity<S, Dim>(ql, unl, ustar + sn, n, S(g) * pstar / (c13 * c13), pstar);
  };
  auto state23 = [&] {
    return internal::with_normal_velocity<S, Dim>(qr, unr, ustar + sn, n, S(g) * pstar / (c23 * c23), pstar);
  };
  auto sonic1 = [&] {  // u - c = 0 on the first subpath
    const S c = S(gm1 / (g + 1.0)) * psil;
    const S rho = ql.rho * internal::power(c / cl, 2.0 / gm1);
    return internal::with_normal_velocity<S, Dim>(ql, unl, c + sn, n, rho, rho * c * c / S(g));
  };
  auto sonic3 = [&] {  // u + c = 0 on the third subpath
    const S c = -S(gm1 / (g + 1.0)) * psir;
    const S rho = qr.rho * internal::power(c / cr, 2.0 / gm1);
    return internal::with_normal_velocity<S, Dim>(qr, unr, sn - c, n, rho, rho * c * c / S(g));
  };
  auto add = [](state<S, Dim>& f, const state<S, Dim>& plus, const state<S, Dim>& minus) {
    for (int k = 0; k < Dim + 2; ++k) f[k] += plus[k] - minus[k];
  };

  state<S, Dim> f = flux(ql);
  // Subpath 1 (u - c), from L to 1/3.
  const bool neg_l = ul - cl < S(0.0), neg_13 = ustar - c13 < S(0.0);
  state<S, Dim> f13;
  if (neg_13 || ustar < S(0.0)) {
    f13 = flux(state13());
  }
  if (neg_l && neg_13) add(f, f13, flux(ql));
  else if (!neg_l && neg_13) add(f, f13, flux(sonic1()));
  else if (neg_l && !neg_13) add(f, flux(sonic1()), flux(ql));
  // Subpath 2 (u), from 1/3 to 2/3: lambda = u* is constant.
  const bool neg_23 = ustar + c23 < S(0.0), neg_r = ur + cr < S(0.0);
  state<S, Dim> f23;
  if (ustar < S(0.0) || neg_23) {
    f23 = flux(state23());
  }
  if (ustar < S(0.0)) add(f, f23, f13);
  // Subpath 3 (u + c), from 2/3 to R.
  if (neg_23 && neg_r) add(f, flux(qr), f23);
  else if (!neg_23 && neg_r) add(f, flux(qr), flux(sonic3()));
  else if (neg_23 && !neg_r) add(f, flux(sonic3()), f23);
  return f;
}

}  // namespace aerohopf::flow
