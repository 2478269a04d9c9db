"""PNG charts of runs (matplotlib, headless): particles coloured by a field, series panels, and
hot-spot circles over a particle picture. Used by examples/plot_run.py and examples/pbx_figures.py."""
import math

import os
import sys

import matplotlib

# Headless (Agg) for scripts without a display; in a notebook or under a GUI backend chosen before
# the import, matplotlib's own backend stays (frictherm.plot is then usable from notebooks).
if "ipykernel" not in sys.modules and "matplotlib.pyplot" not in sys.modules and not os.environ.get("DISPLAY"):
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the backend)
import numpy as np  # noqa: E402

from .fields import field_values, unit_of  # noqa: E402

# The axes box of plot_particles (figure fractions); draw_hotspots overlays the same box.
_BOX = [0.12, 0.1, 0.7, 0.8]


def particle_side(run, snap):
    """Edge length (m) of the square drawn for each particle: its area (2D, volume / thickness) or
    volume (3D) to the power 1/dim."""
    dim = run.dim
    pos = snap["position"].astype(float)
    if "volume" in snap:
        vol = np.abs(snap["volume"].astype(float).reshape(-1))
        if dim == 2 and "thickness" in run.meta:
            vol = vol / float(run.meta["thickness"])
        return vol ** (1.0 / dim)
    span = np.ptp(pos[:, :2], axis=0)
    area = max(span[0] * span[1], 1e-300)
    return np.full(len(pos), math.sqrt(area / max(len(pos), 1)))


def _frame(fig, pos, side):
    ax = fig.add_axes(_BOX)
    pad = float(np.max(side)) if len(side) else 1.0
    lo, hi = pos[:, :2].min(axis=0) - pad, pos[:, :2].max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    return ax, pad


def plot_particles(run, snap, field, out_png):
    """Particles as squares sized to their spacing, coloured by `field` (frictherm.fields names);
    3D runs are projected on the x-y plane, highest z on top."""
    pos = snap["position"].astype(float)
    values, clabel = field_values(snap, field)
    side = particle_side(run, snap)
    factor, lunit = scale_for(np.abs(pos[:, :2]).max(), "m")  # mm or µm axes for small specimens
    pos, side = pos * factor, side * factor
    order = np.argsort(pos[:, 2]) if run.dim == 3 else np.arange(len(pos))
    pos, values, side = pos[order], values[order], side[order]
    # Fixed axes boxes (no tight_layout or colorbar stealing space later), so that the data-unit to
    # point scale measured below is the one the figure is saved with.
    fig = plt.figure(figsize=(7.5, 6), dpi=120)
    ax, _ = _frame(fig, pos, side)
    cax = fig.add_axes([0.86, 0.1, 0.03, 0.8])
    fig.canvas.draw()  # applies the equal aspect to the axes box
    x0, x1 = ax.transData.transform([[0.0, 0.0], [1.0, 0.0]])[:, 0]
    points_per_unit = (x1 - x0) * 72.0 / fig.dpi
    sizes = (side * points_per_unit) ** 2
    finite = np.isfinite(values)
    vmin, vmax = (values[finite].min(), values[finite].max()) if finite.any() else (0.0, 1.0)
    sc = ax.scatter(pos[:, 0], pos[:, 1], c=values, s=sizes, marker="s", linewidths=0, cmap="inferno",
                    vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1.0)
    unit = unit_of(field)
    fig.colorbar(sc, cax=cax).set_label(clabel + (f" ({unit})" if unit else ""))
    ax.set_xlabel(f"x ({lunit})")
    ax.set_ylabel(f"y ({lunit})")
    what = "failure state" if snap.is_failure else f"snapshot {snap.label}"
    ax.set_title(f"{clabel} at t = {snap.time:.4g} s (step {snap.step}, {what})")
    fig.savefig(out_png)
    plt.close(fig)


def plot_slices(run, snap, field, out_png=None, count=3, axis=2):
    """A 3D run drawn as `count` slices normal to `axis` (default z) at evenly spaced levels inside
    the particles' extent, side by side with one colour scale: each panel shows the particles whose
    centre is within half a particle spacing of its level. Axes in m with an SI prefix (mm, µm)
    where it reads better. Returns the figure when out_png is None, else saves and closes it."""
    if run.dim != 3:
        raise ValueError("plot_slices draws 3D runs (this run is %dD)" % run.dim)
    pos = snap["position"].astype(float)
    values, clabel = field_values(snap, field)
    side = particle_side(run, snap)
    lo, hi = pos[:, axis].min(), pos[:, axis].max()
    levels = lo + (hi - lo) * (np.arange(count) + 0.5) / count
    plane = [a for a in range(3) if a != axis]
    factor, lunit = scale_for(np.abs(pos[:, plane]).max(), "m")
    finite = np.isfinite(values)
    vmin, vmax = (values[finite].min(), values[finite].max()) if finite.any() else (0.0, 1.0)
    fig, axes = plt.subplots(1, count, figsize=(4.2 * count + 1.2, 4.2), dpi=110, squeeze=False)
    names = "xyz"
    for ax, level in zip(axes.flat, levels):
        near = np.abs(pos[:, axis] - level) <= 0.5 * side
        sc = ax.scatter(pos[near, plane[0]] * factor, pos[near, plane[1]] * factor, c=values[near], s=8,
                        marker="s", linewidths=0, cmap="inferno", vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1)
        ax.set_aspect("equal")
        pad = float(side.max())
        ax.set_xlim((pos[:, plane[0]].min() - pad) * factor, (pos[:, plane[0]].max() + pad) * factor)
        ax.set_ylim((pos[:, plane[1]].min() - pad) * factor, (pos[:, plane[1]].max() + pad) * factor)
        lf, lu = scale_for(abs(level), "m")
        ax.set_title(f"{names[axis]} = {level * lf:.3g} {lu} ({int(near.sum())} particles)", fontsize=10)
        ax.set_xlabel(f"{names[plane[0]]} ({lunit})")
        ax.set_ylabel(f"{names[plane[1]]} ({lunit})")
    unit = unit_of(field)
    fig.colorbar(sc, ax=list(axes.flat), shrink=0.85).set_label(clabel + (f" ({unit})" if unit else ""))
    fig.suptitle(f"{clabel} at t = {snap.time:.4g} s, slices normal to {names[axis]}", fontsize=11)
    if out_png is None:
        return fig
    fig.savefig(out_png)
    plt.close(fig)
    return None


