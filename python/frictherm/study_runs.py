"""The runs of a resolution study: finding the `frictherm` program, reading the scene, the `--set`
overrides of each (cell size, C) combination, running the program with its cost measured, and the
outputs read from each result file (frictherm/study.py puts them together)."""
import difflib
import json
import math
import os
import shutil
import subprocess
import time

import numpy as np

# ---------------------------------------------------------------------------------------------
# The program


def find_program(program=None):
    """The `frictherm` executable: `program` if given, else $FRICTHERM, $FRICTHERM_EXE, `frictherm`
    on PATH, else the build tree next to this package (source tree: python/frictherm ->
    build/coupling/frictherm; build tree: build/python/frictherm -> build/coupling/frictherm)."""
    tried = []
    candidates = [program] if program else [os.environ.get("FRICTHERM"), os.environ.get("FRICTHERM_EXE"),
                                             shutil.which("frictherm")]
    if not program:
        here = os.path.dirname(os.path.abspath(__file__))
        candidates += [os.path.join(here, "..", "..", "build", "coupling", "frictherm"),
                       os.path.join(here, "..", "..", "coupling", "frictherm")]
    for c in candidates:
        if not c:
            continue
        tried.append(c)
        if os.path.isfile(c) and os.access(c, os.X_OK):
            return os.path.abspath(c)
    raise FileNotFoundError("cannot find the frictherm program (tried %s); pass program=PATH (--frictherm PATH) "
                            "or set FRICTHERM" % (", ".join(tried) or "nothing"))


# ---------------------------------------------------------------------------------------------
# The scene


def strip_comments(text):
    """JSON text without // and /* */ comments (the scene reader ignores them too), strings kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            if j < 0:
                raise ValueError("unterminated /* comment")
            i = j + 2
        else:
            out.append(c)
            i += 1
    return "".join(out)


def read_scene(path):
    with open(path) as f:
        text = f.read()
    try:
        return json.loads(strip_comments(text))
    except ValueError as e:
        raise ValueError("%s: not a JSON scene (%s)" % (path, e)) from None


def _path_tokens(key):
    """'bodies[0].shape.pixel_size' -> ['bodies', 0, 'shape', 'pixel_size']."""
    tokens = []
    for part in key.split("."):
        name, _, rest = part.partition("[")
        if name:
            tokens.append(name)
        while rest:
            idx, _, rest = rest.partition("]")
            tokens.append(int(idx))
            rest = rest[1:] if rest.startswith("[") else rest
    return tokens


def scene_value(scene, key):
    node = scene
    for t in _path_tokens(key):
        try:
            node = node[t]
        except (KeyError, IndexError, TypeError):
            raise KeyError("the scene has no key %s" % key) from None
    return node


def _format(value):
    return json.dumps(value) if not isinstance(value, float) else repr(value)


def cell_sets(scene, cell, scale_with_cell=()):
    """The --set overrides that make the scene's cells `cell` (m) wide: grid.cell_size, or grid.cells
    (per direction, (hi - lo)/cell, which must be whole) when the scene gives its grid in cells, and
    every key of `scale_with_cell` (a number or vector in m, e.g. a pixel size that must follow the
    particle spacing) scaled by cell / the scene's own cell size."""
    grid = scene.get("grid", {})
    lo, hi = grid.get("lo"), grid.get("hi")
    if "cell_size" in grid:
        own = grid["cell_size"]
        if isinstance(own, list):
            if max(own) - min(own) > 1e-12 * max(own):
                raise ValueError("grid.cell_size is %r, not one size for all directions: a study over cell sizes "
                                 "needs one (give grid.cell_size as a number)" % (own,))
            own = own[0]
        sets = ["grid.cell_size=%r" % float(cell)]
    elif "cells" in grid:
        if lo is None or hi is None:
            raise ValueError("grid.cells without grid.lo and grid.hi: cannot turn a cell size into cells")
        counts = [(b - a) / cell for a, b in zip(lo, hi)]
        whole = [int(round(c)) for c in counts]
        if any(abs(c - w) > 1e-6 * max(1.0, c) for c, w in zip(counts, whole)):
            raise ValueError("grid.cells: a cell size of %g m does not divide the grid (hi - lo = %s m) into whole "
                             "cells" % (cell, [b - a for a, b in zip(lo, hi)]))
        sizes = [(b - a) / c for a, b, c in zip(lo, hi, grid["cells"])]
        if max(sizes) - min(sizes) > 1e-9 * max(sizes):
            raise ValueError("grid.cells gives cells of %s m, not square: a study over cell sizes needs square cells"
                             % sizes)
        own = sizes[0]
        sets = ["grid.cells=%s" % json.dumps(whole)]
    else:
        raise ValueError("the scene's grid has neither grid.cell_size nor grid.cells")
    for key in scale_with_cell:
        v = scene_value(scene, key)
        factor = float(cell) / float(own)
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            scaled = float(v) * factor
        elif isinstance(v, list) and all(isinstance(x, (int, float)) for x in v):
            scaled = [float(x) * factor for x in v]
        else:
            raise ValueError("%s is %r: only a number or a vector can scale with the cell size" % (key, v))
        sets.append("%s=%s" % (key, _format(scaled)))
    return sets, float(own)


