"""The table (CSV), the summary (Markdown) and the charts (PNG) of a resolution study
(frictherm/study.py). Charts need matplotlib (Debian python3-matplotlib); without it they are
left out with a message."""
import csv
import math
import os
import re

from .study_analysis import CONVERGED, MONOTONE


def _slug(label):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", label).strip("_")


def _g(x, fmt="%.6g"):
    return "" if x is None or (isinstance(x, float) and not math.isfinite(x)) else fmt % x


def _length_scale(cells):
    """A unit for cell sizes on axes and in tables: mm, µm or m."""
    h = max(cells)
    if h < 1e-4:
        return 1e6, "µm"
    if h < 0.1:
        return 1e3, "mm"
    return 1.0, "m"


def _ensembles(study):
    return len(getattr(study, "offsets", [0.0])) > 1


def _spread(row, label):
    """max - min of an output over a row's grid offsets (NaN without offsets)."""
    lo, hi = row.get("spread", {}).get(label, (math.nan, math.nan))
    return hi - lo


def write_csv(study, path):
    """One row per run (per (cell, C) ensemble with grid offsets): cell_m, cfl, status, then per output
    its value, its relative error to the reference (and with offsets its spread, max - min over the
    offsets), then wall_s, cpu_s, run_wall_s, steps, particles, file, note."""
    labels = [o.label for o in study.outputs]
    errors = {lb: study.analysis(lb)["errors"] for lb in labels}
    ens = _ensembles(study)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        head = ["cell_m", "cfl", "status"]
        for lb in labels:
            head += [lb, lb + " rel_error"] + ([lb + " offset_spread"] if ens else [])
        w.writerow(head + ["wall_s", "cpu_s", "run_wall_s", "steps", "particles", "file", "note"])
        for r in study.rows:
            line = [repr(r["cell"]), repr(r["cfl"]), r["status"]]
            for lb in labels:
                line += [_g(r["values"][lb], "%.10g"), _g(errors[lb][(r["cell"], r["cfl"])], "%.4e")]
                line += [_g(_spread(r, lb), "%.10g")] if ens else []
            w.writerow(line + ["%.3f" % r["wall_s"], "%.3f" % r["cpu_s"], _g(r["run_wall_s"], "%.3f"), r["steps"],
                               r["particles"], os.path.relpath(r["file"], os.path.dirname(os.path.abspath(path))),
                               r["note"]])


def _direction_lines(levels_analysis, what, scale_unit=None):
    """Lines describing one direction's analysis: every triple, then the estimate."""
    lines = []
    a = levels_analysis
    if len(a["levels"]) < 3:
        b = a["best"]
        if b is not None:
            lines.append("%s: 2 levels, assumed order %g: extrapolated %.6g (GCI %.3g %%)"
                         % (what, b.order, b.limit, 100 * b.gci))
        elif len(a["levels"]) == 2:
            f1, f2 = a["values"]
            lines.append("%s: 2 levels only (%.6g, %.6g: change %.3g %%): no order" % (what, f1, f2,
                         100 * (f2 - f1) / abs(f2) if f2 else math.inf))
        return lines
    for t in a["triples"]:
        lines.append("%s: %s" % (what, t.describe()))
    return lines


