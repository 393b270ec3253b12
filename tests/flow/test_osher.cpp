// Osher flux (P-ordering): consistency F(w, w) = physical ALE flux; exact upwinding for
// supersonic states; exact flux of a stationary contact; the exact two-rarefaction pressure
// at a receding wall (the Osher path IS the exact solution there); agreement with an
// independent Roe flux for small jumps to second order in the jump; dd_real and taylor<> scalars.
#include <gtest/gtest.h>

#include <aerohopf/flow/osher_flux.hpp>
#include <aerohopf/scalar.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <cmath>
#include <random>

using namespace aerohopf;
using namespace aerohopf::flow;

namespace {

template <int Dim>
primitive<double, Dim> random_state(std::mt19937& rng, double speed) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  primitive<double, Dim> q;
  q.rho = 1.0 + 0.5 * u(rng);
  for (int d = 0; d < Dim; ++d) q.u[d] = speed * u(rng);
  q.p = 0.7 + 0.3 * u(rng);
  return q;
}

template <int Dim>
vector_d<double, Dim> random_area(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  vector_d<double, Dim> s;
  for (int d = 0; d < Dim; ++d) s[d] = u(rng);
  return s;
}

// Independent Roe flux with the same ALE convention (Roe 1981; Toro ch. 11), no entropy fix.
template <int Dim>
state<double, Dim> roe_flux(const primitive<double, Dim>& l, const primitive<double, Dim>& r,
                            const vector_d<double, Dim>& s, double qf) {
  using Eigen::Matrix;
  constexpr int nv = Dim + 2;
  const double g = gamma_gas, a = std::sqrt(dot<double, Dim>(s, s));
  const auto fl = ale_flux<double, Dim>(l, s, qf), fr = ale_flux<double, Dim>(r, s, qf);
  const auto wl = to_conservative<double, Dim>(l), wr = to_conservative<double, Dim>(r);
  const double sl = std::sqrt(l.rho), sr = std::sqrt(r.rho);
  auto h = [&](const primitive<double, Dim>& q) {
    double k = 0.0;
    for (int d = 0; d < Dim; ++d) k += q.u[d] * q.u[d];
    return g / (g - 1) * q.p / q.rho + 0.5 * k;
  };
  vector_d<double, Dim> u, n;
  double k = 0.0;
  for (int d = 0; d < Dim; ++d) {
    u[d] = (sl * l.u[d] + sr * r.u[d]) / (sl + sr);
    n[d] = s[d] / a;
    k += u[d] * u[d];
  }
  const double hh = (sl * h(l) + sr * h(r)) / (sl + sr);
  // Roe-averaged flux Jacobian in direction n, relative normal speed; |A| by eigen decomposition.
  Matrix<double, nv, nv> A = Matrix<double, nv, nv>::Zero();
  const double un = dot<double, Dim>(u, n);
  A(0, 0) = 0.0;
  for (int d = 0; d < Dim; ++d) A(0, 1 + d) = n[d];
  for (int i = 0; i < Dim; ++i) {
    A(1 + i, 0) = 0.5 * (g - 1) * k * n[i] - u[i] * un;
    for (int j = 0; j < Dim; ++j) A(1 + i, 1 + j) = u[i] * n[j] - (g - 1) * n[i] * u[j] + (i == j ? un : 0.0);
    A(1 + i, Dim + 1) = (g - 1) * n[i];
  }
  A(Dim + 1, 0) = (0.5 * (g - 1) * k - hh) * un;
  for (int j = 0; j < Dim; ++j) A(Dim + 1, 1 + j) = hh * n[j] - (g - 1) * u[j] * un;
  A(Dim + 1, Dim + 1) = g * un;
  A -= (qf / a) * Matrix<double, nv, nv>::Identity();
  Eigen::EigenSolver<Matrix<double, nv, nv>> es(A);
  const Matrix<double, nv, nv> V = es.eigenvectors().real();
  const auto lam = es.eigenvalues().real().cwiseAbs();
  const Matrix<double, nv, nv> absA = V * lam.asDiagonal() * V.inverse();
  Matrix<double, nv, 1> dw;
  for (int v = 0; v < nv; ++v) dw[v] = wr[v] - wl[v];
  const Matrix<double, nv, 1> diss = a * absA * dw;
  state<double, Dim> f;
  for (int v = 0; v < nv; ++v) f[v] = 0.5 * (fl[v] + fr[v]) - 0.5 * diss[v];
  return f;
}

