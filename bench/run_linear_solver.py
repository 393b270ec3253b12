#!/usr/bin/python3
"""Run bench_linear_solver and write out/bench/linear_solver.csv plus a summary.

WHY a script: Google Benchmark reports one line per benchmark with free-form counters; the
project wants one CSV with fixed columns, ratios against STREAM and PETSc, and the
preconditioner-storage table of spec 08 (non-zero blocks per method, form and fill level).

Usage (from the repository root, after building bench_linear_solver):
    bench/run_linear_solver.py [--build-dir build/<name>] [--large] [--filter REGEX]
                               [--repetitions N] [--all-peers] [--out out/bench/linear_solver.csv]
                               [--json existing.json]   # re-summarise a previous run
With --repetitions N every benchmark runs N times and the CSV keeps the fastest repetition
(kernels: CPU time of one application; solves: setup + solve), which filters out the noise of
other processes on a shared machine; the N runs are all in the JSON file.
Benchmark names are kind/matrix/block/scalar/method/fill/solver (see bench_linear_solver.cpp).
CSV columns: matrix,block,scalar,method,fill,solver,iterations,setup_seconds,solve_seconds,
preconditioner_blocks,gbytes_per_second.  For kernels (spmv, bilu_*, stream) solve_seconds is
the time of one application (CPU time), setup_seconds is empty; for solves both are wall time.
"""
import argparse
import csv
import json
import os
import subprocess
import sys

HEADER = ["matrix", "block", "scalar", "method", "fill", "solver", "iterations", "setup_seconds",
          "solve_seconds", "preconditioner_blocks", "gbytes_per_second"]

