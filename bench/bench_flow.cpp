// Flow-solver costs: in 2D on the NACA 0012 C-grids, residual evaluation and Jacobian assembly
// per cell (the "items" counter is cells, so items_per_second inverts to ns/cell), and the
// full steady solve on the medium grid (M = 0.8, alpha = 1.25 deg), the unit of cost of spec 05.
// In 3D the same kernels and the steady solve on a small two-block box grid around a thin
// rectangular parabolic-arc wing (box_wing_grid below), to show what the dimension costs.
#include <benchmark/benchmark.h>

#include <aerohopf/flow/jacobian.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

using namespace aerohopf;
using namespace aerohopf::flow;

namespace {

euler_model<2>& model(int stride) {
  static const auto fine = naca_cgrid();
  static std::map<int, euler_model<2>> models;
  auto it = models.find(stride);
  if (it == models.end())
    it = models.emplace(stride, euler_model<2>(coarsen(fine, stride), {.mach = 0.8, .alpha_rad = 1.25 * std::numbers::pi / 180})).first;
  return it->second;
}

// ---- 3D: rectangular wing of parabolic-arc section in a two-block H-H box -------------------
//
// Block 0 lies above the plane z = 0, block 1 below it; they meet on that plane, where the
// wing (chord 1 from x = 0 to 1, semi-span b from the symmetry plane y = 0) is a wall patch on
// both blocks ("wing") and the rest is an interface. The grid points of the meeting faces are
// lifted by the local half-thickness 2 tau x (1 - x) sqrt(1 - (y/b)^2) (zero at leading edge,
// trailing edge and tip, so the faces coincide off the wing), blended out linearly towards the
// far field. y = 0 is a slip wall (symmetry). The far field is only a few chords away and
// has no vortex correction: the forces are indicative; the case measures cost, not accuracy.
// Sanity (checked once): volumes positive; CL(alpha = 0) ~ 3e-13 by symmetry; CL(1 deg) = 0.065
// per wing area vs 0.062 from Helmbold's low-aspect-ratio lift slope (aspect ratio 3) with the
// Prandtl-Glauert factor at M = 0.5.
struct box_wing_sizes {
  int upstream = 6, chord = 12, downstream = 6;  // cells along x
  int span = 8, outboard = 4;                    // cells along y
  int normal = 8;                                // cells along z in each block
  double semi_span = 1.5, thickness = 0.06, extent = 4.0;
};

// n + 1 points from a to b, spacing growing geometrically by ratio r away from a
std::vector<double> stretched(double a, double b, int n, double r) {
  std::vector<double> x(static_cast<std::size_t>(n) + 1);
  const double total = (std::pow(r, n) - 1.0) / (r - 1.0);
  double sum = 0.0;
  for (int k = 0; k <= n; ++k) {
    x[static_cast<std::size_t>(k)] = a + (b - a) * sum / total;
    sum += std::pow(r, k);
  }
  x.back() = b;
  return x;
}

multiblock_grid<3> box_wing_grid(const box_wing_sizes& s = {}) {
  // x: geometric upstream and downstream, cosine clustering at leading and trailing edges
  std::vector<double> xs;
  for (double x : stretched(0.0, -s.extent, s.upstream, 1.3)) xs.insert(xs.begin(), x);
  for (int i = 1; i <= s.chord; ++i) xs.push_back(0.5 * (1.0 - std::cos(std::numbers::pi * i / s.chord)));
  const auto down = stretched(1.0, 1.0 + s.extent, s.downstream, 1.3);
  xs.insert(xs.end(), down.begin() + 1, down.end());
  // y: sine clustering towards the tip, geometric outboard
  std::vector<double> ys;
  for (int j = 0; j <= s.span; ++j) ys.push_back(s.semi_span * std::sin(0.5 * std::numbers::pi * j / s.span));
  const auto out = stretched(s.semi_span, s.semi_span + s.extent, s.outboard, 1.3);
  ys.insert(ys.end(), out.begin() + 1, out.end());
  const auto zs = stretched(0.0, s.extent, s.normal, 1.3);  // distance from the plane z = 0

  const int nx = static_cast<int>(xs.size()) - 1, ny = static_cast<int>(ys.size()) - 1, nz = s.normal;
  auto half_thickness = [&](double x, double y) {
    if (x <= 0.0 || x >= 1.0 || y >= s.semi_span) return 0.0;
    return 2.0 * s.thickness * x * (1.0 - x) * std::sqrt(1.0 - (y / s.semi_span) * (y / s.semi_span));
  };
  multiblock_grid<3> g;
  for (int b = 0; b < 2; ++b) {
    const double side = b == 0 ? 1.0 : -1.0;  // upper, lower
    grid_block<double, 3> blk;
    blk.points = {nx + 1, ny + 1, nz + 1};
    blk.x.resize(blk.n_points());
    for (std::size_t k = 0; k < blk.x.size(); ++k) {
      const auto i = unravel<3>(k, blk.points);
      const double d = zs[static_cast<std::size_t>(b == 0 ? i[2] : nz - i[2])];
      const double x = xs[static_cast<std::size_t>(i[0])], y = ys[static_cast<std::size_t>(i[1])];
      blk.x[k] = {x, y, side * (d + half_thickness(x, y) * (1.0 - d / s.extent))};
    }
    g.points.blocks.push_back(std::move(blk));
    g.topology.cells.push_back({nx, ny, nz});
  }
  auto& pt = g.topology.patches;
  const auto& c = g.topology.cells;
  const int le = s.upstream, te = s.upstream + s.chord;
  for (int b = 0; b < 2; ++b) {
    const int inner = b == 0 ? 4 : 5, outer = b == 0 ? 5 : 4;  // faces on / away from z = 0
    for (int f : {0, 1, 3, outer}) pt.push_back(whole_face<3>(b, f, c[b], boundary_kind::far_field));
    auto sym = whole_face<3>(b, 2, c[b], boundary_kind::wall);
    sym.tag = "symmetry";
    pt.push_back(sym);
    auto wing = whole_face<3>(b, inner, c[b], boundary_kind::wall);
    wing.begin = {le, 0, 0};
    wing.end = {te, s.span, 0};
    wing.tag = "wing";
    pt.push_back(wing);
    // the rest of the z = 0 plane: interface to the same cells of the other block
    const index_d<3> lo[3] = {{0, 0, 0}, {te, 0, 0}, {le, s.span, 0}};
    const index_d<3> hi[3] = {{le, ny, 0}, {nx, ny, 0}, {te, ny, 0}};
    for (int r = 0; r < 3; ++r) {
      auto p = whole_face<3>(b, inner, c[b], boundary_kind::interface);
      p.begin = lo[r];
      p.end = hi[r];
      p.donor_block = 1 - b;
      p.donor_face = b == 0 ? 5 : 4;
      p.donor_begin = lo[r];
      p.donor_end = hi[r];
      p.transform = {1, 2, 0};
      pt.push_back(p);
    }
  }
  return g;
}

const box_wing_sizes wing_sizes{};

euler_model<3>& model_3d() {
  static euler_model<3> m(box_wing_grid(wing_sizes), {.mach = 0.5, .alpha_rad = 1.0 * std::numbers::pi / 180},
                          {.force_tag = "wing"});
  return m;
}

template <int Dim>
vec<double> state(const euler_model<Dim>& m) {
  auto w = m.free_stream_vector();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  return w;
}

void bm_residual(benchmark::State& st) {
  const auto& m = model(static_cast<int>(st.range(0)));
  const auto w = state<2>(m);
  vec<double> r(w.size());
  for (auto _ : st) {
    m.residual<double>(m.metrics(), w.data(), r.data());
    benchmark::DoNotOptimize(r.data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<long long>(m.n_cells()));
  st.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(m.n_cells()) * st.iterations() * 1e-9,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void bm_jacobian(benchmark::State& st) {
  const auto& m = model(static_cast<int>(st.range(0)));
  const auto kind = st.range(1) ? jacobian_kind::exact : jacobian_kind::modified_order;
  const auto w = state<2>(m);
  block_sparse_matrix<double, 4> a;
  assemble_jacobian<2>(m, w, kind, a);
  for (auto _ : st) {
    assemble_jacobian<2>(m, w, kind, a);
    benchmark::DoNotOptimize(a.values().data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<long long>(m.n_cells()));
  st.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(m.n_cells()) * st.iterations() * 1e-9,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void bm_steady_medium(benchmark::State& st) {
  auto& m = model(2);
  for (auto _ : st) {
    auto w = m.free_stream_vector();
    steady_options opt;
    opt.exact_switch_drop = 1e-3;
    const auto rep = solve_steady<2>(m, w, opt);
    st.counters["steps"] = rep.steps;
    st.counters["gmres_iterations"] = rep.linear_iterations;
  }
}

void bm_residual_3d(benchmark::State& st) {
  const auto& m = model_3d();
  const auto w = state<3>(m);
  vec<double> r(w.size());
  for (auto _ : st) {
    m.residual<double>(m.metrics(), w.data(), r.data());
    benchmark::DoNotOptimize(r.data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<long long>(m.n_cells()));
  st.counters["cells"] = static_cast<double>(m.n_cells());
  st.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(m.n_cells()) * st.iterations() * 1e-9,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void bm_jacobian_3d(benchmark::State& st) {
  const auto& m = model_3d();
  const auto kind = st.range(0) ? jacobian_kind::exact : jacobian_kind::modified_order;
  const auto w = state<3>(m);
  block_sparse_matrix<double, 5> a;
  assemble_jacobian<3>(m, w, kind, a);
  for (auto _ : st) {
    assemble_jacobian<3>(m, w, kind, a);
    benchmark::DoNotOptimize(a.values().data());
  }
  st.SetItemsProcessed(st.iterations() * static_cast<long long>(m.n_cells()));
  st.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(m.n_cells()) * st.iterations() * 1e-9,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// M = 0.5, alpha = 1 deg on the box-wing grid; CL and CD per unit wing (semi-span) area
void bm_steady_box_wing(benchmark::State& st) {
  auto& m = model_3d();
  for (auto _ : st) {
    auto w = m.free_stream_vector();
    const auto rep = solve_steady<3>(m, w, {});
    const auto f = m.forces(w);
    st.counters["cells"] = static_cast<double>(m.n_cells());
    st.counters["steps"] = rep.steps;
    st.counters["gmres_iterations"] = rep.linear_iterations;
    st.counters["solve_s"] = rep.seconds;
    st.counters["CL"] = f.cl / wing_sizes.semi_span;
    st.counters["CD"] = f.cd / wing_sizes.semi_span;
  }
}

}  // namespace

// arguments: grid stride (2 = medium, 1 = fine); for the Jacobian also 0 = modified, 1 = exact
BENCHMARK(bm_residual)->Arg(2)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_jacobian)->Args({2, 0})->Args({2, 1})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(bm_steady_medium)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(bm_residual_3d)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_jacobian_3d)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_steady_box_wing)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
