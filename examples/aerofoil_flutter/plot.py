#!/usr/bin/env python3
"""PNGs of the aerofoil_flutter results.

Usage: /usr/bin/python3 plot.py [out_dir]   (default out/aerofoil_flutter)

boundaries.png  Ubar*(M) for both cases and grids, with the time-marching points
                (filled: decaying at 0.97 Ubar*, crosses: growing at 1.03 Ubar*)
vg_<case>_<grid>_M<mach>.png   V-g / V-f diagram: damping g and frequency omega / omega_alpha of the
                plunge and pitch modes against Ubar, the flutter point (g = 0, rising) marked
spectra.png     very coarse light case M = 0.5: eigenvalues at Ubar* - 0.01, Ubar*, Ubar* + 0.01
histories.png   pitch histories of the time-marching runs
jump_check.png  very coarse grid: largest Re lambda of the whole spectrum against Ubar / Ubar*
                at the Mach numbers where a boundary jumps to another mode (and the last one)
reduced.png     reduced model (heavy case): damping vs the exact eigenvalue, growth rate vs
                amplitude at Ubar*, LCO amplitude vs Ubar, against time marching
"""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=130)
    plt.close(fig)


def finish_axes(ax, xlabel, ylabel, title=None):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def col(rows, key):
    return [float(r[key]) for r in rows]


def boundaries(out):
    files = sorted(glob.glob(os.path.join(out, "boundary_*_*.csv")))
    styles = {"medium": "o-", "coarse": "s--", "very_coarse": "^:"}
    if not files:
        return
    cases = sorted({os.path.basename(f).split("_")[1] for f in files})
    fig, axes = plt.subplots(1, len(cases), figsize=(6 * len(cases), 4.5), squeeze=False)
    ver = read(os.path.join(out, "verification.csv")) if os.path.exists(os.path.join(out, "verification.csv")) else []
    for ax, case in zip(axes[0], cases):
        for f in files:
            parts = os.path.basename(f)[:-4].split("_")
            if parts[1] != case:
                continue
            grid = "_".join(parts[2:])
            rows = read(f)
            if rows:
                ax.plot(col(rows, "mach"), col(rows, "ubar"), styles.get(grid, "o-"), ms=3, label=f"{grid} grid")
        for f in sorted(glob.glob(os.path.join(out, f"hopf_curve_{case}_*.csv"))):
            rows = read(f)
            grid = os.path.basename(f)[:-4].split("_", 3)[3]
            if rows:
                ax.plot(col(rows, "mach"), col(rows, "ubar"), "-", lw=0.8, color="gray",
                        label=f"Hopf curve, pseudo-arclength ({grid})")
        for r in ver:
            if r["case"] != case:
                continue
            grows = float(r["growth_rate"]) > 0
            ax.plot(float(r["mach"]), float(r["ubar"]), "x" if grows else "o", color="r" if grows else "g", ms=8,
                    mfc="none" if grows else "g")
        finish_axes(ax, "Mach number", "flutter speed $\\bar U^*$", f"{case} case: Hopf-point stability boundary")
    save(fig, out, "boundaries.png")


MODE_NAMES = {0: "plunge", 1: "pitch"}  # by in-vacuo frequency (w_R = 0.343 < 1)


