#pragma once
// Block incomplete LU factorisation with level of fill, BILU(k), as a preconditioner.
//
// WHY: the shifted systems A - i omega I of the Hopf and inverse-power solves are much harder
// than a steady CFD system (spec 07), and the original work found that only a block ILU with
// some fill (k = 1..3) made the Krylov method converge with the exact Jacobian. Working on the
// b x b blocks (not single entries) keeps all the couplings within a cell, which a point ILU
// would partly drop, and turns the elimination into small dense products.
//
// Level-of-fill rule (spec 07): lev(i,j) = 0 where block (i,j) is stored in the matrix, infinity
// elsewhere; when the elimination updates c_ij -= c_ik c_kj, lev_ij = min(lev_ij, lev_ik +
// lev_kj + 1); a block is kept iff lev_ij <= k. The pattern depends only on the block graph, so
//   analyze(a)    symbolic phase: permutation, filter, levels -> factor pattern; once per pattern
//   factorize(a)  numeric phase: copies a's (kept) blocks into the factor storage and
//                 eliminates; no allocation (single-precision factors: the double working
//                 copy is allocated here and released after the rounding); once per matrix
//   apply(r, z)   z = (LU)^{-1} r by forward and backward block substitution
// compute(a) does both (the symbolic phase only when the pattern changed).
// A factorize() that throws (non-finite block, singular pivot, pattern other than the analysed
// one) leaves no usable factors: apply() then throws singular_matrix_error naming the failure,
// until a factorisation succeeds (never the stale factors of an earlier matrix).
//
// The diagonal blocks of U are stored INVERTED (LU-factored once with partial pivoting, then
// inverted), so the triangular solves and the elimination only multiply blocks.
//
// Which couplings enter the preconditioner (spec 07 "methods"; the Krylov method still uses the
// whole matrix) is a coupling_filter on ORIGINAL block indices: keep (i, j) iff
// label[i] == label[j] (no labels: keep everything), or any user predicate. The three methods
// are three label vectors (coupling_filter::for_method), not three code paths.
// Optional reverse Cuthill-McKee reordering of the (filtered) block graph; the permutation is
// applied inside apply(), so callers always work in the original numbering.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "../error.hpp"
#include "block_sparse_matrix.hpp"
#include "rcm.hpp"

namespace aerohopf {

/// Which block couplings (i, j) of the matrix are kept in the preconditioner. Diagonal blocks
/// are always kept.
struct coupling_filter {
  /// Keep (i, j) iff labels[i] == labels[j]; empty: keep all.
  std::vector<int> labels;
  /// Optional extra predicate (both must accept).
  std::function<bool(Eigen::Index, Eigen::Index)> predicate;

  bool keep(Eigen::Index i, Eigen::Index j) const {
    if (i == j) return true;
    if (!labels.empty() && labels[i] != labels[j]) return false;
    return !predicate || predicate(i, j);
  }

  /// Spec 07 methods from one description of the block rows: grid_block[i] = index of the grid
  /// block (>= 0) owning flow block row i, or -1 for a structural block row.
  ///   1: the whole matrix;  2: drop fluid-structure couplings;  3: also drop couplings across
  ///   grid blocks.
  static coupling_filter for_method(int method, const std::vector<int>& grid_block) {
    require(method >= 1 && method <= 3, "coupling_filter::for_method: method ", method, " is not 1, 2 or 3");
    coupling_filter f;
    if (method == 1) return f;
    f.labels.resize(grid_block.size());
    for (std::size_t i = 0; i < grid_block.size(); ++i)
      f.labels[i] = method == 2 ? (grid_block[i] < 0 ? 1 : 0) : (grid_block[i] < 0 ? -1 : grid_block[i]);
    return f;
  }

