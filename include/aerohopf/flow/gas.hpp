#pragma once
// Perfect-gas thermodynamics, the Euler flux and the free-stream state, dimension-generic.
//
// NON-DIMENSIONALISATION (used by every flow file): lengths by the chord (root chord in 3D),
// density by rho_inf, velocity by the free-stream SPEED U_inf, pressure by rho_inf U_inf^2,
// time by c / U_inf. Hence rho_inf = 1, |u_inf| = 1, p_inf = 1 / (gamma M^2), c_inf = 1 / M,
// and Cp = 2 (p - p_inf). The conservative variables are w = (rho, rho u_1..u_Dim, rho E).
#include <array>
#include <cmath>

#include "../scalar/traits.hpp"

namespace aerohopf::flow {

inline constexpr double gamma_gas = 1.4;

/// Number of conservative variables in Dim dimensions.
template <int Dim>
inline constexpr int n_vars = Dim + 2;

template <class S, int Dim>
using state = std::array<S, Dim + 2>;
template <class S, int Dim>
using vector_d = std::array<S, Dim>;

template <class S, int Dim>
S dot(const vector_d<S, Dim>& a, const vector_d<S, Dim>& b) {
  S r = a[0] * b[0];
  for (int d = 1; d < Dim; ++d) r += a[d] * b[d];
  return r;
}

/// Primitive variables of a conservative state.
template <class S, int Dim>
struct primitive {
  S rho;
  vector_d<S, Dim> u;
  S p;
};

template <class S, int Dim>
primitive<S, Dim> to_primitive(const state<S, Dim>& w) {
  primitive<S, Dim> q;
  q.rho = w[0];
  const S inv_rho = S(1.0) / w[0];
  S ke = S(0.0);
  for (int d = 0; d < Dim; ++d) {
    q.u[d] = w[1 + d] * inv_rho;
    ke += q.u[d] * w[1 + d];
  }
  q.p = S(gamma_gas - 1.0) * (w[Dim + 1] - S(0.5) * ke);
  return q;
}

/// The pressure of the conservative state at w[0 .. Dim + 1] (a cell of a state vector).
template <class S, int Dim>
S pressure_at(const S* w) {
  state<S, Dim> s;
  for (int v = 0; v < Dim + 2; ++v) s[v] = w[v];
  return to_primitive<S, Dim>(s).p;
}

template <class S, int Dim>
state<S, Dim> to_conservative(const primitive<S, Dim>& q) {
  state<S, Dim> w;
  w[0] = q.rho;
  S ke = S(0.0);
  for (int d = 0; d < Dim; ++d) {
    w[1 + d] = q.rho * q.u[d];
    ke += q.u[d] * q.u[d];
  }
  w[Dim + 1] = q.p / S(gamma_gas - 1.0) + S(0.5) * q.rho * ke;
  return w;
}

template <class S, int Dim>
S sound_speed(const primitive<S, Dim>& q) {
  using std::sqrt;
  return sqrt(S(gamma_gas) * q.p / q.rho);
}

/// ALE flux through a face with area vector n_area (|n_area| = face area) moving with normal
/// volume flux q_face = integral of x_g . dS:  F = w (u . S - q) + p (0, S, u . S).
template <class S, int Dim>
state<S, Dim> ale_flux(const primitive<S, Dim>& q, const vector_d<S, Dim>& n_area, const S& q_face) {
  const S un = dot<S, Dim>(q.u, n_area);
  const S rel = un - q_face;  // relative volume flux through the face
  state<S, Dim> f;
  f[0] = q.rho * rel;
  S ke = S(0.0);
  for (int d = 0; d < Dim; ++d) {
    f[1 + d] = q.rho * q.u[d] * rel + q.p * n_area[d];
    ke += q.u[d] * q.u[d];
  }
  const S rho_e = q.p / S(gamma_gas - 1.0) + S(0.5) * q.rho * ke;
  f[Dim + 1] = rho_e * rel + q.p * un;
  return f;
}

/// Free-stream conditions: Mach number and flow direction (alpha in the x-y plane, beta
/// sideslip in 3D), non-dimensionalised as described above.
struct free_stream {
  double mach = 0.5;
  double alpha_rad = 0.0;
  double beta_rad = 0.0;

  double pressure() const { return 1.0 / (gamma_gas * mach * mach); }
  template <class S, int Dim>
  primitive<S, Dim> primitive_state() const {
    primitive<S, Dim> q;
    q.rho = S(1.0);
    if constexpr (Dim == 2) {
      q.u = {S(std::cos(alpha_rad)), S(std::sin(alpha_rad))};
    } else {
      q.u = {S(std::cos(alpha_rad) * std::cos(beta_rad)), S(-std::sin(beta_rad)),
             S(std::sin(alpha_rad) * std::cos(beta_rad))};
    }
    q.p = S(pressure());
    return q;
  }
  template <class S, int Dim>
  state<S, Dim> conservative_state() const {
    return to_conservative<S, Dim>(primitive_state<S, Dim>());
  }
};

}  // namespace aerohopf::flow
