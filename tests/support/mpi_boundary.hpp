#pragma once
// The distributed flutter families' tests (tests/distributed/test_mpi_*_family.cpp): a boundary
// traced on the ranks against the serial family's.
#include <gtest/gtest.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>

#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "support/mpi_test.hpp"

namespace aerohopf::test {

/// The boundary of `dist` and of `serial` at `level` and `machs` with options o, Newton to
/// ||F|| <= 1e-10 (the driver's default 1e-7 leaves mu* a few 1e-8 from the limit, differently
/// on the ranks, whose GMRES iterates differ): the same Mach numbers, mu* and omega* to 1e-8
/// relative, mu* the same on every rank, the same checks with their lowest crossing to
/// check_tolerance relative. `also(p, q)` checks more of each point p against the serial q (e.g.
/// the static deflection); the root prints each pair.
template <class Serial, class Distributed>
void expect_serial_boundary(
    const Serial& serial, const Distributed& dist, int level, const std::vector<double>& machs,
    flutter_boundary_options o, const std::string& label,
    const std::function<void(const flutter_boundary_point&, const flutter_boundary_point&)>& also = {},
    double check_tolerance = 1e-8) {
  o.tolerance = 1e-10;
  o.log = nullptr;
  o.label = label;
  const flutter_boundary ref = trace_flutter_boundary(serial, level, machs, nullptr, o);
  o.log = world_rank() == 0 ? &std::cout : nullptr;
  o.label = label + " on " + std::to_string(world_size()) + " ranks";
  const flutter_boundary b = trace_flutter_boundary(dist, level, machs, nullptr, o);
  ASSERT_TRUE(ref.complete) << ref.stop_reason;
  ASSERT_TRUE(b.complete) << b.stop_reason;
  ASSERT_EQ(b.points.size(), ref.points.size());
  for (std::size_t k = 0; k < b.points.size(); ++k) {
    const auto &p = b.points[k], &q = ref.points[k];
    EXPECT_EQ(p.mach, q.mach);
    EXPECT_LT(std::abs(p.mu - q.mu), 1e-8 * q.mu) << "M = " << p.mach << ": mu* " << p.mu << " vs " << q.mu;
    EXPECT_LT(std::abs(p.omega - q.omega), 1e-8 * q.omega) << "M = " << p.mach;
    EXPECT_TRUE(same_on_every_rank(p.mu)) << "M = " << p.mach;
    EXPECT_GT(p.linear_iterations, 0);
    if (also) also(p, q);
    if (world_rank() == 0)
      std::cout << label << ", M = " << p.mach << ": mu* " << std::setprecision(12) << p.mu << " (serial " << q.mu
                << "), omega* " << p.omega << " (serial " << q.omega << "), " << p.newton_iterations << " Newton / "
                << p.linear_iterations << " GMRES (serial " << q.newton_iterations << " / " << q.linear_iterations
                << ")\n";
  }
  ASSERT_EQ(b.checks.size(), ref.checks.size());
  EXPECT_TRUE(b.checks_passed());
  // the crossing checks: the lowest crossing (a V-g scan's rising zero of g at an incidence,
  // from eigenvalues to the scan's tolerance) as the serial one's
  for (std::size_t k = 0; k < b.checks.size(); ++k) {
    const auto &c = b.checks[k], &r = ref.checks[k];
    EXPECT_EQ(c.mach, r.mach);
    EXPECT_EQ(c.what, r.what);
    EXPECT_EQ(c.pass, r.pass) << "M = " << c.mach;
    EXPECT_LT(std::abs(c.lowest_mu - r.lowest_mu), check_tolerance * std::abs(r.lowest_mu))
        << "M = " << c.mach << ": lowest crossing " << c.lowest_mu << " vs " << r.lowest_mu;
    if (world_rank() == 0)
      std::cout << label << ", check at M = " << c.mach << " (" << c.what << "): lowest crossing "
                << std::setprecision(12) << c.lowest_mu << " (serial " << r.lowest_mu << ")\n";
  }
}

}  // namespace aerohopf::test
