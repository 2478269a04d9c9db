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


def rigid_particles(run, snap):
    """Boolean mask of the snapshot's particles of rigid materials (walls, pistons: /meta
    material_kinds "rigid"). The pictures draw them in grey, under the others, and leave them out
    of the colour scale: their fixed temperature or zero stress would otherwise stretch the scale
    over the specimen's whole range (a 0.4 K hot spot under 293 K walls reads as one colour)."""
    kinds = run.meta.get("material_kinds") if hasattr(run.meta, "get") else None
    if not isinstance(kinds, (list, tuple)) or "material" not in snap:
        return np.zeros(snap.particle_count, dtype=bool)
    rigid = np.array([k == "rigid" for k in kinds] + [False])
    material = np.asarray(snap["material"]).reshape(-1).astype(np.int64)
    return rigid[np.clip(material, 0, len(kinds))]


def _colour_range(values, rigid):
    """(vmin, vmax) over the finite values of the non-rigid particles (all particles if all are rigid)."""
    use = np.isfinite(values) & (~rigid if (~rigid).any() else True)
    if not use.any():
        return 0.0, 1.0
    vmin, vmax = float(values[use].min()), float(values[use].max())
    return vmin, (vmax if vmax > vmin else vmin + 1.0)


_RIGID_COLOUR = "0.78"


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
    particles of rigid materials in grey and out of the colour scale (rigid_particles). 3D runs are
    projected on the x-y plane, highest z on top, rigid particles beneath the others (plot_slices
    shows the inside)."""
    pos = snap["position"].astype(float)
    values, clabel = field_values(snap, field)
    side = particle_side(run, snap)
    rigid = rigid_particles(run, snap)
    factor, lunit = scale_for(np.abs(pos[:, :2]).max(), "m")  # mm or µm axes for small specimens
    pos, side = pos * factor, side * factor
    order = np.lexsort((pos[:, 2], ~rigid)) if run.dim == 3 else np.arange(len(pos))
    pos, values, side, rigid = pos[order], values[order], side[order], rigid[order]
    # Fixed axes boxes (no tight_layout or colorbar stealing space later), so that the data-unit to
    # point scale measured below is the one the figure is saved with.
    fig = plt.figure(figsize=(7.5, 6), dpi=120)
    ax, _ = _frame(fig, pos, side)
    cax = fig.add_axes([0.86, 0.1, 0.03, 0.8])
    fig.canvas.draw()  # applies the equal aspect to the axes box
    x0, x1 = ax.transData.transform([[0.0, 0.0], [1.0, 0.0]])[:, 0]
    points_per_unit = (x1 - x0) * 72.0 / fig.dpi
    sizes = (side * points_per_unit) ** 2
    vmin, vmax = _colour_range(values, rigid)
    colours = plt.get_cmap("inferno")(np.clip((values - vmin) / (vmax - vmin), 0.0, 1.0))
    colours[rigid] = matplotlib.colors.to_rgba(_RIGID_COLOUR)
    ax.scatter(pos[:, 0], pos[:, 1], c=colours, s=sizes, marker="s", linewidths=0)
    mappable = matplotlib.cm.ScalarMappable(matplotlib.colors.Normalize(vmin, vmax), "inferno")
    unit = unit_of(field)
    fig.colorbar(mappable, cax=cax).set_label(clabel + (f" ({unit})" if unit else ""))
    ax.set_xlabel(f"x ({lunit})")
    ax.set_ylabel(f"y ({lunit})")
    what = "failure state" if snap.is_failure else f"snapshot {snap.label}"
    tf, tunit = scale_for(snap.time, "s")
    ax.set_title(f"{clabel} at t = {snap.time * tf:.4g} {tunit} (step {snap.step}, {what})"
                 + (", rigid in grey" if rigid.any() else ""))
    fig.savefig(out_png)
    plt.close(fig)


def plot_slices(run, snap, field, out_png=None, count=3, axis=2):
    """A 3D run drawn as `count` slices normal to `axis` (default z) at evenly spaced levels inside
    the particles' extent, side by side with one colour scale: each panel shows the particles whose
    centre is within half a particle spacing of its level, as squares of that spacing (rigid
    materials in grey and out of the colour scale, rigid_particles). Axes in m with an SI prefix
    (mm, µm) where it reads better. Returns the figure when out_png is None, else saves and closes it."""
    if run.dim != 3:
        raise ValueError("plot_slices draws 3D runs (this run is %dD)" % run.dim)
    pos = snap["position"].astype(float)
    values, clabel = field_values(snap, field)
    side = particle_side(run, snap)
    rigid = rigid_particles(run, snap)
    lo, hi = pos[:, axis].min(), pos[:, axis].max()
    levels = lo + (hi - lo) * (np.arange(count) + 0.5) / count
    plane = [a for a in range(3) if a != axis]
    factor, lunit = scale_for(np.abs(pos[:, plane]).max(), "m")
    vmin, vmax = _colour_range(values, rigid)
    cmap = plt.get_cmap("inferno")
    colours = cmap(np.clip((values - vmin) / (vmax - vmin), 0.0, 1.0))
    colours[rigid] = matplotlib.colors.to_rgba(_RIGID_COLOUR)
    fig, axes = plt.subplots(1, count, figsize=(4.2 * count + 1.2, 4.6), dpi=110, squeeze=False)
    fig.subplots_adjust(left=0.06, right=0.86, bottom=0.12, top=0.82, wspace=0.3)
    pad = float(side.max())
    names = "xyz"
    for ax in axes.flat:
        ax.set_aspect("equal")
        ax.set_xlim((pos[:, plane[0]].min() - pad) * factor, (pos[:, plane[0]].max() + pad) * factor)
        ax.set_ylim((pos[:, plane[1]].min() - pad) * factor, (pos[:, plane[1]].max() + pad) * factor)
    fig.canvas.draw()  # applies the equal aspect, so the data-to-point scale below is the saved one
    for ax, level in zip(axes.flat, levels):
        x0, x1 = ax.transData.transform([[0.0, 0.0], [1.0, 0.0]])[:, 0]
        points_per_unit = (x1 - x0) * 72.0 / fig.dpi
        near = np.abs(pos[:, axis] - level) <= 0.5 * side
        ax.scatter(pos[near, plane[0]] * factor, pos[near, plane[1]] * factor, c=colours[near],
                   s=(side[near] * factor * points_per_unit) ** 2, marker="s", linewidths=0)
        lf, lu = scale_for(abs(level), "m")
        ax.set_title(f"{names[axis]} = {level * lf:.3g} {lu} ({int(near.sum())} particles)", fontsize=10)
        ax.set_xlabel(f"{names[plane[0]]} ({lunit})")
        ax.set_ylabel(f"{names[plane[1]]} ({lunit})")
    cax = fig.add_axes([0.89, 0.12, 0.015, 0.7])
    mappable = matplotlib.cm.ScalarMappable(matplotlib.colors.Normalize(vmin, vmax), cmap)
    unit = unit_of(field)
    fig.colorbar(mappable, cax=cax).set_label(clabel + (f" ({unit})" if unit else ""))
    tf, tunit = scale_for(snap.time, "s")
    fig.suptitle(f"{clabel} at t = {snap.time * tf:.4g} {tunit}, slices normal to {names[axis]}"
                 + (" (rigid in grey)" if rigid.any() else ""), fontsize=11)
    if out_png is None:
        return fig
    fig.savefig(out_png)
    plt.close(fig)
    return None


# Panels of the grouped series figure, in this order: (unit, panel title). Columns of other units
# go to panels of their own after these. Energies (J) are split further by what they measure
# (_ENERGY_PANELS), so that the frictional work and heat are never crowded out by the mechanical terms.
_SERIES_PANELS = [("J", "energy"), ("K", "temperature"), ("W", "heat rate"), ("m", "length"),
                  ("m/s", "velocity"), ("kg m/s", "momentum"), ("m^2", "area"), ("m^3", "volume"),
                  ("s", "time step"), ("1", "counts")]
_ENERGY_PANELS = [("dissipated energy", ("damping_work", "plastic_dissipation", "energy_lost", "numerical_dissipation",
                                         "contact_normal_work", "boundary_stop_work", "stored_energy_lead")),
                  ("frictional work and heat", ("friction_work", "heat_delivered", "thermal_energy_change"))]
# SI prefixes for axes: the largest with values >= 1 (so a 3e-6 m displacement reads 3 µm).
_PREFIXES = [(1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1.0, "")]
_SCALABLE = {"m", "s", "J", "W"}  # units a prefix reads well on (not K, m/s or counts)
_POWERS = {"m^2": 2, "m^3": 3}  # areas and volumes: the prefix of the length (mm^2 = 1e-6 m^2)
_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")


def scale_for(values, unit):
    """(factor, label unit) so that values * factor reads well: an SI prefix where the unit takes one
    ((1e6, 'µm') for micrometres, (1e9, 'ns') for nanoseconds, (1e6, 'mm²') for square millimetres),
    else a power of ten in the label when the values are far from 1 ((1e8, '10⁻⁸ kg m/s')), so
    that an axis never carries matplotlib's offset text ('1e-8' above it); (1, unit) otherwise."""
    finite = np.abs(np.asarray(values, dtype=float))
    finite = finite[np.isfinite(finite) & (finite > 0)]
    if not finite.size:
        return 1.0, unit.replace("^2", "²").replace("^3", "³")
    top = float(finite.max())
    power = _POWERS.get(unit, 1)
    if unit in _SCALABLE or unit in _POWERS:
        base = "m" if unit in _POWERS else unit
        for size, prefix in _PREFIXES:
            if top ** (1.0 / power) < 1000 * size:  # an area's or volume's side decides its prefix
                label = prefix + base + ("" if power == 1 else "²" if power == 2 else "³")
                return float("%.12g" % (1.0 / size ** power)), label
        return 1.0, unit
    if unit in ("K", "1", ""):  # temperatures and counts read as they are
        return 1.0, unit
    exponent = int(math.floor(math.log10(top)))
    if -3 <= exponent <= 3:
        return 1.0, unit
    return 10.0 ** -exponent, f"10{str(exponent).translate(_SUPERSCRIPT)} {unit}"


