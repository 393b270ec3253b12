#pragma once
// Block compressed-row (BSR) sparse matrix with dense b x b blocks.
//
// WHY: a finite-volume flow Jacobian couples all b unknowns of a cell (b = 4 in 2D, 5 in 3D)
// with all unknowns of each neighbour, so it is naturally a sparse matrix of dense b x b
// blocks. Storing one column index per block instead of per entry cuts the index traffic by
// b^2, and a compile-time b lets the compiler unroll the small dense products of the hot
// kernels (SpMV, BILU(k)). The same class holds the real Jacobian, the complex shifted matrix
// A - i omega I and the real 2n x 2n form of it (spec 07).
//
// USAGE
//   using M = aerohopf::block_sparse_matrix<double, 5>;       // Eigen::Dynamic: runtime size
//   // (a) once per grid: the block pattern (pairs of block row, block column; any order,
//   //     duplicates merged). Columns are kept sorted in each row.
//   M a;  a.set_pattern(n_cells, n_cells, pairs);
//   // (b) every Newton step: zero the values and add blocks, no reallocation
//   a.set_zero();
//   a.add_block(i, j, blk);            // blk any 5x5 Eigen expression; throws if (i,j) absent
//   a.block(i, j) += blk;              // same, through a writable Eigen::Map
//   auto k = a.find(i, j);  a.block_at(k) -= blk;   // cache k to skip the search
//   // or in one go from block triplets (duplicates summed):
//   M b = M::from_triplets(n_cells, n_cells, triplets);
//   a.apply(x, y);  a.multiply_add(alpha, x, y);  a.multiply_transpose(x, y);
//   Eigen::SparseMatrix<double> s = a.to_sparse();  M c = M::from_sparse(s);  // B fixed
//   auto cc = shifted(a, std::complex<double>(0, omega));        // A - i omega I (complex)
//   auto cr = real_shifted_form(a, omega, real_form_ordering::interleaved);
//
// SCALAR SIZES THAT ARE NOT A MULTIPLE OF b (e.g. n_cells*5 flow unknowns + 2 structural
// unknowns). Choice made here: the matrix is PADDED to a whole number of block rows; the padded
// unknowns get an identity diagonal and no couplings, so for a zero padded right-hand side the
// padded solution is zero and the logical solution is unchanged. rows()/cols() are the PADDED
// sizes that all operators act on; logical_rows()/logical_cols() the original ones.
// pad_vector()/unpad_vector() convert vectors. from_sparse() and to_sparse() do this for you.
//
// Storage: row_ptr (block_rows+1), col_index (one int per block, sorted within each row),
// values (b*b scalars per block, column-major, contiguous in the order of col_index).
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <complex>
#include <cstdint>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../scalar/complex.hpp"
#include "block_kernels.hpp"
#include "direct.hpp"
#include "operator.hpp"

namespace aerohopf {

/// Number of block rows needed to hold n scalar unknowns in blocks of size b.
inline Eigen::Index padded_block_count(Eigen::Index n, Eigen::Index b) { return (n + b - 1) / b; }

/// x extended with zeros to padded_size.
template <class Derived>
auto pad_vector(const Eigen::MatrixBase<Derived>& x, Eigen::Index padded_size) {
  require(padded_size >= x.size(), "pad_vector: padded size ", padded_size, " < vector size ", x.size());
  vec<typename Derived::Scalar> y = vec<typename Derived::Scalar>::Zero(padded_size);
  y.head(x.size()) = x;
  return y;
}

/// The first logical_size entries of a padded vector.
template <class Derived>
auto unpad_vector(const Eigen::MatrixBase<Derived>& x, Eigen::Index logical_size) {
  require(logical_size <= x.size(), "unpad_vector: logical size ", logical_size, " > vector size ", x.size());
  return vec<typename Derived::Scalar>(x.head(logical_size));
}

/// One block for from_triplets(): value is added at block (row, col).
template <class Scalar, int B = Eigen::Dynamic>
struct block_triplet {
  Eigen::Index row = 0, col = 0;
  Eigen::Matrix<Scalar, B, B> value;
};

template <class Scalar, int B = Eigen::Dynamic>
class block_sparse_matrix {
  static_assert(B == Eigen::Dynamic || B > 0, "block size must be positive or Eigen::Dynamic");

 public:
  using scalar_type = Scalar;
  using index = Eigen::Index;
  using storage_index = int;
  static constexpr int compile_block_size = B;
  using block_type = Eigen::Matrix<Scalar, B, B>;
  using block_map = Eigen::Map<block_type>;
  using const_block_map = Eigen::Map<const block_type>;
  using segment_type = Eigen::Matrix<Scalar, B, 1>;
  using vector_type = vec<Scalar>;

  /// Empty matrix; block_size is only used (and required) for B == Eigen::Dynamic.
  explicit block_sparse_matrix(index block_size = (B == Eigen::Dynamic ? 1 : B)) : bs_(block_size) {
    require(block_size > 0 && (B == Eigen::Dynamic || block_size == B), "block_sparse_matrix: block size ",
            block_size, " does not match the compile-time size ", B);
    row_ptr_.assign(1, 0);
  }