template <int Dim>
void consistency() {
  std::mt19937 rng(42 + Dim);
  for (int t = 0; t < 200; ++t) {
    const auto q = random_state<Dim>(rng, 2.0);
    const auto s = random_area<Dim>(rng);
    const double qf = 0.3 * std::uniform_real_distribution<double>(-1, 1)(rng);
    const auto f = osher_flux<double, Dim>(q, q, s, qf);
    const auto fe = ale_flux<double, Dim>(q, s, qf);
    for (int v = 0; v < Dim + 2; ++v) EXPECT_NEAR(f[v], fe[v], 1e-13 * (1.0 + std::abs(fe[v]))) << "trial " << t;
  }
}

}  // namespace

TEST(osher_flux, consistency_2d) { consistency<2>(); }
TEST(osher_flux, consistency_3d) { consistency<3>(); }

TEST(osher_flux, supersonic_states_are_fully_upwinded) {
  primitive<double, 2> l{1.0, {3.0, 0.2}, 0.7}, r{0.9, {2.8, -0.1}, 0.8};
  const vector_d<double, 2> s{0.8, 0.1};
  auto f = osher_flux<double, 2>(l, r, s, 0.0);
  auto fl = ale_flux<double, 2>(l, s, 0.0);
  for (int v = 0; v < 4; ++v) EXPECT_NEAR(f[v], fl[v], 1e-13 * (1 + std::abs(fl[v])));
  // both moving against the normal: the right state's flux
  for (auto* q : {&l, &r})
    for (auto& u : q->u) u = -u;
  f = osher_flux<double, 2>(l, r, s, 0.0);
  const auto fr = ale_flux<double, 2>(r, s, 0.0);
  for (int v = 0; v < 4; ++v) EXPECT_NEAR(f[v], fr[v], 1e-13 * (1 + std::abs(fr[v])));
  // a face moving with the flow turns a subsonic state supersonic relative to the face
  primitive<double, 2> a{1.0, {0.5, 0.0}, 1.0}, b{1.1, {0.45, 0.0}, 1.05};
  const double qf = -3.0;  // face moving upstream fast
  f = osher_flux<double, 2>(a, b, {1.0, 0.0}, qf);
  fl = ale_flux<double, 2>(a, {1.0, 0.0}, qf);
  for (int v = 0; v < 4; ++v) EXPECT_NEAR(f[v], fl[v], 1e-13 * (1 + std::abs(fl[v])));
}

TEST(osher_flux, stationary_contact_and_receding_wall_are_exact) {
  // Stationary contact (moving face, flow at the face speed): exact flux is p S and p u.S
  // work, zero relative mass flux.
  const vector_d<double, 2> s{0.6, 0.8};
  const double sn = 0.25;  // normal face speed
  primitive<double, 2> l{1.0, {0.6 * sn + 0.3 * 0.8, 0.8 * sn - 0.3 * 0.6}, 0.9};
  primitive<double, 2> r{0.3, {0.6 * sn - 0.5 * 0.8, 0.8 * sn + 0.5 * 0.6}, 0.9};
  auto f = osher_flux<double, 2>(l, r, s, sn);
  EXPECT_NEAR(f[0], 0.0, 1e-15);
  EXPECT_NEAR(f[1], 0.9 * 0.6, 1e-15);
  EXPECT_NEAR(f[2], 0.9 * 0.8, 1e-15);
  EXPECT_NEAR(f[3], 0.9 * sn, 1e-14);
  // Receding wall: left state moving away from the wall (u < 0), right state its mirror image.
  // Exact Riemann solution: two rarefactions, u* = 0, p* = p (1 - (gamma-1)/2 U/c)^(2gamma/(gamma-1)).
  const double U = 0.4, p = 1.2, rho = 1.3, c = std::sqrt(1.4 * p / rho);
  primitive<double, 2> a{rho, {-U, 0.7}, p}, b{rho, {U, 0.7}, p};
  osher_star<double> star{};
  f = osher_flux<double, 2>(a, b, {2.0, 0.0}, 0.0, &star);
  const double pstar = p * std::pow(1.0 - 0.2 * U / c, 7.0);
  EXPECT_NEAR(star.pressure, pstar, 1e-14);
  EXPECT_NEAR(star.velocity, 0.0, 1e-15);
  EXPECT_NEAR(f[0], 0.0, 1e-14);
  EXPECT_NEAR(f[1], 2.0 * pstar, 1e-14);
  EXPECT_NEAR(f[2], 0.0, 1e-14);
}

