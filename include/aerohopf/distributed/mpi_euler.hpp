#pragma once
// The Euler residual, its Jacobians and their products on a grid partitioned over MPI ranks
// (optional component: needs <mpi.h>; CMake target aerohopf::mpi, from find_package(aerohopf
// CONFIG COMPONENTS mpi)). Each rank owns whole blocks (partition.hpp) and holds its cells'
// values as a local vector. The cells other ranks' halos read are sent by nonblocking
// point-to-point messages, one per neighbouring rank (halo_plan); then the rank evaluates its
// blocks (euler_model::residual_of_blocks, flow::assemble_jacobian with a numbering): its rows,
// bitwise the serial ones (the same operations in the same order per cell). Jacobian rows are
// numbered locally: the owned cells, then the received ones by source rank, so a product A x
// needs x's received values only.
//
// Memory: the grid and its metrics are replicated on every rank, and each rank keeps two
// full-length scratch vectors (the state: owned and received cells current, the rest the free
// stream, never read; and the residual) and the global-to-local map: 88 bytes per cell in 3D,
// 126 MB for 1.43 million cells. A residual over the owned and received cells only is the step
// that removes them.
//
// Errors are collective: a rank whose evaluation throws (a bad local size, a non-physical cell)
// makes every rank throw, the failing rank its own error and the others an input_error naming
// that rank, so no rank waits in a later collective call for one that left.

#include <mpi.h>

#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/flow/euler_model.hpp>
#include <aerohopf/flow/jacobian.hpp>
#include <aerohopf/linalg/block_sparse_matrix.hpp>

#include <array>
#include <complex>
#include <cstddef>
#include <type_traits>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerohopf::distributed {

namespace internal {

inline void check_mpi(int code, const char* call) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  throw std::runtime_error(aerohopf::internal::concat("MPI: ", call, " failed: ", std::string(text, len)));
}

/// The number of ranks of comm.
inline int comm_size(MPI_Comm comm) {
  int n = 0;
  check_mpi(MPI_Comm_size(comm, &n), "MPI_Comm_size");
  return n;
}

/// This process's rank in comm.
inline int comm_rank(MPI_Comm comm) {
  int r = 0;
  check_mpi(MPI_Comm_rank(comm, &r), "MPI_Comm_rank");
  return r;
}

/// p[0 .. n) summed over the ranks of comm, in place (collective).
inline void sum_over_ranks(MPI_Comm comm, double* p, int n) {
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, p, n, MPI_DOUBLE, MPI_SUM, comm), "MPI_Allreduce");
}
inline void sum_over_ranks(MPI_Comm comm, std::complex<double>* p, int n) {
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, p, n, MPI_C_DOUBLE_COMPLEX, MPI_SUM, comm), "MPI_Allreduce");
}

/// The largest v over the ranks of comm, on every rank (collective).
inline double max_over_ranks(MPI_Comm comm, double v) {
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, comm), "MPI_Allreduce");
  return v;
}

/// Whether `ok` holds on every rank of comm (collective).
inline bool on_every_rank(MPI_Comm comm, bool ok) {
  int v = ok ? 1 : 0;
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_MIN, comm), "MPI_Allreduce");
  return v == 1;
}

/// Runs f on every rank; if it throws on any rank, every rank throws (collective).
template <class F>
void collective(MPI_Comm comm, const char* what, F&& f) {
  std::exception_ptr error;
  try {
    f();
  } catch (...) {
    error = std::current_exception();
  }
  const int mine = error ? comm_rank(comm) : -1;
  int first = -1;
  check_mpi(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MAX, comm), "MPI_Allreduce");
  if (error) std::rethrow_exception(error);
  if (first >= 0) throw input_error(aerohopf::internal::concat(what, ": refused on rank ", first, " (its message there)"));
}

}  // namespace internal

/// fn() on rank 0 of comm only (output: printing, writing files), its failure thrown on every
/// rank (as internal::collective: the others would otherwise wait in the next collective call).
template <class F>
void on_root(MPI_Comm comm, const char* what, F&& fn) {
  const int rank = internal::comm_rank(comm);
  internal::collective(comm, what, [&] {
    if (rank == 0) fn();
  });
}

