#pragma once
// The Euler residual on a grid partitioned over MPI ranks (optional component: needs <mpi.h>,
// CMake target aerohopf::mpi). Each rank owns whole blocks (partition.hpp) and holds its cells'
// state as a local vector; a residual evaluation sends the cells other ranks' halos read
// (halo_plan: nonblocking point-to-point, one message per neighbouring rank), evaluates the
// owned blocks (euler_model::residual_of_blocks) and returns the owned rows. Each value equals
// the serial residual's bitwise: the same operations in the same order per cell.
//
// Memory: the grid and its metrics are replicated on every rank, and each rank keeps two
// full-length scratch vectors (the state: owned and received cells current, the rest the free
// stream, never read; and the residual): 2 * 8 * 5 bytes per cell in 3D, 114 MB for 1.43
// million cells. Local numbering of the halo cells (scratch of the owned and ghost cells only)
// is the step that removes them.
//
// Errors are collective: a rank whose evaluation throws (a bad local size, a non-physical cell)
// makes every rank throw, the failing rank its own error and the others an input_error naming
// that rank, so no rank waits in a later collective call for one that left.

#include <mpi.h>

#include <aerohopf/distributed/partition.hpp>
#include <aerohopf/error.hpp>
#include <aerohopf/flow/euler_model.hpp>

#include <cstddef>
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

/// Runs f on every rank; if it throws on any rank, every rank throws (collective).
template <class F>
void collective(MPI_Comm comm, const char* what, F&& f) {
  std::exception_ptr error;
  try {
    f();
  } catch (...) {
    error = std::current_exception();
  }
  int rank = 0;
  check_mpi(MPI_Comm_rank(comm, &rank), "MPI_Comm_rank");
  const int mine = error ? rank : -1;
  int first = -1;
  check_mpi(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MAX, comm), "MPI_Allreduce");
  if (error) std::rethrow_exception(error);
  if (first >= 0) throw input_error(aerohopf::internal::concat(what, ": refused on rank ", first, " (its message there)"));
}

}  // namespace internal

template <int Dim>
class distributed_euler {
 public:
  static constexpr int nv = flow::euler_model<Dim>::nv;

  /// `model` (the same grid and free stream on every rank) must outlive this object; `part`
  /// assigns its blocks to the ranks of `comm` (part.ranks must equal the communicator's size).
  /// Collective.
  distributed_euler(const flow::euler_model<Dim>& model, const block_partition& part, MPI_Comm comm)
      : model_(model), comm_(comm), part_(part) {
    internal::check_mpi(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    int size = 0;
    internal::check_mpi(MPI_Comm_size(comm_, &size), "MPI_Comm_size");
    internal::collective(comm_, "distributed_euler", [&] {
      require(part.ranks == size, "distributed_euler: the partition has ", part.ranks, " ranks, the communicator ",
              size);
      plan_ = make_halo_plan(model_, part, rank_);
    });
    scratch_ = model_.template free_stream_vector<double>();
    residual_.setZero(model_.size());
    send_.resize(plan_.ranks);
    recv_.resize(plan_.ranks);
    for (int q = 0; q < plan_.ranks; ++q) {
      send_[q].resize(plan_.send[q].size() * nv);
      recv_[q].resize(plan_.recv[q].size() * nv);
    }
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

  /// Sends the cells other ranks read and receives those this rank reads into the full-length
  /// scratch, with this rank's own cells from `local` (collective).
  void exchange(const vec<double>& local) {
    internal::collective(comm_, "distributed_euler::exchange",
                         [&] { require_size(local.size(), local_size(), "distributed_euler::exchange", "local state"); });
    Eigen::Index k = 0;
    for (const auto& [a, b] : plan_.owned) {
      const auto n = static_cast<Eigen::Index>((b - a) * nv);
      scratch_.segment(static_cast<Eigen::Index>(a * nv), n) = local.segment(k, n);
      k += n;
    }
    std::vector<MPI_Request> req;
    req.reserve(2 * plan_.ranks);
    constexpr int tag = 7301;
    for (int q = 0; q < plan_.ranks; ++q) {
      if (plan_.recv[q].empty()) continue;
      req.emplace_back();
      internal::check_mpi(MPI_Irecv(recv_[q].data(), static_cast<int>(recv_[q].size()), MPI_DOUBLE, q, tag, comm_,
                                    &req.back()),
                          "MPI_Irecv");
    }
    for (int q = 0; q < plan_.ranks; ++q) {
      if (plan_.send[q].empty()) continue;
      std::size_t i = 0;
      for (const std::size_t c : plan_.send[q])
        for (int v = 0; v < nv; ++v) send_[q][i++] = scratch_[static_cast<Eigen::Index>(c * nv + v)];
      req.emplace_back();
      internal::check_mpi(MPI_Isend(send_[q].data(), static_cast<int>(send_[q].size()), MPI_DOUBLE, q, tag, comm_,
                                    &req.back()),
                          "MPI_Isend");
    }
    internal::check_mpi(MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    for (int q = 0; q < plan_.ranks; ++q) {
      std::size_t i = 0;
      for (const std::size_t c : plan_.recv[q])
        for (int v = 0; v < nv; ++v) scratch_[static_cast<Eigen::Index>(c * nv + v)] = recv_[q][i++];
    }
  }

  /// R in this rank's cells at the distributed state whose local part is `local` (collective).
  vec<double> residual(const vec<double>& local) {
    exchange(local);
    vec<double> r(local_size());
    internal::collective(comm_, "distributed_euler::residual", [&] {
      model_.template residual_of_blocks<double>(model_.metrics(), scratch_.data(), residual_.data(),
                                                 plan_.owned_blocks);
      Eigen::Index k = 0;
      for (const auto& [a, b] : plan_.owned) {
        const auto n = static_cast<Eigen::Index>((b - a) * nv);
        r.segment(k, n) = residual_.segment(static_cast<Eigen::Index>(a * nv), n);
        k += n;
      }
    });
    return r;
  }

 private:
  const flow::euler_model<Dim>& model_;
  MPI_Comm comm_;
  int rank_ = 0;
  block_partition part_;
  halo_plan plan_;
  vec<double> scratch_, residual_;  // full length (see the memory note above)
  std::vector<std::vector<double>> send_, recv_;
};

}  // namespace aerohopf::distributed
