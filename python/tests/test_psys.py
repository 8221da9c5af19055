"""The Python package as a notebook or a tool calls it: compile, step, set, fire, reload,
read points and the system's own arrays; every bad input an exception that says why."""
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import psys

SAMPLES = pathlib.Path(os.environ.get("PSYS_SAMPLES_DIR", pathlib.Path(__file__).parents[2] / "samples"))
EXAMPLES = pathlib.Path(os.environ.get("PSYS_EXAMPLES_DIR", pathlib.Path(__file__).parents[2] / "examples"))

DOTS = (pathlib.Path(__file__).parents[2] / "tests" / "programs" / "beads.psys").read_text()


def test_a_sample_runs_and_its_points_come_back_as_arrays():
    fountain = psys.compile(SAMPLES / "fountain.psys")
    assert sorted(fountain.types) == ["drop", "fountain"]
    fountain.step(1 / 60, steps=60)
    assert fountain.step_count == 60
    assert fountain.time == pytest.approx(1.0)
    p = fountain.points("drop")
    assert p["position"].shape == (len(p["id"]), 3) and len(p["id"]) > 500
    assert p["color"].shape[1] == 4
    assert (p["position"][:, 1] >= 0).all()  # drops bounce off the ground
    st = fountain.stats()
    assert st["steps"] == 60 and st["types"]["drop"]["live"] == len(p["id"])


def test_columns_are_arrays_of_their_own_read_only():
    s = psys.compile(source=DOTS, math="exact")
    s.step(1 / 60, steps=30)
    c = s.columns("bead")
    again = s.columns("bead")
    assert not np.shares_memory(c["x"], again["x"])  # a copy each call
    assert not isinstance(c["x"].base, psys.System)
    assert not c["x"].flags.writeable
    seen = c["visible"] == 1
    p = s.points("bead")
    np.testing.assert_array_equal(c["id"][seen], p["id"])
    np.testing.assert_array_equal(c["x"][seen], p["position"][:, 0])
    assert c["size"].strides == (0,) and (c["size"] == 2).all()  # a constant: one value, no column
    with pytest.raises(ValueError):
        c["x"][0] = 5


def test_columns_outlive_a_reload_and_a_step_that_grows_the_pool():
    # Once views of the system's memory: a reload freed it and a growing pool moved it,
    # and an array read afterwards read freed memory (a segfault on a large pool).
    grows = ("@capacity(2000000) object d(p: vec3) { pos = p; point(pos, vec4(1), 2); }\n"
             "object src { emit d(nrand3()) count 300000; }\nspawn src;")
    s = psys.compile(source=grows)
    s.step(1 / 60, steps=2)
    x = s.columns("d")["x"]
    before = x.copy()
    s.reload(source="object q { point(vec3(0), vec4(1), 1); }\nspawn q;")
    s.step(1 / 60)
    np.testing.assert_array_equal(x, before)
    s = psys.compile(source=grows.replace("count 300000", "at 6000000 per second"))
    s.step(1 / 60)
    y = s.columns("d")["y"]
    before = y.copy()
    s.step(1 / 60, steps=3)  # 100k objects a step: the pool grows
    np.testing.assert_array_equal(y, before)


def test_the_jit_in_exact_maths_and_the_interpreter_give_the_same_bits():
    a = psys.compile(SAMPLES / "fireworks.psys", math="exact")
    b = psys.compile(SAMPLES / "fireworks.psys", backend="interp")
    for _ in range(4):
        a.step(1 / 60, steps=30)
        b.step(1 / 60, steps=30)
        for t in a.types:
            p, q = a.points(t), b.points(t)
            for k in p:
                np.testing.assert_array_equal(p[k], q[k])


def test_a_program_with_errors_raises_compile_error_with_its_diagnostics():
    with pytest.raises(psys.CompileError) as e:
        psys.compile(source="object a {\n    point(vec3(0), red, nope);\n}\nspawn a;\n", name="bad.psys")
    d = e.value.diagnostics[0]
    assert (d["file"], d["line"], d["column"], d["severity"]) == ("bad.psys", 2, 25, "error")
    assert "nope" in d["message"] and "bad.psys:2:25" in str(e.value)
    with pytest.raises(FileNotFoundError, match="no/such"):
        psys.compile("/no/such/file.psys")
    with pytest.raises(TypeError):
        psys.compile()


