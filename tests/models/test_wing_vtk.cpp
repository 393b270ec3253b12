// The flutter mode of a wing for ParaView (models/wing_vtk.hpp): the exact peak displacement over
// the cycle against a fine sampling of the phase, the frames symmetric about the equilibrium half a
// cycle apart, the VTK files of the deflected surface (their points moved by the frame's
// displacement), and refusals.
#include <gtest/gtest.h>

#include <aerohopf/error.hpp>
#include <aerohopf/models/wing_vtk.hpp>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "support/tiny_wing_system.hpp"

using namespace aerohopf;
using models::wing_system;

namespace {
using test_support::tiny_wing;
/// A "Hopf point" with a complex eigenvector mixing the modes with different phases.
hopf_point synthetic_point(const wing_system& s) {
  hopf_point h;
  h.w = s.free_stream_state();
  h.mu = 0.07;
  h.omega = 0.5;
  h.p = vec<std::complex<double>>::Zero(s.size());
  const Eigen::Index nf = s.flow_size();
  for (Eigen::Index i = 0; i < nf; ++i) h.p[i] = std::complex<double>(1e-3 * std::sin(0.1 * double(i)), 1e-3);
  const std::complex<double> a[4] = {{1.0, 0.2}, {0.1, -0.4}, {-0.05, 0.02}, {0.01, 0.03}};
  for (Eigen::Index k = 0; k < 4; ++k) {
    h.p[nf + k] = a[k];
    h.p[nf + 4 + k] = std::complex<double>(0, h.omega) * a[k];
  }
  return h;
}
}  // namespace

TEST(wing_vtk, peak_displacement_is_exact_and_frames_are_symmetric) {
  const wing_system s = tiny_wing();
  const hopf_point h = synthetic_point(s);
  const models::flutter_mode_frames f = models::flutter_mode_states(s, h, 0.05, 4);
  ASSERT_EQ(f.states.size(), 4u);
  // the largest displacement of the scaled mode over 720 sampled phases: 0.05, never above
  const Eigen::Index nf = s.flow_size();
  const auto& rest = s.flow().grid().points.blocks[0];
  double sampled = 0;
  for (int k = 0; k < 720; ++k) {
    const std::complex<double> rot = std::polar(f.eps, 2 * std::numbers::pi * k / 720);
    const auto moved = s.motion().points<double>(vec<double>((rot * h.p.segment(nf, 4)).real()));
    for (std::size_t q = 0; q < rest.x.size(); ++q) {
      double e = 0;
      for (int c = 0; c < 3; ++c) e += std::pow(moved.x[q][c] - rest.x[q][c], 2);
      sampled = std::max(sampled, std::sqrt(e));
    }
  }
  EXPECT_LE(sampled, 0.05 * (1 + 1e-12));
  EXPECT_GT(sampled, 0.05 * (1 - 1e-4));  // (pi / 720)^2 / 2 below the peak at most
  // half a cycle apart: symmetric about the equilibrium
  EXPECT_LT((f.states[0] + f.states[2] - 2 * h.w).norm(), 1e-14 * f.states[0].norm());
  EXPECT_LT((f.states[1] + f.states[3] - 2 * h.w).norm(), 1e-14 * f.states[1].norm());
}

// A flow part too large for the asked displacement (density perturbation 500 in one cell against
// about 1): the scale is halved until every frame is physical, the frames stay symmetric.
TEST(wing_vtk, a_flow_part_too_large_for_the_displacement_is_scaled_down) {
  const wing_system s = tiny_wing();
  hopf_point h = synthetic_point(s);
  EXPECT_EQ(models::flutter_mode_states(s, h, 0.05, 4).displacement, 0.05);  // exactly, not eps * peak rounded
  h.p[5 * 7] = std::complex<double>(400.0, -300.0);
  const models::flutter_mode_frames f = models::flutter_mode_states(s, h, 0.05, 4);
  EXPECT_LT(f.displacement, 0.05) << "eps " << f.eps << " peak " << f.peak_displacement;
  EXPECT_GT(f.displacement, 0.05 / 4096);
  EXPECT_DOUBLE_EQ(f.displacement, f.eps * f.peak_displacement);
  for (const auto& w : f.states) EXPECT_FALSE(s.flow().first_nonphysical_cell(w.data()));
  EXPECT_TRUE(s.flow().first_nonphysical_cell(vec<double>(h.w + (2 * f.eps * h.p).real()).data()) ||
              s.flow().first_nonphysical_cell(vec<double>(h.w - (2 * f.eps * h.p).real()).data()) ||
              s.flow().first_nonphysical_cell(vec<double>(h.w + (2 * f.eps * std::complex<double>(0, 1) * h.p).real()).data()) ||
              s.flow().first_nonphysical_cell(vec<double>(h.w - (2 * f.eps * std::complex<double>(0, 1) * h.p).real()).data()))
      << "twice the scale is unphysical in some frame (the halving stopped at the first physical one)";
  EXPECT_LT((f.states[0] + f.states[2] - 2 * h.w).norm(), 1e-14 * f.states[0].norm());
}

TEST(wing_vtk, writes_the_deflected_surface_per_phase) {
  const wing_system s = tiny_wing();
  const hopf_point h = synthetic_point(s);
  const auto dir = std::filesystem::temp_directory_path() / "aerohopf_test_wing_vtk";
  std::filesystem::create_directories(dir);
  const std::string prefix = (dir / "mode").string();
  const models::flutter_mode_frames f = models::write_flutter_mode_vtk(s, h, prefix, 0.05, 4);
  for (int k = 0; k < 4; ++k) {
    std::ifstream in(prefix + "_phase" + std::to_string(k) + ".vtk");
    ASSERT_TRUE(in.good()) << k;
    std::stringstream text;
    text << in.rdbuf();
    const std::string t = text.str();
    EXPECT_NE(t.find("CELLS " + std::to_string(s.wall_faces()) + " "), std::string::npos);
    EXPECT_NE(t.find("SCALARS cp double 1"), std::string::npos);
  }
  // the surface file of a frame is the one of the flow model moved to it
  io::write_vtk_wall_surface((dir / "ref.vtk").string(), s.moved_flow(f.states[1]),
                             vec<double>(f.states[1].head(s.flow_size())));
  std::ifstream a(prefix + "_phase1.vtk"), b(dir / "ref.vtk");
  std::stringstream ta, tb;
  ta << a.rdbuf();
  tb << b.rdbuf();
  EXPECT_EQ(ta.str(), tb.str());
  std::filesystem::remove_all(dir);
}

TEST(wing_vtk, refuses_bad_input) {
  const wing_system s = tiny_wing();
  hopf_point h = synthetic_point(s);
  EXPECT_THROW(models::flutter_mode_states(s, h, -1.0), input_error);
  EXPECT_THROW(models::flutter_mode_states(s, h, 0.05, 0), input_error);
  hopf_point still = h;
  still.p.tail(8).setZero();  // moves no mode
  EXPECT_THROW(models::flutter_mode_states(s, still), input_error);
  h.p.conservativeResize(h.p.size() - 1);
  EXPECT_THROW(models::flutter_mode_states(s, h), input_error);
}
