// imaginary_axis_crossings against dense eigen-decompositions: on a small random system every
// reported crossing is an eigenvalue on the axis, and every change of the number of unstable
// eigenvalues along a fine q scan is explained by a reported crossing (or the divergence root),
// with B confined to the structural block and with B reaching into the flow columns (as the
// wing's generalised forces do; split_affine recovers both parts); on the aerofoil (very coarse grid, light case, M = 0.5) the lowest crossing is the Hopf point
// of the augmented Newton solver.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/axis_crossings.hpp>
#include <aerohopf/bifurcation/hopf.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>
#include <aerohopf/models/aerofoil.hpp>

#include <Eigen/Eigenvalues>

#include <iostream>
#include <random>
#include <string>

using namespace aerohopf;

namespace {
// A stable "fluid" block of 40 unknowns coupled to two oscillators whose stiffnesses scale with q.
struct toy {
  Eigen::SparseMatrix<double> a0;
  Eigen::MatrixXd b_ss;
  Eigen::SparseMatrix<double> b_sf;  // empty unless flow_columns
  Eigen::MatrixXd dense(double q) const {
    Eigen::MatrixXd a = Eigen::MatrixXd(a0);
    a.bottomRightCorner(4, 4) += q * b_ss;
    if (b_sf.size() != 0) a.bottomLeftCorner(4, b_sf.cols()) += q * Eigen::MatrixXd(b_sf);
    return a;
  }
};
// flow_columns: the oscillators' forces also depend on q times the first ten fluid unknowns
toy make_toy(bool flow_columns = false) {
  const int nf = 40, n = nf + 4;
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < nf; ++i) {
    a(i, i) = -1.0 - 0.1 * i;
    if (i + 1 < nf) a(i, i + 1) = 0.6 * u(gen);
    if (i > 0) a(i, i - 1) = -0.6 * u(gen);
  }
  for (int i = 0; i < nf; ++i)
    for (int j = 0; j < 4; ++j) {
      a(i, nf + j) = 0.3 * u(gen);
      a(nf + j, i) = 0.2 * u(gen);
    }
  // x1' = v1, v1' = -q x1 - 0.02 v1 + 0.3 x2, x2' = v2, v2' = -2 q x2 - 0.01 v2 - 0.2 x1
  Eigen::Matrix4d ss;
  ss << 0, 1, 0, 0, 0, -0.02, 0.3, 0, 0, 0, 0, 1, -0.2, 0, 0, -0.01;
  a.bottomRightCorner(4, 4) += ss;
  toy t;
  t.a0 = a.sparseView();
  t.b_ss = Eigen::Matrix4d::Zero();
  t.b_ss(1, 0) = -1;
  t.b_ss(3, 2) = -2;
  if (flow_columns) {
    Eigen::MatrixXd bsf = Eigen::MatrixXd::Zero(4, nf);
    for (int j = 0; j < 10; ++j) {
      bsf(1, j) = 0.05 * u(gen);
      bsf(3, j) = 0.05 * u(gen);
    }
    t.b_sf = bsf.sparseView();
  }
  return t;
}
int unstable_count(const Eigen::MatrixXd& a) {
  const Eigen::EigenSolver<Eigen::MatrixXd> es(a, false);
  int c = 0;
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) c += es.eigenvalues()[i].real() > 0;
  return c;
}
}  // namespace