  // ---- sizes -----------------------------------------------------------------------------
  index block_size() const { return bs_; }
  index block_rows() const { return nbr_; }
  index block_cols() const { return nbc_; }
  index rows() const { return nbr_ * bs_; }  ///< padded scalar size (what apply() expects)
  index cols() const { return nbc_ * bs_; }
  index logical_rows() const { return logical_rows_; }
  index logical_cols() const { return logical_cols_; }
  index nonzero_blocks() const { return static_cast<index>(col_.size()); }
  index block_entries() const { return bs_ * bs_; }

  /// Declares the logical (unpadded) scalar sizes; the padded unknowns of square matrices get
  /// identity diagonals when set_zero(true)/fill_padding() is used.
  void set_logical_size(index rows, index cols) {
    require(rows <= this->rows() && rows > this->rows() - bs_ && cols <= this->cols() && cols > this->cols() - bs_,
            "set_logical_size: ", rows, "x", cols, " does not fit ", nbr_, "x", nbc_, " blocks of ", bs_);
    logical_rows_ = rows;
    logical_cols_ = cols;
  }

  // ---- raw storage (read-only; for kernels such as block_ilu) ------------------------------
  const std::vector<storage_index>& row_ptr() const { return row_ptr_; }
  const std::vector<storage_index>& col_index() const { return col_; }
  const std::vector<Scalar>& values() const { return val_; }
  std::vector<Scalar>& values() { return val_; }

  // ---- pattern ---------------------------------------------------------------------------
  /// Sets the block pattern from (block row, block column) pairs; values become zero. Any
  /// order; duplicates merged. Logical size = padded size.
  template <class PairRange>
  void set_pattern(index block_rows, index block_cols, const PairRange& blocks) {
    require(block_rows >= 0 && block_cols >= 0, "set_pattern: negative block dimensions ", block_rows, "x",
            block_cols);
    std::vector<storage_index> count(block_rows + 1, 0);
    index k = 0;
    for (const auto& [i, j] : blocks) {
      require(i >= 0 && i < block_rows && j >= 0 && j < block_cols, "set_pattern: entry ", k, " = block (", i,
              ", ", j, ") outside ", block_rows, "x", block_cols, " blocks");
      ++count[i + 1];
      ++k;
    }
    std::vector<storage_index> ptr(block_rows + 1, 0);
    for (index i = 0; i < block_rows; ++i) ptr[i + 1] = ptr[i] + count[i + 1];
    std::vector<storage_index> cols(ptr.back());
    std::vector<storage_index> next(ptr.begin(), ptr.end() - 1);
    for (const auto& [i, j] : blocks) cols[next[i]++] = static_cast<storage_index>(j);
    set_pattern_csr_unchecked(block_rows, block_cols, ptr, cols);
  }

  /// Same from a block CSR pattern (row_ptr of size block_rows+1, column indices per row in
  /// any order, duplicates merged).
  void set_pattern_csr(index block_rows, index block_cols, const std::vector<storage_index>& row_ptr,
                       const std::vector<storage_index>& col_index) {
    require(static_cast<index>(row_ptr.size()) == block_rows + 1 && row_ptr.front() == 0 &&
                static_cast<index>(col_index.size()) == row_ptr.back(),
            "set_pattern_csr: row_ptr/col_index sizes inconsistent with ", block_rows, " block rows");
    for (index i = 0; i < block_rows; ++i) {
      require(row_ptr[i] <= row_ptr[i + 1], "set_pattern_csr: row_ptr decreases at block row ", i);
      for (storage_index p = row_ptr[i]; p < row_ptr[i + 1]; ++p)
        require(col_index[p] >= 0 && col_index[p] < block_cols, "set_pattern_csr: block (", i, ", ", col_index[p],
                ") outside ", block_cols, " block columns");
    }
    set_pattern_csr_unchecked(block_rows, block_cols, row_ptr, col_index);
  }

  /// All values zero (pattern kept, no reallocation). With identity_padding, the padded
  /// diagonal unknowns of a square matrix get 1 (what from_sparse() does).
  void set_zero(bool identity_padding = true) {
    std::fill(val_.begin(), val_.end(), Scalar(0.0));
    if (identity_padding) fill_padding();
  }

  /// Puts 1 on the padded diagonal entries (rows beyond logical_rows()) of a square matrix.
  void fill_padding() {
    if (nbr_ != nbc_ || logical_rows_ == rows()) return;
    for (index r = logical_rows_; r < rows(); ++r) {
      const index bi = r / bs_;
      const index kk = find(bi, bi);
      require(kk >= 0, "fill_padding: padded block row ", bi, " has no diagonal block in the pattern");
      block_at(kk)(r % bs_, r % bs_) = Scalar(1.0);
    }
  }

