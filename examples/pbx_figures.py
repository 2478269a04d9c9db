#!/usr/bin/python3
"""The PBX hot-spot study of Nairn, Bardenhagen & Smith (2018), section 3: run
examples/pbx_compaction.json (or another scene) and draw it, or sweep the CFL factor (figure 9).

  pbx_figures.py [--scene S] [--frictherm PATH] [--out DIR] [--threads N] [--set KEY=VALUE ...]
  pbx_figures.py --redraw RUN.h5 [--out DIR]     # draw an existing run again, without rerunning
  pbx_figures.py --cfl-sweep C1 C2 ... [--scene S] [--out DIR]

One run writes DIR/<scene>.h5 and
  DIR/<scene>_temperature.png   particles coloured by temperature at the end of loading, with the
                                hot spots of that moment circled (equivalent diameter) and numbered
  DIR/<scene>_hotspots.png      the same particles coloured by material (grains, binder, walls)
  DIR/<scene>_series.png        frictional work (both orders), plastic work, heat delivered, the
                                hottest temperature and the hot-spot count against time
and prints the hot-spot fates of the thermal-only continuation (/hotspot_fates) when there are any.
--cfl-sweep runs the scene (mechanics and heating only: the thermal blocks are left in but the
continuation is dropped) at each C and draws DIR/<scene>_fig9_work_vs_cfl.png, the total frictional
work of the loading against C for both orders. Reads runs through the frictherm Python package
(python/frictherm). Uses python3-h5py, python3-matplotlib, python3-numpy.
"""
import argparse
import os
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import frictherm  # noqa: E402
from frictherm.plot import draw_hotspots, plot_particles, plot_series  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
FATES = {0: "undecided", 1: "dying", 2: "runaway"}


def run(a, out, extra):
    cmd = [a.frictherm, "run", a.scene, "-o", out, "--force", "--quiet"]
    if a.threads:
        cmd += ["--threads", str(a.threads)]
    for s in a.set + extra:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t0


def end_of_loading(r):
    """The snapshot nearest the end of the mechanics (meta end_time, else the last)."""
    t_end = r.meta.get("end_time")
    return r.snapshots[-1] if t_end is None else r.snapshot_at(t_end)


def draw(out, prefix, wall=None):
    """The three pictures of one run file and its hot-spot fates."""
    with frictherm.open(out) as r:
        snap = end_of_loading(r)
        plot_particles(r, snap, "temperature", prefix + "_temperature.png")
        n = draw_hotspots(r, snap, prefix + "_temperature.png")
        plot_particles(r, snap, "material", prefix + "_hotspots.png")
        cols = [c for c in ("friction_work_first", "friction_work_second", "plastic_work", "heat_delivered",
                            "max_temperature", "hotspot_count") if c in r.series]
        plot_series(r, cols, prefix + "_series.png")
        took = "" if wall is None else "%.1f s wall, " % wall
        print("%s: %s%d hot spots at the end of loading" % (out, took, n))
        hf = r.hotspot_fates
        for i in range(len(hf)):
            ttr = hf["time_to_runaway"][i]
            print("  hot spot %d: %s (peak %.1f K -> %.1f K%s)" % (
                hf["id"][i], FATES.get(int(hf["fate"][i]), "?"), hf["initial_peak_temperature"][i],
                hf["final_peak_temperature"][i], "" if not np.isfinite(ttr) else ", runaway after %.3g s" % ttr))
    print("wrote %s_temperature.png, _hotspots.png, _series.png" % prefix)


def one_run(a):
    name = os.path.splitext(os.path.basename(a.scene))[0]
    out = os.path.join(a.out, name + ".h5")
    wall = run(a, out, [])
    draw(out, os.path.join(a.out, name), wall)


def cfl_sweep(a):
    name = os.path.splitext(os.path.basename(a.scene))[0]
    cs = sorted(a.cfl_sweep, reverse=True)
    w1, w2, walls = [], [], []
    for c in cs:
        out = os.path.join(a.out, "%s_C%g.h5" % (name, c))
        walls.append(run(a, out, ["solver.cfl=%r" % c, "coupling.continuation=null"]))
        with frictherm.open(out) as r:
            w1.append(float(r.series["friction_work_first"][-1]))
            w2.append(float(r.series["friction_work_second"][-1]))
        print("C = %-6g W1 = %.5e J  W2 = %.5e J  (%.1f s)" % (c, w1[-1], w2[-1], walls[-1]))
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.semilogx(cs, w1, "o-", label="first order")
    ax.semilogx(cs, w2, "s-", label="second order")
    ax.set_xlabel("CFL factor C")
    ax.set_ylabel("total frictional work (J per m of thickness)")
    ax.set_title("PBX compaction (Nairn et al. 2018, fig. 9)")
    ax.legend()
    fig.tight_layout()
    png = os.path.join(a.out, name + "_fig9_work_vs_cfl.png")
    fig.savefig(png, dpi=150)
    print("wrote", png)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=os.path.join(HERE, "pbx_compaction.json"))
    ap.add_argument("--frictherm", default=os.path.join(HERE, "..", "build", "coupling", "frictherm"))
    ap.add_argument("--out", default="results")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--cfl-sweep", type=float, nargs="+")
    ap.add_argument("--redraw", metavar="RUN.h5", help="draw an existing run file instead of running the scene")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.redraw:
        draw(a.redraw, os.path.join(a.out, os.path.splitext(os.path.basename(a.redraw))[0]))
    elif a.cfl_sweep:
        cfl_sweep(a)
    else:
        one_run(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
