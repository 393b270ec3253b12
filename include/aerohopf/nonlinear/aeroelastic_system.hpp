#pragma once
// aeroelastic_system: a dynamical_system (system.hpp) whose state is a flow part followed by a
// structural part bordered onto it,
//     w = [w_f (flow_size() entries), w_s (structure_size() entries)],  size() = their sum.
//
// Why a concept of its own: the structural unknowns are what identifies an aeroelastic mode.
// The flow part of an eigenvector is no test of "the same mode" (a moving shock rotates it far
// from its neighbour's on one branch), its structural part is; so the mode test of natural
// continuation in a second parameter, the V-g tracking and the flutter-boundary driver compare
// structural parts, and with this concept they do it for any model (aerofoil, wing) instead of
// knowing where a particular model keeps them.
//
// A model provides, besides dynamical_system:
//   Eigen::Index flow_size() const;        // entries of the flow part (first)
//   Eigen::Index structure_size() const;   // entries of the structural part (last, > 0)
//   template <class T> vec<T> structure_part(const vec<T>& v) const;
//       // the structural entries of a state or eigenvector v of size() entries, in any scalar
//       // (double states, complex eigenvectors); refuses a v of another size.
#include <Eigen/Core>

#include <cmath>
#include <complex>
#include <concepts>
#include <string>

#include "../error.hpp"
#include "../scalar/traits.hpp"
#include "system.hpp"

namespace aerohopf {

template <class S>
concept aeroelastic_system =
    dynamical_system<S> &&
    requires(const S& s, const vec<double>& w, const vec<std::complex<double>>& z) {
      { s.flow_size() } -> std::convertible_to<Eigen::Index>;
      { s.structure_size() } -> std::convertible_to<Eigen::Index>;
      { s.structure_part(w) } -> std::convertible_to<vec<double>>;
      { s.structure_part(z) } -> std::convertible_to<vec<std::complex<double>>>;
    };

/// Throws input_error unless the layout is [flow, structure] with structure_size() > 0,
/// flow_size() >= 0 and flow_size() + structure_size() == size() (who names the caller).
template <aeroelastic_system S>
void check_aeroelastic_layout(const S& s, const std::string& who) {
  const Eigen::Index nf = s.flow_size(), ns = s.structure_size(), n = s.size();
  require(nf >= 0 && ns > 0 && nf + ns == n, who, ": aeroelastic layout of ", nf, " flow and ", ns,
          " structural entries does not make up the system's ", n, " unknowns");
}

/// Size and finiteness of a state w (size n: nf flow entries in cells of nv, then the structure)
/// and of the parameter, in any scalar (for a jet or Taylor number: its value), before a model
/// moves its grid with them: a NaN structural state would give NaN metrics and a NaN residual
/// without a word. input_error names `who`, the entry and its flow cell or structural unknown.
template <class T>
void require_finite_aeroelastic_state(const vec<T>& w, const T& mu, Eigen::Index n, Eigen::Index nf, int nv,
                                      const char* who, const char* parameter) {
  require_size(w.size(), n, who, "state");
  const double m = to_double(mu);
  require(std::isfinite(m), who, ": parameter ", parameter, " is not finite (", m, ")");
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    const double x = to_double(w[i]);
    if (!std::isfinite(x))
      throw input_error(internal::concat(who, ": state entry ", i, " of ", w.size(), " is not finite (", x, ")",
                                         i < nf ? internal::concat(", flow cell ", i / nv)
                                                : internal::concat(", structural unknown ", i - nf)));
  }
}

/// |a^H b| / (||a|| ||b||) of two structural parts: 1 for the same structural shape up to a
/// complex factor, 0 if either is zero. The one mode test of the library (structural_overlap,
/// the flutter-boundary driver, the V-g tracking).
template <class T>
double structural_cosine(const vec<T>& a, const vec<T>& b) {
  require(a.size() == b.size(), "structural_cosine: structural parts of sizes ", a.size(), " and ", b.size());
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0) || !(nb > 0)) return 0.0;
  using std::abs;
  return abs(a.dot(b)) / (na * nb);
}

/// structural_cosine of the structural parts of two vectors (states or eigenvectors) of the system.
template <aeroelastic_system S, class T>
double structural_overlap(const S& s, const vec<T>& a, const vec<T>& b) {
  return structural_cosine<T>(s.structure_part(a), s.structure_part(b));
}

}  // namespace aerohopf
