// Benchmark of the dedicated linear solver (spec 07): SpMV, BILU(k) phases, complete solves of
// CFD-like block systems in the complex (A - i omega I) and real 2n forms, against a STREAM
// triad measured in the same binary, Eigen's IncompleteLUT + BiCGSTAB / GMRES and (if CMake
// found it) PETSc SeqBAIJ ILU(k) + GMRES: in this build PETSc's real build on the real 2n form;
// in bench_linear_solver_petsc_complex (the same source, where Debian's complex build is
// installed: libpetsc-complex-dev) PETSc's complex build on the complex A - i omega I matrices
// themselves, the like-for-like peer of our complex form.
//
// WHY: the Hopf and centre-manifold solves are dominated by these linear solves; the kernels are
// memory-bound, so their bandwidth is compared with what the machine can stream at all.
//
// Benchmark names are  kind/matrix/block/scalar/method/fill/solver  (fields "-" when not
// applicable); bench/run_linear_solver.py turns the JSON output into out/bench/linear_solver.csv.
// Counters: krylov_iterations, setup_seconds, solve_seconds, preconditioner_blocks, bytes_per_second
// (minimal compulsory traffic: matrix values + indices + each vector once for SpMV; the BILU
// apply counts the four vector passes of its two sweeps, see ilu_apply_bytes).
// scalar "shifted_real": (A - i omega I) x with the real A on complex vectors (shifted_operator);
// solver "<krylov>_realA_<rtol>": complex BILU(k) of the assembled A - i omega I as preconditioner,
// the operator applied that way (the preconditioner needs the assembled matrix, the products not).
//
// Own flags (removed before Google Benchmark parses the rest):
//   --large               add the kernels on 1M-cell matrices (3D 100^3 b=5, 2D 1000^2 b=4;
//                         ~8 GB peak memory), for bandwidth far beyond the last-level cache
//   --all-peers           Eigen IncompleteLUT peers on every matrix (default: the 24^3 one only)
//   --write-mtx=DIR       write the generated matrices (A, real) as Matrix Market files
//                         DIR/<matrix>.mtx (scalar coordinate format, padded size) and exit
//   --load-mtx=FILE --mtx-block=B   also benchmark a Matrix Market matrix (real, square) with
//                         block size B (4 or 5); it is used as A (shift omega as for the others)
// Example: bench_linear_solver --benchmark_filter=spmv --benchmark_format=json
#include <benchmark/benchmark.h>

#include <aerohopf/linalg.hpp>
#include <unsupported/Eigen/IterativeSolvers>
#include <unsupported/Eigen/SparseExtra>

#include <chrono>
#include <cstring>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "cfd_jacobian.hpp"

#ifdef AEROHOPF_HAVE_PETSC
#include <petscksp.h>
#endif

using namespace aerohopf;
using cd = std::complex<double>;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct config {
  bool large = false;
  bool all_peers = false;  // Eigen IncompleteLUT peers on every matrix (slow)
  std::string write_mtx, load_mtx;
  int mtx_block = 5;
} cfg;

constexpr double omega_default = 0.5;  // shift of A - i omega I (cells have unit size, c = 1)
constexpr int max_krylov_iterations = 400;  // a solve that needs more counts as not converged

// ---- problems: generated once, kept while consecutive benchmarks use them ---------------------
template <int B>
struct problem {
  std::string name;
  std::vector<int> grid_block;  // for coupling filters
  block_sparse_matrix<double, B> a;
  std::unique_ptr<block_sparse_matrix<cd, B>> c;        // A - i omega I
  std::unique_ptr<block_sparse_matrix<double, B>> r2n;  // real 2n, interleaved
  const block_sparse_matrix<cd, B>& complex_form() {
    if (!c) c = std::make_unique<block_sparse_matrix<cd, B>>(shifted(a, cd(0, omega_default)));
    return *c;
  }
  const block_sparse_matrix<double, B>& real_form() {
    if (!r2n)
      r2n = std::make_unique<block_sparse_matrix<double, B>>(
          real_shifted_form(a, omega_default, real_form_ordering::interleaved));
    return *r2n;
  }
};

template <int B>
std::unique_ptr<problem<B>>& slot() {
  static std::unique_ptr<problem<B>> p;
  return p;
}

template <int B>
problem<B>& get_problem(const bench::cfd_grid& g) {
  auto& p = slot<B>();
  if (!p || p->name != g.name()) {
    p.reset();  // free the previous one first (large cases)
    p = std::make_unique<problem<B>>();
    p->name = g.name();
    p->a = bench::cfd_jacobian<B>(g);
    p->grid_block = bench::grid_blocks(g);
  }
  return *p;
}

