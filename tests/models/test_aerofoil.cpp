// Coupled Euler / pitch-plunge aerofoil system (spec 05) on the very coarse NACA 0012 C-grid:
// the assembled exact Jacobian against taylor<> directional derivatives of the templated
// coupled residual (through the moving grid), the modified-order variant differs only in the
// flow block, the analytic d_mu / A_mu against jets and differences in Ubar, the loads against
// the flow solver's own force integration, and the symmetric equilibrium (steady flow at
// alpha = 0, zero structural state) with zero residual for every Ubar; the contact smoothing
// that makes the residual three times differentiable there (dd differences vs taylor<>); the
// Mach number and incidence set in place give the bits of a system built with them.
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/nonlinear/system.hpp>
#include <aerohopf/reduction/derivative_products.hpp>
#include <aerohopf/scalar.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <type_traits>

using namespace aerohopf;
using namespace aerohopf::flow;
using models::aerofoil_system;

static_assert(dynamical_system<aerofoil_system>);
static_assert(has_approximate_jacobian<aerofoil_system>);
static_assert(has_d_mu<aerofoil_system>);
static_assert(has_jacobian_d_mu<aerofoil_system>);
static_assert(block_system_of<aerofoil_system, 4>);
static_assert(aeroelastic_system<aerofoil_system>);

namespace {

aerofoil_system make_system(double mach, double mu_s = 10.0) {
  structure::pitch_plunge_parameters p;
  p.mu_s = mu_s;
  return aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = mach, .alpha_rad = 0.0}),
                         structure::pitch_plunge(p));
}

// Perturbed non-uniform flow and a displaced, moving section.
vec<double> perturbed_state(const aerofoil_system& s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  vec<double> w = s.free_stream_state();
  for (Eigen::Index k = 0; k < s.flow_size(); ++k) w[k] *= 1.0 + u(rng);
  w.tail(4) << 0.01, -0.02, 0.03, 0.05;
  return w;
}

vec<double> random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  vec<double> v(n);
  for (auto& x : v) x = n01(rng);
  return v;
}

}  // namespace

TEST(aerofoil_system, jacobian_products_match_taylor_directional_derivatives) {
  const auto s = make_system(0.6);
  const auto w = perturbed_state(s, 3);
  const double mu = 2.5;
  const auto a = s.jacobian(w, mu);
  ASSERT_EQ(a.rows(), s.size());
  const Eigen::Index nf = s.flow_size();
  for (int which = 0; which < 3; ++which) {
    vec<double> v = random_vector(s.size(), 10 + which);
    if (which == 1) v.head(nf).setZero();  // structural directions only: A_fs, A_ss
    if (which == 2) v.tail(4).setZero();   // flow directions only: A_ff, A_sf
    const vec<double> ref = jacobian_product(s, w, mu, v);
    const vec<double> av = a * v;
    ASSERT_GT(ref.norm(), 1e-3);
    std::cout << "case " << which << ": relative error " << (av - ref).norm() / ref.norm() << ", structural rows "
              << (av.tail(4) - ref.tail(4)).norm() / ref.tail(4).norm() << "\n";
    EXPECT_LT((av - ref).norm(), 1e-8 * ref.norm()) << "case " << which;
    // the structural rows alone (a few entries, easily swamped in the norm above)
    EXPECT_LT((av.tail(4) - ref.tail(4)).norm(), 1e-8 * std::max(ref.tail(4).norm(), 1e-12)) << "case " << which;
    ASSERT_GT(ref.tail(4).norm(), 1e-6);
  }
}