  /// The same filter for the real 2n form (each block row i becomes two block rows).
  coupling_filter for_real_form(real_form_ordering o) const {
    coupling_filter f;
    f.predicate = predicate ? [p = predicate, n = static_cast<Eigen::Index>(labels.size()), o](Eigen::Index i,
                                                                                                Eigen::Index j) {
      auto orig = [&](Eigen::Index r) { return o == real_form_ordering::split ? r % n : r / 2; };
      return p(orig(i), orig(j));
    } : std::function<bool(Eigen::Index, Eigen::Index)>();
    if (labels.empty()) return f;
    const Eigen::Index n = static_cast<Eigen::Index>(labels.size());
    f.labels.resize(2 * n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (bool im : {false, true}) f.labels[internal::real_form_row(i, im, n, o)] = labels[i];
    return f;
  }
};

struct block_ilu_options {
  int fill_level = 0;                 ///< k of BILU(k)
  bool reorder_rcm = false;           ///< reverse Cuthill-McKee on the filtered block graph
  coupling_filter filter;             ///< which couplings enter the preconditioner
  double pivot_rcond_tolerance = 1e-14;  ///< pivot block with smaller reciprocal condition: singular
  /// Keep the factors in single precision (float, std::complex<float>): the elimination runs in
  /// double, its result is rounded once, and apply() widens each value back to double, so the
  /// sweeps stream half the bytes and the factors take half the memory. The preconditioner
  /// changes by the rounding (relative 6e-8 per value), far below the incompleteness of BILU(k),
  /// and the Krylov method still works with the exact operator in double, so its solutions do not
  /// lose accuracy. Needs double or std::complex<double> and a compile-time block size.
  bool single_precision_factors = false;
  std::string context = "BILU";       ///< prefix of error messages
};

template <class Scalar, int B = Eigen::Dynamic>
class block_ilu {
 public:
  using matrix_type = block_sparse_matrix<Scalar, B>;
  using index = Eigen::Index;
  using block_type = Eigen::Matrix<Scalar, B, B>;
  using block_map = Eigen::Map<block_type>;
  using const_block_map = Eigen::Map<const block_type>;
  using segment_type = Eigen::Matrix<Scalar, B, 1>;
  using vector_type = vec<Scalar>;
  /// Storage of single-precision factors (block_ilu_options::single_precision_factors).
  using low_scalar = internal::single_precision_t<Scalar>;

  block_ilu() = default;
  explicit block_ilu(block_ilu_options options) : opt_(std::move(options)) {
    require(opt_.fill_level >= 0, opt_.context, ": fill level ", opt_.fill_level, " < 0");
    require(!opt_.single_precision_factors || internal::has_fast_block_kernel_v<Scalar, B>, opt_.context,
            ": single-precision factors need double or std::complex<double> and a compile-time block size");
  }
  const block_ilu_options& options() const { return opt_; }

  /// analyze() if the pattern differs from the analysed one, then factorize().
  block_ilu& compute(const matrix_type& a) {
    if (!analysed_ || !same_pattern(a)) analyze(a);
    factorize(a);
    return *this;
  }

