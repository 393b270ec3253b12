// The block_system concept (nonlinear/block_system.hpp): which models satisfy it (the aerofoil
// does, the tubular reactor and models with a run-time, non-positive or mismatched block size
// do not), the compile-time block-size check (block_system_of as a constraint, require_block_size
// in a constant expression), the aerofoil's jacobians() pair against its single block
// assemblies and its Eigen sparse Jacobians bit for bit, and the size checks of
// checked_jacobians / checked_exact_jacobian. (That a mismatch in require_block_size stops the
// build is the CTest compile_fail_block_size_mismatch, tests/compile_fail/.)
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear/block_system.hpp>

#include <cmath>
#include <random>
#include <utility>

#include "support/bordered_test_system.hpp"
#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;
using models::aerofoil_system;

namespace {

// dw/dt = mu A w with a tridiagonal A of n = 5 unknowns in blocks of 2 (padded to 6); the
// preconditioning matrix is A's diagonal. wrong_size: the pair is of a system 2 unknowns smaller.
struct small_block_system {
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int block_size = 2;
  bool wrong_size = false;

  static Eigen::SparseMatrix<double> a(Eigen::Index n, bool diagonal_only) {
    Eigen::SparseMatrix<double> m(n, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      m.insert(i, i) = -2.0 - 0.1 * double(i);
      if (diagonal_only) continue;
      if (i > 0) m.insert(i, i - 1) = 1.0;
      if (i + 1 < n) m.insert(i, i + 1) = 0.5;
    }
    m.makeCompressed();
    return m;
  }
  Eigen::Index size() const { return 5; }
  vec<double> residual(const vec<double>& w, double mu) const { return mu * (a(5, false) * w); }
  jacobian_type jacobian(const vec<double>&, double mu) const { return mu * a(5, false); }
  block_jacobian_pair<2> jacobians(const vec<double>&, double mu) const {
    const Eigen::Index n = wrong_size ? 3 : 5;
    const Eigen::SparseMatrix<double> e = mu * a(n, false), p = mu * a(5, true);
    return {block_sparse_matrix<double, 2>::from_sparse(e), block_sparse_matrix<double, 2>::from_sparse(p)};
  }
};

// The same dynamical system with block declarations the concept must refuse.
struct runtime_block_size : small_block_system {
  static inline int block_size = 2;  // not a constant expression
};
struct zero_block_size {
  using jacobian_type = Eigen::SparseMatrix<double>;
  static constexpr int block_size = 0;
  Eigen::Index size() const { return 5; }
  vec<double> residual(const vec<double>& w, double) const { return w; }
  jacobian_type jacobian(const vec<double>&, double) const { return {}; }
};
struct mismatched_block_size : small_block_system {
  static constexpr int block_size = 4;  // jacobians() still returns blocks of 2
};
struct std_pair_jacobians : small_block_system {
  std::pair<block_sparse_matrix<double, 2>, block_sparse_matrix<double, 2>> jacobians(const vec<double>&, double) const;
};

// An algorithm written for blocks of B, constrained by the concept.
template <int B, class S>
  requires block_system_of<S, B>
constexpr int krylov_block_size(const S&) {
  return B;
}
template <class S, int B>
concept krylov_accepts = requires(const S& s) { krylov_block_size<B>(s); };

}  // namespace

static_assert(block_system<aerofoil_system>);
static_assert(block_size_of<aerofoil_system> == 4);
static_assert(block_system_of<aerofoil_system, 4>);
static_assert(!block_system_of<aerofoil_system, 5>);
static_assert(dynamical_system<tubular_reactor> && !block_system<tubular_reactor>);
static_assert(block_system<small_block_system> && block_system_of<small_block_system, 2>);
static_assert(dynamical_system<runtime_block_size> && !block_system<runtime_block_size>);
static_assert(dynamical_system<zero_block_size> && !block_system<zero_block_size>);
static_assert(dynamical_system<mismatched_block_size> && !block_system<mismatched_block_size>);
static_assert(dynamical_system<std_pair_jacobians> && !block_system<std_pair_jacobians>);
// A block-size mismatch is no viable call (a compile-time error at the call), never a conversion.
static_assert(krylov_accepts<aerofoil_system, 4>);
static_assert(!krylov_accepts<aerofoil_system, 5>);
static_assert(!krylov_accepts<aerofoil_system, 2>);
static_assert(!krylov_accepts<tubular_reactor, 4>);
static_assert(krylov_accepts<small_block_system, 2>);
// require_block_size is a constant expression for a matching model (with any other B or a
// model that is no block_system it stops the build with its static_assert message).
static_assert((require_block_size<4, aerofoil_system>(), true));
static_assert((require_block_size<2, small_block_system>(), true));

