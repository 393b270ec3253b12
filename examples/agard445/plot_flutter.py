#!/usr/bin/env python3
"""AGARD 445.6 flutter plots from the example's CSV files.

Usage: plot_flutter.py [out_dir]   (default out/agard445)

flutter_boundary.png: flutter speed index and frequency ratio against Mach number, every
boundary_<level>_zeta<percent>.csv against the experiment (experiment.csv).
vg.png: damping g and frequency of every mode against the density parameter, for every
vg_M<mach>_<level>.csv, with the Hopf point of vg_flutter_*.csv.
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def column(rows, name):
    return [float(r[name]) for r in rows]


def boundaries(out):
    files = sorted(glob.glob(os.path.join(out, "boundary_*_zeta*.csv")))
    exp_file = os.path.join(out, "experiment.csv")
    if not files:
        return None
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7.5), sharex=True)
    styles = {"very_coarse": ":", "coarse": "--", "medium": "-", "fine": "-."}
    for path in files:
        rows = read(path)
        if not rows:
            continue
        name = os.path.basename(path)[len("boundary_"):-len(".csv")]
        level, zeta = name.rsplit("_zeta", 1)
        label = f"Euler, {level}, zeta {zeta} %"
        ls = styles.get(level, "-")
        m = column(rows, "mach")
        a1.plot(m, column(rows, "fsi"), ls, marker="o", ms=3, label=label)
        a2.plot(m, column(rows, "frequency_ratio"), ls, marker="o", ms=3, label=label)
    if os.path.exists(exp_file):
        e = read(exp_file)
        a1.plot(column(e, "mach"), column(e, "fsi"), "ks", label="experiment (Yates)")
        a2.plot(column(e, "mach"), column(e, "frequency_ratio"), "ks", label="experiment (Yates)")
    a1.set_ylabel("flutter speed index")
    a2.set_ylabel("frequency ratio $\\omega_f / \\omega_\\alpha$")
    a2.set_xlabel("Mach number")
    a1.set_title("AGARD 445.6 weakened model 3: flutter boundary")
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    a1.legend(fontsize=7)
    fig.tight_layout()
    path = os.path.join(out, "flutter_boundary.png")
    fig.savefig(path, dpi=130)
    return path


def vg(out):
    files = sorted(glob.glob(os.path.join(out, "vg_M*.csv")))
    if not files:
        return None
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.5, 7.5), sharex=True)
    for path in files:
        rows = read(path)
        tag = os.path.basename(path)[len("vg_"):-len(".csv")]
        modes = sorted({int(r["mode"]) for r in rows})
        for k in modes:
            pts = [r for r in rows if int(r["mode"]) == k]
            mu = column(pts, "parameter")
            a1.plot(mu, column(pts, "damping_g"), marker="o", ms=3, label=f"mode {k + 1} ({tag})")
            a2.plot(mu, column(pts, "frequency"), marker="o", ms=3, label=f"mode {k + 1} ({tag})")
        fl = os.path.join(out, "vg_flutter_" + tag + ".csv")
        if os.path.exists(fl):
            for r in read(fl):
                a1.axvline(float(r["hopf_parameter"]), color="k", lw=0.8, ls=":")
                a2.plot([float(r["hopf_parameter"])], [float(r["hopf_frequency"])], "k*", ms=9)
    a1.axhline(0.0, color="k", lw=0.6)
    a1.set_ylabel("damping g = 2 Re / |Im|")
    a2.set_ylabel("frequency (time unit c / U)")
    a2.set_xlabel("density parameter $\\mu = \\rho c^3$ (kg)")
    a1.set_title("AGARD 445.6: V-g / V-f (dotted: direct Hopf point)")
    for a in (a1, a2):
        a.grid(True, alpha=0.3)
    a1.legend(fontsize=7)
    fig.tight_layout()
    path = os.path.join(out, "vg.png")
    fig.savefig(path, dpi=130)
    return path


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/agard445"
    made = [p for p in (boundaries(out), vg(out)) if p]
    if not made:
        print(f"no boundary_*.csv or vg_M*.csv in {out}")
        return 1
    for p in made:
        print("wrote", p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
