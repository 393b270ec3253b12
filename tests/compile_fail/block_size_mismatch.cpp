// Must NOT compile (CTest compile_fail_block_size_mismatch expects require_block_size's message):
// an algorithm instantiated for blocks of 4 with a model whose block_size is 2 stops the build,
// instead of converting the model's matrices.
#include <aerohopf/nonlinear/block_system.hpp>

namespace {
struct two_by_two_model {
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int block_size = 2;
  Eigen::Index size() const { return 4; }
  aerohopf::vec<double> residual(const aerohopf::vec<double>& w, double) const { return w; }
  jacobian_type jacobian(const aerohopf::vec<double>&, double) const { return {}; }
  aerohopf::block_jacobian_pair<2> jacobians(const aerohopf::vec<double>&, double) const;
};
static_assert(aerohopf::block_system<two_by_two_model>);  // a block_system, of another block size

template <int B, class S>
int algorithm_for_blocks_of() {
  aerohopf::require_block_size<B, S>();
  return B;
}
}  // namespace

int instantiate() { return algorithm_for_blocks_of<4, two_by_two_model>(); }
