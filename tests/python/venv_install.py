"""`pip install ./python` into a fresh `python3 -m venv --system-site-packages`, then the installed
package (not the source tree) reads a real run: the route docs/python.md gives a new user. First the
reader alone (FRICTHERM_NATIVE=none: frictherm.run then raises ImportError naming pybind11), then,
when $FRICTHERM_BUILD_DIR holds the compiled bindings, again with them (python/setup.py copies
frictherm/_native into the venv), and the venv runs a scene with an observer.

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

# With the bindings (FRICTHERM_BUILD_DIR given to pip): the venv's own frictherm/_native runs a scene.
CHECK_NATIVE = textwrap.dedent("""
    import os, sys
    import frictherm, frictherm._native
    venv, scene, out = sys.argv[1:4]
    assert os.path.realpath(frictherm._native.__file__).startswith(os.path.realpath(venv)), frictherm._native.__file__
    steps = []
    r = frictherm.run(frictherm.load_scene(scene).set("run.end_time", 2e-5), output=out, threads=1,
                      observer=lambda s: steps.append(s.series["time"]))
    assert r["status"] == "completed" and r["steps"] == len(steps) > 5, (r, len(steps))
    with frictherm.open(out) as run:
        assert run.series["time"][-1] == steps[-1]
    print("installed bindings", frictherm._native.__file__, "ran", r["steps"], "steps")
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
        subprocess.run([python, "-c", CHECK_NATIVE, venv, scene, os.path.join(workdir, "bar.h5")], check=True,
                       cwd=workdir, env=env)
    else:
        print(f"no compiled bindings in {build}: the install with them is not checked")


if __name__ == "__main__":
    main(*sys.argv[1:3])
