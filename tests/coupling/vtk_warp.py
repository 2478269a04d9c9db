#!/usr/bin/python3
"""ParaView-correct output (issue 14, item 1): a 2D and a 3D frictherm run are opened through their
XDMF files with ParaView's VTK (vtkXdmf3Reader, Debian python3-paraview), warped with vtkWarpVector on
`displacement` and passed through a vtkArrayCalculator on `velocity`. Asserted, for every snapshot:

* the reader sees `displacement` and `velocity` as 3-component vectors and `stress` as a 9-component
  tensor (with 2 components vtkWarpVector aborts the program: the bug this guards against);
* the reader's points are the HDF5 `position` rows (z = 0 in 2D), to round-off;
* the warped points are x + u from the HDF5 arrays and the calculator's mag(velocity) is |v|, to
  1e-12 of the largest coordinate / speed (both paths add and square the same doubles; only the
  order of operations may differ);
* in 2D the padded z columns are exactly 0 and stress entry 8 (zz) is `stress_zz`;
* the runs moved: max |u| is more than a cell size / 20, so an all-zero field cannot pass.

    vtk_warp.py FRICTHERM_EXE WORK_DIR [--png docs/figures/warp_2d.png]

--png also draws the 2D run's last snapshot (reference X = warp by -1 and current x = the reader's
points, coloured by the calculator's speed) with matplotlib from the VTK filters' output. Exits 77 (ctest: skipped) when
VTK's XDMF reader is not installed.
"""
import argparse
import json
import os
import subprocess
import sys

import h5py
import numpy as np

try:
    from vtkmodules.vtkCommonDataModel import vtkDataObject, vtkDataSet
    from vtkmodules.vtkFiltersCore import vtkArrayCalculator
    from vtkmodules.vtkFiltersGeneral import vtkWarpVector
    from vtkmodules.vtkIOXdmf3 import vtkXdmf3Reader
    from vtkmodules.util.numpy_support import vtk_to_numpy
except ImportError as e:  # pragma: no cover - depends on the machine
    print(f"vtk_warp.py: VTK's XDMF reader is not available ({e}); install python3-paraview "
          "(scripts/install_deps.sh)")
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from warp_scenes import SCENES  # noqa: E402

failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def run(exe, work, dim):
    scene = os.path.join(work, f"warp_{dim}d.json")
    h5 = os.path.join(work, f"warp_{dim}d.h5")
    with open(scene, "w") as f:
        json.dump(SCENES[dim], f)
    # --force: a rerun in the same build folder replaces the previous result (refused by default)
    subprocess.run([exe, "run", scene, "-o", h5, "--force"], check=True, stdout=subprocess.DEVNULL)
    return h5


def read_step(reader, time):
    reader.UpdateTimeStep(time)
    out = reader.GetOutputDataObject(0)
    if not isinstance(out, vtkDataSet):  # a multiblock when the reader wraps the grid
        it = out.NewIterator()
        it.InitTraversal()
        out = it.GetCurrentDataObject()
    return out


def warped(dataset, scale):
    warp = vtkWarpVector()
    warp.SetInputData(dataset)
    warp.SetInputArrayToProcess(0, 0, 0, vtkDataObject.FIELD_ASSOCIATION_POINTS, "displacement")
    warp.SetScaleFactor(scale)
    warp.Update()
    return vtk_to_numpy(warp.GetOutput().GetPoints().GetData())


def speed(dataset):
    calc = vtkArrayCalculator()
    calc.SetInputData(dataset)
    calc.SetAttributeTypeToPointData()
    calc.AddVectorArrayName("velocity")
    calc.SetFunction("mag(velocity)")
    calc.SetResultArrayName("speed")
    calc.Update()
    return vtk_to_numpy(calc.GetOutput().GetPointData().GetArray("speed"))


