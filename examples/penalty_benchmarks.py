#!/usr/bin/python3
"""Benchmarks of penalty contact with Extended B-splines (Kakouris, Chatzis & Triantafyllou 2024,
sections 4.3-4.5), EBS against OBS (the plain quadratic B-spline), drawn as PNGs under results/penalty/.

  penalty_benchmarks.py hertz-disks [--levels 10 20 40] [--angle 0|45]   a against F, Hertz eq. 43
  penalty_benchmarks.py half-disk   [--levels 0.2 0.1 0.05]              sigma_yy of the contact row, RMSE eq. 45
  penalty_benchmarks.py rings       [--one-field]                        energies, von Mises snapshots
  penalty_benchmarks.py granular    [--levels 5 2.5 1.25]                photoelastic fringes, eqs. 49-50
  penalty_benchmarks.py all                                              the defaults of all four

Each runs build/coupling/frictherm on examples/<scene>.json with --set overrides (shape function,
cell size, ...), keeps the HDF5 files under results/penalty/ and reuses them when present (--rerun
runs again). Options: --frictherm PATH, --threads N, --out DIR, --shapes ebs obs.
Run times on this 2-core machine (defaults): hertz-disks ~3 min, half-disk ~5 min, rings ~2 min,
granular ~1 min; the finest levels (R/40, 0.05 mm, 1.25 mm) take far longer.
Uses python3-h5py (through the frictherm package), python3-matplotlib, python3-numpy; headless.
"""
import argparse
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import frictherm  # noqa: E402  (python/frictherm, the reader of run files)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHAPES = {"ebs": "extended_bspline", "obs": "quadratic_bspline"}
COLORS = {"ebs": "tab:blue", "obs": "tab:red"}


def in_plane_stress(stress):
    """(n, 2, 2) in-plane Cauchy stress of a 2D snapshot: the file stores the 3x3 tensor (n, 9) since
    format_version 2 (docs/output.md), (n, 4) before."""
    stress = np.asarray(stress, dtype=float)
    n = stress.shape[0]
    return stress.reshape(n, 3, 3)[:, :2, :2] if stress.size == 9 * n else stress.reshape(n, 2, 2)


def run(args, scene, tag, sets):
    """Runs frictherm on examples/<scene>.json with --set overrides; returns the output path."""
    out = os.path.join(args.out, f"{tag}.h5")
    if os.path.exists(out) and not args.rerun:
        print(f"reusing {out}")
        return out
    cmd = [args.frictherm, "run", os.path.join(HERE, scene + ".json"), "-o", out, "--force", "--quiet"]
    if args.threads:
        cmd += ["--threads", str(args.threads)]
    for key, value in sets.items():
        cmd += ["--set", f"{key}={value}"]
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    return out


def shape_sets(shape):
    """--set overrides selecting the shape function (the scenes' ebs_occupation only goes with EBS)."""
    sets = {"solver.shape_function": SHAPES[shape]}
    if shape != "ebs":
        sets["solver.ebs_occupation"] = "null"
    return sets


def series(path):
    with frictherm.open(path) as r:
        return r.series.as_dict()


def snapshots(path):
    """[(time, {field: array})] in time order."""
    out = []
    with frictherm.open(path) as r:
        for snap in r.snapshots:
            out.append((snap.time, {k: snap[k] for k in snap.fields}))
    out.sort(key=lambda s: s[0])
    return out


def save(fig, args, name):
    path = os.path.join(args.out, name)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")


