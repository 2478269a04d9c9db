#!/usr/bin/python3
"""Work-precision chart of the thermal integrators on a hot spot cooling by conduction (issue 4,
chart b): error against wall time, log-log, one colour/marker per integrator, one line style per
number of coupling windows, each line running over the tolerances.

  thermal_work_precision.py [CSV] [--program PATH] [--csv OUT.csv] [--out PNG] [--quick] [--check]

With --program (bench/thermal_work_precision, built with the benchmarks) it runs the program
first and writes its CSV (default results/thermal_work_precision.csv); otherwise it reads CSV
(default that same file). The full run takes about 4 minutes (1000 windows re-assemble the
problem 1000 times per point); --quick runs a subset (1, 10 and 100 windows; rtol 1e-3, 1e-6,
1e-7, 1e-9; FE safety 0.2, 0.05, 0.01; arkode_dirk with pcg, whose rebuild is cheaper than KLU's)
in about 10 s. Writes results/thermal_work_precision.png
(--out).

The problem (see the program's header) is the 2D Gaussian pulse, HMX-like, on a 61x61 grid of
1 um cells, cooling from sigma = 4 to 6 um (40 forward-Euler limits), split into 1 to 1000
windows, each integrated as the coupler does (a re-assembled problem per window, so the SUNDIALS
integrators restart at order 1 every window). Forward Euler has no tolerance; its points run
over the safety factor (sub-step = safety x stability limit, capped by the window).

Two errors are measured at the end time. Against the analytic solution the error contains the
5-point grid's spatial error, about 0.86 K here (0.4 % of the final 222 K peak), which no time
integrator can go below: all points pile up on that floor. The left panel therefore shows the
integration error proper, against the semi-discrete reference (the same grid ODE solved by
cvode_bdf/klu at rtol 1e-12; its own error, estimated from an rtol 1e-11 solve, is ~1e-7 K and
drawn as the grey band); the right panel shows the error against the analytic solution, with
the spatial floor dashed. Forward Euler at safety 0.5 lands below the floor on the right: its
time error has the opposite sign to the spatial one and partly cancels it (a coincidence, not
accuracy).

What the chart shows: a restart per window costs CVODE its order. BDF and Adams restart at
order 1 with a small first step, so with windows shorter than a few dt_FE (100 and 1000 windows
here) they behave like first-order methods and their error stalls near forward Euler's at the
same step count (0.067 K at 1000 windows for every rtol >= 1e-6); ERK and DIRK are one-step
methods at full order from their first step and stay accurate.

--check asserts (exit 1 otherwise):
  * every run finished;
  * the reference is converged: its error is < 1e-4 of the spatial floor;
  * the spatial floor is that of the 5-point stencil: between 0.05 and 1 times the truncation
    (h/sigma0)^2/12 of the initial peak A (the largest relative truncation; it decays as the pulse
    widens);
  * CVODE (bdf/klu, bdf/pcg, adams), every window count: at rtol <= 1e-6 the integration error is
    below 25 % of the spatial floor and at rtol <= 1e-7 below 10 % of it (measured at most 16 %
    and 4.5 %; the usual advice rtol ~ 0.01 x the accuracy wanted, thermal-notes section 1, with
    |T| ~ 300-520 K would call 1e-6 enough for 10 %: with 100 restarts it is not);
  * every CVODE point is within the a-priori bound steps x rtol x max T0 (the semi-discrete heat
    equation contracts in the max norm, so the global error is at most the sum of the local
    errors, each held near rtol x |T| by the error test): measured at most 0.5 of it;
  * with 1 and 10 windows, tightening rtol from 1e-3 to 1e-9 cuts every SUNDIALS integrator's
    error by >= 100 x (with more windows ERK and DIRK are already at the reference's own error
    and CVODE is restart-limited);
  * forward Euler converges at first order: with one window, the slope of log(error) against
    log(sub-step) over safety <= 0.2 is within 0.95..1.05.
Uses python3-matplotlib and python3-numpy; runs headless.
"""
import argparse
import csv
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.normpath(os.path.join(HERE, "..", "results"))
QUICK = ["--windows", "1,10,100", "--rtols", "1e-3,1e-6,1e-7,1e-9", "--fe-safety", "0.2,0.05,0.01", "--integrators",
         "forward_euler,cvode_bdf/klu,cvode_bdf/pcg,cvode_adams,arkode_erk,arkode_dirk/pcg"]