template <int B>
problem<B>& get_loaded_problem() {
  auto& p = slot<B>();
  const std::string name = "mtx_" + cfg.load_mtx.substr(cfg.load_mtx.find_last_of('/') + 1);
  if (!p || p->name != name) {
    p.reset();
    Eigen::SparseMatrix<double> s;
    require(Eigen::loadMarket(s, cfg.load_mtx), "cannot read Matrix Market file ", cfg.load_mtx);
    p = std::make_unique<problem<B>>();
    p->name = name;
    p->a = block_sparse_matrix<double, B>::from_sparse(s);
    p->grid_block.assign(p->a.block_rows(), 0);
  }
  return *p;
}

template <class M>
double spmv_bytes(const M& a) {
  using S = typename M::scalar_type;
  return double(a.nonzero_blocks()) * (a.block_entries() * sizeof(S) + sizeof(int)) +
         double(a.block_rows() + 1) * sizeof(int) + 2.0 * a.rows() * sizeof(S);
}

// BILU apply: factor values + column indices + row pointers/diagonal positions, and four vector
// passes: r read and y written by the forward sweep, y read and written again by the backward
// sweep (on the out-of-cache matrices the vector is evicted by the factor stream in between).
template <class S, int B>
double ilu_apply_bytes(const block_ilu<S, B>& m) {
  return double(m.factor_bytes()) + double(m.nonzero_blocks()) * sizeof(int) +
         double(m.block_rows()) * 2 * sizeof(int) + 4.0 * m.rows() * sizeof(S);
}

std::string nm(std::initializer_list<std::string> parts) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : "/") + p;
  return s;
}