namespace {
void check_toy(const toy& t, const char* name) {
  axis_crossing_options o;
  o.omega_min = 1e-3;
  o.omega_max = 6.0;
  o.samples = 3000;
  const axis_crossing_result r = imaginary_axis_crossings(t.a0, t.b_ss, t.b_sf, o);
  EXPECT_EQ(r.rank, 2);
  ASSERT_FALSE(r.crossings.empty());
  for (const auto& c : r.crossings) {
    const Eigen::EigenSolver<Eigen::MatrixXd> es(t.dense(c.q), false);
    double d = INFINITY;
    for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i)
      d = std::min(d, std::abs(es.eigenvalues()[i] - std::complex<double>(0, c.omega)));
    EXPECT_LT(d, 1e-7) << "q " << c.q << " omega " << c.omega;
  }
  // along q in (0, 8]: the unstable count changes only at a reported crossing (2 eigenvalues:
  // the pair) or a divergence root (1 real eigenvalue)
  std::vector<double> events;
  for (const auto& c : r.crossings)
    if (c.q > 0 && c.q < 8) events.push_back(c.q);
  for (const auto& d : r.divergence_roots)
    if (std::abs(d.imag()) < 1e-9 && d.real() > 0 && d.real() < 8) events.push_back(d.real());
  int explained = 0, changes = 0;
  const int nq = 800;
  int prev = unstable_count(t.dense(0.01));
  for (int j = 1; j <= nq; ++j) {
    const double q0 = 0.01 + (j - 1) * (8.0 - 0.01) / nq, q1 = 0.01 + j * (8.0 - 0.01) / nq;
    const int now = unstable_count(t.dense(q1));
    if (now != prev) {
      ++changes;
      bool found = false;
      for (double e : events) found = found || (e > q0 - 1e-9 && e < q1 + 1e-9);
      EXPECT_TRUE(found) << "the unstable count changes from " << prev << " to " << now << " between q = " << q0
                         << " and " << q1 << " without a reported crossing";
      explained += found;
    }
    prev = now;
  }
  std::cout << name << ": " << r.crossings.size() << " crossings (" << r.rejected << " rejected), " << changes
            << " stability changes on the q scan, " << explained << " explained, " << r.factorisations
            << " factorisations\n";
  EXPECT_GE(changes, 1);
}

}  // namespace

TEST(axis_crossings, every_crossing_is_an_axis_eigenvalue_and_every_stability_change_a_crossing) {
  const toy t = make_toy();
  check_toy(t, "toy");
  axis_crossing_options o;
  o.omega_min = 1e-3;
  o.omega_max = 6.0;
  axis_crossing_options bad = o;
  bad.omega_max = 0;
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, bad), input_error);
  EXPECT_THROW(imaginary_axis_crossings(t.a0, Eigen::MatrixXd::Zero(4, 4), o), input_error);
  EXPECT_THROW(imaginary_axis_crossings(t.a0, Eigen::MatrixXd::Identity(50, 50), o), input_error);
}

TEST(axis_crossings, b_reaching_into_the_flow_columns) {
  const toy t = make_toy(true);
  check_toy(t, "toy with B_sf");
  // the crossings move when B_sf is dropped: the flow columns are really used
  const toy t0 = make_toy();
  axis_crossing_options o;
  o.omega_min = 1e-3;
  o.omega_max = 6.0;
  o.samples = 3000;
  const auto r = imaginary_axis_crossings(t.a0, t.b_ss, t.b_sf, o), r0 = imaginary_axis_crossings(t0.a0, t0.b_ss, o);
  ASSERT_FALSE(r.crossings.empty());
  ASSERT_FALSE(r0.crossings.empty());
  EXPECT_GT(std::abs(r.crossings.front().q - r0.crossings.front().q), 1e-4);
  // split_affine recovers A0, B_ss and B_sf from two matrices of the family
  const double q1 = 0.7, q2 = 1.9;
  const Eigen::SparseMatrix<double> j1 = t.dense(q1).sparseView(), j2 = t.dense(q2).sparseView();
  const affine_split sp = split_affine(j1, q1, j2, q2, 4, "toy");
  EXPECT_LT((Eigen::MatrixXd(sp.a0) - t.dense(0)).norm(), 1e-13);
  EXPECT_LT((sp.b_ss - t.b_ss).norm(), 1e-13);
  EXPECT_LT((Eigen::MatrixXd(sp.b_sf) - Eigen::MatrixXd(t.b_sf)).norm(), 1e-13);
  const auto rs = imaginary_axis_crossings(sp, o);
  ASSERT_EQ(rs.crossings.size(), r.crossings.size());
  for (std::size_t k = 0; k < r.crossings.size(); ++k) {
    EXPECT_NEAR(rs.crossings[k].q, r.crossings[k].q, 1e-9 * (1 + std::abs(r.crossings[k].q)));
    EXPECT_NEAR(rs.crossings[k].omega, r.crossings[k].omega, 1e-9);
  }
  // B_sf of the wrong shape or with non-finite entries is refused
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, Eigen::SparseMatrix<double>(4, 7), o), input_error);
  Eigen::SparseMatrix<double> bad = t.b_sf;
  bad.coeffRef(1, 0) = NAN;
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, bad, o), input_error);
}

