#!/usr/bin/python3
"""Work-precision chart of the contact methods on the sliding block (examples/sliding_block.json,
Nairn et al. 2018 figure 2): multimaterial contact with uGIMP against penalty contact on boundary
points (Kakouris et al. 2024) with uGIMP, the quadratic B-spline (OBS) and the extended B-spline (EBS).

  contact_work_precision.py [--frictherm PATH] [--out PNG] [--csv CSV] [--full] [--check]

Each run is `frictherm run sliding_block.json --threads 1` with --set grid.cell_size (5, 2.5, 1.25 mm;
the bodies' edges lie on grid lines at every one) and --set solver.cfl. Errors against the rigid block
(appendix eqs. 46-54, class RigidBlock of sliding_block_figures.py):
  velocity: max |v - v_rigid| over the sliding phase (t >= onset) / v_max;
  work:     |W(tf) - Q(tf)| / Q(tf), W the frictional work of the run, Q the rigid block's.
Wall time is the run's (one thread). A run that blows up is listed and left off the chart.
Default sweep (about 3 minutes): every method at 5 and 2.5 mm with C = 0.5 and 0.25, and 1.25 mm at
C = 0.5 for the uGIMP methods; --full adds 1.25 mm for every method and C = 0.125.
--check exits 1 unless the facts measured when the chart was made still hold (see CHECKS).
Uses the Debian packages python3-h5py (through the frictherm package), python3-matplotlib and python3-numpy; runs headless.
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import frictherm  # noqa: E402  (python/frictherm, the reader of run files)

HERE = os.path.dirname(os.path.abspath(__file__))
from sliding_block_figures import RigidBlock, TF, V_MAX  # noqa: E402

SCENE = os.path.join(HERE, "sliding_block.json")
METHODS = [  # name, marker, --set overrides
    ("multimaterial uGIMP", "o", []),
    ("penalty uGIMP", "s", ["contact.method=penalty"]),
    ("penalty OBS", "^", ["contact.method=penalty", "solver.shape_function=quadratic_bspline"]),
    ("penalty EBS", "D", ["contact.method=penalty", "solver.shape_function=extended_bspline"]),
]
CHECKS = """robust facts (measured when the chart was made; see docs/penalty_contact.md, "Work-precision"):
  * every multimaterial and penalty uGIMP/OBS run completes;
  * at C = 0.5 each of those methods' velocity error at 2.5 mm is below its error at 5 mm;
  * every completed run's velocity error is below 7 % of v_max and its work error below 5 %."""


def sweep(full):
    runs = []
    for name, _, _ in METHODS:
        for cell in (0.005, 0.0025, 0.00125):
            for cfl in (0.5, 0.25, 0.125):
                if cfl == 0.125 and not full:
                    continue
                if cell == 0.00125 and not full and (cfl != 0.5 or "uGIMP" not in name):
                    continue
                if cell == 0.00125 and cfl == 0.125:
                    continue
                runs.append((name, cell, cfl))
    return runs


def run_one(exe, tmp, name, cell, cfl):
    sets = dict((m[0], m[2]) for m in METHODS)[name]
    out = os.path.join(tmp, "run.h5")
    cmd = [exe, "run", SCENE, "-o", out, "--force", "--threads", "1", "--quiet",
           "--set", "grid.cell_size=%r" % cell, "--set", "solver.cfl=%r" % cfl]
    for s in sets:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        return dict(method=name, cell=cell, cfl=cfl, wall=wall, ok=False, v_err=np.nan, w_err=np.nan,
                    note=p.stderr.strip().splitlines()[-1][:160] if p.stderr.strip() else "failed")
    with frictherm.open(out) as r:
        s = r.series
        t, v, w = s["time"], s["mean_velocity_x.block"], s["friction_work_first"]
    rigid = RigidBlock(0.2, 0.2)
    sliding = t >= rigid.onset
    v_err = float(np.max(np.abs(v[sliding] - rigid.velocity(t[sliding]))) / V_MAX)
    q = float(rigid.work(TF))
    w_err = abs(float(w[-1]) - q) / q
    return dict(method=name, cell=cell, cfl=cfl, wall=wall, ok=True, v_err=v_err, w_err=w_err, note="")


