#!/usr/bin/python3
"""A decomposed run's output opened as one data set (issue 16, item 3): `mpirun -n K frictherm run
SCENE -o OUT.h5` writes OUT.rank<r>.h5 per rank joined by OUT.xdmf (DecomposedOutput,
coupling/src/distributed/decomposed_output.cpp). The 2D heated sliding block and the 3D heated
sliding block of the CliMpirun tests (tests/coupling/scenes/) run on 2 and 3 ranks, and the 2D block
started 2 mm further back on 4 ranks (a rank without particles in the first snapshots: no grid for
it there); OUT.xdmf is opened
with VTK's XDMF reader (vtkXdmf3Reader, Debian python3-paraview) and with ParaView's own reader
(paraview.simple.OpenDataFile: Xdmf3ReaderS, then MergeBlocks; headless, no display needed).
Asserted for every snapshot:

* the reader's time steps are the rank files' snapshot `time` attributes and the serial run's
  snapshot times, exactly (the XDMF holds the shortest text that reads back to the same double);
* VTK: one multiblock of one vtkUnstructuredGrid per rank that has particles, block `rank<r>` holding
  rank r's rows in the file's order: points (z = 0 in 2D), `id` (64-bit), `velocity` (3 components),
  `temperature`, `material` and the serial snapshot's `displacement` (3), `stress` (9, a tensor),
  `stress_zz`, `mass`, `volume`, `body` equal to the HDF5 rows exactly (doubles are read as doubles),
  one vertex cell per particle;
* both readers' merged data set (vtkAppendFilter of the blocks / ParaView's MergeBlocks) has exactly
  the total particle count, every id 0..N-1 once, and by id the same points and fields as the rank
  files, exactly;
* at the last snapshot the set of (id, position) equals the serial run's (`frictherm run` without
  mpirun; id = serial row) to 1e-12 of the box size, and the temperatures to 1e-9 of the largest
  rise, the CliMpirun tolerance (they measure 7e-18 m on 1 mm cells and 1e-13 K: the engines add
  the same terms in another order);
* OUT_reference.xdmf (issue 32, the serial RUN_reference.xdmf) is published with the result and VTK
  reads it as OUT.xdmf with the points at each particle's `initial_position`, the same checks.

    vtk_decomposed.py FRICTHERM_EXE SCENES_DIR WORK_DIR [--mpirun MPIRUN] [--png docs/figures/decomposed_xdmf.png]

--png draws the 2D run on 3 ranks at its last snapshot from the VTK reader's blocks (coloured by
rank and by temperature). Exits 77 (ctest: skipped) when VTK's XDMF reader or mpirun is missing.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

try:
    from vtkmodules.vtkCommonDataModel import VTK_POLY_VERTEX, VTK_VERTEX, vtkDataSet
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline
    from vtkmodules.vtkFiltersCore import vtkAppendFilter
    from vtkmodules.vtkIOXdmf3 import vtkXdmf3Reader
    from vtkmodules.util.numpy_support import vtk_to_numpy
except ImportError as e:  # pragma: no cover - depends on the machine
    print(f"vtk_decomposed.py: VTK's XDMF reader is not available ({e}); install python3-paraview "
          "(scripts/install_deps.sh)")
    sys.exit(77)

try:
    from paraview import simple as pv
    from paraview import servermanager
except ImportError as e:  # pragma: no cover - VTK without ParaView's Python
    print(f"vtk_decomposed.py: paraview.simple is not available ({e}); checking with VTK's reader only")
    pv = None

SCENES = {2: "decomposed_sliding_block.json", 3: "decomposed_heated_block_3d.json"}
# (name, dimension, --set options, rank counts). "2D, block 2 mm back" on 4 ranks (2 x 2): the top
# right rank has no particle until the block slides into it, so the first snapshots' spatial
# collections have 3 grids and the later ones 4.
CASES = [("2D", 2, [], (2, 3)),
         ("2D, block 2 mm back", 2, ["bodies[1].shape.lo=[0.004,0.004]", "bodies[1].shape.hi=[0.012,0.008]"], (4,)),
         ("3D", 3, [], (2, 3))]
# With the serial snapshot's other fields (issue 32): displacement, the stress tensor, mass, volume, body.
FIELDS = {"id": 1, "velocity": 3, "temperature": 1, "material": 1, "displacement": 3, "stress": 9, "stress_zz": 1,
          "mass": 1, "volume": 1, "body": 1}


def fields_for(dim):
    """The fields of a snapshot in `dim` D (stress_zz, the out-of-plane stress, is 2D's)."""
    return {k: c for k, c in FIELDS.items() if not (k == "stress_zz" and dim == 3)}

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)
    return ok