namespace {

aerofoil_system very_coarse_aerofoil(double mach) {
  return aerofoil_system(flow::euler_model<2>(flow::coarsen(flow::naca_cgrid(), 8), {.mach = mach, .alpha_rad = 0.0}),
                         structure::pitch_plunge{});
}

// Perturbed flow and a displaced, moving section (every coupling block non-zero).
vec<double> perturbed_state(const aerofoil_system& s) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  vec<double> w = s.free_stream_state();
  for (Eigen::Index k = 0; k < s.flow_size(); ++k) w[k] *= 1.0 + u(rng);
  w.tail(4) << 0.01, -0.02, 0.03, 0.05;
  return w;
}

void expect_identical(const block_sparse_matrix<double, 4>& a, const block_sparse_matrix<double, 4>& b,
                      const char* what) {
  EXPECT_EQ(a.block_rows(), b.block_rows()) << what;
  EXPECT_EQ(a.logical_rows(), b.logical_rows()) << what;
  EXPECT_EQ(a.logical_cols(), b.logical_cols()) << what;
  EXPECT_EQ(a.row_ptr(), b.row_ptr()) << what;
  EXPECT_EQ(a.col_index(), b.col_index()) << what;
  EXPECT_EQ(a.values(), b.values()) << what;
}

double max_abs_difference(const Eigen::SparseMatrix<double>& a, const Eigen::SparseMatrix<double>& b) {
  const Eigen::SparseMatrix<double> d = a - b;
  double m = 0;
  for (int k = 0; k < d.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(d, k); it; ++it) m = std::max(m, std::abs(it.value()));
  return m;
}

}  // namespace

// jacobians() computes the coupling blocks once for both matrices; the single assemblies compute
// them each time. The results are the same bits, and the same as the Eigen sparse Jacobians.
TEST(block_system, aerofoil_pair_equals_the_single_block_assemblies_bit_for_bit) {
  const auto s = very_coarse_aerofoil(0.8);
  const vec<double> w = perturbed_state(s);
  const double mu = 2.5;
  const block_jacobian_pair<4> p = checked_jacobians(s, w, mu, "test");
  EXPECT_EQ(p.exact.logical_rows(), s.size());
  EXPECT_EQ(p.exact.rows(), s.size());  // 4 per cell + 4 structural unknowns: no padding
  expect_identical(p.exact, s.block_jacobian(w, mu), "exact");
  expect_identical(p.preconditioning, s.approximate_block_jacobian(w, mu), "preconditioning");
  expect_identical(checked_exact_jacobian(s, w, mu, "test"), p.exact, "checked_exact_jacobian");
  const auto [e, a] = s.block_jacobians(w, mu);  // the old pair interface
  expect_identical(e, p.exact, "block_jacobians().first");
  expect_identical(a, p.preconditioning, "block_jacobians().second");
  EXPECT_EQ(max_abs_difference(p.exact.to_sparse(), s.jacobian(w, mu)), 0.0);
  EXPECT_EQ(max_abs_difference(p.preconditioning.to_sparse(), s.approximate_jacobian(w, mu)), 0.0);
  // the two really are different matrices (modified-order flow block)
  EXPECT_GT(max_abs_difference(p.exact.to_sparse(), p.preconditioning.to_sparse()), 1e-3);
}

TEST(block_system, aerofoil_jacobians_refuse_a_bad_state_naming_themselves) {
  const auto s = very_coarse_aerofoil(0.6);
  vec<double> w = perturbed_state(s);
  EXPECT_TRUE(contains(input_error_of([&] { (void)s.jacobians(w.head(w.size() - 1), 1.0); }),
                       "aerofoil_system::jacobians"));
  w[7] = std::nan("");
  EXPECT_TRUE(contains(input_error_of([&] { (void)s.jacobians(w, 1.0); }), "aerofoil_system::jacobians"));
}

