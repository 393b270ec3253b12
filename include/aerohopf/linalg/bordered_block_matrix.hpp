#pragma once
// Bordered block matrix: the Jacobian of a flow discretised in cells coupled to a structure of
// any size,
//
//     J = [[A_ff, A_fs],      A_ff  block_sparse_matrix<S, B> of the flow cells (n_f = cells * B)
//          [A_sf, A_ss]]      A_fs  n_f x n_s, A_sf n_s x n_f, A_ss n_s x n_s: dense, any n_s >= 0
//
// WHY: a modal wing has 5 x 5 flow blocks and 2m structural unknowns (m modes); padding the
// structure into flow blocks works only when n_s happens to be the block size, and even then the
// BILU of the padded matrix treats the dense structural row and column by incomplete
// factorisation. Here the structure is a dense border: J x costs the flow SpMV plus 2 n_f n_s
// multiply-adds, and the preconditioner eliminates the border exactly (Schur complement, n_s x n_s)
// around the BILU(k) of the flow part.
//
// USAGE
//   bordered_block_matrix<double, 5> j(std::move(a_ff), a_fs, a_sf, a_ss);  // sizes checked
//   j.apply(x, y);                              // y = J x (x, y of n_f + n_s entries)
//   j.apply_shifted(sigma, xc, yc);             // yc = (J - sigma I) xc, complex vectors, one pass
//   shifted_operator<bordered_block_matrix<double, 5>, std::complex<double>> op(j, sigma);  // fused
//   bordered_block_ilu<std::complex<double>, 5> m(opts);  m.compute(l, sigma);  // M ~ (L - sigma I)^{-1}
//   gmres<std::complex<double>>(op, m, b, x, ko);
//   auto jb = bordered_from_sparse<5>(sparse_j, n_s);      // the last n_s unknowns as the border
//   auto jp = bordered_from_padded(padded_j, n_s);         // a padded block matrix, likewise
//   Eigen::MatrixXd d = j.to_dense();  Eigen::SparseMatrix<double> s = j.to_sparse();
//
// Invariants: A_ff is square and has no padding (logical size = padded size), so vectors are
// exactly [x_f (n_f), x_s (n_s)] and no consumer pads. The products allocate nothing.
#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>

#include <complex>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../scalar/complex.hpp"
#include "block_ilu.hpp"
#include "block_sparse_matrix.hpp"
#include "operator.hpp"

namespace aerohopf {

template <class S, int B>
class bordered_block_matrix {
 public:
  using scalar_type = S;
  using index = Eigen::Index;
  using flow_matrix = block_sparse_matrix<S, B>;
  using dense_matrix = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  static constexpr int compile_block_size = B;

  /// The empty matrix (no unknowns).
  bordered_block_matrix() : fs_(0, 0), sf_(0, 0), ss_(0, 0) {}

  /// [[a_ff, a_fs], [a_sf, a_ss]]; throws input_error (prefixed by who) unless a_ff is square
  /// without padding and the border blocks fit it and each other.
  bordered_block_matrix(flow_matrix a_ff, dense_matrix a_fs, dense_matrix a_sf, dense_matrix a_ss,
                        std::string_view who = "bordered_block_matrix")
      : ff_(std::move(a_ff)), fs_(std::move(a_fs)), sf_(std::move(a_sf)), ss_(std::move(a_ss)) {
    require(ff_.block_rows() == ff_.block_cols(), who, ": flow part is ", ff_.block_rows(), "x", ff_.block_cols(),
            " blocks, not square");
    require(ff_.logical_rows() == ff_.rows() && ff_.logical_cols() == ff_.cols(), who, ": flow part is padded (logical ",
            ff_.logical_rows(), " of ", ff_.rows(), " rows); it must hold whole cells, the rest belongs in the border");
    const index nf = ff_.rows(), ns = ss_.rows();
    require(ss_.cols() == ns && fs_.rows() == nf && fs_.cols() == ns && sf_.rows() == ns && sf_.cols() == nf, who,
            ": border blocks A_fs ", fs_.rows(), "x", fs_.cols(), ", A_sf ", sf_.rows(), "x", sf_.cols(), ", A_ss ",
            ss_.rows(), "x", ss_.cols(), " do not fit a flow part of ", nf, " unknowns and ", ns,
            " structural unknowns (expected ", nf, "x", ns, ", ", ns, "x", nf, ", ", ns, "x", ns, ")");
  }

  index flow_size() const { return ff_.rows(); }
  index structure_size() const { return ss_.rows(); }
  index rows() const { return flow_size() + structure_size(); }
  index cols() const { return rows(); }
  index block_size() const { return ff_.block_size(); }