def test_externs_and_triggers_by_name_and_every_bad_value_refused():
    s = psys.compile(source=DOTS)
    assert s.externs == {"speed": "float", "tint": "color"}
    assert s.triggers == {"burst": "vec3, float"}
    s.set("speed", 2)
    assert s.get("speed") == 2
    s.set("tint", (0, 1, 0, 1))
    assert s.get("tint") == (0, 1, 0, 1)
    with pytest.raises(psys.Error, match="no extern `sped`"):
        s.set("sped", 1)
    with pytest.raises(psys.Error, match="finite"):
        s.set("speed", math.nan)
    with pytest.raises(psys.Error, match="outside its range"):
        s.set("speed", 11)
    with pytest.raises(TypeError, match=r"set: extern `speed` is a float \(1 number\), not \(1, 2\)"):
        s.set("speed", (1, 2))
    with pytest.raises(KeyError):
        s.get("sped")
    assert s.get("speed") == 2
    s.fire("burst", (0, 0, 0), 5)
    assert s.stats()["types"]["bead"]["created"] == 5
    with pytest.raises(psys.Error):
        s.fire("burst", (0, 0, 0))
    with pytest.raises(psys.Error, match="finite, non-negative"):
        s.step(math.nan)
    with pytest.raises(KeyError):
        s.points("nothing")
    with pytest.raises(psys.Error, match="no backend `vulkan`"):
        psys.compile(source=DOTS, backend="vulkan")


def test_a_reload_carries_the_objects_over_and_a_broken_one_changes_nothing():
    s = psys.compile(source=DOTS)
    s.step(1 / 60, steps=30)
    s.reload(DOTS.replace("point(pos, tint, 2)", "point(pos, tint, 3)"))
    p = s.points("bead")
    assert len(p["id"]) == 30 and (p["size"] == 3).all()
    with pytest.raises(psys.CompileError):
        s.reload("object dot {")
    s.step()
    assert len(s.points("bead")["id"]) == 31
    assert s.warnings == []


def test_a_system_ends():
    s = psys.compile(source="object a { point(vec3(0), red, 1); kill when age > 0.1; }\nspawn a;\n")
    assert not s.finished
    s.step(1 / 60, steps=20)
    assert s.finished


def test_the_examples_run(tmp_path):
    out = subprocess.run([sys.executable, EXAMPLES / "python" / "integrators.py", "--plot", tmp_path / "i.png"],
                         capture_output=True, text=True, check=True).stdout
    rows = [line.split() for line in out.splitlines() if line.strip()[:1].isdigit()]
    assert len(rows) == 5
    assert float(rows[2][4]) == pytest.approx(4, abs=0.3)  # rk4's order (before float's rounding)
    assert float(rows[-1][2]) == pytest.approx(1, abs=0.1)  # semi-implicit Euler's
    assert (tmp_path / "i.png").stat().st_size > 0
    subprocess.run([sys.executable, EXAMPLES / "python" / "snapshots.py", SAMPLES / "fountain.psys",
                    tmp_path / "s.png"], capture_output=True, text=True, check=True)
    assert (tmp_path / "s.png").stat().st_size > 0


def test_bad_arguments_say_why_in_words():
    s = psys.compile(source="extern f: float = 1;\nobject a { point(vec3(f), white, 1); }\nspawn a;")
    with pytest.raises(ValueError, match="steps is 0 or more, not -1"):
        s.step(1 / 60, steps=-1)  # once did nothing, silently
    for threads in (257, -1):
        with pytest.raises(ValueError, match=f"threads is 0 to 256, not {threads}"):
            psys.compile(source="object a { }\nspawn a;", threads=threads)
    with pytest.raises(IndexError, match="there is no object type -1: the program's are 0 to 0"):
        s.points(-1)  # once "Unable to cast Python instance…"
    with pytest.raises(TypeError, match="a type is its name or its index, not float"):
        s.points(1.5)
    s.set("f", np.array(2.0))  # a 0-d array (once "len() of unsized object")
    assert s.get("f") == 2
    s.set("f", np.float32(3))
    assert s.get("f") == 3
    with pytest.raises(TypeError, match="set takes a number or a sequence of numbers, not str"):
        s.set("f", "x")
    with pytest.raises(FileNotFoundError, match="no/such.psys"):
        psys.compile(b"no/such.psys")  # a bytes path is a path (once "`b'no/such.psys'`"; once a CompileError)
    with pytest.raises(TypeError, match="a path is text or os.PathLike, not int"):
        psys.compile(3)
    assert psys.compile(SAMPLES / "fire.psys").types  # an os.PathLike