AXES = "xyz"


def offset_sets(scene, cell, offset, axes="x"):
    """The --set overrides that move the grid by `offset` cells (a fraction in [0, 1)) along `axes`
    ("x", "xy", ...) under a scene that stays put: grid.lo and grid.hi each less offset x cell there.
    Where a body's edge falls on a node line, offset 0.5 puts it in the middle of a cell: the spread of
    an output over offsets is the part of its discretization error that the grid's alignment makes
    (docs/study.md, "Grid alignment"). An offset of 0 is the scene's own grid (no override). Only
    axes whose grid faces carry no boundary condition and whose bodies keep a margin to the grid's
    faces should move; `frictherm validate` refuses a body that leaves the grid."""
    offset = float(offset)
    if not 0.0 <= offset < 1.0:
        raise ValueError("grid offset %r: an offset is a fraction of a cell in [0, 1)" % offset)
    if offset == 0.0:
        return []
    grid = scene.get("grid", {})
    lo, hi = grid.get("lo"), grid.get("hi")
    if not isinstance(lo, list) or not isinstance(hi, list) or len(lo) != len(hi):
        raise ValueError("grid offsets move grid.lo and grid.hi: the scene must give both as vectors")
    if not axes or any(a not in AXES[:len(lo)] for a in axes) or len(set(axes)) != len(axes):
        raise ValueError("grid offset axes %r: letters of %r (the grid has %d dimensions)"
                         % (axes, AXES[:len(lo)], len(lo)))
    moved_lo, moved_hi = [float(x) for x in lo], [float(x) for x in hi]
    for a in axes:
        i = AXES.index(a)
        moved_lo[i] -= offset * float(cell)
        moved_hi[i] -= offset * float(cell)
    return ["grid.lo=%s" % json.dumps(moved_lo), "grid.hi=%s" % json.dumps(moved_hi)]


def scene_cfl(scene):
    return float(scene.get("solver", {}).get("cfl", 0.5))  # docs/scenes.md: solver.cfl defaults to 0.5


# ---------------------------------------------------------------------------------------------
# Running


def validate(program, scene_path, sets):
    """`frictherm validate SCENE --set ...`: checks one combination before anything runs and returns
    its particle count and estimated step count (docs/scenes.md, "Cost limits"). A scene error is a
    ValueError with the program's message, which names the key."""
    cmd = [program, "validate", scene_path]
    for s in sets:
        cmd += ["--set", s]
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        msg = [ln for ln in p.stdout.splitlines() if ln.strip()]
        why = msg[-1] if msg else "frictherm validate failed (exit code %d)" % p.returncode
        raise ValueError("%s with %s: %s" % (os.path.basename(scene_path), " ".join("--set " + s for s in sets), why))
    particles = steps = None
    for line in p.stdout.splitlines():
        words = line.split()
        if len(words) >= 2 and words[0] == "particles" and words[1].isdigit():
            particles = int(words[1])
        elif len(words) >= 3 and words[0] == "steps" and words[1] == "about" and words[2].isdigit():
            steps = int(words[2])
    return particles, steps


def run_program(cmd, log_path, env=None):
    """Runs `cmd` with its output to `log_path`. Returns (exit code, wall s, CPU s): the CPU time of
    the child alone (user + system, from wait4), so runs made side by side are measured apart."""
    with open(log_path, "w") as log:
        start = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
        try:
            _, status, usage = os.wait4(p.pid, 0)
        except BaseException:
            p.kill()
            p.wait()
            raise
        wall = time.perf_counter() - start
    p.returncode = os.waitstatus_to_exitcode(status)
    return p.returncode, wall, usage.ru_utime + usage.ru_stime