  /// Position of block (i, j) in the storage, or -1 if it is not in the pattern.
  index find(index i, index j) const {
    const auto first = col_.begin() + row_ptr_[i], last = col_.begin() + row_ptr_[i + 1];
    const auto it = std::lower_bound(first, last, static_cast<storage_index>(j));
    return (it != last && *it == j) ? static_cast<index>(it - col_.begin()) : -1;
  }
  bool contains(index i, index j) const { return i >= 0 && i < nbr_ && j >= 0 && j < nbc_ && find(i, j) >= 0; }

  block_map block_at(index k) { return block_map(val_.data() + k * bs_ * bs_, bs_, bs_); }
  const_block_map block_at(index k) const { return const_block_map(val_.data() + k * bs_ * bs_, bs_, bs_); }

  /// Writable view of block (i, j); throws input_error if it is not in the pattern.
  block_map block(index i, index j) { return block_at(checked_find(i, j)); }
  const_block_map block(index i, index j) const { return block_at(checked_find(i, j)); }

  /// block(i, j) += b.
  template <class Derived>
  void add_block(index i, index j, const Eigen::MatrixBase<Derived>& b) {
    require(b.rows() == bs_ && b.cols() == bs_, "add_block(", i, ", ", j, "): block is ", b.rows(), "x", b.cols(),
            ", expected ", bs_, "x", bs_);
    block(i, j) += b;
  }

  // ---- assembly from triplets / Eigen --------------------------------------------------------
  /// Builds the pattern and sums the blocks of the triplets (duplicates summed).
  static block_sparse_matrix from_triplets(index block_rows, index block_cols,
                                           const std::vector<block_triplet<Scalar, B>>& triplets,
                                           index block_size = (B == Eigen::Dynamic ? 1 : B)) {
    block_sparse_matrix m(block_size);
    std::vector<std::pair<index, index>> pattern;
    pattern.reserve(triplets.size());
    for (std::size_t t = 0; t < triplets.size(); ++t) {
      const auto& tr = triplets[t];
      require(tr.row >= 0 && tr.row < block_rows && tr.col >= 0 && tr.col < block_cols, "from_triplets: triplet ", t,
              " at block (", tr.row, ", ", tr.col, ") outside ", block_rows, "x", block_cols, " blocks");
      require(tr.value.rows() == block_size && tr.value.cols() == block_size, "from_triplets: triplet ", t,
              " has a ", tr.value.rows(), "x", tr.value.cols(), " block, expected ", block_size);
      pattern.emplace_back(tr.row, tr.col);
    }
    m.set_pattern(block_rows, block_cols, pattern);
    for (const auto& tr : triplets) m.block(tr.row, tr.col) += tr.value;
    return m;
  }

  /// Blocks an Eigen sparse matrix: every b x b block holding at least one stored entry
  /// (explicit zeros included, so a Jacobian's pattern survives) becomes a block. Sizes that
  /// are not a multiple of b are padded (identity on the padded diagonal of square matrices).
  template <class SparseDerived>
  static block_sparse_matrix from_sparse(const Eigen::SparseMatrixBase<SparseDerived>& a_in,
                                         index block_size = (B == Eigen::Dynamic ? 1 : B)) {
    using sparse_t = Eigen::SparseMatrix<Scalar, Eigen::RowMajor, int>;
    const sparse_t a = a_in.derived().template cast<Scalar>();
    block_sparse_matrix m(block_size);
    const index bs = block_size;
    const index nbr = padded_block_count(a.rows(), bs), nbc = padded_block_count(a.cols(), bs);
    // pattern, block row by block row, with a marker array over block columns
    std::vector<storage_index> ptr(nbr + 1, 0), cols;
    std::vector<index> mark(nbc, -1);
    for (index bi = 0; bi < nbr; ++bi) {
      for (index r = bi * bs; r < std::min<index>((bi + 1) * bs, a.rows()); ++r)
        for (typename sparse_t::InnerIterator it(a, r); it; ++it) {
          const index bj = it.col() / bs;
          if (mark[bj] != bi) {
            mark[bj] = bi;
            cols.push_back(static_cast<storage_index>(bj));
          }
        }
      if (a.rows() == a.cols() && (bi + 1) * bs > a.rows() && mark[bi] != bi) cols.push_back(static_cast<storage_index>(bi));
      ptr[bi + 1] = static_cast<storage_index>(cols.size());
    }
    m.set_pattern_csr_unchecked(nbr, nbc, ptr, cols);
    m.logical_rows_ = a.rows();
    m.logical_cols_ = a.cols();
    for (index r = 0; r < a.rows(); ++r)
      for (typename sparse_t::InnerIterator it(a, r); it; ++it)
        m.block_at(m.find(r / bs, it.col() / bs))(r % bs, it.col() % bs) += it.value();
    m.fill_padding();
    return m;
  }