// jacobian_product_pair (one jet<double, 2> pass) against two taylor passes and the assembled
// exact Jacobian: the same two products to rounding, with flow and structural directions.
TEST(aerofoil_system, jacobian_product_pair_equals_two_single_products) {
  const auto s = make_system(0.6);
  const auto w = perturbed_state(s, 4);
  const double mu = 2.5;
  const vec<double> u = random_vector(s.size(), 21), v = random_vector(s.size(), 22);
  const auto [au, av] = jacobian_product_pair(s, w, mu, u, v);
  const vec<double> ru = jacobian_product(s, w, mu, u), rv = jacobian_product(s, w, mu, v);
  EXPECT_LT((au - ru).norm(), 1e-13 * ru.norm());
  EXPECT_LT((av - rv).norm(), 1e-13 * rv.norm());
  EXPECT_LT((au.tail(4) - ru.tail(4)).norm(), 1e-13 * ru.tail(4).norm());
  const auto a = s.jacobian(w, mu);
  EXPECT_LT((vec<double>(a * v) - av).norm(), 1e-8 * av.norm());
  EXPECT_THROW(jacobian_product_pair(s, w, mu, u, vec<double>(v.head(3))), input_error);
}

// Independent of the jets: the structural columns [A_fs; A_ss] (grid motion, grid speeds and
// moved loads) against central differences of the double residual.
TEST(aerofoil_system, structural_columns_match_central_differences) {
  const auto s = make_system(0.6);
  const auto w = perturbed_state(s, 7);
  const double mu = 2.5;
  const auto a = s.jacobian(w, mu);
  for (int j = 0; j < 4; ++j) {
    // the flow is invariant under the pure translation h: differences there are rounding only
    // (amplified by 1/V of the small wall cells), so a larger step
    const double h = j == 0 ? 1e-3 : 1e-6;
    vec<double> wp = w, wm = w;
    wp[s.flow_size() + j] += h;
    wm[s.flow_size() + j] -= h;
    const vec<double> fd = (s.residual<double>(wp, mu) - s.residual<double>(wm, mu)) / (2 * h);
    const vec<double> col = a.col(s.flow_size() + j);
    std::cout << "structural unknown " << j << ": relative difference to central differences "
              << (col - fd).norm() / fd.norm() << "\n";
    ASSERT_GT(fd.norm(), 1e-3);
    EXPECT_LT((col - fd).norm(), 1e-6 * fd.norm()) << "structural unknown " << j;
    EXPECT_LT((col.tail(4) - fd.tail(4)).norm(), 1e-6 * std::max(fd.tail(4).norm(), 1e-3)) << "structural unknown " << j;
  }
  // Galilean invariance: plunge displacement alone does not change the flow residual
  const vec<double> dh = a.col(s.flow_size());
  EXPECT_LT(dh.head(s.flow_size()).norm(), 1e-9 * a.col(s.flow_size() + 2).head(s.flow_size()).norm());
}

// The coupling blocks come from one jet<double, 4> pass (all 4 structural directions at once):
// every structural column of the exact and approximate matrices (block_jacobians and the single
// assemblies) equals the one taylor<double, 1> pass per column that defines it, and the
// structural row (A_sf, A_ss) equals per-unknown taylor passes of the residual too.
TEST(aerofoil_system, coupling_blocks_equal_one_taylor_pass_per_structural_unknown) {
  const auto s = make_system(0.8);
  const auto w = perturbed_state(s, 8);
  const double mu = 2.5;
  const Eigen::Index nf = s.flow_size(), n = s.size();
  using tj = taylor<double, 1>;
  Eigen::MatrixXd cols(n, 4);
  for (int j = 0; j < 4; ++j) {
    vec<tj> wj = w.cast<tj>();
    wj[nf + j] = tj::variable(w[nf + j], 1.0);
    const vec<tj> r = s.residual<tj>(wj, tj(mu));
    for (Eigen::Index i = 0; i < n; ++i) cols(i, j) = r[i][1];
  }
  const auto [exact, approximate] = s.block_jacobians(w, mu);
  const std::array<Eigen::SparseMatrix<double>, 4> mats{exact.to_sparse(), approximate.to_sparse(),
                                                        s.block_jacobian(w, mu).to_sparse(),
                                                        s.approximate_block_jacobian(w, mu).to_sparse()};
  for (std::size_t m = 0; m < mats.size(); ++m)
    for (int j = 0; j < 4; ++j) {
      const vec<double> col = mats[m].col(nf + j);
      ASSERT_GT(cols.col(j).norm(), 1e-3);
      EXPECT_LT((col - cols.col(j)).lpNorm<Eigen::Infinity>(), 1e-14 * cols.col(j).lpNorm<Eigen::Infinity>())
          << "matrix " << m << " structural column " << j;
      EXPECT_LT((col.tail(4) - cols.col(j).tail(4)).norm(), 1e-14 * std::max(cols.col(j).tail(4).norm(), 1e-3))
          << "matrix " << m << " structural column " << j;
    }
  // the structural rows: (A_sf, A_ss) v against the taylor product for random flow directions
  const Eigen::SparseMatrix<double> rows = mats[0].bottomRows(4);
  for (int which = 0; which < 2; ++which) {
    const vec<double> v = random_vector(n, 40 + which);
    const vec<double> ref = jacobian_product(s, w, mu, v).tail(4);
    EXPECT_LT((rows * v - ref).norm(), 1e-13 * ref.norm()) << which;
  }
}