def vg(out):
    for path in sorted(glob.glob(os.path.join(out, "vg_*_M*.csv"))):
        name = os.path.basename(path)[:-4]
        if name.startswith("vg_flutter_"):
            continue
        tag = name[3:]  # <case>_<grid>_M<mach>
        rows = read(path)
        if not rows:
            continue
        fpath = os.path.join(out, f"vg_flutter_{tag}.csv")
        flutter = read(fpath) if os.path.exists(fpath) else []
        fig, axes = plt.subplots(2, 1, figsize=(7, 8), sharex=True)
        for mode in sorted({int(r["mode"]) for r in rows}):
            sel = [r for r in rows if int(r["mode"]) == mode]
            u = col(sel, "parameter")
            label = f"mode {mode} ({MODE_NAMES.get(mode, '?')})"
            axes[0].plot(u, col(sel, "damping_g"), "o-", ms=3, label=label)
            # frequency is |Im lambda| in 1/(c/U_inf): omega/omega_alpha = frequency * Ubar / 2
            axes[1].plot(u, [f * x / 2 for f, x in zip(col(sel, "frequency"), u)], "o-", ms=3, label=label)
        for k, f in enumerate(flutter):
            uf, ff = float(f["parameter"]), float(f["frequency"])
            lab = f"flutter (g = 0): $\\bar U$ = {uf:.4f}" + (f", Hopf {float(f['hopf_parameter']):.4f}" if k == 0 else "")
            axes[0].plot(uf, 0.0, "k*", ms=12, label=lab)
            axes[1].plot(uf, ff * uf / 2, "k*", ms=12)
            for ax in axes:
                ax.axvline(uf, color="k", lw=0.6, ls="--")
        axes[0].axhline(0, color="gray", lw=0.8)
        case, rest = tag.split("_", 1)
        grid, mach = rest.rsplit("_M", 1)
        finish_axes(axes[0], "", "damping g = 2 Re $\\lambda$ / |Im $\\lambda$|",
                    f"V-g / V-f: {case} case, {grid} grid, M = {mach}")
        finish_axes(axes[1], "reduced speed $\\bar U = U / (\\omega_\\alpha b)$", "frequency $\\omega / \\omega_\\alpha$")
        save(fig, out, f"vg_{tag}.png")


def spectra(out):
    path = os.path.join(out, "spectra.csv")
    if not os.path.exists(path):
        return
    rows = read(path)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    styles = {-0.01: ("b", "o", "Ubar* - 0.01"), 0.0: ("k", "+", "Ubar*"), 0.01: ("r", "x", "Ubar* + 0.01")}
    for off, (c, m, lab) in styles.items():
        sel = [r for r in rows if abs(float(r["ubar_offset"]) - off) < 1e-12]
        re, im = col(sel, "re"), col(sel, "im")
        axes[0].plot(re, im, m, color=c, ms=3, label=lab, mfc="none")
        axes[1].plot(re, im, m, color=c, ms=8, label=lab, mfc="none")
    axes[0].set_title("full spectrum of the coupled Jacobian (very coarse, light, M = 0.5)")
    axes[1].set_xlim(-0.03, 0.03)
    axes[1].set_ylim(0.0, 1.2)
    axes[1].axvline(0, color="gray", lw=0.8)
    axes[1].set_title("near the imaginary axis: the critical pair crosses at Ubar*")
    for ax in axes:
        finish_axes(ax, "Re $\\lambda$", "Im $\\lambda$")
    save(fig, out, "spectra.png")


def histories(out):
    # the verification runs (history_<case>_<grid>_M<mach>_<factor>.csv), not the reduced model's
    files = [f for f in sorted(glob.glob(os.path.join(out, "history_*.csv")))
             if "_lco_" not in f and "_envelope_" not in f and "smoothed" not in f]
    if not files:
        return
    fig, ax = plt.subplots(figsize=(9, 5))
    for f in files:
        rows = read(f)
        ax.plot(col(rows, "t"), col(rows, "alpha"), lw=1, label=os.path.basename(f)[8:-4])
    finish_axes(ax, "t (c / U)", "pitch alpha (rad)", "time marching at 0.97 and 1.03 Ubar* (BDF2, dt = 0.125)")
    ax.legend(fontsize=7)
    save(fig, out, "histories.png")