def chart(rows, png):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for i, (name, marker, _) in enumerate(METHODS):
        ok = [r for r in rows if r["method"] == name and r["ok"]]
        if not ok:
            continue
        for ax, key in zip(axes, ("v_err", "w_err")):
            for cfl, fill in ((0.5, "full"), (0.25, "none"), (0.125, "none")):
                sel = sorted((r for r in ok if r["cfl"] == cfl), key=lambda r: -r["cell"])
                if not sel:
                    continue
                ax.loglog([r["wall"] for r in sel], [max(r[key], 1e-6) for r in sel], marker=marker,
                          color="C%d" % i, fillstyle=fill, ls="-" if cfl == 0.5 else (":" if cfl == 0.25 else "-."),
                          label="%s, C = %g" % (name, cfl))
                for r in sel:
                    ax.annotate("%g" % (r["cell"] * 1e3), (r["wall"], max(r[key], 1e-6)), fontsize=6,
                                xytext=(3, 3), textcoords="offset points")
    axes[0].set_ylabel("max |v - v_rigid| / v_max (sliding phase)")
    axes[1].set_ylabel("|W - Q| / Q at t_f (frictional work)")
    for ax in axes:
        ax.set_xlabel("wall time, one thread (s)")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=6)
    failed = [r for r in rows if not r["ok"]]
    title = "Sliding block: contact methods (labels: cell size, mm)"
    if failed:
        title += "; blew up: " + ", ".join("%s %g mm C=%g" % (r["method"], r["cell"] * 1e3, r["cfl"]) for r in failed)
    fig.suptitle(title, fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=130)


def check(rows):
    bad = []
    robust = [m[0] for m in METHODS if m[0] != "penalty EBS"]
    for r in rows:
        if r["method"] in robust and not r["ok"]:
            bad.append("%s %g mm C=%g blew up" % (r["method"], r["cell"] * 1e3, r["cfl"]))
        if r["ok"] and not (r["v_err"] < 0.07 and r["w_err"] < 0.05):
            bad.append("%s %g mm C=%g: errors %.4f, %.4f" % (r["method"], r["cell"] * 1e3, r["cfl"], r["v_err"], r["w_err"]))
    for name in robust:
        e = {r["cell"]: r["v_err"] for r in rows if r["method"] == name and r["cfl"] == 0.5 and r["ok"]}
        if 0.005 in e and 0.0025 in e and not e[0.0025] < e[0.005]:
            bad.append("%s: velocity error does not fall from 5 to 2.5 mm (%.4f -> %.4f)" % (name, e[0.005], e[0.0025]))
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frictherm", default=os.path.join(HERE, "..", "build", "coupling", "frictherm"))
    ap.add_argument("--out", default=os.path.join(HERE, "..", "results", "contact_work_precision.png"))
    ap.add_argument("--csv", default=None, help="also write the table (default: next to --out)")
    ap.add_argument("--full", action="store_true", help="1.25 mm for every method and C = 0.125 too (~15 min)")
    ap.add_argument("--check", action="store_true", help="exit 1 unless the measured facts hold:\n" + CHECKS)
    a = ap.parse_args()
    if not os.access(a.frictherm, os.X_OK):
        sys.exit("frictherm not found at %s (build first, or pass --frictherm)" % a.frictherm)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, cell, cfl in sweep(a.full):
            r = run_one(a.frictherm, tmp, name, cell, cfl)
            rows.append(r)
            print("%-20s %5.2f mm  C = %-5g  %7.2f s  " % (name, cell * 1e3, cfl, r["wall"]) +
                  ("velocity %.4f  work %.4f" % (r["v_err"], r["w_err"]) if r["ok"] else "BLEW UP: " + r["note"]),
                  flush=True)
    chart(rows, a.out)
    out_csv = a.csv or os.path.splitext(a.out)[0] + ".csv"
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["method", "cell", "cfl", "wall", "ok", "v_err", "w_err", "note"])
        w.writeheader()
        w.writerows(rows)
    print("wrote", a.out, "and", out_csv)
    if a.check:
        bad = check(rows)
        if bad:
            sys.exit("check failed:\n  " + "\n  ".join(bad))
        print("check passed")


if __name__ == "__main__":
    main()