TEST(aerofoil_system, modified_order_jacobian_differs_only_in_the_flow_block) {
  const auto s = make_system(0.6);
  const auto w = perturbed_state(s, 4);
  const Eigen::SparseMatrix<double> d = s.jacobian(w, 2.0) - s.approximate_jacobian(w, 2.0);
  const Eigen::Index nf = s.flow_size();
  double flow_block = 0, other = 0;
  for (int k = 0; k < d.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(d, k); it; ++it)
      (it.row() < nf && it.col() < nf ? flow_block : other) += std::abs(it.value());
  EXPECT_GT(flow_block, 1.0);
  EXPECT_EQ(other, 0.0);
}

TEST(aerofoil_system, parameter_derivatives_are_analytic_and_exact) {
  const auto s = make_system(0.6);
  const auto w = perturbed_state(s, 5);
  const double mu = 1.8;
  using jet = taylor<double, 1>;
  const vec<jet> rj = s.residual<jet>(w.cast<jet>(), jet::variable(mu, 1.0));
  vec<double> ref(s.size());
  for (Eigen::Index i = 0; i < s.size(); ++i) ref[i] = rj[i][1];
  const vec<double> dmu = s.d_mu(w, mu);
  ASSERT_GT(ref.norm(), 1e-3);
  EXPECT_LT((dmu - ref).norm(), 1e-13 * ref.norm());
  EXPECT_EQ(dmu.head(s.flow_size()).norm(), 0.0);
  const double h = 1e-4;
  const Eigen::SparseMatrix<double> fd = (s.jacobian(w, mu + h) - s.jacobian(w, mu - h)) / (2 * h);
  const Eigen::SparseMatrix<double> amu = s.jacobian_d_mu(w, mu);
  EXPECT_LT((Eigen::SparseMatrix<double>(fd - amu)).norm(), 1e-7 * amu.norm());
}

TEST(aerofoil_system, loads_match_flow_force_integration) {
  // at rest the moment about the elastic axis must equal euler_model::forces with that centre
  euler_options eo;
  eo.moment_centre = {0.4, 0.0, 0.0};
  const euler_model<2> flow(coarsen(naca_cgrid(), 8), {.mach = 0.6, .alpha_rad = 0.02}, eo);
  const aerofoil_system s(flow, structure::pitch_plunge{});
  auto w = perturbed_state(s, 6);
  w.tail(4).setZero();
  const auto [cl, cm] = s.load_coefficients<double>(w);
  const auto f = flow.forces(w.head(s.flow_size()));
  ASSERT_GT(std::abs(f.cl), 1e-3);
  EXPECT_NEAR(cl, f.cl, 1e-12 * std::abs(f.cl));
  EXPECT_NEAR(cm, f.cm, 1e-12 * std::max(std::abs(f.cm), std::abs(f.cl)));
  // rigid pitch of flow + grid together with the same wall pressures: the lift rotates with the
  // body (a rigid rotation of everything by alpha turns the body-axis force by alpha)
  auto wa = w;
  wa[s.flow_size() + 2] = 0.1;
  const auto [cla, cma] = s.load_coefficients<double>(wa);
  const double fx = f.force[0], fy = f.force[1];
  EXPECT_NEAR(cla, -(fx * std::cos(0.1) + fy * std::sin(0.1)) * std::sin(0.02) +
                       (-fx * std::sin(0.1) + fy * std::cos(0.1)) * std::cos(0.02), 1e-12);
  EXPECT_NEAR(cma, cm, 1e-12);  // moment about the elastic axis is invariant under rotation about it
}