  /// Symbolic phase: ordering, filter and level-of-fill pattern of the factors.
  void analyze(const matrix_type& a) {
    require(a.block_rows() == a.block_cols(), opt_.context, ": matrix is ", a.block_rows(), "x", a.block_cols(),
            " blocks, not square");
    require(opt_.filter.labels.empty() || static_cast<index>(opt_.filter.labels.size()) == a.block_rows(),
            opt_.context, ": coupling filter has ", opt_.filter.labels.size(), " labels for ", a.block_rows(),
            " block rows");
    const int n = static_cast<int>(a.block_rows());
    bs_ = a.block_size();
    n_ = n;
    a_row_ptr_ = a.row_ptr();
    a_col_ = a.col_index();
    const auto& ap = a.row_ptr();
    const auto& ac = a.col_index();

    // filtered pattern (original numbering), diagonal always present
    std::vector<int> fptr(n + 1, 0), fcol;
    fcol.reserve(ac.size() + n);
    for (int i = 0; i < n; ++i) {
      bool diag = false;
      for (int p = ap[i]; p < ap[i + 1]; ++p)
        if (opt_.filter.keep(i, ac[p])) {
          fcol.push_back(ac[p]);
          diag = diag || ac[p] == i;
        }
      if (!diag) fcol.push_back(i);
      fptr[i + 1] = static_cast<int>(fcol.size());
    }
    if (opt_.reorder_rcm) {
      perm_ = reverse_cuthill_mckee(fptr, fcol);
      inv_ = inverse_permutation(perm_);
    } else {
      perm_.clear();
      inv_.clear();
    }
    auto new_of = [&](int old) { return inv_.empty() ? old : inv_[old]; };
    auto old_of = [&](int nw) { return perm_.empty() ? nw : perm_[nw]; };

    // level-of-fill symbolic factorisation, row by row in the new numbering
    constexpr int unset = std::numeric_limits<int>::max();
    std::vector<int> lev(n, unset), next(n + 1, -1);
    row_ptr_.assign(n + 1, 0);
    col_.clear();
    std::vector<int> levels;  // level of each stored factor block (needed for later rows)
    col_.reserve(fcol.size());
    levels.reserve(fcol.size());
    diag_.assign(n, -1);
    const int k_fill = opt_.fill_level;
    std::vector<int> row;
    for (int i = 0; i < n; ++i) {
      // initial row: level 0 entries, sorted linked list head = n (sentinel)
      row.clear();
      const int oi = old_of(i);
      for (int p = fptr[oi]; p < fptr[oi + 1]; ++p) row.push_back(new_of(fcol[p]));
      std::sort(row.begin(), row.end());
      row.erase(std::unique(row.begin(), row.end()), row.end());
      int head = n;  // sentinel index n marks the list head
      int prev = head;
      for (int c : row) {
        lev[c] = 0;
        next[prev] = c;
        prev = c;
      }
      next[prev] = -1;
      // eliminate with the rows k < i in increasing order (no fill at all for k = 0: every
      // update has level >= 1)
      for (int k = k_fill > 0 ? next[head] : -1; k != -1 && k < i; k = next[k]) {
        const int lik = lev[k];
        int cur = k;  // columns of U row k increase, so each search resumes where the last ended
        for (int u = diag_[k] + 1; u < row_ptr_[k + 1]; ++u) {
          const int j = col_[u];
          const int l = lik + levels[u] + 1;
          if (l > k_fill) continue;
          while (next[cur] != -1 && next[cur] < j) cur = next[cur];
          if (next[cur] == j) {
            lev[j] = std::min(lev[j], l);
          } else {  // fill-in
            next[j] = next[cur];
            next[cur] = j;
            lev[j] = l;
          }
          cur = j;
        }
      }
      for (int c = next[head]; c != -1; c = next[c]) {
        if (c == i) diag_[i] = static_cast<int>(col_.size());
        col_.push_back(c);
        levels.push_back(lev[c]);
        lev[c] = unset;
      }
      row_ptr_[i + 1] = static_cast<int>(col_.size());
    }
    col_.shrink_to_fit();
    // storage slots: the L parts of the rows in row order, then the U parts (diagonal first) in
    // REVERSE row order, so that both triangular sweeps stream through memory forwards (a
    // backward-running stream was measured 2x slower on the hardware prefetchers).
    slot_.resize(col_.size());
    {
      int next_slot = 0;
      for (int i = 0; i < n; ++i)
        for (int q = row_ptr_[i]; q < diag_[i]; ++q) slot_[q] = next_slot++;
      for (int i = n - 1; i >= 0; --i)
        for (int q = diag_[i]; q < row_ptr_[i + 1]; ++q) slot_[q] = next_slot++;
    }

    // where each block of a goes in the factor storage (-1: dropped by the filter)
    source_.assign(ac.size(), -1);
    for (int i = 0; i < n; ++i)
      for (int p = ap[i]; p < ap[i + 1]; ++p)
        if (opt_.filter.keep(i, ac[p])) {
          const int ni = new_of(i), nj = new_of(ac[p]);
          const auto first = col_.begin() + row_ptr_[ni], last = col_.begin() + row_ptr_[ni + 1];
          source_[p] = slot_[std::lower_bound(first, last, nj) - col_.begin()];
        }
    // factor blocks that no matrix block initialises (fill-in): zeroed before each elimination
    {
      std::vector<char> sourced(col_.size(), 0);
      for (int sl : source_)
        if (sl >= 0) sourced[sl] = 1;
      fill_slots_.clear();
      for (std::size_t sl = 0; sl < sourced.size(); ++sl)
        if (!sourced[sl]) fill_slots_.push_back(static_cast<int>(sl));
    }
    val_.assign(col_.size() * bs_ * bs_, Scalar(0.0));
    pos_.assign(n, -1);
    work_.resize(static_cast<index>(n) * bs_);
    analysed_ = true;
    factorized_ = false;
    failure_.clear();
  }

