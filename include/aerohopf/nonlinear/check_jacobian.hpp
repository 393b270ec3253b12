#pragma once
// check_jacobian(sys, w, mu): are the assembled Jacobians of a system the derivative of its
// residual? (the analogue of PETSc's -snes_test_jacobian, without its finite differences)
//
// The reference is exact: the directional derivatives f'(w) v of the templated residual along
// a few seeded random directions v, all of them in one residual pass with jet<double, 4> (or,
// for a residual that does not take jets, one taylor<double, 1> pass per direction). Each
// matrix A the system offers is compared through the products A v:
//   relative_error      = max_v ||A v - f'(w) v||_2 / ||f'(w) v||_2   (norm-wise), and
//   componentwise_error = max_v max_i |A v - f'(w) v|_i / ((|A| |v|)_i + |f'(w) v|_i),
// the second being what finds ONE wrong entry in a large matrix: the norm-wise error of an
// entry wrong by delta is delta |A_ij v_j| / ||A v||, swamped by the other rows, whereas its
// row's componentwise error is about delta |A_ij| / sum_j |A_ij| whatever the size. An exact
// Jacobian gives both at rounding level (a few 1e-16 times the cancellation in the residual);
// an approximate one (a modified-order CFD Jacobian) differs at O(1) componentwise. Random
// directions hit every entry: an entry can only escape if a v_j is zero.
// Checked, when the system has them: jacobian (always), approximate_jacobian,
// block_jacobians (the (exact, approximate) block pair, models::aerofoil_system), the bordered
// pair of the Krylov path (bordered_jacobians: models::aerofoil_system, models::wing_system), d_mu (against
// a taylor<double, 1> pass in mu). Absent members are reported with present = false.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "../error.hpp"
#include "../linalg/direct.hpp"
#include "../scalar/jet.hpp"
#include "../scalar/taylor.hpp"
#include "system.hpp"

namespace aerohopf {

struct jacobian_check_options {
  int probes = 3;              ///< random directions v (>= 1)
  std::uint64_t seed = 1;      ///< of the directions (splitmix64: the same on every platform)
  bool approximate = true;     ///< check approximate_jacobian if the system has one
  bool blocks = true;          ///< check block_jacobians / bordered_jacobians if the system has them
  bool d_mu = true;            ///< check d_mu if the system has it
};

/// The comparison of one matrix (or of d_mu) with the exact directional derivatives.
struct jacobian_check_entry {
  std::string name;
  bool present = false;              ///< the system has this member (else nothing was checked)
  double relative_error = 0.0;       ///< max over probes of ||A v - f' v||_2 / ||f' v||_2
  double componentwise_error = 0.0;  ///< max over probes and rows (file comment)
  Eigen::Index worst_row = -1;       ///< row of the largest componentwise error (-1: no error at all)
  int worst_probe = -1;              ///< its probe
  double reference_norm = 0.0;       ///< min over probes of ||f' v||_2 (the scale of the products)
};

struct jacobian_check_report {
  int probes = 0;
  jacobian_check_entry exact{"jacobian"}, approximate{"approximate_jacobian"},
      block_exact{"block_jacobians (exact)"}, block_approximate{"block_jacobians (approximate)"},
      bordered_exact{"bordered_jacobians (exact)"}, bordered_approximate{"bordered_jacobians (preconditioning)"},
      d_mu{"d_mu"};

  friend std::ostream& operator<<(std::ostream& os, const jacobian_check_report& r) {
    os << "check_jacobian (" << r.probes << " random directions):\n";
    for (const auto* e : {&r.exact, &r.approximate, &r.block_exact, &r.block_approximate, &r.bordered_exact,
                          &r.bordered_approximate, &r.d_mu}) {
      os << "  " << e->name << ": ";
      if (!e->present) {
        os << "not provided or not checked\n";
        continue;
      }
      os << "||A v - f'v|| / ||f'v|| = " << e->relative_error << ", componentwise " << e->componentwise_error;
      if (e->worst_row >= 0) os << " (row " << e->worst_row << ", direction " << e->worst_probe << ")";
      os << "\n";
    }
    return os;
  }
};

template <class S>
concept has_block_jacobian_pair = system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.block_jacobians(w, mu).first.to_sparse() } -> std::convertible_to<Eigen::SparseMatrix<double>>;
  { s.block_jacobians(w, mu).second.to_sparse() } -> std::convertible_to<Eigen::SparseMatrix<double>>;
};

