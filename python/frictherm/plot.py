"""PNG charts of runs (matplotlib, headless): particles coloured by a field, series panels, and
hot-spot circles over a particle picture. Used by examples/plot_run.py and examples/pbx_figures.py."""
import math

import matplotlib

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
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    what = "failure state" if snap.is_failure else f"snapshot {snap.label}"
    ax.set_title(f"{clabel} at t = {snap.time:.4g} s (step {snap.step}, {what})")
    fig.savefig(out_png)
    plt.close(fig)


def plot_series(run, columns, out_png):
    """One panel per series column against time."""
    s = run.series
    time = s["time"].astype(float)
    k = len(columns)
    ncols = int(math.ceil(math.sqrt(k)))
    nrows = int(math.ceil(k / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.0 * ncols, 2.8 * nrows), dpi=110, squeeze=False)
    for ax, name in zip(axes.flat, columns):
        ax.plot(time, s[name], lw=1.2)
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("time (s)")
        ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[k:]:
        ax.set_visible(False)
    fig.tight_layout()
    fig.savefig(out_png)
    plt.close(fig)


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
    ax, pad = _frame(fig, snap["position"].astype(float), particle_side(run, snap))
    ax.set_zorder(1)  # above the figure image (figure images are drawn after axes of equal zorder)
    ax.patch.set_alpha(0.0)
    ax.set_axis_off()
    for x, y, d, i in zip(sel["centroid_x"], sel["centroid_y"], sel["equivalent_diameter"], sel["id"]):
        ax.add_patch(plt.Circle((x, y), max(d, 2 * pad) / 2, fill=False, color="cyan", lw=1.2))
        ax.annotate("%d" % i, (x, y), color="cyan", fontsize=7, xytext=(4, 4), textcoords="offset points")
    fig.savefig(png)
    plt.close(fig)
    return len(sel)