// Independent of any model's assembly: the pair of the small system against its own Eigen
// matrices, and a pair of the wrong size refused with both sizes in the message.
TEST(block_system, checked_jacobians_compares_the_pair_with_the_system_size) {
  small_block_system ok;
  const vec<double> w = vec<double>::Ones(5);
  const auto p = checked_jacobians(ok, w, 2.0, "small");
  EXPECT_EQ(p.exact.rows(), 6);
  EXPECT_EQ(p.exact.logical_rows(), 5);
  EXPECT_EQ(max_abs_difference(Eigen::SparseMatrix<double>(p.exact.to_sparse()), ok.jacobian(w, 2.0)), 0.0);
  const vec<double> x = vec<double>::LinSpaced(6, 1.0, 2.0);
  vec<double> y(6);
  p.preconditioning.apply(x, y);
  for (Eigen::Index i = 0; i < 5; ++i) EXPECT_EQ(y[i], 2.0 * (-2.0 - 0.1 * double(i)) * x[i]);
  // no block_jacobian member: the exact matrix of the pair
  static_assert(!has_exact_block_jacobian<small_block_system> && has_exact_block_jacobian<aerofoil_system>);
  EXPECT_EQ(checked_exact_jacobian(ok, w, 2.0, "small").values(), p.exact.values());
  small_block_system bad;
  bad.wrong_size = true;
  for (const bool exact_only : {false, true}) {
    const std::string msg = input_error_of([&] {
      if (exact_only) (void)checked_exact_jacobian(bad, w, 2.0, "small system");
      else (void)checked_jacobians(bad, w, 2.0, "small system");
    });
    EXPECT_TRUE(contains(msg, "small system: exact block Jacobian is 3x3 (padded 4x4)")) << msg;
    EXPECT_TRUE(contains(msg, "system has 5 unknowns (padded 6)")) << msg;
  }
}

// ---- the bordered form (bordered_system, krylov_jacobians): every interface of a system gives
// the Krylov path the same bordered matrices ----
namespace {
using test_support::modal_block_system;
using test_support::sparse_view;
static_assert(bordered_system<modal_block_system> && !block_system<modal_block_system>);
static_assert(block_system_of<modal_block_system, 5> && !block_system_of<modal_block_system, 4>);
static_assert((require_block_size<5, modal_block_system>(), true));
static_assert(bordered_system<aerofoil_system> && block_system<aerofoil_system>);
static_assert(has_exact_bordered_jacobian<aerofoil_system> && !has_exact_bordered_jacobian<modal_block_system>);
static_assert(!bordered_system<sparse_view<modal_block_system>> && aeroelastic_system<sparse_view<modal_block_system>>);

void expect_same(const bordered_block_matrix<double, 4>& a, const bordered_block_matrix<double, 4>& b, const char* what) {
  EXPECT_EQ(a.structure_size(), b.structure_size()) << what;
  EXPECT_EQ(a.flow().row_ptr(), b.flow().row_ptr()) << what;
  EXPECT_EQ(a.flow().col_index(), b.flow().col_index()) << what;
  EXPECT_EQ(a.flow().values(), b.flow().values()) << what;
  EXPECT_EQ(a.flow_structure(), b.flow_structure()) << what;
  EXPECT_EQ(a.structure_flow(), b.structure_flow()) << what;
  EXPECT_EQ(a.structure(), b.structure()) << what;
}
}  // namespace

