#!/usr/bin/env python3
"""Projection of the distributed steady solve to 64 .. 1024 ranks from measured per-rank costs.

Usage: mpi_projection.py ONE_RANK.csv TWO_RANKS.csv STEADY.csv
  ONE_RANK.csv, TWO_RANKS.csv: the output of `mpirun -np 1 mpi_scaling 2` and `-np 2` (per-cell
  costs and memory); STEADY.csv: a run with steady = 1 (`mpirun -np 2 mpi_scaling 2 100 <mach> 1`),
  whose steps and GMRES iterations per step are used.

Model (the assumptions printed with the table):
  - compute per rank scales with its cells n = N / P at the per-cell costs measured on one rank
    (residual, two Jacobians, BILU(0)) and, for a GMRES iteration, the larger of the kernel
    solve's and the steady solve's (its time less its evaluations, per iteration and cell);
  - halo: a rank of n cells in a 3D decomposition receives 2 layers on up to 6 faces, 12 n^(2/3)
    cells, 40 bytes each per exchange (5 doubles), one exchange per product; cost
    latency + bytes / bandwidth;
  - reductions: 3 all-reduces per GMRES iteration (classical Gram-Schmidt with its second pass,
    and the norm), each latency * log2(P);
  - GMRES iterations grow with the number of subdomains as P^(1/6) from the measured count at
    two ranks, up to the steady solver's limit of 200 per step (block Jacobi without overlap; measured here: 4 -> 5 at CFL 100 from 1 to 2
    ranks, 13 -> 14 at CFL 10^4 from 1 to 4);
  - steady steps and GMRES iterations per step as measured (STEADY.csv);
  - memory: the replicated part (grid, metrics, two full-length vectors) per cell of the whole
    grid and the owned part per owned cell, both fitted to the 1- and 2-rank peak RSS.
"""
import csv
import math
import sys

LATENCY = 2e-6          # s, point-to-point and per all-reduce stage
BANDWIDTH = 10e9        # bytes/s per rank (InfiniBand HDR shared by a node's ranks, conservative)
REDUCTIONS_PER_ITERATION = 3
MAX_ITERATIONS = 200    # the steady solver's krylov.max_iterations: GMRES stops there


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: float(v) for k, v in rows[-1].items()}


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    one, two, steady = read(sys.argv[1]), read(sys.argv[2]), read(sys.argv[3])
    n1 = one["cells"]
    per_cell = {
        "residual": one["residual_s"] / n1,
        "jacobian": one["jacobian_s"] / n1,
        "bilu": one["bilu_s"] / n1,
        "gmres_it": one["gmres_s"] / max(one["gmres_iterations"], 1) / n1,
    }
    steps = steady["steady_steps"]
    its_per_step = steady["steady_gmres_iterations"] / steps
    # a GMRES iteration inside the steady solve (Krylov bases up to the restart length: more
    # orthogonalisation than the short kernel solve): the solve's time less its evaluations
    n_s = steady["cells_per_rank_max"]
    evaluations = steps * (steady["residual_s"] + 2 * steady["jacobian_s"] + steady["bilu_s"])
    in_solve = (steady["steady_s"] - evaluations) / steady["steady_gmres_iterations"] / n_s
    kernel_it = per_cell["gmres_it"]
    per_cell["gmres_it"] = max(kernel_it, in_solve)
    # memory: rss = R * N + O * n  (N whole grid, n owned)
    owned = (one["peak_rss_mb_max"] - two["peak_rss_mb_max"]) / (n1 - two["cells_per_rank_max"])
    replicated = (one["peak_rss_mb_max"] - owned * n1) / n1
    print(f"measured per cell (1 rank): residual {per_cell['residual'] * 1e6:.2f} us, Jacobian rows "
          f"{per_cell['jacobian'] * 1e6:.2f} us, BILU(0) {per_cell['bilu'] * 1e6:.2f} us, GMRES iteration "
          f"{kernel_it * 1e6:.3f} us (kernel) / {in_solve * 1e6:.3f} us (in the steady solve; the larger used); steady: {steps:.0f} steps, {its_per_step:.1f} GMRES iterations "
          f"per step; memory {owned * 1e3:.2f} kB per owned cell + {replicated * 1e3:.3f} kB per grid cell")
    print(f"assumed: latency {LATENCY * 1e6:.0f} us, bandwidth {BANDWIDTH / 1e9:.0f} GB/s per rank, "
          f"{REDUCTIONS_PER_ITERATION} all-reduces per GMRES iteration, iterations x (P/2)^(1/6) up to {MAX_ITERATIONS}")
    print()
    print("| grid | ranks | cells/rank | ghost cells/rank | halo kB/product | GMRES its/step | "
          "time/iteration (compute + communication) | steady solve | efficiency | memory/rank (replicated + owned) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, cells in (("AGARD fine (1.43 M points)", 1.43e6), ("10 M points", 10e6)):
        t_serial = steps * (cells * (per_cell["residual"] + 2 * per_cell["jacobian"] + per_cell["bilu"])
                            + its_per_step * cells * per_cell["gmres_it"])
        for p in (64, 128, 256, 512, 1024):
            n = cells / p
            ghost = 12 * n ** (2 / 3)
            halo_bytes = 40 * ghost
            its = min(MAX_ITERATIONS, its_per_step * (p / 2) ** (1 / 6))
            t_comp = n * per_cell["gmres_it"]
            t_comm = (LATENCY * 6 + halo_bytes / BANDWIDTH) + REDUCTIONS_PER_ITERATION * LATENCY * math.log2(p)
            t_step = n * (per_cell["residual"] + 2 * per_cell["jacobian"] + per_cell["bilu"]) \
                + 3 * (LATENCY * 6 + halo_bytes / BANDWIDTH) + its * (t_comp + t_comm)
            t_solve = steps * t_step
            eff = t_serial / (p * t_solve)
            mem = replicated * cells, owned * n
            print(f"| {name} | {p} | {n:,.0f} | {ghost:,.0f} | {halo_bytes / 1e3:.0f} | {its:.1f} | "
                  f"{(t_comp + t_comm) * 1e3:.3f} ms ({t_comp * 1e3:.3f} + {t_comm * 1e3:.3f}) | {t_solve:.1f} s | "
                  f"{eff:.2f} | {mem[0] + mem[1]:,.0f} MB ({mem[0]:,.0f} + {mem[1]:,.0f}) |")


if __name__ == "__main__":
    main()
