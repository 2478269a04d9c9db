"""Resolution studies: run a scene over cell sizes and CFL factors, measure the cost of each run, and
estimate the observed order and the converged value of chosen outputs (docs/study.md).

    import frictherm.study as fs
    st = fs.run_study("examples/sliding_block.json", cells=[5e-3, 2.5e-3, 1.25e-3], cfls=[0.5, 0.25],
                      outputs=["friction_work_second"], workdir="/tmp/study")
    st.rows                        # one dict per run: cell, cfl, status, values, wall_s, cpu_s, steps, ...
    st.analysis("friction_work_second")   # along_cell[C], along_cfl[h], reference, errors, recommendation
    st.write("/tmp/study")         # study.csv, study.md, <output>_vs_cell.png, _vs_cfl.png, _error_vs_cpu.png

or from a shell:

    python3 -m frictherm.study SCENE.json --cells 5e-3,2.5e-3,1.25e-3 --cfl 0.5,0.25 \\
        --output friction_work_second -o DIR

Each run is `frictherm run SCENE --set grid.cell_size=h --set solver.cfl=C` (grid.cells when the
scene gives cells) on one thread by default; its CPU time is the child's own (wait4), so `jobs` > 1
runs side by side without mixing the costs (the wall times then share the cores). A finished run
is reused when the same study is asked again with the same command (its record,
DIR/runs/NAME.json, holds the command and the cost), so a study can be extended by a finer cell
or redrawn for another output without rerunning.
"""
import argparse
import concurrent.futures
import datetime
import json
import math
import os
import sys

from . import open as open_run
from .study_analysis import study_levels
from .study_runs import (Output, cell_sets, find_program, last_line, offset_sets, read_scene, run_program, scene_cfl,
                         validate)

__all__ = ["run_study", "Study", "Output", "find_program", "main"]


def _run_name(cell, cfl, offset=0.0):
    return "h%.6g_C%.6g" % (cell, cfl) + ("_o%.6g" % offset if offset else "")


