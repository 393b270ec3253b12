// The aeroelastic_system concept (nonlinear/aeroelastic_system.hpp): the aerofoil satisfies it
// and the tubular reactor does not; the aerofoil's structure_part against its known layout
// (w = [flow cells, (h, h', alpha, alpha')], the pose read by the rigid motion) for real states
// and complex eigenvectors; the layout check; structural_overlap against its definition
// (invariant under complex scaling, blind to the flow part, 0 for orthogonal structural parts).
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/nonlinear/aeroelastic_system.hpp>

#include <complex>
#include <random>
#include <string>
#include <type_traits>

#include "support/error_messages.hpp"

using namespace aerohopf;
using aerohopf::test::contains;
using aerohopf::test::input_error_of;
using models::aerofoil_system;
using cplx = std::complex<double>;

namespace {

// dw/dt = -w with a layout of 3 flow and 2 structural entries; `claimed_flow` lets a test give a
// layout that does not add up to size().
struct small_aeroelastic {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index claimed_flow = 3;
  Eigen::Index size() const { return 5; }
  vec<double> residual(const vec<double>& w, double) const { return -w; }
  jacobian_type jacobian(const vec<double>&, double) const { return -Eigen::MatrixXd::Identity(5, 5); }
  Eigen::Index flow_size() const { return claimed_flow; }
  Eigen::Index structure_size() const { return 2; }
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    return v.tail(2);
  }
};

// A structural part without its size: no aeroelastic_system.
struct no_structure_size {
  using jacobian_type = Eigen::MatrixXd;
  Eigen::Index size() const { return 5; }
  vec<double> residual(const vec<double>& w, double) const { return -w; }
  jacobian_type jacobian(const vec<double>&, double) const { return -Eigen::MatrixXd::Identity(5, 5); }
  Eigen::Index flow_size() const { return 3; }
  template <class T>
  vec<T> structure_part(const vec<T>& v) const {
    return v.tail(2);
  }
};

}  // namespace

static_assert(aeroelastic_system<aerofoil_system>);
static_assert(dynamical_system<tubular_reactor> && !aeroelastic_system<tubular_reactor>);
static_assert(aeroelastic_system<small_aeroelastic>);
static_assert(dynamical_system<no_structure_size> && !aeroelastic_system<no_structure_size>);

namespace {

aerofoil_system very_coarse_aerofoil() {
  return aerofoil_system(flow::euler_model<2>(flow::coarsen(flow::naca_cgrid(), 8), {.mach = 0.7, .alpha_rad = 0.0}),
                         structure::pitch_plunge{});
}

template <class T>
vec<T> random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  vec<T> v(n);
  for (auto& x : v) {
    if constexpr (std::is_same_v<T, cplx>) x = cplx(n01(rng), n01(rng));
    else x = n01(rng);
  }
  return v;
}

}  // namespace

TEST(aeroelastic_system, aerofoil_structure_part_is_the_pitch_plunge_state) {
  const auto s = very_coarse_aerofoil();
  check_aeroelastic_layout(s, "aerofoil");  // no throw
  EXPECT_EQ(s.flow_size(), Eigen::Index(s.flow().n_cells()) * 4);
  EXPECT_EQ(s.structure_size(), 4);
  EXPECT_EQ(s.flow_size() + s.structure_size(), s.size());
  vec<double> w = s.free_stream_state();
  w.tail(4) << 0.01, -0.02, 0.03, 0.05;  // h, h', alpha, alpha'
  const vec<double> ws = s.structure_part(w);
  ASSERT_EQ(ws.size(), 4);
  const auto pose = s.pose<double>(w);  // what the rigid grid motion reads
  EXPECT_EQ(ws[0], pose.h);
  EXPECT_EQ(ws[1], pose.h_dot);
  EXPECT_EQ(ws[2], pose.alpha);
  EXPECT_EQ(ws[3], pose.alpha_dot);
  EXPECT_EQ(ws, w.tail(4));
  // a complex eigenvector: the same entries
  const vec<cplx> z = random_vector<cplx>(s.size(), 3);
  const vec<cplx> zs = s.structure_part(z);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(zs[k], z[s.flow_size() + k]) << k;
  // a vector of another size (e.g. of another grid level) is refused
  EXPECT_TRUE(contains(input_error_of([&] { (void)s.structure_part(vec<cplx>(z.head(z.size() - 4))); }),
                       "aerofoil_system::structure_part"));
}

TEST(aeroelastic_system, layout_that_does_not_add_up_is_refused) {
  small_aeroelastic ok;
  check_aeroelastic_layout(ok, "small");
  small_aeroelastic bad;
  bad.claimed_flow = 4;
  const std::string msg = input_error_of([&] { check_aeroelastic_layout(bad, "small system"); });
  EXPECT_TRUE(contains(msg, "small system: aeroelastic layout of 4 flow and 2 structural entries")) << msg;
  EXPECT_TRUE(contains(msg, "5 unknowns")) << msg;
}

// The mode test: |s_a^H s_b| / (||s_a|| ||s_b||) of the structural parts, computed here from the
// aerofoil's known layout.
TEST(aeroelastic_system, structural_overlap_compares_the_structural_parts_only) {
  const auto s = very_coarse_aerofoil();
  const Eigen::Index nf = s.flow_size();
  const vec<cplx> a = random_vector<cplx>(s.size(), 5), b = random_vector<cplx>(s.size(), 6);
  const vec<cplx> sa = a.tail(4), sb = b.tail(4);
  const double ref = std::abs(sa.dot(sb)) / (sa.norm() * sb.norm());
  EXPECT_NEAR(structural_overlap(s, a, b), ref, 1e-15);
  EXPECT_NEAR(structural_overlap(s, b, a), ref, 1e-15);
  // the same mode up to a complex factor, with any other flow part
  vec<cplx> c = cplx(-0.3, 2.0) * a;
  c.head(nf) = random_vector<cplx>(nf, 7);
  EXPECT_NEAR(structural_overlap(s, a, c), 1.0, 1e-14);
  // orthogonal structural parts, identical flow parts
  vec<cplx> d = a;
  d.tail(4) = sa - (sb.dot(sa) / sb.squaredNorm()) * sb;  // minus its sb component (sb^H sa): d_s orthogonal to sb
  vec<cplx> e = a;
  e.tail(4) = sb;
  EXPECT_LT(structural_overlap(s, d, e), 1e-14);
  // no structural part: 0, not NaN
  vec<cplx> f = a;
  f.tail(4).setZero();
  EXPECT_EQ(structural_overlap(s, a, f), 0.0);
  // real states too
  const vec<double> x = random_vector<double>(s.size(), 8);
  EXPECT_NEAR(structural_overlap(s, x, vec<double>(-3.0 * x)), 1.0, 1e-14);
}
