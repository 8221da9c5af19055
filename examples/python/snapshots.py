#!/usr/bin/env python3
"""Runs a sample and saves what it draws at four moments as one picture (matplotlib), or an
animation (a GIF) with --gif. The points come from the system's own arrays (columns(): no
copy on the CPU backends), the drawn rows picked with NumPy.

    python3 examples/python/snapshots.py samples/fountain.psys fountain.png [--gif fountain.gif]
"""
import argparse

import numpy as np

import psys


def drawn(system):
    """Every type's drawn points as (x, y, rgba) arrays, side view."""
    xs, ys, colours = [], [], []
    for t in system.types:
        c = system.columns(t)
        seen = c["visible"] == 1
        if not seen.any():
            continue
        xs.append(np.asarray(c["x"])[seen])
        ys.append(np.asarray(c["y"])[seen])
        colours.append(np.clip(np.stack([c[k][seen] for k in "rgba"], axis=1), 0, 1))
    if not xs:
        return np.zeros(0), np.zeros(0), np.zeros((0, 4))
    return np.concatenate(xs), np.concatenate(ys), np.concatenate(colours)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program")
    parser.add_argument("out", help="a PNG of four moments")
    parser.add_argument("--gif", help="also an animation, 3 s at 20 frames a second")
    parser.add_argument("--backend", default="llvm")
    args = parser.parse_args()

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    system = psys.compile(args.program, backend=args.backend)
    moments = [0.5, 1.0, 2.0, 4.0]
    fig, axes = plt.subplots(1, len(moments), figsize=(12, 3.4), facecolor="black", sharex=True, sharey=True)
    for ax, at in zip(axes, moments):
        system.step(1 / 60, steps=round((at - system.time) * 60))
        x, y, rgba = drawn(system)
        ax.set_facecolor("black")
        ax.scatter(x, y, s=2, c=rgba, linewidths=0)
        ax.set_title(f"t = {system.time:.1f} s, {len(x)} points", color="white", fontsize=9)
        ax.set_aspect("equal", adjustable="box")  # one scale for the four (shared axes)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100, facecolor="black")
    print(f"saved {args.out}: {system.stats()['types']}")

    if args.gif:
        from matplotlib.animation import FuncAnimation, PillowWriter
        system = psys.compile(args.program, backend=args.backend)
        fig, ax = plt.subplots(figsize=(4, 4), facecolor="black")
        ax.set_facecolor("black")
        ax.axis("off")
        scatter = ax.scatter([], [], s=2, linewidths=0)
        ax.set_xlim(-8, 8)
        ax.set_ylim(-1, 15)

        def frame(_):
            system.step(1 / 60, steps=3)
            x, y, rgba = drawn(system)
            scatter.set_offsets(np.column_stack([x, y]) if len(x) else np.zeros((0, 2)))
            scatter.set_color(rgba)
            return (scatter,)

        FuncAnimation(fig, frame, frames=60, blit=True).save(args.gif, writer=PillowWriter(fps=20))
        print(f"saved {args.gif}")


if __name__ == "__main__":
    main()
