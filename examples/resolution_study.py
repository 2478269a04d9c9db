#!/usr/bin/python3
"""Resolution studies of the paper's cases with frictherm.study (docs/study.md): each preset is a
scene, its outputs and its default cell sizes and CFL factors; the options change them.

  resolution_study.py PRESET [--cells H1,H2,...] [--cfl C1,C2,...] [-o DIR] [--frictherm PATH]
                      [--jobs N] [--max-cpu S] [--reference VALUE] [--offsets O1,O2 [--offset-axes x]]

presets
  sliding_block   examples/sliding_block.json (Nairn et al. 2018 fig. 2), the frictional work of both
                  orders at the end, cells 5, 2.5, 1.25 mm x C 0.5, 0.25, 0.125 (about 11 CPU minutes;
                  docs/study.md shows it with --max-cpu 200); the rigid-block value of the work (appendix
                  eqs. 52-54) is 0.099856 J: pass it as --reference to measure errors against it
  fig7            examples/oscillating_block.json (fig. 7): the work of both orders after the pushers
                  start (W(end) - W(t1)) against C = 1 ... 0.0125 at the scene's 2.5 mm cells
  fig9            examples/pbx_compaction.json (fig. 9): the total frictional work of both orders of the
                  loading (the thermal-only continuation dropped) against C = 0.5, 0.25, 0.1

--offsets 0,0.5 runs every (h, C) with the grid also moved by half a cell along x (the oscillating block's
edges then fall mid-cell): the value is the mean, the range the alignment spread (docs/study.md).
Each writes DIR/study.csv, DIR/study.md and the charts (value against the cell size and against C,
error against CPU seconds); the runs stay in DIR/runs and are reused when the study is run again.
The same from a shell, for any scene:  python3 -m frictherm.study SCENE --cells ... --cfl ... --output ...
"""
import argparse
import os
import sys

import frictherm.study as fstudy  # noqa: E402  (python/frictherm, through examples/frictherm)
from frictherm.study_runs import read_scene  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def _pusher_start():
    """When the oscillating block's pushers start (s): its work is counted from there."""
    return read_scene(os.path.join(HERE, "oscillating_block.json"))["materials"]["pusher"]["velocity"][0]["start"]


def presets():
    t1 = _pusher_start()
    return {
        "sliding_block": dict(scene="sliding_block.json", cells=[5e-3, 2.5e-3, 1.25e-3], cfls=[0.5, 0.25, 0.125],
                              outputs=["friction_work_second", "friction_work_first"], sets=[]),
        "fig7": dict(scene="oscillating_block.json", cells=None, cfls=[1.0, 0.5, 0.25, 0.1, 0.05, 0.025, 0.0125],
                     outputs=["friction_work_second.base.block:since=%r" % t1,
                              "friction_work_first.base.block:since=%r" % t1], sets=[]),
        "fig9": dict(scene="pbx_compaction.json", cells=None, cfls=[0.5, 0.25, 0.1],
                     outputs=["friction_work_second", "friction_work_first"], sets=["coupling.continuation=null"]),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("preset", choices=sorted(presets()))
    ap.add_argument("--cells", type=fstudy.parse_floats, help="cell sizes (m), comma-separated")
    ap.add_argument("--cfl", type=fstudy.parse_floats, help="CFL factors, comma-separated")
    ap.add_argument("-o", "--out", help="directory (default results/study_PRESET)")
    ap.add_argument("--frictherm", help="the frictherm program (default: $FRICTHERM, PATH, ../build)")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--max-cpu", type=float, help="skip runs predicted to take more CPU seconds than this")
    ap.add_argument("--reference", type=float, help="the value errors are measured against (the first output)")
    ap.add_argument("--offsets", type=fstudy.parse_floats, help="grid offsets in cells, e.g. 0,0.5")
    ap.add_argument("--offset-axes", default="x", help="axes the grid moves along (default x)")
    a = ap.parse_args()
    p = presets()[a.preset]
    reference = {p["outputs"][0]: a.reference} if a.reference is not None else None
    study = fstudy.run_study(os.path.join(HERE, p["scene"]), cells=a.cells or p["cells"], cfls=a.cfl or p["cfls"],
                             outputs=p["outputs"], sets=p["sets"], program=a.frictherm, jobs=a.jobs, max_cpu=a.max_cpu,
                             reference=reference, offsets=a.offsets, offset_axes=a.offset_axes,
                             workdir=a.out or os.path.join("results", "study_" + a.preset))
    from frictherm.study_report import summary_lines
    print("\n".join(summary_lines(study)))
    return 0 if all(r["status"] in ("completed", "skipped") for r in study.rows) else 1


if __name__ == "__main__":
    sys.exit(main())