// The aerofoil: q = 1/Ubar^2 enters only the structural stiffness, so J(Ubar) = A0 + q B with B in
// the structural 4 x 4 block. The largest crossing q (lowest Ubar) over the band is the Hopf
// point of the augmented Newton solver (the dense-spectrum test of test_aerofoil_hopf checks
// that point against all eigenvalues).
TEST(axis_crossings, aerofoil_lowest_crossing_is_the_hopf_point) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  const models::aerofoil_system s(flow::euler_model<2>(flow::coarsen(flow::naca_cgrid(), 8), {.mach = 0.5, .alpha_rad = 0.0}),
                                  structure::pitch_plunge(p));
  const vec<double> w = s.steady_equilibrium();
  const double u1 = 1.5, u2 = 2.5, q1 = 1 / (u1 * u1), q2 = 1 / (u2 * u2);
  const Eigen::SparseMatrix<double> j1 = s.jacobian(w, u1), j2 = s.jacobian(w, u2);
  const affine_split sp = split_affine(j1, q1, j2, q2, 4, "aerofoil");
  const Eigen::SparseMatrix<double>& a0 = sp.a0;
  const Eigen::MatrixXd& b = sp.b_ss;
  // a change outside the structural block is refused
  Eigen::SparseMatrix<double> j2x = j2;
  j2x.coeffRef(0, 0) += 1.0;
  EXPECT_THROW(split_affine(j1, q1, j2x, q2, 4), input_error);
  // affine in q: the third Jacobian is reproduced
  const double u3 = 1.9, q3 = 1 / (u3 * u3);
  Eigen::MatrixXd j3 = Eigen::MatrixXd(s.jacobian(w, u3)), a3 = Eigen::MatrixXd(a0);
  a3.bottomRightCorner(4, 4) += q3 * b;
  EXPECT_LT((j3 - a3).norm(), 1e-12 * j3.norm());

  axis_crossing_options o;
  o.omega_min = 0.05;
  o.omega_max = 3.0;
  o.samples = 120;
  const axis_crossing_result r = imaginary_axis_crossings(a0, b, o);
  ASSERT_FALSE(r.crossings.empty());
  const axis_crossing& lowest = r.crossings.front();  // largest q
  const double ubar = 1 / std::sqrt(lowest.q);

  hopf_options ho;
  ho.fixed_equilibrium = true;
  const hopf_result h = solve_hopf(s, hopf_start(s, w, 1.75, 0.6), ho);
  std::cout << "aerofoil: " << r.crossings.size() << " crossings, lowest Ubar = " << ubar << " omega = " << lowest.omega
            << " (Hopf solver: " << h.point.mu << ", " << h.point.omega << "), rank " << r.rank << ", "
            << r.factorisations << " factorisations\n";
  EXPECT_NEAR(ubar, h.point.mu, 1e-7);
  EXPECT_NEAR(lowest.omega, h.point.omega, 1e-7);
}

TEST(axis_crossings, refuses_non_finite_band_tolerances_and_matrix_entries) {
  const toy t = make_toy();
  axis_crossing_options o;
  o.samples = 20;
  EXPECT_NO_THROW(imaginary_axis_crossings(t.a0, t.b_ss, o));
  // an infinite band end or tolerance used to pass the range checks (inf > omega_min, inf > 0)
  axis_crossing_options bad = o;
  bad.omega_max = INFINITY;
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, bad), input_error);
  bad = o;
  bad.real_tolerance = INFINITY;  // would accept every sign change of Im q, poles included
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, bad), input_error);
  bad = o;
  bad.omega_tolerance = std::nan("");
  EXPECT_THROW(imaginary_axis_crossings(t.a0, t.b_ss, bad), input_error);
  // a NaN in the flow block of both matrices: NaN - NaN is no dependence on q, it is a bad entry
  Eigen::SparseMatrix<double> j1 = t.a0, j2 = t.a0;
  j1.coeffRef(3, 3) = std::nan("");
  j2.coeffRef(3, 3) = std::nan("");
  try {
    split_affine(j1, 0.5, j2, 1.0, 4);
    ADD_FAILURE() << "no exception";
  } catch (const input_error& e) {
    EXPECT_NE(std::string(e.what()).find("j1(3, 3) is not finite"), std::string::npos) << e.what();
  }
}
