#!/usr/bin/env python3
"""Plots of the tubular-reactor example: python3 plot.py OUT_DIR (the folder the example wrote).

Writes branch.png, coefficients.png, damping.png, reduced_vs_full.png and history_*.png there.
Uses only the standard library and matplotlib (Debian: python3-matplotlib).
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
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"plot.py: {path} has no rows")
    return rows


def col(rows, name, conv=float):
    out = []
    for r in rows:
        v = r[name]
        out.append(conv(v) if v != "" else float("nan"))
    return out


def branch(out):
    rows = read(os.path.join(out, "branch.csv"))
    mu, th, stable = col(rows, "mu"), col(rows, "max_theta"), col(rows, "stable", int)
    fig, ax = plt.subplots(figsize=(7, 5))
    # draw stable parts solid, unstable dashed
    seg_mu, seg_th, seg_st = [mu[0]], [th[0]], stable[0]
    for m, t, s in zip(mu[1:], th[1:], stable[1:]):
        seg_mu.append(m)
        seg_th.append(t)
        if s != seg_st:
            ax.plot(seg_mu, seg_th, "b-" if seg_st else "r--", lw=1.5)
            seg_mu, seg_th, seg_st = [m], [t], s
    ax.plot(seg_mu, seg_th, "b-" if seg_st else "r--", lw=1.5)
    for b in read(os.path.join(out, "bifurcations.csv")):
        m, t = float(b["mu"]), float(b["max_theta"])
        if b["kind"] == "hopf":
            ax.plot(m, t, "ko", ms=7, mfc="gold")
            ax.annotate(f"Hopf {m:.6f}", (m, t), textcoords="offset points", xytext=(8, -12), fontsize=8)
        else:
            ax.plot(m, t, "ks", ms=6, mfc="white")
            ax.annotate(f"fold {m:.5f}", (m, t), textcoords="offset points", xytext=(8, 4), fontsize=8)
    ax.set_xlabel(r"Damkohler number $\mu$")
    ax.set_ylabel(r"max $\Theta$")
    ax.set_title("Tubular reactor: equilibrium branch (solid stable, dashed unstable)")
    ax.set_xlim(0.12, 0.22)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "branch.png"), dpi=130)
    plt.close(fig)


def coefficients(out):
    rows = read(os.path.join(out, "coefficients.csv"))
    exact = [r for r in rows if r["precision"] == "taylor"][0]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, name in zip(axes, ["g20_re", "g21_re"]):
        ref = float(exact[name])
        for prec, style in [("double", "r-o"), ("dd", "g-s"), ("qd", "b-^")]:
            rr = [r for r in rows if r["precision"] == prec]
            h = [float(r["h"]) for r in rr]
            err = [max(abs(float(r[name]) - ref) / abs(ref), 1e-17) for r in rr]
            ax.loglog(h, err, style, ms=4, label=prec)
        ax.invert_xaxis()
        ax.set_xlabel("finite-difference step h")
        ax.set_ylabel(f"relative difference from taylor<> ({name})")
        ax.set_title(("2nd" if name.startswith("g20") else "3rd") + "-derivative coefficient")
        ax.grid(alpha=0.3, which="both")
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "coefficients.png"), dpi=130)
    plt.close(fig)


def damping(out):
    rows = read(os.path.join(out, "damping.csv"))
    d = col(rows, "dmu")
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(d, col(rows, "exact_re"), "ko-", label="exact eigenvalue (inverse power)")
    ax.plot(d, col(rows, "linear_re"), "b--", label=r"reduced model: Re($i\omega + \lambda_\mu \Delta\mu$)")
    ax.axhline(0, color="gray", lw=0.8)
    ax.set_xlabel(r"$\mu - \mu^*$")
    ax.set_ylabel(r"Re $\lambda$ (growth rate)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "damping.png"), dpi=130)
    plt.close(fig)


def lco(out):
    rows = read(os.path.join(out, "reduced_vs_full.csv"))
    d = col(rows, "dmu")
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(d, col(rows, "reduced_amplitude"), "b-o", label="reduced 2-DOF model")
    ax.plot(d, col(rows, "full_amplitude"), "ks", label="time marching, full system (BDF2)")
    ax.set_xlabel(r"$\mu - \mu^*$")
    ax.set_ylabel(r"LCO amplitude of $\Theta(x=1)$")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "reduced_vs_full.png"), dpi=130)
    plt.close(fig)


def lco_branch(out):
    """Theta(1) amplitude against mu - mu* by harmonic balance (per H, stable solid, unstable
    dotted), the reduced model and the BDF2 runs."""
    path = os.path.join(out, "lco_branch.csv")
    cmp_path = os.path.join(out, "lco_compare.csv")
    if not (os.path.exists(path) and os.path.exists(cmp_path)):
        return
    rows, cmp = read(path), read(cmp_path)
    mu_star = float(cmp[0]["mu"]) - float(cmp[0]["dmu"])
    fig, ax = plt.subplots(figsize=(7, 4.8))
    colours = {1: "tab:orange", 2: "tab:green", 3: "tab:purple", 5: "tab:blue", 8: "k"}
    for h in sorted({int(r["harmonics"]) for r in rows}):
        pts = [r for r in rows if int(r["harmonics"]) == h]
        x = [float(r["mu"]) - mu_star for r in pts]
        y = [float(r["theta_amplitude"]) for r in pts]
        st = [int(r["stable"]) for r in pts]
        c = colours.get(h, "gray")
        for k in range(len(pts) - 1):  # segment style by the stability of its ends
            style = "-" if st[k] and st[k + 1] else ":"
            ax.plot(x[k:k + 2], y[k:k + 2], style, color=c, lw=1.2,
                    label=f"harmonic balance, H = {h}" if k == 0 else None)
    d = col(cmp, "dmu")
    ax.plot(d, col(cmp, "reduced_amplitude"), "r^", label="reduced 2-DOF model")
    ax.plot(d, col(cmp, "full_amplitude"), "ks", mfc="none", label="BDF2 time marching")
    ax.set_xlabel(r"$\mu - \mu^*$")
    ax.set_ylabel(r"LCO amplitude of $\Theta(x=1)$ (half peak-to-peak)")
    ax.set_title("LCO branch (solid: stable, dotted: unstable by Hill's method)", fontsize=9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "lco_branch.png"), dpi=130)
    plt.close(fig)


def histories(out):
    for path in sorted(glob.glob(os.path.join(out, "history_*.csv"))):
        rows = read(path)
        t = col(rows, "t")
        fig, ax = plt.subplots(figsize=(8, 3.8))
        ax.plot(t, col(rows, "theta_full"), "k-", lw=0.8, label="full system")
        ax.plot(t, col(rows, "theta_reduced"), "r--", lw=0.8, label="reduced model")
        ax.set_xlabel("t")
        ax.set_ylabel(r"$\Theta(x=1)$")
        ax.set_title(os.path.basename(path)[:-4])
        ax.legend(loc="lower right", fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(path[:-4] + ".png", dpi=110)
        plt.close(fig)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/tubular_reactor"
    for f in (branch, coefficients, damping, lco, lco_branch, histories):
        f(out)
    print(f"plot.py: wrote PNGs to {out}")


if __name__ == "__main__":
    main()
