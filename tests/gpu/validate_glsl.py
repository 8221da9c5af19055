#!/usr/bin/python3
"""Every shader `psysc --emit=glsl` prints for each program given, checked by
glslangValidator (OpenGL GLSL 4.50 semantics; the stage from the name's extension).

    validate_glsl.py PSYSC GLSLANGVALIDATOR WORKDIR PROGRAM...
"""
import os
import subprocess
import sys


def shaders(psysc, program):
    out = subprocess.run([psysc, "--emit=glsl", program], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{program}: psysc --emit=glsl failed:\n{out.stderr}")
    name, lines = None, []
    for line in out.stdout.splitlines(keepends=True):
        if line.startswith("//// "):
            if name:
                yield name, "".join(lines)
            name, lines = line[5:].strip(), []
        else:
            lines.append(line)
    if name:
        yield name, "".join(lines)


def main():
    psysc, validator, work, programs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    os.makedirs(work, exist_ok=True)
    failures, count = [], 0
    for program in programs:
        stem = os.path.splitext(os.path.basename(program))[0]
        found = list(shaders(psysc, program))
        if not any(n.endswith(".comp") for n, _ in found):
            failures.append(f"{program}: no compute shader emitted")
        paths = []
        for name, source in found:
            path = os.path.join(work, f"{stem}.{name}")
            with open(path, "w") as f:
                f.write(source)
            paths.append(path)
        count += len(paths)
        # A program's shaders in one run (each its own compilation unit: no -l, nothing
        # linked); where that fails, each again alone, for its own messages.
        if paths and subprocess.run([validator, *paths], capture_output=True, text=True).returncode != 0:
            for path in paths:
                check = subprocess.run([validator, path], capture_output=True, text=True)
                if check.returncode != 0:
                    failures.append(f"{path}:\n{check.stdout}{check.stderr}")
            if not failures:
                failures.append(f"{program}: its shaders fail together and pass one by one")
    print(f"{count} shaders of {len(programs)} programs validated")
    if failures:
        sys.exit("\n".join(failures))


main()