// The moved metrics (rotation of the rest metrics) against compute_metrics on the rigidly moved
// points and speeds of rigid_motion.hpp: area vectors, volumes and swept volumes to rounding, in
// double and with the derivatives of jet<double, 4> in the four structural unknowns.
TEST(aerofoil_system, moved_metrics_equal_compute_metrics_on_the_moved_grid) {
  const aerofoil_system s = make_system(0.7);
  const vec<double> w = perturbed_state(s, 11);
  using J = jet<double, 4>;
  vec<J> wj(w.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) wj[i] = J(w[i]);
  for (int j = 0; j < 4; ++j) wj[s.flow_size() + j] = J::variable(w[s.flow_size() + j], j);
  const auto check = [&](const auto& got, const auto& ref, double scale, const char* what) {
    EXPECT_NEAR(to_double(got), to_double(ref), 1e-13 * scale) << what;
    if constexpr (std::is_same_v<std::decay_t<decltype(got)>, J>) {
      for (int j = 0; j < 4; ++j) {
        EXPECT_NEAR(got.derivative(j), ref.derivative(j), 1e-13 * scale) << what << " d/dx" << j;
      }
    }
  };
  const auto compare = [&](const auto& wv) {
    using T = typename std::decay_t<decltype(wv)>::Scalar;
    multiblock_points<T, 2> pts, spd;
    coupling::rigid_grid_motion<T>(s.flow().grid().points, s.pose<T>(wv),
                                   {s.structure().parameters().x_ea, s.structure().parameters().y_ea}, pts, &spd);
    const auto ref = compute_metrics<T, 2>(pts, &spd);
    const auto got = s.moved_metrics<T>(wv);
    ASSERT_EQ(got.blocks.size(), ref.blocks.size());
    double amax = 0, vmax = 0;
    for (const auto& b : ref.blocks) {
      for (const auto& v : b.volume) vmax = std::max(vmax, std::abs(to_double(v)));
      for (int d = 0; d < 2; ++d)
        for (const auto& n : b.normal[d]) amax = std::max({amax, std::abs(to_double(n[0])), std::abs(to_double(n[1]))});
    }
    for (std::size_t b = 0; b < ref.blocks.size(); ++b) {
      ASSERT_EQ(got.blocks[b].volume.size(), ref.blocks[b].volume.size());
      for (std::size_t k = 0; k < ref.blocks[b].volume.size(); ++k)
        check(got.blocks[b].volume[k], ref.blocks[b].volume[k], vmax, "volume");
      for (int d = 0; d < 2; ++d) {
        ASSERT_EQ(got.blocks[b].normal[d].size(), ref.blocks[b].normal[d].size());
        for (std::size_t k = 0; k < ref.blocks[b].normal[d].size(); ++k) {
          check(got.blocks[b].normal[d][k][0], ref.blocks[b].normal[d][k][0], amax, "area x");
          check(got.blocks[b].normal[d][k][1], ref.blocks[b].normal[d][k][1], amax, "area y");
          // swept volume: |x_g| ~ alpha' 30 chords on the far field
          check(got.blocks[b].speed[d][k], ref.blocks[b].speed[d][k], 30 * amax, "swept volume");
        }
      }
    }
  };
  compare(w);
  compare(wj);
  // the swept volumes are not all zero (the test compares moving faces)
  const auto m = s.moved_metrics<double>(w);
  double qmax = 0;
  for (const auto& q : m.blocks[0].speed[0]) qmax = std::max(qmax, std::abs(q));
  EXPECT_GT(qmax, 1e-3);
}