# Panels of the grouped series figure, in this order: (unit, panel title). Columns of other units
# go to panels of their own after these.
_SERIES_PANELS = [("J", "energy"), ("K", "temperature"), ("W", "heat rate"), ("m", "length"),
                  ("m/s", "velocity"), ("kg m/s", "momentum"), ("m^2", "area"), ("s", "time step"),
                  ("1", "counts")]
# SI prefixes for axes: the largest with values >= 1 (so a 3e-6 m displacement reads 3 µm).
_PREFIXES = [(1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1.0, "")]
_SCALABLE = {"m", "s", "J", "W"}  # units a prefix reads well on (not K, m/s or counts)


def scale_for(values, unit):
    """(factor, label unit) so that values * factor reads with an SI prefix: (1e6, 'µm') for
    micrometres, (1e9, 'ns') for nanoseconds; (1, unit) for units without prefixes."""
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite) & (finite > 0)]
    if unit not in _SCALABLE or not finite.size:
        return 1.0, unit
    top = float(finite.max())
    for size, prefix in _PREFIXES:
        if top < 1000 * size:
            return 1.0 / size, prefix + unit
    return 1.0, unit


def series_groups(run, columns=None):
    """The series columns grouped by unit into panels: [(title, unit, [column, ...]), ...]; `time`
    and `step` are left out."""
    s = run.series
    columns = [c for c in (columns or s.columns) if c not in ("time", "step")]
    groups = {}
    for c in columns:
        groups.setdefault(s.unit_of(c), []).append(c)
    order = [u for u, _ in _SERIES_PANELS if u in groups] + [u for u in groups if u not in dict(_SERIES_PANELS)]
    titles = dict(_SERIES_PANELS)
    return [(titles.get(u, u or "other"), u, groups[u]) for u in order]


def plot_series(run, columns=None, out_png=None, max_lines=8):
    """The series against time, grouped by unit into a few panels (energies, temperatures, heat
    rates, displacements, ...), each line named by its long_name, axes in SI units with a prefix where
    it reads better (µm, ns, mJ). Returns the figure when out_png is None (notebooks), else saves
    and closes it. A panel shows at most `max_lines` lines (the first columns of its unit)."""
    s = run.series
    groups = series_groups(run, columns)
    time = s["time"].astype(float)
    tf, tunit = scale_for(time, "s")
    k = max(len(groups), 1)
    ncols = 1 if k == 1 else 2 if k <= 4 else 3
    nrows = int(math.ceil(k / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 3.3 * nrows), dpi=110, squeeze=False)
    for ax, (title, unit, names) in zip(axes.flat, groups):
        names = names[:max_lines]
        yf, yunit = scale_for(np.concatenate([s[n].astype(float) for n in names]), unit)
        for n in names:
            label = s.long_names.get(n, n.replace("_", " "))
            ax.plot(time * tf, s[n].astype(float) * yf, lw=1.3, label=label)
        ax.set_title(title, fontsize=11)
        ax.set_xlabel(f"time ({tunit})")
        ax.set_ylabel(f"{title} ({yunit})" if yunit and yunit != "1" else title)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best", frameon=False)
    for ax in list(axes.flat)[len(groups):]:
        ax.set_visible(False)
    fig.tight_layout()
    if out_png is None:
        return fig
    fig.savefig(out_png)
    plt.close(fig)
    return None


def draw_hotspots(run, snap, png):
    """Circles (equivalent diameter) and ids of the hot spots of the coupling window nearest the
    snapshot's time, drawn over `png` (a plot_particles picture of that snapshot). Returns how many."""
    h = run.hotspots
    if not len(h):
        return 0
    times = np.unique(h["time"])
    tn = times[np.argmin(np.abs(times - snap.time))]
    sel = h.where(h["time"] == tn)
    img = plt.imread(png)
    fig = plt.figure(figsize=(7.5, 6), dpi=120)
    fig.figimage(img, 0, 0)
    pos = snap["position"].astype(float)
    factor, _ = scale_for(np.abs(pos[:, :2]).max(), "m")  # the axes plot_particles drew
    ax, pad = _frame(fig, pos * factor, particle_side(run, snap) * factor)
    ax.set_zorder(1)  # above the figure image (figure images are drawn after axes of equal zorder)
    ax.patch.set_alpha(0.0)
    ax.set_axis_off()
    for x, y, d, i in zip(sel["centroid_x"] * factor, sel["centroid_y"] * factor, sel["equivalent_diameter"] * factor,
                          sel["id"]):
        ax.add_patch(plt.Circle((x, y), max(d, 2 * pad) / 2, fill=False, color="cyan", lw=1.2))
        ax.annotate("%d" % i, (x, y), color="cyan", fontsize=7, xytext=(4, 4), textcoords="offset points")
    fig.savefig(png)
    plt.close(fig)
    return len(sel)
