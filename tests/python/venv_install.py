"""`pip install ./python` into a fresh `python3 -m venv --system-site-packages`, then the installed
package (not the source tree) reads a real run: the route docs/python.md gives a new user.

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
    subprocess.run([pip, "install", "--quiet", "--no-index", "--no-build-isolation", src], check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    subprocess.run([os.path.join(venv, "bin", "python"), "-c", CHECK, venv, os.path.abspath(run_file)],
                   check=True, cwd=workdir, env=env)


if __name__ == "__main__":
    main(*sys.argv[1:3])