  const flow_matrix& flow() const { return ff_; }        ///< A_ff
  const dense_matrix& flow_structure() const { return fs_; }  ///< A_fs (border columns)
  const dense_matrix& structure_flow() const { return sf_; }  ///< A_sf (border rows)
  const dense_matrix& structure() const { return ss_; }       ///< A_ss (corner)

  /// y = J x; x and y of rows() entries, y not aliasing x.
  void apply(const vec<S>& x, vec<S>& y) const {
    check_vectors(x.size(), y.size(), x.data() == y.data(), "apply");
    const index nf = flow_size(), ns = structure_size();
    ff_.multiply(x.head(nf), y.head(nf));
    if (ns == 0) return;
    y.head(nf).noalias() += fs_ * x.tail(ns);
    y.tail(ns).noalias() = sf_ * x.head(nf);
    y.tail(ns).noalias() += ss_ * x.tail(ns);
  }

  /// y = (J - sigma I) x for a real J and complex vectors: one pass over the flow blocks
  /// (block_sparse_matrix::apply_shifted) plus the border; x and y of rows() entries, not aliased.
  void apply_shifted(std::complex<double> sigma, const vec<std::complex<double>>& x,
                     vec<std::complex<double>>& y) const
    requires std::is_same_v<S, double>
  {
    check_vectors(x.size(), y.size(), x.data() == y.data(), "apply_shifted");
    const index nf = flow_size(), ns = structure_size();
    ff_.apply_shifted(sigma, x.head(nf), y.head(nf));
    if (ns == 0) return;
    y.head(nf).noalias() += fs_ * x.tail(ns);
    y.tail(ns).noalias() = sf_ * x.head(nf);
    y.tail(ns).noalias() += ss_ * x.tail(ns);
    y.tail(ns) -= sigma * x.tail(ns);
  }

  /// y = J x for a real J and complex vectors (apply_shifted with sigma = 0).
  void apply(const vec<std::complex<double>>& x, vec<std::complex<double>>& y) const
    requires std::is_same_v<S, double>
  {
    apply_shifted(std::complex<double>(0.0), x, y);
  }

  /// ||J||_inf, the largest absolute row sum (the scale of attainable residuals).
  double norm_inf() const {
    double m = 0;
    const index b = block_size(), ns = structure_size();
    vec<double> sums(b);
    for (index i = 0; i < ff_.block_rows(); ++i) {
      sums.setZero();
      for (auto p = ff_.row_ptr()[i]; p < ff_.row_ptr()[i + 1]; ++p)
        sums += ff_.block_at(p).cwiseAbs().rowwise().sum().template cast<double>();
      if (ns > 0) sums += fs_.middleRows(i * b, b).cwiseAbs().rowwise().sum().template cast<double>();
      m = std::max(m, sums.maxCoeff());
    }
    for (index r = 0; r < ns; ++r)
      m = std::max(m, double(sf_.row(r).cwiseAbs().sum() + ss_.row(r).cwiseAbs().sum()));
    return m;
  }

  /// The whole matrix, dense (tests, small systems).
  dense_matrix to_dense() const {
    const index nf = flow_size(), ns = structure_size();
    dense_matrix d(rows(), cols());
    d.topLeftCorner(nf, nf) = dense_matrix(ff_.to_sparse());
    d.topRightCorner(nf, ns) = fs_;
    d.bottomLeftCorner(ns, nf) = sf_;
    d.bottomRightCorner(ns, ns) = ss_;
    return d;
  }