/// A system with the bordered pair of the Krylov path (nonlinear/block_system.hpp's
/// bordered_system, stated here without its header).
template <class S>
concept has_bordered_jacobian_pair = system<S> && requires(const S& s, const vec<double>& w, double mu) {
  { s.bordered_jacobians(w, mu).exact.to_sparse() } -> std::convertible_to<Eigen::SparseMatrix<double>>;
  { s.bordered_jacobians(w, mu).preconditioning.to_sparse() } -> std::convertible_to<Eigen::SparseMatrix<double>>;
};

namespace internal {

/// Uniform in [-1, 1) from splitmix64 (std:: distributions differ between libraries).
inline double check_uniform(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return 2.0 * (static_cast<double>(z >> 11) * 0x1.0p-53) - 1.0;
}

/// f'(w) v for every column v of dirs, exactly: jet<double, 4> passes (4 directions each), or
/// one taylor<double, 1> pass per direction if the residual does not take jets.
template <system S>
Eigen::MatrixXd exact_directional_derivatives(const S& sys, const vec<double>& w, double mu,
                                              const Eigen::MatrixXd& dirs) {
  constexpr int P = 4;
  using J = jet<double, P>;
  using K = taylor<double, 1>;
  const Eigen::Index n = w.size();
  Eigen::MatrixXd out(n, dirs.cols());
  if constexpr (system_over<S, J>) {
    for (Eigen::Index c0 = 0; c0 < dirs.cols(); c0 += P) {
      vec<J> wj(n);
      for (Eigen::Index i = 0; i < n; ++i) {
        std::array<double, P> d{};
        for (int k = 0; k < P && c0 + k < dirs.cols(); ++k) d[k] = dirs(i, c0 + k);
        wj[i] = J::variable(w[i], d);
      }
      const vec<J> fj = sys.residual(wj, J(mu));
      require_size(fj.size(), n, "check_jacobian", "residual (jet pass)");
      for (int k = 0; k < P && c0 + k < dirs.cols(); ++k)
        for (Eigen::Index i = 0; i < n; ++i) out(i, c0 + k) = fj[i].derivative(k);
    }
  } else {
    static_assert(system_over<S, K>,
                  "check_jacobian needs a residual templated on the scalar (jet<double, 4> or taylor<double, 1>)");
    for (Eigen::Index c = 0; c < dirs.cols(); ++c) {
      vec<K> wj(n);
      for (Eigen::Index i = 0; i < n; ++i) wj[i] = K::variable(w[i], dirs(i, c));
      const vec<K> fj = sys.residual(wj, K(mu));
      require_size(fj.size(), n, "check_jacobian", "residual (taylor pass)");
      for (Eigen::Index i = 0; i < n; ++i) out(i, c) = fj[i][1];
    }
  }
  return out;
}

/// Fills e from the products av (A v) and the magnitudes mag (|A| |v|) of one probe.
inline void accumulate_check(jacobian_check_entry& e, int probe, const vec<double>& av, const vec<double>& mag,
                             const vec<double>& ref) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const vec<double> diff = av - ref;
  const double rn = ref.norm(), dn = diff.norm();
  // 0 / 0 = 0 (both zero); d / 0 = inf; a non-finite product is an infinite error
  const double rel = !std::isfinite(dn) ? inf : dn == 0.0 ? 0.0 : dn / rn;
  e.relative_error = std::max(e.relative_error, rel);
  e.reference_norm = e.present ? std::min(e.reference_norm, rn) : rn;
  e.present = true;
  for (Eigen::Index i = 0; i < diff.size(); ++i) {
    const double d = std::abs(diff[i]);
    const double c = !std::isfinite(d) || !std::isfinite(mag[i]) ? inf : d == 0.0 ? 0.0 : d / (mag[i] + std::abs(ref[i]));
    if (c > e.componentwise_error) {
      e.componentwise_error = c;
      e.worst_row = i;
      e.worst_probe = probe;
    }
  }
}

