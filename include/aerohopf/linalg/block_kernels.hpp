#pragma once
// Small dense block kernels of the hot loops (SpMV, BILU(k) triangular solves).
//
// WHY hand-written loops instead of Eigen fixed-size products: for std::complex<double> without
// -ffast-math every complex product goes through the C99 NaN/Inf-checking path (__muldc3), which
// made complex SpMV 2-3x slower than the memory traffic allows; spelling the complex product in
// real arithmetic on the interleaved (re, im) storage avoids that. Other scalars (dd_real,
// runtime block size) fall back to Eigen in the callers.
//
// The unit of work is a block ROW: acc (+|-)= sum_q A_q x_{col_q} over the consecutive blocks A_q
// of one row. A `row_accumulator` keeps the partial sums in registers across all blocks of the
// row, so the accumulator is loaded and stored once per row, not once per block.
//
// Instruction sets: with AVX2 + FMA (compile with -march=native, the CMake option
// AEROHOPF_NATIVE) the B = 4 and B = 5 kernels use 256-bit fused multiply-adds with two or more
// independent accumulators (the FMA latency, not the memory, would otherwise bound a 5 x 5 real
// block). The fused products are written as intrinsics on purpose: the library compiles with
// -ffp-contract=off (QD needs exact IEEE rounding of every operation), so the compiler never
// fuses these itself. The complex kernels accumulate A x_re and A x_im separately and combine
// them once per row with one add-subtract (no shuffles in the inner loop). Without AVX2 the
// real kernels are plain unrolled loops and the complex ones SSE2.
//
// Blocks are column-major B x B.
#include <Eigen/Core>

#include <cmath>
#include <complex>
#include <cstddef>
#include <utility>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define AEROHOPF_AVX2_BLOCK_KERNELS 1
#endif

