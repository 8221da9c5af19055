#!/usr/bin/python3
"""Error against cost for every integration method: docs/images/accuracy.png.

    build/bench/psys_accuracy --csv build/accuracy.csv > docs/accuracy-run.md
    bench/plot_accuracy.py build/accuracy.csv docs/images/accuracy.png

One panel per reference problem; each method is a line through its steps (1/15 … 1/240 s).
x: the CPU time one object costs per simulated second (ns per update ÷ step), y: the
largest position error over the run. Down and to the left is better. Dashed: rk4 and
leapfrog under @precision(double), their error measured on the state (not the drawn floats).
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PROBLEMS = ["projectile", "drag", "spring", "damped_spring", "orbit", "eccentric"]
STYLE = {
    "euler": ("tab:red", "o"),
    "semi_implicit": ("tab:orange", "s"),
    "midpoint": ("tab:olive", "^"),
    "rk2": ("tab:green", "v"),
    "rk4": ("tab:blue", "D"),
    "leapfrog": ("tab:cyan", "X"),
    "exponential": ("tab:purple", "P"),
    "exact": ("black", "*"),
    "bs3": ("tab:pink", "h"),
    "rk4 double": ("tab:blue", "d"),
    "leapfrog double": ("tab:cyan", "x"),
}


def main(source, target):
    rows = defaultdict(list)
    with open(source) as f:
        for r in csv.DictReader(f):
            if r["problem"] not in PROBLEMS or "@step" in r["step"]:
                continue
            cost = float(r["ns_per_update"]) / float(r["frame"]) / 1000  # µs per simulated second
            error = max(float(r["max_error"]), 1e-16)
            rows[(r["problem"], r["method"])].append((cost, error))
    fig, grid = plt.subplots(2, 3, figsize=(14, 8), constrained_layout=True)
    axes = grid.flatten()
    for ax, problem in zip(axes, PROBLEMS):
        for method, (colour, marker) in STYLE.items():
            points = sorted(rows.get((problem, method), []))
            if not points:
                continue
            ax.loglog([p[0] for p in points], [p[1] for p in points], marker=marker, color=colour, label=method,
                      linewidth=1.2, markersize=5, linestyle="--" if method.endswith("double") else "-")
        ax.axhspan(1e-16, 1e-6, color="0.92", zorder=0)
        ax.set_title(problem.replace("_", " "))
        ax.grid(True, which="major", color="0.85", linewidth=0.6)
    for ax in grid[1]:
        ax.set_xlabel("µs of CPU per simulated second, one object")
    for ax in grid[:, 0]:
        ax.set_ylabel("largest position error (m)")
    handles = [plt.Line2D([], [], color=c, marker=m, label=name, linestyle="--" if name.endswith("double") else "-")
               for name, (c, m) in STYLE.items()]
    axes[0].legend(handles=handles, loc="lower right", fontsize=8)
    fig.suptitle("psys integrators: error against cost, steps 1/15 to 1/240 s\n"
                 "(grey: below 1e-6 m, float's resolution of positions of a few metres; dashed: state in double)",
                 fontsize=11)
    fig.savefig(target, dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_accuracy.py RESULTS.csv OUT.png")
    main(sys.argv[1], sys.argv[2])
