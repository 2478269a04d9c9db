"""The thermal grid's nodal temperature in ParaView (issue 33 item 3), headless: a short run of the heated
sliding block (examples/sliding_block_heating.json, 7 ms: the block is sliding and its contact heats) is
opened in ParaView's own Python (`pvpython`, paraview.simple) through RUN_nodes.xdmf, which draws
/nodes/NNNNNN (the thermal grid's nodes). Asserted at every snapshot time:

* the reader offers the snapshot times, and the grid has as many points as the file's /nodes/NNNNNN
  rows;
* its `temperature` and `heat_capacity` arrays equal the HDF5 datasets exactly (both are the file's
  doubles, nothing is computed: any difference is a wrong dataset, grid or time);
* its points are the grid nodes named by `lattice` (lo + lattice * cell size, to 1e-12 of the grid's
  extent: the writer multiplies the same doubles), z = 0 in 2D;
* the temperature varies over the nodes at the last time (max - min > 1e-3 K: the sliding heated the
  contact), so a constant field cannot pass.

    pvpython paraview_nodes.py FRICTHERM_EXE SOURCE_DIR WORK_DIR

Exits 77 (ctest: skipped) when ParaView's Python (Debian python3-paraview) is not installed.
"""
import os
import subprocess
import sys

try:
    import h5py
    import numpy as np
    from paraview import servermanager
    from paraview import simple as pv
    from vtkmodules.util.numpy_support import vtk_to_numpy
except ImportError as e:  # pragma: no cover - depends on the machine
    print(f"paraview_nodes.py: ParaView's Python is not available ({e}); install python3-paraview "
          "(scripts/install_deps.sh all)")
    sys.exit(77)


def leaf(data):
    """The one point set of what the reader gives (a multiblock of a multipiece of one grid)."""
    while data is not None and data.IsA("vtkCompositeDataSet"):
        if data.IsA("vtkMultiPieceDataSet"):
            data = data.GetPiece(0)
        else:
            data = data.GetBlock(0)
    return data


def main():
    exe, source, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    h5 = os.path.join(work, "heated.h5")
    subprocess.run([exe, "run", os.path.join(source, "examples", "sliding_block_heating.json"), "-o", h5, "--force",
                    "--quiet", "--threads", "1", "--set", "run.end_time=0.007", "--set", "output.snapshot_count=3",
                    "--set", "coupling.continuation=null"], check=True)
    failures = []
    reader = pv.OpenDataFile(os.path.abspath(h5[:-3] + "_nodes.xdmf"))
    with h5py.File(h5, "r") as f:
        dim = int(f.attrs["dim"])
        lo = np.asarray(f["meta"]["grid_lo"][()], dtype=float)
        h = np.asarray(f["meta"]["grid_cell_size"][()], dtype=float)
        cells = np.asarray(f["meta"]["grid_cells"][()], dtype=np.int64)
        extent = float(np.max(h * cells))
        names = sorted(f["nodes"])
        times = [float(f["nodes"][n].attrs["time"]) for n in names]
        if names != sorted(f["snapshots"]):
            failures.append(f"/nodes {names} does not follow /snapshots {sorted(f['snapshots'])}")
        if list(reader.TimestepValues) != times:
            failures.append(f"reader times {list(reader.TimestepValues)} != /nodes times {times}")
        spread = 0.0
        for n, t in zip(names, times):
            g = f["nodes"][n]
            reader.UpdatePipeline(t)
            block = leaf(servermanager.Fetch(reader))
            if block is None:
                failures.append(f"t={t}: RUN_nodes.xdmf gives no data set")
                continue
            rows = g["temperature"].shape[0]
            if block.GetNumberOfPoints() != rows:
                failures.append(f"t={t}: {block.GetNumberOfPoints()} points in ParaView, {rows} rows in /nodes/{n}")
                continue
            for name in ("temperature", "heat_capacity"):
                got = vtk_to_numpy(block.GetPointData().GetArray(name))
                if not np.array_equal(got, g[name][()]):
                    failures.append(f"t={t}: {name} differs from /nodes/{n}/{name} "
                                    f"(max {np.max(np.abs(got - g[name][()])):.3e})")
            points = vtk_to_numpy(block.GetPoints().GetData())
            expect = lo + g["lattice"][()].astype(float) * h
            err = float(np.max(np.abs(points[:, :dim] - expect))) if rows else 0.0
            if err > 1e-12 * extent or (dim == 2 and np.any(points[:, 2] != 0.0)):
                failures.append(f"t={t}: node points differ from the grid nodes by {err:.3e} m")
            temperature = g["temperature"][()]
            spread = float(temperature.max() - temperature.min())
            print(f"t={t:.4e}: {rows} nodes, T {temperature.min():.4f} .. {temperature.max():.4f} K, "
                  f"points vs grid {err:.1e} m")
        if spread < 1e-3:
            failures.append(f"the nodal temperature hardly varies at the last time ({spread:.3e} K)")
    pv.Delete(reader)
    for msg in failures:
        print("FAIL:", msg)
    sys.stdout.flush()
    os._exit(1 if failures else 0)


if __name__ == "__main__":
    main()