# ---- Hertz, two disks (section 4.3.1) --------------------------------------------------------------
def hertz_disks(args):
    R, E, nu = 0.01, 9.453e10, 0.07
    Rs, Es = R / 2, E / (2 * (1 - nu * nu))
    F_max = math.pi * Es * (2e-3) ** 2 / (4 * Rs)  # the scene's load: a_Hertz = 2 mm
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    F = np.linspace(0, F_max, 200)
    ax.plot(F / 1e6, 1e3 * np.sqrt(4 * F * Rs / (math.pi * Es)), "k-", lw=2, label="Hertz (eq. 43)")
    markers = "os^v"
    for shape in args.shapes:
        for i, level in enumerate(args.levels):
            h = R / level
            sets = dict(shape_sets(shape), **{"grid.cell_size": h})
            if args.angle == 45:
                c = R / math.sqrt(2)
                sets.update({"grid.lo": "[-0.024,-0.024]", "grid.hi": "[0.024,0.024]",
                             "bodies[0].shape.center": f"[{-c},{-c}]", "bodies[1].shape.center": f"[{c},{c}]",
                             "loads.point[0].box": '{"lo":[-0.019,-0.019],"hi":[0.004,0.004]}',
                             "loads.point[1].box": '{"lo":[-0.004,-0.004],"hi":[0.019,0.019]}',
                             "loads.point[0].force": f"[{F_max / math.sqrt(2)},{F_max / math.sqrt(2)}]",
                             "loads.point[1].force": f"[{-F_max / math.sqrt(2)},{-F_max / math.sqrt(2)}]",
                             "contact.boundary_spacing": 2 * math.pi * R / 199.5})
            path = run(args, "hertz_disks", f"hertz_disks_{args.angle}deg_{shape}_R{level}", sets)
            s = series(path)
            Fc, L = s["penalty_force.left.right"], s["penalty_contact_length.left.right"]
            keep = Fc > 0.02 * F_max
            # Mean over bins of F: the disks ring on the contact spring around the quasi-static state.
            bins = np.linspace(0, F_max * 1.05, 22)
            idx = np.digitize(Fc[keep], bins)
            Fm = [Fc[keep][idx == k].mean() for k in range(1, len(bins)) if np.any(idx == k)]
            am = [0.5 * L[keep][idx == k].mean() for k in range(1, len(bins)) if np.any(idx == k)]
            ax.plot(np.array(Fm) / 1e6, 1e3 * np.array(am), markers[i % 4] + ("-" if shape == "ebs" else "--"),
                    color=COLORS[shape], ms=4, label=f"{shape.upper()} R/{level}")
    ax.set_xlabel("contact force F (MN per m)")
    ax.set_ylabel("half contact length a (mm)")
    ax.set_title(f"Hertz, two disks, {args.angle} deg: a = half the penetrated master segments")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, args, f"hertz_disks_{args.angle}deg.png")


