"""`pip install ./python` into a fresh `python3 -m venv --system-site-packages`, then the installed
package (not the source tree) reads a real run: the route docs/python.md gives a new user. First the
reader alone (FRICTHERM_NATIVE=none: frictherm.run then raises ImportError naming pybind11), then,
when $FRICTHERM_BUILD_DIR holds the compiled bindings, again with them (python/setup.py copies
frictherm/_native into the venv), and the venv's package does what issue 33 checks: it runs the
vibrating bar with an observer at two CFL factors (solver.cfl 0.5 and 0.25), and each run's series
equal those of the frictherm program's own run of the same scene with the same --set values
($FRICTHERM_EXE) to round-off (every column, relative 1e-12); the observer saw every mechanics step
and the series rows the file holds; and every dataset of all four files carries `units` and
`long_name`. $FRICTHERM_EXPECT_NATIVE=1 (set by ctest when CMake built the bindings) makes missing
bindings a failure instead of a note.

usage: venv_install.py WORKDIR RUN.h5   (RUN.h5: a small run of the frictherm program, made by the
ctest fixture python.run_file). Offline: pip gets --no-index and --no-build-isolation (Debian's
setuptools builds the package)."""
import os
import shutil
import subprocess
import sys
import textwrap

SOURCE = os.environ["FRICTHERM_SOURCE_DIR"]

# What the installed package must do on the run file (in the venv, with no PYTHONPATH).
CHECK = textwrap.dedent("""
    import os, sys, json
    import frictherm
    venv = sys.argv[1]
    assert os.path.realpath(frictherm.__file__).startswith(os.path.realpath(venv)), frictherm.__file__
    with frictherm.open(sys.argv[2]) as run:
        assert len(run.series.to_dataframe()) == len(run.series) > 2, len(run.series)
        t = run.series["time"]
        assert (t[1:] > t[:-1]).all(), "series time not increasing"
        assert run.snapshots and "temperature" in run.snapshot("last").fields
        # Self-describing (issue 33 item 2): time index, units, plain JSON scene, xarray.
        df = run.series.to_dataframe()
        assert df.index.name == "time" and df.attrs["units"]["kinetic_energy"] == "J"
        assert run.unit_of("max_temperature") == "K"
        assert len(run.snapshot("last").to_dataframe()) == run.snapshot("last").particle_count
        assert isinstance(json.loads(run.meta["scene_json"]), dict)
        assert run.to_xarray()["temperature"].attrs["units"] == "K"
    print("installed frictherm", frictherm.__version__, "read", sys.argv[2])
""")

