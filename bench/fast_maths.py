#!/usr/bin/env python3
"""How far the JIT's fast maths is from the true value, per function and argument range.

Each function runs over 20,000 arguments spread evenly at random over a range (a render
kernel draws point(vec3(f(x), x, 0))), with `--math fast` (LLVM intrinsics, vectorized
through glibc's libmvec) and with `--math exact` (the C library: the interpreter's result
bit for bit). Each drawn f(x) is held against f of the same float x computed in double
precision and rounded to a float: the largest absolute error, and the largest in units in
the last place (ulp) of that float.

  python3 bench/fast_maths.py [build]          (build: the build folder, `build`)

Prints a Markdown table (docs/accuracy.md, "Fast maths").
"""
import csv
import math
import os
import struct
import subprocess
import sys
import tempfile

build = sys.argv[1] if len(sys.argv) > 1 else "build"
psysc = os.path.join(build, "tools", "psysc", "psysc")

# (function, argument ranges as (low, high)): where each is defined and finite.
CASES = [
    ("sin", [(-3.15, 3.15), (-100, 100), (-1e4, 1e4), (-1e6, 1e6)]),
    ("cos", [(-3.15, 3.15), (-100, 100), (-1e4, 1e4), (-1e6, 1e6)]),
    ("tan", [(-1.5, 1.5), (-100, 100)]),
    ("exp", [(-10, 10), (-80, 80)]),
    ("log", [(1e-3, 10), (1, 1e6)]),
    ("atan", [(-10, 10)]),
    ("asin", [(-1, 1)]),
    ("acos", [(-1, 1)]),
    ("tanh", [(-10, 10)]),
    ("pow", [(0.01, 10)]),  # pow(x, 2.5)
]


def bits(x):
    return struct.unpack("<i", struct.pack("<f", x))[0]


def ulps(a, b):
    # Distance in representable floats (both of one sign here, or zero).
    ia, ib = bits(a), bits(b)
    if ia < 0:
        ia = -2**31 - ia
    if ib < 0:
        ib = -2**31 - ib
    return abs(ia - ib)


def run(fn, low, high, math, folder):
    call = f"pow(x, 2.5)" if fn == "pow" else f"{fn}(x)"
    text = (f"object p(x: float) {{ point(vec3({call}, x, 0), white, 1); }}\n"
            f"object e {{ emit p({low} + ({high} - ({low})) * rand()) count 20000; }}\n"
            "spawn e;\n")
    source = os.path.join(folder, "fn.psys")
    with open(source, "w") as f:
        f.write(text)
    dump = os.path.join(folder, f"{math}.csv")
    subprocess.run([psysc, "run", "--quiet", "--frames", "1", "--math", math, "--dump", dump, source],
                   check=True, stdout=subprocess.DEVNULL)
    with open(dump) as f:
        rows = [r for r in csv.DictReader(f) if r["type"] == "p"]
    # (the dump writes a float's shortest decimal: read back as a double it must be rounded
    # to the float it stands for)
    return [(to_float(float(r["x"])), to_float(float(r["y"]))) for r in rows]


def to_float(x):
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


def truth(fn, x):
    f = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "exp": math.exp, "log": math.log, "atan": math.atan,
         "asin": math.asin, "acos": math.acos, "tanh": math.tanh, "pow": lambda v: v ** 2.5}[fn]
    return to_float(f(x))


def worst(fn, drawn):
    """The largest absolute error, the largest in ulp, and the argument of the latter."""
    most_abs, most_ulp, at = 0.0, 0, 0.0
    for value, x in drawn:
        t = truth(fn, x)
        most_abs = max(most_abs, abs(value - t))
        u = ulps(value, t)
        if u > most_ulp:
            most_ulp, at = u, x
    return most_abs, most_ulp, at


print("| function | arguments | fast: largest error | in ulp | exact: largest error | in ulp |")
print("|---|---|---:|---:|---:|---:|")
with tempfile.TemporaryDirectory() as folder:
    for fn, ranges in CASES:
        for low, high in ranges:
            fa, fu, _ = worst(fn, run(fn, low, high, "fast", folder))
            ea, eu, _ = worst(fn, run(fn, low, high, "exact", folder))
            name = "pow(x, 2.5)" if fn == "pow" else f"{fn}(x)"
            print(f"| `{name}` | [{low:g}, {high:g}] | {fa:.2g} | {fu} | {ea:.2g} | {eu} |")