// ---- STREAM triad ------------------------------------------------------------------------------
void stream_triad(benchmark::State& state, std::size_t n) {
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const double s = 3.0;
  for (auto _ : state) {
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + s * pc[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.counters["bytes_per_second"] = benchmark::Counter(3.0 * n * sizeof(double), benchmark::Counter::kIsIterationInvariantRate);
}

// The machine's bandwidth drifts by tens of percent within minutes here (a shared host), so
// every kernel benchmark also measures a STREAM triad right after its own timing loop: out of
// cache (3 x 160 MB) for kernels moving more than 24 MB, in cache (3 x 4 MB) below; the best of
// five triads is reported as stream_bytes_per_second (run_linear_solver.py forms the ratio).
double triad_now(std::size_t n) {
  static std::vector<double> a, b, c;
  if (a.size() != n) {
    a.assign(n, 0.0);
    b.assign(n, 1.0);
    c.assign(n, 2.0);
  }
  double best = 1e300;
  for (int rep = 0; rep < 6; ++rep) {
    const double t0 = now();
    double* __restrict pa = a.data();
    const double* __restrict pb = b.data();
    const double* __restrict pc = c.data();
    for (std::size_t i = 0; i < n; ++i) pa[i] = pb[i] + 3.0 * pc[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
    if (rep > 0) best = std::min(best, now() - t0);  // the first pass warms up
  }
  return 3.0 * n * sizeof(double) / best;
}

void add_stream_reference(benchmark::State& state, double kernel_bytes) {
  state.counters["stream_bytes_per_second"] = triad_now(kernel_bytes > 24e6 ? 20'000'000 : 500'000);
}

// ---- SpMV --------------------------------------------------------------------------------------
template <int B, class S>
void bench_spmv(benchmark::State& state, std::function<problem<B>&()> get) {
  auto& p = get();
  const block_sparse_matrix<S, B>* m;
  if constexpr (std::is_same_v<S, double>) m = &p.a;
  else m = &p.complex_form();
  vec<S> x = vec<S>::Ones(m->cols()), y(m->rows());
  m->apply(x, y);  // warm-up: first touch of y, page tables
  for (auto _ : state) {
    m->apply(x, y);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["bytes_per_second"] = benchmark::Counter(spmv_bytes(*m), benchmark::Counter::kIsIterationInvariantRate);
  add_stream_reference(state, spmv_bytes(*m));
}

// (A - i omega I) x with the real A on complex vectors (shifted_operator): the real matrix once,
// the complex x and y once each.
template <int B>
void bench_spmv_shifted_real(benchmark::State& state, std::function<problem<B>&()> get) {
  auto& p = get();
  const shifted_operator<block_sparse_matrix<double, B>, cd> op(p.a, cd(0, omega_default));
  vec<cd> x = vec<cd>::Ones(p.a.cols()), y(p.a.rows());
  op.apply(x, y);  // warm-up
  for (auto _ : state) {
    op.apply(x, y);
    benchmark::DoNotOptimize(y.data());
  }
  const double bytes = spmv_bytes(p.a) + 2.0 * p.a.rows() * sizeof(double);  // vectors complex
  state.counters["bytes_per_second"] = benchmark::Counter(bytes, benchmark::Counter::kIsIterationInvariantRate);
  add_stream_reference(state, bytes);
}

// ---- BILU phases -------------------------------------------------------------------------------
enum class form { real, complex, real2n };
const char* form_name(form f) { return f == form::real ? "real" : f == form::complex ? "complex" : "real2n_interleaved"; }
/// The form's name with "_f32" where the BILU factors are kept in single precision
/// (block_ilu_options::single_precision_factors).
std::string form_name(form f, bool single) { return std::string(form_name(f)) + (single ? "_f32" : ""); }

template <int B, class S>
const block_sparse_matrix<S, B>& pick(problem<B>& p, form f) {
  if constexpr (std::is_same_v<S, cd>) return p.complex_form();
  else return f == form::real2n ? p.real_form() : p.a;
}

template <int B>
coupling_filter filter_for(problem<B>& p, int method, form f) {
  auto filt = coupling_filter::for_method(method, p.grid_block);
  return f == form::real2n ? filt.for_real_form(real_form_ordering::interleaved) : filt;
}

// phase: 0 symbolic, 1 numeric, 2 apply
template <int B, class S>
void bench_ilu(benchmark::State& state, std::function<problem<B>&()> get, form f, int method, int fill, int phase,
               bool single = false) {
  auto& p = get();
  const auto& m = pick<B, S>(p, f);
  block_ilu_options o;
  o.fill_level = fill;
  o.single_precision_factors = single;
  o.filter = filter_for(p, method, f);
  block_ilu<S, B> ilu(o);
  if (phase == 0) {
    for (auto _ : state) ilu.analyze(m);
  } else {
    ilu.analyze(m);
    if (phase == 1) {
      for (auto _ : state) ilu.factorize(m);
    } else {
      ilu.factorize(m);
      vec<S> r = vec<S>::Ones(m.rows()), z(m.rows());
      ilu.apply(r, z);  // warm-up
      for (auto _ : state) {
        ilu.apply(r, z);
        benchmark::DoNotOptimize(z.data());
      }
      state.counters["bytes_per_second"] =
          benchmark::Counter(ilu_apply_bytes(ilu), benchmark::Counter::kIsIterationInvariantRate);
      add_stream_reference(state, ilu_apply_bytes(ilu));
    }
  }
  state.counters["preconditioner_blocks"] = double(ilu.nonzero_blocks());
}

// ---- complete solves ---------------------------------------------------------------------------
// real_operator: the Krylov method applies A - i omega I as the real A on complex vectors
// (shifted_operator, one fused pass over the real matrix) instead of the assembled complex matrix;
// the preconditioner is the same complex BILU(k) of the assembled matrix.
template <int B, class S>
void bench_solve(benchmark::State& state, std::function<problem<B>&()> get, form f, int method, int fill,
                 krylov_method km, double rtol, bool real_operator = false, bool single = false) {
  auto& p = get();
  const auto& m = pick<B, S>(p, f);
  // right-hand side: a smooth complex field (the same for both forms)
  vec<cd> bc(p.a.rows());
  for (Eigen::Index i = 0; i < bc.size(); ++i) bc(i) = cd(std::sin(0.001 * i) + 1.0, std::cos(0.0007 * i));
  vec<S> b;
  if constexpr (std::is_same_v<S, cd>) b = bc;
  else if (f == form::real2n) b = real_form_vector(bc, B, real_form_ordering::interleaved);
  else b = bc.real();
  for (auto _ : state) {
    const double t0 = now();
    block_ilu_options o;
    o.fill_level = fill;
    o.filter = filter_for(p, method, f);
    o.single_precision_factors = single;
    block_ilu<S, B> ilu(o);
    krylov_report rep;
    double t1 = t0;
    try {
      ilu.compute(m);
      t1 = now();
      krylov_options ko;
      ko.relative_tolerance = rtol;
      ko.restart = 60;
      ko.max_iterations = max_krylov_iterations;
      vec<S> x;
      if constexpr (std::is_same_v<S, cd>) {
        if (real_operator)
          rep = krylov_solve(km, shifted_operator<block_sparse_matrix<double, B>, cd>(p.a, cd(0, omega_default)), ilu, b,
                             x, ko);
        else rep = krylov_solve(km, m, ilu, b, x, ko);
      } else {
        rep = krylov_solve(km, m, ilu, b, x, ko);
      }
    } catch (const error& e) {
      state.SkipWithError(e.what());
      return;
    }
    const double t2 = now();
    state.SetIterationTime(t2 - t0);
    state.counters["krylov_iterations"] = rep.iterations;
    state.counters["operator_applications"] = rep.operator_applications;
    state.counters["setup_seconds"] = t1 - t0;
    state.counters["solve_seconds"] = t2 - t1;
    state.counters["preconditioner_blocks"] = double(ilu.nonzero_blocks());
    state.counters["relative_residual"] = rep.relative_residual;
    state.counters["converged"] = rep.converged ? 1 : 0;
  }
}

// ---- Eigen side by side ------------------------------------------------------------------------
template <int B, class S>
void bench_eigen(benchmark::State& state, std::function<problem<B>&()> get, form f, bool use_gmres, double rtol) {
  auto& p = get();
  const auto& m = pick<B, S>(p, f);
  const Eigen::SparseMatrix<S, Eigen::RowMajor> s = m.to_sparse(true);
  vec<cd> bc(p.a.rows());
  for (Eigen::Index i = 0; i < bc.size(); ++i) bc(i) = cd(std::sin(0.001 * i) + 1.0, std::cos(0.0007 * i));
  vec<S> b;
  if constexpr (std::is_same_v<S, cd>) b = bc;
  else if (f == form::real2n) b = real_form_vector(bc, B, real_form_ordering::interleaved);
  else b = bc.real();
  for (auto _ : state) {
    const double t0 = now();
    double t1 = t0;
    vec<S> x;
    int its = 0;
    double nnz = 0;
    if (use_gmres) {
      Eigen::GMRES<Eigen::SparseMatrix<S, Eigen::RowMajor>, Eigen::IncompleteLUT<S>> solver;
      solver.preconditioner().setDroptol(1e-3);
      solver.preconditioner().setFillfactor(5);
      solver.set_restart(60);
      solver.setTolerance(rtol);
      solver.setMaxIterations(max_krylov_iterations);
      solver.compute(s);
      t1 = now();
      x = solver.solve(b);
      its = int(solver.iterations());
    } else {
      Eigen::BiCGSTAB<Eigen::SparseMatrix<S, Eigen::RowMajor>, Eigen::IncompleteLUT<S>> solver;
      solver.preconditioner().setDroptol(1e-3);
      solver.preconditioner().setFillfactor(5);
      solver.setTolerance(rtol);
      solver.setMaxIterations(max_krylov_iterations);
      solver.compute(s);
      t1 = now();
      x = solver.solve(b);
      its = int(solver.iterations());
    }
    const double t2 = now();
    (void)nnz;
    state.SetIterationTime(t2 - t0);
    const double res = double((b - s * x).norm() / b.norm());
    state.counters["krylov_iterations"] = its;
    state.counters["setup_seconds"] = t1 - t0;
    state.counters["solve_seconds"] = t2 - t1;
    state.counters["relative_residual"] = res;
    state.counters["converged"] = res <= rtol * 1.0001 ? 1 : 0;
  }
}

#ifdef AEROHOPF_HAVE_PETSC
// The scalar of the PETSc build linked: complex (Debian's libpetsc-complex-dev, the target
// bench_linear_solver_petsc_complex) solves A - i omega I itself, the matrices of our complex
// form; real solves the real 2n form.
#if defined(PETSC_USE_COMPLEX)
using petsc_value = cd;
constexpr form petsc_form = form::complex;
#else
using petsc_value = double;
constexpr form petsc_form = form::real2n;
#endif
static_assert(sizeof(PetscScalar) == sizeof(petsc_value), "PETSc's scalar is not the expected one");

// PETSc SeqBAIJ (block size B) ILU(k) + right-preconditioned GMRES(60), unpreconditioned norm.
template <int B>
void bench_petsc(benchmark::State& state, std::function<problem<B>&()> get, form f, int fill, double rtol) {
  auto& p = get();
  const auto& m = pick<B, petsc_value>(p, f);
  vec<cd> bc(p.a.rows());
  for (Eigen::Index i = 0; i < bc.size(); ++i) bc(i) = cd(std::sin(0.001 * i) + 1.0, std::cos(0.0007 * i));
  vec<petsc_value> b;
  if constexpr (std::is_same_v<petsc_value, cd>) b = bc;
  else b = f == form::real2n ? real_form_vector(bc, B, real_form_ordering::interleaved) : vec<double>(bc.real());
  // the same layout (std::complex<double> is two doubles, as PETSc's complex scalar)
  auto petsc = [](const petsc_value* x) { return reinterpret_cast<const PetscScalar*>(x); };
  for (auto _ : state) {
    // The conversion to PETSc's own matrix (SeqBAIJ assembly) is timed separately
    // (assembly_seconds) and NOT counted in setup or total: only PETSc's solver is compared.
    const double ta = now();
    const PetscInt nb = m.block_rows();
    std::vector<PetscInt> nnz(nb);
    for (PetscInt i = 0; i < nb; ++i) nnz[i] = m.row_ptr()[i + 1] - m.row_ptr()[i];
    Mat a;
    MatCreateSeqBAIJ(PETSC_COMM_SELF, B, nb * B, nb * B, 0, nnz.data(), &a);
    MatSetOption(a, MAT_ROW_ORIENTED, PETSC_FALSE);  // our blocks are column-major, contiguous per row
    std::vector<PetscInt> cols;
    for (PetscInt i = 0; i < nb; ++i) {
      cols.assign(m.col_index().begin() + m.row_ptr()[i], m.col_index().begin() + m.row_ptr()[i + 1]);
      MatSetValuesBlocked(a, 1, &i, PetscInt(cols.size()), cols.data(),
                          petsc(m.values().data() + std::size_t(m.row_ptr()[i]) * B * B), INSERT_VALUES);
    }
    MatAssemblyBegin(a, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(a, MAT_FINAL_ASSEMBLY);
    Vec pb, px;
    VecCreateSeq(PETSC_COMM_SELF, nb * B, &pb);
    VecDuplicate(pb, &px);
    PetscScalar* pv;
    VecGetArray(pb, &pv);
    std::copy(petsc(b.data()), petsc(b.data()) + b.size(), pv);
    VecRestoreArray(pb, &pv);
    const double t0 = now();
    KSP ksp;
    PC pc;
    KSPCreate(PETSC_COMM_SELF, &ksp);
    KSPSetOperators(ksp, a, a);
    KSPSetType(ksp, KSPGMRES);
    KSPGMRESSetRestart(ksp, 60);
    KSPSetPCSide(ksp, PC_RIGHT);
    KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED);
    KSPSetTolerances(ksp, rtol, 1e-300, 1e10, max_krylov_iterations);
    KSPGetPC(ksp, &pc);
    PCSetType(pc, PCILU);
    PCFactorSetLevels(pc, fill);
    KSPSetUp(ksp);
    const double t1 = now();
    KSPSolve(ksp, pb, px);
    const double t2 = now();
    PetscInt its;
    KSPGetIterationNumber(ksp, &its);
    KSPConvergedReason reason;
    KSPGetConvergedReason(ksp, &reason);
    Mat fact;
    PCFactorGetMatrix(pc, &fact);
    MatInfo info;
    MatGetInfo(fact, MAT_LOCAL, &info);
    // true residual
    Vec r;
    VecDuplicate(pb, &r);
    MatMult(a, px, r);
    VecAYPX(r, -1.0, pb);
    PetscReal rn, bn;
    VecNorm(r, NORM_2, &rn);
    VecNorm(pb, NORM_2, &bn);
    state.SetIterationTime(t2 - t0);
    state.counters["krylov_iterations"] = double(its);
    state.counters["setup_seconds"] = t1 - t0;
    state.counters["solve_seconds"] = t2 - t1;
    state.counters["assembly_seconds"] = t0 - ta;
    state.counters["preconditioner_blocks"] = info.nz_used / double(B * B);
    state.counters["relative_residual"] = rn / bn;
    state.counters["converged"] = reason > 0 ? 1 : 0;
    VecDestroy(&r);
    VecDestroy(&pb);
    VecDestroy(&px);
    KSPDestroy(&ksp);
    MatDestroy(&a);
  }
}
#endif

// ---- registration ------------------------------------------------------------------------------
const char* solver_name(krylov_method k) {
  switch (k) {
    case krylov_method::gcr: return "gcr60";
    case krylov_method::tfqmr: return "tfqmr";
    case krylov_method::bicgstab: return "bicgstab";
    default: return "gmres60";
  }
}
std::string tol_name(double t) { return t >= 1e-2 ? "rtol1e-2" : "rtol1e-8"; }

template <int B>
void register_matrix_kernels(const std::string& mname, std::function<problem<B>&()> get, bool ilu_phases) {
  const std::string bs = std::to_string(B);
  benchmark::RegisterBenchmark(nm({"spmv", mname, bs, "real", "-", "-", "spmv"}).c_str(),
                               [get](benchmark::State& s) { bench_spmv<B, double>(s, get); })->Unit(benchmark::kMillisecond)->MinTime(0.3);
  benchmark::RegisterBenchmark(nm({"spmv", mname, bs, "complex", "-", "-", "spmv"}).c_str(),
                               [get](benchmark::State& s) { bench_spmv<B, cd>(s, get); })->Unit(benchmark::kMillisecond)->MinTime(0.3);
  benchmark::RegisterBenchmark(nm({"spmv", mname, bs, "shifted_real", "-", "-", "spmv"}).c_str(),
                               [get](benchmark::State& s) { bench_spmv_shifted_real<B>(s, get); })
      ->Unit(benchmark::kMillisecond)
      ->MinTime(0.3);
  for (int k = 0; k <= (ilu_phases ? 3 : 0); ++k) {
    for (form f : {form::real, form::complex}) {
      for (int phase = (ilu_phases ? 0 : 2); phase <= 2; ++phase) {
        const char* ph = phase == 0 ? "bilu_symbolic" : phase == 1 ? "bilu_numeric" : "bilu_apply";
        auto fn = [get, f, k, phase](benchmark::State& s) {
          if (f == form::complex) bench_ilu<B, cd>(s, get, f, 1, k, phase);
          else bench_ilu<B, double>(s, get, f, 1, k, phase);
        };
        benchmark::RegisterBenchmark(nm({"ilu", mname, bs, form_name(f), "1", std::to_string(k), ph}).c_str(), fn)
            ->Unit(benchmark::kMillisecond)
            ->MinTime(phase == 2 ? 0.3 : 0.1);
      }
      // the same apply with the factors in single precision (half the factor bytes)
      auto fs = [get, f, k](benchmark::State& s) {
        if (f == form::complex) bench_ilu<B, cd>(s, get, f, 1, k, 2, true);
        else bench_ilu<B, double>(s, get, f, 1, k, 2, true);
      };
      benchmark::RegisterBenchmark(nm({"ilu", mname, bs, form_name(f, true), "1", std::to_string(k), "bilu_apply"}).c_str(),
                                   fs)
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.3);
    }
  }
}

// preconditioner storage (symbolic phase only) per method, form and fill level: spec 08's table
template <int B>
void register_storage(const std::string& mname, std::function<problem<B>&()> get, int max_fill,
                      std::vector<form> forms) {
  const std::string bs = std::to_string(B);
  for (form f : forms)
    for (int method = 1; method <= 3; ++method)
      for (int k = 0; k <= max_fill; ++k) {
        auto fn = [get, f, method, k](benchmark::State& s) {
          if (f == form::complex) bench_ilu<B, cd>(s, get, f, method, k, 0);
          else bench_ilu<B, double>(s, get, f, method, k, 0);
        };
        benchmark::RegisterBenchmark(
            nm({"storage", mname, bs, form_name(f), std::to_string(method), std::to_string(k), "bilu_symbolic"}).c_str(), fn)
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1);
      }
}

template <int B>
void register_solve(const std::string& mname, std::function<problem<B>&()> get, form f, int method, int k,
                    krylov_method km, double tol, bool real_operator = false, bool single = false) {
  auto fn = [=](benchmark::State& s) {
    if (f == form::complex) bench_solve<B, cd>(s, get, f, method, k, km, tol, real_operator, single);
    else bench_solve<B, double>(s, get, f, method, k, km, tol, false, single);
  };
  benchmark::RegisterBenchmark(nm({"solve", mname, std::to_string(B), form_name(f, single), std::to_string(method),
                                   std::to_string(k),
                                   std::string(solver_name(km)) + (real_operator ? "_realA_" : "_") + tol_name(tol)})
                                   .c_str(),
                               fn)
      ->Unit(benchmark::kMillisecond)
      ->UseManualTime()
      ->Iterations(1);
}

template <int B>
void register_peers(const std::string& mname, std::function<problem<B>&()> get, std::vector<form> forms, double tol,
                    std::vector<int> petsc_fills, bool with_eigen = false) {
  const std::string bs = std::to_string(B);
  for (form f : forms) {
    // Eigen's IncompleteLUT setup takes 20-90 s at 70k-140k unknowns: only where asked
    if (with_eigen || cfg.all_peers)
      for (bool g : {false, true}) {
      auto fn = [=](benchmark::State& s) {
        if (f == form::complex) bench_eigen<B, cd>(s, get, f, g, tol);
        else bench_eigen<B, double>(s, get, f, g, tol);
      };
      benchmark::RegisterBenchmark(nm({"solve", mname, bs, form_name(f), "1", "ilut",
                                       std::string(g ? "eigen_ilut_gmres60_" : "eigen_ilut_bicgstab_") + tol_name(tol)})
                                       .c_str(),
                                   fn)
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime()
          ->Iterations(1);
    }
#ifdef AEROHOPF_HAVE_PETSC
    if (f == petsc_form)
      for (int k : petsc_fills)
        benchmark::RegisterBenchmark(nm({"solve", mname, bs, form_name(f), "1", std::to_string(k),
                                         "petsc_baij_ilu_gmres60_" + tol_name(tol)})
                                         .c_str(),
                                     [=](benchmark::State& s) { bench_petsc<B>(s, get, f, k, tol); })
            ->Unit(benchmark::kMillisecond)
            ->UseManualTime()
            ->Iterations(1);
#else
    (void)petsc_fills;
#endif
  }
}

template <int B>
std::function<problem<B>&()> grid_getter(bench::cfd_grid g) {
  return [g]() -> problem<B>& { return get_problem<B>(g); };
}

void register_all() {
  // STREAM triad: out of cache (3 x 160 MB) and in the last-level cache (3 x 4 MB)
  benchmark::RegisterBenchmark("stream/triad_160MB/-/real/-/-/stream_triad",
                               [](benchmark::State& s) { stream_triad(s, 20'000'000); })->Unit(benchmark::kMillisecond)->MinTime(0.5);
  benchmark::RegisterBenchmark("stream/triad_4MB/-/real/-/-/stream_triad",
                               [](benchmark::State& s) { stream_triad(s, 500'000); })->Unit(benchmark::kMicrosecond)->MinTime(0.3);

  // in-cache kernels (matrix fits the 32 MB L3): 2D 48^2 b=4 and 3D 16^3 b=5
  bench::cfd_grid g2s{48, 48, 1};
  bench::cfd_grid g3s{16, 16, 16};
  register_matrix_kernels<4>(g2s.name(), grid_getter<4>(g2s), false);
  register_matrix_kernels<5>(g3s.name(), grid_getter<5>(g3s), false);
  // out of cache (~200-400 MB): 2D 512^2 b=4 and 3D 64^3 b=5
  bench::cfd_grid g2m{512, 512, 1};
  bench::cfd_grid g3m{64, 64, 64};
  register_matrix_kernels<4>(g2m.name(), grid_getter<4>(g2m), false);
  register_matrix_kernels<5>(g3m.name(), grid_getter<5>(g3m), false);

  // AGARD-sized 3D case (24^3 = 13,824 cells, b = 5): all BILU phases, storage table, solves
  bench::cfd_grid ga{24, 24, 24};
  ga.blocks_per_direction = 2;
  auto geta = grid_getter<5>(ga);
  register_matrix_kernels<5>(ga.name(), geta, true);
  register_storage<5>(ga.name(), geta, 3, {form::complex, form::real2n});
  for (double tol : {1e-2, 1e-8})
    for (form f : {form::complex, form::real2n})
      for (int k = 0; k <= 2; ++k)
        for (auto km : {krylov_method::gmres, krylov_method::gcr, krylov_method::tfqmr, krylov_method::bicgstab})
          register_solve<5>(ga.name(), geta, f, 1, k, km, tol);
  for (double tol : {1e-2, 1e-8})
    for (int k = 0; k <= 1; ++k)
      for (auto km : {krylov_method::gmres, krylov_method::gcr, krylov_method::tfqmr, krylov_method::bicgstab})
        register_solve<5>(ga.name(), geta, form::complex, 1, k, km, tol, true);
  for (int method = 2; method <= 3; ++method)
    register_solve<5>(ga.name(), geta, form::complex, method, 1, krylov_method::gmres, 1e-8);
  // the Hopf solves' configuration with single-precision factors (beside the double ones above)
  for (double tol : {1e-2, 1e-8})
    for (int k = 0; k <= 2; ++k)
      register_solve<5>(ga.name(), geta, form::complex, 1, k, krylov_method::gmres, tol, true, true);
  register_peers<5>(ga.name(), geta, {form::complex, form::real2n}, 1e-8, {0, 1, 2}, true);
  register_peers<5>(ga.name(), geta, {form::real2n}, 1e-2, {0, 1});

  // second-order (13-point) Jacobian of the same grid: storage at BILU(3) and solves
  bench::cfd_grid ga2 = ga;
  ga2.second_order = true;
  auto geta2 = grid_getter<5>(ga2);
  register_storage<5>(ga2.name(), geta2, 3, {form::complex});
  // solves with the second-order Jacobian on 16^3 (BILU(3) of the 13-point stencil is costly)
  bench::cfd_grid gs2{16, 16, 16};
  gs2.second_order = true;
  auto gets2 = grid_getter<5>(gs2);
  for (int k = 0; k <= 3; ++k) register_solve<5>(gs2.name(), gets2, form::complex, 1, k, krylov_method::gmres, 1e-8);
  for (int method = 2; method <= 3; ++method)
    register_solve<5>(gs2.name(), gets2, form::complex, method, 3, krylov_method::gmres, 1e-8);
  for (int k = 0; k <= 1; ++k) register_solve<5>(gs2.name(), gets2, form::real2n, 1, k, krylov_method::gmres, 1e-8);
  register_peers<5>(gs2.name(), gets2, {form::complex, form::real2n}, 1e-8, {0, 1});

  // 2D b = 4 (128^2): complex and real forms, all four Krylov methods
  bench::cfd_grid g2{128, 128, 1};
  auto get2 = grid_getter<4>(g2);
  for (form f : {form::complex, form::real2n})
    for (int k = 0; k <= 1; ++k)
      for (auto km : {krylov_method::gmres, krylov_method::gcr, krylov_method::tfqmr, krylov_method::bicgstab})
        if (km == krylov_method::gmres || f == form::complex || k > 0)  // real BILU(0) does not converge (5-8 s)
          register_solve<4>(g2.name(), get2, f, 1, k, km, 1e-8);
  for (int k = 0; k <= 1; ++k)
    for (auto km : {krylov_method::gmres, krylov_method::gcr, krylov_method::tfqmr, krylov_method::bicgstab})
      register_solve<4>(g2.name(), get2, form::complex, 1, k, km, 1e-8, true);
  register_peers<4>(g2.name(), get2, {form::complex, form::real2n}, 1e-8, {0, 1});

  if (!cfg.load_mtx.empty()) {
    auto run = [&]<int B>() {
      std::function<problem<B>&()> get = [] () -> problem<B>& { return get_loaded_problem<B>(); };
      const std::string name = "mtx";
      register_matrix_kernels<B>(name, get, true);
      for (form f : {form::complex, form::real2n})
        for (int k = 0; k <= 2; ++k) register_solve<B>(name, get, f, 1, k, krylov_method::gmres, 1e-8);
      register_peers<B>(name, get, {form::complex, form::real2n}, 1e-8, {0, 1});
    };
    if (cfg.mtx_block == 4) run.template operator()<4>();
    else run.template operator()<5>();
  }

  if (cfg.large) {
    // 1M cells, far beyond the 32 MB L3: 3D 100^3 b=5 (A: 1.4 GB real) and 2D 1000^2 b=4
    bench::cfd_grid g3l{100, 100, 100};
    g3l.blocks_per_direction = 4;
    register_matrix_kernels<5>(g3l.name(), grid_getter<5>(g3l), false);
    bench::cfd_grid g2l{1000, 1000, 1};
    g2l.blocks_per_direction = 4;
    register_matrix_kernels<4>(g2l.name(), grid_getter<4>(g2l), false);
  }
}

int write_mtx() {
  for (auto g : {bench::cfd_grid{48, 48, 1}, bench::cfd_grid{128, 128, 1}}) {
    const auto a = bench::cfd_jacobian<4>(g);
    Eigen::saveMarket(a.to_sparse(true), cfg.write_mtx + "/" + g.name() + ".mtx");
  }
  bench::cfd_grid g3{24, 24, 24};
  for (bool o2 : {false, true}) {
    g3.second_order = o2;
    const auto a = bench::cfd_jacobian<5>(g3);
    Eigen::saveMarket(a.to_sparse(true), cfg.write_mtx + "/" + g3.name() + ".mtx");
  }
  std::cout << "wrote Matrix Market files to " << cfg.write_mtx << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--large") cfg.large = true;
    else if (a == "--all-peers") cfg.all_peers = true;
    else if (a.rfind("--write-mtx=", 0) == 0) cfg.write_mtx = a.substr(12);
    else if (a.rfind("--load-mtx=", 0) == 0) cfg.load_mtx = a.substr(11);
    else if (a.rfind("--mtx-block=", 0) == 0) cfg.mtx_block = std::stoi(a.substr(12));
    else rest.push_back(argv[i]);
  }
  if (!cfg.write_mtx.empty()) return write_mtx();
  int rc = static_cast<int>(rest.size());
#ifdef AEROHOPF_HAVE_PETSC
  int pargc = 1;
  char** pargv = argv;
  PetscInitialize(&pargc, &pargv, nullptr, nullptr);
#endif
  benchmark::Initialize(&rc, rest.data());
  // The kernels' compile-time prefetch tuning (linalg/block_kernels.hpp), so every result file
  // says which one it measured.
#ifdef AEROHOPF_AMD_TUNING
  const char* vendor = "amd";
#else
  const char* vendor = "default";
#endif
  benchmark::AddCustomContext("aerohopf_prefetch",
                              "tuning=" + std::string(vendor) + " locality=" + std::to_string(AEROHOPF_PREFETCH_LOCALITY) +
                                  " distance=" + std::to_string(aerohopf::internal::prefetch_distance_bytes) +
                                  " spmv_distance=" + std::to_string(aerohopf::internal::spmv_prefetch_distance_bytes<double>) +
                                  " complex_spmv_distance=" +
                                  std::to_string(aerohopf::internal::spmv_prefetch_distance_bytes<std::complex<double>>));
  register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
#ifdef AEROHOPF_HAVE_PETSC
  PetscFinalize();
#endif
  return 0;
}
