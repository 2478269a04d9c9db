"""Files that describe themselves (issue 33 item 2): every dataset the program writes carries
`units` and `long_name`, the scene is plain JSON, fates have names, and the reader hands them on
(series indexed by time with units in attrs, a snapshot as a DataFrame, the run as xarray)."""
import json

import h5py
import numpy as np
import pytest

import frictherm

# Units a physicist would check by hand for a few datasets of the heated sliding block (2D).
EXPECTED = {"series/time": "s", "series/kinetic_energy": "J", "series/max_temperature": "K",
            "series/momentum_x": "kg m/s", "series/contact_heat_rate": "W", "series/step": "1",
            "hotspots/size": "m^2", "hotspots/centroid_x": "m", "hotspot_fates/decision_time": "s",
            "meta/cell_size": "m", "meta/heat_delivered": "J", "meta/scene": "", "meta/grid_lo": "m",
            "snapshots/000000/stress": "Pa", "snapshots/000000/velocity": "m/s",
            "snapshots/000000/temperature": "K", "snapshots/000000/volume": "m^3"}


@pytest.fixture(scope="module")
def run(run_file):
    with frictherm.open(run_file) as r:
        yield r


def datasets_without_units(path):
    missing = []
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and not ("units" in obj.attrs and "long_name" in obj.attrs):
                missing.append(name)
        f.visititems(visit)
    return missing


def test_every_dataset_has_units_and_long_name(run_file):
    assert datasets_without_units(run_file) == []
    with h5py.File(run_file, "r") as f:
        for path, units in EXPECTED.items():
            assert frictherm._h5.text(f[path].attrs["units"]) == units, path
        # Per-body and per-pair columns name their body or pair.
        per_body = [c for c in f["series"] if c.startswith("mean_temperature.")]
        assert per_body and all(frictherm._h5.text(f["series"][c].attrs["units"]) == "K" for c in per_body)
        assert per_body[0].split(".", 1)[1] in frictherm._h5.text(f["series"][per_body[0]].attrs["long_name"])


def test_series_indexed_by_time_with_units(run):
    df = run.series.to_dataframe()
    assert df.index.name == "time"
    assert np.array_equal(df.index.to_numpy(), run.series["time"])
    assert df.attrs["units"]["max_temperature"] == "K" and df.attrs["units"]["kinetic_energy"] == "J"
    assert run.unit_of("max_temperature") == "K" and run.unit_of("temperature") == "K"
    assert run.unit_of("heat_delivered") == "J" and run.unit_of("dt") == "s"


def test_scene_is_plain_json_with_the_overrides(run):
    scene = json.loads(run.meta["scene_json"])
    assert scene == run.scene
    assert scene["coupling"]["continuation"]["duration"] == 0.002  # --set by conftest.py
    assert scene["units"] == "SI"


def test_grid_and_materials_as_numbers(run):
    g = run.grid
    # The text /meta/grid says the same (lo ...; hi ...; cells ...; cell_size ...).
    parts = dict(p.strip().split(" ", 1) for p in run.meta["grid"].split(";"))
    for k in ("lo", "hi", "cell_size"):
        assert np.allclose(g[k], np.array(parts[k].split(), dtype=float), rtol=1e-9, atol=0)
    assert g["cells"].dtype == np.int64 and list(g["cells"]) == [int(v) for v in parts["cells"].split()]
    # cells x cell size spans the grid
    assert np.allclose(g["cells"] * g["cell_size"], g["hi"] - g["lo"], rtol=1e-12)
    assert run.materials == [p.split()[1] for p in run.meta["materials"].split(";")]
    assert run.meta["body_names"] == [p.split()[1] for p in run.meta["bodies"].split(";")]


def test_fates_by_name(run):
    fates = run.hotspot_fates
    names = fates.names_of("fate")
    assert set(names) <= {"undecided", "dying", "runaway"} and len(names) == len(fates)
    assert all(frictherm.FATE_NAMES[int(c)] == n for c, n in zip(fates["fate"], names))
    df = fates.to_dataframe()
    assert list(df["fate_name"].astype(str)) == list(names)