template <class M>
void check_matrix(jacobian_check_entry& e, const M& a, const Eigen::MatrixXd& dirs, const Eigen::MatrixXd& ref) {
  const Eigen::Index n = dirs.rows();
  require(a.rows() == n && a.cols() == n, "check_jacobian: ", e.name, " is ", a.rows(), " x ", a.cols(),
          ", the system has ", n, " unknowns");
  for (Eigen::Index k = 0; k < dirs.cols(); ++k) {
    const vec<double> v = dirs.col(k);
    const vec<double> av = a * v;
    const vec<double> mag = a.cwiseAbs() * v.cwiseAbs();
    accumulate_check(e, static_cast<int>(k), av, mag, ref.col(k));
  }
}

}  // namespace internal

/// Compares every Jacobian sys offers at (w, mu) with exact directional derivatives of its
/// residual along opt.probes seeded random directions (file comment). Throws input_error for a
/// state of the wrong size or with a non-finite entry, opt.probes < 1, a matrix of the wrong
/// size, or a residual whose derivative at w is not finite (names the direction and entry).
/// Nothing is asserted: the caller decides the tolerance (exact Jacobians: componentwise
/// ~1e-14 for smooth residuals, ~1e-12 for CFD residuals).
template <system S>
jacobian_check_report check_jacobian(const S& sys, const vec<double>& w, double mu,
                                     const jacobian_check_options& opt = {}) {
  const Eigen::Index n = sys.size();
  require_size(w.size(), n, "check_jacobian", "state w");
  require_finite(w, "check_jacobian", "state w");
  require(std::isfinite(mu), "check_jacobian: parameter mu is not finite (", mu, ")");
  require(opt.probes >= 1, "check_jacobian: needs at least one probe direction (got ", opt.probes, ")");
  std::uint64_t state = 0x2545f4914f6cdd1dULL ^ opt.seed;
  Eigen::MatrixXd dirs(n, opt.probes);
  for (Eigen::Index k = 0; k < dirs.cols(); ++k)
    for (Eigen::Index i = 0; i < n; ++i) dirs(i, k) = internal::check_uniform(state);
  const Eigen::MatrixXd ref = internal::exact_directional_derivatives(sys, w, mu, dirs);
  for (Eigen::Index k = 0; k < ref.cols(); ++k)
    require_finite(ref.col(k), "check_jacobian",
                   internal::concat("directional derivative f'(w) v of the residual along direction ", k));

  jacobian_check_report r;
  r.probes = opt.probes;
  internal::check_matrix(r.exact, sys.jacobian(w, mu), dirs, ref);
  if constexpr (has_approximate_jacobian<S>) {
    if (opt.approximate) internal::check_matrix(r.approximate, sys.approximate_jacobian(w, mu), dirs, ref);
  }
  if constexpr (has_block_jacobian_pair<S>) {
    if (opt.blocks) {
      const auto pair = sys.block_jacobians(w, mu);
      internal::check_matrix(r.block_exact, Eigen::SparseMatrix<double>(pair.first.to_sparse()), dirs, ref);
      internal::check_matrix(r.block_approximate, Eigen::SparseMatrix<double>(pair.second.to_sparse()), dirs, ref);
    }
  }
  if constexpr (has_bordered_jacobian_pair<S>) {
    if (opt.blocks) {
      const auto pair = sys.bordered_jacobians(w, mu);
      internal::check_matrix(r.bordered_exact, Eigen::SparseMatrix<double>(pair.exact.to_sparse()), dirs, ref);
      internal::check_matrix(r.bordered_approximate, Eigen::SparseMatrix<double>(pair.preconditioning.to_sparse()), dirs,
                             ref);
    }
  }
  if constexpr (has_d_mu<S> && system_over<S, taylor<double, 1>>) {
    if (opt.d_mu) {
      using K = taylor<double, 1>;
      const vec<K> fj = sys.residual(vec<K>(w.template cast<K>()), K::variable(mu));
      vec<double> ref_mu(n);
      for (Eigen::Index i = 0; i < n; ++i) ref_mu[i] = fj[i][1];
      require_finite(ref_mu, "check_jacobian", "derivative of the residual in mu");
      const vec<double> dm = sys.d_mu(w, mu);
      require_size(dm.size(), n, "check_jacobian", "d_mu");
      internal::accumulate_check(r.d_mu, 0, dm, dm.cwiseAbs(), ref_mu);
    }
  }
  return r;
}

}  // namespace aerohopf
