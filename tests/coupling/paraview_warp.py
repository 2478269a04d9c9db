"""ParaView as users drive it (issue 33 item 3), headless: a 2D and a 3D frictherm run are opened in
ParaView's own Python (`pvpython`, paraview.simple) through RUN_reference.xdmf, the snapshots drawn at
their reference positions X, and warped by `displacement` with the *Warp By Vector* filter. Asserted for
every snapshot: the warped points' bounds equal the bounds of the HDF5 `position` rows (the current
positions x = X + u), to 1e-12 of the grid's extent (ParaView adds the same doubles as the writer
subtracted: only round-off may differ), and the runs moved (max |u| over a twentieth of a cell), so an
all-zero displacement cannot pass. The same warp on RUN.xdmf (drawn at x) lands elsewhere: checked too,
so a reference file that silently held x would fail.

    pvpython paraview_warp.py FRICTHERM_EXE WORK_DIR [--png SHOT.png]

--png also saves a screenshot of the warped 2D run (needs a display: run under `xvfb-run -a` on a
machine without one; docs/output.md "In ParaView"). Filters and bounds need no display. Exits 77
(ctest: skipped) when ParaView's Python (Debian python3-paraview) is not installed.
"""
import argparse
import json
import os
import subprocess
import sys

try:
    import h5py
    import numpy as np
    from paraview import simple as pv
except ImportError as e:  # pragma: no cover - depends on the machine
    print(f"paraview_warp.py: ParaView's Python is not available ({e}); install python3-paraview "
          "(scripts/install_deps.sh all)")
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from warp_scenes import SCENES  # noqa: E402 (the same runs as vtk_warp.py)


def bounds_of(source, time):
    source.UpdatePipeline(time)
    b = source.GetDataInformation().GetBounds()
    return np.array(b).reshape(3, 2)


def check(exe, work, dim, png):
    scene = SCENES[dim]
    path = os.path.join(work, f"warp_{dim}d.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    h5 = os.path.join(work, f"warp_{dim}d.h5")
    subprocess.run([exe, "run", path, "-o", h5, "--force", "--quiet"], check=True)
    reference = h5[:-3] + "_reference.xdmf"
    current = h5[:-3] + ".xdmf"
    failures = []
    extent = max(np.subtract(scene["grid"]["hi"], scene["grid"]["lo"]))
    tol = 1e-12 * extent
    ref = pv.OpenDataFile(os.path.abspath(reference))  # Xdmf3 resolves the HDF5 name against an absolute path
    warp = pv.WarpByVector(Input=ref, Vectors=["POINTS", "displacement"])
    cur = pv.OpenDataFile(os.path.abspath(current))
    warp_cur = pv.WarpByVector(Input=cur, Vectors=["POINTS", "displacement"])
    with h5py.File(h5, "r") as f:
        names = sorted(f["snapshots"])
        times = [float(f["snapshots"][n].attrs["time"]) for n in names]
        if list(ref.TimestepValues) != times:
            failures.append(f"{dim}D: reference file times {list(ref.TimestepValues)} != snapshots {times}")
        moved = 0.0
        for n, t in zip(names, times):
            x = f["snapshots"][n]["position"][()]
            u = f["snapshots"][n]["displacement"][()]
            moved = max(moved, float(np.abs(u).max()))
            expect = np.zeros((3, 2))
            expect[:dim, 0], expect[:dim, 1] = x.min(axis=0), x.max(axis=0)
            got = bounds_of(warp, t)
            err = float(np.abs(got - expect).max())
            print(f"{dim}D t={t:.3e}: warped bounds {got[:dim].ravel()} vs positions {expect[:dim].ravel()}: "
                  f"max difference {err:.2e} m")
            if err > tol:
                failures.append(f"{dim}D t={t}: warped bounds differ from the positions' by {err:.3e} m")
            u_bound = float(np.abs(u[:, :dim]).max())
            if u_bound > 0.05 * scene["grid"]["cell_size"]:
                off = float(np.abs(bounds_of(warp_cur, t) - expect).max())
                if off < 0.5 * u_bound:  # warping x again moves it by u: the old (wrong) picture
                    failures.append(f"{dim}D t={t}: warping RUN.xdmf lands on the positions too ({off:.2e} m)")
        if moved < 0.05 * scene["grid"]["cell_size"]:
            failures.append(f"{dim}D: the run hardly moved (max |u| = {moved:.2e} m)")
    if png and dim == 2:
        view = pv.GetActiveViewOrCreate("RenderView")
        display = pv.Show(warp, view)
        display.SetRepresentationType("Points")
        display.PointSize = 6
        pv.ColorBy(display, ("POINTS", "velocity", "Magnitude"))
        display.RescaleTransferFunctionToDataRange(True, False)
        view.ViewTime = times[-1]
        view.ViewSize = [800, 600]
        pv.ResetCamera(view)
        pv.SaveScreenshot(png, view, ImageResolution=[800, 600])
        print(f"wrote {png}")
    for s in (warp_cur, cur, warp, ref):
        pv.Delete(s)
    return failures


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("exe")
    parser.add_argument("work")
    parser.add_argument("--png")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    failures = check(args.exe, args.work, 2, args.png) + check(args.exe, args.work, 3, None)
    for f in failures:
        print("FAIL:", f)
    sys.stdout.flush()
    # os._exit: under xvfb-run, ParaView's render window teardown at interpreter exit raises an X
    # error (GLXBadContext) after the screenshot is written; the checks are done by then.
    os._exit(1 if failures else 0)


if __name__ == "__main__":
    main()