class Study:
    """The runs of a study and their analysis. ``rows``: one dict per (cell, C) with keys cell, cfl,
    status (the run's /meta/status, or "error"), values {label: float}, wall_s (the child's wall
    time), cpu_s (its user + system CPU time), run_wall_s (the run's own /meta/wall_time), steps,
    particles, file, note. ``outputs``: the Output objects; ``reference``: {label: given value}.
    With several grid offsets (``offsets``, fractions of a cell along ``offset_axes``) a row is the
    ensemble of its (cell, C): values the mean over the offsets, ``spread`` {label: (min, max)},
    costs summed, ``members`` the rows of the single runs (each with its ``offset``)."""

    def __init__(self, scene, rows, outputs, cells, cfls, sets=(), reference=None, assumed_order=None,
                 tolerance=0.01, program=None, offsets=(0.0,), offset_axes="x"):
        self.scene, self.rows, self.outputs = scene, rows, list(outputs)
        self.cells, self.cfls = sorted(cells, reverse=True), sorted(cfls, reverse=True)
        self.sets, self.program = list(sets), program
        self.reference = dict(reference or {})
        self.assumed_order, self.tolerance = assumed_order, tolerance
        self.offsets, self.offset_axes = [float(o) for o in offsets], offset_axes
        self._analysis = {}

    def output(self, label):
        for o in self.outputs:
            if o.label == label or o.spec == label:
                return o
        raise KeyError("no output %s in this study (%s)" % (label, ", ".join(o.label for o in self.outputs)))

    def value(self, label, cell, cfl):
        for r in self.rows:
            if r["cell"] == cell and r["cfl"] == cfl:
                return r["values"].get(label, math.nan)
        return math.nan

    def analysis(self, label):
        """The analysis of one output (a dict):
        along_cell {C: study_levels over the cells}, along_cfl {h: study_levels over the C},
        limit_both (the along-cell extrapolation of the along-C limits, when >= 3 cells have one),
        reference (value, source), errors {(cell, C): (f - reference)/|reference|},
        recommendation (the row of the cheapest run within `tolerance` of the reference, or None)."""
        label = self.output(label).label
        if label in self._analysis:
            return self._analysis[label]
        along_cell = {c: study_levels(self.cells, [self.value(label, h, c) for h in self.cells], self.assumed_order)
                      for c in self.cfls}
        along_cfl = {h: study_levels(self.cfls, [self.value(label, h, c) for c in self.cfls], self.assumed_order)
                     for h in self.cells}
        c_limits = [(h, a["best"].limit) for h, a in along_cfl.items()
                    if a["best"] is not None and a["best"].extrapolated]
        limit_both = study_levels([h for h, _ in c_limits], [f for _, f in c_limits]) if len(c_limits) >= 3 else None
        ref, source = self._reference(label, along_cell, along_cfl, limit_both)
        errors = {}
        for r in self.rows:
            f = r["values"].get(label, math.nan)
            ok = ref not in (None, 0) and math.isfinite(f)
            errors[(r["cell"], r["cfl"])] = (f - ref) / abs(ref) if ok else math.nan
        ok = [r for r in self.rows if r["status"] == "completed" and math.isfinite(errors[(r["cell"], r["cfl"])])
              and abs(errors[(r["cell"], r["cfl"])]) <= self.tolerance]
        rec = min(ok, key=lambda r: r["cpu_s"]) if ok else None
        a = dict(along_cell=along_cell, along_cfl=along_cfl, limit_both=limit_both, reference=(ref, source),
                 errors=errors, recommendation=rec)
        self._analysis[label] = a
        return a

    def _reference(self, label, along_cell, along_cfl, limit_both):
        """The value errors are measured against, best first: the one given; the limit in both h and C;
        the limit in h at the smallest C that has one; the limit in C at the smallest h that has one;
        the finest, smallest-C run."""
        if label in self.reference:
            return float(self.reference[label]), "given"
        if limit_both and limit_both["best"] is not None and limit_both["best"].extrapolated:
            return limit_both["best"].limit, "extrapolated in C at each cell, then in the cell size"
        for c in sorted(along_cell):
            b = along_cell[c]["best"]
            if b is not None and b.extrapolated:
                return b.limit, "extrapolated in the cell size at C = %g" % c
        for h in sorted(along_cfl):
            b = along_cfl[h]["best"]
            if b is not None and b.extrapolated:
                return b.limit, "extrapolated in C at h = %g m" % h
        have = [r for r in self.rows if math.isfinite(r["values"].get(label, math.nan))]
        if have:
            r = min(have, key=lambda r: (r["cell"], r["cfl"]))
            return (r["values"][label], "the finest run (h = %g m, C = %g): no extrapolation possible"
                    % (r["cell"], r["cfl"]))
        return None, "none (no run has a value)"

    def write(self, directory, charts=True):
        """study.csv, study.md and the charts into `directory`; returns the list of files written."""
        from .study_report import write_all
        return write_all(self, directory, charts=charts)


def _plan(scene_path, cells, cfls, sets, scale_with_cell, offsets=(0.0,), offset_axes="x"):
    scene = read_scene(scene_path)
    plan = []
    for cell in cells:
        csets, _ = cell_sets(scene, cell, scale_with_cell)
        for cfl in cfls:
            for offset in offsets:
                plan.append((cell, cfl, offset, list(sets) + csets + offset_sets(scene, cell, offset, offset_axes)
                             + ["solver.cfl=%r" % float(cfl)]))
    return plan


def _ensemble_row(members, outputs):
    """One (cell, C) over several grid offsets: the mean of each output over the completed members
    (NaN unless all completed), its (min, max), the costs summed (the ensemble's cost)."""
    first = members[0]
    bad = [m for m in members if m["status"] != "completed"]
    row = dict(first, members=members, values={}, spread={},
               status=bad[0]["status"] if bad else "completed",
               note="; ".join("offset %g: %s" % (m["offset"], m["note"] or m["status"]) for m in bad),
               wall_s=sum(m["wall_s"] for m in members), cpu_s=sum(m["cpu_s"] for m in members),
               run_wall_s=sum(m["run_wall_s"] for m in members))
    for o in outputs:
        vals = [m["values"][o.label] for m in members]
        ok = not bad and all(math.isfinite(v) for v in vals)
        row["values"][o.label] = sum(vals) / len(vals) if ok else math.nan
        row["spread"][o.label] = (min(vals), max(vals)) if ok else (math.nan, math.nan)
    return row