UNIT = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def run_bench(exe, large, flt, json_path, all_peers=False, repetitions=1):
    cmd = [exe, "--benchmark_format=console", "--benchmark_out_format=json",
           "--benchmark_out=" + json_path]
    if repetitions > 1:
        cmd.append("--benchmark_repetitions=%d" % repetitions)
    if large:
        cmd.append("--large")
    if all_peers:
        cmd.append("--all-peers")
    if flt:
        cmd.append("--benchmark_filter=" + flt)
    print("running:", " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)


def rows_from_json(path):
    with open(path) as f:
        data = json.load(f)
    rows = []
    best = {}  # name -> index in rows of its fastest repetition
    for b in data["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue  # mean/median/stddev aggregates of repetitions
        name = b["name"].split("/min_time")[0].split("/iterations")[0].split("/manual_time")[0]
        parts = name.split("/")
        if len(parts) < 7:
            continue
        kind, matrix, block, scalar, method, fill, solver = parts[:7]
        err = b.get("error_occurred", False)
        unit = UNIT[b.get("time_unit", "ns")]
        row = {"kind": kind, "matrix": matrix, "block": block, "scalar": scalar, "method": method,
               "fill": fill, "solver": solver, "iterations": "", "setup_seconds": "",
               "solve_seconds": "", "preconditioner_blocks": "", "gbytes_per_second": "",
               "converged": "", "relative_residual": "", "error": b.get("error_message", "") if err else ""}
        if err:
            if name not in best:
                best[name] = len(rows)
                row["_cost"] = float("inf")
                rows.append(row)
            continue
        if kind == "solve":
            row["iterations"] = int(b["krylov_iterations"])
            row["setup_seconds"] = "%.6g" % b["setup_seconds"]
            row["solve_seconds"] = "%.6g" % b["solve_seconds"]
            row["converged"] = int(b.get("converged", 0))
            row["relative_residual"] = "%.3g" % b.get("relative_residual", float("nan"))
        else:
            t = b["cpu_time"] * unit
            if solver == "bilu_symbolic" or solver == "bilu_numeric":
                row["setup_seconds"] = "%.6g" % t
            else:
                row["solve_seconds"] = "%.6g" % t
        if "preconditioner_blocks" in b:
            row["preconditioner_blocks"] = int(round(b["preconditioner_blocks"]))
        if "bytes_per_second" in b:
            row["gbytes_per_second"] = "%.3f" % (b["bytes_per_second"] / 1e9)
        if "stream_bytes_per_second" in b:
            row["stream_gbytes_per_second"] = b["stream_bytes_per_second"] / 1e9
        cost = (float(row["setup_seconds"] or 0) + float(row["solve_seconds"] or 0)) if kind == "solve" \
            else b["cpu_time"] * unit
        if kind == "solve" and str(row["converged"]) != "1":
            cost = float("inf")
        row["_cost"] = cost
        if name in best:
            if cost < rows[best[name]]["_cost"]:
                rows[best[name]] = row
            continue
        best[name] = len(rows)
        rows.append(row)
    return rows


def fnum(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def summary(rows):
    out = []
    stream = {r["matrix"]: fnum(r["gbytes_per_second"]) for r in rows if r["solver"] == "stream_triad"}
    big = stream.get("triad_160MB")
    small = stream.get("triad_4MB")
    out.append("STREAM triad: out of cache %s GB/s, in cache (3 x 4 MB) %s GB/s" % (big, small))
    out.append("")
    out.append("Bandwidth of kernels relative to STREAM (out-of-cache matrices vs a 3 x 160 MB triad,")
    out.append("in-cache ones vs a 3 x 4 MB triad, each measured right after the kernel in the same")
    out.append("benchmark; minimal-traffic byte model):")
    for r in rows:
        if r["solver"] in ("spmv", "bilu_apply") and r["gbytes_per_second"]:
            gb = float(r["gbytes_per_second"])
            cells = r["matrix"].split("_")[-1]
            ncell = 1
            for d in cells.split("x"):
                ncell *= int(d) if d.isdigit() else 1
            in_cache = ncell * int(r["block"]) ** 2 * 7 * (16 if r["scalar"] == "complex" else 8) < 24e6
            # the triad measured inside the same benchmark, right after the kernel (drift-free)
            ref = r.get("stream_gbytes_per_second") or (small if in_cache else big)
            if ref:
                out.append("  %-28s b=%s %-8s fill=%-2s %-11s %7.2f GB/s = %5.1f%% of %s STREAM (%.2f GB/s)" % (
                    r["matrix"], r["block"], r["scalar"], r["fill"], r["solver"], gb, 100 * gb / ref,
                    "in-cache" if in_cache else "out-of-cache", ref))
    out.append("")
    # best time to solution per matrix and tolerance: ours vs peers
    solves = [r for r in rows if r["kind"] == "solve" and r["solve_seconds"] and str(r["converged"]) == "1"]
    groups = {}
    for r in solves:
        tol = r["solver"].split("_")[-1]
        peer = "petsc" if r["solver"].startswith("petsc") else ("eigen" if r["solver"].startswith("eigen") else "aerohopf")
        total = float(r["setup_seconds"]) + float(r["solve_seconds"])
        key = (r["matrix"], tol)
        best = groups.setdefault(key, {})
        if peer not in best or total < best[peer][0]:
            best[peer] = (total, r)
    out.append("Best time to solution (setup + solve, converged runs only):")
    for (m, tol), best in sorted(groups.items()):
        line = "  %-24s %-9s" % (m, tol)
        for peer in ("aerohopf", "petsc", "eigen"):
            if peer in best:
                t, r = best[peer]
                line += " | %s %.3fs (%s %s k=%s, %s it)" % (peer, t, r["scalar"], r["solver"].rsplit("_", 1)[0], r["fill"], r["iterations"])
        if "aerohopf" in best and "petsc" in best:
            line += " | petsc/aerohopf = %.2f" % (best["petsc"][0] / best["aerohopf"][0])
        out.append(line)
    out.append("")
    # storage table (spec 08)
    st = [r for r in rows if r["kind"] == "storage"]
    mats = sorted(set(r["matrix"] for r in st))
    for m in mats:
        out.append("Preconditioner non-zero %sx%s blocks, %s:" % (
            next(r["block"] for r in st if r["matrix"] == m), next(r["block"] for r in st if r["matrix"] == m), m))
        fills = sorted(set(int(r["fill"]) for r in st if r["matrix"] == m))
        out.append("  | method | form | " + " | ".join("BILU(%d)" % k for k in fills) + " |")
        keys = sorted(set((r["method"], r["scalar"]) for r in st if r["matrix"] == m), key=lambda k: (k[0], k[1] != "real2n_interleaved"))
        for method, form in keys:
            cells = []
            for k in fills:
                v = [r["preconditioner_blocks"] for r in st if r["matrix"] == m and r["method"] == method and r["scalar"] == form and int(r["fill"]) == k]
                cells.append("{:,}".format(v[0]) if v else "n/a")
            out.append("  | %s | %s | %s |" % (method, "real" if form.startswith("real") else form, " | ".join(cells)))
        for k in fills:
            c = [r["preconditioner_blocks"] for r in st if r["matrix"] == m and r["method"] == "1" and r["scalar"] == "complex" and int(r["fill"]) == k]
            rr = [r["preconditioner_blocks"] for r in st if r["matrix"] == m and r["method"] == "1" and r["scalar"].startswith("real") and int(r["fill"]) == k]
            if c and rr:
                out.append("  method 1, BILU(%d): complex/real storage = %.3f (target <= 0.5 at BILU(0))" % (k, c[0] / rr[0]))
        out.append("")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build-dir", default="build/linalg")
    ap.add_argument("--large", action="store_true", help="add the 1M-cell cases (needs ~10 GB)")
    ap.add_argument("--filter", default="")
    ap.add_argument("--all-peers", action="store_true", help="Eigen IncompleteLUT peers on every matrix (slow)")
    ap.add_argument("--repetitions", type=int, default=1, help="run each benchmark N times, keep the fastest")
    ap.add_argument("--json", default="", help="summarise an existing JSON output instead of running")
    ap.add_argument("--out", default="out/bench/linear_solver.csv")
    args = ap.parse_args()
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    json_path = args.json or os.path.join(os.path.dirname(args.out), "linear_solver.json")
    if not args.json:
        exe = os.path.join(args.build_dir, "bench", "bench_linear_solver")
        if not os.path.exists(exe):
            sys.exit("no %s: build the target bench_linear_solver first" % exe)
        run_bench(exe, args.large, args.filter, json_path, args.all_peers, args.repetitions)
    rows = rows_from_json(json_path)
    with open(json_path) as f:
        tuning = json.load(f).get("context", {}).get("aerohopf_prefetch", "not recorded")
    with open(args.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(HEADER)
        for r in rows:
            w.writerow([r[h] for h in HEADER])
    text = "Kernel prefetch tuning: %s\n" % tuning + summary(rows)
    print(text)
    with open(os.path.splitext(args.out)[0] + "_summary.txt", "w") as f:
        f.write(text + "\n")
    failed = [r for r in rows if r["error"] or (r["kind"] == "solve" and str(r["converged"]) == "0")]
    if failed:
        print("Not converged / errors:")
        for r in failed:
            print("  %s %s %s k=%s %s: %s res=%s" % (r["matrix"], r["scalar"], r["method"], r["fill"], r["solver"], r["error"] or "not converged", r["relative_residual"]))
    print("wrote", args.out)


if __name__ == "__main__":
    main()