def test_a_nul_in_a_source_is_the_error_psysc_gives_not_a_program_cut_short():
    with pytest.raises(psys.CompileError) as e:
        psys.compile(source="object a {\n point(vec3(0), white, 1);\0 }\nspawn a;", name="nul.psys")
    assert str(e.value) == "nul.psys:2:27: error: unexpected character U+0000"
    d = e.value.diagnostics[0]
    assert (d["line"], d["column"], d["severity"]) == (2, 27, "error")
    s = psys.compile(source="object a { point(vec3(0), white, 1); }\nspawn a;")
    with pytest.raises(psys.CompileError, match="unexpected character U[+]0000"):
        s.reload(source="object a {\0}")


def test_unknown_names_are_key_errors_and_wrong_sizes_type_errors_saying_what_was_expected():
    s = psys.compile(source=DOTS)
    for call, message in ((lambda: s.set("sped", 1), "there is no extern `sped`: the program's are `speed`, `tint`"),
                          (lambda: s.get("sped"), "there is no extern `sped`"),
                          (lambda: s.fire("bang"), "there is no trigger `bang`: the program's are `burst`"),
                          (lambda: s.points("nothing"), "there is no object type `nothing`: the program's are")):
        with pytest.raises(KeyError) as caught:
            call()
        assert isinstance(caught.value, psys.Error) and isinstance(caught.value, psys.UnknownNameError)
        assert str(caught.value).startswith(message)  # a sentence, not a KeyError's quoted key
    with pytest.raises(TypeError, match=r"set: extern `tint` is a color \(4 numbers\), not 1"):
        s.set("tint", 1)
    with pytest.raises(TypeError, match=r"fire: trigger `burst` takes \(vec3, float\): 4 numbers, not 3 in"):
        s.fire("burst", (0, 0, 0))
    with pytest.raises(psys.ValueTypeError):
        s.fire("burst", 1, 2, 3, 4, 5)
    assert s.stats()["types"]["bead"]["created"] == 0  # nothing refused changed anything


def test_a_missing_or_unreadable_file_is_the_oserror_python_gives(tmp_path):
    with pytest.raises(FileNotFoundError):
        psys.compile(tmp_path / "absent.psys")
    with pytest.raises(IsADirectoryError):
        psys.compile(tmp_path)


def test_a_system_closes_at_the_end_of_a_with_and_a_closed_one_refuses_every_call():
    with psys.compile(source=DOTS) as s:
        s.fire("burst", (0, 0, 0), 5)
        s.step(1 / 60)
        assert not s.closed
    assert s.closed
    for call in (lambda: s.step(1 / 60), lambda: s.points("bead"), lambda: s.columns("bead"), lambda: s.stats(),
                 lambda: s.set("speed", 1), lambda: s.get("speed"), lambda: s.fire("burst", (0, 0, 0), 1),
                 lambda: s.reload(), lambda: s.types, lambda: s.time, lambda: s.finished):
        with pytest.raises(ValueError, match="the system is closed"):
            call()
    s.close()  # a second close does nothing
    t = psys.compile(source=DOTS)
    t.close()
    assert t.closed


def test_positions_are_the_drawn_points_positions_as_an_n_by_3_array():
    s = psys.compile(SAMPLES / "fountain.psys")
    s.step(1 / 60, steps=90)
    p = s.positions("drop")
    assert p.shape == (len(s.points("drop")["id"]), 3) and p.shape[0] > 100
    assert np.array_equal(p, s.points("drop")["position"])


def test_step_releases_the_gil_other_python_threads_run_meanwhile():
    import threading
    s = psys.compile(SAMPLES / "fire.psys", threads=1)
    s.set("rate", 100000)
    s.step(1 / 60, steps=30)  # a pool of some size: each step takes a while
    counted = 0
    done = threading.Event()

    def stepping():
        s.step(1 / 60, steps=60)
        done.set()

    worker = threading.Thread(target=stepping)
    worker.start()
    while not done.is_set():  # runs only while the worker is inside step() without the GIL
        counted += 1
    worker.join()
    # Held, the worker's 60 steps would run with this loop stopped (a few turns at most,
    # before and after); released, it turns all the while (millions of times).
    assert counted > 10000, counted