// steady_equilibrium returns only equilibria of the COUPLED system: at non-zero incidence the
// converged flow loads the section at rest (C_l ~ 0.1 here), so it throws and says why; at zero
// incidence the same call returns a state with f(w, Ubar) ~ 0 for any Ubar.
TEST(aerofoil_system, steady_equilibrium_refuses_a_flow_that_loads_the_section) {
  const aerofoil_system lifting(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.6, .alpha_rad = 0.02}),
                                structure::pitch_plunge{});
  try {
    (void)lifting.steady_equilibrium();
    FAIL() << "no convergence_error for a lifting flow";
  } catch (const convergence_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("C_l = "), std::string::npos) << msg;
    EXPECT_NE(msg.find("not an equilibrium"), std::string::npos) << msg;
  }
  // the same flow is accepted with a load limit above its C_l (the caller's choice)
  const vec<double> w = lifting.steady_equilibrium({}, 1.0);
  EXPECT_GT(std::abs(lifting.load_coefficients<double>(w).first), 1e-2);
  const aerofoil_system symmetric(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.6, .alpha_rad = 0.0}),
                                  structure::pitch_plunge{});
  const vec<double> ws = symmetric.steady_equilibrium();
  EXPECT_LT(std::abs(symmetric.load_coefficients<double>(ws).first), 1e-9);
  EXPECT_LT(symmetric.residual<double>(ws, 3.0).norm(), 1e-7);
}

TEST(aerofoil_system, symmetric_equilibrium_is_independent_of_ubar) {
  auto s = make_system(0.5);
  euler_model<2> flow = s.flow();
  vec<double> wf = flow.free_stream_vector();
  const auto rep = solve_steady<2>(flow, wf);
  ASSERT_TRUE(rep.converged);
  vec<double> w = s.free_stream_state();
  w.head(s.flow_size()) = wf;
  const double flow_scale = s.residual<double>(s.free_stream_state(), 1.0).norm();
  ASSERT_GT(flow_scale, 1e-2);  // free stream alone is not an equilibrium (the wall deflects it)
  for (double ubar : {0.5, 1.0, 3.0}) {
    const auto r = s.residual<double>(w, ubar);
    EXPECT_LT(r.head(s.flow_size()).norm(), 1e-9 * flow_scale) << "Ubar " << ubar;
    EXPECT_LT(r.tail(4).norm(), 1e-10) << "Ubar " << ubar;
    EXPECT_EQ(s.d_mu(w, ubar).norm(), 0.0);
  }
  // a displaced section is not an equilibrium and the spring force depends on Ubar
  auto wd = w;
  wd[s.flow_size() + 2] = 0.01;
  EXPECT_GT(std::abs(s.residual<double>(wd, 1.0)[s.size() - 1] - s.residual<double>(wd, 3.0)[s.size() - 1]), 1e-3);
}

TEST(aerofoil_system, rejects_bad_input) {
  const auto s = make_system(0.6);
  EXPECT_THROW(s.residual<double>(vec<double>::Zero(5), 1.0), input_error);
  auto w = s.free_stream_state();
  w[3] = std::nan("");
  EXPECT_THROW(s.jacobian(w, 1.0), input_error);
  euler_options eo;
  eo.vortex_far_field = true;
  EXPECT_THROW(aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.5}, eo), structure::pitch_plunge{}),
               input_error);
}