# The program's set-up (bench/thermal_work_precision.cpp).
H, SIGMA0, AMPLITUDE, T_MAX = 1e-6, 4e-6, 500.0, 800.0

STYLE = {  # label -> (colour, marker)
    "forward_euler": ("black", "o"),
    "cvode_bdf/klu": ("tab:blue", "s"),
    "cvode_bdf/pcg": ("tab:cyan", "D"),
    "cvode_adams": ("tab:green", "^"),
    "arkode_erk": ("tab:orange", "v"),
    "arkode_dirk/klu": ("tab:red", "P"),
    "arkode_dirk/pcg": ("tab:pink", "X"),
}
LINESTYLE = {1: "-", 10: "--", 100: "-.", 1000: ":"}


def label(row):
    opt = row["option"]
    if row["integrator"] in ("forward_euler", "arkode_erk") or opt in ("", "fixed_point"):
        return row["integrator"]
    return row["integrator"] + "/" + opt


def read(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k in ("tolerance", "err_semi_max_K", "err_semi_l2_K", "err_analytic_max_K",
                      "err_analytic_l2_K", "wall_s"):
                r[k] = float(r[k])
            for k in ("windows", "steps", "rhs_evals"):
                r[k] = int(r[k])
            r["label"] = label(r)
            rows.append(r)
    return rows


def draw(rows, ref, png):
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5), sharex=True)
    runs = [r for r in rows if r["integrator"] != "reference" and r["status"] == "ok"]
    groups = {}
    for r in runs:
        groups.setdefault((r["label"], r["windows"]), []).append(r)
    for (lab, nw), pts in sorted(groups.items()):
        pts.sort(key=lambda r: -r["tolerance"])
        colour, marker = STYLE.get(lab, ("grey", "x"))
        for ax, key in zip(axes, ("err_semi_max_K", "err_analytic_max_K")):
            ax.plot([p["wall_s"] for p in pts], [max(p[key], 0.3 * ref["err_semi_max_K"]) for p in pts],
                    color=colour, marker=marker,
                    linestyle=LINESTYLE.get(nw, "-"), markersize=5, linewidth=1.1, alpha=0.85)
    lo = 0.3 * ref["err_semi_max_K"]
    axes[0].set_ylim(bottom=lo)
    axes[0].axhspan(lo, ref["err_semi_max_K"], color="0.88", zorder=0)
    axes[0].text(0.02, 0.02, "grey: below the reference's own error (unresolved)", transform=axes[0].transAxes,
                 fontsize=8)
    axes[0].set_title("integration error: max |T - T_semi-discrete| at t_end")
    axes[1].axhline(ref["err_analytic_max_K"], color="0.3", linestyle="--", linewidth=1)
    axes[1].text(0.98, 0.96, "dashed: spatial error of the 5-point grid (%.2f K)" % ref["err_analytic_max_K"],
                 transform=axes[1].transAxes, fontsize=8, ha="right", va="top")
    axes[1].set_title("total error: max |T - T_analytic| at t_end")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time for the whole run [s] (1 core)")
        ax.set_ylabel("error [K]")
        ax.grid(True, which="major", alpha=0.3)
    labels = sorted({r["label"] for r in runs}, key=list(STYLE).index)
    handles = [Line2D([], [], color=STYLE[lab][0], marker=STYLE[lab][1], linestyle="") for lab in labels]
    windows = sorted({r["windows"] for r in runs})
    handles += [Line2D([], [], color="k", linestyle=LINESTYLE.get(w, "-")) for w in windows]
    labels += ["%d window%s" % (w, "" if w == 1 else "s") for w in windows]
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8, frameon=False)
    fig.suptitle("Gaussian hot spot (2D, HMX-like, 61x61, 40 dt_FE) cooling over 1-1000 coupling windows: "
                 "rtol 1e-3..1e-9 (atol = rtol x 1 K), FE safety 0.9..0.01", fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=130)
    print("wrote", png)


