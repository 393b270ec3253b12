// Flow-solver costs in 2D on the NACA 0012 C-grids: residual evaluation and Jacobian assembly
// per cell (the "items" counter is cells, so items_per_second inverts to ns/cell), and the
// full steady solve on the medium grid (M = 0.8, alpha = 1.25 deg), the unit of cost of spec 05.
#include <benchmark/benchmark.h>

#include <aerohopf/flow/jacobian.hpp>
#include <aerohopf/flow/naca_cgrid.hpp>
#include <aerohopf/flow/steady_solver.hpp>

#include <map>
#include <numbers>
#include <random>

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

vec<double> state(const euler_model<2>& m) {
  auto w = m.free_stream_vector();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (Eigen::Index k = 0; k < w.size(); ++k) w[k] *= 1.0 + u(rng);
  return w;
}

void bm_residual(benchmark::State& st) {
  const auto& m = model(static_cast<int>(st.range(0)));
  const auto w = state(m);
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
  const auto w = state(m);
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

}  // namespace

// arguments: grid stride (2 = medium, 1 = fine); for the Jacobian also 0 = modified, 1 = exact
BENCHMARK(bm_residual)->Arg(2)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_jacobian)->Args({2, 0})->Args({2, 1})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(bm_steady_medium)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
