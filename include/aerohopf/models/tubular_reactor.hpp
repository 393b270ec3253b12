#pragma once
// The non-adiabatic tubular reactor with axial mixing (spec 04), the model problem on which
// the original work developed the augmented Hopf solver and the centre-manifold reduction:
//
//   y_t  = y_xx / Pe_m - y_x - mu y exp(Gam - Gam/Th)
//   Th_t = Th_xx / Pe_h - Th_x - beta (Th - Th_bar) + mu alpha y exp(Gam - Gam/Th)
//
// on 0 < x < 1 with y_x = Pe_m (y - 1), Th_x = Pe_m (Th - 1) at x = 0 (Pe_m in both, as in the
// source) and y_x = Th_x = 0 at x = 1; mu is the Damkohler number.
//
// N cells of width h = 1/N, unknowns at cell centres interleaved per cell (w[2i] = y_i,
// w[2i+1] = Th_i) so the Jacobian is banded; central differences with one halo cell per end.
// x = 1: the halo equals the last cell. x = 0: the halo u_{-1} by one of three closures
// (u_b is the boundary value placed on the face x = 0):
//   first_order           u_b = u_0:                u_{-1} = u_0 - h Pe (u_0 - 1)
//   second_order          u_b = (u_0 + u_{-1})/2:   u_{-1} = (u_0 (2 - h Pe) + 2 h Pe)/(2 + h Pe)
//   second_order_upwind   u_b = (3 u_0 - u_1)/2:    u_{-1} = u_0 - (h Pe/2)(3 u_0 - u_1 - 2)
// second_order is the reference (the first-order closure is far from grid convergence).
//
// The residual is a template over the scalar (double, dd_real, qd_real, taylor<>); the exact
// Jacobian, f_mu, A_mu and the directional derivative A_w v are analytic (only the reaction
// term is nonlinear).
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cmath>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../scalar/traits.hpp"

namespace aerohopf {

enum class reactor_inflow { first_order = 1, second_order = 2, second_order_upwind = 3 };

struct tubular_reactor_parameters {
  double pe_m = 5.0;
  double pe_h = 5.0;
  double beta = 2.5;
  double alpha = 0.5;
  double gamma = 25.0;
  double theta_bar = 1.0;
};

class tubular_reactor {
 public:
  using jacobian_type = Eigen::SparseMatrix<double>;

  explicit tubular_reactor(int cells, reactor_inflow inflow = reactor_inflow::second_order,
                           tubular_reactor_parameters prm = {})
      : n_(cells), inflow_(inflow), prm_(prm), h_(1.0 / cells) {
    require(cells >= 3, "tubular_reactor: needs at least 3 cells, got ", cells);
    require(std::isfinite(prm.pe_m) && std::isfinite(prm.pe_h) && prm.pe_m > 0 && prm.pe_h > 0,
            "tubular_reactor: Peclet numbers must be finite and positive (got Pe_m = ", prm.pe_m, ", Pe_h = ", prm.pe_h,
            ")");
    require(std::isfinite(prm.beta) && std::isfinite(prm.alpha) && std::isfinite(prm.gamma) &&
                std::isfinite(prm.theta_bar),
            "tubular_reactor: parameters must be finite (got beta = ", prm.beta, ", alpha = ", prm.alpha,
            ", gamma = ", prm.gamma, ", theta_bar = ", prm.theta_bar, ")");
    // Halo at x = 0: u_{-1} = c0 u_0 + c1 u_1 + cc (same closure for y and Theta, Pe = Pe_m).
    const double hp = h_ * prm_.pe_m;
    switch (inflow_) {
      case reactor_inflow::first_order: c0_ = 1 - hp, c1_ = 0, cc_ = hp; break;
      case reactor_inflow::second_order: c0_ = (2 - hp) / (2 + hp), c1_ = 0, cc_ = 2 * hp / (2 + hp); break;
      case reactor_inflow::second_order_upwind: c0_ = 1 - 1.5 * hp, c1_ = 0.5 * hp, cc_ = hp; break;
      default: throw input_error("tubular_reactor: unknown inflow closure");
    }
  }

