#!/usr/bin/python3
"""Draw a frictherm run (the HDF5 file written by `frictherm run`) as PNG charts.

  plot_run.py RUN.h5 [--field NAME] [--snapshot INDEX|last|failure] [--series COL ...] [-o PREFIX]
  plot_run.py RUN.h5 --list

Writes PREFIX_particles.png (particles as squares sized to their spacing, coloured by a field)
and PREFIX_series.png (series against /series/time). PREFIX defaults to RUN without .h5.

Fields: any stored snapshot field (temperature, mass, material, ...), one component of a stored
field (velocity_x, position_z, stress_xy, or velocity_0 ...), or a derived one:
  speed                   |velocity|
  displacement_magnitude  |displacement| (or |position - initial_position|)
  von_mises               sqrt(3/2 s:s) of the Cauchy stress
  pressure                -trace(stress)/3
In 2D the out-of-plane stress comes from the field stress_zz when stored (plane strain), else 0
(plane stress). 3D runs are drawn projected on the x-y plane, highest z on top.

Uses the Debian packages python3-h5py, python3-matplotlib and python3-numpy; runs headless.
"""
import argparse
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the backend)
import numpy as np  # noqa: E402

AXES = "xyz"
UNITS = {"temperature": "K", "speed": "m/s", "velocity": "m/s", "position": "m", "displacement": "m",
         "displacement_magnitude": "m", "stress": "Pa", "stress_zz": "Pa", "von_mises": "Pa", "pressure": "Pa",
         "mass": "kg", "volume": "m^3", "initial_position": "m"}


def text(value):
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return text(value[()])
    return str(value)


def snapshot_groups(f):
    """[(label, group)] of the ended snapshots in order, then the failure snapshot if any."""
    out = []
    if "snapshots" in f:
        out = [(name, f["snapshots"][name]) for name in sorted(f["snapshots"].keys())]
    if "failure" in f:
        out.append(("failure", f["failure"]))
    return out


def series_columns(f):
    if "series" not in f:
        return []
    g = f["series"]
    if "columns" in g.attrs:
        return [text(c) for c in g.attrs["columns"]]
    names = sorted(g.keys())
    return sorted(names, key=lambda n: n != "time")


def dim_of(f, group):
    if "dim" in f.attrs:
        return int(f.attrs["dim"])
    return int(group["position"].shape[1])


def list_run(f, path):
    print(f"{path}: {int(f.attrs.get('dim', 0))}D, format {text(f.attrs.get('format', '?'))}")
    if "meta" in f:
        print("metadata:")
        for key in f["meta"]:
            value = f["meta"][key][()]
            shown = text(value).replace("\n", " ")
            print(f"  {key}: {shown[:70] + ('...' if len(shown) > 70 else '')}")
    snaps = snapshot_groups(f)
    print(f"snapshots: {sum(1 for label, _ in snaps if label != 'failure')}")
    for index, (label, g) in enumerate(snaps):
        step = int(g.attrs.get("step", -1))
        time = float(g.attrs.get("time", float("nan")))
        fields = ", ".join(f"{k}{list(g[k].shape[1:]) if g[k].ndim > 1 else ''}" for k in g.keys())
        extra = f"  message: {text(g.attrs['message'])}" if "message" in g.attrs else ""
        shown = "failure" if label == "failure" else str(index)
        print(f"  [{shown}] {label} step {step} t = {time:.6g} s, "
              f"{g['position'].shape[0] if 'position' in g else 0} particles: {fields}{extra}")
    cols = series_columns(f)
    rows = f["series"]["time"].shape[0] if "time" in cols else 0
    print(f"series ({rows} rows): {', '.join(cols) if cols else 'none'}")


def stress_parts(g, dim):
    """Returns (3x3 stress per particle as an (n, 3, 3) array)."""
    s = np.asarray(g["stress"], dtype=float)
    n = s.shape[0]
    if s.size == 9 * n:  # format_version 2: the full 3x3 tensor (zz = stress_zz in 2D)
        return s.reshape(n, 3, 3)
    full = np.zeros((n, 3, 3))  # format_version 1 files: dim x dim, stress_zz apart
    full[:, :dim, :dim] = s.reshape(n, dim, dim)
    if dim == 2 and "stress_zz" in g:
        full[:, 2, 2] = np.asarray(g["stress_zz"], dtype=float).reshape(n)
    return full