  /// The matrix as an Eigen sparse matrix (column-major), of the logical size unless
  /// with_padding. Every entry of every block is stored (explicit zeros included).
  Eigen::SparseMatrix<Scalar> to_sparse(bool with_padding = false) const {
    const index nr = with_padding ? rows() : logical_rows_, nc = with_padding ? cols() : logical_cols_;
    std::vector<Eigen::Triplet<Scalar>> t;
    t.reserve(col_.size() * bs_ * bs_);
    for (index i = 0; i < nbr_; ++i)
      for (storage_index p = row_ptr_[i]; p < row_ptr_[i + 1]; ++p) {
        const auto blk = block_at(p);
        for (index c = 0; c < bs_; ++c)
          for (index r = 0; r < bs_; ++r) {
            const index gr = i * bs_ + r, gc = index(col_[p]) * bs_ + c;
            if (gr < nr && gc < nc) t.emplace_back(gr, gc, blk(r, c));
          }
      }
    Eigen::SparseMatrix<Scalar> s(nr, nc);
    s.setFromTriplets(t.begin(), t.end());
    return s;
  }

  /// Same pattern and sizes, values cast to another scalar.
  template <class T>
  block_sparse_matrix<T, B> cast() const {
    block_sparse_matrix<T, B> m(bs_);
    m.set_pattern_csr(nbr_, nbc_, row_ptr_, col_);
    m.set_logical_size(logical_rows_, logical_cols_);
    for (std::size_t k = 0; k < val_.size(); ++k) m.values()[k] = T(val_[k]);
    return m;
  }

  // ---- products (x, y of the padded sizes; y must not alias x) -----------------------------
  /// y = A x.
  void apply(const vector_type& x, vector_type& y) const { multiply(x, y); }

  void multiply(Eigen::Ref<const vector_type> x, Eigen::Ref<vector_type> y) const {
    check_product_sizes(x.size(), y.size(), "multiply");
    spmv<false>(Scalar(1.0), x, y);
  }

  /// y += alpha A x.
  void multiply_add(const Scalar& alpha, Eigen::Ref<const vector_type> x, Eigen::Ref<vector_type> y) const {
    check_product_sizes(x.size(), y.size(), "multiply_add");
    spmv<true>(alpha, x, y);
  }

  /// y = A^T x (plain transpose); with conjugate, y = A^H x.
  void multiply_transpose(Eigen::Ref<const vector_type> x, Eigen::Ref<vector_type> y, bool conjugate = false) const {
    require(x.size() == rows() && y.size() == cols(), "multiply_transpose: vector sizes ", x.size(), ", ", y.size(),
            " do not match the ", rows(), "x", cols(), " matrix");
    y.setZero();
    const index b = bs_;
    for (index i = 0; i < nbr_; ++i) {
      const auto xi = x.template segment<B>(i * b, b);
      for (storage_index p = row_ptr_[i]; p < row_ptr_[i + 1]; ++p) {
        auto yj = y.template segment<B>(index(col_[p]) * b, b);
        if (conjugate) yj.noalias() += block_at(p).adjoint() * xi;
        else yj.noalias() += block_at(p).transpose() * xi;
      }
    }
  }

  /// y = (A - sigma I) x for a REAL matrix and complex vectors: the product of shifted(A, sigma)
  /// without assembling it (half the matrix bytes per product; the padded unknowns are not
  /// shifted, as in shifted()). x and y of the padded sizes, y must not alias x.
  /// x and y may be segments of longer vectors (a bordered matrix applies its flow part so).
  void apply_shifted(std::complex<double> sigma, Eigen::Ref<const vec<std::complex<double>>> x,
                     Eigen::Ref<vec<std::complex<double>>> y) const
    requires std::is_same_v<Scalar, double>
  {
    using C = std::complex<double>;
    require(nbr_ == nbc_, "apply_shifted: matrix is ", nbr_, "x", nbc_, " blocks, not square");
    require(x.size() == cols() && y.size() == rows(), "apply_shifted: vector sizes x ", x.size(), ", y ", y.size(),
            " do not match the ", rows(), "x", cols(), " (padded) matrix");
    require(x.data() != y.data(), "apply_shifted: y must not alias x");
    const index b = bs_;
    const C* xv = x.data();
    C* yv = y.data();
    const double* v = val_.data();
    const storage_index* cols = col_.data();
    const double sr = sigma.real(), si = sigma.imag();
    auto shift_row = [&](index i) {
      const index r1 = std::min(b, logical_rows_ - i * b);  // padded unknowns keep their identity
      for (index r = 0; r < r1; ++r) {
        const C xr = xv[i * b + r];
        yv[i * b + r] -= C(sr * xr.real() - si * xr.imag(), sr * xr.imag() + si * xr.real());
      }
    };
    if constexpr (B != Eigen::Dynamic) {
      for (index i = 0; i < nbr_; ++i) {
        const storage_index p0 = row_ptr_[i], p1 = row_ptr_[i + 1];
        // prefetched on every machine, unlike the complex SpMV on AMD (block_kernels.hpp): it gains
        // there too (Zen 5, bench_linear_solver: 58-60 % of STREAM without, 93-101 % with prefetchnta)
        internal::prefetch_ahead(v + index(p0) * B * B, index(p1 - p0) * B * B * index(sizeof(double)));
        internal::real_complex_row_accumulator<B> t;
        for (storage_index p = p0; p < p1; ++p) t.add(v + index(p) * B * B, xv + index(cols[p]) * B);
        t.store(yv + i * B);
        shift_row(i);
      }
    } else {
      for (index i = 0; i < nbr_; ++i) {
        for (index r = 0; r < b; ++r) yv[i * b + r] = C(0.0);
        for (storage_index p = row_ptr_[i]; p < row_ptr_[i + 1]; ++p) {
          const double* a = v + index(p) * b * b;
          const C* xs = xv + index(cols[p]) * b;
          for (index c = 0; c < b; ++c)
            for (index r = 0; r < b; ++r) {
              const double arc = a[c * b + r];
              yv[i * b + r] += C(arc * xs[c].real(), arc * xs[c].imag());
            }
        }
        shift_row(i);
      }
    }
  }