  /// Numeric phase for a matrix with the analysed pattern. Throws input_error for non-finite
  /// blocks or another pattern and singular_matrix_error for a singular pivot block (naming the
  /// block row); after any of these apply() refuses until a factorisation succeeds.
  void factorize(const matrix_type& a) {
    require(analysed_, opt_.context, ": factorize() before analyze()");
    factorized_ = false;
    try {
      factorize_numeric(a);
    } catch (const error& e) {
      failure_ = e.what();
      throw;
    }
    failure_.clear();
    factorized_ = true;
  }

  /// z = M^{-1} r (original numbering). r and z must not alias. Not thread-safe (workspace).
  void apply(const vector_type& r, vector_type& z) const {
    if (!factorized_ && !failure_.empty())
      throw singular_matrix_error(
          internal::concat(opt_.context, ": apply() refused: the last factorisation failed (", failure_, ")"));
    require(factorized_, opt_.context, ": apply() before factorize()");
    require(r.size() == rows() && z.size() == rows(), opt_.context, ": apply: vector sizes ", r.size(), ", ",
            z.size(), ", expected ", rows());
    apply_factors(r, z);
  }

  index rows() const { return index(n_) * bs_; }
  index block_rows() const { return n_; }
  /// Non-zero blocks of the preconditioner (L + U + diagonal): its storage in blocks.
  index nonzero_blocks() const { return static_cast<index>(col_.size()); }
  /// Bytes of the factors' values as apply() reads them (single_precision_factors: half).
  std::size_t factor_bytes() const {
    return std::size_t(col_.size()) * std::size_t(bs_ * bs_) *
           (opt_.single_precision_factors ? sizeof(low_scalar) : sizeof(Scalar));
  }
  /// perm[new] = old (empty without reordering).
  const std::vector<int>& permutation() const { return perm_; }
  /// Factor pattern in the (possibly permuted) numbering, for inspection.
  const std::vector<int>& factor_row_ptr() const { return row_ptr_; }
  const std::vector<int>& factor_col_index() const { return col_; }

 private:
  void factorize_numeric(const matrix_type& a) {
    require(same_pattern(a), opt_.context, ": matrix pattern differs from the analysed one (", a.block_rows(),
            " block rows, ", a.nonzero_blocks(), " blocks vs ", n_, ", ", a_col_.size(), ")");
    const index bb = bs_ * bs_;
    // every slot is written below (sourced ones copied, fill-in zeroed): no initialisation
    if (val_.size() != col_.size() * std::size_t(bb)) val_.resize(col_.size() * std::size_t(bb));
    for (int sl : fill_slots_) std::fill_n(val_.data() + index(sl) * bb, bb, Scalar(0.0));
    const auto& av = a.values();
    for (int i = 0; i < n_; ++i)
      for (int p = a_row_ptr_[i]; p < a_row_ptr_[i + 1]; ++p) {
        const Scalar* src = av.data() + index(p) * bb;
        bool finite = true;
        if constexpr (internal::has_fast_block_kernel_v<Scalar, B>) finite = internal::all_finite<B * B>(src);
        else
          for (index e = 0; e < bb; ++e) finite = finite && std::isfinite(std::abs(src[e]));
        if (!finite)
          throw input_error(internal::concat(opt_.context, ": matrix block (", i, ", ", a_col_[p],
                                             ") has a non-finite entry (NaN or Inf)"));
        if (source_[p] >= 0) std::copy(src, src + bb, val_.data() + index(source_[p]) * bb);
      }

    const index b = bs_;
    block_type tmp(b, b);
    if constexpr (internal::has_fast_block_kernel_v<Scalar, B>) {
      // the same elimination with the hand-written block products (no __muldc3 for complex)
      constexpr int bb2 = B * B;
      Scalar t[bb2];
      Scalar* v = val_.data();
      for (int i = 0; i < n_; ++i) {
        for (int q = row_ptr_[i]; q < row_ptr_[i + 1]; ++q) pos_[col_[q]] = q;
        for (int q = row_ptr_[i]; q < diag_[i]; ++q) {
          const int k = col_[q];
          Scalar* lik = v + index(slot_[q]) * bb2;
          std::copy(lik, lik + bb2, t);
          std::fill(lik, lik + bb2, Scalar(0.0));
          internal::block_gemm<1, B>(t, v + index(slot_[diag_[k]]) * bb2, lik);  // L_ik = C_ik U_kk^{-1}
          for (int u = diag_[k] + 1; u < row_ptr_[k + 1]; ++u) {
            const int tq = pos_[col_[u]];
            if (tq >= 0) internal::block_gemm<-1, B>(lik, v + index(slot_[u]) * bb2, v + index(slot_[tq]) * bb2);
          }
        }
        for (int q = row_ptr_[i]; q < row_ptr_[i + 1]; ++q) pos_[col_[q]] = -1;
        invert_pivot(i);
      }
      if (opt_.single_precision_factors) {  // round once, then keep only the single copy
        valf_.resize(val_.size());
        std::transform(val_.begin(), val_.end(), valf_.begin(), [](const Scalar& x) { return low_scalar(x); });
        std::vector<Scalar>().swap(val_);
      }
      return;
    }
    for (int i = 0; i < n_; ++i) {
      for (int q = row_ptr_[i]; q < row_ptr_[i + 1]; ++q) pos_[col_[q]] = q;
      for (int q = row_ptr_[i]; q < diag_[i]; ++q) {
        const int k = col_[q];
        block_map lik = blk(q);
        tmp.noalias() = lik * blk(diag_[k]);  // L_ik = C_ik U_kk^{-1}
        lik = tmp;
        for (int u = diag_[k] + 1; u < row_ptr_[k + 1]; ++u) {
          const int t = pos_[col_[u]];
          if (t >= 0) blk(t).noalias() -= lik * blk(u);
        }
      }
      for (int q = row_ptr_[i]; q < row_ptr_[i + 1]; ++q) pos_[col_[q]] = -1;
      invert_pivot(i);
    }
  }

