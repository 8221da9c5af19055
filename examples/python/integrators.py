#!/usr/bin/env python3
"""How accurate two integrators are, measured from Python: an undamped spring (one period a
second, from x = 1 at rest: exactly x = cos(2πt)) run for 1.2 s at several step lengths under
@integrator(semi_implicit) and @integrator(rk4); the error at the end, and the order it
shows (halving the step divides the error by 2^order) until the error meets float's
rounding (about 1e-7 of x).

    python3 examples/python/integrators.py [--plot OUT.png]
"""
import argparse
import math

import psys

SPRING = """
@integrator({method});
const w = 6.2831853;
object mass {{
    x = 1 + integrate(v);
    v = integrate(-w * w * x);
    point(vec3(x, v, 0), white, 1);
}}
spawn mass;
"""

METHODS = ["semi_implicit", "rk4"]
STEPS = [15, 30, 60, 120, 240]  # steps a second
SECONDS = 1.2  # not a whole period, where a method's phase error would cancel


def error(method, per_second):
    """|x − cos(2πt)| after SECONDS, stepping 1/per_second (exact maths: the interpreter's bits)."""
    system = psys.compile(source=SPRING.format(method=method), name="spring.psys", math="exact")
    system.step(1 / per_second, steps=round(SECONDS * per_second))
    x = float(system.points("mass")["position"][0, 0])
    return abs(x - math.cos(2 * math.pi * system.time))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", help="save a log-log plot of the errors here")
    args = parser.parse_args()
    errors = {m: [error(m, n) for n in STEPS] for m in METHODS}
    print(f"{'steps/s':>8}" + "".join(f"{m:>16}{'order':>7}" for m in METHODS))
    for i, n in enumerate(STEPS):
        row = f"{n:>8}"
        for m in METHODS:
            e = errors[m]
            order = math.log2(e[i - 1] / e[i]) if i and e[i] > 0 else float("nan")
            row += f"{e[i]:>16.3e}{order:>7.2f}"
        print(row)
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for m in METHODS:
            ax.loglog([1 / n for n in STEPS], errors[m], "o-", label=m)
        ax.set_xlabel("step (s)")
        ax.set_ylabel(f"|x − cos 2πt| at t = {SECONDS} s")
        ax.set_title("a spring, from Python")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=100)
        print(f"saved {args.plot}")


if __name__ == "__main__":
    main()