  /// The whole matrix as an Eigen sparse matrix: every entry of the flow blocks (explicit zeros
  /// included, as block_sparse_matrix::to_sparse) and the non-zero entries of the border.
  Eigen::SparseMatrix<S> to_sparse() const {
    const index nf = flow_size(), ns = structure_size();
    const Eigen::SparseMatrix<S> f = ff_.to_sparse();
    std::vector<Eigen::Triplet<S>> t;
    t.reserve(static_cast<std::size_t>(f.nonZeros() + 2 * nf * ns + ns * ns));
    for (int k = 0; k < f.outerSize(); ++k)
      for (typename Eigen::SparseMatrix<S>::InnerIterator it(f, k); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
    auto add = [&](const dense_matrix& m, index r0, index c0) {
      for (index c = 0; c < m.cols(); ++c)
        for (index r = 0; r < m.rows(); ++r)
          if (m(r, c) != S(0.0)) t.emplace_back(r0 + r, c0 + c, m(r, c));
    };
    add(fs_, 0, nf);
    add(sf_, nf, 0);
    add(ss_, nf, nf);
    Eigen::SparseMatrix<S> s(rows(), cols());
    s.setFromTriplets(t.begin(), t.end());
    return s;
  }

 private:
  void check_vectors(index nx, index ny, bool aliased, const char* what) const {
    require(nx == rows() && ny == rows(), "bordered_block_matrix::", what, ": vector sizes x ", nx, ", y ", ny,
            ", expected ", rows(), " (", flow_size(), " flow + ", structure_size(), " structural unknowns)");
    require(!aliased || rows() == 0, "bordered_block_matrix::", what, ": y must not alias x");
  }

  flow_matrix ff_;
  dense_matrix fs_, sf_, ss_;
};

/// J - sigma I as a complex bordered matrix (the flow part by shifted(), the corner shifted).
template <class S, int B>
bordered_block_matrix<std::complex<double>, B> shifted(const bordered_block_matrix<S, B>& a, std::complex<double> sigma) {
  using C = std::complex<double>;
  using D = typename bordered_block_matrix<C, B>::dense_matrix;
  D ss = a.structure().template cast<C>();
  ss.diagonal().array() -= sigma;
  return {shifted(a.flow(), sigma), a.flow_structure().template cast<C>(), a.structure_flow().template cast<C>(),
          std::move(ss), "shifted(bordered_block_matrix)"};
}

/// The preconditioner of a bordered matrix J - sigma I: BILU(k) of the flow part A_ff - sigma I
/// and the exact elimination of the border around it (the algebra of bordered_preconditioner:
/// Schur complement (A_ss - sigma I) - A_sf M^{-1} A_fs, dense LU), so each apply costs one BILU
/// solve plus O(n_f n_s). The flow part is shifted for a real J and a complex S; otherwise
/// sigma must be 0. The BILU's symbolic phase is kept while the flow pattern does not change.
/// Failures: as block_ilu (singular_matrix_error on a singular pivot block), and
/// singular_matrix_error for a singular Schur complement.
template <class S, int B>
class bordered_block_ilu {
 public:
  explicit bordered_block_ilu(block_ilu_options options = {})
      : context_(options.context), ilu_(std::move(options)) {}

  template <class T>
  bordered_block_ilu& compute(const bordered_block_matrix<T, B>& l, S sigma = S(0.0)) {
    using D = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
    computed_ = false;
    nf_ = l.flow_size();
    ns_ = l.structure_size();
    if (nf_ > 0) {
      if constexpr (std::is_same_v<T, S>) {
        if (sigma == S(0.0)) ilu_.compute(l.flow());
        else ilu_.compute(shifted_flow(l.flow(), sigma));
      } else {
        ilu_.compute(shifted_flow(l.flow(), sigma));
      }
    }
    D corner = l.structure().template cast<S>();
    corner.diagonal().array() -= sigma;
    const std::string who = internal::concat(context_, ": border elimination");
    const D fs = l.flow_structure().template cast<S>(), sf = l.structure_flow().template cast<S>();
    if (ns_ > 0 && nf_ > 0) border_.compute(ilu_, nf_, fs, sf, corner, who);
    else if (ns_ > 0) border_.compute(identity_preconditioner{}, nf_, fs, sf, corner, who);
    computed_ = true;
    return *this;
  }

  Eigen::Index rows() const { return nf_ + ns_; }
  Eigen::Index structure_size() const { return ns_; }
  const block_ilu<S, B>& flow_preconditioner() const { return ilu_; }

  /// z = M^{-1} r; r and z of rows() entries. Allocates nothing.
  void apply(const vec<S>& r, vec<S>& z) const {
    require(computed_, context_, ": apply() before a successful compute()");
    require(r.size() == rows() && z.size() == rows(), context_, ": apply: vector sizes ", r.size(), ", ", z.size(),
            ", expected ", rows(), " (", nf_, " flow + ", ns_, " structural unknowns)");
    if (ns_ == 0) ilu_.apply(r, z);
    else if (nf_ == 0) border_.apply(identity_preconditioner{}, r, z);
    else border_.apply(ilu_, r, z);
  }

 private:
  template <class T>
  block_sparse_matrix<S, B> shifted_flow(const block_sparse_matrix<T, B>& a, S sigma) const {
    if constexpr (is_complex_v<S> && std::is_same_v<T, double>) {
      return shifted(a, sigma);
    } else {
      require(sigma == S(0.0), context_, ": a shift needs a complex preconditioner of a real matrix");
      return a.template cast<S>();
    }
  }