def field_values(g, name, dim):
    """(values per particle, label) for a stored, component or derived field name."""
    if name in g:
        data = np.asarray(g[name], dtype=float)
        if data.ndim == 1:
            return data, name
        return np.linalg.norm(data, axis=1), f"|{name}|"
    if name == "speed" and "velocity" in g:
        return np.linalg.norm(np.asarray(g["velocity"], dtype=float), axis=1), "speed"
    if name == "displacement_magnitude":
        if "displacement" in g:
            return np.linalg.norm(np.asarray(g["displacement"], dtype=float), axis=1), name
        if "initial_position" in g:
            d = np.asarray(g["position"], dtype=float) - np.asarray(g["initial_position"], dtype=float)
            return np.linalg.norm(d, axis=1), name
    if name in ("von_mises", "pressure") and "stress" in g:
        s = stress_parts(g, dim)
        trace = np.trace(s, axis1=1, axis2=2)
        if name == "pressure":
            return -trace / 3.0, "pressure"
        dev = s - trace[:, None, None] / 3.0 * np.eye(3)
        return np.sqrt(1.5 * np.einsum("nij,nij->n", dev, dev)), "von Mises stress"
    base, _, suffix = name.rpartition("_")
    if base in g and suffix:
        data = np.asarray(g[base], dtype=float)
        comps = data.shape[1] if data.ndim > 1 else 1
        index = None
        if suffix.isdigit():
            index = int(suffix)
        elif len(suffix) == 1 and suffix in AXES[:dim]:
            index = AXES.index(suffix)
        elif len(suffix) == 2 and all(c in AXES for c in suffix) and comps in (9, dim * dim):
            width = 3 if comps == 9 else dim  # 9: the 3x3 tensor of format_version 2, also in 2D
            if all(AXES.index(c) < width for c in suffix):
                index = AXES.index(suffix[0]) * width + AXES.index(suffix[1])
        if index is not None and index < comps:
            return (data[:, index] if data.ndim > 1 else data), name
    available = sorted(set(g.keys()) | {"speed", "von_mises", "pressure", "displacement_magnitude"})
    raise SystemExit(f"plot_run.py: no field '{name}' in this snapshot; available: {', '.join(available)} "
                     "(and components such as velocity_x, stress_xy)")


def particle_side(f, g, pos, dim):
    """Edge length of the square drawn for each particle (data units)."""
    if "half_size" in g:
        return 2.0 * np.asarray(g["half_size"], dtype=float)[:, :2].mean(axis=1)
    if "volume" in g:
        vol = np.abs(np.asarray(g["volume"], dtype=float).reshape(-1))
        if dim == 2 and "meta" in f and "thickness" in f["meta"]:
            vol = vol / float(f["meta"]["thickness"][()])
        return vol ** (1.0 / dim)
    span = np.ptp(pos[:, :2], axis=0)
    area = max(span[0] * span[1], 1e-300)
    return np.full(len(pos), math.sqrt(area / max(len(pos), 1)))


