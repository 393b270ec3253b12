#pragma once
// Scalar traits shared by every layer.
//
// The residuals, Jacobians and projection operators of aerohopf are templates over the scalar
// type: double, QD's dd_real / qd_real (extended precision for finite-difference derivative
// products), taylor<T, K> (exact derivative products) and std::complex<double> (complex
// shifted systems). Generic code needs three things no single standard facility gives for all
// of them: the unit roundoff as a double, a lossless conversion to double for reporting, and a
// short printable name. They live here so that no algorithm has to special-case a type.
#include <complex>
#include <limits>
#include <string_view>
#include <type_traits>

namespace aerohopf {

/// Primary template: built-in floating point types.
template <class T, class Enable = void>
struct scalar_traits {
  static_assert(std::is_floating_point_v<T>, "aerohopf: no scalar_traits for this type");
  static constexpr std::string_view name() {
    if constexpr (std::is_same_v<T, float>) return "float";
    else if constexpr (std::is_same_v<T, double>) return "double";
    else return "long double";
  }
  /// Unit roundoff (machine epsilon) as a double.
  static constexpr double epsilon() { return static_cast<double>(std::numeric_limits<T>::epsilon()); }
  static constexpr int digits10 = std::numeric_limits<T>::digits10;
  static double to_double(const T& x) { return static_cast<double>(x); }
};

template <class T>
struct scalar_traits<std::complex<T>> {
  static constexpr std::string_view name() { return "complex"; }
  static constexpr double epsilon() { return scalar_traits<T>::epsilon(); }
  static constexpr int digits10 = scalar_traits<T>::digits10;
};

/// Leading (value) part of any scalar as a double; for a Taylor jet, its constant term.
template <class T>
double to_double(const T& x) { return scalar_traits<T>::to_double(x); }

/// The real constant v represented exactly in T (v is a double, so this is exact for every
/// supported T). Generic code writes make_constant<T>(0.5) rather than T(0.5) to stay clear
/// of QD's ambiguous int/double constructors.
template <class T>
T make_constant(double v) { return T(v); }

}  // namespace aerohopf