// The centre-manifold reduction needs 2nd and 3rd derivatives of the residual at the symmetric
// equilibrium. With the exact Osher contact switch they do not exist there (the wake cut has
// u* = 0 between mirror states, the outer boundary ub = 0: finite-difference C(v, v, v) does
// not converge as h falls); with
// contact_smoothing they do, and dd finite differences converge to the taylor<> value.
TEST(aerofoil_system, contact_smoothing_makes_the_residual_smooth_at_the_symmetric_equilibrium) {
  auto third_by = [](double delta) {
    structure::pitch_plunge_parameters p;
    p.mu_s = 100.0;
    euler_options fo;
    fo.contact_smoothing = delta;
    const aerofoil_system s(euler_model<2>(coarsen(naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.0}, fo),
                            structure::pitch_plunge(p));
    const vec<double> w = s.steady_equilibrium();
    vec<double> v = 0.01 * random_vector(s.size(), 7);
    v.tail(4) << 0.01, 0.02, 0.03, -0.01;  // plunge, pitch and their rates: breaks the symmetry
    const double mu = 4.0;
    // the assembled exact Jacobian differentiates the smoothed switches too
    const vec<double> wp = perturbed_state(s, 5);
    const vec<double> ref = jacobian_product(s, wp, mu, v);
    EXPECT_LT((s.jacobian(wp, mu) * v - ref).norm(), 1e-8 * ref.norm()) << "delta " << delta;
    std::array<vec<double>, 3> c{taylor_products<double>{}.third(s, w, mu, v),
                                 fd_products<dd_real>{1e-3}.third(s, w, mu, v),
                                 fd_products<dd_real>{1e-5}.third(s, w, mu, v)};
    return c;
  };
  const auto smooth = third_by(0.05);
  const double scale = smooth[0].norm();
  ASSERT_GT(scale, 1e-6);
  std::cout << "smoothed: |C_fd(1e-3) - C_taylor| / |C| = " << (smooth[1] - smooth[0]).norm() / scale
            << ", |C_fd(1e-5) - C_taylor| / |C| = " << (smooth[2] - smooth[0]).norm() / scale << "\n";
  EXPECT_LT((smooth[1] - smooth[0]).norm(), 1e-5 * scale);
  EXPECT_LT((smooth[2] - smooth[0]).norm(), 1e-5 * scale);
  const auto exact = third_by(0.0);
  const double spread = (exact[2] - exact[1]).norm() / std::max(exact[1].norm(), exact[2].norm());
  std::cout << "exact switch: |C_fd(1e-3)| = " << exact[1].norm() << ", |C_fd(1e-5)| = " << exact[2].norm()
            << ", relative difference " << spread << " (no third derivative)\n";
  EXPECT_GT(spread, 0.5);
}

TEST(aerofoil_system, residual_and_loads_refuse_non_finite_and_wrongly_sized_states) {
  const auto s = make_system(0.6);
  const vec<double> ok = perturbed_state(s, 3);
  EXPECT_TRUE(s.residual<double>(ok, 1.0).allFinite());  // valid
  auto message = [](auto f) {
    try {
      f();
    } catch (const input_error& e) {
      return std::string(e.what());
    } catch (const std::exception& e) {
      return std::string("not an input_error: ") + e.what();
    }
    return std::string("no exception");
  };
  // a NaN pitch moves the grid to NaN: the refusal names the structural unknown
  vec<double> w = ok;
  w[s.flow_size() + 2] = std::nan("");
  EXPECT_NE(message([&] { s.residual<double>(w, 1.0); }).find("aerofoil_system::residual: state entry "),
            std::string::npos)
      << message([&] { s.residual<double>(w, 1.0); });
  EXPECT_NE(message([&] { s.residual<double>(w, 1.0); }).find("structural unknown 2"), std::string::npos);
  w = ok;
  w[4 * 5 + 1] = INFINITY;
  EXPECT_NE(message([&] { s.residual<double>(w, 1.0); }).find("flow cell 5"), std::string::npos)
      << message([&] { s.residual<double>(w, 1.0); });
  // a jet state: its value part is checked
  using J = taylor<double, 1>;
  vec<J> wj(ok.size());
  for (Eigen::Index i = 0; i < ok.size(); ++i) wj[i] = J::variable(ok[i], 0.0);
  wj[s.flow_size()] = J::variable(std::nan(""), 1.0);
  EXPECT_THROW(s.residual<J>(wj, J(1.0)), input_error);
  EXPECT_THROW(s.residual<double>(ok, std::nan("")), input_error);
  // Ubar = 0: K has 1/Ubar^2
  EXPECT_THROW(s.residual<double>(ok, 0.0), input_error);
  // pose and loads read w[flow_size() + k] of any vector
  const vec<double> short_w = ok.head(ok.size() - 2);
  EXPECT_THROW(s.load_coefficients<double>(short_w), input_error);
  EXPECT_THROW(s.pose<double>(short_w), input_error);
  // every Jacobian entry point names itself
  EXPECT_NE(message([&] { s.approximate_block_jacobian(short_w, 1.0); }).find("aerofoil_system::approximate_jacobian"),
            std::string::npos);
  EXPECT_NE(message([&] { s.block_jacobians(short_w, 1.0); }).find("aerofoil_system::jacobian"), std::string::npos);
}

