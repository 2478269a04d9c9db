#!/usr/bin/python3
"""The PBX hot-spot study of Nairn, Bardenhagen & Smith (2018), section 3: run
examples/pbx_compaction.json (or another scene) and draw it, or sweep the CFL factor (figure 9).

  pbx_figures.py [--scene S] [--frictherm PATH] [--out DIR] [--threads N] [--set KEY=VALUE ...]
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
work of the loading against C for both orders. Uses python3-h5py, python3-matplotlib, python3-numpy.
"""
import argparse
import os
import subprocess
import sys
import time

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import plot_run  # noqa: E402

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


def end_of_loading(f):
    """The snapshot nearest the end of the mechanics (meta end_time, else the last)."""
    groups = [(k, g) for k, g in plot_run.snapshot_groups(f) if k != "failure"]
    t_end = float(f["meta"]["end_time"][()]) if "meta" in f and "end_time" in f["meta"] else None
    if t_end is None:
        return groups[-1]
    return min(groups, key=lambda kg: abs(float(kg[1].attrs.get("time", 0.0)) - t_end))


def draw_hotspots(f, g, png):
    """Circles of the hot spots alive at the snapshot's time on the temperature picture."""
    if "hotspots" not in f or "time" not in f["hotspots"]:
        return 0
    h = {k: np.asarray(f["hotspots"][k]) for k in f["hotspots"]}
    t = float(g.attrs.get("time", 0.0))
    times = np.unique(h["time"])
    if times.size == 0:
        return 0
    tn = times[np.argmin(np.abs(times - t))]
    sel = h["time"] == tn
    img = plt.imread(png)
    fig = plt.figure(figsize=(7.5, 6), dpi=120)
    fig.figimage(img, 0, 0)
    ax = fig.add_axes([0.12, 0.1, 0.7, 0.8])  # the same box as plot_run.plot_particles
    dim = plot_run.dim_of(f, g)
    pos = np.asarray(g["position"], dtype=float).reshape(-1, dim)
    side = plot_run.particle_side(f, g, pos, dim)
    pad = float(np.max(side))
    lo, hi = pos[:, :2].min(axis=0) - pad, pos[:, :2].max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.patch.set_alpha(0.0)
    ax.set_axis_off()
    for x, y, d, i in zip(h["centroid_x"][sel], h["centroid_y"][sel], h["equivalent_diameter"][sel], h["id"][sel]):
        ax.add_patch(plt.Circle((x, y), max(d, 2 * pad) / 2, fill=False, color="cyan", lw=1.2))
        ax.annotate("%d" % i, (x, y), color="cyan", fontsize=7, xytext=(4, 4), textcoords="offset points")
    fig.savefig(png)
    plt.close(fig)
    return int(sel.sum())


def one_run(a):
    name = os.path.splitext(os.path.basename(a.scene))[0]
    out = os.path.join(a.out, name + ".h5")
    wall = run(a, out, [])
    with h5py.File(out, "r") as f:
        label, g = end_of_loading(f)
        prefix = os.path.join(a.out, name)
        plot_run.plot_particles(f, g, label, "temperature", prefix + "_temperature.png")
        n = draw_hotspots(f, g, prefix + "_temperature.png")
        plot_run.plot_particles(f, g, label, "material", prefix + "_hotspots.png")
        cols = [c for c in ("friction_work_first", "friction_work_second", "plastic_work", "heat_delivered",
                            "max_temperature", "hotspot_count") if c in plot_run.series_columns(f)]
        plot_run.plot_series(f, cols, prefix + "_series.png")
        print("%s: %.1f s wall, %d hot spots at the end of loading" % (out, wall, n))
        if "hotspot_fates" in f:
            hf = {k: np.asarray(f["hotspot_fates"][k]) for k in f["hotspot_fates"]}
            for i in range(len(hf["id"])):
                print("  hot spot %d: %s (peak %.1f K -> %.1f K%s)" % (
                    hf["id"][i], FATES.get(int(hf["fate"][i]), "?"), hf["initial_peak_temperature"][i],
                    hf["final_peak_temperature"][i],
                    "" if not np.isfinite(hf["time_to_runaway"][i]) else ", runaway after %.3g s" % hf["time_to_runaway"][i]))
    print("wrote %s_temperature.png, _hotspots.png, _series.png" % prefix)


def cfl_sweep(a):
    name = os.path.splitext(os.path.basename(a.scene))[0]
    cs = sorted(a.cfl_sweep, reverse=True)
    w1, w2, walls = [], [], []
    for c in cs:
        out = os.path.join(a.out, "%s_C%g.h5" % (name, c))
        walls.append(run(a, out, ["solver.cfl=%r" % c, "coupling.continuation=null"]))
        with h5py.File(out, "r") as f:
            w1.append(float(f["series"]["friction_work_first"][-1]))
            w2.append(float(f["series"]["friction_work_second"][-1]))
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
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.cfl_sweep:
        cfl_sweep(a)
    else:
        one_run(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
