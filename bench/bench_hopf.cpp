// Speed of the foundation pipeline (Google Benchmark):
//  * the reactor Hopf solve (augmented 3n+2 system, sparse LU) at 64, 256, 1024 cells, from an
//    inverse-power start (the original dense elimination took 8,109 s at 256 cells), and the
//    steady solve it is compared with (Hopf / steady ratio = the cost unit of the method);
//  * B(v,v) and C(v,v,v) products by finite differences in double, dd, qd vs one taylor pass.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/reduction.hpp>
#include <aerohopf/scalar/qd.hpp>

#include <benchmark/benchmark.h>

using namespace aerohopf;

namespace {
vec<double> equilibrium(const tubular_reactor& r, double mu) {
  vec<double> w = r.rest_state();
  for (int k = 1; k <= 8; ++k) w = newton(r, w, mu * k / 8).x;
  return w;
}

void hopf_solve(benchmark::State& st) {
  const tubular_reactor r(int(st.range(0)));
  const vec<double> w = equilibrium(r, 0.16);
  int iters = 0;
  for (auto _ : st) {
    const hopf_result h = solve_hopf(r, hopf_start(r, w, 0.16, 0.4));
    iters = h.report.iterations;
    benchmark::DoNotOptimize(h.point.mu);
  }
  st.counters["newton_iterations"] = iters;
  st.counters["unknowns"] = double(3 * r.size() + 2);
}
BENCHMARK(hopf_solve)->Arg(64)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

void steady_solve(benchmark::State& st) {
  const tubular_reactor r(int(st.range(0)));
  const vec<double> w = equilibrium(r, 0.15);
  for (auto _ : st) benchmark::DoNotOptimize(newton(r, w, 0.16).x.data());
}
BENCHMARK(steady_solve)->Arg(64)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

template <class Provider>
void products(benchmark::State& st) {
  const tubular_reactor r(256);
  const vec<double> w = equilibrium(r, 0.16);
  const vec<double> v = vec<double>::Random(r.size());
  const Provider p{};
  for (auto _ : st) {
    if constexpr (requires { p.products(r, w, 0.16, v); }) {
      benchmark::DoNotOptimize(p.products(r, w, 0.16, v).c_vvv.data());
    } else {
      benchmark::DoNotOptimize(p.second(r, w, 0.16, v).data());
      benchmark::DoNotOptimize(p.third(r, w, 0.16, v).data());
    }
  }
}
BENCHMARK(products<fd_products<double>>)->Name("B_and_C/fd_double/256cells")->Unit(benchmark::kMicrosecond);
BENCHMARK(products<fd_products<dd_real>>)->Name("B_and_C/fd_dd/256cells")->Unit(benchmark::kMicrosecond);
BENCHMARK(products<fd_products<qd_real>>)->Name("B_and_C/fd_qd/256cells")->Unit(benchmark::kMicrosecond);
BENCHMARK(products<taylor_products<double>>)->Name("B_and_C/taylor_double/256cells")->Unit(benchmark::kMicrosecond);
}  // namespace

BENCHMARK_MAIN();