  /// apply() after its checks.
  void apply_factors(const vector_type& r, vector_type& z) const {
    const index b = bs_;
    Scalar* w = perm_.empty() ? z.data() : work_.data();
    constexpr bool fast = internal::has_fast_block_kernel_v<Scalar, B>;
    if (!perm_.empty())
      for (int i = 0; i < n_; ++i)
        Eigen::Map<segment_type>(w + index(i) * b, b) = r.template segment<B>(index(perm_[i]) * b, b);
    else if (!fast)
      z = r;  // the fast forward sweep reads r itself (one vector pass less)
    if constexpr (fast) {
      if (opt_.single_precision_factors) sweeps(valf_.data(), perm_.empty() ? r.data() : w, w);
      else sweeps(val_.data(), perm_.empty() ? r.data() : w, w);
    } else {
      segment_type acc(b);
      for (int i = 0; i < n_; ++i) {  // forward: L y = r (unit block diagonal)
        acc = Eigen::Map<segment_type>(w + index(i) * b, b);
        for (int q = row_ptr_[i]; q < diag_[i]; ++q)
          acc.noalias() -= cblk(q) * Eigen::Map<const segment_type>(w + index(col_[q]) * b, b);
        Eigen::Map<segment_type>(w + index(i) * b, b) = acc;
      }
      for (int i = n_ - 1; i >= 0; --i) {  // backward: U x = y, diagonal stored inverted
        acc = Eigen::Map<segment_type>(w + index(i) * b, b);
        for (int q = diag_[i] + 1; q < row_ptr_[i + 1]; ++q)
          acc.noalias() -= cblk(q) * Eigen::Map<const segment_type>(w + index(col_[q]) * b, b);
        Eigen::Map<segment_type>(w + index(i) * b, b).noalias() = cblk(diag_[i]) * acc;
      }
    }
    if (!perm_.empty())
      for (int i = 0; i < n_; ++i)
        z.template segment<B>(index(perm_[i]) * b, b) = Eigen::Map<const segment_type>(w + index(i) * b, b);
  }