// set_mach / set_free_stream change the free stream in place: a system built at M = 0.6 and set
// to M = 0.85 gives the same bits as one built at 0.85 (residual, both block Jacobians, loads,
// parameter derivatives), the flow model's grid, metrics and halos are the same objects (their
// storage is not reallocated), and bad conditions are refused with the system unchanged.
TEST(aerofoil_system, set_mach_in_place_equals_a_system_built_at_that_mach) {
  auto changed = make_system(0.6);
  const auto* points = changed.flow().grid().points.blocks[0].x.data();
  const auto* volumes = changed.flow().metrics().blocks[1].volume.data();
  const auto* halos = changed.flow().halos().data();
  auto same_bits = [](const aerofoil_system& a, const aerofoil_system& b, const char* where) {
    SCOPED_TRACE(where);
    EXPECT_EQ(a.free_stream_state(), b.free_stream_state());
    const vec<double> w = perturbed_state(b, 9);
    const double mu = 2.5;
    EXPECT_EQ(a.residual<double>(w, mu), b.residual<double>(w, mu));
    const auto pa = a.jacobians(w, mu), pb = b.jacobians(w, mu);
    EXPECT_EQ(pa.exact.col_index(), pb.exact.col_index());
    EXPECT_EQ(pa.exact.values(), pb.exact.values());
    EXPECT_EQ(pa.preconditioning.values(), pb.preconditioning.values());
    EXPECT_EQ(a.load_coefficients<double>(w), b.load_coefficients<double>(w));
    EXPECT_EQ(a.d_mu(w, mu), b.d_mu(w, mu));
  };
  changed.set_mach(0.85);
  EXPECT_EQ(changed.flow().conditions().mach, 0.85);
  same_bits(changed, make_system(0.85), "set_mach");
  EXPECT_EQ(changed.flow().grid().points.blocks[0].x.data(), points);
  EXPECT_EQ(changed.flow().metrics().blocks[1].volume.data(), volumes);
  EXPECT_EQ(changed.flow().halos().data(), halos);
  // the incidence too (the lift direction of the loads follows it)
  const flow::free_stream inclined{.mach = 0.7, .alpha_rad = 0.02};
  changed.set_free_stream(inclined);
  same_bits(changed, aerofoil_system(euler_model<2>(coarsen(naca_cgrid(), 8), inclined), structure::pitch_plunge{}),
            "set_free_stream");
  // refused: the system keeps its free stream and its bits
  const vec<double> w = perturbed_state(changed, 10);
  const vec<double> r0 = changed.residual<double>(w, 2.0);
  for (const double mach : {0.0, -0.7, std::nan(""), std::numeric_limits<double>::infinity()}) EXPECT_THROW(changed.set_mach(mach), input_error) << mach;
  EXPECT_THROW(changed.set_free_stream({.mach = 0.7, .alpha_rad = std::nan("")}), input_error);
  EXPECT_EQ(changed.flow().conditions().mach, inclined.mach);
  EXPECT_EQ(changed.flow().conditions().alpha_rad, inclined.alpha_rad);
  EXPECT_EQ(changed.residual<double>(w, 2.0), r0);
}