def test_reserve_takes_room_ahead_and_changes_nothing_else():
    a = psys.compile(SAMPLES / "fire.psys", math="exact")
    b = psys.compile(SAMPLES / "fire.psys", math="exact")
    b.reserve("part", 100000)
    for s in (a, b):
        s.set("rate", 20000)
        s.step(1 / 60, steps=60)
    assert np.array_equal(a.points("part")["position"], b.points("part")["position"])
    with pytest.raises(psys.Error, match="part holds at most 1048576 objects"):
        b.reserve("part", 2**21)
    with pytest.raises(KeyError):
        b.reserve("nothing", 1)


def test_the_library_path_and_the_jit_cache_are_options(tmp_path):
    (tmp_path / "lib" / "std").mkdir(parents=True)
    (tmp_path / "lib" / "std" / "mine.psys").write_text("const far = 40;\n")
    source = 'import "std/mine.psys";\nobject a { point(vec3(far), white, 1); }\nspawn a;\n'
    s = psys.compile(source=source, library_path=[tmp_path / "nothing", tmp_path / "lib"],
                     jit_cache=tmp_path / "cache")
    s.step(1 / 60)
    assert s.points("a")["position"].tolist() == [[40, 40, 40]]
    assert any(p.suffix == ".o" for p in (tmp_path / "cache").iterdir())
    with pytest.raises(psys.CompileError, match="std/mine.psys"):
        psys.compile(source=source)


def test_prewarm_and_reset():
    s = psys.compile(SAMPLES / "fountain.psys", math="exact")
    s.prewarm(3.0)
    assert s.step_count == 30 and abs(s.time - 3.0) < 1e-9
    warm = s.points("drop")["position"]
    assert len(warm) > 1000
    s.reset()
    assert s.time == 0 and s.step_count == 0 and len(s.points("drop")["id"]) == 0
    s.prewarm(3.0, longest_step=0.1)
    assert np.array_equal(s.points("drop")["position"], warm)  # the same seed: the same run
    with pytest.raises(psys.Error, match="non-negative"):
        s.prewarm(-1)


def test_a_close_from_another_thread_waits_for_the_step_it_would_cut_short():
    import threading
    s = psys.compile(SAMPLES / "fire.psys", threads=1)
    s.set("rate", 100000)
    s.step(1 / 60, steps=30)
    started = threading.Event()

    def stepping():
        started.set()
        s.step(1 / 60, steps=40)

    worker = threading.Thread(target=stepping)
    worker.start()
    started.wait()
    s.close()  # waits for the 40 steps (freed under them, the step would read freed memory)
    worker.join()
    assert s.closed


HIT = """
object spark(v: vec3) {
    pos = snapshot(instance.pos) + integrate(v);
    point(pos, white, 2);
    kill when age > 0.5;
}
object hit {
    emit spark(nrand3()) at 120 per second;
    kill when age > 0.3;
}
trigger burst(n: float) { emit hit count n; }
spawn hit;
"""


def test_instances_play_at_their_transforms_and_finish():
    s = psys.compile(source=HIT)
    s.kill(0)  # the system's own: the host plays them all
    places = {}
    for k in range(4):
        m = np.eye(4, dtype=np.float32)
        m[:3, 3] = (10 * k, 0, 0)  # NumPy's rows and columns: the translation is the last column
        places[s.play(m)] = 10 * k
    s.step(1 / 60, steps=6)
    assert s.instance_count == 4
    p = s.points("spark")
    assert set(np.unique(p["instance"]).astype(int)) == {h & 0xFFFFFFFF for h in places}
    for h, x in places.items():
        mine = p["position"][p["instance"] == (h & 0xFFFFFFFF)]
        assert len(mine) > 5 and np.abs(mine[:, 0] - x).max() < 1
    first = next(iter(places))
    s.fire("burst", 2, instance=first)
    s.stop(first)
    assert s.life(first) == "stopped"
    finished = []
    for _ in range(120):
        s.step(1 / 60)
        finished += s.finished_instances()
    assert sorted(finished) == sorted(places)
    assert s.life(first) == "finished" and s.instance_count == 0
    with pytest.raises(psys.Error, match="has finished"):
        s.move(first, np.eye(4))
    with pytest.raises(psys.Error, match="affine"):
        s.play(np.ones((4, 4)))
    with pytest.raises(psys.ValueTypeError, match="4×4"):
        s.play([1, 2, 3])
    with pytest.raises(psys.Error, match="not instanced"):
        psys.compile(source=DOTS).play()