def _panel_of(name, unit):
    if unit == "J":
        for title, prefixes in _ENERGY_PANELS:
            if name.split(".", 1)[0].startswith(prefixes):
                return title
    return dict(_SERIES_PANELS).get(unit, unit or "other")


def series_groups(run, columns=None, max_lines=8):
    """The series columns grouped into panels by unit (and energies by what they measure):
    [(title, unit, [column, ...]), ...]. `time` and `step` are left out, and so are columns without
    a single finite value (e.g. the hottest hot spot's size before there is one) and per-body or
    per-pair columns equal to their total (``friction_work_first.base.block`` when there is one
    pair). Totals (names without a '.') come first and are always shown (a panel with more than
    `max_lines` of them continues in a second panel); per-body and per-pair columns fill a panel
    up to `max_lines`, and the title says how many of them were left out."""
    s = run.series
    columns = [c for c in (columns or s.columns) if c not in ("time", "step")]
    kept = []
    for c in columns:
        values = np.asarray(s[c], dtype=float)
        if not np.isfinite(values).any():
            continue
        total = c.split(".", 1)[0]
        if "." in c and total in s.columns and np.array_equal(values, np.asarray(s[total], dtype=float), equal_nan=True):
            continue
        kept.append(c)
    panels = {}  # (title, unit): [columns]
    for c in kept:
        unit = s.unit_of(c)
        panels.setdefault((_panel_of(c, unit), unit), []).append(c)
    order = [u for u, _ in _SERIES_PANELS]
    keys = sorted(panels, key=lambda k: (order.index(k[1]) if k[1] in order else len(order), list(panels).index(k)))
    out = []
    for title, unit in keys:
        totals = [c for c in panels[(title, unit)] if "." not in c]
        parts = [c for c in panels[(title, unit)] if "." in c]
        chunks = [totals[i:i + max_lines] for i in range(0, len(totals), max_lines)] or [[]]
        room = max_lines - len(chunks[-1])
        shown, left = parts[:room], len(parts) - min(room, len(parts))
        chunks[-1] = chunks[-1] + shown
        for i, chunk in enumerate(chunks):
            name = title if i == 0 else f"{title} (continued)"
            if left and i == len(chunks) - 1:
                name += f" ({len(shown)} of {len(parts)} per body shown)"
            out.append((name, unit, chunk))
    return out


