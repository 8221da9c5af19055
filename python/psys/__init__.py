"""psys: particle systems compiled from .psys programs, run from Python.

    import psys
    fountain = psys.compile("samples/fountain.psys")          # or psys.compile(source=...)
    fountain.step(1 / 60, steps=120)
    drops = fountain.points("drop")                           # id, position (n×3), color, size
    cols = fountain.columns("drop")                           # visible, id, x y z, r g b a, size (copies)

An instanced program (one that reads `instance`) plays many times in one system:
`h = s.play(m)` with a 4×4 transform, `s.move(h, m)`, `s.stop(h)`, `s.kill(h)`,
`s.life(h)`, `s.fire(name, *args, instance=h)`, `s.finished_instances()` after a step;
`points()` and `columns()` give each row's instance.

Errors are exceptions: psys.CompileError carries the compiler's diagnostics (a list of
dicts: severity, file, line, column, end_line, end_column, message); an unknown extern,
trigger or type is psys.UnknownNameError (a KeyError), a value of the wrong size
psys.ValueTypeError (a TypeError), a file that cannot be read the OSError open() gives;
psys.Error the rest. A System is a context manager: `with psys.compile(...) as s:` closes
it at the end (close() does it at once; a closed system's calls raise ValueError).
docs/embedding.md has the whole story.
"""

import os

from . import _psys


class Error(Exception):
    """A call the system refused: a bad step, an unknown extern or trigger, a wrong value."""

    diagnostics = []


class CompileError(Error):
    """A program that does not compile; `diagnostics` says where and why."""


class UnknownNameError(Error, KeyError):
    """An extern, trigger or object type the program does not have (a KeyError too)."""

    def __str__(self):  # a KeyError's str is the repr of its key: this one is a sentence
        return str(self.args[0]) if self.args else ""


class ValueTypeError(Error, TypeError):
    """A value of the wrong size for an extern or a trigger (a TypeError too)."""


_psys._set_errors(CompileError, Error, UnknownNameError, ValueTypeError)

System = _psys.System
version = _psys.version


def compile(path=None, *, source=None, name="<string>", backend="llvm", math="fast", seed=1,
            capacity=0, threads=0, optimize=True, jit_cache=None, library_path=None):
    """Compiles a .psys file (or `source`, standing for a file called `name`) and starts a
    system on `backend`: "llvm" (the JIT), "interp" or "glsl" (a GPU, through OpenGL 4.5).
    capacity: objects per type (0: the default, 2^20); threads: 0 for every core;
    jit_cache: the folder of the JIT's compiled kernels ("" none; None: the default);
    library_path: folders (a list, or ':'-separated) where `import "std/…"` looks first."""
    if jit_cache is not None:
        jit_cache = os.fsdecode(jit_cache)
    if library_path is not None and not isinstance(library_path, (str, bytes, os.PathLike)):
        library_path = ":".join(os.fsdecode(p) for p in library_path)
    elif library_path is not None:
        library_path = os.fsdecode(library_path)
    if (path is None) == (source is None):
        raise TypeError("psys.compile takes a path or source=, one of them")
    for what, value, least, most in (("seed", seed, 0, 2**32 - 1), ("capacity", capacity, 0, 4294967295),
                                     ("threads", threads, 0, 256)):
        if isinstance(value, bool) or not isinstance(value, int):
            raise TypeError(f"psys.compile: {what} is a whole number, not {type(value).__name__}")
        if not least <= value <= most:
            raise ValueError(f"psys.compile: {what} is {least} to {most}, not {value}")
    if source is not None:
        if isinstance(source, bytes):
            source = source.decode("utf-8")
        if not isinstance(source, str):
            raise TypeError(f"psys.compile: source is text, not {type(source).__name__}")
        return _psys._compile(source, True, name, backend, math, seed, capacity, threads, optimize, jit_cache,
                              library_path)
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"psys.compile: a path is text or os.PathLike, not {type(path).__name__}")
    path = os.fsdecode(path)
    if "\0" in path:  # the C API would read the path up to it: another file
        raise ValueError("psys.compile: a path has no NUL character")
    with open(path, "rb"):  # a missing or unreadable file: the OSError Python gives (FileNotFoundError, …)
        pass
    return _psys._compile(path, False, "", backend, math, seed, capacity, threads, optimize, jit_cache, library_path)



__all__ = ["compile", "System", "Error", "CompileError", "UnknownNameError", "ValueTypeError", "version"]
