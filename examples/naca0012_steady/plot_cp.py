"""Cp plots of the naca0012_steady example: medium vs fine at M = 0.8, alpha = 0, and all four
grid levels at M = 0.8, alpha = 1.25 deg. Usage: /usr/bin/python3 plot_cp.py [output dir]."""
import csv
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

out = sys.argv[1] if len(sys.argv) > 1 else "out/naca0012_steady"


def load(name):
    with open(os.path.join(out, name)) as f:
        rows = list(csv.DictReader(f))
    return [float(r["x"]) for r in rows], [float(r["cp"]) for r in rows]


def plot(cases, title, png):
    plt.figure(figsize=(7, 5))
    for name, label, style in cases:
        x, cp = load(name)
        plt.plot(x, cp, style, label=label, ms=3, lw=1)
    plt.gca().invert_yaxis()
    plt.xlabel("x / c")
    plt.ylabel("Cp")
    plt.title(title)
    plt.grid(alpha=0.3)
    plt.legend()
    plt.tight_layout()
    plt.savefig(os.path.join(out, png), dpi=120)
    print("wrote", os.path.join(out, png))


plot([("cp_M0.80_a0.00_medium.csv", "medium 129 x 33", "o-"), ("cp_M0.80_a0.00_fine.csv", "fine 257 x 65", "-")],
     "NACA 0012, M = 0.8, alpha = 0 (Euler)", "cp_M0.80_a0.00_medium_vs_fine.png")
plot([("cp_M0.80_a1.25_very_coarse.csv", "very coarse", "^-"), ("cp_M0.80_a1.25_coarse.csv", "coarse", "s-"),
      ("cp_M0.80_a1.25_medium.csv", "medium", "o-"), ("cp_M0.80_a1.25_fine.csv", "fine", "-")],
     "NACA 0012, M = 0.8, alpha = 1.25 deg (Euler)", "cp_M0.80_a1.25_levels.png")