  /// y = A x for a real matrix and complex vectors (apply_shifted with sigma = 0).
  void apply(const vec<std::complex<double>>& x, vec<std::complex<double>>& y) const
    requires std::is_same_v<Scalar, double>
  {
    apply_shifted(std::complex<double>(0.0), x, y);
  }

 private:
  template <class, int>
  friend class block_sparse_matrix;

  index checked_find(index i, index j) const {
    require(i >= 0 && i < nbr_ && j >= 0 && j < nbc_, "block_sparse_matrix: block (", i, ", ", j, ") outside ", nbr_,
            "x", nbc_, " blocks");
    const index k = find(i, j);
    require(k >= 0, "block_sparse_matrix: block (", i, ", ", j, ") is not in the sparsity pattern");
    return k;
  }

  void check_product_sizes(index nx, index ny, const char* what) const {
    require(nx == cols() && ny == rows(), what, ": vector sizes x ", nx, ", y ", ny, " do not match the ", rows(), "x",
            cols(), " (padded) matrix");
  }

  template <bool Accumulate>
  void spmv(const Scalar& alpha, const Eigen::Ref<const vector_type>& x, Eigen::Ref<vector_type>& y) const {
    const index b = bs_;
    const Scalar* xv = x.data();
    Scalar* yv = y.data();
    const Scalar* v = val_.data();
    const storage_index* cols = col_.data();
    if constexpr (internal::has_fast_block_kernel_v<Scalar, B>) {
      const std::ptrdiff_t ahead = val_.size() * sizeof(Scalar) > internal::spmv_prefetch_min_bytes
                                       ? internal::spmv_prefetch_distance_bytes<Scalar>
                                       : 0;
      for (index i = 0; i < nbr_; ++i) {
        Scalar acc[B];
        for (int r = 0; r < B; ++r) acc[r] = Scalar(0.0);
        const storage_index p0 = row_ptr_[i];
        internal::prefetch_ahead(v + index(p0) * B * B, index(row_ptr_[i + 1] - p0) * B * B * index(sizeof(Scalar)),
                                 ahead);
        internal::block_row_gemv<1, B>(v + index(p0) * B * B, cols + p0, row_ptr_[i + 1] - p0, xv, acc);
        for (int r = 0; r < B; ++r) {
          if constexpr (Accumulate) yv[i * B + r] += alpha * acc[r];
          else yv[i * B + r] = acc[r];
        }
      }
    } else {
      for (index i = 0; i < nbr_; ++i) {
        segment_type acc = segment_type::Zero(b);
        for (storage_index p = row_ptr_[i]; p < row_ptr_[i + 1]; ++p)
          acc.noalias() += const_block_map(v + index(p) * b * b, b, b) *
                           Eigen::Map<const segment_type>(xv + index(cols[p]) * b, b);
        Eigen::Map<segment_type> yi(yv + i * b, b);
        if constexpr (Accumulate) yi += alpha * acc;
        else yi = acc;
      }
    }
  }

  // cols within each row: sorted, duplicates merged; values zero.
  void set_pattern_csr_unchecked(index block_rows, index block_cols, const std::vector<storage_index>& ptr,
                                 const std::vector<storage_index>& cols) {
    nbr_ = block_rows;
    nbc_ = block_cols;
    row_ptr_.assign(block_rows + 1, 0);
    col_.clear();
    col_.reserve(cols.size());
    std::vector<storage_index> row;
    for (index i = 0; i < block_rows; ++i) {
      row.assign(cols.begin() + ptr[i], cols.begin() + ptr[i + 1]);
      std::sort(row.begin(), row.end());
      row.erase(std::unique(row.begin(), row.end()), row.end());
      col_.insert(col_.end(), row.begin(), row.end());
      row_ptr_[i + 1] = static_cast<storage_index>(col_.size());
    }
    col_.shrink_to_fit();
    val_.assign(col_.size() * bs_ * bs_, Scalar(0.0));
    logical_rows_ = rows();
    logical_cols_ = this->cols();
  }

