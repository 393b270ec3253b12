#pragma once
// Two-degree-of-freedom pitch-plunge aerofoil section (spec 05), the structural half of the
// aerofoil flutter problem.
//
// State w_s = [h, h', alpha, alpha'] with h the plunge over the chord (positive UP), alpha the
// pitch (positive NOSE-UP) and ' = d/dt, t in units of c / U_inf (the same time unit as the
// flow solver, which is non-dimensionalised by chord and free-stream speed, so the coupled
// ODE needs no rescaling). Equations
//     M dw_s/dt + K(Ubar) w_s = f_a,   f_a = (0, 2 C_l / (pi mu_s), 0, 4 C_m / (pi mu_s)),
// M and K as written in spec 05, C_m nose-up about the elastic axis. Ubar = U_inf/(omega_a b)
// is the bifurcation parameter and enters only K (through 1/Ubar^2), so d/dUbar is analytic.
// Everything that the coupled residual needs is templated on the scalar so that taylor<> jets
// (in the state or in Ubar) pass through.
#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>
#include <numbers>

#include "../error.hpp"
#include "../scalar/traits.hpp"

namespace aerohopf::structure {

/// Non-dimensional section parameters (defaults: spec 05 test case, light, mu_s = 10).
struct pitch_plunge_parameters {
  double r_a = 0.539;   ///< radius of gyration / semichord
  double x_a = -0.2;    ///< static unbalance / semichord in the h-UP convention
  double w_r = 0.343;   ///< omega_h / omega_alpha
  double mu_s = 10.0;   ///< mass ratio m / (pi rho_inf b^2)
  double x_ea = 0.4;    ///< elastic axis (chords from the leading edge)
  double y_ea = 0.0;
};

class pitch_plunge {
 public:
  using matrix4 = Eigen::Matrix4d;
  template <class T>
  using vector4 = Eigen::Matrix<T, 4, 1>;

  explicit pitch_plunge(const pitch_plunge_parameters& p = {}) : p_(p) {
    require(std::isfinite(p.r_a) && p.r_a > 0, "pitch_plunge: r_a = ", p.r_a, " must be positive");
    require(std::isfinite(p.x_a), "pitch_plunge: x_a = ", p.x_a, " is not finite");
    require(std::isfinite(p.w_r) && p.w_r > 0, "pitch_plunge: w_r = ", p.w_r, " must be positive");
    require(std::isfinite(p.mu_s) && p.mu_s > 0, "pitch_plunge: mu_s = ", p.mu_s, " must be positive");
    require(std::isfinite(p.x_ea) && std::isfinite(p.y_ea), "pitch_plunge: elastic axis is not finite");
    // M positive definite <=> r_a^2 > x_a^2 (the inertia about the c.g. is positive).
    require(p.r_a * p.r_a > p.x_a * p.x_a, "pitch_plunge: r_a^2 = ", p.r_a * p.r_a, " must exceed x_a^2 = ",
            p.x_a * p.x_a, " (mass matrix not positive definite)");
    m_inv_ = mass_matrix().inverse();
  }

  const pitch_plunge_parameters& parameters() const { return p_; }

  matrix4 mass_matrix() const {
    matrix4 m = matrix4::Identity();
    m(1, 3) = p_.x_a / 2;
    m(3, 1) = p_.x_a;
    m(3, 3) = p_.r_a * p_.r_a / 2;
    return m;
  }
  const matrix4& mass_inverse() const { return m_inv_; }

  /// K(Ubar) of spec 05; Ubar (its value, for a jet) must be finite and non-zero (input_error).
  template <class T>
  Eigen::Matrix<T, 4, 4> stiffness_matrix(const T& ubar) const {
    const double u = to_double(ubar);
    require(std::isfinite(u) && u != 0, "pitch_plunge::stiffness_matrix: Ubar = ", u, " must be finite and non-zero");
    Eigen::Matrix<T, 4, 4> k;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) k(i, j) = T(0.0);
    k(0, 1) = T(-1.0);
    k(2, 3) = T(-1.0);
    const T inv_u2 = T(1.0) / (ubar * ubar);
    k(1, 0) = T(4 * p_.w_r * p_.w_r) * inv_u2;
    k(3, 2) = T(2 * p_.r_a * p_.r_a) * inv_u2;
    return k;
  }
  /// dK/dUbar.
  matrix4 stiffness_d_ubar(double ubar) const {
    require(std::isfinite(ubar) && ubar != 0, "pitch_plunge: Ubar = ", ubar, " must be finite and non-zero");
    matrix4 k = matrix4::Zero();
    const double u3 = ubar * ubar * ubar;
    k(1, 0) = -8 * p_.w_r * p_.w_r / u3;
    k(3, 2) = -4 * p_.r_a * p_.r_a / u3;
    return k;
  }

  /// Generalised aerodynamic force f_a from C_l and C_m (about the elastic axis, nose-up).
  template <class T>
  vector4<T> aerodynamic_force(const T& cl, const T& cm) const {
    const double pi = std::numbers::pi;
    vector4<T> f;
    f[0] = T(0.0);
    f[1] = T(2.0 / (pi * p_.mu_s)) * cl;
    f[2] = T(0.0);
    f[3] = T(4.0 / (pi * p_.mu_s)) * cm;
    return f;
  }

  /// dw_s/dt = M^{-1} (f_a - K(Ubar) w_s).
  template <class T>
  vector4<T> rate(const vector4<T>& ws, const T& cl, const T& cm, const T& ubar) const {
    const auto k = stiffness_matrix<T>(ubar);
    const auto f = aerodynamic_force<T>(cl, cm);
    vector4<T> g;
    for (int i = 0; i < 4; ++i) {
      g[i] = f[i];
      for (int j = 0; j < 4; ++j) g[i] -= k(i, j) * ws[j];
    }
    vector4<T> r;
    for (int i = 0; i < 4; ++i) {
      r[i] = T(0.0);
      for (int j = 0; j < 4; ++j) r[i] += T(m_inv_(i, j)) * g[j];
    }
    return r;
  }

  /// In-vacuo state matrix -M^{-1} K(Ubar) (the structural block of the coupled Jacobian
  /// apart from the aerodynamic stiffness and damping).
  /// Ubar must be finite and non-zero (input_error): K has 1/Ubar^2.
  matrix4 in_vacuo_matrix(double ubar) const {
    require(std::isfinite(ubar) && ubar != 0, "pitch_plunge::in_vacuo_matrix: Ubar = ", ubar,
            " must be finite and non-zero");
    return -m_inv_ * stiffness_matrix<double>(ubar);
  }

 private:
  pitch_plunge_parameters p_;
  matrix4 m_inv_;
};

}  // namespace aerohopf::structure
