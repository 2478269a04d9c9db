"""The frictherm Python package against real runs: what it reads must agree with the physics the
C++ side wrote (kinetic energy and momentum from the snapshot particles, the energy books, the
hot-spot table against the series), and integers must arrive as integers."""
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

import frictherm

C_V = 200.0  # J/(kg K), both materials of examples/sliding_block_heating.json
EXAMPLES = os.path.join(os.environ.get("FRICTHERM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                        "examples")


@pytest.fixture(scope="module")
def run(run_file):
    with frictherm.open(run_file) as r:
        yield r


def test_format_and_integer_storage(run, run_file):
    assert isinstance(run, frictherm.Run)
    assert run.format == "frictherm-output" and run.format_version == 2 and run.dim == 2
    assert run.status == "completed"
    # On disk (the C++ writer): counts are int64, strings are strings, the rest doubles.
    with h5py.File(run_file, "r") as f:
        for path in ("series/step", "series/hotspot_count", "series/contact_nodes", "hotspots/id",
                     "hotspots/particle_count", "hotspot_fates/fate", "meta/steps", "meta/particle_count",
                     "meta/thermal_steps", "meta/hotspots_seen"):
            assert f[path].dtype == np.dtype("<i8"), path
        for path in ("series/time", "series/kinetic_energy", "hotspots/peak_temperature", "meta/heat_delivered"):
            assert f[path].dtype == np.dtype("<f8"), path
        assert f["meta/scene"].dtype.kind == "S" and f["meta/scene"].dtype.char == "S"
    # Decoded: Python ints and strs.
    assert isinstance(run.meta["steps"], int) and isinstance(run.meta["particle_count"], int)
    assert isinstance(run.meta["scene"], str) and '"units": "SI"' in run.meta["scene"]
    assert run.meta["steps"] == int(run.series["step"][-1]) > 100
    assert run.series["step"].dtype == np.int64 and run.series["time"].dtype == np.float64


def test_kinetic_energy_and_momentum_of_snapshots_match_the_series(run):
    s = run.series
    rows = {int(k): i for i, k in enumerate(s["step"]) if i == 0 or s["step"][i] != s["step"][i - 1]}
    checked = 0
    for snap in run.snapshots[:-1]:  # the last one ends the thermal-only phase (mechanics frozen)
        i = rows[snap.step]
        m, v = snap["mass"], snap["velocity"]
        assert v.shape == (snap.particle_count, 2)
        ke = 0.5 * np.sum(m * np.sum(v * v, axis=1))
        assert abs(s["time"][i] - snap.time) <= 1e-12 * max(snap.time, 1e-3)
        # Both are the same sums over the same doubles (summation order aside): 1e-12 relative.
        assert ke == pytest.approx(s["kinetic_energy"][i], rel=1e-12, abs=1e-15)
        assert np.sum(m * v[:, 0]) == pytest.approx(s["momentum_x"][i], rel=1e-11, abs=1e-15)
        checked += 1
    assert checked == len(run.snapshots) - 1 >= 10
    assert max(abs(s["kinetic_energy"])) > 0.1  # the block does slide (J per m)


def test_energy_books_close(run):
    books = run.energy_books
    assert books["heat_delivered"] == run.series["heat_delivered"][-1]
    assert books["heat_delivered"] > 0.0
    # Heat delivered equals the particles' thermal energy change, recomputed here from the first
    # and last snapshots: sum m c_v (T_end - T_0). Conservation, to round-off of ~1e5 particle sums.
    first, last = run.snapshots[0], run.snapshots[-1]
    de = np.sum(last["mass"] * C_V * (last["temperature"] - first["temperature"]))
    assert de == pytest.approx(books["particle_energy_change"], rel=1e-9)
    assert de == pytest.approx(books["heat_delivered"], rel=1e-6)


def test_hotspot_table_agrees_with_the_series(run):
    h, s = run.hotspots, run.series
    assert len(h) > 0 and h["id"].dtype == np.int64
    assert h.columns[:3] == ["time", "id", "particle_count"]
    # Each coupling window's rows are written with the series row of that time: as many rows as the
    # series' hotspot_count there, and no peak above the series' max_temperature.
    for t in np.unique(h["time"]):
        i = int(np.flatnonzero(s["time"] == t)[0])
        assert np.count_nonzero(h["time"] == t) == s["hotspot_count"][i]
        assert h.where(h["time"] == t)["peak_temperature"].max() <= s["max_temperature"][i] + 1e-9
    assert len(run.hotspot_fates) == len(np.unique(run.hotspot_fates["id"])) > 0


def test_series_as_dataframe(run):
    df = run.series.to_dataframe(index=None)  # row numbers, time a column
    assert list(df.columns) == run.series.columns
    assert df.shape == (len(run.series), len(run.series.columns))
    assert run.series.to_dataframe().shape == (len(run.series), len(run.series.columns) - 1)  # time: the index
    assert np.array_equal(df["kinetic_energy"].to_numpy(), run.series["kinetic_energy"])
    assert str(df["step"].dtype) == "int64"


def test_snapshots_times_and_selection(run):
    times = run.snapshot_times
    assert times[0] == 0.0 and np.all(np.diff(times) > 0)
    assert run.snapshot("last") is run.snapshots[-1]
    assert run.snapshot_at(run.meta["end_time"]).time == pytest.approx(run.meta["end_time"], rel=1e-12)
    assert run.failure is None
    with pytest.raises(KeyError, match="no field 'nope'"):
        run.snapshots[0]["nope"]


def test_physical_shape_accepts_two_and_three_component_vectors():
    v2 = np.arange(10.0).reshape(5, 2)
    v3 = np.column_stack([v2, np.zeros(5)])  # a 2D vector padded for VTK
    assert np.array_equal(frictherm.physical_shape(v3, 2), v2)
    assert np.array_equal(frictherm.physical_shape(v2, 2), v2)
    t4 = np.arange(20.0).reshape(5, 4)
    t9 = np.zeros((5, 3, 3))
    t9[:, :2, :2] = t4.reshape(5, 2, 2)
    assert np.array_equal(frictherm.physical_shape(t9.reshape(5, 9), 2), t4.reshape(5, 2, 2))
    assert np.array_equal(frictherm.physical_shape(t4, 2), t4.reshape(5, 2, 2))
    sym = np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 5.0], [3.0, 5.0, 6.0]])
    t6 = np.tile([1.0, 2.0, 3.0, 4.0, 5.0, 6.0], (5, 1))  # xx, xy, xz, yy, yz, zz
    assert np.array_equal(frictherm.physical_shape(t6, 3), np.broadcast_to(sym, (5, 3, 3)))


