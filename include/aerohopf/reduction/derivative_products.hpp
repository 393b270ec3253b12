#pragma once
// Second and third derivative products B(v, v), C(v, v, v) of f at an equilibrium (w0, mu),
// without ever forming a second- or third-derivative tensor (spec 03, "Derivative products
// without the matrices").
//
// Two interchangeable providers compute the two basic products for a REAL direction v:
//  * fd_products<T>{h}: the finite differences of spec 03 along w0 + l h v,
//        B(v, v)    = [R_1 - 2 R_0 + R_-1] / h^2                                  + O(h^2)
//        C(v, v, v) = [-R_3 + 8 R_2 - 13 R_1 + 13 R_-1 - 8 R_-2 + R_-3] / (8 h^3) + O(h^4)
//    evaluated in scalar T (double, dd_real, qd_real). w0, v, h and mu are converted to T
//    exactly; only the final product is rounded to double. This is the route of the original
//    work (double loses most digits of C; dd/qd keep them over a wide range of h).
//  * taylor_products<T>: one pass of the residual on the jet w0 + t v (taylor<T, 3>); the t,
//    t^2, t^3 coefficients are A v, B(v, v)/2, C(v, v, v)/6 exactly (to rounding in T).
// A provider is any type with
//    vec<double> second(const S&, const vec<double>& w0, double mu, const vec<double>& v) const;
//    vec<double> third (const S&, const vec<double>& w0, double mu, const vec<double>& v) const;
//
// derivative_products<S, Provider> binds system, equilibrium and provider and builds every
// product the centre-manifold coefficients need from those two by polarisation (spec 03),
// handing the provider unit-norm directions only (so h is a step along a unit vector):
//    B(v, u)    = 1/4 [B(v+u, v+u) - B(v-u, v-u)]
//    C(v, v, u) = 1/6 [C(v+u)^3 - C(v-u)^3 - 2 C(u, u, u)]
// and, for complex p = a + i b, k = c + i d (B, C are real multilinear forms),
//    B(p, k)         = B(a, c) - B(b, d) + i [B(a, d) + B(b, c)]
//    B(p, conj p)    = B(a, a) + B(b, b),     B(p, p) = B(a, a) - B(b, b) + 2 i B(a, b)
//    C(p, p, conj p) = C(a,a,a) + C(a,b,b) + i [C(a,a,b) + C(b,b,b)]
// with C(a,a,b), C(a,b,b) from the four cubes C(a), C(b), C(a+b), C(a-b).
#include <Eigen/Core>

#include <complex>
#include <concepts>
#include <string>

#include "../error.hpp"
#include "../nonlinear/system.hpp"
#include "../scalar/qd.hpp"
#include "../scalar/taylor.hpp"
#include "../scalar/traits.hpp"

namespace aerohopf {

/// The three products one jet pass gives: A v, B(v, v), C(v, v, v).
struct jet_products {
  vec<double> a_v, b_vv, c_vvv;
};

namespace internal {
template <class T>
vec<T> to_scalar(const vec<double>& x) {
  vec<T> r(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) r[i] = make_constant<T>(x[i]);
  return r;
}
template <class T>
vec<double> to_double_vec(const vec<T>& x) {
  vec<double> r(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) r[i] = to_double(x[i]);
  return r;
}
template <class S>
void check_direction(const S& s, const vec<double>& w0, double mu, const vec<double>& v, const char* who) {
  check_state(s, w0, mu, who);
  require(v.size() == s.size(), who, ": direction has ", v.size(), " entries, system has ", s.size());
  for (Eigen::Index i = 0; i < v.size(); ++i)
    require(std::isfinite(v[i]), who, ": direction entry ", i, " is not finite (", v[i], ")");
}
}  // namespace internal

/// Finite-difference products in scalar T with step h along v (absolute: points w0 + l h v).
template <class T = qd_real>
struct fd_products {
  double h = 1e-6;

  std::string name() const { return "fd<" + std::string(scalar_traits<T>::name()) + ">"; }

  /// The state w0 + l h v in T (w0, v, h exact in T).
  template <class S>
  vec<T> residual_at(const S& s, const vec<T>& w0, const T& mu, const vec<T>& v, int l) const {
    const T step = make_constant<T>(static_cast<double>(l)) * make_constant<T>(h);
    vec<T> w(w0.size());
    for (Eigen::Index i = 0; i < w0.size(); ++i) w[i] = w0[i] + step * v[i];
    return s.residual(w, mu);
  }

