#pragma once
// Small dense block kernels of the hot loops (SpMV, BILU(k) triangular solves).
//
// WHY hand-written loops instead of Eigen fixed-size products: for std::complex<double> without
// -ffast-math every complex product goes through the C99 NaN/Inf-checking path (__muldc3), which
// made complex SpMV 2-3x slower than the memory traffic allows; spelling the complex product in
// real arithmetic on the interleaved (re, im) storage avoids that, and for real blocks the plain
// column loop with a compile-time B unrolls and vectorises at least as well. Other scalars
// (dd_real, runtime block size) fall back to Eigen.
//
// Blocks are column-major B x B; acc (+|-)= A x.
#include <Eigen/Core>

#include <complex>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace aerohopf::internal {

template <class S, int B>
inline constexpr bool has_fast_block_kernel_v =
    B != Eigen::Dynamic && (std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>);

/// acc += sign * A x for a B x B column-major block a (Sign = +1 or -1).
template <int Sign, int B>
inline void block_gemv(const double* __restrict a, const double* __restrict x, double* __restrict acc) {
  double t[B] = {};
  for (int c = 0; c < B; ++c) {
    const double xc = x[c];
    for (int r = 0; r < B; ++r) t[r] += a[c * B + r] * xc;
  }
  for (int r = 0; r < B; ++r) acc[r] += Sign > 0 ? t[r] : -t[r];
}

template <int Sign, int B>
inline void block_gemv(const std::complex<double>* __restrict ac, const std::complex<double>* __restrict xc,
                       std::complex<double>* __restrict accc) {
  // std::complex<double> is layout-compatible with double[2]
  const double* a = reinterpret_cast<const double*>(ac);
  const double* x = reinterpret_cast<const double*>(xc);
  double* acc = reinterpret_cast<double*>(accc);
#if defined(__SSE2__)
  // one (re, im) register per block row: t += (ar, ai) * xr + (ai, ar) * (-xi, xi)
  __m128d t[B];
  for (int r = 0; r < B; ++r) t[r] = _mm_setzero_pd();
  for (int c = 0; c < B; ++c) {
    const __m128d xr = _mm_set1_pd(x[2 * c]);
    const __m128d xi = _mm_set_pd(x[2 * c + 1], -x[2 * c + 1]);
    for (int r = 0; r < B; ++r) {
      const __m128d av = _mm_loadu_pd(a + 2 * (c * B + r));
      const __m128d as = _mm_shuffle_pd(av, av, 1);
      t[r] = _mm_add_pd(t[r], _mm_add_pd(_mm_mul_pd(av, xr), _mm_mul_pd(as, xi)));
    }
  }
  for (int r = 0; r < B; ++r) {
    const __m128d old = _mm_loadu_pd(acc + 2 * r);
    _mm_storeu_pd(acc + 2 * r, Sign > 0 ? _mm_add_pd(old, t[r]) : _mm_sub_pd(old, t[r]));
  }
#else
  double re[B] = {}, im[B] = {};
  for (int c = 0; c < B; ++c) {
    const double xr = x[2 * c], xi = x[2 * c + 1];
    for (int r = 0; r < B; ++r) {
      const double ar = a[2 * (c * B + r)], ai = a[2 * (c * B + r) + 1];
      re[r] += ar * xr - ai * xi;
      im[r] += ar * xi + ai * xr;
    }
  }
  for (int r = 0; r < B; ++r) {
    acc[2 * r] += Sign > 0 ? re[r] : -re[r];
    acc[2 * r + 1] += Sign > 0 ? im[r] : -im[r];
  }
#endif
}

}  // namespace aerohopf::internal
