#!/usr/bin/env python3
"""Fault injection (issue 34 item 3): runs, resumes and continues killed (SIGKILL) at several points
and run out of disk (the file-size limit RLIMIT_FSIZE: writes fail with EFBIG as on a full disk with
ENOSPC) at several sizes. After every fault:

* the result, its XDMF files and its checkpoint agree: a result under its final name is a readable
  HDF5 file whose status is not "running" (a failed one has /failure and /meta/failure); an XDMF file
  exists only beside its result and names exactly its snapshots (and /failure), at their times; a
  checkpoint beside a result of the same run (/meta/run_id) counts no more rows or snapshots than the
  result holds;
* no earlier result is lost: the input of a resume keeps its rows (appended to, never cut), the
  input of a continue (result, XDMF, checkpoint) is byte-equal;
* `frictherm resume` (or `continue` again) either completes to a result equal to the uninterrupted
  run's (series and last snapshot bit for bit: one thread) or is refused with exit code 2 saying why.

Kill points are fractions of the uninterrupted command's CPU time (read from /proc, so a loaded
machine moves them, never the verdict); every case is checked whatever point it lands on.

    fault_injection.py FRICTHERM_EXE [-k SUBSTRING] [--keep DIR]
"""
import argparse
import glob
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy

SCENE = {
    "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.005},
    "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
    "bodies": [{"name": "block", "material": "soft", "velocity": [1, 0],
                "shape": {"type": "rectangle", "lo": [0.02, 0.01], "hi": [0.06, 0.04]}}],
    "thermal": {"materials": {"soft": {"heat_capacity": 1000, "conductivity": 1}}},
    "coupling": {"continuation": {"duration": 2e-2, "intervals": 40}},
    "run": {"end_time": 1.5e-2, "threads": 1, "checkpoint_interval": 2e-3},
    "output": {"snapshot_count": 12, "series_interval": 1e-4},
}
TICK = os.sysconf("SC_CLK_TCK")
FAILURES = []