def summary_lines(study):
    """The Markdown summary as lines: per output, the values (and CPU s) by cell and C, the analysis
    along each direction, the reference and the cheapest run within the tolerance."""
    k, lu = _length_scale(study.cells)
    out = ["# Resolution study of `%s`" % os.path.basename(study.scene), ""]
    out.append("%s; program `%s`; %d thread(s) per run%s." % (
        getattr(study, "created", ""), study.program, getattr(study, "threads", 1),
        ("; every run with " + ", ".join("`--set %s`" % s for s in study.sets)) if study.sets else ""))
    if getattr(study, "scale_with_cell", None):
        out[-1] += " Scaled with the cell: %s." % ", ".join("`%s`" % s for s in study.scale_with_cell)
    ens = _ensembles(study)
    if ens:
        out[-1] += (" Every (h, C) ran with the grid moved by %s cells along %s: its value is the mean over "
                    "these offsets, ± half their range (the alignment spread)."
                    % (", ".join("%g" % o for o in study.offsets), study.offset_axes))
    out.append("")
    bad = [r for r in study.rows if r["status"] != "completed"]
    for r in bad:
        out.append("- **h = %g %s, C = %g: %s** %s" % (r["cell"] * k, lu, r["cfl"], r["status"], r["note"]))
    if bad:
        out.append("")
    for o in study.outputs:
        a = study.analysis(o.label)
        unit = (" (%s)" % o.unit) if o.unit else ""
        out += ["## %s%s" % (o.label, unit), ""]
        out.append("| h (%s) \\ C | " % lu + " | ".join("%g" % c for c in study.cfls) + " |")
        out.append("|---" * (len(study.cfls) + 1) + "|")
        for h in study.cells:
            cells = []
            for c in study.cfls:
                row = next((r for r in study.rows if r["cell"] == h and r["cfl"] == c), None)
                if row is None:
                    cells.append("")
                elif row["status"] != "completed":
                    cells.append(row["status"])
                else:
                    err = a["errors"][(h, c)]
                    pm = " ± %.3g" % (0.5 * _spread(row, o.label)) if ens else ""
                    cells.append("%.6g%s (%s %%, %.3g s)"
                                 % (row["values"][o.label], pm, _g(100 * err, "%+.2g"), row["cpu_s"]))
            out.append("| %g | " % (h * k) + " | ".join(cells) + " |")
        ref, source = a["reference"]
        out += ["", "Each entry: value (relative error to the reference, CPU seconds of the run). Reference: "
                + ("%.6g, %s." % (ref, source) if ref is not None else source), ""]
        for c, la in a["along_cell"].items():
            out += ["- " + s for s in _direction_lines(la, "along h at C = %g" % c)]
        for h, la in a["along_cfl"].items():
            out += ["- " + s for s in _direction_lines(la, "along C at h = %g %s" % (h * k, lu))]
        for what, direction in (("h", a["along_cell"]), ("C", a["along_cfl"])):
            limits = [d["best"].limit for d in direction.values() if d["best"] is not None and d["best"].extrapolated]
            if len(limits) >= 2:
                lo, hi = min(limits), max(limits)
                out.append("- the %d limits in %s span %.6g to %.6g (%.2g %%): an uncertainty of the limit that one "
                           "triple's GCI does not show" % (len(limits), what, lo, hi, 100 * (hi - lo) / abs(hi)))
        if a["limit_both"] is not None:
            out += ["- " + s for s in _direction_lines(a["limit_both"], "the limits in C, along h")]
        if ens:
            out += ["- " + s for s in alignment_lines(study, o.label, k, lu)]
        rec = a["recommendation"]
        tol = 100 * study.tolerance
        if rec is None:
            out.append("- No run is within %g %% of the reference." % tol)
        else:
            out.append("- Cheapest run within %g %% of the reference: h = %g %s, C = %g (%.6g, %+.2f %%, %.3g CPU s)"
                       % (tol, rec["cell"] * k, lu, rec["cfl"], rec["values"][o.label],
                          100 * a["errors"][(rec["cell"], rec["cfl"])], rec["cpu_s"]))
        out.append("")
    return out


def alignment_lines(study, label, k=1.0, lu="m"):
    """Per cell size, the largest spread over the grid offsets (relative to the mean), and whether it
    shrinks with the cell: a spread that does not shrink is a discretization error of that size at
    every cell, which no single-grid run shows and no extrapolation removes."""
    lines = []
    worst = []
    for h in study.cells:
        rel = [abs(_spread(r, label) / r["values"][label]) for r in study.rows
               if r["cell"] == h and r["status"] == "completed" and r["values"][label]]
        rel = [x for x in rel if math.isfinite(x)]
        if rel:
            worst.append((h, max(rel)))
    if worst:
        lines.append("alignment spread (max - min over the offsets, of the mean), largest over C: "
                     + ", ".join("%.3g %% at h = %g %s" % (100 * x, h * k, lu) for h, x in worst))
    if len(worst) >= 2:
        shrinks = all(b[1] < a[1] for a, b in zip(worst, worst[1:]))
        lines.append("the alignment spread %s as the cell shrinks" % ("shrinks" if shrinks else "does not shrink steadily"))
    return lines


def write_markdown(study, path):
    with open(path, "w") as f:
        f.write("\n".join(summary_lines(study)) + "\n")


def _axis_label(outputs):
    """The output's name and unit; several outputs (named in the legend): the unit only."""
    unit = outputs[0].unit
    name = outputs[0].label if len(outputs) == 1 and len(outputs[0].label) <= 40 else "value"
    return name + (" (%s)" % unit if unit else "")


def _groups(outputs):
    """Outputs that share a unit go on one chart (e.g. the first- and second-order work)."""
    groups = {}
    for o in outputs:
        groups.setdefault(o.unit or ("-" + o.label), []).append(o)
    return list(groups.values())


MARKERS = "osD^v<>pP*X"