def check(rows, ref):
    failures = []
    floor = ref["err_analytic_max_K"]
    bad = [r for r in rows if r["status"] != "ok"]
    if bad:
        failures.append("%d runs failed, e.g. %s: %s" % (len(bad), bad[0]["label"], bad[0]["status"]))
    if not ref["err_semi_max_K"] < 1e-4 * floor:
        failures.append("reference not converged: %.3g K vs floor %.3g K" % (ref["err_semi_max_K"], floor))
    trunc = (H / SIGMA0) ** 2 / 12 * AMPLITUDE
    if not 0.05 * trunc <= floor <= trunc:
        failures.append("spatial floor %.3g K outside [0.05, 1] x (h/sigma0)^2/12 A = %.3g K" % (floor, trunc))
    worst = {1e-6: 0.0, 1e-7: 0.0}
    bound = 0.0
    for r in rows:
        if r["label"] not in ("cvode_bdf/klu", "cvode_bdf/pcg", "cvode_adams"):
            continue
        err, rtol = r["err_semi_max_K"], r["tolerance"]
        a_priori = r["steps"] * rtol * T_MAX
        bound = max(bound, err / a_priori)
        if not err <= a_priori:
            failures.append("%s, %d windows, rtol %g: error %.3g K above steps x rtol x max T = %.3g K"
                            % (r["label"], r["windows"], rtol, err, a_priori))
        for level, frac in ((1e-6, 0.25), (1e-7, 0.1)):
            if rtol <= level * 1.0001:
                worst[level] = max(worst[level], err / floor)
                if not err < frac * floor:
                    failures.append("%s, %d windows, rtol %g: integration error %.3g K >= %g of the floor %.3g K"
                                    % (r["label"], r["windows"], rtol, err, frac, floor))
    print("CVODE integration error / spatial floor: at most %.3g at rtol <= 1e-6 (bound 0.25), %.3g at rtol <= 1e-7"
          " (bound 0.1); error / (steps rtol max T0) at most %.3g (bound 1)" % (worst[1e-6], worst[1e-7], bound))
    for (lab, nw) in sorted({(r["label"], r["windows"]) for r in rows if r["label"] != "forward_euler"}):
        e = {r["tolerance"]: r["err_semi_max_K"] for r in rows if r["label"] == lab and r["windows"] == nw}
        if 1e-3 in e and 1e-9 in e:
            gain = e[1e-3] / max(e[1e-9], 1e-300)
            print("%-16s %5d windows: error at rtol 1e-3 / at rtol 1e-9 = %.3g" % (lab, nw, gain))
            if nw <= 10 and not gain >= 100:
                failures.append("%s, %d windows: rtol 1e-3 -> 1e-9 cuts the error only %.3g x" % (lab, nw, gain))
    fe = sorted([r for r in rows if r["label"] == "forward_euler" and r["windows"] == 1 and r["tolerance"] <= 0.2],
                key=lambda r: r["tolerance"])
    if len(fe) >= 2:
        h = np.array([1.0 / r["steps"] for r in fe])  # sub-step = t_end/steps (equal sub-steps)
        err = np.array([r["err_semi_max_K"] for r in fe])
        slope = np.polyfit(np.log(h), np.log(err), 1)[0]
        print("forward Euler, 1 window: observed order %.4f over %d safety factors" % (slope, len(fe)))
        if not 0.95 <= slope <= 1.05:
            failures.append("forward Euler order %.3f outside 0.95..1.05" % slope)
    else:
        failures.append("need >= 2 forward Euler points with safety <= 0.2 and one window")
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv_in", nargs="?", help="CSV written by thermal_work_precision (default: --csv)")
    ap.add_argument("--program", help="run this thermal_work_precision binary first")
    ap.add_argument("--csv", default=os.path.join(RESULTS, "thermal_work_precision.csv"),
                    help="CSV the program writes (with --program) or that is read")
    ap.add_argument("--out", default=os.path.join(RESULTS, "thermal_work_precision.png"))
    ap.add_argument("--quick", action="store_true", help="with --program: a subset that runs in ~10 s")
    ap.add_argument("--check", action="store_true", help="assert the facts listed above; exit 1 on failure")
    a = ap.parse_args()
    path = a.csv_in or a.csv
    if a.program:
        os.makedirs(os.path.dirname(os.path.abspath(a.csv)), exist_ok=True)
        cmd = [a.program, "--out", a.csv] + (QUICK if a.quick else [])
        print(" ".join(cmd))
        subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
        path = a.csv
    rows = read(path)
    refs = [r for r in rows if r["integrator"] == "reference"]
    if not refs:
        sys.exit("%s: no reference row" % path)
    ref = refs[0]
    runs = [r for r in rows if r["integrator"] != "reference"]
    draw(runs, ref, a.out)
    if a.check:
        failures = check(runs, ref)
        for f in failures:
            print("FAIL:", f)
        if failures:
            sys.exit(1)
        print("check passed")


if __name__ == "__main__":
    main()
