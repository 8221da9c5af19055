#!/usr/bin/env python3
"""Every VS Code snippet, expanded with its placeholders' defaults, is a program psysc
checks without an error: top-level snippets in a file beside the objects they name, the
others inside an object that has `pos` and `vel`.
    check_snippets.py PSYSC SNIPPETS.json"""
import json
import re
import subprocess
import sys
import tempfile

# What each snippet's text needs around it: where it goes, and how many values the
# `spark` it emits takes (the burst snippets' defaults differ).
CONTEXT = {
    "object": ("top", 1), "trigger": ("top", 1), "extern": ("top", 1), "fn": ("top", 1),
    "emit": ("body", 1), "emit count": ("body", 1), "kill when": ("body", 1), "sprite": ("body", 1),
    "streak": ("body", 1), "trail": ("body", 1), "burst when": ("body", 2), "on death": ("body", 1),
}
DRAWS = ("sprite", "streak", "trail")


def expand(body):
    """A snippet's text with ${N:default} → default and $N / ${N} → nothing."""
    text = "\n".join(body)
    while True:
        new = re.sub(r"\$\{\d+:([^${}]*)\}", r"\1", text)
        if new == text:
            break
        text = new
    return re.sub(r"\$\{?\d+\}?", "", text)


def program(name, text):
    where, spark = CONTEXT[name]
    spark_params = ", ".join(f"p{k}: vec3" for k in range(spark))
    prelude = (f"object child(p: vec3) {{ point(p, white, 1); kill when age > 1; }}\n"
               f"object spark({spark_params}) {{ point(p0, white, 1); kill when age > 1; }}\n")
    if where == "top":
        return prelude + text + "\nobject host { pos = vec3(0); point(pos, white, 1); emit child(pos) count 1; }\nspawn host;\n"
    draw = "" if name in DRAWS else "    point(pos, white, 1);\n"
    kill = "" if name in ("kill when", "burst when") else "    kill when age > 2;\n"
    return (prelude + "object host(ipos: vec3) {\n    pos = snapshot(ipos) + integrate(vel);\n"
            "    vel = vec3(0, 1, 0) + integrate(vec3(0, -9.82, 0));\n" + draw + kill +
            "    " + text.replace("\n", "\n    ") + "\n}\nspawn host(vec3(0));\n")


def main():
    psysc, path = sys.argv[1], sys.argv[2]
    snippets = json.load(open(path))
    failed = []
    missing = set(snippets) - set(CONTEXT)
    if missing:
        sys.exit(f"snippets this test does not know where to put: {sorted(missing)}")
    for name, snippet in snippets.items():
        source = program(name, expand(snippet["body"]))
        with tempfile.NamedTemporaryFile("w", suffix=".psys") as f:
            f.write(source)
            f.flush()
            r = subprocess.run([psysc, "check", "--color=never", f.name], capture_output=True, text=True)
        if r.returncode != 0 or "error" in r.stderr:
            failed.append(f"snippet `{name}`:\n{source}\n{r.stderr}")
    if failed:
        sys.exit("\n".join(failed))
    print(f"{len(snippets)} snippets expand to programs without errors")


if __name__ == "__main__":
    main()
