#!/usr/bin/env python3
"""Plays 100 instances of each of two effects at moving positions in one system each, and
plots what they draw seen from above, coloured by instance, with each instance's path
(matplotlib). A burst that finishes is played again where it is then.

    python3 examples/python/instances.py examples/effects/burst.psys examples/effects/halo.psys out.png
"""
import argparse
import math

import numpy as np

import psys


def place(k, j, n, t):
    """Instance j of the n of effect k at time t: on a turning ring, a 4×4 transform."""
    a = 2 * math.pi * j / n + t * (-0.3 if k % 2 else 0.4)
    m = np.eye(4, dtype=np.float32)
    m[:3, 3] = ((3 + 2 * k) * math.cos(a), 2 + 1.5 * k, (3 + 2 * k) * math.sin(a))
    return m


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("effects", nargs="+")
    parser.add_argument("out", help="a PNG")
    parser.add_argument("--play", type=int, default=100)
    parser.add_argument("--seconds", type=float, default=2.5)
    args = parser.parse_args()

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    systems, played, paths = [], [], []
    for k, path in enumerate(args.effects):
        s = psys.compile(path)
        s.kill(0)  # the host plays them all
        systems.append(s)
        played.append([s.play(place(k, j, args.play, 0)) for j in range(args.play)])
        paths.append([[] for _ in range(args.play)])
    replayed = 0
    for frame in range(round(args.seconds * 60)):
        for k, s in enumerate(systems):
            s.step(1 / 60)
            done = set(s.finished_instances())
            for j, h in enumerate(played[k]):
                m = place(k, j, args.play, s.time)
                if h in done:
                    played[k][j] = s.play(m)
                    replayed += 1
                else:
                    s.move(h, m)
                paths[k][j].append((m[0, 3], m[2, 3]))

    fig, axes = plt.subplots(1, len(systems), figsize=(5.5 * len(systems), 5.5), facecolor="black")
    axes = np.atleast_1d(axes)
    for k, (ax, s) in enumerate(zip(axes, systems)):
        ax.set_facecolor("black")
        counts = []
        for t in s.types:
            p = s.points(t)
            counts.append(len(p["id"]))
            hue = (p["instance"] % args.play) / args.play
            ax.scatter(p["position"][:, 0], p["position"][:, 2], s=1.5, c=plt.cm.hsv(hue), linewidths=0)
        for trail in paths[k][:: max(1, args.play // 10)]:
            xy = np.array(trail)
            ax.plot(xy[:, 0], xy[:, 1], color="white", linewidth=0.4, alpha=0.5)
        ax.set_title(f"{args.effects[k].split('/')[-1]}: {s.instance_count} instances, {sum(counts)} points",
                     color="white", fontsize=9)
        ax.set_aspect("equal")
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100, facecolor="black")
    print(f"saved {args.out}: {[s.instance_count for s in systems]} instances playing, {replayed} played again")


if __name__ == "__main__":
    main()