template <int Dim>
class distributed_euler {
 public:
  static constexpr int nv = flow::euler_model<Dim>::nv;

  /// `model` (the same grid and free stream on every rank) must outlive this object; `part`
  /// assigns its blocks to the ranks of `comm` (part.ranks must equal the communicator's size).
  /// Collective.
  distributed_euler(const flow::euler_model<Dim>& model, const block_partition& part, MPI_Comm comm)
      : model_(model), comm_(comm), part_(part) {
    rank_ = internal::comm_rank(comm_);
    const int size = internal::comm_size(comm_);
    internal::collective(comm_, "distributed_euler", [&] {
      require(part.ranks == size, "distributed_euler: the partition has ", part.ranks, " ranks, the communicator ",
              size);
      plan_ = make_halo_plan(model_, part, rank_);
    });
    // local numbering: the owned cells in global order, then the received cells by source rank
    numbering_.blocks = plan_.owned_blocks;
    numbering_.local.assign(model_.n_cells(), -1);
    Eigen::Index k = 0;
    for (const auto& [first, last] : plan_.owned)
      for (std::size_t c = first; c < last; ++c) numbering_.local[c] = k++;
    numbering_.rows = k;
    ghost_offset_.assign(plan_.ranks + 1, 0);
    for (int q = 0; q < plan_.ranks; ++q) {
      ghost_offset_[q] = k;
      for (const std::size_t c : plan_.recv[q]) numbering_.local[c] = k++;
    }
    ghost_offset_[plan_.ranks] = k;
    numbering_.cols = k;
    send_local_.resize(plan_.ranks);
    send_.resize(plan_.ranks);
    for (int q = 0; q < plan_.ranks; ++q)
      for (const std::size_t c : plan_.send[q]) send_local_[q].push_back(numbering_.local[c]);
    scratch_ = model_.template free_stream_vector<double>();
    residual_.setZero(model_.size());
  }

  const halo_plan& plan() const { return plan_; }
  int rank() const { return rank_; }
  /// Values in this rank's local state (its owned cells times nv).
  Eigen::Index local_size() const { return static_cast<Eigen::Index>(plan_.owned_cells() * nv); }

  /// This rank's part of a global state (model.size() values, as the serial solver has it).
  vec<double> local_part(const vec<double>& global) const {
    require_size(global.size(), model_.size(), "distributed_euler::local_part", "global state");
    vec<double> local(local_size());
    Eigen::Index k = 0;
    for (const auto& [a, b] : plan_.owned) {
      const auto n = static_cast<Eigen::Index>((b - a) * nv);
      local.segment(k, n) = global.segment(static_cast<Eigen::Index>(a * nv), n);
      k += n;
    }
    return local;
  }

  /// The global state assembled from every rank's local part, on every rank (collective; for
  /// output and tests: it is model.size() values).
  vec<double> all_gather(const vec<double>& local) const {
    internal::collective(comm_, "distributed_euler::all_gather",
                         [&] { require_size(local.size(), local_size(), "distributed_euler::all_gather", "local state"); });
    vec<double> global(model_.size());
    // each rank broadcasts its ranges in turn: the ranges are known to all from the partition
    for (int q = 0; q < plan_.ranks; ++q) {
      std::vector<double> buf;
      if (q == rank_) buf.assign(local.data(), local.data() + local.size());
      long long n = static_cast<long long>(buf.size());
      internal::check_mpi(MPI_Bcast(&n, 1, MPI_LONG_LONG, q, comm_), "MPI_Bcast");
      buf.resize(static_cast<std::size_t>(n));
      internal::check_mpi(MPI_Bcast(buf.data(), static_cast<int>(n), MPI_DOUBLE, q, comm_), "MPI_Bcast");
      std::size_t k = 0;
      for (std::size_t b = 0; b < plan_.owned_blocks.size(); ++b) {
        if (part_.owner[b] != q) continue;
        const std::size_t first = model_.cell_offset(static_cast<int>(b)) * nv;
        const std::size_t last = model_.cell_offset(static_cast<int>(b) + 1) * nv;
        for (std::size_t i = first; i < last; ++i) global[static_cast<Eigen::Index>(i)] = buf[k++];
      }
    }
    return global;
  }

