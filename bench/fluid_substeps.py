# The fluid sample under sub-steps (docs/language.md, "Neighbours": under @step a fold is
# the step's). Each drop's speed after 8 s, from its displacement over the last frame: the
# mean and the 99th percentile (a liquid at rest: near 0), and the highest drop (the
# glass is 4 high). Run from the repository root after a build:
#   PYTHONPATH=build/python python3 bench/fluid_substeps.py
import os, sys
import numpy as np
import psys
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
src = open(os.path.join(root, "samples", "fluid.psys")).read()
def run(dt, step):
    text = src if step is None else src.replace("@shape(disc)", f"@shape(disc)\n@step({step})")
    s = psys.compile(source=text, name="fluid.psys", math="exact", backend="llvm")
    frames = int(round(8 / dt))
    s.step(dt, frames - 1)
    a = s.points("drop")
    s.step(dt, 1)
    b = s.points("drop")
    ia = {int(i): k for k, i in enumerate(a["id"])}
    v = [np.linalg.norm(b["position"][k] - a["position"][ia[int(i)]]) / dt for k, i in enumerate(b["id"]) if int(i) in ia]
    v = np.array(v)
    top = b["position"][:, 1].max()
    return len(b["id"]), v.mean(), np.percentile(v, 99), top
print("dt      @step      drops  mean speed  p99 speed  highest drop")
for dt in (1/60, 1/30, 1/20):
    for step in (None, "1/120", "1/240", "1/480"):
        n, m, p, top = run(dt, step)
        print(f"1/{round(1/dt):<4} {step or '-':<9} {n:6d}  {m:9.3f}  {p:9.3f}  {top:8.3f}")