# With the bindings (FRICTHERM_BUILD_DIR given to pip): the venv's own frictherm/_native runs the bar
# at two CFL factors with an observer; the program runs the same scene with the same --set values.
CHECK_NATIVE = textwrap.dedent("""
    import os, subprocess, sys
    import h5py, numpy as np
    import frictherm, frictherm._native
    venv, scene_file, exe, workdir = sys.argv[1:5]
    assert os.path.realpath(frictherm._native.__file__).startswith(os.path.realpath(venv)), frictherm._native.__file__
    END = 2e-4  # s: a quarter of the bar's period (~440 steps at C = 0.5)

    def without_units(path):  # (datasets lacking `units` or `long_name`, number of datasets)
        found = []
        with h5py.File(path, "r") as f:
            f.visititems(lambda n, o: found.append((n, "units" in o.attrs and "long_name" in o.attrs))
                         if isinstance(o, h5py.Dataset) else None)
        return [n for n, ok in found if not ok], len(found)

    def series(path):
        with frictherm.open(path) as r:
            return {c: np.asarray(r.series[c], dtype=float) for c in r.series.columns}

    steps_of = {}
    base = frictherm.load_scene(scene_file).set("run.end_time", END)
    for cfl in (0.5, 0.25):  # the sweep: a loop over solver.cfl
        seen, rows = [], []
        def observer(s):
            seen.append((s.step, s.time, s.kinetic_energy, float(np.sum(s.particles()["mass"]))))
            if s.series_new:
                rows.append(dict(s.series))
        py_out = os.path.join(workdir, f"py_cfl{cfl}.h5")
        r = frictherm.run(base.copy().set("solver.cfl", cfl), output=py_out, threads=1, observer=observer)
        assert r["status"] == "completed" and r["steps"] == len(seen) > 50, (r, len(seen))
        assert [s[0] for s in seen] == list(range(1, len(seen) + 1)), "observer missed steps"
        assert all(s[3] > 0 for s in seen), "particle views without mass"
        cli_out = os.path.join(workdir, f"cli_cfl{cfl}.h5")
        subprocess.run([exe, "run", scene_file, "-o", cli_out, "--force", "--quiet", "--threads", "1",
                        "--set", f"run.end_time={END}", "--set", f"solver.cfl={cfl}"], check=True,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
        a, b = series(py_out), series(cli_out)
        assert list(a) == list(b) and len(a["time"]) == len(b["time"]) > 10, (list(a), list(b))
        worst = 0.0
        for c in a:
            assert np.allclose(a[c], b[c], rtol=1e-12, atol=1e-300, equal_nan=True), (cfl, c)
            scale = np.maximum(np.abs(b[c]), 1e-300)
            d = np.abs(a[c] - b[c])[np.isfinite(b[c])] / scale[np.isfinite(b[c])]
            worst = max(worst, float(d.max()) if d.size else 0.0)
        # The observer's rows are the file's rows after the first (t = 0, written before any step).
        assert len(rows) == len(a["time"]) - 1, (len(rows), len(a["time"]))
        for c in a:
            assert np.array_equal(np.array([row[c] for row in rows], dtype=float), a[c][1:], equal_nan=True), c
        for path in (py_out, cli_out):
            missing, count = without_units(path)
            assert count > 20 and missing == [], (path, missing)
        steps_of[cfl] = r["steps"]
        print(f"C = {cfl}: {r['steps']} steps, {len(a)} series columns x {len(a['time'])} rows equal the "
              f"program's (largest relative difference {worst:.1e}); {count} datasets, all with units and long_name")
    # Halving C about doubles the steps: the sweep really changed the run.
    assert 1.8 < steps_of[0.25] / steps_of[0.5] < 2.2, steps_of
    print("installed bindings", frictherm._native.__file__)
""")

# Without them: the reader installs and works, and frictherm.run says what is missing.
CHECK_PURE = textwrap.dedent("""
    import frictherm
    assert frictherm.native._native is None
    try:
        frictherm.validate({"dimension": 2})
        raise SystemExit("validate ran without the bindings")
    except ImportError as e:
        assert "pybind11" in str(e), e
    print("reader only: frictherm.validate raises ImportError naming pybind11")
""")


def main(workdir, run_file):
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    venv = os.path.join(workdir, "venv")
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv], check=True)
    # A copy of python/ so that the build (setuptools writes build/ and *.egg-info beside
    # pyproject.toml) leaves the source tree untouched.
    src = os.path.join(workdir, "python")
    shutil.copytree(os.path.join(SOURCE, "python"), src,
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    pip = os.path.join(venv, "bin", "pip")
    python = os.path.join(venv, "bin", "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "FRICTHERM_BUILD_DIR")}
    # The reader alone (no compiled bindings), then with them when the build made them.
    subprocess.run([pip, "install", "--quiet", "--no-index", "--no-build-isolation", src], check=True,
                   env=dict(env, FRICTHERM_NATIVE="none"))
    subprocess.run([python, "-c", CHECK, venv, os.path.abspath(run_file)], check=True, cwd=workdir, env=env)
    subprocess.run([python, "-c", CHECK_PURE], check=True, cwd=workdir, env=env)
    build = os.environ.get("FRICTHERM_BUILD_DIR")
    if build and os.path.isdir(os.path.join(build, "python", "frictherm")) and any(
            f.startswith("_native") for f in os.listdir(os.path.join(build, "python", "frictherm"))):
        subprocess.run([pip, "install", "--quiet", "--no-index", "--no-build-isolation", "--force-reinstall",
                        "--no-deps", src], check=True, env=dict(env, FRICTHERM_BUILD_DIR=build))
        scene = os.path.join(SOURCE, "examples", "bar_vibration.json")
        subprocess.run([python, "-c", CHECK_NATIVE, venv, scene, os.environ["FRICTHERM_EXE"], workdir], check=True,
                       cwd=workdir, env=env)
    elif os.environ.get("FRICTHERM_EXPECT_NATIVE") == "1":
        raise SystemExit(f"venv_install.py: CMake built the bindings but {build}/python/frictherm has no _native module")
    else:
        print(f"no compiled bindings in {build}: the install with them is not checked")


if __name__ == "__main__":
    main(*sys.argv[1:3])
