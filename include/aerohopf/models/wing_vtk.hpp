#pragma once
// The flutter mode of a wing for ParaView: the states w0 + eps Re(e^{i phi} p) of a Hopf point
// (w0, p) of a wing_system at equally spaced phases of the cycle, and their wall surfaces
// (deflected, with Cp) as VTK files.
//
// Scale: eps makes the largest grid displacement over the whole cycle a given length (root
// chords). The displacement of a grid point is linear in the modal coordinates, d(phi) =
// Re(e^{i phi} z) with z = d_r + i d_i the point's complex displacement (d_r, d_i: the motion of
// Re p_a, Im p_a), and max over phi of |Re(e^{i phi} z)|^2 = (|z|^2 + |z . z|) / 2 (z . z the
// bilinear product): the exact peak, not a sampled one. Where that scale would make a frame's flow
// state unphysical somewhere (the AGARD medium flutter mode at M = 0.96 at 5 % of the root chord:
// a negative pressure in a far-wake cell at the outflow), eps is halved until every frame is
// physical, and the frames' displacement says so.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "../bifurcation/hopf_point.hpp"
#include "../error.hpp"
#include "../io/vtk.hpp"
#include "wing.hpp"

namespace aerohopf::models {

struct flutter_mode_frames {
  double eps = 0;                   ///< the scale of p
  double peak_displacement = 0;     ///< of the unscaled p over the cycle, root chords
  double displacement = 0;          ///< of the frames (eps * peak_displacement): the one asked for, or less
  std::vector<vec<double>> states;  ///< w0 + eps Re(e^{2 pi i k / phases} p), k = 0 .. phases - 1
};

/// The states of the flutter mode of h at `phases` phases, scaled to a largest grid displacement
/// of `displacement` root chords, or less where that makes a frame unphysical (file comment);
/// input_error if p does not move the wing or the sizes differ.
inline flutter_mode_frames flutter_mode_states(const wing_system& s, const hopf_point& h, double displacement = 0.05,
                                               int phases = 4) {
  const char* who = "flutter_mode_states";
  require_size(h.w.size(), s.size(), who, "Hopf point's equilibrium");
  require_size(h.p.size(), s.size(), who, "Hopf point's eigenvector");
  require(std::isfinite(displacement) && displacement > 0 && phases >= 1, who,
          ": displacement must be > 0 and phases >= 1 (got ", displacement, ", ", phases, ")");
  const Eigen::Index nf = s.flow_size(), m = s.modes();
  const auto& rest = s.flow().grid().points.blocks[0];
  const auto dr = s.motion().points<double>(vec<double>(h.p.segment(nf, m).real()));
  const auto di = s.motion().points<double>(vec<double>(h.p.segment(nf, m).imag()));
  double peak2 = 0;
  for (std::size_t k = 0; k < rest.x.size(); ++k) {
    double rr = 0, ii = 0, ri = 0;
    for (int c = 0; c < 3; ++c) {
      const double a = dr.x[k][c] - rest.x[k][c], b = di.x[k][c] - rest.x[k][c];
      rr += a * a;
      ii += b * b;
      ri += a * b;
    }
    peak2 = std::max(peak2, 0.5 * (rr + ii + std::hypot(rr - ii, 2 * ri)));
  }
  flutter_mode_frames f;
  f.peak_displacement = std::sqrt(peak2);
  require(f.peak_displacement > 0 && std::isfinite(f.peak_displacement), who,
          ": the eigenvector does not move the wing (largest displacement ", f.peak_displacement, ")");
  require(!s.flow().first_nonphysical_cell(h.w.data()), who, ": the Hopf point's equilibrium is not a physical state");
  f.eps = displacement / f.peak_displacement;
  int halvings = 0;
  for (;; ++halvings) {
    f.states.clear();
    bool physical = true;
    for (int k = 0; k < phases && physical; ++k) {
      const std::complex<double> rot = std::polar(f.eps, 2 * std::numbers::pi * k / phases);
      f.states.push_back(h.w + vec<double>((rot * h.p).real()));
      physical = !s.flow().first_nonphysical_cell(f.states.back().data());
    }
    if (physical) break;
    require(halvings < 60, who, ": no scale of the eigenvector keeps the flow physical");
    f.eps *= 0.5;
  }
  // exactly the one asked for unless halved (eps * peak can round below it)
  f.displacement = halvings == 0 ? displacement : f.eps * f.peak_displacement;
  return f;
}

/// flutter_mode_states written as <prefix>_phase<k>.vtk: the wall surface of the grid moved to
/// each state with its Cp (io::write_vtk_wall_surface). Returns the frames.
inline flutter_mode_frames write_flutter_mode_vtk(const wing_system& s, const hopf_point& h, const std::string& prefix,
                                                  double displacement = 0.05, int phases = 4) {
  flutter_mode_frames f = flutter_mode_states(s, h, displacement, phases);
  for (std::size_t k = 0; k < f.states.size(); ++k)
    io::write_vtk_wall_surface(prefix + "_phase" + std::to_string(k) + ".vtk", s.moved_flow(f.states[k]),
                               vec<double>(f.states[k].head(s.flow_size())));
  return f;
}

}  // namespace aerohopf::models
