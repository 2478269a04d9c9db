#!/usr/bin/python3
"""Thermal integrators compared on one PBX loading (issue 17): run the mechanics once, then rerun only
the thermal-only continuation from its end-of-loading checkpoint with each integrator
(`frictherm continue`), and compare hot-spot fates, peak temperatures and wall time.

  pbx_continue_integrators.py [--scene S] [--frictherm PATH] [--out DIR] [--threads N]
                              [--integrators I1 I2 ...] [--set KEY=VALUE ...] [--full] [--check]

Default: examples/pbx_microstructure_small.json with 2 us of compaction (--set run.end_time=...),
the HMX Arrhenius reaction after it (held back during loading), hot spots above a 3 K rise and 20 us
of conduction; --full runs examples/pbx_compaction.json as it is (1-2 minutes of loading; add
--set run.end_time=4e-6 for a shorter one). Explicit integrators get thermal.linear_solver=null. One
`frictherm run` writes DIR/pbx_loading.h5 and its end-of-loading checkpoint; each integrator then
gets DIR/pbx_<integrator>.h5 from `frictherm continue` (the loading copied, the continuation new).
Prints one line per integrator: hot spots, fates (dying / runaway / undecided), the hottest
hot-spot peak at the end, the largest difference of the final peaks from the first integrator's,
and the continuation's wall time next to the loading run's. --check exits 1 unless every integrator
gives the first one's hot spots and fates and final peaks within 0.05 K. Reads the results through
the frictherm Python package (python/frictherm). Uses python3-h5py and python3-numpy.
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np

import frictherm

HERE = os.path.dirname(os.path.abspath(__file__))
FATES = {0: "undecided", 1: "dying", 2: "runaway"}
EXPLICIT = ("forward_euler", "arkode_erk")
SMALL = [
    "run.end_time=2e-6",
    'thermal.reaction={"kinetics": "hmx_rogers1975", "materials": ["hmx"], "during_loading": false}',
    'coupling.hotspots={"mode": "rise", "threshold": 3.0, "min_particles": 2}',
    'coupling.continuation={"duration": 20e-6, "intervals": 20}',
]


def call(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t0


def summary(path):
    r = frictherm.open(path)
    f = r.hotspot_fates
    ids = np.asarray(f["id"]).astype(int)
    fates = np.asarray(f["fate"]).astype(int)
    final = np.asarray(f["final_peak_temperature"], dtype=float)
    return r, ids, fates, final


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=None)
    ap.add_argument("--frictherm", default=os.path.join(HERE, "..", "build", "coupling", "frictherm"))
    ap.add_argument("--out", default="results")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--integrators", nargs="+", default=["cvode_bdf", "cvode_adams", "forward_euler"])
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--full", action="store_true", help="examples/pbx_compaction.json as it is")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scene = a.scene or os.path.join(HERE, "pbx_compaction.json" if a.full else "pbx_microstructure_small.json")
    sets = ([] if a.full or a.scene else SMALL) + a.set
    threads = ["--threads", str(a.threads)] if a.threads else []
    loading = os.path.join(a.out, "pbx_loading.h5")
    cmd = [a.frictherm, "run", scene, "-o", loading, "--force", "--quiet"] + threads
    for s in sets:
        cmd += ["--set", s]
    wall_loading = call(cmd)
    r = frictherm.open(loading)
    print(f"loading: {scene} -> {loading}: {wall_loading:.2f} s wall "
          f"(integrator {r.meta.get('thermal_integrator')}, checkpoint {os.path.getsize(loading + '.checkpoint') / 1e6:.2f} MB)")
    first = None
    ok = True
    for integrator in a.integrators:
        out = os.path.join(a.out, f"pbx_{integrator}.h5")
        extra = ["--set", "thermal.linear_solver=null"] if integrator in EXPLICIT else []  # no linear solver
        wall = call([a.frictherm, "continue", loading, "-o", out, "--force", "--quiet",
                     "--set", f"thermal.integrator={integrator}"] + extra + threads)
        r, ids, fates, final = summary(out)
        counts = {name: int(np.sum(fates == k)) for k, name in FATES.items()}
        hottest = final.max() if final.size else float("nan")
        line = (f"{integrator:14s} {ids.size:3d} hot spots  " + " ".join(f"{n} {c}" for n, c in counts.items()) +
                f"  hottest final peak {hottest:.4f} K  continue {wall:.2f} s wall"
                f" ({r.meta.get('thermal_wall_time', float('nan')):.3f} s in the integrator)"
                f" vs {wall_loading:.2f} s for the loading run")
        if first is None:
            first = (ids, fates, final)
        else:
            same = np.array_equal(ids, first[0]) and np.array_equal(fates, first[1])
            dT = float(np.max(np.abs(final - first[2]))) if same and final.size else float("inf")
            line += f"  same fates as {a.integrators[0]}: {same}, max |dT_peak| {dT:.2e} K"
            ok = ok and same and dT < 0.05
        print(line)
    if a.check and not ok:
        print("check failed: the integrators disagree on the hot spots", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