def check_run(h5_path, dim):
    xdmf = h5_path[:-3] + ".xdmf"
    reader = vtkXdmf3Reader()
    reader.SetFileName(xdmf)
    reader.UpdateInformation()
    with h5py.File(h5_path, "r") as f:
        check(int(f.attrs["format_version"]) == 2, f"{dim}D: format_version 2")
        snaps = [f["snapshots"][k] for k in sorted(f["snapshots"])]
        check(len(snaps) >= 2, f"{dim}D: at least two snapshots")
        h = float(f["meta"]["cell_size"][()])
        largest_u = 0.0
        for g in snaps:
            t = float(g.attrs["time"])
            x = np.zeros((g["position"].shape[0], 3))
            x[:, :dim] = g["position"][()]
            u, v, s = g["displacement"][()], g["velocity"][()], g["stress"][()]
            n = len(x)
            tag = f"{dim}D t = {t:.3g}"
            check(u.shape == (n, 3) and v.shape == (n, 3) and s.shape == (n, 9), f"{tag}: HDF5 shapes {u.shape} {v.shape} {s.shape}")
            if dim == 2:
                check(np.all(u[:, 2] == 0) and np.all(v[:, 2] == 0), f"{tag}: z padding is 0")
                check(np.all(s[:, [2, 5, 6, 7]] == 0), f"{tag}: stress xz, yz, zx, zy are 0")
                check(np.array_equal(s[:, 8], g["stress_zz"][()]), f"{tag}: stress entry 8 is stress_zz")
            data = read_step(reader, t)
            pd = data.GetPointData()
            check(data.GetNumberOfPoints() == n, f"{tag}: {data.GetNumberOfPoints()} VTK points, {n} particles")
            for name, comps in (("displacement", 3), ("velocity", 3), ("stress", 9)):
                arr = pd.GetArray(name)
                check(arr is not None and arr.GetNumberOfComponents() == comps, f"{tag}: VTK {name} has {comps} components")
            check(pd.GetVectors() is not None or pd.GetArray("displacement") is not None, f"{tag}: vectors")
            points = vtk_to_numpy(data.GetPoints().GetData())
            scale = np.max(np.abs(x)) + np.max(np.abs(u))
            check(np.max(np.abs(points - x)) <= 1e-12 * scale, f"{tag}: VTK points are the HDF5 positions")
            w = warped(data, 1.0)
            err = np.max(np.abs(w - (x + u)))
            check(err <= 1e-12 * scale, f"{tag}: warped points = x + u (max error {err:.3g} m)")
            sp = speed(data)
            vmax = max(np.max(np.abs(v)), 1e-300)
            err_v = np.max(np.abs(sp - np.linalg.norm(v, axis=1)))
            check(err_v <= 1e-12 * vmax, f"{tag}: mag(velocity) = |v| (max error {err_v:.3g} m/s)")
            largest_u = max(largest_u, float(np.max(np.linalg.norm(u, axis=1))))
        check(largest_u > h / 20, f"{dim}D: the run moved (max |u| = {largest_u:.3g} m, cell {h:.3g} m)")
        print(f"{dim}D: {len(snaps)} snapshots, {n} particles, max |u| = {largest_u:.4g} m checked through VTK")
        return reader, float(snaps[-1].attrs["time"])


def draw(reader, time, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = read_step(reader, time)
    x = vtk_to_numpy(data.GetPoints().GetData())
    X = warped(data, -1.0)   # x - u: the reference configuration
    sp = speed(data)
    fig, axes = plt.subplots(1, 2, figsize=(8.5, 4.2))
    for ax, pts, title in ((axes[0], X, "reference X = x - u (vtkWarpVector, scale -1)"),
                           (axes[1], x, "current x (XDMF geometry)")):
        sc = ax.scatter(1e3 * pts[:, 0], 1e3 * pts[:, 1], c=sp, s=6, cmap="viridis", vmin=0, vmax=float(np.max(sp)))
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.axhline(0, color="k", lw=1)
        ax.set_ylim(-1, 32)
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=axes, shrink=0.8, label="mag(velocity) (m/s), vtkArrayCalculator")
    fig.suptitle(f"2D disk thrown at a fixed floor, t = {1e3 * time:.2f} ms: RUN.xdmf read by vtkXdmf3Reader",
                 fontsize=10)
    fig.savefig(png, dpi=110)
    print("wrote", png)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("frictherm")
    ap.add_argument("work")
    ap.add_argument("--png")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    last = {}
    for dim in (2, 3):
        last[dim] = check_run(run(a.frictherm, a.work, dim), dim)
    if a.png:
        draw(*last[2], a.png)
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