  index bs_;
  index nbr_ = 0, nbc_ = 0;
  index logical_rows_ = 0, logical_cols_ = 0;
  std::vector<storage_index> row_ptr_;
  std::vector<storage_index> col_;
  std::vector<Scalar> val_;
};

// ---- builders for the shifted systems of spec 07 -------------------------------------------

namespace internal {
/// The pattern of a square matrix with every diagonal block added.
template <class S, int B>
void pattern_with_diagonal(const block_sparse_matrix<S, B>& a, std::vector<int>& ptr, std::vector<int>& cols) {
  const auto n = a.block_rows();
  ptr.assign(n + 1, 0);
  cols.clear();
  cols.reserve(a.nonzero_blocks() + n);
  for (Eigen::Index i = 0; i < n; ++i) {
    bool has_diag = false;
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) {
      cols.push_back(a.col_index()[p]);
      has_diag = has_diag || a.col_index()[p] == i;
    }
    if (!has_diag) cols.push_back(static_cast<int>(i));
    ptr[i + 1] = static_cast<int>(cols.size());
  }
}
}  // namespace internal

/// A - sigma I (complex), e.g. sigma = i omega gives C_c = A - i omega I. The padded unknowns
/// keep their identity diagonal (not shifted). Diagonal blocks are added to the pattern if absent.
template <class S, int B>
block_sparse_matrix<std::complex<double>, B> shifted(const block_sparse_matrix<S, B>& a, std::complex<double> sigma) {
  using C = std::complex<double>;
  require(a.block_rows() == a.block_cols(), "shifted: matrix is ", a.block_rows(), "x", a.block_cols(),
          " blocks, not square");
  std::vector<int> ptr, cols;
  internal::pattern_with_diagonal(a, ptr, cols);
  block_sparse_matrix<C, B> c(a.block_size());
  c.set_pattern_csr(a.block_rows(), a.block_cols(), ptr, cols);
  c.set_logical_size(a.logical_rows(), a.logical_cols());
  const auto b = a.block_size();
  for (Eigen::Index i = 0; i < a.block_rows(); ++i) {
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p)
      c.block(i, a.col_index()[p]) = a.block_at(p).template cast<C>();
    auto d = c.block(i, i);
    for (Eigen::Index r = 0; r < b; ++r)
      if (i * b + r < a.logical_rows()) d(r, r) -= sigma;
  }
  return c;
}

/// A - sigma I for a real matrix with a fused shifted product on complex vectors
/// (block_sparse_matrix::apply_shifted: one pass over A; bordered_block_matrix likewise): the
/// operator of the shifted Krylov solves at half the matrix traffic of the assembled
/// shifted(A, sigma). Same product as shifted(A, sigma).apply.
template <class M>
concept fused_shift_matrix = requires(const M& m, std::complex<double> s, const vec<std::complex<double>>& x,
                                      vec<std::complex<double>>& y) {
  m.apply_shifted(s, x, y);
  { m.rows() } -> std::convertible_to<Eigen::Index>;
};

template <fused_shift_matrix M>
class shifted_operator<M, std::complex<double>> {
 public:
  shifted_operator(const M& a, std::complex<double> sigma) : a_(&a), sigma_(sigma) {}
  void apply(const vec<std::complex<double>>& x, vec<std::complex<double>>& y) const { a_->apply_shifted(sigma_, x, y); }
  Eigen::Index rows() const { return a_->rows(); }
  Eigen::Index cols() const { return a_->cols(); }
  std::complex<double> shift() const { return sigma_; }

 private:
  const M* a_;
  std::complex<double> sigma_;
};

/// Orderings of the real 2n x 2n form [[A, omega I], [-omega I, A]] of A - i omega I acting on
/// (x_re, x_im): split = all real parts then all imaginary parts (block rows i and nb + i);
/// interleaved = real and imaginary part of block i adjacent (block rows 2i and 2i + 1).
enum class real_form_ordering { split, interleaved };

namespace internal {
inline Eigen::Index real_form_row(Eigen::Index i, bool imag, Eigen::Index nb, real_form_ordering o) {
  return o == real_form_ordering::split ? i + (imag ? nb : 0) : 2 * i + (imag ? 1 : 0);
}
}  // namespace internal

