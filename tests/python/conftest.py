"""Small real runs of the frictherm program, made once per pytest session.

FRICTHERM_EXE (the program), FRICTHERM_SOURCE_DIR and FRICTHERM_TEST_DIR come from ctest
(tests/python/CMakeLists.txt)."""
import os
import shutil
import subprocess

import pytest

SOURCE = os.environ.get("FRICTHERM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCENE = os.path.join(SOURCE, "examples", "sliding_block_heating.json")
# The sliding block with heat (the README's main example), every mechanics step in the series so
# that each snapshot has its series row, and 2 ms of conduction alone instead of 20 ms.
SETS = ["output.series_interval=0", "coupling.continuation.duration=0.002", "coupling.continuation.intervals=10"]


def _exe():
    exe = os.environ.get("FRICTHERM_EXE", os.path.join(SOURCE, "build", "coupling", "frictherm"))
    if not os.path.exists(exe):
        pytest.fail(f"the frictherm program is missing: {exe} (set FRICTHERM_EXE)")
    return exe


@pytest.fixture(scope="session")
def workdir():
    d = os.environ.get("FRICTHERM_TEST_DIR") or os.path.join(os.getcwd(), "frictherm_python_test")
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def _sets(sets):
    out = []
    for s in sets:
        out += ["--set", s]
    return out


@pytest.fixture(scope="session")
def run_file(workdir):
    out = os.path.join(workdir, "run.h5")
    subprocess.run([_exe(), "run", SCENE, "-o", out, "--quiet", "--threads", "1"] + _sets(SETS), check=True)
    return out


@pytest.fixture(scope="session")
def ensemble_file(workdir):
    out = os.path.join(workdir, "ens.h5")
    # A harmless integer key stands in for a microstructure seed (as in tests/coupling/test_ensemble.cpp).
    subprocess.run([_exe(), "ensemble", SCENE, "--seed-key", "output.snapshot_count", "--first-seed", "2", "-n", "2",
                    "-o", out, "--quiet", "--threads", "1"] + _sets(SETS[1:]), check=True)
    return out


@pytest.fixture(scope="session")
def decomposed_pair(workdir):
    """The small decomposed sliding block (tests/coupling/scenes) run serially and on 2 ranks: the
    decomposed run's snapshots live in OUT.rank<r>.h5 (frictherm/ranks.py joins them)."""
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec is not installed")
    scene = os.path.join(SOURCE, "tests", "coupling", "scenes", "decomposed_sliding_block.json")
    serial, decomposed = os.path.join(workdir, "serial.h5"), os.path.join(workdir, "decomposed.h5")
    subprocess.run([_exe(), "run", scene, "-o", serial, "--quiet", "--threads", "1"], check=True)
    subprocess.run([mpiexec, "-n", "2", "--oversubscribe", "--allow-run-as-root", _exe(), "run", scene, "-o", decomposed,
                    "--quiet"], check=True)
    return serial, decomposed


# A small 3D run with a rigid material: a rubber cube thrown at 1 m/s onto a rigid floor, 0.2 ms
# (one snapshot at the end; 1440 particles, 288 of them the floor's). For the 3D pictures.
CUBE_3D = {
    "units": "SI", "dimension": 3,
    "grid": {"lo": [0, 0, 0], "hi": [0.02, 0.02, 0.02], "cell_size": 0.002},
    "materials": {"rubber": {"type": "neo_hookean", "density": 1100, "youngs_modulus": 5e6, "poisson_ratio": 0.4},
                  "floor": {"type": "rigid", "boundary": True, "velocity": [None, None, 0.0]}},
    "bodies": [{"name": "cube", "material": "rubber", "velocity": [0.0, 0.0, -1.0],
                "shape": {"type": "box", "lo": [0.004, 0.004, 0.004], "hi": [0.016, 0.016, 0.012]}},
               {"name": "floor", "material": "floor",
                "shape": {"type": "box", "lo": [0.004, 0.004, 0.002], "hi": [0.016, 0.016, 0.004]}}],
    "run": {"end_time": 2e-4}, "output": {"snapshot_count": 1}}


@pytest.fixture(scope="session")
def run_file_3d(workdir):
    import json
    scene, out = os.path.join(workdir, "cube_3d.json"), os.path.join(workdir, "cube_3d.h5")
    with open(scene, "w") as f:
        json.dump(CUBE_3D, f)
    subprocess.run([_exe(), "run", scene, "-o", out, "--quiet", "--threads", "1"], check=True)
    return out