def mpirun_command(mpirun, ranks):
    cmd = [mpirun, "--oversubscribe", "-n", str(ranks)]  # any machine: CI has 2 cores
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")  # Open MPI refuses root otherwise
    return cmd


def run(cmd, out):
    # --force: a rerun in the same build folder replaces the previous result (refused by default)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    subprocess.run(cmd + ["-o", out, "--force", "-q"], check=True, env=env, stdout=subprocess.DEVNULL)


def rank_snapshots(base, ranks, dim, geometry="position"):
    """Per snapshot (in file order): time, step and per rank the rows of every field (the points: `geometry`
    padded to 3)."""
    snaps = []
    for r in range(ranks):
        with h5py.File(f"{base}.rank{r}.h5", "r") as f:
            groups = [f["snapshots"][k] for k in sorted(f["snapshots"])]
            if r == 0:
                snaps = [{"time": float(g.attrs["time"]), "step": int(g.attrs["step"]), "ranks": {}} for g in groups]
            check(len(groups) == len(snaps), f"{base}: rank {r} has {len(groups)} snapshots, rank 0 {len(snaps)}")
            for s, g in zip(snaps, groups):
                check(float(g.attrs["time"]) == s["time"] and int(g.attrs["step"]) == s["step"],
                      f"{base}: rank {r} snapshot {g.name} at the time and step of rank 0's")
                x = np.zeros((g["id"].shape[0], 3))
                x[:, :dim] = g[geometry][()]
                rows = {"position": x, **{k: g[k][()] for k in fields_for(dim)}}
                if len(x):
                    s["ranks"][r] = rows
    return snaps


def by_id(parts, total):
    """The rows of several parts (ranks or a merged data set) ordered by id; None when an id is missing or repeated."""
    ids = np.concatenate([p["id"] for p in parts])
    if len(ids) != total or not np.array_equal(np.sort(ids), np.arange(total)):
        return None
    order = np.argsort(ids)
    return {k: np.concatenate([p[k] for p in parts])[order] for k in parts[0]}


def dataset_rows(data, dim):
    pd = data.GetPointData()
    rows = {"position": vtk_to_numpy(data.GetPoints().GetData())}
    for name, comps in fields_for(dim).items():
        a = pd.GetArray(name)
        if not check(a is not None and a.GetNumberOfComponents() == comps, f"VTK array {name} with {comps} component(s)"):
            return None
        rows[name] = vtk_to_numpy(a).reshape((-1, comps)) if comps > 1 else vtk_to_numpy(a)
    check(pd.GetArray("id").GetDataTypeSize() == 8, "VTK id array is 64-bit")
    return rows


def same_rows(got, want, tag):
    for k, v in want.items():
        check(got[k].shape == v.shape and np.array_equal(got[k], v), f"{tag}: {k} equals the HDF5 rows")


def vertex_cells(data, tag):
    n = data.GetNumberOfPoints()
    types = {data.GetCellType(c) for c in range(data.GetNumberOfCells())}
    sizes = {data.GetCell(c).GetNumberOfPoints() for c in range(min(n, 50))}
    check(data.GetNumberOfCells() == n and types <= {VTK_VERTEX, VTK_POLY_VERTEX} and sizes == {1},
          f"{tag}: {data.GetNumberOfCells()} cells of types {types} for {n} particles (one vertex each)")


