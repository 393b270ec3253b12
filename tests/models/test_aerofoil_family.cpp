// models/aerofoil_family.hpp: the aerofoil as a flutter_family. The levels are grid strides of
// the fine C-grid; the static aeroelastic equilibrium at incidence is checked by the coupled
// residual at the result and by path independence (straight from the section at rest, continued
// up and continued down in Ubar); at zero incidence the equilibrium does not move with Ubar.
#include <gtest/gtest.h>

#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/models/aerofoil_family.hpp>

#include <cmath>
#include <numbers>
#include <optional>

#include "../support/error_messages.hpp"

namespace {

using namespace aerohopf;
using models::aerofoil_family;

aerofoil_family family(double alpha_deg) {
  structure::pitch_plunge_parameters p;
  p.mu_s = 10;
  return aerofoil_family(flow::naca_cgrid(), p, {}, alpha_deg * std::numbers::pi / 180);
}

/// The pitch unknown of a state (h, h', alpha, alpha' last).
double pitch(const vec<double>& w) { return w[w.size() - 2]; }

TEST(AerofoilFamily, LevelsAreStridesOfTheFineGrid) {
  const auto f = family(0.0);
  const auto fine = f.system(1, 0.5), coarse = f.system(4, 0.5), very_coarse = f.system(8, 0.5);
  // the stride-m grid has (n - 1)/m + 1 points a direction: a quarter, then a sixteenth of the cells
  EXPECT_EQ(coarse.flow_size() * 4, f.system(2, 0.5).flow_size());
  EXPECT_EQ(very_coarse.flow_size() * 4, coarse.flow_size());
  EXPECT_EQ(fine.structure_size(), 4);
  EXPECT_EQ(aerofoil_family::level_name(4), "coarse");
  EXPECT_TRUE(f.refines(8, 4));
  EXPECT_FALSE(f.refines(8, 2));
  // the coarser-level bridge's next level: twice the stride, none below the very coarse grid
  EXPECT_EQ(f.coarser_level(2), std::optional<int>(4));
  EXPECT_EQ(f.coarser_level(4), std::optional<int>(8));
  EXPECT_FALSE(f.coarser_level(8).has_value());
  EXPECT_TRUE(f.refines(*f.coarser_level(1), 1));
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)f.system(0, 0.5); }), "stride"));
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)f.coarser_level(0); }), "stride"));
}

TEST(AerofoilFamily, StaticEquilibriumAtIncidenceIsPathIndependent) {
  const auto f = family(1.0);
  const auto s = f.system(8, 0.5);
  EXPECT_FALSE(f.fixed_equilibrium());
  EXPECT_TRUE(f.boundary_options().moving_equilibrium);
  const double tol = 1e-10;
  const vec<double> w17 = f.static_equilibrium(s, 1.7, 2, tol);
  EXPECT_LE(s.residual(w17, 1.7).norm(), tol);
  // the pitch spring deflects under the nose-up moment, more at a lower stiffness (higher Ubar)
  const vec<double> w12 = f.static_equilibrium(s, 1.2, 2, tol);
  EXPECT_GT(pitch(w12), 0.0);
  EXPECT_GT(pitch(w17), pitch(w12));
  // continued up from Ubar = 1.2 and down from Ubar = 2.2: the same equilibrium
  const vec<double> up = f.static_equilibrium_from(s, w12, 1.2, 1.7, 2, tol);
  const vec<double> down = f.static_equilibrium_from(s, f.static_equilibrium(s, 2.2, 2, tol), 2.2, 1.7, 2, tol);
  EXPECT_LE(s.residual(down, 1.7).norm(), tol);
  EXPECT_NEAR(pitch(up), pitch(w17), 1e-9);
  EXPECT_NEAR(pitch(down), pitch(w17), 1e-9);
  EXPECT_LE((down - w17).norm(), 1e-7 * w17.norm());
  // the driver's continuation entry point is the same solve
  EXPECT_NEAR(pitch(f.equilibrium_from(s, w12, 1.2, 1.7)), pitch(w17), 1e-9);
  // a start of the wrong size is refused before any solve
  EXPECT_TRUE(test::contains(test::input_error_of([&] { (void)f.static_equilibrium_from(s, vec<double>(3), 1.2, 1.7); }),
                             "start state"));
}

TEST(AerofoilFamily, ZeroIncidenceEquilibriumDoesNotMoveWithUbar) {
  const auto f = family(0.0);
  const auto s = f.system(8, 0.5);
  EXPECT_TRUE(f.fixed_equilibrium());
  EXPECT_FALSE(f.boundary_options().moving_equilibrium);
  EXPECT_TRUE(f.boundary_options().parameter_even);
  const vec<double> w = f.equilibrium(s, 1.5);
  EXPECT_EQ(pitch(w), 0.0);
  // an equilibrium at every Ubar (the structure at rest, the symmetric flow unloaded)
  for (double ubar : {0.8, 1.5, 3.0}) EXPECT_LE(s.residual(w, ubar).norm(), 1e-8) << "Ubar = " << ubar;
  EXPECT_EQ(f.equilibrium_from(s, w, 1.5, 3.0), w);
}

}  // namespace
