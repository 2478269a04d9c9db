#!/usr/bin/env python3
"""Damaged checkpoints (issue 34 item 4, docs/robustness.md "Damaged checkpoints"): a real checkpoint
of a small heated penalty-contact run (hot spots, a reaction, slip histories: every kind of state a
serial checkpoint holds) is damaged systematically and `frictherm resume` (and `frictherm continue`
on the end-of-loading checkpoint) is run on each damaged copy:

* every dataset deleted, emptied, truncated, padded, given another rank, another type (float <->
  integer, another width) or replaced by a group; NaN, +Inf and -Inf in every floating dataset;
  out-of-range values (-2, 2^31 - 1) in every integer dataset (the index arrays);
* the root attributes (format, dimension) deleted, changed, of another type;
* the file cut at several byte offsets and bytes flipped at several offsets.

Each damaged copy must be refused cleanly: exit code 2 and a message naming the dataset or attribute
at fault (the file, for byte-level damage), no signal, no sanitizer report, the run's result and
checkpoint byte-equal afterwards and no result written. The exceptions, each justified in HARMLESS
and FLIP_OK below, may also complete (exit code 0).

    damaged_checkpoints.py FRICTHERM_EXE [--full] [-k SUBSTRING] [--keep DIR] [-j JOBS] [-v]

Without --full (ctest): one damage per dataset, the kinds taken in rotation, the attribute damages,
5 cuts and a third of the flips (about 170 cases); --full: all of them (about 1600, minutes).
"""
import argparse
import concurrent.futures
import hashlib
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy

# The seed scene, tests/fuzz/checkpoint_seed_scene.json (also the checkpoint fuzzer's): a 2D block
# sliding on a base with penalty contact and Coulomb friction, frictional heat conducted on the grid, hot spots above 1 nK (so hot spots are tracked at the checkpoint) and an Arrhenius
# reaction (per-particle progress): 656 particles, 176 boundary points, 80 steps; 0.2 s of CPU.
SCENE = json.loads((pathlib.Path(__file__).resolve().parent.parent / "fuzz" / "checkpoint_seed_scene.json").read_text())
# Stored in /scene_overrides (so that dataset is not empty); the mid-loading checkpoint stops at step 60 of 80.
OVERRIDES = ["--set", "run.threads=1"]
MID_STEPS = 60

# Damage that leaves a valid checkpoint, so the command may complete (exit code 0) or refuse it.
HARMLESS = {
    "extra root attribute": "an attribute the reader does not know is never read",
    "extra dataset attribute": "an attribute the reader does not know is never read",
    "extra dataset": "a dataset the reader does not know is never read",
    "extra group": "a group the reader does not know is never read",
}
# A counter set to 2^31 - 1: a plausible count that only reports (integrator counts in /meta, the last
# step's contact counters in series rows, window counts) or, for the id counter and the penalty call
# counter, a valid state of another run. The corpus rewrites the value with a valid checksum (as a
# program that writes a wrong value would), so the checksum cannot tell it from the written one
# (docs/robustness.md "Damaged checkpoints").
PLAUSIBLE_COUNTERS = ("integrator/", "mechanics/contact_stats/", "books/windows", "books/steps",
                      "books/continuation_intervals", "hotspots/next_id", "mechanics/penalty/stamp", "window_steps",
                      "run/hotspot_windows_written")


def harmless(name, label):
    """Why damage `label` of dataset `name` leaves a valid checkpoint, or None."""
    if name == "scene_source" and label in ("emptied", "truncated to half", "one item short", "one item more"):
        return "/scene_source only names the scene and the folder relative image paths resolve against; this scene has none"
    if name == "scene_overrides" and label == "one item short":
        return "drops the final newline, a separator: the same overrides"
    if name == "scene_overrides" and label == "emptied":
        return ("drops run.threads=1, which OMP_NUM_THREADS=1 sets anyway (a checkpoint records no hash of its scene: "
                "an override lost that changed the physics would not be noticed; docs/robustness.md)")
    if name == "marks/table_names" and label == "one item short":
        return "drops the final newline, a separator: the same table names"
    if name == "marks/run_id" and label in ("emptied", "deleted"):
        return ("a checkpoint without a run id is one of a version before run ids, accepted by design "
                "(docs/checkpoints.md)")
    if name == "mechanics/penalty/records" and label == "emptied":
        return ("the last step's contact records (none: no contact) are only reported, in that step's series row, "
                "already written; the next step replaces them")
    if label == "value 2147483647" and name.startswith(PLAUSIBLE_COUNTERS):
        return "a plausible count (PLAUSIBLE_COUNTERS)"
    return None