def _command(program, scene_path, out, threads, run_sets):
    cmd = [program, "run", os.path.abspath(scene_path), "-o", out, "--force", "--quiet", "--threads", str(threads)]
    for s in run_sets:
        cmd += ["--set", s]
    return cmd


def _record(out, record_path, cmd):
    """The record of an earlier run of the same command whose output is still there, else None."""
    if os.path.exists(out) and os.path.exists(record_path):
        with open(record_path) as f:
            old = json.load(f)
        if old.get("command") == cmd:
            return old
    return None


def _skipped_row(cell, cfl, offset, outputs, runs_dir, note):
    return dict(cell=cell, cfl=cfl, offset=offset, status="skipped", values={o.label: math.nan for o in outputs},
                wall_s=math.nan, cpu_s=math.nan, run_wall_s=math.nan, steps=0, particles=0,
                file=os.path.join(runs_dir, _run_name(cell, cfl, offset) + ".h5"), note=note, returncode=None)


def _one_run(program, scene_path, cell, cfl, offset, run_sets, threads, runs_dir, outputs, reuse):
    name = _run_name(cell, cfl, offset)
    out = os.path.join(runs_dir, name + ".h5")
    record_path = os.path.join(runs_dir, name + ".json")
    cmd = _command(program, scene_path, out, threads, run_sets)
    record = _record(out, record_path, cmd) if reuse else None
    if record is None:
        rc, wall, cpu = run_program(cmd, os.path.join(runs_dir, name + ".log"))
        record = dict(command=cmd, returncode=rc, wall_s=wall, cpu_s=cpu,
                      note="" if rc == 0 else last_line(os.path.join(runs_dir, name + ".log")))
        with open(record_path, "w") as f:
            json.dump(record, f, indent=1)
    row = dict(cell=cell, cfl=cfl, offset=offset, status="error", values={o.label: math.nan for o in outputs},
               wall_s=record["wall_s"],
               cpu_s=record["cpu_s"], run_wall_s=math.nan, steps=0, particles=0, file=out, note=record["note"],
               returncode=record["returncode"])
    if not os.path.exists(out):
        return row
    with open_run(out) as run:
        m = run.meta
        row.update(status=m.get("status", "unknown"), run_wall_s=float(m.get("wall_time", math.nan)),
                   steps=int(m.get("steps", 0)), particles=int(m.get("particle_count", 0)))
        # the run is the one asked for: its own record of the cell size and C
        if "cfl" in m and abs(float(m["cfl"]) - cfl) > 1e-12 * cfl:
            raise RuntimeError("%s: the run's C is %g, not %g" % (out, m["cfl"], cfl))
        if row["status"] == "completed":
            for o in outputs:
                try:
                    row["values"][o.label] = o.value(run)
                except (KeyError, ValueError) as e:
                    raise type(e)("%s (run %s)" % (e.args[0] if e.args else e, name)) from None
    return row