def last_line(path, limit=300):
    try:
        with open(path) as f:
            lines = [ln.strip() for ln in f if ln.strip()]
    except OSError:
        return ""
    return lines[-1][:limit] if lines else ""


# ---------------------------------------------------------------------------------------------
# Outputs

REDUCTIONS = ("final", "max", "min", "mean", "at=T", "since=T")


class Output:
    """One quantity read from each run.

    `spec` is "COLUMN" or "COLUMN:REDUCE" with COLUMN a /series column (e.g. friction_work_second,
    max_temperature, hotspot_count) and REDUCE one of final, max, min, mean, at=T (the value at time
    T s, interpolated), since=T (final minus the value at T: e.g. the work after a preload ramp);
    or "meta:KEY" for a number of /meta (e.g. meta:heat_delivered, meta:steps); or a callable
    run -> float (Python only; `label` then names it). `unit` is guessed from the name unless given."""

    def __init__(self, spec, reduce="final", label=None, unit=None):
        self.spec, self.func = spec, None
        if callable(spec):
            self.func, self.kind, self.column, self.reduce = spec, "callable", None, None
            self.label = label or getattr(spec, "__name__", "output")
        elif spec.startswith("meta:"):
            self.kind, self.column, self.reduce = "meta", spec[5:], None
            self.label = label or spec
        else:
            column, _, red = spec.partition(":")
            self.kind, self.column, self.reduce = "series", column, red or reduce
            name = self.reduce.split("=")[0]
            timed = name in ("at", "since")
            if name not in ("final", "max", "min", "mean", "at", "since") or timed != ("=" in self.reduce):
                raise ValueError("%s: unknown reduction '%s' (one of %s)" % (spec, self.reduce, ", ".join(REDUCTIONS)))
            if "=" in self.reduce:
                self.time = float(self.reduce.split("=", 1)[1])
            self.label = label or (column if self.reduce == "final" else "%s:%s" % (column, self.reduce))
        self.unit = unit if unit is not None else guess_unit(self.column or self.label)

    def value(self, run):
        if self.func is not None:
            return float(self.func(run))
        if self.kind == "meta":
            if self.column not in run.meta:
                raise KeyError("%s: /meta has no %s%s" % (run.path, self.column, _close(self.column, run.meta)))
            return float(run.meta[self.column])
        s = run.series
        if self.column not in s:
            raise KeyError("%s: /series has no column %s%s" % (run.path, self.column, _close(self.column, s.columns)))
        y = np.asarray(s[self.column], dtype=float)
        if len(y) == 0:
            return math.nan
        name = self.reduce.split("=")[0]
        if name == "final":
            return float(y[-1])
        if name == "max":
            return float(np.max(y))
        if name == "min":
            return float(np.min(y))
        if name == "mean":  # time average (trapezoid rule over the series rows)
            t = np.asarray(s["time"], dtype=float)
            if t[-1] <= t[0]:
                return float(y[-1])
            return float(0.5 * np.sum((y[1:] + y[:-1]) * np.diff(t)) / (t[-1] - t[0]))
        t = np.asarray(s["time"], dtype=float)
        if not t[0] <= self.time <= t[-1]:
            raise ValueError("%s: time %g s is outside the series (%g to %g s)" % (self.spec, self.time, t[0], t[-1]))
        at = float(np.interp(self.time, t, y))
        return at if name == "at" else float(y[-1]) - at

    def __repr__(self):
        return "Output(%r)" % (self.label,)


def _close(name, names):
    near = difflib.get_close_matches(name, list(names), n=4, cutoff=0.5)
    return " (did you mean %s?)" % ", ".join(near) if near else ""


def guess_unit(name):
    n = (name or "").lower()
    if "count" in n or n.startswith("meta:steps") or n.endswith("steps") or "contact_nodes" in n:
        return ""
    if "temperature" in n:
        return "K"
    if any(w in n for w in ("work", "energy", "heat")):
        return "J"
    if "momentum" in n:
        return "kg m/s"
    if "displacement" in n or "position" in n:
        return "m"
    if n.endswith("time") or n == "dt":
        return "s"
    return ""