  /// Local numbering of this rank's Jacobian rows and columns (flow::jacobian_numbering): the
  /// owned cells, then the received cells by source rank.
  const flow::jacobian_numbering& numbering() const { return numbering_; }

  /// `local` followed by the values of the received cells (numbering().cols cells): sends the
  /// cells other ranks read and receives those this rank reads (collective). S is double or
  /// std::complex<double> (sent as pairs of doubles).
  template <class S>
  vec<S> with_ghosts(const vec<S>& local) {
    static_assert(std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>,
                  "with_ghosts: double or std::complex<double> values");
    constexpr int k = static_cast<int>(sizeof(S) / sizeof(double));  // doubles per value
    internal::collective(comm_, "distributed_euler::with_ghosts", [&] {
      require_size(local.size(), local_size(), "distributed_euler::with_ghosts", "local vector");
    });
    vec<S> ext(numbering_.cols * nv);
    ext.head(local.size()) = local;
    std::vector<MPI_Request> req;
    req.reserve(2 * plan_.ranks);
    constexpr int tag = 7301;
    for (int q = 0; q < plan_.ranks; ++q) {
      const auto n = (ghost_offset_[q + 1] - ghost_offset_[q]) * nv * k;
      if (n == 0) continue;
      req.emplace_back();
      internal::check_mpi(MPI_Irecv(reinterpret_cast<double*>(ext.data() + ghost_offset_[q] * nv), static_cast<int>(n),
                                    MPI_DOUBLE, q, tag, comm_, &req.back()),
                          "MPI_Irecv");
    }
    for (int q = 0; q < plan_.ranks; ++q) {
      if (send_local_[q].empty()) continue;
      auto& buf = send_[q];
      buf.resize(send_local_[q].size() * nv * k);  // allocates once per value type
      S* out = reinterpret_cast<S*>(buf.data());
      std::size_t i = 0;
      for (const Eigen::Index c : send_local_[q])
        for (int v = 0; v < nv; ++v) out[i++] = local[c * nv + v];
      req.emplace_back();
      internal::check_mpi(MPI_Isend(buf.data(), static_cast<int>(buf.size()), MPI_DOUBLE, q, tag, comm_, &req.back()),
                          "MPI_Isend");
    }
    internal::check_mpi(MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    return ext;
  }

  /// dR/dw in this rank's rows at the distributed state `local`, columns in numbering() (each
  /// entry bitwise the serial Jacobian's; the pattern is set on first use and reused).
  /// Collective.
  void jacobian(const vec<double>& local, flow::jacobian_kind kind, block_sparse_matrix<double, nv>& a) {
    load_state(local);
    internal::collective(comm_, "distributed_euler::jacobian",
                         [&] { flow::assemble_jacobian<Dim>(model_, scratch_, kind, a, &numbering_); });
  }

  /// y = A x for a real matrix of this rank's rows in numbering() (jacobian()) and x distributed
  /// as states are, real or complex (collective: the ghost values of x are exchanged).
  template <class S>
  vec<S> multiply(const block_sparse_matrix<double, nv>& a, const vec<S>& x) {
    const vec<S> ext = with_ghosts(x);
    vec<S> y(local_size());
    internal::collective(comm_, "distributed_euler::multiply", [&] {
      require(a.block_rows() == numbering_.rows && a.block_cols() == numbering_.cols,
              "distributed_euler::multiply: the matrix has ", a.block_rows(), " x ", a.block_cols(),
              " blocks, this rank's numbering ", numbering_.rows, " x ", numbering_.cols);
      if constexpr (std::is_same_v<S, double>) {
        a.multiply(ext, y);
      } else {  // a real rectangular matrix: real and imaginary parts by two real products
        const vec<double> re = ext.real(), im = ext.imag();
        vec<double> yr(y.size()), yi(y.size());
        a.multiply(re, yr);
        a.multiply(im, yi);
        y.real() = yr;
        y.imag() = yi;
      }
    });
    return y;
  }

  /// R in this rank's cells at the distributed state whose local part is `local` (collective).
  vec<double> residual(const vec<double>& local) { return residual(local, model_.metrics()); }

  /// The same on other metrics of the model's grid (a moved grid: an aeroelastic system's).
  vec<double> residual(const vec<double>& local, const flow::grid_metrics<double, Dim>& metrics) {
    load_state(local);
    vec<double> r(local_size());
    internal::collective(comm_, "distributed_euler::residual", [&] {
      model_.template residual_of_blocks<double>(metrics, scratch_.data(), residual_.data(), plan_.owned_blocks);
      r = local_part(residual_);
    });
    return r;
  }

  /// The whole-grid state as this rank sees it after the halo exchange of `local` (collective):
  /// its own and its received cells current, every other cell the free stream (physical, never
  /// read by this rank's evaluations). Valid until the next evaluation.
  const vec<double>& state_with_halo(const vec<double>& local) {
    load_state(local);
    return scratch_;
  }

  /// The blocks this rank owns (one entry per block of the grid).
  const std::vector<char>& owned_blocks() const { return plan_.owned_blocks; }

  /// The local time-step denominators (euler_model::spectral_radius) of this rank's cells, one
  /// per cell (collective).
  vec<double> spectral_radius(const vec<double>& local) {
    load_state(local);
    vec<double> rad(static_cast<Eigen::Index>(plan_.owned_cells()));
    internal::collective(comm_, "distributed_euler::spectral_radius", [&] {
      rad = cells_of(model_.spectral_radius(scratch_, &plan_.owned_blocks));
    });
    return rad;
  }

  /// The force coefficients of the whole body: each rank's walls, summed (collective; the same
  /// values on every rank).
  flow::force_coefficients forces(const vec<double>& local) {
    load_state(local);
    std::array<double, 6> fm{};
    internal::collective(comm_, "distributed_euler::forces", [&] {
      const auto c = model_.forces(scratch_, &plan_.owned_blocks);
      for (int i = 0; i < 3; ++i) {
        fm[i] = c.force[i];
        fm[3 + i] = c.moment[i];
      }
    });
    internal::sum_over_ranks(comm_, fm.data(), 6);
    return model_.coefficients({fm[0], fm[1], fm[2]}, {fm[3], fm[4], fm[5]});
  }

  /// Empty if every cell this rank's residual reads (its own and the received ones) has
  /// positive, finite density and pressure, else which is not (collective: the halo exchange).
  std::string nonphysical(const vec<double>& local) {
    load_state(local);
    const auto d = model_.first_nonphysical_cell(scratch_.data(), plan_.owned_blocks);
    if (!d) return {};
    return aerohopf::internal::concat("non-positive density or pressure in ", model_.cell_name(d->global),
                                      " (state cell ", d->global, ")");
  }

  /// Cell volumes of this rank's cells, in its local order.
  std::vector<double> volumes() const {
    std::vector<double> v;
    v.reserve(plan_.owned_cells());
    for (std::size_t b = 0; b < plan_.owned_blocks.size(); ++b)
      if (plan_.owned_blocks[b])
        for (const double x : model_.metrics().blocks[b].volume) v.push_back(x);
    return v;
  }

  /// Global cell number of this rank's local cell c.
  std::size_t global_cell(Eigen::Index c) const {
    for (const auto& [first, last] : plan_.owned) {
      if (c < static_cast<Eigen::Index>(last - first)) return first + static_cast<std::size_t>(c);
      c -= static_cast<Eigen::Index>(last - first);
    }
    throw input_error(aerohopf::internal::concat("distributed_euler::global_cell: local cell out of range"));
  }

  const flow::euler_model<Dim>& model() const { return model_; }
  MPI_Comm communicator() const { return comm_; }

 private:
  /// This rank's entries of a per-cell vector over all cells.
  vec<double> cells_of(const vec<double>& all) const {
    vec<double> v(static_cast<Eigen::Index>(plan_.owned_cells()));
    Eigen::Index k = 0;
    for (const auto& [first, last] : plan_.owned)
      for (std::size_t c = first; c < last; ++c) v[k++] = all[static_cast<Eigen::Index>(c)];
    return v;
  }

  /// The full-length scratch holds `local` and the received cells (collective).
  void load_state(const vec<double>& local) {
    const vec<double> ext = with_ghosts(local);
    for (const auto& [first, last] : plan_.owned)
      for (std::size_t c = first; c < last; ++c)
        scratch_.segment(static_cast<Eigen::Index>(c * nv), nv) = ext.segment(numbering_.local[c] * nv, nv);
    for (int q = 0; q < plan_.ranks; ++q)
      for (const std::size_t c : plan_.recv[q])
        scratch_.segment(static_cast<Eigen::Index>(c * nv), nv) = ext.segment(numbering_.local[c] * nv, nv);
  }

  const flow::euler_model<Dim>& model_;
  MPI_Comm comm_;
  int rank_ = 0;
  block_partition part_;
  halo_plan plan_;
  flow::jacobian_numbering numbering_;
  std::vector<Eigen::Index> ghost_offset_;            // first local column of each source rank's cells
  std::vector<std::vector<Eigen::Index>> send_local_;  // local cells each rank reads here
  std::vector<std::vector<double>> send_;
  vec<double> scratch_, residual_;  // full length (see the memory note above)
};

/// A - sigma I for a matrix A of one rank's rows in distributed_euler's numbering
/// (distributed_euler::jacobian, or any matrix of that pattern) as a distributed linear operator
/// (linalg/operator.hpp) on real (S = double, sigma = 0) or complex vectors: the ghost values of
/// x are exchanged for the product, inner products are summed over the ranks, so that gmres runs
/// the same iteration on every rank. `d` and `a` must outlive it.
template <int Dim, class S = double>
class distributed_matrix_operator {
 public:
  distributed_matrix_operator(distributed_euler<Dim>& d, const block_sparse_matrix<double, Dim + 2>& a, MPI_Comm comm,
                              S sigma = S(0))
      : d_(&d), a_(&a), comm_(comm), sigma_(sigma) {}
  Eigen::Index rows() const { return d_->local_size(); }
  Eigen::Index cols() const { return d_->local_size(); }
  void apply(const vec<S>& x, vec<S>& y) const {
    y = d_->multiply(*a_, x);
    if (sigma_ != S(0)) y -= sigma_ * x;
  }
  void global_sum(double* p, int n) const { internal::sum_over_ranks(comm_, p, n); }
  void global_sum(std::complex<double>* p, int n) const { internal::sum_over_ranks(comm_, p, n); }

