"""The installed frictherm Python package (under PREFIX) reads the consumer's run file:
check_python.py PREFIX RUN.h5. The free-falling block's momentum follows p_y(t) = -g t M exactly."""
import os
import sys

import frictherm

prefix, path = sys.argv[1], sys.argv[2]
assert os.path.realpath(frictherm.__file__).startswith(os.path.realpath(prefix)), frictherm.__file__
with frictherm.open(path) as run:
    s = run.series
    assert run.status == "completed" and run.meta["steps"] == s["step"][-1] > 0, run
    mass = run.snapshots[0]["mass"].sum()
    expected = -9.81 * s["time"] * mass
    err = abs(s["momentum_y"] - expected).max()
    assert err <= 1e-9 * abs(expected).max(), err
    print(f"installed frictherm package: {run}, momentum_y = -g t M within {err:.2e}")