  std::string context_;
  block_ilu<S, B> ilu_;
  internal::border_elimination<S> border_;
  Eigen::Index nf_ = 0, ns_ = 0;
  bool computed_ = false;
};

/// An Eigen sparse matrix (n x n) viewed as flow blocks of B (the first n - border unknowns, a
/// multiple of B) and a dense border of the last `border` unknowns. Explicit zeros of the flow
/// part keep their blocks (from_sparse), so the pattern of an assembled Jacobian survives.
template <int B, class SparseDerived>
auto bordered_from_sparse(const Eigen::SparseMatrixBase<SparseDerived>& a_in, Eigen::Index border,
                          std::string_view who = "bordered_from_sparse") {
  static_assert(B != Eigen::Dynamic && B > 0, "bordered_from_sparse: the block size must be a compile-time constant");
  using S = typename SparseDerived::Scalar;
  using D = typename bordered_block_matrix<S, B>::dense_matrix;
  const Eigen::SparseMatrix<S> a = a_in.derived();
  const Eigen::Index n = a.rows(), nf = n - border;
  require(a.cols() == n, who, ": matrix is ", a.rows(), "x", a.cols(), ", not square");
  require(border >= 0 && nf >= 0 && nf % B == 0, who, ": a border of ", border, " of ", n,
          " unknowns leaves a flow part that is not a whole number of blocks of ", B);
  std::vector<Eigen::Triplet<S>> t;
  t.reserve(static_cast<std::size_t>(a.nonZeros()));
  D fs = D::Zero(nf, border), sf = D::Zero(border, nf), ss = D::Zero(border, border);
  for (int k = 0; k < a.outerSize(); ++k)
    for (typename Eigen::SparseMatrix<S>::InnerIterator it(a, k); it; ++it) {
      const Eigen::Index r = it.row(), c = it.col();
      if (r < nf && c < nf) t.emplace_back(r, c, it.value());
      else if (r < nf) fs(r, c - nf) += it.value();
      else if (c < nf) sf(r - nf, c) += it.value();
      else ss(r - nf, c - nf) += it.value();
    }
  Eigen::SparseMatrix<S> f(nf, nf);
  f.setFromTriplets(t.begin(), t.end());
  return bordered_block_matrix<S, B>(block_sparse_matrix<S, B>::from_sparse(f, B), std::move(fs), std::move(sf),
                                     std::move(ss), who);
}

/// A padded block matrix (logical size n) viewed as flow blocks (the first n - border unknowns,
/// a multiple of B) and a dense border of the last `border` logical unknowns; the padding is
/// dropped. The flow part keeps the blocks of the padded pattern, values copied bit for bit.
template <class S, int B>
bordered_block_matrix<S, B> bordered_from_padded(const block_sparse_matrix<S, B>& a, Eigen::Index border,
                                                 std::string_view who = "bordered_from_padded") {
  using D = typename bordered_block_matrix<S, B>::dense_matrix;
  const Eigen::Index b = a.block_size(), n = a.logical_rows(), nf = n - border;
  require(a.block_rows() == a.block_cols() && a.logical_cols() == n, who, ": matrix is ", a.logical_rows(), "x",
          a.logical_cols(), ", not square");
  require(border >= 0 && nf >= 0 && nf % b == 0, who, ": a border of ", border, " of ", n,
          " unknowns leaves a flow part that is not a whole number of blocks of ", b);
  const auto nfb = static_cast<int>(nf / b);
  std::vector<int> ptr(static_cast<std::size_t>(nfb) + 1, 0), cols;
  cols.reserve(static_cast<std::size_t>(a.nonzero_blocks()));
  for (int i = 0; i < nfb; ++i) {
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p)
      if (a.col_index()[p] < nfb) cols.push_back(a.col_index()[p]);
    ptr[i + 1] = static_cast<int>(cols.size());
  }
  block_sparse_matrix<S, B> f(b);
  f.set_pattern_csr(nfb, nfb, ptr, cols);
  D fs = D::Zero(nf, border), sf = D::Zero(border, nf), ss = D::Zero(border, border);
  int q = 0;  // position in f's storage: f keeps a's order of the flow columns
  for (Eigen::Index i = 0; i < a.block_rows(); ++i)
    for (int p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p) {
      const Eigen::Index j = a.col_index()[p];
      const auto blk = a.block_at(p);
      if (i < nfb && j < nfb) {
        f.block_at(q++) = blk;
        continue;
      }
      for (Eigen::Index c = 0; c < b; ++c)
        for (Eigen::Index r = 0; r < b; ++r) {
          const Eigen::Index gr = i * b + r, gc = j * b + c;
          if (gr >= n || gc >= n) continue;
          if (gr < nf) fs(gr, gc - nf) = blk(r, c);
          else if (gc < nf) sf(gr - nf, gc) = blk(r, c);
          else ss(gr - nf, gc - nf) = blk(r, c);
        }
    }
  return {std::move(f), std::move(fs), std::move(sf), std::move(ss), who};
}

}  // namespace aerohopf
