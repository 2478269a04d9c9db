"""frictherm.study on a real (small) study, and its scene handling and output reductions."""
import csv
import json
import os
import subprocess

import numpy as np
import pytest

import frictherm
from frictherm.study import run_study
from frictherm.study_runs import Output, cell_sets, offset_sets, strip_comments

SOURCE = os.environ.get("FRICTHERM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
# The smallest sliding block with frictional heat (1 mm cells, 0.5 ms, about 0.2 s of CPU): at 1 and
# 0.5 mm cells the whole study takes about a second of CPU.
SCENE = os.path.join(SOURCE, "tests", "coupling", "scenes", "decomposed_sliding_block.json")
CELLS = [0.001, 0.0005]
OUTPUTS = ["friction_work_second", "max_temperature:max", "meta:heat_delivered"]


def _exe():
    exe = os.environ.get("FRICTHERM_EXE", os.path.join(SOURCE, "build", "coupling", "frictherm"))
    if not os.path.exists(exe):
        pytest.fail(f"the frictherm program is missing: {exe} (set FRICTHERM_EXE)")
    return exe


@pytest.fixture(scope="module")
def study(workdir):
    # jobs=2: the two runs side by side, each one's CPU time measured apart (wait4)
    return run_study(SCENE, cells=CELLS, cfls=[0.5], outputs=OUTPUTS, program=_exe(), jobs=2,
                     workdir=os.path.join(workdir, "study"), log=None)


def test_study_runs_every_cell_and_reads_the_outputs(study, workdir):
    assert [(r["cell"], r["cfl"], r["status"]) for r in study.rows] == [(0.001, 0.5, "completed"),
                                                                         (0.0005, 0.5, "completed")]
    for r in study.rows:
        with frictherm.open(r["file"]) as run:
            assert run.meta["cell_size"] == pytest.approx(r["cell"], rel=1e-12)  # the --set reached the run
            assert r["steps"] == run.meta["steps"] and r["particles"] == run.meta["particle_count"]
        # one thread: the child's CPU time cannot much exceed its wall time (2 % + 50 ms for the clocks)
        assert 0 < r["cpu_s"] <= 1.02 * r["wall_s"] + 0.05
    # Halving the cell quadruples the particles in 2D; the time step halves with the cell.
    assert study.rows[1]["particles"] == 4 * study.rows[0]["particles"]
    assert study.rows[1]["steps"] == pytest.approx(2 * study.rows[0]["steps"], rel=0.02)


def test_study_values_are_those_of_the_scene_run_directly(study, workdir):
    """The finer run repeated by hand with `frictherm run --set grid.cell_size=...`: one thread is
    deterministic, so the study's values are the direct run's to the last bit."""
    out = os.path.join(workdir, "study_direct.h5")
    subprocess.run([_exe(), "run", SCENE, "-o", out, "--force", "--quiet", "--threads", "1",
                    "--set", "grid.cell_size=0.0005"], check=True)
    with frictherm.open(out) as run:
        direct = {"friction_work_second": run.series["friction_work_second"][-1],
                  "max_temperature:max": np.max(run.series["max_temperature"]),
                  "meta:heat_delivered": run.meta["heat_delivered"]}
    assert direct["friction_work_second"] > 0 and direct["max_temperature:max"] > 300.0
    assert study.rows[1]["values"] == direct


def test_study_writes_its_table_summary_and_charts(study, workdir):
    d = os.path.join(workdir, "study")
    with open(os.path.join(d, "study.csv")) as f:
        rows = list(csv.DictReader(f))
    assert [float(r["cell_m"]) for r in rows] == CELLS
    for r, mine in zip(rows, study.rows):
        for label in ("friction_work_second", "max_temperature:max", "meta:heat_delivered"):
            assert float(r[label]) == pytest.approx(mine["values"][label], rel=1e-9)  # written with 10 digits
        assert float(r["cpu_s"]) == pytest.approx(mine["cpu_s"], abs=1e-3)
        assert int(r["steps"]) == mine["steps"]
    # Two levels give no order: the reference is the finest run, the coarse run's error is against it.
    a = study.analysis("friction_work_second")
    assert a["along_cell"][0.5]["best"] is None and a["reference"][1].startswith("the finest run")
    w = [r["values"]["friction_work_second"] for r in study.rows]
    assert float(rows[0]["friction_work_second rel_error"]) == pytest.approx((w[0] - w[1]) / abs(w[1]), rel=1e-4)
    with open(os.path.join(d, "study.md")) as f:
        md = f.read()
    assert "2 levels only" in md and "## friction_work_second (J)" in md and "## max_temperature:max (K)" in md
    pytest.importorskip("matplotlib")
    for png in ("friction_work_second_meta_heat_delivered_vs_cell.png", "max_temperature_max_vs_cell.png",
                "friction_work_second_meta_heat_delivered_error_vs_cpu.png"):
        assert os.path.getsize(os.path.join(d, png)) > 1000


def test_study_reuses_finished_runs(study, workdir):
    d = os.path.join(workdir, "study")
    record = os.path.join(d, "runs", "h0.0005_C0.5.json")
    before = os.path.getmtime(record)
    again = run_study(SCENE, cells=CELLS, cfls=[0.5], outputs=OUTPUTS[:1], program=_exe(), workdir=d, write=False,
                      log=None)
    assert os.path.getmtime(record) == before
    assert again.rows[1]["cpu_s"] == study.rows[1]["cpu_s"]  # the recorded cost, not a new run's
    assert again.rows[1]["values"]["friction_work_second"] == study.rows[1]["values"]["friction_work_second"]


def test_a_bad_cell_size_is_refused_before_any_run(workdir):
    with pytest.raises(ValueError, match="grid.cell_size"):
        run_study(SCENE, cells=[0.0007], program=_exe(), workdir=os.path.join(workdir, "bad_study"), log=None)
    assert not os.path.exists(os.path.join(workdir, "bad_study", "runs"))


def test_grid_offsets_make_an_ensemble_of_direct_runs(workdir):
    """Offsets 0 and 0.5 cells along x at 1 mm: each member is `frictherm run` with the grid moved
    (grid.lo and grid.hi less half a cell in x, the scene in place), bit for bit on one thread; the
    row is their mean, its spread their range, its cost their sum; offset 0 is the scene's own grid."""
    d = os.path.join(workdir, "offset_study")
    st = run_study(SCENE, cells=[0.001], cfls=[0.5], outputs=OUTPUTS[:1], program=_exe(), workdir=d, log=None,
                   offsets=[0.0, 0.5], offset_axes="x")
    (row,) = st.rows
    members = {m["offset"]: m for m in row["members"]}
    assert sorted(members) == [0.0, 0.5] and row["status"] == "completed"
    direct = {}
    for off, extra in ((0.0, []), (0.5, ["--set", "grid.lo=[-0.0005, 0.0]", "--set", "grid.hi=[0.0255, 0.012]"])):
        out = os.path.join(workdir, "offset_direct_%g.h5" % off)
        subprocess.run([_exe(), "run", SCENE, "-o", out, "--force", "--quiet", "--threads", "1",
                        "--set", "grid.cell_size=0.001"] + extra, check=True)
        with frictherm.open(out) as run:
            direct[off] = run.series["friction_work_second"][-1]
        with frictherm.open(members[off]["file"]) as run:
            assert run.meta["grid_lo"][0] == pytest.approx(-off * 1e-3, abs=1e-15)  # moved by 0 / 0.5 cell
    for off in (0.0, 0.5):
        assert members[off]["values"]["friction_work_second"] == direct[off]
    w = row["values"]["friction_work_second"]
    assert w == pytest.approx(0.5 * (direct[0.0] + direct[0.5]), rel=1e-15)
    assert row["spread"]["friction_work_second"] == (min(direct.values()), max(direct.values()))
    assert row["cpu_s"] == pytest.approx(members[0.0]["cpu_s"] + members[0.5]["cpu_s"], rel=1e-12)
    with open(os.path.join(d, "study.csv")) as f:
        (line,) = list(csv.DictReader(f))
    assert float(line["friction_work_second offset_spread"]) == pytest.approx(abs(direct[0.5] - direct[0.0]), rel=1e-9)
    with open(os.path.join(d, "study.md")) as f:
        assert "alignment spread" in f.read()


def test_grid_offsets_are_checked():
    scene = {"grid": {"lo": [0, 0], "hi": [0.2, 0.1], "cell_size": 0.01}}
    assert offset_sets(scene, 0.01, 0.0) == []
    assert offset_sets(scene, 0.01, 0.25, "xy") == ["grid.lo=[-0.0025, -0.0025]", "grid.hi=[0.1975, 0.0975]"]
    with pytest.raises(ValueError, match="fraction of a cell"):
        offset_sets(scene, 0.01, 1.0)
    with pytest.raises(ValueError, match="axes 'z'"):
        offset_sets(scene, 0.01, 0.5, "z")  # a 2D grid
    with pytest.raises(ValueError, match="grid.lo and grid.hi"):
        offset_sets({"grid": {"cells": [4, 4]}}, 0.01, 0.5)


# ---- scene handling and reductions (no runs) ----

def test_cell_sets_for_cell_size_cells_and_scaled_keys():
    scene = {"grid": {"lo": [0, 0], "hi": [0.2, 0.1], "cell_size": 0.01},
             "bodies": [{"shape": {"pixel_size": 0.005, "origin": [0.02, 0.04]}}]}
    sets, own = cell_sets(scene, 0.0025, ["bodies[0].shape.pixel_size"])
    assert own == 0.01 and sets == ["grid.cell_size=0.0025", "bodies[0].shape.pixel_size=0.00125"]
    cells = {"grid": {"lo": [0, 0], "hi": [0.2, 0.1], "cells": [20, 10]}}
    assert cell_sets(cells, 0.005)[0] == ["grid.cells=[40, 20]"]
    with pytest.raises(ValueError, match="grid.cells"):
        cell_sets(cells, 0.003)  # 0.2 / 0.003 is not whole
    with pytest.raises(ValueError, match="grid.cell_size"):
        cell_sets({"grid": {"lo": [0, 0], "hi": [1, 1], "cell_size": [0.1, 0.05]}}, 0.01)
    with pytest.raises(ValueError, match="grid"):
        cell_sets({"grid": {"lo": [0, 0], "hi": [1, 1]}}, 0.01)


def test_strip_comments_keeps_strings():
    text = '// head\n{"a": "x//y", /* note */ "b": "/*z*/", "c": 1 // tail\n}'
    assert json.loads(strip_comments(text)) == {"a": "x//y", "b": "/*z*/", "c": 1}


class _FakeRun:
    def __init__(self, t, y):
        self.path = "fake.h5"
        self.series = frictherm.Table("series", {"time": np.asarray(t, float), "w": np.asarray(y, float)})
        self.meta = {"steps": 7}


def test_output_reductions():
    run = _FakeRun([0.0, 1.0, 2.0, 4.0], [0.0, 3.0, 1.0, 5.0])
    assert Output("w").value(run) == 5.0
    assert Output("w:max").value(run) == 5.0 and Output("w:min").value(run) == 0.0
    assert Output("w:at=1.5").value(run) == pytest.approx(2.0)        # linear between (1, 3) and (2, 1)
    assert Output("w:since=0.5").value(run) == pytest.approx(5.0 - 1.5)
    assert Output("w:mean").value(run) == pytest.approx((1.5 + 2.0 + 6.0) / 4.0)  # trapezoids / 4 s
    assert Output("meta:steps").value(run) == 7.0
    assert Output(lambda r: 2.0 * r.meta["steps"], label="twice").value(run) == 14.0
    with pytest.raises(ValueError, match="unknown reduction"):
        Output("w:median")
    with pytest.raises(KeyError, match="did you mean w"):
        Output("ww").value(run)
    with pytest.raises(ValueError, match="outside the series"):
        Output("w:at=5").value(run)


def test_command_line_plan_and_refusal(workdir, capsys):
    from frictherm.study import main
    d = os.path.join(workdir, "cli_study")
    assert main([SCENE, "--cells", "1e-3,5e-4", "--cfl", "0.5,0.25", "--frictherm", _exe(), "-o", d, "--plan"]) == 0
    out = capsys.readouterr().out
    assert out.count("plan: h = ") == 4 and not os.path.exists(os.path.join(d, "runs"))  # nothing ran
    assert main([SCENE, "--cells", "7e-4", "--frictherm", _exe(), "-o", d, "-q"]) == 2
    assert "grid.cell_size" in capsys.readouterr().err
