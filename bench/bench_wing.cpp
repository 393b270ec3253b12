// Costs of the coupled AGARD 445.6 wing (models/wing.hpp) per level, the figures of issue 25 §6
// that are not ratios of one run: residual and bordered-Jacobian assembly in ns per cell, the
// memory of the Jacobians and of the complex BILU(2) of A_ff - i omega I in bytes per cell, the
// products and the preconditioner apply of the Hopf solves in ns per cell and effective GB/s,
// and the steady solve. Argument: grid stride (4 = coarse, 2 = medium); the medium steady solve
// (about 2.5 minutes) is registered apart (bm_wing_steady/2). The state is the free stream at
// M = 0.96 with every mode displaced by 1e-3, so the residual moves the grid and the Jacobian
// has its full coupling; omega = 0.15 is about the flutter frequency there (c / U units).
#include <benchmark/benchmark.h>

#include <aerohopf/flow/wing_geometry.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/models/wing.hpp>
#include <aerohopf/models/wing_family.hpp>
#include <aerohopf/structure/wing_plate.hpp>

#include <complex>
#include <map>
#include <memory>

using namespace aerohopf;

namespace {

constexpr double mach = 0.96, omega = 0.15, mu = 0.01;
constexpr int nb = models::wing_system::nv;

const models::wing_family& family() {
  static const models::wing_family f = [] {
    const flow::wing_geometry w = flow::agard445_6();
    const structure::plate_mesh pm = structure::wing_plate_mesh(w, 24, 24);
    const auto km = structure::assemble_plate(pm, structure::agard445_6_mahogany(w.planform));
    structure::plate_mode_options mo;
    mo.count = 4;
    const auto modes = structure::modal_data_from_plate(pm, structure::plate_modes_of(km, structure::clamped_root(pm, 24), mo));
    return models::wing_family(w, flow::wing_grid_options{}, {2, 4}, modes, Eigen::VectorXd::Zero(1),
                               models::speed_of_sound_schedule{{mach}, {300.0}});
  }();
  return f;
}

struct level_case {
  models::wing_system s;
  vec<double> w;
  std::size_t cells;
};

const level_case& level(int stride) {
  static std::map<int, std::unique_ptr<level_case>> cases;
  auto& c = cases[stride];
  if (!c) {
    models::wing_system s = family().system(stride, mach);
    vec<double> w = s.free_stream_state();
    w.tail(2 * s.structure().modes()).head(s.structure().modes()).setConstant(1e-3);
    const std::size_t cells = s.flow().n_cells();
    c = std::make_unique<level_case>(level_case{std::move(s), std::move(w), cells});
  }
  return *c;
}

void per_cell(benchmark::State& st, std::size_t cells) {
  st.SetItemsProcessed(st.iterations() * static_cast<long long>(cells));
  st.counters["cells"] = static_cast<double>(cells);
  st.counters["ns_per_cell"] = benchmark::Counter(static_cast<double>(cells) * st.iterations() * 1e-9,
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <class M>
double matrix_bytes(const M& a) {
  using S = typename std::decay_t<decltype(a.values())>::value_type;
  return static_cast<double>(a.values().size() * sizeof(S) + a.col_index().size() * sizeof(a.col_index()[0]) +
                             a.row_ptr().size() * sizeof(a.row_ptr()[0]));
}

void bm_wing_residual(benchmark::State& st) {
  const level_case& c = level(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    vec<double> r = c.s.residual(c.w, mu);
    benchmark::DoNotOptimize(r.data());
  }
  per_cell(st, c.cells);
}

// Both matrices of a Newton or Hopf step: the exact one and the first-order preconditioning one.
void bm_wing_jacobians(benchmark::State& st) {
  const level_case& c = level(static_cast<int>(st.range(0)));
  double bytes = 0;
  for (auto _ : st) {
    const auto j = c.s.bordered_jacobians(c.w, mu);
    bytes = matrix_bytes(j.exact.flow()) + matrix_bytes(j.preconditioning.flow());
    benchmark::DoNotOptimize(&j);
  }
  per_cell(st, c.cells);
  st.counters["bytes_per_cell"] = bytes / static_cast<double>(c.cells);
}

struct operators {
  block_sparse_matrix<double, nb> a;
  block_ilu<std::complex<double>, nb> ilu;
  vec<std::complex<double>> x, y;
};

const operators& hopf_operators(int stride) {
  static std::map<int, std::unique_ptr<operators>> ops;
  auto& o = ops[stride];
  if (!o) {
    const level_case& c = level(stride);
    const auto j = c.s.bordered_jacobians(c.w, mu);
    o = std::make_unique<operators>();
    o->a = j.exact.flow();
    block_ilu_options io;
    io.fill_level = 2;
    o->ilu = block_ilu<std::complex<double>, nb>(io);
    o->ilu.compute(shifted(j.preconditioning.flow(), std::complex<double>(0, omega)));
    o->x = vec<std::complex<double>>::Ones(o->a.cols());
    o->y.resize(o->a.rows());
  }
  return *o;
}

// The real Jacobian applied to a complex vector with the shift: (A - i omega I) x.
void bm_wing_shifted_product(benchmark::State& st) {
  const auto& o = hopf_operators(static_cast<int>(st.range(0)));
  vec<std::complex<double>> y(o.a.rows());
  for (auto _ : st) {
    o.a.apply_shifted(std::complex<double>(0, omega), o.x, y);
    benchmark::DoNotOptimize(y.data());
  }
  per_cell(st, level(static_cast<int>(st.range(0))).cells);
  const double bytes = matrix_bytes(o.a) + 2.0 * static_cast<double>(o.x.size()) * sizeof(std::complex<double>);
  st.counters["GBps"] = benchmark::Counter(bytes * st.iterations() * 1e-9, benchmark::Counter::kIsRate);
}

void bm_wing_bilu_apply(benchmark::State& st) {
  const auto& o = hopf_operators(static_cast<int>(st.range(0)));
  vec<std::complex<double>> z(o.x.size());
  for (auto _ : st) {
    o.ilu.apply(o.x, z);
    benchmark::DoNotOptimize(z.data());
  }
  const std::size_t cells = level(static_cast<int>(st.range(0))).cells;
  per_cell(st, cells);
  const double factor_bytes = static_cast<double>(o.ilu.nonzero_blocks()) * (nb * nb * sizeof(std::complex<double>) + sizeof(int));
  st.counters["bytes_per_cell"] = factor_bytes / static_cast<double>(cells);
  st.counters["GBps"] = benchmark::Counter(
      (factor_bytes + 2.0 * static_cast<double>(o.x.size()) * sizeof(std::complex<double>)) * st.iterations() * 1e-9,
      benchmark::Counter::kIsRate);
}

void bm_wing_bilu_factor(benchmark::State& st) {
  const level_case& c = level(static_cast<int>(st.range(0)));
  const auto j = c.s.bordered_jacobians(c.w, mu);
  const auto cc = shifted(j.preconditioning.flow(), std::complex<double>(0, omega));
  block_ilu_options io;
  io.fill_level = 2;
  block_ilu<std::complex<double>, nb> ilu(io);
  ilu.analyze(cc);
  for (auto _ : st) {
    ilu.factorize(cc);
    benchmark::DoNotOptimize(&ilu);
  }
  per_cell(st, c.cells);
}

void bm_wing_steady(benchmark::State& st) {
  const level_case& c = level(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    flow::euler_model<3> f = c.s.flow();
    vec<double> w = f.free_stream_vector();
    const auto rep = flow::solve_steady<3>(f, w, {});
    st.counters["steps"] = rep.steps;
    st.counters["gmres_iterations"] = rep.linear_iterations;
    st.counters["final_residual"] = rep.final_residual;
  }
  st.counters["cells"] = static_cast<double>(c.cells);
}

}  // namespace

BENCHMARK(bm_wing_residual)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_wing_jacobians)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_wing_shifted_product)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_wing_bilu_factor)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_wing_bilu_apply)->Arg(4)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(bm_wing_steady)->Arg(4)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(bm_wing_steady)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
