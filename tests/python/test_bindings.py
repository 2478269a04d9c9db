"""frictherm.load_scene / Scene.set / validate / run (the pybind11 bindings, python/src/native.cpp)
against the frictherm program: the same scene and the same --set changes must give the same series
to round-off, an observer must see every step, and a bad value must raise SceneError naming its key.

Run by the ctest python.bindings (built only with pybind11): FRICTHERM_EXE, FRICTHERM_SOURCE_DIR,
FRICTHERM_TEST_DIR as for the other tests here."""
import os
import subprocess

import numpy as np
import pytest

import frictherm

SOURCE = os.environ.get("FRICTHERM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCENE = os.path.join(SOURCE, "examples", "bar_vibration.json")
END = 2e-4  # s: a quarter of the bar's period, ~110 steps at C = 0.5 (the scene runs two periods)

pytest.importorskip("frictherm._native", reason="built without pybind11")


@pytest.fixture(scope="module")
def workdir():
    d = os.path.join(os.environ.get("FRICTHERM_TEST_DIR", os.getcwd()), "bindings")
    os.makedirs(d, exist_ok=True)
    return d


def cli_run(out, sets):
    args = [os.environ["FRICTHERM_EXE"], "run", SCENE, "-o", out, "--force", "--quiet", "--threads", "1"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True, env=dict(os.environ, OMP_NUM_THREADS="1"))


def series(path):
    with frictherm.open(path) as r:
        return {c: r.series[c] for c in r.series.columns}


@pytest.mark.parametrize("cfl", [0.5, 0.25])
def test_python_run_equals_the_program_run(workdir, cfl):
    """The CFL sweep of the issue: one scene, two CFL factors, each equal to `frictherm run --set`."""
    scene = frictherm.load_scene(SCENE).set("run.end_time", END).set("solver.cfl", cfl)
    seen = []
    rows = []  # the series rows the observer was handed as new

    def observer(step):
        p = step.particles()
        seen.append((step.step, step.time, step.kinetic_energy, float(np.sum(p["mass"] * np.sum(p["velocity"] ** 2, 1)))))
        if step.series_new:
            rows.append(step.series)
        assert step.series["time"] <= step.time  # the latest row, never one of a later step

    py_out = os.path.join(workdir, f"py_{cfl}.h5")
    result = frictherm.run(scene, output=py_out, threads=1, observer=observer)
    assert result["status"] == "completed" and result["steps"] == len(seen) > 50
    cli_out = os.path.join(workdir, f"cli_{cfl}.h5")
    cli_run(cli_out, [f"run.end_time={END}", f"solver.cfl={cfl}"])
    a, b = series(py_out), series(cli_out)
    assert list(a) == list(b)
    for c in a:  # the same program on the same thread: identical, up to round-off in the last bit
        assert np.allclose(a[c], b[c], rtol=1e-12, atol=1e-300, equal_nan=True), c
    # The observer's steps are the mechanics steps, and its particle views give its kinetic energy.
    assert [s[0] for s in seen] == list(range(1, len(seen) + 1))
    for _, _, ke, mv2 in seen:
        assert ke == pytest.approx(0.5 * mv2, rel=1e-12)
    # The observer sees the series rows the file holds (step.series, issue 33 item 1): the file's rows
    # after the first (t = 0, written before any step), every column, bit for bit and in order.
    assert len(rows) > 10 and list(rows[-1]) == list(a)
    with frictherm.open(py_out) as r:
        for c in a:
            stored = np.asarray(r.file["series"][c][()])
            assert [row[c] for row in rows] == stored[1:].tolist(), c
        assert rows[-1]["time"] == r.series["time"][-1] and rows[-1]["step"] == result["steps"]


def test_scene_errors_name_the_key():
    scene = frictherm.load_scene(SCENE).set("solver.cfl", -1)
    with pytest.raises(frictherm.SceneError) as e:
        frictherm.validate(scene)
    assert e.value.key == "solver.cfl" and "solver.cfl" in str(e.value)
    with pytest.raises(frictherm.SceneError) as e:
        frictherm.validate(frictherm.load_scene({"units": "SI", "dimension": 2, "grdi": {}}))
    assert "grdi" in str(e.value)


def test_validate_lists_the_notes_of_a_combination_known_to_fail():
    """USL with linear shape functions and multimaterial contact blew up in every contact scene
    measured (docs/contact.md): it validates, with one note naming solver.scheme; the default has none."""
    scene = frictherm.load_scene(os.path.join(SOURCE, "examples", "sliding_block.json"))
    assert frictherm.validate(scene)["notes"] == []
    linear = scene.set("solver.shape_function", "linear").set("solver.scheme", "usl")
    (note,) = frictherm.validate(linear)["notes"]
    assert 'solver.scheme "usl"' in note and "musl" in note


def test_scene_from_a_dict_and_back():
    scene = frictherm.load_scene(SCENE).set("solver.cfl", 0.3)
    d = scene.to_dict()
    assert d["solver"]["cfl"] == 0.3 and d["run"]["end_time"] == pytest.approx(1.571e-3)
    again = frictherm.load_scene(d)
    assert frictherm.validate(again)["dimension"] == 2


def test_observer_exception_ends_the_run(workdir):
    """An exception in the observer (as KeyboardInterrupt from Ctrl-C) stops the run and reaches
    the caller; the file written so far stays readable."""
    out = os.path.join(workdir, "stopped.h5")

    def observer(step):
        if step.step == 20:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        frictherm.run(frictherm.load_scene(SCENE).set("run.end_time", END), output=out, threads=1, observer=observer)
    part = [f for f in os.listdir(workdir) if f.startswith("stopped.h5")]
    assert part, os.listdir(workdir)


def test_ctrl_c_interrupts_the_run_cleanly(workdir):
    """Ctrl-C (a real SIGINT to this process, sent from the observer at step 30): the run's own handler
    takes it, ends the run after that step with status `interrupted` and a complete file, and
    frictherm.run raises KeyboardInterrupt saying where the run is; Python's handler is back after.
    (Were the signal left to Python's handler, the observer itself would raise, and the file would
    not say `interrupted`.)"""
    import signal
    out = os.path.join(workdir, "ctrl_c.h5")
    seen = []

    def observer(step):
        seen.append(step.step)
        if step.step == 30:
            os.kill(os.getpid(), signal.SIGINT)

    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt) as e:
        frictherm.run(frictherm.load_scene(SCENE).set("run.end_time", END), output=out, threads=1, observer=observer)
    assert "holds the run so far" in str(e.value) and out in str(e.value)
    assert signal.getsignal(signal.SIGINT) is before
    assert seen[-1] in (30, 31) and seen == list(range(1, seen[-1] + 1))  # ends after the current step
    with frictherm.open(out) as r:
        assert r.status == "interrupted"
        assert r.series["step"][-1] == seen[-1] and len(r.snapshots) >= 1