def jump_check(out):
    path = os.path.join(out, "jump_check.csv")
    if not os.path.exists(path):
        return
    rows = read(path)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    keys = sorted({(r["case"], r["mach"], r["ubar_star"]) for r in rows})
    for case, mach, us in keys:
        sel = [r for r in rows if (r["case"], r["mach"], r["ubar_star"]) == (case, mach, us)]
        x = [float(r["ubar"]) / float(us) for r in sel]
        ax.plot(x, col(sel, "max_re"), "o-", ms=3, label=f"{case}, M = {float(mach):.4f} (Ubar* = {float(us):.3f})")
    ax.axhline(0, color="gray", lw=0.8)
    ax.axvline(1, color="gray", lw=0.8, ls="--")
    ax.set_yscale("symlog", linthresh=1e-4)
    finish_axes(ax, "$\\bar U / \\bar U^*$", "max Re $\\lambda$ (all eigenvalues)",
                "very coarse grid: is the boundary point the lowest crossing?")
    save(fig, out, "jump_check.png")


def reduced(out):
    dpath = os.path.join(out, "reduced_damping.csv")
    lpath, mpath = os.path.join(out, "reduced_lco.csv"), os.path.join(out, "reduced_lco_march.csv")
    epath = os.path.join(out, "reduced_envelope.csv")
    if not os.path.exists(dpath):
        return
    d = read(dpath)
    e = read(epath) if os.path.exists(epath) else []  # the time-marching runs (not with --skip-verify)
    fig, axes = plt.subplots(1, 3 if e else 2, figsize=(16 if e else 11, 4.5))
    ax = axes[0]
    ax.plot(col(d, "ubar"), col(d, "re_reduced"), "-", label="reduced model")
    ax.plot(col(d, "ubar"), col(d, "re_exact"), "o", mfc="none", label="exact eigenvalue (inverse power)")
    g = [(float(r["ubar"]), float(r["growth_march"])) for r in d if r["growth_march"] not in ("", "nan")]
    if g:
        ax.plot(*zip(*g), "x", ms=8, label="time marching")
    ax.axhline(0, color="gray", lw=0.8)
    finish_axes(ax, "$\\bar U$", "Re $\\lambda$ (growth rate)", "damping of the critical mode")
    # growth rate against amplitude at Ubar* (the lowest Ubar of the envelope runs)
    if e:
        ax = axes[1]
        u0 = min(float(r["ubar"]) for r in e)
        sel = sorted((r for r in e if abs(float(r["ubar"]) - u0) < 1e-12), key=lambda r: float(r["alpha_amplitude"]))
        ax.plot(col(sel, "alpha_amplitude"), col(sel, "growth_march"), "x", label="time marching (envelopes)")
        k = float(sel[-1]["growth_model"]) / float(sel[-1]["alpha_amplitude"]) ** 2  # Re(c1) / kappa^2
        amax = 1.1 * float(sel[-1]["alpha_amplitude"])
        a = [amax * i / 100 for i in range(101)]
        ax.plot(a, [k * x * x for x in a], "-", label="reduced model Re(c1) (A/kappa)$^2$")
        finish_axes(ax, "pitch amplitude A (rad)", "growth rate of A", "amplitude-dependent damping at $\\bar U^*$")
    ax = axes[-1]
    if os.path.exists(lpath):
        lrows = read(lpath)
        ax.plot(col(lrows, "ubar"), col(lrows, "alpha_amplitude"), "-", label="reduced model")
    if os.path.exists(mpath):
        m = [r for r in read(mpath) if r["alpha_amplitude_march"] not in ("", "nan")]
        if m:
            ax.plot(col(m, "ubar"), col(m, "alpha_amplitude_march"), "o", mfc="none", label="time marching (envelope fit)")
    finish_axes(ax, "$\\bar U$", "LCO pitch amplitude (rad)", "supercritical LCO")
    save(fig, out, "reduced.png")