def _level_ticks(ax, levels):
    """A log axis with a tick at each level of the study, labelled plainly (5, 2.5, 1.25)."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(FixedLocator(sorted(levels)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: "%g" % x))
    ax.xaxis.set_minor_locator(NullLocator())


def _offset_bars(ax, study, label, rows, x_key, x_scale, color):
    """With grid offsets: a bar from the smallest to the largest value over the offsets at each point."""
    if not _ensembles(study):
        return
    pts = [(r[x_key] * x_scale, r["values"][label], r["spread"][label]) for r in rows
           if r["status"] == "completed" and math.isfinite(r["values"][label])]
    if pts:
        ax.errorbar([p[0] for p in pts], [p[1] for p in pts],
                    yerr=[[p[1] - p[2][0] for p in pts], [p[2][1] - p[1] for p in pts]],
                    fmt="none", ecolor=color, elinewidth=0.8, capsize=3)


def write_charts(study, directory):
    """Per group of outputs with one unit: value against the cell size (one line per C, dashed: the
    extrapolated limit), value against C (one line per cell size), and the work-precision chart:
    |relative error to the reference| against the CPU seconds of each run. Returns the files."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("frictherm.study: no charts (matplotlib is not installed: Debian python3-matplotlib)")
        return []
    k, lu = _length_scale(study.cells)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    files = []
    for group in _groups(study.outputs):
        stem = os.path.join(directory, _slug("_".join(o.label for o in group)))
        # value against the cell size
        if len(study.cells) > 1:
            fig, ax = plt.subplots(figsize=(6, 4.2))
            for j, o in enumerate(group):
                a = study.analysis(o.label)
                for i, c in enumerate(study.cfls):
                    la = a["along_cell"][c]
                    col = colors[(j * len(study.cfls) + i) % len(colors)]
                    ax.plot([h * k for h in la["levels"]], la["values"], MARKERS[j % len(MARKERS)] + "-", color=col,
                            label="%s, C = %g" % (o.label, c) if len(group) > 1 else "C = %g" % c)
                    _offset_bars(ax, study, o.label, [r for r in study.rows if r["cfl"] == c], "cell", k, col)
                    b = la["best"]
                    if b is not None and b.extrapolated and b.status in (MONOTONE, CONVERGED, "assumed order"):
                        ax.axhline(b.limit, color=col, ls="--", lw=0.8)
            _level_ticks(ax, [h * k for h in study.cells])
            ax.set_xlabel("cell size h (%s)" % lu)
            ax.set_ylabel(_axis_label(group))
            ax.set_title("against the cell size (dashed: extrapolated h → 0)", fontsize=9)
            ax.legend(fontsize=7)
            fig.tight_layout()
            files.append(stem + "_vs_cell.png")
            fig.savefig(files[-1], dpi=130)
            plt.close(fig)
        # value against C
        if len(study.cfls) > 1:
            fig, ax = plt.subplots(figsize=(6, 4.2))
            for j, o in enumerate(group):
                a = study.analysis(o.label)
                for i, h in enumerate(study.cells):
                    la = a["along_cfl"][h]
                    col = colors[(j * len(study.cells) + i) % len(colors)]
                    ax.plot(la["levels"], la["values"], MARKERS[j % len(MARKERS)] + "-", color=col,
                            label=("%s, " % o.label if len(group) > 1 else "") + "h = %g %s" % (h * k, lu))
                    _offset_bars(ax, study, o.label, [r for r in study.rows if r["cell"] == h], "cfl", 1.0, col)
                    b = la["best"]
                    if b is not None and b.extrapolated:
                        ax.axhline(b.limit, color=col, ls="--", lw=0.8)
            _level_ticks(ax, study.cfls)
            ax.set_xlabel("CFL factor C (time step = C h / wave speed)")
            ax.set_ylabel(_axis_label(group))
            ax.set_title("against C (dashed: extrapolated C → 0)", fontsize=9)
            ax.legend(fontsize=7)
            fig.tight_layout()
            files.append(stem + "_vs_cfl.png")
            fig.savefig(files[-1], dpi=130)
            plt.close(fig)
        # work-precision: error against cost
        fig, ax = plt.subplots(figsize=(6, 4.2))
        drawn = False
        for j, o in enumerate(group):
            a = study.analysis(o.label)
            for i, c in enumerate(study.cfls):
                errs = [(r, a["errors"][(r["cell"], c)]) for r in study.rows if r["cfl"] == c]
                pts = [(r["cpu_s"], abs(e), r["cell"]) for r, e in errs if math.isfinite(e) and e != 0]
                if not pts:
                    continue
                pts.sort()
                ax.plot([p[0] for p in pts], [100 * p[1] for p in pts], MARKERS[j % len(MARKERS)] + "-",
                        color=colors[(j * len(study.cfls) + i) % len(colors)],
                        label="%s, C = %g" % (o.label, c) if len(group) > 1 else "C = %g" % c)
                for x, y, h in pts if j == 0 else []:  # the first output's points carry the labels
                    ax.annotate("%g" % (h * k), (x, 100 * y), fontsize=6, xytext=(3, 3), textcoords="offset points")
                drawn = True
        if drawn:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("CPU time of the run (s)")
            ax.set_ylabel("|relative error| to the reference (%)")
            ref, source = study.analysis(group[0].label)["reference"]
            ax.set_title("work-precision (labels: h in %s); reference: %s" % (lu, source), fontsize=7)
            ax.legend(fontsize=7)
            fig.tight_layout()
            files.append(stem + "_error_vs_cpu.png")
            fig.savefig(files[-1], dpi=130)
        plt.close(fig)
    return files


def write_all(study, directory, charts=True):
    os.makedirs(directory, exist_ok=True)
    files = [os.path.join(directory, "study.csv"), os.path.join(directory, "study.md")]
    write_csv(study, files[0])
    write_markdown(study, files[1])
    if charts:
        files += write_charts(study, directory)
    return files