def test_each_instance_reads_its_own_externs():
    s = psys.compile(source="""
extern spread: float = 1;
object spark(v: vec3) {
    pos = instance.pos + v * spread;
    point(pos, white, 1);
}
object hit { emit spark(normalize(nrand3())) count 16; }
spawn hit;
""")
    s.kill(0)
    a, b = s.play(), s.play()
    s.set("spread", 4, instance=a)
    assert s.get("spread", instance=a) == 4 and s.get("spread", instance=b) == 1 and s.get("spread") == 1
    s.step()
    p = s.points("spark")
    r = np.linalg.norm(p["position"], axis=1)
    assert np.allclose(r[p["instance"] == (a & 0xFFFFFFFF)], 4, rtol=1e-5)
    assert np.allclose(r[p["instance"] == (b & 0xFFFFFFFF)], 1, rtol=1e-5)
    s.set("spread", 2)  # the effect's: every instance's
    assert s.get("spread", instance=a) == 2
    with pytest.raises(psys.UnknownNameError):
        s.set("nope", 1, instance=a)
    s.kill(b)
    s.step()
    with pytest.raises(psys.Error, match="has finished"):
        s.set("spread", 3, instance=b)
    with pytest.raises(ValueError, match="no instance"):
        s.get("spread", instance=b)


def test_instances_run_at_their_own_speed_and_pause():
    src = """
object spark(v: vec3) {
    pos = instance.pos + integrate(v);
    point(pos, white, age);
}
object hit { emit spark(vec3(1, 0, 0)) count 1; }
spawn hit;
"""
    s = psys.compile(source=src, backend="interp")
    s.kill(0)
    slow, still, full = s.play(), s.play(), s.play()
    s.speed(slow, 0.25)
    s.pause(still)
    assert s.speed(slow) == 0.25 and s.speed(full) == 1
    assert s.paused(still) and not s.paused(slow)
    s.step(1 / 32, steps=32)  # 1 s of the system's
    p = s.points("spark")
    age = {int(i): a for i, a in zip(p["instance"], p["size"])}
    assert age == {slow & 0xFFFFFFFF: 0.25, still & 0xFFFFFFFF: 0, full & 0xFFFFFFFF: 1}
    s.pause(still, False)
    assert s.speed(still) == 1 and not s.paused(still)
    with pytest.raises(psys.Error, match="from 0 to 100"):
        s.speed(slow, -1)
    with pytest.raises(TypeError, match="not str"):
        s.speed(slow, "fast")
    s.kill(slow)
    s.step()
    with pytest.raises(ValueError, match="no instance"):
        s.speed(slow)
    with pytest.raises(psys.Error, match="has finished"):
        s.pause(slow)


def test_the_instances_example_plays_two_effects_and_plots_them(tmp_path):
    out = tmp_path / "instances.png"
    r = subprocess.run([sys.executable, EXAMPLES / "python" / "instances.py", EXAMPLES / "effects" / "burst.psys",
                        EXAMPLES / "effects" / "halo.psys", out, "--play", "20", "--seconds", "1.5"],
                       capture_output=True, text=True, check=True)
    assert "[20, 20] instances playing" in r.stdout
    assert int(r.stdout.split("instances playing, ")[1].split()[0]) >= 20  # the bursts, again
    assert out.stat().st_size > 10_000


def test_events_come_once_a_step_as_an_array():
    s = psys.compile(source="""
object shell(v: vec3) {
    pos = integrate(v + integrate(vec3(0, -9.8, 0)));
    point(pos, white, 3);
    kill when age > 1;
    on death { notify "pop"(pos, age); }
}
object launcher { emit shell(vec3(nrand(), 8, nrand())) at 5 per second; }
spawn launcher;
""")
    assert s.event_names == ["pop"]
    total = 0
    for _ in range(180):
        s.step(1 / 60)
        e = s.events("pop")
        assert e.shape[1] == 4 and e.dtype == np.float32
        assert (e[:, 3] > 1).all()
        total += len(e)
    assert total == s.stats()["types"]["shell"]["killed"]
    with pytest.raises(psys.UnknownNameError, match='its events are "pop"'):
        s.events("boom")