def run_study(scene, cells=None, cfls=None, outputs=("friction_work_second",), reduce="final", sets=(),
              scale_with_cell=(), threads=1, jobs=1, program=None, workdir=None, reuse=True, reference=None,
              assumed_order=None, tolerance=0.01, units=None, max_cpu=None, plan_only=False, write=True, charts=True,
              offsets=None, offset_axes="x", log=print):
    """Runs `scene` at every cell size of `cells` (m; default the scene's own) and CFL factor of
    `cfls` (default the scene's own) and returns a Study.

    outputs   what to read from each run: strings "COLUMN[:REDUCE]" or "meta:KEY", or callables
              run -> float, or Output objects (frictherm.study_runs.Output); `reduce` is the default
              reduction of a series column (final, max, min, mean, at=T, since=T)
    sets      further --set overrides for every run ("coupling.continuation=null", ...)
    scale_with_cell  keys (m) to scale with the cell size, e.g. a pixel size that must stay the
              particle spacing; by default everything but the grid is kept
    threads   OpenMP threads of each run; jobs: runs at once (each child's CPU time is its own)
    workdir   where the runs (workdir/runs/) and, with write=True, the table, summary and charts go
    reuse     reuse finished runs of the same command (workdir/runs/NAME.json)
    reference {output label: value} to measure errors against (an analytic or reference code value)
              instead of the extrapolated one
    assumed_order  with only 2 levels in a direction, extrapolate with this order (marked as assumed)
    tolerance relative error to the reference for the recommended (cheapest sufficient) run
    units     {output label: unit} for the charts (else guessed: J for work, K for temperature)
    max_cpu   skip a run whose CPU time, predicted from the finished ones (CPU s per particle-step
              times its particles x steps from `frictherm validate`), exceeds this many seconds
    offsets   grid offsets in cells, e.g. [0, 0.5]: each (cell, C) runs once per offset with the grid
              moved under the scene along `offset_axes` ("x", "xy"); its values are the mean over the
              offsets and their range the alignment spread (docs/study.md, "Grid alignment")
    plan_only check every combination with `frictherm validate` and return
              {(cell, C): (particles, estimated steps)} ({(cell, C, offset): ...} with several
              offsets) without running anything
    log       a function for progress lines (None: quiet)
    """
    program = find_program(program)
    scene_obj = read_scene(scene)
    cells = [float(h) for h in (cells or [])]
    cfls = [float(c) for c in (cfls or [scene_cfl(scene_obj)])]
    outs = []
    for o in outputs:
        if not isinstance(o, Output):
            o = Output(o, reduce=reduce)
        if units and o.label in units:
            o.unit = units[o.label]
        outs.append(o)
    if len({o.label for o in outs}) != len(outs):
        raise ValueError("two outputs share the label %s" % [o.label for o in outs])
    if not cells:
        own = scene_obj.get("grid", {}).get("cell_size")
        if own is None:
            raise ValueError("the scene gives grid.cells: pass the cell sizes to study (cells=[...], --cells)")
        cells = [float(own[0] if isinstance(own, list) else own)]
    if len(set(cells)) != len(cells) or len(set(cfls)) != len(cfls):
        raise ValueError("the cell sizes and the C values must each be distinct")
    offsets = [float(o) for o in (offsets or [0.0])]
    if len(set(offsets)) != len(offsets):
        raise ValueError("the grid offsets must be distinct")
    plan = _plan(scene, cells, cfls, sets, scale_with_cell, offsets, offset_axes)
    workdir = workdir or os.path.join(os.getcwd(), os.path.splitext(os.path.basename(scene))[0] + "_study")
    runs_dir = os.path.join(workdir, "runs")
    if log:
        log("study of %s: %d runs (cells %s m, C %s%s), %d thread(s) each, %d at once, in %s"
            % (scene, len(plan), ", ".join("%g" % h for h in sorted(cells, reverse=True)),
               ", ".join("%g" % c for c in sorted(cfls, reverse=True)),
               "; grid offsets %s cells along %s" % (", ".join("%g" % o for o in offsets), offset_axes)
               if len(offsets) > 1 else "", threads, jobs, runs_dir))
    plan.sort(key=lambda p: (-p[0], -p[1], p[2]))  # cheapest first: a broken set-up shows at once
    # scene errors now
    estimates = {(cell, cfl, off): validate(program, scene, run_sets) for cell, cfl, off, run_sets in plan}
    if log:
        for cell, cfl, off, _ in plan:
            n, steps = estimates[(cell, cfl, off)]
            log("  plan: h = %-9g C = %-7g %s%9s particles x %9s steps"
                % (cell, cfl, "offset %-5g " % off if len(offsets) > 1 else "", n, steps))
    if plan_only:  # keyed (cell, C), or (cell, C, offset) with several offsets
        return estimates if len(offsets) > 1 else {(h, c): v for (h, c, _), v in estimates.items()}
    os.makedirs(runs_dir, exist_ok=True)
    rows = []

    def done(row):
        row["estimate"] = estimates[(row["cell"], row["cfl"], row["offset"])]
        rows.append(row)
        if log:
            vals = "  ".join("%s = %.6g" % (k, v) for k, v in row["values"].items())
            log("  h = %-9g C = %-7g %s%-10s %7.1f s CPU %7.1f s wall  %d steps  %s%s"
                % (row["cell"], row["cfl"], "offset %-5g " % row["offset"] if len(offsets) > 1 else "",
                   row["status"], row["cpu_s"], row["wall_s"], row["steps"], vals,
                   ("  (" + row["note"] + ")") if row["note"] else ""))

    def predicted_cpu(cell, cfl, offset):
        """CPU s of a run from the finished ones: CPU s per particle-step times its particles x steps."""
        rates = sorted(r["cpu_s"] / (r["particles"] * r["steps"]) for r in rows
                       if r["status"] == "completed" and r["particles"] and r["steps"])
        n, steps = estimates[(cell, cfl, offset)]
        if not rates or not n or not steps:
            return None
        return rates[len(rates) // 2] * n * steps

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        pending = set()
        for cell, cfl, off, run_sets in plan:
            while len(pending) >= max(1, jobs):
                finished, pending = concurrent.futures.wait(pending, return_when=concurrent.futures.FIRST_COMPLETED)
                for fut in finished:
                    done(fut.result())
            guess = predicted_cpu(cell, cfl, off) if max_cpu else None
            out = os.path.join(runs_dir, _run_name(cell, cfl, off) + ".h5")
            cmd = _command(program, scene, out, threads, run_sets)
            if guess is not None and guess > max_cpu and not (reuse and _record(out, out[:-3] + ".json", cmd)):
                done(_skipped_row(cell, cfl, off, outs, runs_dir,
                                  "predicted %.0f s CPU > max_cpu %g s" % (guess, max_cpu)))
                continue
            pending.add(pool.submit(_one_run, program, scene, cell, cfl, off, run_sets, threads, runs_dir, outs,
                                    reuse))
        for fut in concurrent.futures.as_completed(pending):
            done(fut.result())
    rows.sort(key=lambda r: (-r["cell"], -r["cfl"], r["offset"]))
    if len(offsets) > 1:  # one row per (cell, C): the ensemble over the offsets
        groups = {}
        for r in rows:
            groups.setdefault((r["cell"], r["cfl"]), []).append(r)
        rows = [_ensemble_row(members, outs) for members in groups.values()]
    study = Study(scene, rows, outs, cells, cfls, sets=sets, reference=reference, assumed_order=assumed_order,
                  tolerance=tolerance, program=program, offsets=offsets, offset_axes=offset_axes)
    study.created = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    study.threads, study.scale_with_cell = threads, list(scale_with_cell)
    if write:
        files = study.write(workdir, charts=charts)
        if log:
            log("wrote " + ", ".join(os.path.relpath(f) for f in files))
    return study


def parse_floats(text):
    return [float(x) for x in text.replace(" ", "").split(",") if x]


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python3 -m frictherm.study",
        description="Run a scene over cell sizes and CFL factors; write a table (study.csv), a summary with the "
                    "observed order and the extrapolated value (study.md) and charts of an output against the "
                    "resolution and the cost. docs/study.md.")
    ap.add_argument("scene")
    ap.add_argument("--cells", type=parse_floats, help="cell sizes in m, comma-separated (default: the scene's)")
    ap.add_argument("--cfl", type=parse_floats, help="CFL factors C, comma-separated (default: the scene's)")
    ap.add_argument("--output", action="append", default=None,
                    help="a /series column, COLUMN:REDUCE (final, max, min, mean, at=T, since=T) or meta:KEY; "
                         "repeatable (default friction_work_second)")
    ap.add_argument("--reduce", default="final", help="default reduction of a series column (default final)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="a --set for every run")
    ap.add_argument("--scale-with-cell", action="append", default=[], metavar="KEY",
                    help="a scene key (m) that scales with the cell size, e.g. bodies[0].shape.pixel_size")
    ap.add_argument("--reference", action="append", default=[], metavar="[OUTPUT=]VALUE",
                    help="measure errors against this value (e.g. an analytic one) instead of the extrapolated one")
    ap.add_argument("--unit", action="append", default=[], metavar="[OUTPUT=]UNIT", help="unit of an output's axis")
    ap.add_argument("--assumed-order", type=float, help="extrapolate two levels with this order (marked assumed)")
    ap.add_argument("--tolerance", type=float, default=0.01,
                    help="relative error for the recommended (cheapest sufficient) run (default 0.01)")
    ap.add_argument("--threads", type=int, default=1, help="threads per run (default 1)")
    ap.add_argument("-j", "--jobs", type=int, default=1, help="runs at once (default 1)")
    ap.add_argument("--frictherm", help="the frictherm program (default: $FRICTHERM, PATH, the build tree)")
    ap.add_argument("-o", "--out", help="directory for runs, table and charts (default SCENE_study)")
    ap.add_argument("--max-cpu", type=float, metavar="S",
                    help="skip runs predicted (from the finished ones) to take more than S CPU seconds")
    ap.add_argument("--offsets", type=parse_floats, metavar="O1,O2,...",
                    help="grid offsets in cells, e.g. 0,0.5: every (h, C) runs once per offset, its value the mean "
                         "and the range the alignment spread")
    ap.add_argument("--offset-axes", default="x", help="the axes the grid moves along (default x)")
    ap.add_argument("--plan", action="store_true", help="validate every combination, print the plan, run nothing")
    ap.add_argument("--rerun", action="store_true", help="rerun even runs that are already there")
    ap.add_argument("--no-charts", action="store_true")
    ap.add_argument("-q", "--quiet", action="store_true")
    a = ap.parse_args(argv)
    outputs = a.output or ["friction_work_second"]
    labels = [Output(o, reduce=a.reduce).label for o in outputs]

    def per_output(items, convert, what):
        d = {}
        for item in items:
            key, sep, val = item.rpartition("=") if "=" in item else ("", "", item)
            if not sep:
                if len(labels) != 1:
                    ap.error("%s %s: name the output (OUTPUT=VALUE) when there are several" % (what, item))
                key = labels[0]
            if key not in labels:
                ap.error("%s %s: no output %s (outputs: %s)" % (what, item, key, ", ".join(labels)))
            d[key] = convert(val)
        return d

    reference = per_output(a.reference, float, "--reference")
    units = per_output(a.unit, str, "--unit")
    try:
        study = run_study(a.scene, cells=a.cells, cfls=a.cfl, outputs=outputs, reduce=a.reduce, sets=a.set,
                          scale_with_cell=a.scale_with_cell, threads=a.threads, jobs=a.jobs, program=a.frictherm,
                          workdir=a.out, reuse=not a.rerun, reference=reference, assumed_order=a.assumed_order,
                          tolerance=a.tolerance, units=units, max_cpu=a.max_cpu, plan_only=a.plan,
                          charts=not a.no_charts, offsets=a.offsets, offset_axes=a.offset_axes,
                          log=None if a.quiet and not a.plan else print)
    except (ValueError, KeyError, FileNotFoundError, RuntimeError) as e:
        print("frictherm.study: %s" % (e.args[0] if e.args else e), file=sys.stderr)
        return 2
    if a.plan:
        return 0
    if not a.quiet:
        from .study_report import summary_lines
        print("\n".join(summary_lines(study)))
    return 0 if all(r["status"] in ("completed", "skipped") for r in study.rows) else 1


if __name__ == "__main__":
    sys.exit(main())