def test_format_version_1_counts_come_back_as_integers(tmp_path):
    p = str(tmp_path / "v1.h5")
    with h5py.File(p, "w") as f:
        f.attrs["format"] = np.bytes_("frictherm-output")
        f.attrs["format_version"] = np.int32(1)
        f.attrs["dim"] = np.int32(2)
        g = f.create_group("series")
        g.attrs["columns"] = np.array([b"time", b"step", b"kinetic_energy"])
        g["time"], g["step"], g["kinetic_energy"] = [0.0, 1e-6], [0.0, 1.0], [0.0, 2.5]
        f.create_group("meta")["steps"] = 1.0
    with frictherm.open(p) as r:
        assert r.series["step"].dtype == np.int64 and list(r.series["step"]) == [0, 1]
        assert r.series["kinetic_energy"].dtype == np.float64 and len(r.snapshots) == 0


def test_not_a_frictherm_file(tmp_path):
    p = str(tmp_path / "other.h5")
    with h5py.File(p, "w") as f:
        f["x"] = 1
    with pytest.raises(ValueError, match="not a frictherm file"):
        frictherm.open(p)


def test_ensemble(ensemble_file):
    with frictherm.open(ensemble_file) as ens:
        assert isinstance(ens, frictherm.Ensemble) and ens.format_version == 2
        m, h = ens.members, ens.hotspots
        assert list(m["seed"]) == [2, 3] and m["seed"].dtype == np.int64
        assert list(m["status"]) == [0, 0]
        assert ens.summary["members"] == 2 and isinstance(ens.summary["hotspots_total"], int)
        assert ens.summary["hotspots_total"] == len(h) == int(m["hotspots"].sum()) > 0
        decided = np.count_nonzero(h["fate"] > 0)
        if decided:
            assert ens.critical_fraction == pytest.approx(np.count_nonzero(h["fate"] == 2) / decided, rel=1e-15)
        else:
            assert ens.critical_fraction is None
        for k, seed in enumerate(m["seed"]):
            with ens.member(seed) as member:
                assert isinstance(member, frictherm.Run)
                assert len(np.unique(member.hotspots["id"])) == m["hotspots"][k]
                assert member.meta["steps"] == m["steps"][k]