  template <dynamical_system S>
    requires system_over<S, T>
  vec<double> second(const S& s, const vec<double>& w0, double mu, const vec<double>& v) const {
    internal::check_direction(s, w0, mu, v, "fd_products::second");
    require(std::isfinite(h) && h > 0, "fd_products: step h must be positive and finite (got ", h, ")");
    const vec<T> wt = internal::to_scalar<T>(w0), vt = internal::to_scalar<T>(v);
    const T mt = make_constant<T>(mu), ht = make_constant<T>(h);
    const vec<T> r1 = residual_at(s, wt, mt, vt, 1), r0 = residual_at(s, wt, mt, vt, 0),
                 rm1 = residual_at(s, wt, mt, vt, -1);
    const T h2 = ht * ht, two = make_constant<T>(2.0);
    vec<T> b(r0.size());
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = (r1[i] - two * r0[i] + rm1[i]) / h2;
    return internal::to_double_vec(b);
  }

  template <dynamical_system S>
    requires system_over<S, T>
  vec<double> third(const S& s, const vec<double>& w0, double mu, const vec<double>& v) const {
    internal::check_direction(s, w0, mu, v, "fd_products::third");
    require(std::isfinite(h) && h > 0, "fd_products: step h must be positive and finite (got ", h, ")");
    const vec<T> wt = internal::to_scalar<T>(w0), vt = internal::to_scalar<T>(v);
    const T mt = make_constant<T>(mu), ht = make_constant<T>(h);
    const vec<T> r3 = residual_at(s, wt, mt, vt, 3), r2 = residual_at(s, wt, mt, vt, 2),
                 r1 = residual_at(s, wt, mt, vt, 1), rm1 = residual_at(s, wt, mt, vt, -1),
                 rm2 = residual_at(s, wt, mt, vt, -2), rm3 = residual_at(s, wt, mt, vt, -3);
    const T eight = make_constant<T>(8.0), thirteen = make_constant<T>(13.0);
    const T denom = eight * ht * ht * ht;
    vec<T> c(r1.size());
    for (Eigen::Index i = 0; i < c.size(); ++i)
      c[i] = (-r3[i] + eight * r2[i] - thirteen * r1[i] + thirteen * rm1[i] - eight * rm2[i] + rm3[i]) / denom;
    return internal::to_double_vec(c);
  }
};

/// Exact products by one residual pass on the jet w0 + t v in taylor<T, 3>.
template <class T = double>
struct taylor_products {
  using jet = taylor<T, 3>;

  std::string name() const { return "taylor<" + std::string(scalar_traits<T>::name()) + ">"; }

  template <dynamical_system S>
    requires system_over<S, jet>
  jet_products products(const S& s, const vec<double>& w0, double mu, const vec<double>& v) const {
    internal::check_direction(s, w0, mu, v, "taylor_products");
    vec<jet> w(w0.size());
    for (Eigen::Index i = 0; i < w0.size(); ++i) w[i] = jet::variable(make_constant<T>(w0[i]), make_constant<T>(v[i]));
    const vec<jet> f = s.residual(w, jet(make_constant<T>(mu)));
    jet_products r{vec<double>(f.size()), vec<double>(f.size()), vec<double>(f.size())};
    const T two = make_constant<T>(2.0), six = make_constant<T>(6.0);
    for (Eigen::Index i = 0; i < f.size(); ++i) {
      r.a_v[i] = to_double(f[i][1]);
      r.b_vv[i] = to_double(T(two * f[i][2]));
      r.c_vvv[i] = to_double(T(six * f[i][3]));
    }
    return r;
  }
  template <dynamical_system S>
    requires system_over<S, jet>
  vec<double> second(const S& s, const vec<double>& w0, double mu, const vec<double>& v) const {
    return products(s, w0, mu, v).b_vv;
  }
  template <dynamical_system S>
    requires system_over<S, jet>
  vec<double> third(const S& s, const vec<double>& w0, double mu, const vec<double>& v) const {
    return products(s, w0, mu, v).c_vvv;
  }
};

/// A type that gives B(v, v) and C(v, v, v) of system S (fd_products, taylor_products, ...).
template <class P, class S>
concept derivative_product_provider =
    dynamical_system<S> && requires(const P& p, const S& s, const vec<double>& w, double mu, const vec<double>& v) {
      { p.second(s, w, mu, v) } -> std::convertible_to<vec<double>>;
      { p.third(s, w, mu, v) } -> std::convertible_to<vec<double>>;
    };

/// Every derivative product of f at (w0, mu) that the reduction needs, from one provider.
template <dynamical_system S, class Provider>
  requires derivative_product_provider<Provider, S>
class derivative_products {
 public:
  using cvec = vec<std::complex<double>>;

  derivative_products(const S& s, const vec<double>& w0, double mu, Provider provider = {})
      : s_(s), w0_(w0), mu_(mu), provider_(std::move(provider)) {
    check_state(s, w0, mu, "derivative_products");
  }

  const Provider& provider() const { return provider_; }
  /// Number of B(v, v) and C(v, v, v) evaluations so far (the cost measure).
  int second_evaluations() const { return n_second_; }
  int third_evaluations() const { return n_third_; }