def lco_branch(out):
    """Pitch LCO amplitude against Ubar / Ubar*: harmonic balance per H (solid where marked
    stable), the reduced model and the BDF2 runs to the cycle (--lco-march); the cycles' radial
    Floquet exponent (lco_floquet.png)."""
    path = os.path.join(out, "lco_branch_heavy_coarse_M0.80.csv")
    if not os.path.exists(path):
        return
    rows = read(path)
    ubar_star = min(float(r["ubar"]) for r in rows if int(r["harmonics"]) == 1)  # the start: next to Ubar*
    fig, ax = plt.subplots(figsize=(7.5, 5))
    colours = {1: "tab:orange", 2: "tab:green", 3: "tab:blue", 5: "k"}
    for h in sorted({int(r["harmonics"]) for r in rows}):
        pts = [r for r in rows if int(r["harmonics"]) == h]
        x = [float(r["ubar"]) / ubar_star for r in pts]
        y = [float(r["alpha_amplitude"]) for r in pts]
        st = [int(r["stable"]) for r in pts]
        for k in range(len(pts) - 1):
            ax.plot(x[k:k + 2], y[k:k + 2], "-" if st[k] and st[k + 1] else ":", color=colours.get(h, "gray"),
                    label=f"harmonic balance, H = {h}" if k == 0 else None)
    lpath = os.path.join(out, "reduced_lco.csv")
    if os.path.exists(lpath):
        lr = read(lpath)
        ax.plot([float(r["ubar"]) / ubar_star for r in lr], col(lr, "alpha_amplitude"), "r--", label="reduced 2-DOF model")
    mpath = os.path.join(out, "lco_march_heavy_coarse_M0.80.csv")
    if os.path.exists(mpath):
        m = read(mpath)
        runs = [r for r in m if float(r["start_scale"]) > 0]
        fits = [r for r in m if float(r["start_scale"]) == 0]
        ax.plot([float(r["ubar"]) / ubar_star for r in runs], col(runs, "march_amplitude"), "ks", mfc="none",
                label="BDF2 after 60 periods (from 0.9 and 1.1 x the cycle)")
        if fits:
            ax.plot([float(r["ubar"]) / ubar_star for r in fits], col(fits, "march_amplitude"), "k*", ms=10,
                    label="BDF2: zero of the envelopes' growth rate")
    finish_axes(ax, "$\\bar U / \\bar U^*$ (first point of the H = 1 branch)", "pitch LCO amplitude (rad)",
                "heavy case, coarse grid, M = 0.8 (solid: stable, dotted: unstable)")
    save(fig, out, "lco_branch.png")
    fpath = os.path.join(out, "lco_floquet_heavy_coarse_M0.80.csv")
    if os.path.exists(fpath):
        # the radial Floquet exponent of the cycles: Hill (Krylov) per H, BDF2 envelopes' slope
        f = read(fpath)
        fig, ax = plt.subplots(figsize=(7.5, 4.5))
        for h in sorted({int(r["harmonics"]) for r in f}):
            pts = [r for r in f if int(r["harmonics"]) == h]
            ax.plot([float(r["ubar"]) / ubar_star for r in pts], col(pts, "radial_exponent"), "o-",
                    color=colours.get(h, "gray"), label=f"Hill's method (Krylov), H = {h}")
        if os.path.exists(mpath):
            fits = [r for r in read(mpath) if float(r["start_scale"]) == 0]
            if fits:
                ax.plot([float(r["ubar"]) / ubar_star for r in fits], col(fits, "march_exponent"), "k*", ms=10,
                        label="BDF2: amplitude x slope of the envelopes' growth rate")
        ax.axhline(0, color="gray", lw=0.5)
        finish_axes(ax, "$\\bar U / \\bar U^*$", "radial Floquet exponent",
                    "stability of the LCO (negative: stable)")
        save(fig, out, "lco_floquet.png")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/aerofoil_flutter"
    boundaries(out)
    vg(out)
    spectra(out)
    histories(out)
    jump_check(out)
    reduced(out)
    lco_branch(out)
    print("plots written to", out)


if __name__ == "__main__":
    main()
