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
//
// Contact smoothing (optional, contact_width = delta > 0). The middle subpath contributes
// H(-u*) (F(w_2/3) - F(w_1/3)) with H the Heaviside function: the flux switches from the
// left to the right intermediate state where u* changes sign. At u* = 0 the two fluxes agree
// (mass flux 0, pressure p* in both), and their derivatives differ by (rho_2/3 - rho_1/3) du*
// (and the tangential-velocity jump): the flux is C0 with a kink in general, C1 where the two
// sides are mirror images. That is exactly the wake cut of a symmetric aerofoil at zero
// incidence (v = 0 there), so the 2nd and 3rd derivatives of the residual that the centre-
// manifold reduction needs do not exist at its equilibrium (measured: finite-difference g21
// grows like 1/h). With delta > 0, H(-u*) is replaced by the logistic
//     h(u*) = 1 / (1 + exp(2 u* / (delta cbar))),   cbar = (c_1/3 + c_2/3) / 2,
// (= (1 - tanh(u* / (delta cbar))) / 2), which is C-infinity and equals H to 1e-35 for
// |u*| > 40 delta cbar, where the exact switch is used. The flux stays consistent (F(w, w) =
// F(w): the bracket vanishes for equal states) and conservative; only the upwinding of the
// contact (entropy and shear) wave on faces with |u*| <~ delta c changes, to a smooth central
// blend. At a mirror-symmetric face (u* = 0, w_1/3 and w_2/3 mirror images) the bracket and
// its first derivative vanish, so the flux and its Jacobian there are unchanged; faces
// elsewhere with |u*| <~ delta c (e.g. nearly aligned with the flow) change slightly, and so
// does the equilibrium (measured in examples/aerofoil_flutter). euler_options::contact_smoothing
// sets delta, also for the far field's own contact switch (euler_model.hpp).
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
/// q_face (= face area times the normal grid speed). contact_width: delta of the contact
/// smoothing (file comment; 0 = the exact switch).
template <class S, int Dim>
state<S, Dim> osher_flux(const primitive<S, Dim>& ql, const primitive<S, Dim>& qr, const vector_d<S, Dim>& area,
                         const S& q_face, osher_star<S>* star = nullptr, double contact_width = 0.0) {
  using std::exp;
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
  S arg(0.0);  // u* / (delta cbar) for the smoothed contact
  bool smooth = false;
  if (contact_width > 0.0) {
    arg = ustar / (S(0.5 * contact_width) * (c13 + c23));
    smooth = arg < S(40.0) && arg > S(-40.0);
  }
  state<S, Dim> f23;
  if (smooth && !(neg_13 || ustar < S(0.0))) f13 = flux(state13());
  if (smooth || ustar < S(0.0) || neg_23) {
    f23 = flux(state23());
  }
  if (smooth) {
    const S h = S(1.0) / (S(1.0) + exp(S(2.0) * arg));
    for (int k = 0; k < Dim + 2; ++k) f[k] += h * (f23[k] - f13[k]);
  } else if (ustar < S(0.0)) {
    add(f, f23, f13);
  }
  // Subpath 3 (u + c), from 2/3 to R.
  if (neg_23 && neg_r) add(f, flux(qr), f23);
  else if (!neg_23 && neg_r) add(f, flux(qr), flux(sonic3()));
  else if (neg_23 && !neg_r) add(f, flux(sonic3()), f23);
  return f;
}

}  // namespace aerohopf::flow