def check_vtk(xdmf, snaps, total, label, dim):
    reader = vtkXdmf3Reader()
    reader.SetFileName(os.path.abspath(xdmf))  # Xdmf3 resolves the rank files against the folder of this path
    reader.UpdateInformation()
    times = list(reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS()) or [])
    check(times == [s["time"] for s in snaps], f"{label}: VTK time steps {times} are the snapshot times")
    merged = []
    for s in snaps:
        tag = f"{label} VTK t = {s['time']:.6g}"
        reader.UpdateTimeStep(s["time"])
        out = reader.GetOutputDataObject(0)
        if not check(out.IsA("vtkMultiBlockDataSet"), f"{tag}: a multiblock ({out.GetClassName()})"):
            continue
        check(out.GetNumberOfPoints() == total, f"{tag}: {out.GetNumberOfPoints()} points, {total} particles")
        blocks, append = {}, vtkAppendFilter()
        for b in range(out.GetNumberOfBlocks()):
            data = out.GetBlock(b)
            name = out.GetMetaData(b).Get(out.NAME()) if out.HasMetaData(b) else ""
            m = re.match(r"rank(\d+)", name or "")  # the reader appends [k] to the names of later time steps
            if not check(isinstance(data, vtkDataSet) and m is not None, f"{tag}: block {b} '{name}' is a rank's grid"):
                continue
            blocks[int(m.group(1))] = data
            append.AddInputData(data)
        check(sorted(blocks) == sorted(s["ranks"]), f"{tag}: blocks of ranks {sorted(blocks)}, ranks with particles {sorted(s['ranks'])}")
        for r, data in blocks.items():
            rows = dataset_rows(data, dim)
            if rows is not None and r in s["ranks"]:
                same_rows(rows, s["ranks"][r], f"{tag} rank {r}")
            vertex_cells(data, f"{tag} rank {r}")
        append.Update()
        one = append.GetOutput()
        rows = dataset_rows(one, dim)
        got = by_id([rows], total) if rows is not None else None
        if check(got is not None, f"{tag}: the merged data set holds every id 0..{total - 1} once"):
            same_rows(got, by_id(list(s["ranks"].values()), total), f"{tag} merged")
            merged.append(got)
        vertex_cells(one, f"{tag} merged")
    return merged


def check_paraview(xdmf, snaps, total, label, dim):
    source = pv.OpenDataFile(os.path.abspath(xdmf))
    check(source.GetXMLName() == "Xdmf3ReaderS", f"{label}: ParaView picks {source.GetXMLName()}")
    times = list(source.TimestepValues)
    check(times == [s["time"] for s in snaps], f"{label}: ParaView time steps {times} are the snapshot times")
    merge = pv.MergeBlocks(Input=source)
    for s in snaps:
        tag = f"{label} ParaView t = {s['time']:.6g}"
        merge.UpdatePipeline(s["time"])
        one = servermanager.Fetch(merge)
        check(one.GetNumberOfPoints() == total, f"{tag}: {one.GetNumberOfPoints()} points, {total} particles")
        rows = dataset_rows(one, dim)
        got = by_id([rows], total) if rows is not None else None
        if check(got is not None, f"{tag}: every id 0..{total - 1} once"):
            same_rows(got, by_id(list(s["ranks"].values()), total), tag)
    pv.Delete(merge)
    pv.Delete(source)


def serial_last(h5, dim):
    with h5py.File(h5, "r") as f:
        groups = [f["snapshots"][k] for k in sorted(f["snapshots"])]
        g = groups[-1]
        x = np.zeros((g["position"].shape[0], 3))
        x[:, :dim] = g["position"][()]
        grid = dict(part.split(" ", 1) for part in f["meta"]["grid"][()].decode().split("; "))  # "lo 0 0; hi ...; ..."
        lo, hi = (np.array([float(v) for v in grid[k].split()]) for k in ("lo", "hi"))
        return [float(s.attrs["time"]) for s in groups], x, g["temperature"][()], float(np.max(hi - lo))