  Eigen::Index size() const { return 2 * Eigen::Index(n_); }
  int cells() const { return n_; }
  double h() const { return h_; }
  const tubular_reactor_parameters& parameters() const { return prm_; }
  reactor_inflow inflow() const { return inflow_; }
  /// Theta at x = 1 (the outflow halo equals the last cell).
  template <class T>
  T outlet_theta(const vec<T>& w) const {
    require_size(w.size(), size(), "tubular_reactor::outlet_theta", "state");
    return w[2 * n_ - 1];
  }
  /// The trivial equilibrium at mu = 0: y = Theta = 1 everywhere.
  vec<double> rest_state() const { return vec<double>::Ones(size()); }

  template <class T>
  vec<T> residual(const vec<T>& w, const T& mu) const {
    using std::exp;
    require_size(w.size(), size(), "tubular_reactor::residual", "state");
    const T gam(prm_.gamma), alpha(prm_.alpha), beta(prm_.beta), tbar(prm_.theta_bar);
    const T dm = T(1.0) / (T(prm_.pe_m) * T(h_) * T(h_)), dh = T(1.0) / (T(prm_.pe_h) * T(h_) * T(h_));
    const T c = T(1.0) / (T(2.0) * T(h_));
    vec<T> f(size());
    for (int i = 0; i < n_; ++i) {
      for (int v = 0; v < 2; ++v) {
        const T u = w[2 * i + v];
        const T up = (i + 1 < n_) ? T(w[2 * (i + 1) + v]) : u;
        const T um = (i > 0) ? T(w[2 * (i - 1) + v]) : T(T(c0_) * u + T(c1_) * w[2 + v] + T(cc_));
        const T d = v == 0 ? dm : dh;
        f[2 * i + v] = d * (up - T(2.0) * u + um) - c * (up - um);
      }
      const T y = w[2 * i], th = w[2 * i + 1];
      const T rate = mu * y * exp(gam - gam / th);
      f[2 * i] -= rate;
      f[2 * i + 1] += alpha * rate - beta * (th - tbar);
    }
    return f;
  }

  jacobian_type jacobian(const vec<double>& w, double mu) const {
    check(w, mu, "jacobian");
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(10 * n_);
    linear_part(t);
    for (int i = 0; i < n_; ++i) {
      const double y = w[2 * i], th = w[2 * i + 1];
      const double r = std::exp(prm_.gamma - prm_.gamma / th), rt = r * prm_.gamma / (th * th);
      t.emplace_back(2 * i, 2 * i, -mu * r);
      t.emplace_back(2 * i, 2 * i + 1, -mu * y * rt);
      t.emplace_back(2 * i + 1, 2 * i, mu * prm_.alpha * r);
      t.emplace_back(2 * i + 1, 2 * i + 1, mu * prm_.alpha * y * rt);
    }
    return build(t);
  }

  vec<double> d_mu(const vec<double>& w, double mu) const {
    check(w, mu, "d_mu");
    vec<double> f(size());
    for (int i = 0; i < n_; ++i) {
      const double g = w[2 * i] * std::exp(prm_.gamma - prm_.gamma / w[2 * i + 1]);
      f[2 * i] = -g;
      f[2 * i + 1] = prm_.alpha * g;
    }
    return f;
  }

  jacobian_type jacobian_d_mu(const vec<double>& w, double mu) const {
    check(w, mu, "jacobian_d_mu");
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(4 * n_);
    for (int i = 0; i < n_; ++i) {
      const double y = w[2 * i], th = w[2 * i + 1];
      const double r = std::exp(prm_.gamma - prm_.gamma / th), rt = r * prm_.gamma / (th * th);
      t.emplace_back(2 * i, 2 * i, -r);
      t.emplace_back(2 * i, 2 * i + 1, -y * rt);
      t.emplace_back(2 * i + 1, 2 * i, prm_.alpha * r);
      t.emplace_back(2 * i + 1, 2 * i + 1, prm_.alpha * y * rt);
    }
    return build(t);
  }