/// The real equivalent of A - i omega I (same block size, twice the block rows): solving it for
/// the right-hand side real_form_vector(b) gives real_form_vector(x) of the complex solution.
template <int B>
block_sparse_matrix<double, B> real_shifted_form(const block_sparse_matrix<double, B>& a, double omega,
                                                 real_form_ordering ordering) {
  require(a.block_rows() == a.block_cols(), "real_shifted_form: matrix is ", a.block_rows(), "x", a.block_cols(),
          " blocks, not square");
  const auto nb = a.block_rows(), b = a.block_size();
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pattern;
  pattern.reserve(2 * a.nonzero_blocks() + 4 * nb);
  for (Eigen::Index i = 0; i < nb; ++i) {
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) {
      const Eigen::Index j = a.col_index()[p];
      for (bool im : {false, true})
        pattern.emplace_back(internal::real_form_row(i, im, nb, ordering), internal::real_form_row(j, im, nb, ordering));
    }
    for (bool im : {false, true}) {
      pattern.emplace_back(internal::real_form_row(i, im, nb, ordering), internal::real_form_row(i, !im, nb, ordering));
      pattern.emplace_back(internal::real_form_row(i, im, nb, ordering), internal::real_form_row(i, im, nb, ordering));
    }
  }
  block_sparse_matrix<double, B> r(b);
  r.set_pattern(2 * nb, 2 * nb, pattern);
  for (Eigen::Index i = 0; i < nb; ++i) {
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) {
      const Eigen::Index j = a.col_index()[p];
      for (bool im : {false, true})
        r.block(internal::real_form_row(i, im, nb, ordering), internal::real_form_row(j, im, nb, ordering)) +=
            a.block_at(p);
    }
    auto re_im = r.block(internal::real_form_row(i, false, nb, ordering), internal::real_form_row(i, true, nb, ordering));
    auto im_re = r.block(internal::real_form_row(i, true, nb, ordering), internal::real_form_row(i, false, nb, ordering));
    for (Eigen::Index k = 0; k < b; ++k)
      if (i * b + k < a.logical_rows()) {
        re_im(k, k) += omega;  // real rows:      A x_re + omega x_im
        im_re(k, k) -= omega;  // imaginary rows: -omega x_re + A x_im
      }
  }
  return r;
}

/// Complex padded vector z -> real vector of the real form in the given ordering.
template <class Derived>
vec<double> real_form_vector(const Eigen::MatrixBase<Derived>& z, Eigen::Index block_size, real_form_ordering o) {
  const Eigen::Index n = z.size(), nb = n / block_size;
  require(nb * block_size == n, "real_form_vector: size ", n, " is not a multiple of the block size ", block_size);
  vec<double> x(2 * n);
  for (Eigen::Index i = 0; i < nb; ++i) {
    x.segment(internal::real_form_row(i, false, nb, o) * block_size, block_size) = z.segment(i * block_size, block_size).real();
    x.segment(internal::real_form_row(i, true, nb, o) * block_size, block_size) = z.segment(i * block_size, block_size).imag();
  }
  return x;
}

/// Inverse of real_form_vector().
template <class Derived>
vec<std::complex<double>> complex_from_real_form(const Eigen::MatrixBase<Derived>& x, Eigen::Index block_size,
                                                 real_form_ordering o) {
  const Eigen::Index n = x.size() / 2, nb = n / block_size;
  require(2 * nb * block_size == x.size(), "complex_from_real_form: size ", x.size(), " is not 2 * block size * k");
  vec<std::complex<double>> z(n);
  for (Eigen::Index i = 0; i < nb; ++i) {
    z.segment(i * block_size, block_size).real() = x.segment(internal::real_form_row(i, false, nb, o) * block_size, block_size);
    z.segment(i * block_size, block_size).imag() = x.segment(internal::real_form_row(i, true, nb, o) * block_size, block_size);
  }
  return z;
}

// ---- bordered operator for the Hopf Newton systems --------------------------------------------

/// [[A, U], [V^T, D]] acting on (x, s) with x of A's size n and s of size k: A any operator
/// (block matrix, matrix-free), U = border_columns (n x k), V^T = border_rows (k x n), D = corner
/// (k x k). The Hopf Newton matrices are of this form with k = 1 or 2 around the (shifted)
/// Jacobian or its real 2n form.
template <class Op, class S>
class bordered_operator {
 public:
  using matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  bordered_operator(const Op& a, Eigen::Index n, matrix border_columns, const matrix& border_rows, matrix corner)
      : a_(&a), n_(n), u_(std::move(border_columns)), v_(border_rows.transpose()), d_(std::move(corner)) {
    const auto k = d_.rows();
    require(d_.cols() == k && u_.rows() == n && u_.cols() == k && v_.cols() == k && v_.rows() == n,
            "bordered_operator: border columns ", u_.rows(), "x", u_.cols(), ", border rows ", v_.cols(), "x",
            v_.rows(), ", corner ", d_.rows(), "x", d_.cols(), " inconsistent with n = ", n);
    require_operator_size(a, n, "bordered_operator", "inner operator");
    x1_.resize(n);
    y1_.resize(n);
  }
  Eigen::Index rows() const { return n_ + d_.rows(); }
  Eigen::Index border_size() const { return d_.rows(); }
  const matrix& border_columns() const { return u_; }
  auto border_rows() const { return v_.transpose(); }  ///< V^T (k x n)
  const matrix& corner() const { return d_; }
  const Op& inner_operator() const { return *a_; }