// For a jump of size delta both fluxes equal F_L + A^-(w) dw + O(delta^2): the difference must
// fall by 4 when delta halves, in 2D and 3D, sub- and supersonic, on moving faces.
TEST(osher_flux, agrees_with_roe_to_second_order_in_the_jump) {
  std::mt19937 rng(3);
  int checked = 0;
  for (int t = 0; t < 40; ++t) {
    const auto q = random_state<3>(rng, 1.0);
    const auto dq = random_state<3>(rng, 1.0);
    const auto s = random_area<3>(rng);
    const double qf = 0.2 * std::uniform_real_distribution<double>(-1, 1)(rng);
    // Away from sonic points (where Roe without an entropy fix differs at first order).
    const double a = std::sqrt(dot<double, 3>(s, s));
    const double un = dot<double, 3>(q.u, s) / a - qf / a, c = sound_speed(q);
    if (std::min({std::abs(un), std::abs(un - c), std::abs(un + c)}) < 0.1) continue;
    double err[2];
    for (int k = 0; k < 2; ++k) {
      const double delta = (k == 0 ? 1e-3 : 5e-4);
      primitive<double, 3> r = q;
      r.rho += delta * dq.rho;
      r.p += delta * (dq.p - 0.7);
      for (int d = 0; d < 3; ++d) r.u[d] += delta * dq.u[d];
      const auto fo = osher_flux<double, 3>(q, r, s, qf);
      const auto fr = roe_flux<3>(q, r, s, qf);
      err[k] = 0.0;
      for (int v = 0; v < 5; ++v) err[k] = std::max(err[k], std::abs(fo[v] - fr[v]));
    }
    EXPECT_LT(err[0], 1e-4) << "trial " << t;
    if (err[0] < 1e-12) continue;  // fully upwind: both give F_L or F_R exactly
    const double ratio = err[0] / err[1];
    EXPECT_GT(ratio, 3.5) << "trial " << t;
    EXPECT_LT(ratio, 4.5) << "trial " << t;
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

TEST(osher_flux, extended_precision_and_jets) {
  std::mt19937 rng(8);
  const auto l = random_state<2>(rng, 0.8), r = random_state<2>(rng, 0.8);
  const auto s = random_area<2>(rng);
  const auto fd = osher_flux<double, 2>(l, r, s, 0.1);
  // dd_real: same value to double rounding
  primitive<dd_real, 2> ld{dd_real(l.rho), {dd_real(l.u[0]), dd_real(l.u[1])}, dd_real(l.p)};
  primitive<dd_real, 2> rd{dd_real(r.rho), {dd_real(r.u[0]), dd_real(r.u[1])}, dd_real(r.p)};
  const auto fq = osher_flux<dd_real, 2>(ld, rd, {dd_real(s[0]), dd_real(s[1])}, dd_real(0.1));
  for (int v = 0; v < 4; ++v) EXPECT_NEAR(to_double(fq[v]), fd[v], 1e-13 * (1 + std::abs(fd[v])));
  // taylor<double,1>: derivative along a direction of the right state = central difference in dd
  using jet = taylor<double, 1>;
  const double dr = 0.3, du = -0.2, dp = 0.1;
  primitive<jet, 2> lj{jet(l.rho), {jet(l.u[0]), jet(l.u[1])}, jet(l.p)};
  primitive<jet, 2> rj{jet::variable(r.rho, dr), {jet::variable(r.u[0], du), jet(r.u[1])}, jet::variable(r.p, dp)};
  const auto fj = osher_flux<jet, 2>(lj, rj, {jet(s[0]), jet(s[1])}, jet(0.1));
  const dd_real h(1e-12);
  auto shifted = [&](dd_real e) {
    primitive<dd_real, 2> q = rd;
    q.rho += e * dr;
    q.u[0] += e * du;
    q.p += e * dp;
    return osher_flux<dd_real, 2>(ld, q, {dd_real(s[0]), dd_real(s[1])}, dd_real(0.1));
  };
  const auto fp = shifted(h), fm = shifted(-h);
  for (int v = 0; v < 4; ++v) {
    EXPECT_NEAR(fj[v][0], fd[v], 1e-15 * (1 + std::abs(fd[v])));
    EXPECT_NEAR(fj[v][1], to_double((fp[v] - fm[v]) / (2.0 * h)), 1e-9);
  }
}

// Contact smoothing (osher_flux.hpp): the exact flux has a jump in its derivative where the
// contact speed u* changes sign between different left/right intermediate states; with
// contact_width > 0 the first and second derivatives are continuous there, the flux is the
// exact one away from u* = 0 and stays consistent. u* is swept by the face speed q (|s| = 1:
// u* = u*(q = 0) - q by Galilean invariance), differentiated by taylor<> jets.
TEST(osher_flux, contact_smoothing_removes_the_kink_of_the_contact_switch) {
  const primitive<double, 2> l{1.2, {0.3, 0.4}, 0.8}, r{0.8, {0.3, -0.2}, 0.8};
  const vector_d<double, 2> s{1.0, 0.0};
  osher_star<double> st;
  (void)osher_flux<double, 2>(l, r, s, 0.0, &st);
  const double q0 = st.velocity;  // u* = 0 at this face speed
  osher_star<double> st0;
  (void)osher_flux<double, 2>(l, r, s, q0, &st0);
  ASSERT_NEAR(st0.velocity, 0.0, 1e-14);
  using jet = taylor<double, 2>;
  auto f = [&](double q, double delta) {
    const primitive<jet, 2> lj{jet(l.rho), {jet(l.u[0]), jet(l.u[1])}, jet(l.p)};
    const primitive<jet, 2> rj{jet(r.rho), {jet(r.u[0]), jet(r.u[1])}, jet(r.p)};
    return osher_flux<jet, 2>(lj, rj, {jet(1.0), jet(0.0)}, jet::variable(q), nullptr, delta);
  };
  auto jump = [&](double delta, int order) {
    const double e = 1e-8;
    const auto a = f(q0 - e, delta), b = f(q0 + e, delta);
    double j = 0.0;
    for (int v = 0; v < 4; ++v) j = std::max(j, std::abs(a[v][order] - b[v][order]));
    return j;
  };
  // exact switch: the mass flux derivative jumps by rho_2/3 - rho_1/3 (here ~0.4)
  EXPECT_GT(jump(0.0, 1), 0.1);
  EXPECT_LT(jump(0.05, 1), 1e-6);
  EXPECT_LT(jump(0.05, 2), 1e-4);
  // the smoothed second derivative is O(1 / (delta c)), finite and not zero
  const auto mid = f(q0, 0.05);
  EXPECT_GT(std::abs(mid[0][2]), 1.0);
  EXPECT_TRUE(std::isfinite(mid[0][2]));
  // far from u* = 0 (|u*| > 40 delta c) the smoothed flux is the exact one, bit for bit
  for (double dq : {-3.0, 3.0}) {
    const auto a = osher_flux<double, 2>(l, r, s, q0 + dq), b = osher_flux<double, 2>(l, r, s, q0 + dq, nullptr, 0.01);
    for (int v = 0; v < 4; ++v) EXPECT_EQ(a[v], b[v]);
  }
  // near it, the two differ, by at most the contact bracket F(w_2/3) - F(w_1/3)
  const auto a = osher_flux<double, 2>(l, r, s, q0 + 0.01), b = osher_flux<double, 2>(l, r, s, q0 + 0.01, nullptr, 0.05);
  EXPECT_GT(std::abs(a[0] - b[0]), 1e-4);
  EXPECT_LT(std::abs(a[0] - b[0]), 0.4 * 0.02);
  // consistency: F(w, w) = physical flux, also exactly at u* = 0
  for (double q : {l.u[0], l.u[0] + 0.02, l.u[0] - 0.3}) {
    const auto fc = osher_flux<double, 2>(l, l, s, q, nullptr, 0.05);
    const auto fe = ale_flux<double, 2>(l, s, q);
    for (int v = 0; v < 4; ++v) EXPECT_NEAR(fc[v], fe[v], 1e-14) << "q " << q;
  }
}