def check_scene(a, name, dim, sets, rank_counts):
    """Runs the scene serially and on each rank count, checks every run; returns {ranks: OUT base}."""
    scene = os.path.join(a.scenes, SCENES[dim])
    options = [w for kv in sets for w in ("--set", kv)]
    serial = os.path.join(a.work, f"serial_{re.sub(r'[^0-9A-Za-z]+', '_', name)}.h5")
    run([a.frictherm, "run", scene, "--threads", "1"] + options, serial)
    serial_times, serial_x, serial_T, box = serial_last(serial, dim)
    result = {}
    for ranks in rank_counts:
        label = f"{name} on {ranks} ranks"
        base = os.path.join(a.work, f"split_{re.sub(r'[^0-9A-Za-z]+', '_', name)}_np{ranks}")
        run(mpirun_command(a.mpirun, ranks) + [a.frictherm, "run", scene] + options, base + ".h5")
        snaps = rank_snapshots(base, ranks, dim)
        total = sum(len(rows["id"]) for rows in snaps[0]["ranks"].values())
        check(total == len(serial_x), f"{label}: {total} particles, serial {len(serial_x)}")
        check([s["time"] for s in snaps] == serial_times, f"{label}: snapshot times are the serial run's")
        merged = check_vtk(base + ".xdmf", snaps, total, label, dim)
        # OUT_reference.xdmf (issue 32, the serial RUN_reference.xdmf): the same grids at initial_position.
        if check(os.path.exists(base + "_reference.xdmf"), f"{label}: the reference XDMF is published"):
            check_vtk(base + "_reference.xdmf", rank_snapshots(base, ranks, dim, "initial_position"), total,
                      label + " (reference)", dim)
        if pv is not None:
            check_paraview(base + ".xdmf", snaps, total, label, dim)
        if len(merged) == len(snaps) and total == len(serial_x):
            dx = float(np.max(np.abs(merged[-1]["position"] - serial_x)))
            dT = float(np.max(np.abs(merged[-1]["temperature"] - serial_T)))
            rise = float(np.max(serial_T) - np.min(serial_T))
            check(dx <= 1e-12 * box, f"{label}: last snapshot positions {dx:.3g} m from the serial run's (box {box:.3g} m)")
            check(dT <= 1e-9 * rise, f"{label}: last snapshot temperatures {dT:.3g} K from the serial run's (rise {rise:.3g} K)")
            print(f"{label}: {len(snaps)} snapshots, {total} particles, blocks per snapshot "
                  f"{[len(s['ranks']) for s in snaps]}; last snapshot vs serial: position {dx:.3g} m "
                  f"({dx / box:.2g} of the box), temperature {dT:.3g} K (rise {rise:.3g} K)")
        result[ranks] = base
    return result


def draw(base, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    reader = vtkXdmf3Reader()
    reader.SetFileName(os.path.abspath(base + ".xdmf"))
    reader.UpdateInformation()
    t = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS())[-1]
    reader.UpdateTimeStep(t)
    out = reader.GetOutputDataObject(0)
    fig, axes = plt.subplots(2, 1, figsize=(7.5, 5.2), sharex=True)
    colours = plt.get_cmap("tab10")
    temps = []
    for b in range(out.GetNumberOfBlocks()):
        data = out.GetBlock(b)
        x = 1e3 * vtk_to_numpy(data.GetPoints().GetData())
        rank = re.match(r"rank(\d+)", out.GetMetaData(b).Get(out.NAME())).group(1)
        axes[0].scatter(x[:, 0], x[:, 1], s=7, color=colours(int(rank)), label=f"block rank{rank} ({len(x)} particles)")
        temps.append((x, vtk_to_numpy(data.GetPointData().GetArray("temperature"))))
    lo = min(float(T.min()) for _, T in temps)
    hi = max(float(T.max()) for _, T in temps)
    for x, T in temps:
        sc = axes[1].scatter(x[:, 0], x[:, 1], c=T - 300.0, s=7, cmap="inferno", vmin=lo - 300.0, vmax=hi - 300.0)
    axes[0].legend(fontsize=7, loc="upper left")
    axes[0].set_title("blocks of OUT.xdmf (one per rank file)", fontsize=9)
    axes[1].set_title("temperature rise over all blocks", fontsize=9)
    fig.colorbar(sc, ax=axes.tolist(), shrink=0.5, anchor=(0.0, 0.1), label="T - 300 K (K)")
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_ylabel("y (mm)")
    axes[1].set_xlabel("x (mm)")
    fig.suptitle(f"2D heated sliding block, mpirun -n 3, t = {1e3 * t:.3g} ms, read by vtkXdmf3Reader", fontsize=10)
    fig.savefig(png, dpi=110)
    print("wrote", png)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("frictherm")
    ap.add_argument("scenes")
    ap.add_argument("work")
    ap.add_argument("--mpirun", default=shutil.which("mpirun"))
    ap.add_argument("--png")
    a = ap.parse_args()
    if not a.mpirun or not os.path.exists(a.mpirun):
        print("vtk_decomposed.py: mpirun is not installed (Debian: openmpi-bin)")
        return 77
    os.makedirs(a.work, exist_ok=True)
    runs = {name: check_scene(a, name, dim, sets, ranks) for name, dim, sets, ranks in CASES}
    if a.png:
        draw(runs["2D"][3], a.png)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed" + ("" if pv is not None else " (VTK's reader only: paraview.simple missing)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
