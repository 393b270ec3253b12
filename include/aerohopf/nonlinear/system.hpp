#pragma once
// The central concept of aerohopf: a parameter-dependent dynamical system dw/dt = f(w, mu).
//
// Every algorithm of nonlinear/, bifurcation/ and reduction/ is written against this concept,
// never against a particular model, so that the Hopf normal form, the tubular reactor, the
// aerofoil and the wings all go through the same Newton, Hopf and reduction code.
//
// A model provides (S is the model type):
//   using jacobian_type = Eigen::MatrixXd or Eigen::SparseMatrix<double>;
//   Eigen::Index size() const;                                   // n
//   template <class T> vec<T> residual(const vec<T>& w, const T& mu) const;
//                                  // f(w, mu); templated so double, dd_real, qd_real and
//                                  // taylor<T, K> flow through it
//   jacobian_type jacobian(const vec<double>& w, double mu) const;   // A = f_w, exact
// and optionally
//   jacobian_type approximate_jacobian(w, mu) const;   // e.g. modified-order CFD Jacobian
//   vec<double>   d_mu(w, mu) const;                   // f_mu
//   jacobian_type jacobian_d_mu(w, mu) const;          // A_mu
//   jacobian_type jacobian_directional(w, mu, v) const;// d/dt A(w + t v) at t = 0 ("A_w v")
// Missing optional members get the defaults below: f_mu and A v exactly by a taylor<double,1>
// pass through the templated residual, A_mu and A_w v by central differences of the exact
// Jacobian (step h = eps^(1/3) scaled, error O(h^2) ~ 1e-11 relative).
//
// SIGN: f is the right-hand side of the ODE (the negative of the usual CFD residual), so the
// eigenvalues of A follow the dynamical-systems convention: Re(lambda) < 0 is stable.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cmath>
#include <concepts>
#include <exception>
#include <new>
#include <string>
#include <type_traits>
#include <utility>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../scalar/jet.hpp"
#include "../scalar/taylor.hpp"

namespace aerohopf {

template <class S>
concept dynamical_system = requires(const S& s, const vec<double>& w, double mu) {
  typename S::jacobian_type;
  { s.size() } -> std::convertible_to<Eigen::Index>;
  { s.residual(w, mu) } -> std::convertible_to<vec<double>>;
  { s.jacobian(w, mu) } -> std::convertible_to<typename S::jacobian_type>;
};

/// Same as dynamical_system. Prefer the longer name in user code: under `using namespace
/// aerohopf;` the short one collides with std::system from <cstdlib>.
template <class S>
concept system = dynamical_system<S>;

/// A system whose residual can be evaluated in scalar T (dd_real, qd_real, taylor<...>).
template <class S, class T>
concept system_over = system<S> && requires(const S& s, const vec<T>& w, const T& mu) {
  { s.residual(w, mu) } -> std::convertible_to<vec<T>>;
};

template <class S>
concept has_approximate_jacobian = system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.approximate_jacobian(w, mu) } -> std::convertible_to<typename S::jacobian_type>;
};
template <class S>
concept has_d_mu = system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.d_mu(w, mu) } -> std::convertible_to<vec<double>>;
};
template <class S>
concept has_jacobian_d_mu = system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.jacobian_d_mu(w, mu) } -> std::convertible_to<typename S::jacobian_type>;
};
template <class S>
concept has_jacobian_directional =
    system<S> && requires(const S& s, const vec<double>& w, double mu, const vec<double>& v) {
      { s.jacobian_directional(w, mu, v) } -> std::convertible_to<typename S::jacobian_type>;
    };

template <system S>
using jacobian_t = typename S::jacobian_type;

namespace internal {
/// Inside a catch block: rethrows the exception being handled with `context` in front of its
/// message, keeping its aerohopf type (a foreign std::exception becomes convergence_error;
/// std::bad_alloc and non-std exceptions pass unchanged).
[[noreturn]] inline void rethrow_with_context(const std::string& context) {
  try {
    throw;
  } catch (const singular_matrix_error& e) {
    throw singular_matrix_error(context + e.what());
  } catch (const input_error& e) {
    throw input_error(context + e.what());
  } catch (const convergence_error& e) {
    throw convergence_error(context + e.what());
  } catch (const error& e) {
    throw error(context + e.what());
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw convergence_error(context + e.what());
  }
}

/// The message of the exception being handled (inside a catch block).
inline std::string current_exception_text() {
  try {
    throw;
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown exception";
  }
}
}  // namespace internal

/// Throws input_error if w has the wrong size or a non-finite entry (names the first one), or
/// if mu is not finite.
template <system S>
void check_state(const S& s, const vec<double>& w, double mu, const char* who) {
  require_size(w.size(), s.size(), who, "state");
  require(std::isfinite(mu), who, ": parameter mu is not finite (", mu, ")");
  require_finite(w, who, "state");
}

