#pragma once
// The result of a Hopf (flutter) point calculation, as handed to the centre-manifold reduction.
#include <Eigen/Core>

#include <complex>

#include "../linalg/direct.hpp"

namespace aerohopf {

/// A Hopf point of dw/dt = f(w, mu): f(w, mu) = 0 and A = f_w has the simple pair +-i omega.
struct hopf_point {
  vec<double> w;                        ///< equilibrium at the Hopf point
  double mu = 0;                        ///< critical parameter mu*
  double omega = 0;                     ///< critical frequency (> 0)
  vec<std::complex<double>> p;          ///< right eigenvector, A p = i omega p (any normalisation)
};

}  // namespace aerohopf