namespace aerohopf::internal {

template <class S, int B>
inline constexpr bool has_fast_block_kernel_v =
    B != Eigen::Dynamic && (std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>);

/// Which kernel family this translation unit compiled (for benchmark labels and tests).
inline constexpr const char* block_kernel_isa() {
#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
  return "avx2-fma";
#elif defined(__SSE2__)
  return "sse2";
#else
  return "scalar";
#endif
}

#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
/// The value, kept in a register. WHY: each complex matrix column is used by two fused
/// multiply-adds (with Re x and Im x); left alone, the compiler folds the load into both, so every
/// matrix value is loaded twice and the 5 x 5 complex block is bound by the load ports (measured
/// in cache: 15.1 -> 12.8 ns per block with the single load).
template <class V>
inline V in_register(V v) {
#if defined(__GNUC__)
  __asm__("" : "+x"(v));
#endif
  return v;
}
#endif

/// The stored element type of a block whose products accumulate in S: S itself, or the single
/// precision of S (float, std::complex<float>) for factors kept in half the bytes.
template <class S>
using single_precision_t = std::conditional_t<std::is_same_v<S, std::complex<double>>, std::complex<float>, float>;
template <class S, class A>
inline constexpr bool block_storage_v = std::is_same_v<A, S> || std::is_same_v<A, single_precision_t<S>>;

// Loads of stored values into double registers: a float is widened exactly, so a kernel gives
// the same sums on a block stored in float as on that block's values held in double.
#if defined(__SSE2__)
inline __m128d load2_pd(const double* p) { return _mm_loadu_pd(p); }
inline __m128d load2_pd(const float* p) {  // two floats by a 64-bit integer load (may alias anything)
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
}
#endif
#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
inline __m256d load4_pd(const double* p) { return _mm256_loadu_pd(p); }
inline __m256d load4_pd(const float* p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }
inline __m128d load1_sd(const double* p) { return _mm_load_sd(p); }
inline __m128d load1_sd(const float* p) { return _mm_set_sd(static_cast<double>(*p)); }
#endif

/// Partial sums of one block row: add(a, x) accumulates the B x B block a times the segment x;
/// finish<Sign>(acc) does acc += Sign * sum. The block is stored in S or in its single
/// precision (block_storage_v), the sums are always in S. The primary template is the portable
/// version.
template <class S, int B>
struct row_accumulator {
  static_assert(std::is_same_v<S, double>, "row_accumulator: double and std::complex<double> only");
  double t[B] = {};
  template <class A>
  inline void add(const A* __restrict a, const double* __restrict x) {
    for (int c = 0; c < B; ++c) {
      const double xc = x[c];
      for (int r = 0; r < B; ++r) t[r] += static_cast<double>(a[c * B + r]) * xc;
    }
  }
  template <int Sign>
  inline void finish(double* __restrict acc) const {
    for (int r = 0; r < B; ++r) acc[r] += Sign > 0 ? t[r] : -t[r];
  }
};

template <int B>
struct row_accumulator<std::complex<double>, B> {
#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
  // P = sum A x_re, Q = sum A x_im on the interleaved (re, im) lanes, two block rows per 256-bit
  // register (one 128-bit register for an odd last row); A x = P + i Q, i.e.
  // (P_re - Q_im, P_im + Q_re) = addsub(P, swap(Q)), formed once per block row in finish().
  static constexpr int nv = B / 2;
  static constexpr bool odd = B % 2 != 0;
  __m256d p[nv > 0 ? nv : 1], q[nv > 0 ? nv : 1];
  __m128d p1 = _mm_setzero_pd(), q1 = _mm_setzero_pd();
  row_accumulator() {
    for (int v = 0; v < nv; ++v) p[v] = q[v] = _mm256_setzero_pd();
  }
  template <class A>
  inline void add(const A* __restrict ac, const std::complex<double>* __restrict xc) {
    const auto* a = reinterpret_cast<const typename A::value_type*>(ac);  // (re, im) pairs
    const double* x = reinterpret_cast<const double*>(xc);
    for (int c = 0; c < B; ++c) {
      const __m256d xr = _mm256_broadcast_sd(x + 2 * c), xi = _mm256_broadcast_sd(x + 2 * c + 1);
      const auto* col = a + 2 * B * c;
      for (int v = 0; v < nv; ++v) {
        const __m256d av = in_register(load4_pd(col + 4 * v));
        p[v] = _mm256_fmadd_pd(av, xr, p[v]);
        q[v] = _mm256_fmadd_pd(av, xi, q[v]);
      }
      if constexpr (odd) {
        const __m128d av = in_register(load2_pd(col + 4 * nv));
        p1 = _mm_fmadd_pd(av, _mm256_castpd256_pd128(xr), p1);
        q1 = _mm_fmadd_pd(av, _mm256_castpd256_pd128(xi), q1);
      }
    }
  }
  template <int Sign>
  inline void finish(std::complex<double>* __restrict accc) const {
    double* acc = reinterpret_cast<double*>(accc);
    for (int v = 0; v < nv; ++v) {
      const __m256d r = _mm256_addsub_pd(p[v], _mm256_permute_pd(q[v], 0x5)), o = _mm256_loadu_pd(acc + 4 * v);
      _mm256_storeu_pd(acc + 4 * v, Sign > 0 ? _mm256_add_pd(o, r) : _mm256_sub_pd(o, r));
    }
    if constexpr (odd) {
      const __m128d r = _mm_addsub_pd(p1, _mm_permute_pd(q1, 0x1)), o = _mm_loadu_pd(acc + 4 * nv);
      _mm_storeu_pd(acc + 4 * nv, Sign > 0 ? _mm_add_pd(o, r) : _mm_sub_pd(o, r));
    }
  }
#elif defined(__SSE2__)
  // one (re, im) register per block row: t += (ar, ai) * xr + (ai, ar) * (-xi, xi)
  __m128d t[B];
  row_accumulator() {
    for (int r = 0; r < B; ++r) t[r] = _mm_setzero_pd();
  }
  template <class A>
  inline void add(const A* __restrict ac, const std::complex<double>* __restrict xc) {
    const auto* a = reinterpret_cast<const typename A::value_type*>(ac);  // layout-compatible with T[2]
    const double* x = reinterpret_cast<const double*>(xc);
    for (int c = 0; c < B; ++c) {
      const __m128d xr = _mm_set1_pd(x[2 * c]);
      const __m128d xi = _mm_set_pd(x[2 * c + 1], -x[2 * c + 1]);
      for (int r = 0; r < B; ++r) {
        const __m128d av = load2_pd(a + 2 * (c * B + r));
        const __m128d as = _mm_shuffle_pd(av, av, 1);
        t[r] = _mm_add_pd(t[r], _mm_add_pd(_mm_mul_pd(av, xr), _mm_mul_pd(as, xi)));
      }
    }
  }
  template <int Sign>
  inline void finish(std::complex<double>* __restrict accc) const {
    double* acc = reinterpret_cast<double*>(accc);
    for (int r = 0; r < B; ++r) {
      const __m128d old = _mm_loadu_pd(acc + 2 * r);
      _mm_storeu_pd(acc + 2 * r, Sign > 0 ? _mm_add_pd(old, t[r]) : _mm_sub_pd(old, t[r]));
    }
  }
#else
  double re[B] = {}, im[B] = {};
  template <class A>
  inline void add(const A* __restrict ac, const std::complex<double>* __restrict xc) {
    const auto* a = reinterpret_cast<const typename A::value_type*>(ac);
    const double* x = reinterpret_cast<const double*>(xc);
    for (int c = 0; c < B; ++c) {
      const double xr = x[2 * c], xi = x[2 * c + 1];
      for (int r = 0; r < B; ++r) {
        const double ar = a[2 * (c * B + r)], ai = a[2 * (c * B + r) + 1];
        re[r] += ar * xr - ai * xi;
        im[r] += ar * xi + ai * xr;
      }
    }
  }
  template <int Sign>
  inline void finish(std::complex<double>* __restrict accc) const {
    double* acc = reinterpret_cast<double*>(accc);
    for (int r = 0; r < B; ++r) {
      acc[2 * r] += Sign > 0 ? re[r] : -re[r];
      acc[2 * r + 1] += Sign > 0 ? im[r] : -im[r];
    }
  }
#endif
};

#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
// ---- AVX2 + FMA: real 4 x 4 (one column = one register, two accumulators) -------------------
template <>
struct row_accumulator<double, 4> {
  __m256d t0 = _mm256_setzero_pd(), t1 = _mm256_setzero_pd();
  template <class A>
  inline void add(const A* __restrict a, const double* __restrict x) {
    t0 = _mm256_fmadd_pd(load4_pd(a), _mm256_broadcast_sd(x), t0);
    t1 = _mm256_fmadd_pd(load4_pd(a + 4), _mm256_broadcast_sd(x + 1), t1);
    t0 = _mm256_fmadd_pd(load4_pd(a + 8), _mm256_broadcast_sd(x + 2), t0);
    t1 = _mm256_fmadd_pd(load4_pd(a + 12), _mm256_broadcast_sd(x + 3), t1);
  }
  template <int Sign>
  inline void finish(double* __restrict acc) const {
    const __m256d s = _mm256_add_pd(t0, t1), old = _mm256_loadu_pd(acc);
    _mm256_storeu_pd(acc, Sign > 0 ? _mm256_add_pd(old, s) : _mm256_sub_pd(old, s));
  }
};

// ---- real 5 x 5: rows 0-3 of a column in a register, row 4 as a scalar fused multiply-add ----
template <>
struct row_accumulator<double, 5> {
  __m256d t0 = _mm256_setzero_pd(), t1 = _mm256_setzero_pd();
  __m128d s0 = _mm_setzero_pd(), s1 = _mm_setzero_pd();
  template <class A>
  inline void add(const A* __restrict a, const double* __restrict x) {
    const __m256d x0 = _mm256_broadcast_sd(x), x1 = _mm256_broadcast_sd(x + 1), x2 = _mm256_broadcast_sd(x + 2),
                  x3 = _mm256_broadcast_sd(x + 3), x4 = _mm256_broadcast_sd(x + 4);
    t0 = _mm256_fmadd_pd(load4_pd(a), x0, t0);
    t1 = _mm256_fmadd_pd(load4_pd(a + 5), x1, t1);
    t0 = _mm256_fmadd_pd(load4_pd(a + 10), x2, t0);
    t1 = _mm256_fmadd_pd(load4_pd(a + 15), x3, t1);
    t0 = _mm256_fmadd_pd(load4_pd(a + 20), x4, t0);
    s0 = _mm_fmadd_sd(load1_sd(a + 4), _mm256_castpd256_pd128(x0), s0);
    s1 = _mm_fmadd_sd(load1_sd(a + 9), _mm256_castpd256_pd128(x1), s1);
    s0 = _mm_fmadd_sd(load1_sd(a + 14), _mm256_castpd256_pd128(x2), s0);
    s1 = _mm_fmadd_sd(load1_sd(a + 19), _mm256_castpd256_pd128(x3), s1);
    s0 = _mm_fmadd_sd(load1_sd(a + 24), _mm256_castpd256_pd128(x4), s0);
  }
  template <int Sign>
  inline void finish(double* __restrict acc) const {
    const __m256d s = _mm256_add_pd(t0, t1), old = _mm256_loadu_pd(acc);
    _mm256_storeu_pd(acc, Sign > 0 ? _mm256_add_pd(old, s) : _mm256_sub_pd(old, s));
    const double s4 = _mm_cvtsd_f64(_mm_add_sd(s0, s1));
    acc[4] += Sign > 0 ? s4 : -s4;
  }
};

#endif  // AEROHOPF_AVX2_BLOCK_KERNELS

/// Partial sums of one block row of a REAL matrix times a COMPLEX vector: add(a, x) accumulates
/// the real B x B block a times the complex segment x; store(y) writes the sum, interleaved
/// (re, im) like std::complex. WHY: the shifted systems (A - sigma I) x of the Hopf and inverse
/// power solves have a real A; applying it to complex vectors directly streams half the bytes
/// of the assembled complex matrix. P = A Re x and Q = A Im x are accumulated in separate
/// registers (same loads as the real kernel) and interleaved once per row.
template <int B>
struct real_complex_row_accumulator {
  double re[B] = {}, im[B] = {};
  inline void add(const double* __restrict a, const std::complex<double>* __restrict xc) {
    const double* x = reinterpret_cast<const double*>(xc);
    for (int c = 0; c < B; ++c) {
      const double xr = x[2 * c], xi = x[2 * c + 1];
      for (int r = 0; r < B; ++r) {
        re[r] += a[c * B + r] * xr;
        im[r] += a[c * B + r] * xi;
      }
    }
  }
  inline void store(std::complex<double>* __restrict yc) const {
    double* y = reinterpret_cast<double*>(yc);
    for (int r = 0; r < B; ++r) {
      y[2 * r] = re[r];
      y[2 * r + 1] = im[r];
    }
  }
};

#if defined(AEROHOPF_AVX2_BLOCK_KERNELS)
// B = 4 and 5: rows 0-3 of a column in one register, times broadcast Re x_c and Im x_c; row 4 of
// the 5 x 5 block as one 128-bit (a, a) * (Re x_c, Im x_c), already interleaved. Even and odd
// columns go to separate accumulators (the FMA latency chain of a long block row).
template <int B>
  requires(B == 4 || B == 5)
struct real_complex_row_accumulator<B> {
  __m256d p[2] = {_mm256_setzero_pd(), _mm256_setzero_pd()}, q[2] = {_mm256_setzero_pd(), _mm256_setzero_pd()};
  __m128d t4[2] = {_mm_setzero_pd(), _mm_setzero_pd()};
  inline void add(const double* __restrict a, const std::complex<double>* __restrict xc) {
    const double* x = reinterpret_cast<const double*>(xc);
    for (int c = 0; c < B; ++c) {
      const int s = c & 1;
      const __m256d av = _mm256_loadu_pd(a + B * c);
      p[s] = _mm256_fmadd_pd(av, _mm256_broadcast_sd(x + 2 * c), p[s]);
      q[s] = _mm256_fmadd_pd(av, _mm256_broadcast_sd(x + 2 * c + 1), q[s]);
      if constexpr (B == 5) t4[s] = _mm_fmadd_pd(_mm_loaddup_pd(a + B * c + 4), _mm_loadu_pd(x + 2 * c), t4[s]);
    }
  }
  inline void store(std::complex<double>* __restrict yc) const {
    double* y = reinterpret_cast<double*>(yc);
    const __m256d pp = _mm256_add_pd(p[0], p[1]), qq = _mm256_add_pd(q[0], q[1]);
    const __m256d lo = _mm256_unpacklo_pd(pp, qq), hi = _mm256_unpackhi_pd(pp, qq);  // (p0 q0 p2 q2), (p1 q1 p3 q3)
    _mm256_storeu_pd(y, _mm256_permute2f128_pd(lo, hi, 0x20));
    _mm256_storeu_pd(y + 4, _mm256_permute2f128_pd(lo, hi, 0x31));
    if constexpr (B == 5) _mm_storeu_pd(y + 8, _mm_add_pd(t4[0], t4[1]));
  }
};
#endif

/// Software prefetch of the bytes [p + distance, p + distance + bytes) of a read-only stream,
/// one request per 64-byte line. WHY: in the BILU sweeps each row waits for the previous row's
/// result, which stalls the out-of-order window and with it the hardware prefetchers' lead;
/// requests issued a few kilobytes ahead keep the memory busy regardless (measured in
/// bench_linear_solver: SpMV and BILU apply on matrices larger than the last-level cache).
#ifndef AEROHOPF_PREFETCH_DISTANCE
#define AEROHOPF_PREFETCH_DISTANCE 8192
#endif
/// The tuning differs by vendor, so the kernels tell AMD from the rest at compile time by the
/// AMD-only SSE4a extension, which -march=native and -march=znverN define on every Zen (Clang 14
/// names a Zen 5 host "k8", so the __znverN__ macros miss it; GCC 12 calls it znver3).
#if !defined(AEROHOPF_AMD_TUNING) && defined(__SSE4A__)
#define AEROHOPF_AMD_TUNING 1
#endif
/// The requests are prefetcht2 (__builtin_prefetch locality 1) except on AMD, where they are
/// prefetchnta (0): on Intel server cores a non-temporal prefetch fills the first-level cache
/// only, and the sweeps ran at half the STREAM triad with it (3D b = 5 BILU(0) apply out of cache:
/// 41-48 % with prefetchnta, 81-89 % with prefetcht2, an Intel Xeon); on AMD Zen it is the better
/// one (the same kernel 89-96 % with prefetchnta, 70-87 % with prefetcht2, a Zen 5 EPYC).
#ifndef AEROHOPF_PREFETCH_LOCALITY
#if defined(AEROHOPF_AMD_TUNING)
#define AEROHOPF_PREFETCH_LOCALITY 0
#else
#define AEROHOPF_PREFETCH_LOCALITY 1
#endif
#endif
/// The SpMV of a block_sparse_matrix on vectors of its own scalar (multiply/apply) takes the same
/// prefetch, except for complex values on AMD: there no row waits for another, the out-of-order
/// window and the hardware prefetchers keep the memory busy, and the extra requests (6-7 per 5 x 5
/// complex block) cost more than they bring (3D b = 5 complex 64^3 and 100^3 on a Zen 5 EPYC:
/// 58-65 % of the STREAM triad with them, 77-85 % without), while the real SpMV still gains from
/// them. AEROHOPF_SPMV_PREFETCH_DISTANCE and AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE set them for
/// experiments (0: off).
#ifndef AEROHOPF_SPMV_PREFETCH_DISTANCE
#define AEROHOPF_SPMV_PREFETCH_DISTANCE AEROHOPF_PREFETCH_DISTANCE
#endif
#ifndef AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE
#if defined(AEROHOPF_AMD_TUNING)
#define AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE 0
#else
#define AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE AEROHOPF_PREFETCH_DISTANCE
#endif
#endif
static_assert(AEROHOPF_PREFETCH_LOCALITY >= 0 && AEROHOPF_PREFETCH_LOCALITY <= 3,
              "AEROHOPF_PREFETCH_LOCALITY must be 0 (prefetchnta), 1 (t2), 2 (t1) or 3 (t0)");
static_assert(AEROHOPF_PREFETCH_DISTANCE >= 0 && AEROHOPF_SPMV_PREFETCH_DISTANCE >= 0 &&
                  AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE >= 0,
              "the AEROHOPF_*PREFETCH_DISTANCE macros are byte distances >= 0 (0: no prefetch)");
inline constexpr std::ptrdiff_t prefetch_distance_bytes = AEROHOPF_PREFETCH_DISTANCE;
/// The own-scalar SpMV's prefetch distance for values of type S.
template <class S>
inline constexpr std::ptrdiff_t spmv_prefetch_distance_bytes =
    std::is_same_v<S, std::complex<double>> ? AEROHOPF_SPMV_COMPLEX_PREFETCH_DISTANCE : AEROHOPF_SPMV_PREFETCH_DISTANCE;
/// ... and only for matrices whose values exceed this many bytes: from cache the SpMV has no
/// memory latency to hide and the requests only cost issue slots (Intel, 3D b = 5 16^3: 95-98 %
/// of an in-cache STREAM triad without them, 75-87 % with).
inline constexpr std::size_t spmv_prefetch_min_bytes = std::size_t(24) << 20;
inline void prefetch_ahead(const void* p, std::ptrdiff_t bytes, std::ptrdiff_t distance = prefetch_distance_bytes) {
#if defined(__GNUC__)
  if (distance <= 0) return;
  const char* c = static_cast<const char*>(p) + distance;
  for (std::ptrdiff_t o = 0; o < bytes; o += 64) __builtin_prefetch(c + o, 0, AEROHOPF_PREFETCH_LOCALITY);
#else
  (void)p;
  (void)bytes;
  (void)distance;
#endif
}

/// acc += Sign * sum_{q < count} A_q x[cols[q]], the blocks A_q stored consecutively from a (in
/// S or in its single precision).
template <int Sign, int B, class S, class A>
  requires block_storage_v<S, A>
inline void block_row_gemv(const A* __restrict a, const int* __restrict cols, int count, const S* __restrict x,
                           S* __restrict acc) {
  row_accumulator<S, B> t;
  for (int q = 0; q < count; ++q) t.add(a + static_cast<std::ptrdiff_t>(q) * B * B, x + static_cast<std::ptrdiff_t>(cols[q]) * B);
  t.template finish<Sign>(acc);
}

/// acc += Sign * A x for one B x B block (stored in S or in its single precision).
template <int Sign, int B, class S, class A>
  requires block_storage_v<S, A>
inline void block_gemv(const A* __restrict a, const S* __restrict x, S* __restrict acc) {
  row_accumulator<S, B> t;
  t.add(a, x);
  t.template finish<Sign>(acc);
}

/// c += Sign * a b for B x B column-major blocks (column j of c gets a times column j of b).
template <int Sign, int B, class S>
inline void block_gemm(const S* __restrict a, const S* __restrict b, S* __restrict c) {
  for (int j = 0; j < B; ++j) block_gemv<Sign, B>(a, b + j * B, c + j * B);
}

/// Product without the C99 NaN/Inf recovery of std::complex operator* (the factorisation checks
/// finiteness itself), plain product otherwise.
template <class S>
inline S plain_mul(const S& a, const S& b) {
  if constexpr (std::is_same_v<S, std::complex<double>>)
    return {a.real() * b.real() - a.imag() * b.imag(), a.real() * b.imag() + a.imag() * b.real()};
  else return a * b;
}

/// True iff every real component of the N scalars at p is finite (complex: both parts; no
/// hypot). x * 0 is NaN iff x is NaN or Inf; four independent partial sums.
template <int N, class S>
inline bool all_finite(const S* p) {
  constexpr int m = std::is_same_v<S, std::complex<double>> ? 2 * N : N;
  const double* d = reinterpret_cast<const double*>(p);
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
  int e = 0;
  for (; e + 4 <= m; e += 4) {
    a0 += d[e] * 0.0;
    a1 += d[e + 1] * 0.0;
    a2 += d[e + 2] * 0.0;
    a3 += d[e + 3] * 0.0;
  }
  if constexpr (m % 4 != 0)
    for (; e < m; ++e) a0 += d[e] * 0.0;
  return (a0 + a1) + (a2 + a3) == 0.0;
}

/// |Re z| + |Im z| (LAPACK's cabs1): as good as the modulus for pivoting and norms, no hypot.
template <class S>
inline double cabs1(const S& z) {
  if constexpr (std::is_same_v<S, std::complex<double>>) return std::abs(z.real()) + std::abs(z.imag());
  else return std::abs(z);
}

/// In-place inverse of a B x B column-major block by Gauss-Jordan elimination with partial
/// (row) pivoting. Returns the reciprocal 1-norm condition number 1 / (||A||_1 ||A^-1||_1),
/// exact since the inverse is formed (complex entries measured by cabs1, which changes it by at
/// most a factor 2), or 0 if a pivot is exactly zero or not finite; a is then unspecified.
template <int B, class S>
inline double invert_block(S* __restrict a) {
  auto abs = [](const S& z) { return cabs1(z); };
  auto at = [a](int r, int c) -> S& { return a[c * B + r]; };
  double norm_a = 0.0;
  for (int c = 0; c < B; ++c) {
    double s = 0.0;
    for (int r = 0; r < B; ++r) s += abs(at(r, c));
    norm_a = s > norm_a ? s : norm_a;
  }
  int piv[B];
  for (int k = 0; k < B; ++k) {
    int p = k;
    double best = abs(at(k, k));
    for (int r = k + 1; r < B; ++r)
      if (abs(at(r, k)) > best) {
        best = abs(at(r, k));
        p = r;
      }
    piv[k] = p;
    if (!(best > 0.0) || !std::isfinite(best)) return 0.0;
    if (p != k)
      for (int c = 0; c < B; ++c) std::swap(at(k, c), at(p, c));
    const S inv = S(1.0) / at(k, k);
    at(k, k) = S(1.0);
    for (int c = 0; c < B; ++c) at(k, c) = plain_mul(at(k, c), inv);
    for (int r = 0; r < B; ++r) {
      if (r == k) continue;
      const S f = at(r, k);
      at(r, k) = S(0.0);
      for (int c = 0; c < B; ++c) at(r, c) -= plain_mul(f, at(k, c));
    }
  }
  // undo the row interchanges as column interchanges of the inverse, in reverse order
  for (int k = B - 1; k >= 0; --k)
    if (piv[k] != k)
      for (int r = 0; r < B; ++r) std::swap(at(r, k), at(r, piv[k]));
  double norm_inv = 0.0;
  for (int c = 0; c < B; ++c) {
    double s = 0.0;
    for (int r = 0; r < B; ++r) s += abs(at(r, c));
    norm_inv = s > norm_inv ? s : norm_inv;
  }
  const double rc = 1.0 / (norm_a * norm_inv);
  return std::isfinite(rc) ? rc : 0.0;
}

}  // namespace aerohopf::internal