/// The approximate (left-hand-side) Jacobian if the system has one, else the exact one.
template <system S>
jacobian_t<S> lhs_jacobian(const S& s, const vec<double>& w, double mu) {
  if constexpr (has_approximate_jacobian<S>) return s.approximate_jacobian(w, mu);
  else return s.jacobian(w, mu);
}

/// Exact matrix-free product A v = d/dt f(w + t v) at t = 0 (taylor pass if the residual is
/// templated, else the assembled Jacobian).
template <system S>
vec<double> jacobian_product(const S& s, const vec<double>& w, double mu, const vec<double>& v) {
  using J = taylor<double, 1>;
  if constexpr (system_over<S, J>) {
    vec<J> wj(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) wj[i] = J::variable(w[i], v[i]);
    const vec<J> fj = s.residual(wj, J(mu));
    vec<double> r(fj.size());
    for (Eigen::Index i = 0; i < fj.size(); ++i) r[i] = fj[i][1];
    return r;
  } else {
    return s.jacobian(w, mu) * v;
  }
}

/// The exact products (A u, A v) at one state: one jet<double, 2> pass of the residual if it
/// takes jets (it costs what one taylor pass does: 7.3 ms against 15.2 ms for two on the NACA 0012
/// medium grid, measured), else two taylor passes, else one assembled Jacobian.
template <system S>
std::pair<vec<double>, vec<double>> jacobian_product_pair(const S& s, const vec<double>& w, double mu,
                                                          const vec<double>& u, const vec<double>& v) {
  using J2 = jet<double, 2>;
  if constexpr (system_over<S, J2>) {
    require(u.size() == w.size() && v.size() == w.size(), "jacobian_product_pair: directions of ", u.size(), " and ",
            v.size(), " entries for a state of ", w.size());
    vec<J2> wj(w.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) wj[i] = J2::variable(w[i], {u[i], v[i]});
    const vec<J2> fj = s.residual(wj, J2(mu));
    std::pair<vec<double>, vec<double>> r{vec<double>(fj.size()), vec<double>(fj.size())};
    for (Eigen::Index i = 0; i < fj.size(); ++i) {
      r.first[i] = fj[i].derivative(0);
      r.second[i] = fj[i].derivative(1);
    }
    return r;
  } else if constexpr (system_over<S, taylor<double, 1>>) {
    return {jacobian_product(s, w, mu, u), jacobian_product(s, w, mu, v)};
  } else {
    const auto a = s.jacobian(w, mu);
    return {vec<double>(a * u), vec<double>(a * v)};
  }
}

/// f_mu: the member if present, else exact by a taylor pass in mu, else central differences.
template <system S>
vec<double> residual_d_mu(const S& s, const vec<double>& w, double mu) {
  using J = taylor<double, 1>;
  if constexpr (has_d_mu<S>) {
    return s.d_mu(w, mu);
  } else if constexpr (system_over<S, J>) {
    vec<J> wj = w.template cast<J>();
    const vec<J> fj = s.residual(wj, J::variable(mu));
    vec<double> r(fj.size());
    for (Eigen::Index i = 0; i < fj.size(); ++i) r[i] = fj[i][1];
    return r;
  } else {
    const double h = std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, std::abs(mu));
    return (s.residual(w, mu + h) - s.residual(w, mu - h)) / (2 * h);
  }
}

/// A_mu = d A / d mu: the member if present, else central differences of the exact Jacobian.
template <system S>
jacobian_t<S> jacobian_d_mu(const S& s, const vec<double>& w, double mu) {
  if constexpr (has_jacobian_d_mu<S>) {
    return s.jacobian_d_mu(w, mu);
  } else {
    const double h = std::cbrt(Eigen::NumTraits<double>::epsilon()) * std::max(1.0, std::abs(mu));
    jacobian_t<S> d = s.jacobian(w, mu + h) - s.jacobian(w, mu - h);
    return d / (2 * h);
  }
}

/// "A_w v" = d/dt A(w + t v) at t = 0, the matrix with (A_w v) x = B(v, x): the member if
/// present, else central differences of the exact Jacobian along v.
template <system S>
jacobian_t<S> jacobian_directional(const S& s, const vec<double>& w, double mu, const vec<double>& v) {
  if constexpr (has_jacobian_directional<S>) {
    return s.jacobian_directional(w, mu, v);
  } else {
    const double vn = v.template lpNorm<Eigen::Infinity>();
    if (vn == 0) return jacobian_t<S>(s.jacobian(w, mu) * 0.0);
    const double wn = std::max(1.0, w.template lpNorm<Eigen::Infinity>());
    const double h = std::cbrt(Eigen::NumTraits<double>::epsilon()) * wn / vn;
    jacobian_t<S> d = s.jacobian(w + h * v, mu) - s.jacobian(w - h * v, mu);
    return d / (2 * h);
  }
}

}  // namespace aerohopf