  /// The two block sweeps of the fast kernels, the factors' values v stored in Scalar or in its
  /// single precision: w = (LU)^{-1} rin (rin may be w itself).
  template <class V>
  void sweeps(const V* v, const Scalar* rin, Scalar* w) const {
    {  // the factor pattern, read through plain pointers in the hot loops
      const int* rp = row_ptr_.data();
      const int* dg = diag_.data();
      const int* cl = col_.data();
      const int* sl = slot_.data();
      for (int i = 0; i < n_; ++i) {  // forward: L y = r (unit block diagonal)
        Scalar acc[B];
        Scalar* wi = w + index(i) * B;
        const Scalar* ri = rin + index(i) * B;
        for (int r = 0; r < B; ++r) acc[r] = ri[r];
        const V* lv = v + index(sl[rp[i]]) * B * B;  // L part of row i is contiguous
        internal::prefetch_ahead(lv, index(dg[i] - rp[i]) * B * B * index(sizeof(V)));
        internal::block_row_gemv<-1, B>(lv, cl + rp[i], dg[i] - rp[i], w, acc);
        for (int r = 0; r < B; ++r) wi[r] = acc[r];
      }
      for (int i = n_ - 1; i >= 0; --i) {  // backward: U x = y, diagonal stored inverted
        Scalar acc[B];
        Scalar* wi = w + index(i) * B;
        for (int r = 0; r < B; ++r) acc[r] = wi[r];
        const V* uv = v + index(sl[dg[i]]) * B * B;  // diagonal, then the U part of row i
        internal::prefetch_ahead(uv, index(rp[i + 1] - dg[i]) * B * B * index(sizeof(V)));
        internal::block_row_gemv<-1, B>(uv + B * B, cl + dg[i] + 1, rp[i + 1] - dg[i] - 1, w, acc);
        Scalar out[B];
        for (int r = 0; r < B; ++r) out[r] = Scalar(0.0);
        internal::block_gemv<1, B>(uv, acc, out);
        for (int r = 0; r < B; ++r) wi[r] = out[r];
      }
    }
  }

  bool same_pattern(const matrix_type& a) const {
    return a.block_rows() == n_ && a.block_size() == bs_ && a.row_ptr() == a_row_ptr_ && a.col_index() == a_col_;
  }
  // block at logical (CSR) position q
  block_map blk(int q) { return block_map(val_.data() + index(slot_[q]) * bs_ * bs_, bs_, bs_); }
  const_block_map cblk(int q) const { return const_block_map(val_.data() + index(slot_[q]) * bs_ * bs_, bs_, bs_); }

  void invert_pivot(int i) {
    block_map d = blk(diag_[i]);
    const int orig = perm_.empty() ? i : perm_[i];
    if constexpr (internal::has_fast_block_kernel_v<Scalar, B>) {
      if (!internal::all_finite<B * B>(d.data()))
        throw singular_matrix_error(internal::concat(opt_.context, ": pivot block of block row ", orig,
                                                     " became non-finite during the elimination"));
      block_type keep = d;
      const double rc = internal::invert_block<B>(d.data());
      if (!(rc > opt_.pivot_rcond_tolerance)) {
        d = keep;
        throw singular_matrix_error(internal::concat(opt_.context, ": pivot block of block row ", orig,
                                                     " is singular (reciprocal condition ", rc, ")"));
      }
      return;
    }
    if (!d.allFinite())
      throw singular_matrix_error(internal::concat(opt_.context, ": pivot block of block row ", orig,
                                                   " became non-finite during the elimination"));
    Eigen::PartialPivLU<block_type> lu(d);
    const double rc = static_cast<double>(std::abs(lu.rcond()));
    if (!(rc > opt_.pivot_rcond_tolerance))
      throw singular_matrix_error(internal::concat(opt_.context, ": pivot block of block row ", orig,
                                                   " is singular (reciprocal condition ", rc, ")"));
    d = lu.inverse();
  }

  block_ilu_options opt_;
  bool analysed_ = false, factorized_ = false;
  std::string failure_;  // why the last factorize() failed ("" after a success)
  index bs_ = (B == Eigen::Dynamic ? 1 : B);
  int n_ = 0;
  std::vector<int> a_row_ptr_, a_col_;  // pattern of the analysed matrix
  std::vector<int> perm_, inv_;
  std::vector<int> row_ptr_, col_, diag_, source_, slot_, fill_slots_;
  std::vector<Scalar> val_;      // the factors (single_precision_factors: only during factorize)
  std::vector<low_scalar> valf_;  // the factors rounded to single precision (that option only)
  std::vector<int> pos_;
  mutable vector_type work_;
};

}  // namespace aerohopf