  void apply(const vec<S>& x, vec<S>& y) const {
    require(x.size() == rows() && y.size() == rows(), "bordered_operator::apply: vector sizes ", x.size(), ", ",
            y.size(), ", expected ", rows());
    x1_ = x.head(n_);
    apply_operator<S>(*a_, x1_, y1_);
    const auto k = d_.rows();
    y.head(n_) = y1_;
    y.head(n_).noalias() += u_ * x.tail(k);
    y.tail(k).noalias() = v_.transpose() * x1_;  // k dot products (a k x n matrix times x: 2-5x slower)
    y.tail(k).noalias() += d_ * x.tail(k);
  }

 private:
  const Op* a_;
  Eigen::Index n_;
  matrix u_, v_, d_;  // v_ = V (n x k): the border rows stored as columns
  mutable vec<S> x1_, y1_;
};

namespace internal {
/// The block elimination of a border of k unknowns around an n x n operator A, given a
/// preconditioner M of A (the algebra of bordered_preconditioner, which also serves
/// bordered_block_ilu): W = M^{-1} U (k applications of M, once), S = D - V^T W (k x k, dense LU);
/// apply() then costs one application of M. M is passed to every call, so the holder of the
/// elimination may own M and still be moved. apply() allocates nothing.
template <class S>
class border_elimination {
 public:
  using matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  template <class Pre, class Rows>
  void compute(const Pre& m, Eigen::Index n, const matrix& border_columns, const Eigen::MatrixBase<Rows>& border_rows,
               const matrix& corner, std::string_view who) {
    const auto k = corner.rows();
    require(corner.cols() == k && border_columns.rows() == n && border_columns.cols() == k && border_rows.rows() == k &&
                border_rows.cols() == n,
            who, ": border columns ", border_columns.rows(), "x", border_columns.cols(), ", border rows ",
            border_rows.rows(), "x", border_rows.cols(), ", corner ", corner.rows(), "x", corner.cols(),
            " inconsistent with n = ", n);
    require_operator_size(m, n, who, "inner preconditioner");
    n_ = n;
    w_.resize(n, k);
    r1_.resize(n);
    z1_.resize(n);
    for (Eigen::Index c = 0; c < k; ++c) {
      r1_ = border_columns.col(c);
      apply_operator<S>(m, r1_, z1_);
      w_.col(c) = z1_;
    }
    const matrix schur = corner - border_rows * w_;
    v_ = border_rows.transpose();
    if (!schur.allFinite()) throw singular_matrix_error(internal::concat(who, ": non-finite Schur complement"));
    schur_.compute(schur);
    if (k > 0 && !(std::abs(schur_.determinant()) > 0))
      throw singular_matrix_error(internal::concat(who, ": singular Schur complement of the border"));
    t_.resize(k);
    s_.resize(k);
  }
  Eigen::Index rows() const { return n_ + w_.cols(); }
  Eigen::Index border_size() const { return w_.cols(); }
  /// z = M_bordered^{-1} r (r, z of rows() entries, not aliased).
  template <class Pre>
  void apply(const Pre& m, const vec<S>& r, vec<S>& z) const {
    const auto k = w_.cols();
    r1_ = r.head(n_);
    apply_operator<S>(m, r1_, z1_);
    t_ = r.tail(k);
    t_.noalias() -= v_.transpose() * z1_;
    s_ = schur_.solve(t_);
    z.head(n_) = z1_;
    z.head(n_).noalias() -= w_ * s_;
    z.tail(k) = s_;
  }

 private:
  Eigen::Index n_ = 0;
  matrix w_, v_;  // W = M^{-1} U and V (n x k; V^T z as k dot products)
  Eigen::PartialPivLU<matrix> schur_;
  mutable vec<S> r1_, z1_, t_, s_;
};
}  // namespace internal

/// Preconditioner for a bordered operator by block elimination with a preconditioner M of A:
/// W = M^{-1} U (k applications, once), Schur complement S = D - V^T W (k x k, dense LU); then
/// each apply costs ONE application of M^{-1}: x' = M^{-1} r1, s = S^{-1}(r2 - V^T x'),
/// x = x' - W s. Exact when M^{-1} = A^{-1}. Keeps a pointer to M (which must outlive it).
template <class Pre, class S>
class bordered_preconditioner {
 public:
  template <class Op>
  bordered_preconditioner(const bordered_operator<Op, S>& a, const Pre& m) : m_(&m) {
    e_.compute(m, a.rows() - a.border_size(), a.border_columns(), a.border_rows(), a.corner(),
               "bordered_preconditioner");
  }
  Eigen::Index rows() const { return e_.rows(); }
  /// z = M_bordered^{-1} r; r and z of rows() entries (checked once per call).
  void apply(const vec<S>& r, vec<S>& z) const {
    require(r.size() == rows() && z.size() == rows(), "bordered_preconditioner::apply: vector sizes ", r.size(), ", ",
            z.size(), ", expected ", rows());
    e_.apply(*m_, r, z);
  }

 private:
  const Pre* m_;
  internal::border_elimination<S> e_;
};

}  // namespace aerohopf