def plot_particles(f, g, label, field, out_png):
    dim = dim_of(f, g)
    pos = np.asarray(g["position"], dtype=float).reshape(-1, dim)
    values, clabel = field_values(g, field, dim)
    side = particle_side(f, g, pos, dim)
    order = np.argsort(pos[:, 2]) if dim == 3 else np.arange(len(pos))
    pos, values, side = pos[order], values[order], side[order]

    # Fixed axes boxes (no tight_layout or colorbar stealing space later), so that the data-unit to
    # point scale measured below is the one the figure is saved with.
    fig = plt.figure(figsize=(7.5, 6), dpi=120)
    ax = fig.add_axes([0.12, 0.1, 0.7, 0.8])
    cax = fig.add_axes([0.86, 0.1, 0.03, 0.8])
    pad = float(np.max(side)) if len(side) else 1.0
    lo, hi = pos[:, :2].min(axis=0) - pad, pos[:, :2].max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    fig.canvas.draw()  # applies the equal aspect to the axes box
    x0, x1 = ax.transData.transform([[0.0, 0.0], [1.0, 0.0]])[:, 0]
    points_per_unit = (x1 - x0) * 72.0 / fig.dpi
    sizes = (side * points_per_unit) ** 2
    finite = np.isfinite(values)
    vmin, vmax = (values[finite].min(), values[finite].max()) if finite.any() else (0.0, 1.0)
    sc = ax.scatter(pos[:, 0], pos[:, 1], c=values, s=sizes, marker="s", linewidths=0, cmap="inferno",
                    vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1.0)
    unit = UNITS.get(field, UNITS.get(field.rpartition("_")[0], ""))
    fig.colorbar(sc, cax=cax).set_label(clabel + (f" ({unit})" if unit else ""))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    step, time = int(g.attrs.get("step", -1)), float(g.attrs.get("time", float("nan")))
    what = "failure state" if label == "failure" else f"snapshot {label}"
    ax.set_title(f"{clabel} at t = {time:.4g} s (step {step}, {what})")
    fig.savefig(out_png)
    plt.close(fig)


def plot_series(f, columns, out_png):
    g = f["series"]
    time = np.asarray(g["time"], dtype=float)
    k = len(columns)
    ncols = int(math.ceil(math.sqrt(k)))
    nrows = int(math.ceil(k / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.0 * ncols, 2.8 * nrows), dpi=110, squeeze=False)
    for ax, name in zip(axes.flat, columns):
        y = np.asarray(g[name], dtype=float)
        n = min(len(y), len(time))
        ax.plot(time[:n], y[:n], lw=1.2)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("time (s)")
        ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[k:]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(out_png)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("run", help="HDF5 file of a run")
    p.add_argument("--field", default="temperature", help="colour particles by this field (default temperature, "
                   "or speed when there is no temperature)")
    p.add_argument("--snapshot", default="last", help="snapshot index, 'last' (default) or 'failure'")
    p.add_argument("--series", nargs="+", metavar="COL", help="series columns to plot (default: all but time)")
    p.add_argument("-o", "--output", metavar="PREFIX", help="output prefix (default: RUN without .h5)")
    p.add_argument("--list", action="store_true", help="print snapshots, fields, series and metadata, then exit")
    args = p.parse_args(argv)

    try:
        f = h5py.File(args.run, "r")
    except OSError as e:
        raise SystemExit(f"plot_run.py: cannot open {args.run}: {e}")
    with f:
        if args.list:
            list_run(f, args.run)
            return 0
        prefix = args.output or os.path.splitext(args.run)[0]
        wrote = []
        snaps = snapshot_groups(f)
        regular = [(label, g) for label, g in snaps if label != "failure"]
        if snaps:
            if args.snapshot == "last":
                label, g = regular[-1] if regular else snaps[-1]
            elif args.snapshot == "failure":
                if "failure" not in f:
                    raise SystemExit("plot_run.py: this run has no failure snapshot")
                label, g = "failure", f["failure"]
            else:
                try:
                    label, g = regular[int(args.snapshot)]
                except (ValueError, IndexError):
                    raise SystemExit(f"plot_run.py: no snapshot '{args.snapshot}' ({len(regular)} snapshots; "
                                     "use an index, 'last' or 'failure')")
            field = args.field
            if field == "temperature" and "temperature" not in g:
                field = "speed" if "velocity" in g else "position_x"
            plot_particles(f, g, label, field, prefix + "_particles.png")
            wrote.append(prefix + "_particles.png")
        else:
            print("plot_run.py: no snapshots in this run; no particle picture", file=sys.stderr)
        columns = series_columns(f)
        if columns and f["series"]["time"].shape[0] > 0:
            chosen = args.series or [c for c in columns if c != "time"]
            missing = [c for c in chosen if c not in columns]
            if missing:
                raise SystemExit(f"plot_run.py: no series {', '.join(missing)}; available: {', '.join(columns)}")
            if chosen:
                plot_series(f, chosen, prefix + "_series.png")
                wrote.append(prefix + "_series.png")
        else:
            print("plot_run.py: no series in this run; no series chart", file=sys.stderr)
    for path in wrote:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