 private:
  distributed_euler<Dim>* d_;
  const block_sparse_matrix<double, Dim + 2>* a_;
  MPI_Comm comm_;
  S sigma_;
};

/// The part of a rank's rows in its own cells (columns 0 .. block_rows - 1 of the local
/// numbering), square: the matrix of the block-Jacobi preconditioner, whose BILU(k) per rank
/// drops the couplings across ranks (the original's preconditioner "method 3", additive Schwarz
/// without overlap).
template <int B>
block_sparse_matrix<double, B> owned_part(const block_sparse_matrix<double, B>& a) {
  using storage_index = typename block_sparse_matrix<double, B>::storage_index;
  const Eigen::Index n = a.block_rows();
  std::vector<storage_index> ptr(n + 1, 0), col;
  for (Eigen::Index i = 0; i < n; ++i) {
    for (auto p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p)
      if (a.col_index()[p] < n) col.push_back(a.col_index()[p]);
    ptr[i + 1] = static_cast<storage_index>(col.size());
  }
  block_sparse_matrix<double, B> o;
  o.set_pattern_csr(n, n, ptr, col);
  o.set_zero(false);
  for (Eigen::Index i = 0; i < n; ++i)
    for (auto p = a.row_ptr()[i]; p < a.row_ptr()[i + 1]; ++p)
      if (a.col_index()[p] < n) o.block(i, a.col_index()[p]) = a.block_at(p);
  return o;
}

}  // namespace aerohopf::distributed