def test_fate_names_of_files_without_flags(tmp_path):
    """A file written before the flag attributes still names its fates (the reader's own table)."""
    path = tmp_path / "old.h5"
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "frictherm-output"
        f.attrs["format_version"] = 2
        f.attrs["dim"] = 2
        g = f.create_group("hotspot_fates")
        g["id"] = np.array([3, 4, 5], dtype=np.int64)
        g["fate"] = np.array([2, 0, 1], dtype=np.int64)
        s = f.create_group("series")
        s["time"] = np.array([0.0, 1.0])
    with frictherm.open(path) as r:
        assert list(r.hotspot_fates.names_of("fate")) == ["runaway", "undecided", "dying"]
        assert r.unit_of("time") == "s"


def test_snapshot_as_dataframe(run):
    snap = run.snapshot("last")
    df = snap.to_dataframe()
    assert len(df) == snap.particle_count
    assert np.array_equal(df["velocity_x"].to_numpy(), snap["velocity"][:, 0])
    assert np.array_equal(df["stress_xy"].to_numpy(), snap["stress"][:, 0, 1])
    assert "velocity_z" not in df  # 2D: the stored z padding is not a column
    assert df.attrs["units"]["temperature"] == "K" and df.attrs["units"]["stress_xy"] == "Pa"
    assert df.attrs["time"] == snap.time


def test_run_as_xarray(run):
    xr = pytest.importorskip("xarray")
    ds = run.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert np.array_equal(ds["kinetic_energy"].to_numpy(), run.series["kinetic_energy"])
    assert ds["kinetic_energy"].attrs["units"] == "J"
    n = run.snapshots[0].particle_count
    assert ds["temperature"].shape == (len(run.snapshots), n) and ds["temperature"].attrs["units"] == "K"
    assert ds["velocity"].shape == (len(run.snapshots), n, 2)
    assert np.array_equal(ds["temperature"].isel(snapshot=-1).to_numpy(), run.snapshot("last")["temperature"])
    assert np.array_equal(ds["snapshot_time"].to_numpy(), run.snapshot_times)


def test_decomposed_run_files_have_units(decomposed_pair):
    """The serial file of the small decomposed scene, and the decomposed run's OUT.h5 and rank files."""
    serial, decomposed = decomposed_pair
    files = [serial, decomposed] + [decomposed.replace(".h5", f".rank{r}.h5") for r in range(2)]
    for path in files:
        assert datasets_without_units(path) == [], path
    with frictherm.open(decomposed) as r:
        assert r.unit_of("temperature") == "K" and r.snapshot("last").unit_of("velocity") == "m/s"


def test_ensemble_file_has_units(ensemble_file):
    assert datasets_without_units(ensemble_file) == []
    with frictherm.open(ensemble_file) as ens:
        assert ens.members.units["simulated_time"] == "s" and ens.hotspots.units["size"] == "m^2"
        assert list(ens.hotspots.names_of("fate")) == [frictherm.FATE_NAMES[int(c)] for c in ens.hotspots["fate"]]


def test_nodal_temperature_holds_the_particles_heat(run):
    """/nodes (the thermal grid's state at each snapshot): with adiabatic edges and the incremental
    update (no sub-grid relaxation), sum_i M_i T_i equals sum_p m_p C_v T_p at every snapshot (eq. 38 at
    assembly, then sum_p m_p C_v dT_p = sum_i M_i dT_i for each window). Compared as the heat-capacity
    weighted mean temperatures; the two differ only by the nodes left out as unknowns (M_i below the
    active fraction of the largest: measured 4e-11 of sum M here) times T, so 1e-8 K (1e-7 of the
    block's mean rise, 1000 x the measured 1e-11 K) cannot hide a stale or misplaced nodal field."""
    c_v = 200.0  # J/(kg K), both materials of examples/sliding_block_heating.json
    assert len(run.snapshots) >= 3
    rise = 0.0
    for snap in run.snapshots:
        nodes = snap.nodes()
        assert nodes.attrs["units"]["temperature"] == "K" and nodes.attrs["units"]["heat_capacity"] == "J/K"
        assert len(nodes) > 0
        m = snap["mass"] * c_v
        particle_mean = float((m * snap["temperature"]).sum() / m.sum())
        node_mean = float((nodes["heat_capacity"] * nodes["temperature"]).sum() / nodes["heat_capacity"].sum())
        assert abs(node_mean - particle_mean) < 1e-8, (snap.label, node_mean, particle_mean)
        rise = particle_mean - 293.15
    assert rise > 1e-3  # the sliding heated the block, so the identity is not 293.15 = 293.15