def plot_series(run, columns=None, out_png=None, max_lines=8):
    """The series against time, grouped into a few panels (energies, dissipated energy, frictional
    work and heat, temperatures, heat rates, lengths, ...; series_groups), each line named by its
    long_name, axes in SI units with a prefix where it reads better (µm, ns, mJ, mm²). Returns the
    figure when out_png is None (notebooks), else saves and closes it. A panel shows at most
    `max_lines` per-body lines (series_groups)."""
    s = run.series
    groups = series_groups(run, columns, max_lines)
    time = s["time"].astype(float)
    tf, tunit = scale_for(time, "s")
    k = max(len(groups), 1)
    ncols = 1 if k == 1 else 2 if k <= 4 else 3
    nrows = int(math.ceil(k / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.2 * ncols, 3.3 * nrows), dpi=110, squeeze=False)
    for ax, (title, unit, names) in zip(axes.flat, groups):
        yf, yunit = scale_for(np.concatenate([s[n].astype(float) for n in names]), unit)
        for n in names:
            label = s.long_names.get(n, n.replace("_", " "))
            ax.plot(time * tf, s[n].astype(float) * yf, lw=1.3, label=label)
        ax.set_title(title, fontsize=11)
        ax.set_xlabel(f"time ({tunit})")
        quantity = title.split(" (", 1)[0]
        ax.set_ylabel(f"{quantity} ({yunit})" if yunit and yunit != "1" else quantity)
        ax.ticklabel_format(axis="y", useOffset=False)
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