# A flipped byte outside every dataset's stored data: refused naming the file (exit code 2), or
# completed (exit code 0) only when the damaged file still has every dataset and attribute of the
# seed with their types and shapes, so the flip changed an unused byte (free space, padding, a
# checksum-free header field the library does not read). A flip inside a dataset's stored data
# (its chunk, checksum included) must be refused since checkpoints carry Fletcher32 checksums
# (format 3 and later; docs/robustness.md).
FLIP_OK = "flip"


def structure(path):
    try:
        with h5py.File(path, "r") as f:
            return walk(f), sorted((k, str(v)) for k, v in f.attrs.items())
    except Exception as e:  # noqa: BLE001 (any failure to read is "not the same structure")
        return repr(e)


def cpu_run(exe, args, cwd, timeout=120):
    p = subprocess.run([exe] + args, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    return p.returncode, p.stderr.decode(errors="replace")


def sha(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def walk(f):
    """Every dataset (path, dtype, shape) and group of an open h5py file, sorted."""
    datasets, groups = [], []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            datasets.append((name, obj.dtype, obj.shape))
        else:
            groups.append(name)
    f.visititems(visit)
    return sorted(datasets), sorted(groups)


def replace(f, name, data, dtype=None):
    """Rewrites dataset `name` with `data`, with a Fletcher32 checksum as frictherm writes them (format 3 on)
    when it holds values, so that the damage itself, not the missing checksum, is what is refused."""
    del f[name]
    data = numpy.asarray(data, dtype=dtype)
    if data.size > 0:
        f.create_dataset(name, data=data, chunks=data.shape, fletcher32=True)
    else:
        f.create_dataset(name, data=data)


def chunks(path):
    """{dataset name: (byte offset, size)} of every dataset's first stored chunk (its contiguous data,
    in a checkpoint before checksums)."""
    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.size > 0:
                if obj.chunks is not None:
                    info = obj.id.get_chunk_info(0)
                    out[name] = (info.byte_offset, info.size)
                elif obj.id.get_offset() is not None:
                    out[name] = (obj.id.get_offset(), obj.id.get_storage_size())
        f.visititems(visit)
    return out


def flip_in_chunk(raw, offset, size, at=None):
    """`raw` with one bit of the chunk at `offset` flipped: the lowest bit of its middle byte (a double's
    or an integer's value changed to another valid one; the checksum alone can tell)."""
    damaged = bytearray(raw)
    damaged[offset + (size // 2 if at is None else at)] ^= 0x01
    return bytes(damaged)


def other_type(dtype):
    """A different HDF5 type of the same kind of content: float <-> integer, or another width."""
    if dtype.kind == "f":
        return [("float32", numpy.float32), ("int64", numpy.int64)]
    if dtype.itemsize == 1:
        return [("uint8", numpy.uint8), ("int32", numpy.int32)]
    return [("float64", numpy.float64), ("int16" if dtype.itemsize > 2 else "int64", numpy.int16 if dtype.itemsize > 2 else numpy.int64)]


def dataset_damages(name, dtype, shape):
    """(label, mutate(f)) for one dataset; every one must be refused naming it."""
    out = []
    n = shape[0] if shape else 1
    text = dtype.itemsize == 1

    def pad_item(d):
        if text:
            return numpy.frombuffer(b"x", dtype=dtype)  # never whitespace: a JSON text or an override line breaks
        return d[-1:] if len(d) else numpy.zeros((1,) + d.shape[1:], dtype=d.dtype)
    out.append(("deleted", lambda f: f.__delitem__(name)))
    out.append(("replaced by a group", lambda f: (f.__delitem__(name), f.create_group(name))))
    if n > 0:
        out.append(("emptied", lambda f: replace(f, name, numpy.zeros((0,) + shape[1:], dtype=dtype))))
    if n > 2:
        out.append(("truncated to half", lambda f: replace(f, name, f[name][: n // 2])))
    if n > 1:
        out.append(("one item short", lambda f: replace(f, name, f[name][: n - 1])))
    out.append(("one item more", lambda f: replace(f, name, numpy.concatenate([f[name][()], pad_item(f[name][()])]))))
    if n > 0 or len(shape) == 2:
        out.append(("rank changed", lambda f: replace(f, name, f[name][()].reshape(-1) if len(shape) == 2 else
                                                       f[name][()].reshape(n, 1))))
    for label, t in other_type(dtype):
        out.append((f"stored as {label}", lambda f, t=t: replace(f, name, f[name][()].astype(t) if n else
                                                                  numpy.zeros(shape, dtype=t), dtype=t)))
    if dtype.kind == "f" and n > 0:
        for label, v in (("NaN", numpy.nan), ("+Inf", numpy.inf), ("-Inf", -numpy.inf)):
            def inject(f, v=v):
                d = f[name][()]
                d.reshape(-1)[(d.size - 1) // 2] = v  # the middle value: not only the first item is checked
                f[name][...] = d
            out.append((f"{label} injected", inject))
    if dtype.kind in "iu" and not text and n > 0:
        for v in (-2, 2**31 - 1):
            if dtype.kind == "u" and v < 0:
                continue
            def set_value(f, v=v):
                d = f[name][()]
                d.reshape(-1)[(d.size - 1) // 2] = v
                f[name][...] = d
            out.append((f"value {v}", set_value))
    return out


def attribute_damages():
    def set_attr(name, value):
        def m(f):
            if name in f.attrs:
                del f.attrs[name]
            f.attrs[name] = value
        return m
    out = []
    for a in ("format", "dimension"):
        out.append((a, "deleted", lambda f, a=a: f.attrs.__delitem__(a)))
        out.append((a, "a string", set_attr(a, numpy.bytes_(b"2"))))
        out.append((a, "a float 2.5", set_attr(a, numpy.float64(2.5))))
        out.append((a, "an array", set_attr(a, numpy.array([2, 2], dtype=numpy.int32))))
    for v in (1, 2, 3, 5, -1, 2**31 - 1):  # 2, 3: checkpoints of older versions (refused, docs/checkpoints.md)
        out.append(("format", f"= {v}", set_attr("format", numpy.int32(v))))
    for v in (3, 0, 1, -7):
        out.append(("dimension", f"= {v}", set_attr("dimension", numpy.int32(v))))
    out.append(("ranks", "added (= 2: a decomposed checkpoint's global file)", set_attr("ranks", numpy.int32(2))))
    return out


def harmless_damages():
    return [("extra root attribute", lambda f: f.attrs.__setitem__("note", numpy.int32(7))),
            ("extra dataset attribute", lambda f: f["mechanics/time"].attrs.__setitem__("note", numpy.int32(7))),
            ("extra dataset", lambda f: f.create_dataset("notes/extra", data=numpy.arange(3.0))),
            ("extra group", lambda f: f.create_group("mechanics/unused"))]


class Corpus:
    def __init__(self, exe, top, verbose):
        self.exe, self.top, self.verbose = exe, top, verbose
        self.failures, self.counts = [], {}
        self.refused = 0
        self.completed = 0

    def seed(self, name, extra):
        folder = os.path.join(self.top, name)
        os.makedirs(folder)
        with open(os.path.join(folder, "s.json"), "w") as f:
            json.dump(SCENE, f)
        rc, err = cpu_run(self.exe, ["run", "s.json", "-o", "R.h5", "-q"] + OVERRIDES + extra, folder)
        assert rc == 0, err
        return folder

    def case(self, seed, command, label, expect, mutate=None, raw=None):
        """Writes the damaged checkpoint, runs the command, checks the verdict. expect: the text the
        message must hold (None: harmless, exit code 0 allowed)."""
        folder = tempfile.mkdtemp(dir=self.top, prefix="case")
        ckpt = os.path.join(folder, "R.h5.checkpoint")
        os.link(os.path.join(seed, "R.h5"), os.path.join(folder, "R.h5"))
        shutil.copyfile(os.path.join(seed, "s.json"), os.path.join(folder, "s.json"))
        if raw is not None:
            with open(ckpt, "wb") as f:
                f.write(raw)
        else:
            shutil.copyfile(os.path.join(seed, "R.h5.checkpoint"), ckpt)
            with h5py.File(ckpt, "a") as f:
                mutate(f)
        before = {n: sha(os.path.join(folder, n)) for n in ("R.h5", "R.h5.checkpoint")}
        args = ["resume", "R.h5", "-o", "O.h5", "-q"] if command == "resume" else ["continue", "R.h5", "-o", "O.h5", "-q"]
        try:
            rc, err = cpu_run(self.exe, args, folder)
        except subprocess.TimeoutExpired:
            rc, err = None, "timed out"
        problems = []
        if rc is None or rc < 0:
            problems.append(f"{'timed out' if rc is None else 'killed by signal %d' % -rc}")
        if "Sanitizer" in err or "runtime error:" in err:
            problems.append("sanitizer report")
        after = {n: sha(os.path.join(folder, n)) if os.path.exists(os.path.join(folder, n)) else None for n in before}
        if after != before:
            problems.append("the input (R.h5 or its checkpoint) changed")
        if sha(os.path.join(seed, "R.h5")) != self.seed_hash[seed]:
            problems.append("the seed's R.h5 changed (written in place through the link)")
        first = err.strip().splitlines()[0] if err.strip() else ""
        if expect is FLIP_OK:
            expect = "R.h5.checkpoint"
            if rc == 0:
                expect = None
                if structure(ckpt) != self.seed_structure[seed]:
                    problems.append("accepted (exit code 0) with another structure than the seed's")
        if rc == 0:
            if expect is not None:
                problems.append("accepted (exit code 0)")
            elif not os.path.exists(os.path.join(folder, "O.h5")):
                problems.append("exit code 0 without O.h5")
        elif rc == 2:
            if os.path.exists(os.path.join(folder, "O.h5")):
                problems.append("refused but O.h5 written")
            if expect is not None and expect not in err:
                problems.append(f"message does not name '{expect}'")
        elif rc is not None and rc > 0:
            problems.append(f"exit code {rc}")
        verdict = "ok" if not problems else "FAIL " + "; ".join(problems)
        key = "refused" if rc == 2 else "completed" if rc == 0 else "other"
        self.counts[key] = self.counts.get(key, 0) + 1
        line = f"{command} {label}: exit {rc} {verdict} | {first[:220]}"
        if problems:
            self.failures.append(line)
        if problems or self.verbose:
            print(line, flush=True)
        shutil.rmtree(folder, ignore_errors=True)


# The decomposed seed (--decomposed, ctest robustness.damaged_checkpoints_mpi): the heated sliding block
# of the decomposed tests (tests/coupling/scenes/decomposed_sliding_block.json, 1280 particles, heat on
# the grid, hot spots) under `mpirun -n 2` to 0.2 ms with a checkpoint at 0.1 ms; its rank files
# damaged one at a time, and `mpirun -n 2 frictherm resume R.h5` (in place) run on each.
DECOMPOSED_SCENE = pathlib.Path(__file__).resolve().parent.parent / "coupling" / "scenes" / "decomposed_sliding_block.json"


def mpirun(ranks):
    cmd = ["mpirun", "--oversubscribe", "-n", str(ranks)]
    return cmd + (["--allow-run-as-root"] if os.geteuid() == 0 else [])


def decomposed_cases(seed, rank_files, full):
    """(label, file, expected text, mutate or raw bytes) for the rank files of the decomposed seed."""
    cases = []
    floats = ["mechanics/coor", "mechanics/velocity", "mechanics/mass", "mechanics/stress", "mechanics/F",
              "mechanics/scalars", "mechanics/time", "mechanics/work_first", "window/pending", "gather/M",
              "gather/T", "gather/local_M", "books/heat_delivered"]
    for k, name in enumerate(floats if full else floats[::3]):
        file = rank_files[k % len(rank_files)]
        values = (("NaN", numpy.nan), ("+Inf", numpy.inf), ("-Inf", -numpy.inf))
        for label, v in values if full else values[k % 3: k % 3 + 1]:  # quick: the kinds in rotation
            def inject(f, name=name, v=v):
                d = f[name][()]
                d.reshape(-1)[(d.size - 1) // 2] = v
                f[name][...] = d
            cases.append((f"{file} /{name} {label} injected", file, name, inject))
    for k, (name, v) in enumerate((("mechanics/material", -2), ("mechanics/material", 2**31 - 1), ("mechanics/id", -2),
                                   ("mechanics/id", 2**31 - 1), ("mechanics/owned_nodes", 10**6),
                                   ("mechanics/owned_nodes", -2), ("mechanics/contact_stats", -2),
                                   ("books/windows", -2))):
        if not full and k % 2:
            continue
        file = rank_files[k % len(rank_files)]
        def set_value(f, name=name, v=v):
            d = f[name][()]
            d.reshape(-1)[(d.size - 1) // 2 if name != "mechanics/owned_nodes" else (1 if v > 0 else 0)] = v
            f[name][...] = d
        cases.append((f"{file} /{name} value {v}", file, name, set_value))
    for k, (name, label, cut) in enumerate((("mechanics/mass", "one item short", -1), ("mechanics/velocity", "truncated to half", 0.5),
                                            ("mechanics/material", "one item more", +1), ("mechanics/work_first", "one item short", -1),
                                            ("window/pending", "emptied", 0), ("gather/local_M", "one item more", +1),
                                            ("gather/T", "one item short", -1), ("mechanics/id", "one item more", +1))):
        if not full and k % 2:
            continue
        file = rank_files[k % len(rank_files)]
        def resize(f, name=name, cut=cut):
            d = f[name][()]
            n = len(d)
            d = d[: n - 1] if cut == -1 else d[: n // 2] if cut == 0.5 else d[:0] if cut == 0 else numpy.concatenate([d, d[-1:]])
            replace(f, name, d)
        cases.append((f"{file} /{name} {label}", file, name, resize))
    for k, file in enumerate(rank_files):  # a valid value of another state: only the checksum tells
        stored = chunks(os.path.join(seed, file))
        raw = open(os.path.join(seed, file), "rb").read()
        for name in ("mechanics/velocity", "gather/T", "mechanics/coor") if full else (("mechanics/velocity",), ("mechanics/coor",))[k % 2]:
            cases.append((f"{file} /{name} one stored bit flipped", file, name, flip_in_chunk(raw, *stored[name])))
    # The global file (every rank reads it): the run loop's state and the series rows.
    def global_nan(f):
        f["run/time"][...] = numpy.nan
    def global_short(f):
        replace(f, "output/series_rows", f["output/series_rows"][:-1])
    def global_step(f):
        f["run/last_series_step"][...] = f["run/step"][()] + 1
    for k, (label, name, damage) in enumerate((("NaN injected", "run/time", global_nan),
                                               ("one item short", "output/series_rows", global_short),
                                               ("after /run/step", "run/last_series_step", global_step))):
        if full or k < 2:
            cases.append((f"R.h5.checkpoint /{name} {label}", "R.h5.checkpoint", name, damage))
    def strip(f):
        d = f["mechanics/velocity"][()]
        del f["mechanics/velocity"]
        f.create_dataset("mechanics/velocity", data=d)
    cases.append((f"{rank_files[-1]} /mechanics/velocity rewritten without its checksum", rank_files[-1],
                  "no checksum", strip))
    return cases


def run_decomposed(exe, top, full, verbose, jobs):
    """The decomposed seed's corpus; returns the failures."""
    seed = os.path.join(top, "decomposed")
    os.makedirs(seed)
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_mpi_yield_when_idle="1", OMPI_MCA_pml="ob1",
               OMPI_MCA_btl="self,vader")  # FRICTHERM_MPI_TEST_ENVIRONMENT (tests/CMakeLists.txt)
    p = subprocess.run(mpirun(2) + [exe, "run", str(DECOMPOSED_SCENE), "-q", "-o", "R.h5", "--set", "run.end_time=2e-4",
                                    "--set", "run.checkpoint_interval=1e-4"], cwd=seed, env=env, capture_output=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr.decode(errors="replace")
    rank_files = sorted(n for n in os.listdir(seed) if n.startswith("R.h5.checkpoint.") and ".rank" in n)
    assert len(rank_files) == 2, rank_files
    failures, counts = [], {}

    def case(label, file, expect, damage):
        folder = tempfile.mkdtemp(dir=top, prefix="case")
        for n in os.listdir(seed):
            shutil.copyfile(os.path.join(seed, n), os.path.join(folder, n))
        if isinstance(damage, bytes):
            with open(os.path.join(folder, file), "wb") as f:
                f.write(damage)
        else:
            with h5py.File(os.path.join(folder, file), "a") as f:
                damage(f)
        before = {n: sha(os.path.join(folder, n)) for n in os.listdir(folder)}
        try:
            r = subprocess.run(mpirun(2) + [exe, "resume", "R.h5", "-q"], cwd=folder, env=env, capture_output=True,
                               timeout=120)
            rc, err = r.returncode, r.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired:
            rc, err = None, "timed out"
        problems = []
        if rc != 2:
            problems.append(f"exit code {rc} (expected 2)")
        if "signal" in err.lower() or "Sanitizer" in err:
            problems.append("a signal or sanitizer report")
        if expect not in err or (rc == 2 and file not in err):
            problems.append(f"message does not name '{expect}' and '{file}'")
        after = {n: sha(os.path.join(folder, n)) for n in os.listdir(folder)}
        if after != before:
            problems.append("a file of the run changed, was added or removed")
        first = next((l for l in err.splitlines() if "frictherm" in l), err.strip()[:200])
        counts["refused" if rc == 2 else "other"] = counts.get("refused" if rc == 2 else "other", 0) + 1
        line = f"mpirun resume {label}: exit {rc} {'ok' if not problems else 'FAIL ' + '; '.join(problems)} | {first[:240]}"
        if problems:
            failures.append(line)
        if problems or verbose:
            print(line, flush=True)
        shutil.rmtree(folder, ignore_errors=True)
    # Two resumes at a time: a refused resume spends most of its wall time starting MPI, not computing.
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        list(pool.map(lambda x: case(*x), decomposed_cases(seed, rank_files, full)))
    print(f"decomposed seed: {sum(counts.values())} cases: {counts}; {len(failures)} failures", flush=True)
    return failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("exe")
    ap.add_argument("-k", default="", help="only cases whose label holds this")
    ap.add_argument("--keep", help="work in this folder and keep it")
    ap.add_argument("-j", type=int, default=int(os.environ.get("DAMAGED_CHECKPOINT_JOBS", "2")))
    ap.add_argument("-v", action="store_true")
    ap.add_argument("--full", action="store_true", help="every damage of every dataset (docs/robustness.md counts)")
    ap.add_argument("--every", type=int, default=int(os.environ.get("DAMAGED_CHECKPOINTS_EVERY", "1")),
                    help="only every Nth case (the sanitizer build: 10-50x slower)")
    ap.add_argument("--decomposed", action="store_true",
                    help="the decomposed seed under mpirun -n 2 (its rank files damaged) instead of the serial one")
    a = ap.parse_args()
    t0 = time.time()
    top = a.keep or tempfile.mkdtemp(prefix="frictherm_damaged_")
    os.makedirs(top, exist_ok=True)
    if a.decomposed:
        failures = run_decomposed(os.path.abspath(a.exe), top, a.full, a.v, a.j)
        print(f"{time.time() - t0:.1f} s")
        if not a.keep:
            shutil.rmtree(top, ignore_errors=True)
        return 1 if failures else 0
    c = Corpus(os.path.abspath(a.exe), top, a.v)
    mid = c.seed("mid", ["--set", f"run.max_steps={MID_STEPS}"])  # a checkpoint in the loading
    eol = c.seed("eol", [])  # the end-of-loading checkpoint (frictherm continue)
    c.seed_hash = {s: sha(os.path.join(s, "R.h5")) for s in (mid, eol)}
    c.seed_structure = {s: structure(os.path.join(s, "R.h5.checkpoint")) for s in (mid, eol)}
    with h5py.File(os.path.join(mid, "R.h5.checkpoint"), "r") as f:
        datasets, groups = walk(f)
    cases = []
    rotation = 0
    for name, dtype, shape in datasets:
        damages = dataset_damages(name, dtype, shape)
        if not a.full:  # the quick corpus (ctest): one damage per dataset, the kinds in rotation
            damages = [damages[rotation % len(damages)]]
            rotation += 1
        for label, m in damages:
            expect = None if harmless(name, label) else name
            cases.append((mid, "resume", f"/{name} {label}", expect, m, None))
            if a.full and label in ("deleted", "one item short", "NaN injected", "value -2", "stored as float32"):
                cases.append((eol, "continue", f"/{name} {label}", expect, m, None))
        if not a.full and rotation % 7 == 0:  # and the continue of every seventh
            label, m = damages[0]
            cases.append((eol, "continue", f"/{name} {label}", None if harmless(name, label) else name, m, None))
    for attr, label, m in attribute_damages():
        for seed, command in ((mid, "resume"), (eol, "continue")) if a.full else ((mid, "resume"),):
            cases.append((seed, command, f"attribute {attr} {label}", attr, m, None))
    for label, m in harmless_damages():
        cases.append((mid, "resume", label, None, m, None))
    # The reaction's datasets disagreeing (issue 34: an emptied progress had restarted the reaction on
    # `resume`): always, through resume and continue.
    def set_enabled(f, v):
        f["reaction/enabled"][...] = v
    for seed, command in ((mid, "resume"), (eol, "continue")):
        cases.append((seed, command, "/reaction/particle_progress emptied (reaction check)", "reaction/particle_progress",
                      lambda f: replace(f, "reaction/particle_progress", numpy.zeros(0)), None))
        cases.append((seed, command, "/reaction/enabled 0 with the progress kept (reaction check)",
                      "reaction/particle_progress", lambda f: set_enabled(f, 0), None))
    # A dataset rewritten with the same values but without its checksum: refused naming the checksum.
    for name in ("mechanics/time", "mechanics/particles/velocity", "nodal_temperature"):
        def strip(f, name=name):
            d = f[name][()]
            del f[name]
            f.create_dataset(name, data=d)
        cases.append((mid, "resume", f"/{name} rewritten without its checksum", "no checksum", strip, None))
    raw = open(os.path.join(mid, "R.h5.checkpoint"), "rb").read()
    size = len(raw)
    # One bit of a dataset's stored data flipped (a valid value of another state): refused by the
    # checksum, naming the dataset. The quick corpus: every fifth dataset; --full: every one.
    stored = chunks(os.path.join(mid, "R.h5.checkpoint"))
    for k, (name, (offset, length)) in enumerate(sorted(stored.items())):
        if a.full or k % 5 == 0:
            cases.append((mid, "resume", f"/{name} one stored bit flipped", name, None,
                          flip_in_chunk(raw, offset, length)))
    data_bytes = [(o, o + n, name) for name, (o, n) in stored.items()]
    cuts = {0, 1, 8, 96, 512, 2048, size // 4, size // 2, 3 * size // 4, size - 1024, size - 1}
    for cut in sorted(cuts if a.full else {0, 96, 2048, size // 2, size - 1}):
        cases.append((mid, "resume", f"file cut at byte {cut} of {size}", "R.h5.checkpoint", None, raw[:cut]))
    # Bytes flipped: the superblock, the root group's header and spread through the file (object
    # headers, B-trees, heaps and raw data).
    flips = sorted({0, 8, 13, 24, 40, 56, 64, 72, 80, 96, 136, 200, 300, 400, 600, 800, 1000, 1200, 1400} |
                   {size * k // 24 for k in range(1, 24)})
    for at in flips if a.full else flips[::3]:
        damaged = bytearray(raw)
        damaged[at] ^= 0xFF
        inside = [name for lo, hi, name in data_bytes if lo <= at < hi]
        expect = inside[0] if inside else FLIP_OK  # stored data: the checksum refuses it, naming the dataset
        cases.append((mid, "resume", f"byte {at} of {size} flipped" + (f" (in /{inside[0]})" if inside else ""),
                      expect, None, bytes(damaged)))
    cases = [x for x in cases if a.k in x[2]][::max(1, a.every)]
    print(f"{len(cases)} damaged checkpoints ({len(datasets)} datasets, {len(groups)} groups, {size} bytes)", flush=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.j)) as pool:
        list(pool.map(lambda x: c.case(x[0], x[1], x[2], x[3], mutate=x[4], raw=x[5]), cases))
    print(f"{len(cases)} cases: {c.counts}; {len(c.failures)} failures; {time.time() - t0:.1f} s")
    if not a.keep:
        shutil.rmtree(top, ignore_errors=True)
    return 1 if c.failures or not cases else 0


if __name__ == "__main__":
    sys.exit(main())
