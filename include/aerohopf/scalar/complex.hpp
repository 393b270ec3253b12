#pragma once
// Helpers for complex scalars: the complex shifted systems A - i omega I of inverse power and
// of the centre-manifold solves, and the conjugating inner product <q, v> = sum conj(q_i) v_i
// used throughout (Kuznetsov's convention).
#include <Eigen/Core>

#include <complex>
#include <type_traits>

namespace aerohopf {

template <class T>
struct is_complex : std::false_type {};
template <class T>
struct is_complex<std::complex<T>> : std::true_type {};
template <class T>
inline constexpr bool is_complex_v = is_complex<T>::value;

/// Real type underlying a real or complex scalar.
template <class T>
using real_of_t = typename Eigen::NumTraits<T>::Real;

/// <q, v> = sum_i conj(q_i) v_i (Eigen's dot() already conjugates its first argument).
template <class DerivedQ, class DerivedV>
auto inner(const Eigen::MatrixBase<DerivedQ>& q, const Eigen::MatrixBase<DerivedV>& v) {
  return q.dot(v);
}

}  // namespace aerohopf