// The aerofoil's own bordered form (flow blocks + 4-wide structural border) is its padded pair
// split at the structure, bit for bit; krylov_jacobians takes the bordered one, and the same
// model seen only through its Eigen sparse Jacobians gives the same matrices.
TEST(block_system, aerofoil_bordered_form_is_its_padded_pair_split_at_the_structure) {
  const auto s = very_coarse_aerofoil(0.8);
  const vec<double> w = perturbed_state(s);
  const double mu = 2.5;
  const auto b = s.bordered_jacobians(w, mu);
  const auto p = s.jacobians(w, mu);
  EXPECT_EQ(b.exact.structure_size(), 4);
  EXPECT_EQ(b.exact.flow_size(), s.flow_size());
  expect_same(b.exact, bordered_from_padded(p.exact, 4), "exact");
  expect_same(b.preconditioning, bordered_from_padded(p.preconditioning, 4), "preconditioning");
  expect_same(s.bordered_jacobian(w, mu), b.exact, "bordered_jacobian");
  expect_same(krylov_exact_jacobian<4>(s, w, mu, "test"), b.exact, "krylov_exact_jacobian");
  const auto k = krylov_jacobians<4>(s, w, mu, "test");
  expect_same(k.exact, b.exact, "krylov_jacobians");
  EXPECT_EQ(krylov_border_size<4>(s), 4);
  struct sparse_only {  // not aeroelastic: the last block (1..B unknowns) is the border
    const aerofoil_system& a;
    using jacobian_type = Eigen::SparseMatrix<double>;
    Eigen::Index size() const { return a.size(); }
    vec<double> residual(const vec<double>& v, double m) const { return a.residual<double>(v, m); }
    jacobian_type jacobian(const vec<double>& v, double m) const { return a.jacobian(v, m); }
    jacobian_type approximate_jacobian(const vec<double>& v, double m) const { return a.approximate_jacobian(v, m); }
  };
  const sparse_only so{s};
  EXPECT_EQ(krylov_border_size<4>(so), 4);
  const auto ks = krylov_jacobians<4>(so, w, mu, "test");
  expect_same(ks.exact, b.exact, "sparse route, exact");
  expect_same(ks.preconditioning, b.preconditioning, "sparse route, preconditioning");
}

// A structure of 6 unknowns with flow blocks of 5: the model's bordered pair passes through
// (checked), its sparse view is split at its aeroelastic layout to the same matrices; a padded
// block_system and a plain sparse system are split at their last block.
TEST(block_system, krylov_jacobians_view_every_form_as_bordered) {
  const modal_block_system m(7);
  vec<double> w = vec<double>::Constant(m.size(), 1.1);
  w.tail(6) << 0.1, -0.2, 0.3, 0.05, 0.0, -0.1;
  const auto p = krylov_jacobians<5>(m, w, 0.4, "modal");
  EXPECT_EQ(p.exact.structure_size(), 6);
  EXPECT_EQ(p.exact.flow_size(), 35);
  EXPECT_EQ((Eigen::MatrixXd(p.exact.to_sparse()) - Eigen::MatrixXd(m.jacobian(w, 0.4))).norm(), 0.0);
  const sparse_view<modal_block_system> v{m};
  EXPECT_EQ(krylov_border_size<5>(v), 6);
  const auto pv = krylov_jacobians<5>(v, w, 0.4, "view");
  EXPECT_EQ((pv.exact.to_dense() - p.exact.to_dense()).norm(), 0.0);
  EXPECT_EQ((pv.preconditioning.to_dense() - p.preconditioning.to_dense()).norm(), 0.0);
  EXPECT_EQ(krylov_exact_jacobian<5>(v, w, 0.4, "view").structure_size(), 6);
  // padded block_system: n = 5 in blocks of 2, the last unknown is the border
  const small_block_system sb;
  EXPECT_EQ(krylov_border_size<2>(sb), 1);
  const vec<double> ws = vec<double>::Ones(5);
  const auto ps = krylov_jacobians<2>(sb, ws, 2.0, "small");
  EXPECT_EQ(ps.exact.structure_size(), 1);
  EXPECT_EQ((Eigen::MatrixXd(ps.exact.to_sparse()) - Eigen::MatrixXd(sb.jacobian(ws, 2.0))).norm(), 0.0);
  EXPECT_EQ(krylov_exact_jacobian<2>(sb, ws, 2.0, "small").to_dense(), ps.exact.to_dense());
  // a plain sparse system whose size is a multiple of B: the last whole block
  const tubular_reactor reactor(10);
  EXPECT_EQ(krylov_border_size<2>(reactor), reactor.size() % 2 == 0 ? 2 : 1);
}

// A bordered pair of the wrong size is refused with both sizes.
TEST(block_system, krylov_jacobians_refuse_a_bordered_pair_of_another_size) {
  struct short_pair : modal_block_system {
    using modal_block_system::modal_block_system;
    Eigen::Index size() const { return modal_block_system::size() + 1; }
  };
  const short_pair s(4);
  const std::string msg =
      input_error_of([&] { (void)krylov_jacobians<5>(s, vec<double>::Ones(s.size() - 1), 0.5, "short model"); });
  EXPECT_TRUE(contains(msg, "short model: exact bordered Jacobian is 26x26 (20 flow + 6 structural unknowns), system has 27"))
      << msg;
}