  // ---- real directions ----
  // Every direction must have the system's size (input_error otherwise): the polarisation sums
  // v +- u of vectors of different sizes would read past the shorter one. Non-finite entries
  // are refused by the provider (check_direction).
  // Every direction handed to the provider is scaled to unit 2-norm first (B(v, v) =
  // |v|^2 B(v^, v^), ...), so a finite-difference step h always means the same thing, however
  // large or small the vectors of the reduction are (k11, w0_mu can be O(1e3) near a fold).
  vec<double> B(const vec<double>& v) const {
    require_size(v.size(), s_.size(), "derivative_products::B", "direction v");
    const double nv = v.norm();
    if (nv == 0) return vec<double>::Zero(v.size());
    ++n_second_;
    return (nv * nv) * provider_.second(s_, w0_, mu_, vec<double>(v / nv));
  }
  vec<double> B(const vec<double>& v, const vec<double>& u) const {
    require_size(v.size(), s_.size(), "derivative_products::B(v, u)", "direction v");
    require_size(u.size(), s_.size(), "derivative_products::B(v, u)", "direction u");
    const double nv = v.norm(), nu = u.norm();
    if (nv == 0 || nu == 0) return vec<double>::Zero(v.size());
    const vec<double> vh = v / nv, uh = u / nu;
    return (0.25 * nv * nu) * (B(vec<double>(vh + uh)) - B(vec<double>(vh - uh)));
  }
  vec<double> C(const vec<double>& v) const {
    require_size(v.size(), s_.size(), "derivative_products::C", "direction v");
    const double nv = v.norm();
    if (nv == 0) return vec<double>::Zero(v.size());
    ++n_third_;
    return (nv * nv * nv) * provider_.third(s_, w0_, mu_, vec<double>(v / nv));
  }
  /// C(v, v, u).
  vec<double> C_vvu(const vec<double>& v, const vec<double>& u) const {
    require_size(v.size(), s_.size(), "derivative_products::C_vvu", "direction v");
    require_size(u.size(), s_.size(), "derivative_products::C_vvu", "direction u");
    const double nv = v.norm(), nu = u.norm();
    if (nv == 0 || nu == 0) return vec<double>::Zero(v.size());
    const vec<double> vh = v / nv, uh = u / nu;
    return (nv * nv * nu / 6.0) * (C(vec<double>(vh + uh)) - C(vec<double>(vh - uh)) - 2.0 * C(uh));
  }

  // ---- complex directions (B, C are real forms extended bilinearly, no conjugation) ----
  /// B(p, k); real parts skip the products that vanish (B(a, d) = 0 for real k, ...).
  cvec B(const cvec& p, const cvec& k) const {
    require_size(p.size(), s_.size(), "derivative_products::B(p, k)", "direction p");
    require_size(k.size(), s_.size(), "derivative_products::B(p, k)", "direction k");
    const vec<double> a = p.real(), b = p.imag(), c = k.real(), d = k.imag();
    const bool p_real = b.isZero(0.0), k_real = d.isZero(0.0);
    const vec<double> zero = vec<double>::Zero(a.size());
    cvec r(a.size());
    r.real() = B(a, c) - (p_real || k_real ? zero : B(b, d));
    r.imag() = (k_real ? zero : B(a, d)) + (p_real ? zero : B(b, c));
    return r;
  }
  /// B(p, p) = B(a, a) - B(b, b) + 2 i B(a, b).
  cvec B_pp(const cvec& p) const {
    require_size(p.size(), s_.size(), "derivative_products::B_pp", "direction p");
    const vec<double> a = p.real(), b = p.imag();
    cvec r(a.size());
    r.real() = B(a) - B(b);
    r.imag() = 2.0 * B(a, b);
    return r;
  }
  /// B(p, conj p) = B(a, a) + B(b, b) (real).
  vec<double> B_ppbar(const cvec& p) const {
    require_size(p.size(), s_.size(), "derivative_products::B_ppbar", "direction p");
    const vec<double> a = p.real(), b = p.imag();
    return B(a) + B(b);
  }
  /// C(p, p, conj p) = C(a,a,a) + C(a,b,b) + i [C(a,a,b) + C(b,b,b)].
  cvec C_ppbar(const cvec& p) const {
    require_size(p.size(), s_.size(), "derivative_products::C_ppbar", "direction p");
    const vec<double> a = p.real(), b = p.imag();
    const vec<double> caaa = C(a), cbbb = C(b), cplus = C((a + b).eval()), cminus = C((a - b).eval());
    const vec<double> caab = (cplus - cminus - 2.0 * cbbb) / 6.0;
    const vec<double> cabb = (cplus + cminus - 2.0 * caaa) / 6.0;
    cvec r(a.size());
    r.real() = caaa + cabb;
    r.imag() = caab + cbbb;
    return r;
  }

 private:
  const S& s_;
  vec<double> w0_;
  double mu_;
  Provider provider_;
  mutable int n_second_ = 0, n_third_ = 0;
};

}  // namespace aerohopf