def test_examples_read_through_the_package(run_file, ensemble_file, tmp_path):
    """plot_run.py --list, pbx_figures.py --redraw (no rerun) and ensemble_figures.py on the files."""
    env = dict(os.environ)
    out = subprocess.run([sys.executable, os.path.join(EXAMPLES, "plot_run.py"), run_file, "--list"], env=env,
                         check=True, capture_output=True, text=True).stdout
    assert "status completed" in out and "hotspots (" in out
    redraw = subprocess.run([sys.executable, os.path.join(EXAMPLES, "pbx_figures.py"), "--redraw", run_file, "--out",
                             str(tmp_path)], env=env, check=True, capture_output=True, text=True).stdout
    with frictherm.open(run_file) as r:  # the hot spots circled: those of the window at the end of loading
        at_end = int(np.count_nonzero(r.hotspots["time"] == r.hotspots["time"][np.argmin(
            abs(r.hotspots["time"] - r.meta["end_time"]))]))
    assert at_end >= 1 and f"{at_end} hot spots at the end of loading" in redraw
    for suffix in ("_temperature.png", "_hotspots.png", "_series.png"):
        png = tmp_path / ("run" + suffix)
        assert png.stat().st_size > 10000, png
    subprocess.run([sys.executable, os.path.join(EXAMPLES, "ensemble_figures.py"), ensemble_file, "-o",
                    str(tmp_path / "ens")], env=env, check=True, capture_output=True)
    assert (tmp_path / "ens_hotspots.png").stat().st_size > 10000


def test_decomposed_run_snapshots_join_the_rank_files(decomposed_pair):
    # The decomposed run equals the serial run to round-off (tests/coupling: mpirun tests), so its
    # rank files joined by id must give the serial snapshots: every particle once, in id order, with
    # the serial positions, velocities and temperatures to 1e-12 of the scene's own scales (the
    # 26 mm grid, the block's 10 m/s, its 300 K); measured 7e-18 m, 2e-14 m/s, 1.1e-13 K.
    serial_file, decomposed_file = decomposed_pair
    with frictherm.open(serial_file) as serial, frictherm.open(decomposed_file) as decomposed:
        assert serial.ranks == 1 and decomposed.ranks == 2
        assert len(decomposed.snapshots) == len(serial.snapshots) == 5
        for a, b in zip(serial.snapshots, decomposed.snapshots):
            assert b.time == a.time and b.step == a.step
            assert b.particle_count == a.particle_count == serial.meta["particle_count"]
            np.testing.assert_array_equal(b["id"], np.arange(b.particle_count))
            np.testing.assert_array_equal(b["material"], a["material"])
            np.testing.assert_array_equal(b["connectivity"], np.arange(b.particle_count))
            assert np.abs(b["position"] - a["position"]).max() <= 1e-12 * 0.026
            assert np.abs(b["velocity"] - a["velocity"]).max() <= 1e-12 * 10.0
            assert np.abs(b["temperature"] - a["temperature"]).max() <= 1e-12 * 300.0
            # The thermal grid's nodes: each rank's owned unknowns joined in the serial (grid node)
            # order, the serial positions and lattice exactly, T_i and M_i to round-off (issue 32).
            assert a.has_nodes and b.has_nodes
            na, nb = a.nodes(), b.nodes()
            assert list(nb.columns) == list(na.columns) and len(nb) == len(na) > 0
            for c in na.columns:
                if c.startswith(("position", "lattice")):
                    np.testing.assert_array_equal(nb[c].values, na[c].values)
            assert np.abs(nb["temperature"].values - na["temperature"].values).max() <= 1e-12 * 300.0
            assert np.abs(nb["heat_capacity"].values - na["heat_capacity"].values).max() <= 1e-12 * na["heat_capacity"].max()
            assert nb.attrs["units"] == na.attrs["units"]
        assert decomposed.failure is None
    # Without its rank files a decomposed run says which file is missing.
    os.rename(decomposed_file.replace(".h5", ".rank1.h5"), decomposed_file.replace(".h5", ".rank1.moved"))
    try:
        with frictherm.open(decomposed_file) as decomposed:
            with pytest.raises(FileNotFoundError, match="rank1.h5"):
                decomposed.snapshots
    finally:
        os.rename(decomposed_file.replace(".h5", ".rank1.moved"), decomposed_file.replace(".h5", ".rank1.h5"))


