#pragma once
// Modal structural model of a wing (spec 06): m generalised coordinates a_i of mass-normalised
// modes with structural damping, the structural half of the coupled wing system.
//
// Physical form, phi_i^T M phi_i = 1:  a_i'' + 2 zeta_i omega_i a_i' + omega_i^2 a_i = phi_i^T F,
// with F the aerodynamic forces at the structural points. The coupled system runs in the flow
// solver's time unit tau = c / U_inf (lengths by the reference chord c, pressure by rho U^2, spec
// 06), so with a_hat = a / c (a in m kg^1/2, a_hat in kg^1/2: the shapes keep their kg^-1/2) and
// F = rho U^2 c^2 F_hat:
//     a_hat'' + 2 zeta_i k_i a_hat' + k_i^2 a_hat = mu phi_i^T F_hat,   k_i = omega_i c / U,
//     mu = rho_inf c^3  (the density parameter, in kg: the air mass of a chord cube)
// Time derivatives are in tau. At a fixed Mach number and speed (fixed k_i), the free-stream
// density is the bifurcation parameter, as in the original work (density ratio); the flutter speed
// index follows from the critical mu by the wing's mass ratio.
//
// State w_s = [a_hat_1 .. a_hat_m, a_hat_1' .. a_hat_m'] and residual R_s = dw_s/dt:
//     R_s = [a_hat';  mu g - K a_hat - D a_hat'],  K = diag(k_i^2), D = diag(2 zeta_i k_i),
// g the generalised aerodynamic forces phi^T F_hat (non-dimensional) at the current flow state.
// Everything is templated on the scalar so jets and Taylor numbers pass through; A_ss = dR_s/dw_s
// and dR_s/dmu are analytic.
#include <Eigen/Dense>

#include <cmath>
#include <string>

#include "../error.hpp"

namespace aerohopf::structure {

class modal_structure {
 public:
  /// reduced frequencies k_i = omega_i c / U (> 0) and damping ratios zeta_i (>= 0), one per mode.
  modal_structure(Eigen::VectorXd reduced_frequency, Eigen::VectorXd damping_ratio)
      : k_(std::move(reduced_frequency)), zeta_(std::move(damping_ratio)) {
    const char* who = "modal_structure";
    require(k_.size() >= 1, who, ": no modes");
    require_size(zeta_.size(), k_.size(), who, "damping ratios");
    for (Eigen::Index i = 0; i < k_.size(); ++i) {
      require(std::isfinite(k_[i]) && k_[i] > 0, who, ": mode ", i + 1, " reduced frequency ", k_[i],
              " must be finite and > 0");
      require(std::isfinite(zeta_[i]) && zeta_[i] >= 0 && zeta_[i] < 1, who, ": mode ", i + 1, " damping ratio ",
              zeta_[i], " must lie in [0, 1)");
    }
  }
  /// From frequencies in rad/s, the reference chord c and the free-stream speed U.
  static modal_structure from_physical(const Eigen::VectorXd& omega, const Eigen::VectorXd& damping_ratio,
                                       double chord, double speed) {
    require(std::isfinite(chord) && chord > 0 && std::isfinite(speed) && speed > 0,
            "modal_structure::from_physical: chord and speed must be finite and > 0 (got ", chord, ", ", speed, ")");
    return modal_structure(omega * (chord / speed), damping_ratio);
  }
  /// The density parameter mu = rho_inf c^3 of a free-stream density (kg/m^3) and chord (m).
  static double density_parameter(double rho_inf, double chord) { return rho_inf * chord * chord * chord; }

  Eigen::Index modes() const { return k_.size(); }
  Eigen::Index size() const { return 2 * k_.size(); }
  const Eigen::VectorXd& reduced_frequency() const { return k_; }
  const Eigen::VectorXd& damping_ratio() const { return zeta_; }

  /// R_s(w_s, g, mu) as above; w_s of size 2m, g (generalised forces) of size m.
  template <class T, class DerivedW, class DerivedG>
  Eigen::Matrix<T, Eigen::Dynamic, 1> residual(const Eigen::MatrixBase<DerivedW>& ws, const Eigen::MatrixBase<DerivedG>& g,
                                               const T& mu) const {
    const Eigen::Index m = modes();
    require_size(ws.size(), 2 * m, "modal_structure::residual", "structural state");
    require_size(g.size(), m, "modal_structure::residual", "generalised forces");
    Eigen::Matrix<T, Eigen::Dynamic, 1> r(2 * m);
    for (Eigen::Index i = 0; i < m; ++i) {
      r[i] = T(ws[m + i]);
      r[m + i] = mu * T(g[i]) - T(k_[i] * k_[i]) * T(ws[i]) - T(2 * zeta_[i] * k_[i]) * T(ws[m + i]);
    }
    return r;
  }
  /// dR_s / dw_s = [[0, I], [-K, -D]] (the generalised forces held).
  Eigen::MatrixXd a_ss() const {
    const Eigen::Index m = modes();
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * m, 2 * m);
    a.topRightCorner(m, m).setIdentity();
    for (Eigen::Index i = 0; i < m; ++i) {
      a(m + i, i) = -k_[i] * k_[i];
      a(m + i, m + i) = -2 * zeta_[i] * k_[i];
    }
    return a;
  }
  /// dR_s / dg = [0; mu I] (the coupling through the generalised forces), 2m x m.
  Eigen::MatrixXd force_coupling(double mu) const {
    const Eigen::Index m = modes();
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(2 * m, m);
    b.bottomRows(m).diagonal().setConstant(mu);
    return b;
  }
  /// dR_s / dmu = [0; g].
  Eigen::VectorXd d_mu(const Eigen::VectorXd& g) const {
    require_size(g.size(), modes(), "modal_structure::d_mu", "generalised forces");
    Eigen::VectorXd r = Eigen::VectorXd::Zero(size());
    r.tail(modes()) = g;
    return r;
  }

 private:
  Eigen::VectorXd k_, zeta_;
};

}  // namespace aerohopf::structure