  /// d/dt A(w + t v): only the reaction g = y exp(Gam - Gam/Th) has second derivatives,
  /// g_yTh = r Gam/Th^2, g_ThTh = y r (Gam^2/Th^4 - 2 Gam/Th^3).
  jacobian_type jacobian_directional(const vec<double>& w, double mu, const vec<double>& v) const {
    check(w, mu, "jacobian_directional");
    require_size(v.size(), size(), "tubular_reactor::jacobian_directional", "direction");
    require_finite(v, "tubular_reactor::jacobian_directional", "direction");
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(4 * n_);
    const double g = prm_.gamma;
    for (int i = 0; i < n_; ++i) {
      const double y = w[2 * i], th = w[2 * i + 1], vy = v[2 * i], vt = v[2 * i + 1];
      const double r = std::exp(g - g / th);
      const double gyt = r * g / (th * th), gtt = y * r * (g * g / std::pow(th, 4) - 2 * g / std::pow(th, 3));
      const double dgy = gyt * vt, dgt = gyt * vy + gtt * vt;
      t.emplace_back(2 * i, 2 * i, -mu * dgy);
      t.emplace_back(2 * i, 2 * i + 1, -mu * dgt);
      t.emplace_back(2 * i + 1, 2 * i, mu * prm_.alpha * dgy);
      t.emplace_back(2 * i + 1, 2 * i + 1, mu * prm_.alpha * dgt);
    }
    return build(t);
  }

 private:
  /// The entry check of every double-valued evaluation: state of the system's size, finite,
  /// and a finite mu (a NaN would come back as a NaN matrix or vector without a word).
  void check(const vec<double>& w, double mu, const char* who) const {
    const std::string where = std::string("tubular_reactor::") + who;
    require_size(w.size(), size(), where, "state");
    require_finite(w, where, "state");
    require(std::isfinite(mu), where, ": parameter mu is not finite (", mu, ")");
  }
  jacobian_type build(const std::vector<Eigen::Triplet<double>>& t) const {
    jacobian_type a(size(), size());
    a.setFromTriplets(t.begin(), t.end());
    a.makeCompressed();
    return a;
  }
  /// Diffusion, convection, cooling and the halo chain rule.
  void linear_part(std::vector<Eigen::Triplet<double>>& t) const {
    const double c = 1.0 / (2 * h_);
    for (int v = 0; v < 2; ++v) {
      const double d = 1.0 / ((v == 0 ? prm_.pe_m : prm_.pe_h) * h_ * h_);
      const double a_minus = d + c, a_plus = d - c, a_self = -2 * d;
      for (int i = 0; i < n_; ++i) {
        const int r = 2 * i + v;
        t.emplace_back(r, r, a_self);
        if (i + 1 < n_) t.emplace_back(r, 2 * (i + 1) + v, a_plus);
        else t.emplace_back(r, r, a_plus);  // halo u_N = u_{N-1}
        if (i > 0) {
          t.emplace_back(r, 2 * (i - 1) + v, a_minus);
        } else {  // halo u_{-1} = c0 u_0 + c1 u_1 + cc
          t.emplace_back(r, r, a_minus * c0_);
          if (c1_ != 0) t.emplace_back(r, 2 + v, a_minus * c1_);
        }
      }
      if (v == 1) {
        for (int i = 0; i < n_; ++i) t.emplace_back(2 * i + 1, 2 * i + 1, -prm_.beta);
      }
    }
  }

  int n_;
  reactor_inflow inflow_;
  tubular_reactor_parameters prm_;
  double h_;
  double c0_ = 0, c1_ = 0, cc_ = 0;
};

}  // namespace aerohopf
