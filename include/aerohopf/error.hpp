#pragma once
// Exceptions thrown by aerohopf. Every solver that fails says what failed, at which iterate and
// with which residual; every check of user input names the offending entry. Nothing the user
// passed in is modified before such a check has passed.
#include <sstream>
#include <stdexcept>
#include <string>

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
template <class... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  os.precision(10);
  (os << ... << args);
  return os.str();
}
}  // namespace internal

/// Throws input_error("context: what") unless cond holds.
template <class... Args>
void require(bool cond, const Args&... args) {
  if (!cond) throw input_error(internal::concat(args...));
}

}  // namespace aerohopf
