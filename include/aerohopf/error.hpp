#pragma once
// Exceptions thrown by aerohopf. Every solver that fails says what failed, at which iterate and
// with which residual; every check of user input names the offending entry. Nothing the user
// passed in is modified before such a check has passed.
#include <cmath>
#include <complex>
#include <cstddef>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace aerohopf {

/// Base of all aerohopf exceptions.
struct error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Malformed or inconsistent input (sizes, NaN in a state, bad grid, negative volumes...).
struct input_error : error {
  using error::error;
};

/// An iterative method did not converge, diverged, or produced a non-finite iterate.
struct convergence_error : error {
  using error::error;
};

/// A (block) pivot or factorisation broke down: singular or non-finite matrix.
struct singular_matrix_error : error {
  using error::error;
};

namespace internal {
/// One argument of concat, by its decayed type: a string literal is a const char*, so the
/// stream insertion (an overload resolution over every operator<< in scope) is instantiated
/// once per type, not once per literal length and argument list (hundreds of messages).
template <class T>
void put_one(std::ostream& os, const T& x) {
  os << x;
}

template <class... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  os.precision(10);
  (put_one<std::decay_t<const Args>>(os, args), ...);
  return os.str();
}
}  // namespace internal

/// Throws input_error("context: what") unless cond holds.
template <class... Args>
void require(bool cond, const Args&... args) {
  if (!cond) throw input_error(internal::concat(args...));
}

/// The one size check of every public entry point that takes a state, a vector or an operator:
/// throws input_error("<where>: <what> has <got> entries, expected <expected>") unless they
/// match. Written once so that every refusal reads the same and none is forgotten in Release
/// builds, where Eigen's own assertions are off.
template <class I, class J>
void require_size(I got, J expected, std::string_view where, std::string_view what) {
  if (static_cast<long long>(got) != static_cast<long long>(expected))
    throw input_error(internal::concat(where, ": ", what, " has ", static_cast<long long>(got), " entries, expected ",
                                       static_cast<long long>(expected)));
}

namespace internal {
template <class T>
bool is_finite_value(const T& x) {
  using std::isfinite;
  if constexpr (requires { x.real(); x.imag(); })
    return is_finite_value(x.real()) && is_finite_value(x.imag());
  else
    return isfinite(x);
}
}  // namespace internal

/// Throws input_error naming the first non-finite entry of v (any container with size() and
/// operator[] or operator() over double or std::complex<double>).
template <class V>
void require_finite(const V& v, std::string_view where, std::string_view what) {
  const auto n = static_cast<long long>(v.size());
  for (long long i = 0; i < n; ++i) {
    const auto& x = v[static_cast<decltype(v.size())>(i)];
    if (!internal::is_finite_value(x))
      throw input_error(internal::concat(where, ": ", what, " entry ", i, " of ", n, " is not finite (", x, ")"));
  }
}

}  // namespace aerohopf