def cpu_seconds(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICK
    except (OSError, IndexError):
        return None


def command(exe, args, cwd, fsize=None, kill_at=None):
    """Runs exe ARGS in cwd; fsize: RLIMIT_FSIZE in bytes; kill_at: SIGKILL after that much CPU time.
    Returns (exit code or -signal, stderr text, CPU seconds of the child)."""
    def limit():
        if fsize is not None:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails instead of the signal killing
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.Popen([exe] + args, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         preexec_fn=limit, env=dict(os.environ, OMP_NUM_THREADS="1"))
    if kill_at is not None:
        while p.poll() is None:
            used = cpu_seconds(p.pid)
            if used is not None and used >= kill_at:
                p.send_signal(signal.SIGKILL)
                break
            time.sleep(0.002)
    err = p.communicate()[1].decode(errors="replace")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return p.returncode, err, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def fail(case, what):
    FAILURES.append(f"{case}: {what}")
    print(f"  FAIL {what}")


def text(h5, name):
    v = h5[name][()]
    return v.decode() if isinstance(v, bytes) else str(v)


def check_agree(case, folder, name):
    """The result NAME.h5, NAME.xdmf and NAME.h5.checkpoint of folder agree (module docstring)."""
    h5p = os.path.join(folder, name + ".h5")
    xdmf = os.path.join(folder, name + ".xdmf")
    ckpt = h5p + ".checkpoint"
    snapshots = None
    if os.path.exists(h5p):
        try:
            with h5py.File(h5p, "r") as f:
                status = text(f, "meta/status")
                if status not in ("completed", "interrupted", "failed", "stopped_at_max_steps"):
                    fail(case, f"{name}.h5 published with status {status!r}")
                if status == "failed" and ("failure" not in f or "failure" not in f["meta"]):
                    fail(case, f"{name}.h5 failed without /failure and /meta/failure")
                snapshots = {"/snapshots/" + k: float(f["snapshots"][k].attrs["time"]) for k in f["snapshots"]}
                if "failure" in f:
                    snapshots["/failure"] = float(f["failure"].attrs["time"])
                rows = len(f["series/time"]) if "series" in f and "time" in f["series"] else 0
                run_id = text(f, "meta/run_id") if "run_id" in f["meta"] else ""
                count = len(f["snapshots"])
        except (OSError, KeyError) as e:
            fail(case, f"{name}.h5 does not read: {e}")
            return
    for x in (xdmf, os.path.join(folder, name + "_reference.xdmf")):
        if not os.path.exists(x):
            continue
        if snapshots is None:
            fail(case, f"{os.path.basename(x)} without {name}.h5")
            continue
        doc = open(x).read()
        named = set(re.findall(re.escape(name) + r"\.h5:(/(?:snapshots/\d+|failure))/", doc))
        times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', doc)]
        regular = {k for k in snapshots if k != "/failure"}  # /failure: drawn only after the last snapshot
        if not (regular <= named <= set(snapshots)):
            fail(case, f"{os.path.basename(x)} names {sorted(named)}, {name}.h5 holds {sorted(snapshots)}")
        elif sorted(times) != sorted(snapshots[k] for k in named):
            fail(case, f"{os.path.basename(x)} times {times} differ from the snapshots'")
    if snapshots is not None and os.path.exists(ckpt):
        with h5py.File(ckpt, "r") as c:
            marks_id = bytes(c["marks/run_id"][()]).decode() if "marks/run_id" in c else ""
            marks_rows = int(c["marks/series_rows"][0])
            marks_snapshots = int(c["marks/snapshots"][0])
        if marks_id == run_id and (marks_rows > rows or marks_snapshots > count):
            fail(case, f"checkpoint counts {marks_rows} rows / {marks_snapshots} snapshots, {name}.h5 holds {rows} / {count}")


def series(h5p):
    with h5py.File(h5p, "r") as f:
        out = {k: numpy.array(f["series"][k]) for k in f["series"]}
        last = sorted(f["snapshots"])[-1]
        out["last_snapshot_time"] = numpy.array([f["snapshots"][last].attrs["time"]])
        out["last_snapshot_position"] = numpy.array(f["snapshots"][last]["position"])
        out["snapshot_count"] = numpy.array([len(f["snapshots"])])
    return out


def equal_to(case, h5p, reference, alone=False):
    """The result equals the uninterrupted run's; alone: a continuation written without the result it
    continues (a killed run leaves only its .part): its rows are the reference's last ones."""
    got = series(h5p)
    if sorted(got) != sorted(reference):
        return fail(case, "columns differ from the uninterrupted run's")
    for k, v in reference.items():
        if alone and k == "snapshot_count":
            continue
        want = v[len(v) - len(got[k]):] if alone and k not in ("last_snapshot_time", "last_snapshot_position") else v
        if got[k].shape != want.shape or not numpy.array_equal(got[k], want, equal_nan=True):
            return fail(case, f"{k} differs from the uninterrupted run's ({got[k].shape} vs {want.shape})")


def finish(exe, case, folder, args, name, reference):
    """Runs ARGS (resume or continue) without faults until it completes or is refused (exit 2)."""
    alone = args[0] == "resume" and not os.path.exists(os.path.join(folder, name + ".h5"))
    for _ in range(3):
        rc, err, _ = command(exe, args, folder)
        check_agree(case + " then " + args[0], folder, name)
        if rc == 0:
            return equal_to(case + " then " + args[0], os.path.join(folder, name + ".h5"), reference, alone)
        if rc == 2 and "frictherm:" in err and len(err.strip()) > 20:
            print(f"  refused: {err.strip().splitlines()[0][:160]}")
            return
        if rc != 1:
            return fail(case, f"{' '.join(args)} exit code {rc}: {err.strip()[:300]}")
        print(f"  {args[0]} failed (exit 1): {err.strip().splitlines()[0][:160]}")  # and is tried again
    fail(case, f"{' '.join(args)} did not complete in 3 tries")


def files_of(folder, names):
    return {n: open(os.path.join(folder, n), "rb").read() for n in names if os.path.exists(os.path.join(folder, n))}


def faults(cpu, size):
    """Kill points and file-size limits of one command: cpu s of CPU and size bytes of result."""
    return ([("SIGKILL at %.0f %% CPU" % (100 * f), dict(kill_at=f * cpu)) for f in (0.1, 0.3, 0.5, 0.7, 0.9)] +
            [("RLIMIT_FSIZE %d kB" % (f * size // 1024), dict(fsize=int(f * size))) for f in (0.05, 0.3, 0.6, 0.9)])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("exe")
    ap.add_argument("-k", default="")
    ap.add_argument("--keep")
    a = ap.parse_args()
    exe = os.path.abspath(a.exe)
    top = a.keep or tempfile.mkdtemp(prefix="frictherm_faults_")
    os.makedirs(top, exist_ok=True)
    t0 = time.time()
    ref = os.path.join(top, "ref")
    os.makedirs(ref, exist_ok=True)
    with open(os.path.join(ref, "s.json"), "w") as f:
        json.dump(SCENE, f)
    rc, err, run_cpu = command(exe, ["run", "s.json", "-o", "R.h5", "-q"], ref)
    assert rc == 0, err
    rc, err, cont_cpu = command(exe, ["continue", "R.h5", "-o", "C.h5", "-q"], ref)
    assert rc == 0, err
    reference_run = series(os.path.join(ref, "R.h5"))
    reference_cont = series(os.path.join(ref, "C.h5"))
    run_size = os.path.getsize(os.path.join(ref, "R.h5"))
    cont_size = os.path.getsize(os.path.join(ref, "C.h5"))
    print(f"uninterrupted: run {run_cpu:.2f} s CPU, {run_size} B; continue {cont_cpu:.2f} s CPU, {cont_size} B")

    # An interrupted result to resume: SIGTERM at half the run (it writes its final checkpoint).
    interrupted = os.path.join(top, "interrupted")
    shutil.copytree(ref, interrupted)
    for n in ("R.h5", "R.xdmf", "R_reference.xdmf", "R_nodes.xdmf", "R.h5.checkpoint",
              "C.h5", "C.xdmf", "C_reference.xdmf", "C_nodes.xdmf", "C.h5.checkpoint"):
        if os.path.exists(os.path.join(interrupted, n)):
            os.remove(os.path.join(interrupted, n))
    p = subprocess.Popen([exe, "run", "s.json", "-o", "R.h5", "-q"], cwd=interrupted, stderr=subprocess.DEVNULL)
    # Half way through the run's CPU, and only once it has opened its result (R.h5.PID.part): on a
    # loaded machine the start-up's CPU grows, and a signal before the result is opened ends the run
    # with nothing to resume (nothing was computed), which is not the case this input is for.
    part = os.path.join(interrupted, "R.h5.%d.part" % p.pid)
    while p.poll() is None and ((cpu_seconds(p.pid) or 0) < 0.5 * run_cpu or not os.path.exists(part)):
        time.sleep(0.002)
    if p.poll() is None:
        p.send_signal(signal.SIGTERM)
    p.wait()
    with h5py.File(os.path.join(interrupted, "R.h5"), "r") as f:
        kept_rows = {k: numpy.array(f["series"][k]) for k in f["series"]}
        print(f"resume input: status {text(f, 'meta/status')}, {len(kept_rows['time'])} rows")

    cases = 0
    for kind in ("run", "resume", "continue"):
        cpu, size = {"run": (run_cpu, run_size), "resume": (run_cpu / 2, run_size), "continue": (cont_cpu, cont_size)}[kind]
        for label, fault in faults(cpu, size):
            case = f"{kind}, {label}"
            if a.k not in case:
                continue
            cases += 1
            folder = os.path.join(top, f"case{cases}")
            shutil.copytree(interrupted if kind == "resume" else ref, folder)
            if kind == "run":
                for n in os.listdir(folder):
                    if n != "s.json":
                        os.remove(os.path.join(folder, n))
                rc, err, _ = command(exe, ["run", "s.json", "-o", "R.h5", "-q"], folder, **fault)
                print(f"{case}: exit {rc} {err.strip().splitlines()[0][:140] if err.strip() else ''}")
                check_agree(case, folder, "R")
                if rc == 0:
                    equal_to(case, os.path.join(folder, "R.h5"), reference_run)
                elif os.path.exists(os.path.join(folder, "R.h5.checkpoint")):
                    finish(exe, case, folder, ["resume", "R.h5", "-q"], "R", reference_run)
            elif kind == "resume":
                rc, err, _ = command(exe, ["resume", "R.h5", "-q"], folder, **fault)
                print(f"{case}: exit {rc} {err.strip().splitlines()[0][:140] if err.strip() else ''}")
                check_agree(case, folder, "R")
                if not os.path.exists(os.path.join(folder, "R.h5")):
                    fail(case, "the resumed result R.h5 is gone")
                else:
                    with h5py.File(os.path.join(folder, "R.h5"), "r") as f:
                        for k, v in kept_rows.items():
                            have = numpy.array(f["series"][k])
                            if len(have) < len(v) or not numpy.array_equal(have[:len(v)], v, equal_nan=True):
                                fail(case, f"the rows of R.h5 before the resume were lost or changed ({k})")
                                break
                    finish(exe, case, folder, ["resume", "R.h5", "-q"], "R", reference_run)
            else:
                for n in ("C.h5", "C.xdmf", "C_reference.xdmf", "C_nodes.xdmf", "C.h5.checkpoint"):
                    if os.path.exists(os.path.join(folder, n)):
                        os.remove(os.path.join(folder, n))
                inputs = files_of(folder, ["R.h5", "R.xdmf", "R_reference.xdmf", "R.h5.checkpoint"])
                rc, err, _ = command(exe, ["continue", "R.h5", "-o", "C.h5", "-q"], folder, **fault)
                print(f"{case}: exit {rc} {err.strip().splitlines()[0][:140] if err.strip() else ''}")
                if files_of(folder, list(inputs)) != inputs:
                    fail(case, "the input of continue changed")
                check_agree(case, folder, "C")
                finish(exe, case, folder, ["continue", "R.h5", "-o", "C.h5", "-q", "--force"], "C", reference_cont)
            leftovers = [n for n in os.listdir(folder) if n.endswith(".lock")]
            if leftovers and rc >= 0:
                fail(case, f"lock files left by a run that ended: {leftovers}")
    print(f"{cases} cases, {len(FAILURES)} failures, {time.time() - t0:.1f} s")
    if not a.keep:
        shutil.rmtree(top, ignore_errors=True)
    for f in FAILURES:
        print("FAILED:", f)
    return 1 if FAILURES or cases == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