# ---- Hertz, half disk on a rigid plane (section 4.3.2) ---------------------------------------------
def hertz_sigma_zz(x, z, a, p0):
    """McEwen (1949) / Johnson (1985) eq. 4.49: sigma_zz below an elliptic pressure, depth z >= 0."""
    q = a * a - x * x + z * z
    r = np.sqrt(q * q + 4 * x * x * z * z)
    m2, n2 = np.maximum(0.5 * (r + q), 0), np.maximum(0.5 * (r - q), 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = -(p0 / a) * np.sqrt(m2) * (1 - (z * z + n2) / (m2 + n2))
    return np.where(m2 + n2 > 0, s, 0.0)


def half_disk(args):
    R, E, F = 0.01, 1e10, 156.7 / 1e-3  # N per metre of thickness
    b = 2 * math.sqrt(2 * F * R / (math.pi * 2 * E))
    p0 = 2 * F / (math.pi * b)
    fig, axes = plt.subplots(1, len(args.levels), figsize=(4.2 * len(args.levels), 3.8), squeeze=False)
    rmse = {s: [] for s in args.shapes}
    for j, level in enumerate(args.levels):
        h = level * 1e-3
        k = math.ceil(0.8e-3 / h)  # the plane's surface (y = 0) sits 0.1 h above a grid line
        lo_y = -(k + 0.1) * h
        ny = math.ceil((R + 0.0002 - lo_y) / h) + 2
        nx = 2 * math.ceil((R + 0.0012) / h)
        sets = {"grid.cell_size": h, "grid.lo": f"[{-nx / 2 * h},{lo_y}]", "grid.hi": f"[{nx / 2 * h},{lo_y + ny * h}]"}
        ax = axes[0][j]
        x = np.linspace(-1.5 * b, 1.5 * b, 300)
        ax.plot(1e3 * x, -1e-6 * p0 * np.sqrt(np.maximum(1 - x * x / b / b, 0)), "k-", lw=2, label="Hertz p(x)")
        for shape in args.shapes:
            sets.update(shape_sets(shape))
            path = run(args, "half_disk_plane", f"half_disk_{shape}_{level}mm", sets)
            snaps = snapshots(path)
            X0 = snaps[0][1]["position"]
            body = snaps[0][1]["body"]
            d = R - np.hypot(X0[:, 0], X0[:, 1] - R)
            row = np.where((body == 0) & (d < 0.5 * h) & (np.abs(X0[:, 0]) < 2 * b) & (X0[:, 1] < 0.5 * R))[0]
            hold = [g for t, g in snaps if t >= 1.999e-4]  # the load is held from 200 us
            pos = np.mean([g["position"][row] for g in hold], axis=0)
            syy = np.mean([in_plane_stress(g["stress"][row])[:, 1, 1] for g in hold], axis=0)
            an = hertz_sigma_zz(pos[:, 0], np.maximum(pos[:, 1], 0), b, p0)
            inside = np.abs(pos[:, 0]) <= 1.5 * b
            e = math.sqrt(np.mean((syy[inside] - an[inside]) ** 2)) / p0
            rmse[shape].append(e)
            order = np.argsort(pos[:, 0])
            ax.plot(1e3 * pos[order, 0], 1e-6 * syy[order], "o-" if shape == "ebs" else "s--", ms=3,
                    color=COLORS[shape], label=f"{shape.upper()} (RMSE {e:.3f})")
        ax.set_title(f"dh = {level} mm (b = {b / h:.1f} dh)")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("sigma_yy of the contact row (MPa)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    save(fig, args, "half_disk_profiles.png")
    fig, ax = plt.subplots(figsize=(4.8, 3.8))
    for shape in args.shapes:
        ax.loglog(args.levels, rmse[shape], "o-" if shape == "ebs" else "s--", color=COLORS[shape], label=shape.upper())
    ax.set_xlabel("dh (mm)")
    ax.set_ylabel("relative RMSE (eq. 45)")
    ax.set_title("half disk on a rigid plane")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    save(fig, args, "half_disk_rmse.png")
    for shape in args.shapes:
        print(f"half disk {shape}: RMSE " + ", ".join(f"{lv} mm: {e:.4f}" for lv, e in zip(args.levels, rmse[shape])))


# ---- Neo-Hookean rings (section 4.4) ----------------------------------------------------------------
def von_mises(g):
    s = in_plane_stress(g["stress"])
    szz = g["stress_zz"] if "stress_zz" in g else np.zeros(len(s))
    sxx, syy, sxy = s[:, 0, 0], s[:, 1, 1], s[:, 0, 1]
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)


def rings(args):
    runs = [("penalty", {})]
    if args.one_field:
        runs.append(("one_field", {"contact": "null", "materials.right": "null",
                                   "bodies[1].material": "left"}))
    for tag, sets in runs:
        path = run(args, "neo_hookean_rings", f"rings_{tag}", sets)
        s = series(path)
        t = 1e3 * s["time"]
        P = s.get("penalty_energy", np.zeros_like(t))
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        ax.plot(t, s["kinetic_energy"], label="kinetic")
        ax.plot(t, s["strain_energy"], label="strain")
        ax.plot(t, P, label="penalty springs")
        T = s["kinetic_energy"] + s["strain_energy"] + P
        ax.plot(t, T, "k-", lw=2, label="total")
        ax.set_xlabel("t (ms)")
        ax.set_ylabel("energy (J per m)")
        ax.set_title(f"Neo-Hookean rings ({tag}): total {100 * (T[-1] - T[0]) / T[0]:+.1f} % at {t[-1]:.2f} ms")
        ax.grid(alpha=0.3)
        ax.legend()
        save(fig, args, f"rings_{tag}_energy.png")
        snaps = snapshots(path)
        wanted = [0.0, 0.87e-3, 1.59e-3, 2.33e-3, 3.09e-3, 3.97e-3]  # the paper's Fig. 24 times
        fig, axes = plt.subplots(2, 3, figsize=(12, 6.2))
        vmax = max(np.percentile(von_mises(g), 99.5) for _, g in snaps)
        for ax, tw in zip(axes.flat, wanted):
            tt, g = min(snaps, key=lambda sg: abs(sg[0] - tw))
            sc = ax.scatter(1e3 * g["position"][:, 0], 1e3 * g["position"][:, 1], c=1e-6 * von_mises(g), s=1,
                            cmap="jet", vmin=0, vmax=1e-6 * vmax)
            ax.set_title(f"t = {1e3 * tt:.2f} ms")
            ax.set_aspect("equal")
            ax.set_xlim(-100, 100)
            ax.set_ylim(-60, 60)
        fig.colorbar(sc, ax=axes, label="von Mises (MPa)")
        save(fig, args, f"rings_{tag}_von_mises.png")


# ---- Granular stress waves (section 4.5.1) ---------------------------------------------------------
def granular(args):
    R = 0.025
    kf = math.pi / 0.07e9
    fig, axes = plt.subplots(len(args.levels), 1, figsize=(9, 2.6 * len(args.levels)), squeeze=False)
    for ax, level in zip(axes[:, 0], args.levels):
        h = level * 1e-3
        n = 4 * math.ceil(2 * math.pi * R / (2 * h))
        sets = {"grid.cell_size": h, "contact.boundary_spacing": 2 * math.pi * R / (n - 0.5)}
        path = run(args, "granular_waves", f"granular_{level}mm", sets)
        tt, g = snapshots(path)[-1]
        s = in_plane_stress(g["stress"])
        d = np.sqrt(4 * s[:, 0, 1] ** 2 + (s[:, 0, 0] - s[:, 1, 1]) ** 2)  # eq. 50
        fringe = 1 - np.sin(kf * d) ** 2  # eq. 49
        disks = g["body"] > 0
        ax.scatter(1e3 * g["position"][disks, 0], 1e3 * g["position"][disks, 1], c=fringe[disks], s=0.5 * level,
                   cmap="gray", vmin=0, vmax=1)
        ax.scatter(1e3 * g["position"][~disks, 0], 1e3 * g["position"][~disks, 1], c="tab:orange", s=0.5 * level)
        ax.set_aspect("equal")
        ax.set_title(f"dh = {level} mm, t = {1e6 * tt:.1f} us: fringes 1 - sin^2(k_f (s1 - s2)), k_f = pi/0.07 GPa")
        ax.set_xlim(-25, 205)
        ax.set_ylim(-30, 30)
    save(fig, args, "granular_fringes.png")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=["hertz-disks", "half-disk", "rings", "granular", "all"])
    ap.add_argument("--levels", type=float, nargs="+", help="R/dh (hertz-disks), dh in mm (half-disk, granular)")
    ap.add_argument("--shapes", nargs="+", default=["ebs", "obs"], choices=list(SHAPES))
    ap.add_argument("--angle", type=int, default=0, choices=[0, 45])
    ap.add_argument("--one-field", action="store_true", help="rings: also the rings in one velocity field")
    ap.add_argument("--frictherm", default=os.path.join(ROOT, "build", "coupling", "frictherm"))
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "penalty"))
    ap.add_argument("--rerun", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if not os.path.exists(args.frictherm):
        sys.exit(f"{args.frictherm} not found (build it, or pass --frictherm)")
    levels = args.levels
    cases = ["hertz-disks", "half-disk", "rings", "granular"] if args.case == "all" else [args.case]
    defaults = {"hertz-disks": [10, 20], "half-disk": [0.2, 0.1], "granular": [5, 2.5]}
    for case in cases:
        args.levels = levels or defaults.get(case)
        if case == "hertz-disks":
            args.levels = [int(v) for v in args.levels]
        {"hertz-disks": hertz_disks, "half-disk": half_disk, "rings": rings, "granular": granular}[case](args)


if __name__ == "__main__":
    main()