def test_series_figure_groups_columns_by_unit_with_prefixed_axes(run, tmp_path):
    """frictherm.plot (issue 33 item 4): the series figure has a few panels of one unit each (energies
    split into mechanical, dissipated, frictional work and heat), every column but time/step in exactly
    one panel of its own unit unless it has no finite value or repeats its total (a per-pair column
    with one pair), no total left out, and axes read with SI prefixes (3e-6 m as 3 µm, 2e-8 s as
    20 ns, 4e-4 m^2 as 400 mm²) or a power of ten in the label; with no file name the figure is
    returned (notebooks)."""
    from frictherm.plot import plot_series, scale_for, series_groups
    s = run.series
    groups = series_groups(run)
    placed = [c for _, _, names in groups for c in names]
    assert len(placed) == len(set(placed))
    for c in s.columns:
        if c in ("time", "step") or c in placed:
            continue
        values, total = np.asarray(s[c], dtype=float), c.split(".", 1)[0]
        assert not np.isfinite(values).any() or (
            "." in c and np.array_equal(values, np.asarray(s[total], dtype=float), equal_nan=True)), c
    assert all(s.unit_of(c) == unit for _, unit, names in groups for c in names)
    panel = {c: title for title, _, names in groups for c in names}
    assert panel["kinetic_energy"] == "energy" and panel["energy_lost"] == "dissipated energy"
    assert panel["friction_work_first"] == panel["heat_delivered"] == "frictional work and heat"
    assert all(len(names) <= 8 for _, _, names in groups) and len(groups) < len(placed) / 2
    assert scale_for([0.0, 3e-6], "m") == (1e6, "µm")
    factor, unit = scale_for([0.0, 2e-8], "s")
    assert unit == "ns" and abs(factor * 2e-8 - 20.0) < 1e-12
    assert scale_for([4e-4], "m^2") == (1e6, "mm²") and scale_for([2e-15], "m^3") == (1e18, "µm³")
    factor, unit = scale_for([-2.2e-8, 1e-9], "kg m/s")
    assert unit == "10⁻⁸ kg m/s" and abs(factor * 2.2e-8 - 2.2) < 1e-12
    assert scale_for([1.0, 300.0], "K") == (1.0, "K")  # no prefixes on temperatures
    fig = plot_series(run)
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == len(groups)
    fig.canvas.draw()  # sets the tick labels and offset texts
    for ax in visible:  # no offset text ("1e-8" above an axis): the scale is in the label
        assert ax.yaxis.get_offset_text().get_text() == "", (ax.get_title(), ax.yaxis.get_offset_text().get_text())
    assert plot_series(run, None, str(tmp_path / "s.png")) is None and (tmp_path / "s.png").stat().st_size > 10000


def test_3d_run_drawn_as_slices_with_rigid_particles_apart(run_file_3d, tmp_path):
    """frictherm.plot.plot_slices (issue 33 item 4: a 3D run drawn as slices): three panels normal to z,
    each with the particles within half a spacing of its level drawn as squares of that spacing (not
    dots: the marker side in points equals the particle side times the axes' points per metre), axes
    in mm; the rigid floor's particles are grey and out of the colour scale, which spans exactly the
    cube's speeds (the floor's 0 m/s would otherwise stretch it)."""
    import matplotlib
    from frictherm.fields import field_values
    from frictherm.plot import particle_side, plot_particles, plot_slices, rigid_particles
    with frictherm.open(run_file_3d) as run:
        snap = run.snapshot("last")
        rigid = rigid_particles(run, snap)
        assert rigid.sum() == 288 and (~rigid).sum() == 1152  # the 12 x 12 x 2 floor, the 12 x 12 x 8 cube
        speed, _ = field_values(snap, "speed")
        assert speed[rigid].max() == 0.0 and speed[~rigid].min() > 0.0
        fig = plot_slices(run, snap, "speed")
        panels = [ax for ax in fig.axes if ax.get_xlabel() == "x (mm)"]
        assert len(panels) == 3 and all(ax.get_ylabel() == "y (mm)" for ax in panels)
        side = float(particle_side(run, snap).max())
        for ax in panels:
            (dots,) = ax.collections
            x0, x1 = ax.transData.transform([[0.0, 0.0], [1.0, 0.0]])[:, 0]
            expected = side * 1e3 * (x1 - x0) * 72.0 / fig.dpi  # points (axes in mm)
            assert np.allclose(np.sqrt(dots.get_sizes()), expected, rtol=0.02), (np.sqrt(dots.get_sizes()[:3]), expected)
        (bar,) = [ax for ax in fig.axes if ax not in panels]
        lo, hi = bar.get_ylim()
        assert lo == pytest.approx(speed[~rigid].min(), rel=1e-12) and hi == pytest.approx(speed[~rigid].max(), rel=1e-12)
        grey = matplotlib.colors.to_rgba("0.78")
        # Particle centres span z = 2.5 ... 11.5 mm: the lowest slice (z = 4 mm) meets the floor's top
        # layer, the highest (z = 10 mm) the cube only.
        greys = [sum(tuple(c) == grey for c in ax.collections[0].get_facecolors()) for ax in panels]
        assert greys[0] > 0 and greys[-1] == 0, greys
        matplotlib.pyplot.close(fig)
        plot_particles(run, snap, "speed", str(tmp_path / "p.png"))
        assert (tmp_path / "p.png").stat().st_size > 10000
