#!/usr/bin/env python3
"""Mode shapes of the AGARD 445.6 plate model: contours of the deflection of each mode over the
planform, from mode_shapes.csv and modes.csv written by the agard445 example.
Usage: plot_modes.py [out_dir]   (default out/agard445; writes modes.png there)."""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.tri as mtri
import numpy as np

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/agard445")
freq = {}
with open(out / "modes.csv") as f:
    for r in csv.DictReader(f):
        freq[int(r["mode"])] = float(r["frequency_hz"])
pts = {}
with open(out / "mode_shapes.csv") as f:
    for r in csv.DictReader(f):
        pts.setdefault(int(r["mode"]), []).append((float(r["x"]), float(r["y"]), float(r["w"])))
modes = sorted(pts)[:4]
fig, axes = plt.subplots(1, len(modes), figsize=(3.4 * len(modes), 3.6), squeeze=False, layout="constrained")
yates = [9.60, 38.17, 48.35, 91.54]
for ax, k in zip(axes[0], modes):
    x, y, w = zip(*pts[k])
    tri = mtri.Triangulation(x, y)
    c = ax.tricontourf(tri, w, levels=np.linspace(-1, 1, 21), cmap="RdBu_r")
    if min(w) < 0 < max(w):
        ax.tricontour(tri, w, levels=[0.0], colors="k", linewidths=1.0)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ref = f" (Yates {yates[k - 1]:.2f})" if k <= len(yates) else ""
    ax.set_title(f"mode {k}: {freq[k]:.2f} Hz{ref}", fontsize=9)
fig.colorbar(c, ax=axes[0].tolist(), shrink=0.9, label="w / max|w|  (black: nodal line)")
fig.suptitle("AGARD 445.6 weakened model 3: plate FE modes (clamped root)")
fig.savefig(out / "modes.png", dpi=130)
print(f"wrote {out / 'modes.png'}")
