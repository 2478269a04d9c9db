#!/usr/bin/python3
"""Draw a frictherm run (the HDF5 file written by `frictherm run`) as PNG charts.

  plot_run.py RUN.h5 [--field NAME] [--snapshot INDEX|last|failure] [--series COL ...] [-o PREFIX]
  plot_run.py RUN.h5 --list

Writes PREFIX_particles.png (particles as squares sized to their spacing, coloured by a field)
and PREFIX_series.png (series against /series/time, grouped by unit into a few panels: energies,
temperatures, heat rates, lengths, ...; lines named by their long_name, axes in units with SI
prefixes where they read better: ms, ns, µm, mJ). PREFIX defaults to RUN without .h5.

Fields: any stored snapshot field (temperature, mass, material, ...), one component of a stored
field (velocity_x, position_z, stress_xy, or velocity_0 ...), or a derived one:
  speed                   |velocity|
  displacement_magnitude  |displacement| (or |position - initial_position|)
  von_mises               sqrt(3/2 s:s) of the Cauchy stress
  pressure                -trace(stress)/3
In 2D the out-of-plane stress comes from the field stress_zz when stored (plane strain), else 0
(plane stress). 3D runs are drawn projected on the x-y plane, highest z on top, and as three slices
normal to z in PREFIX_slices.png.

Reads the run through the frictherm Python package (python/frictherm; draws with frictherm.plot).
Uses the Debian packages python3-h5py, python3-matplotlib and python3-numpy; runs headless.
"""
import argparse
import os
import sys

import frictherm
from frictherm.fields import field_values
from frictherm.plot import plot_particles, plot_series, plot_slices


def list_run(run):
    print(f"{run.path}: {run.dim}D, format {run.format} version {run.format_version}, status {run.status}")
    print("metadata:")
    for key, value in run.meta.items():
        shown = str(value).replace("\n", " ")
        print(f"  {key}: {shown[:70] + ('...' if len(shown) > 70 else '')}")
    snaps = run.snapshots + ([run.failure] if run.failure else [])
    print(f"snapshots: {len(run.snapshots)}")
    for s in snaps:
        fields = ", ".join(f"{k}{list(s.raw(k).shape[1:]) if s.raw(k).ndim > 1 else ''}" for k in s.fields)
        extra = f"  message: {s.message}" if s.message else ""
        shown = "failure" if s.is_failure else str(s.index)
        print(f"  [{shown}] {s.label} step {s.step} t = {s.time:.6g} s, {s.particle_count} particles: {fields}{extra}")
    print(f"series ({len(run.series)} rows): {', '.join(run.series.columns) or 'none'}")
    for name in ("hotspots", "hotspot_fates"):
        t = run.table(name)
        if t.columns:
            print(f"{name} ({len(t)} rows): {', '.join(t.columns)}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("run", help="HDF5 file of a run")
    p.add_argument("--field", default="temperature", help="colour particles by this field (default temperature, "
                   "or speed when there is no temperature)")
    p.add_argument("--snapshot", default="last", help="snapshot index, 'last' (default) or 'failure'")
    p.add_argument("--series", nargs="+", metavar="COL", help="series columns to plot (default: all but time)")
    p.add_argument("-o", "--output", metavar="PREFIX", help="output prefix (default: RUN without .h5)")
    p.add_argument("--list", action="store_true", help="print snapshots, fields, series and metadata, then exit")
    args = p.parse_args(argv)

    try:
        run = frictherm.open(args.run)
    except (OSError, ValueError) as e:
        raise SystemExit(f"plot_run.py: cannot open {args.run}: {e}")
    with run:
        if args.list:
            list_run(run)
            return 0
        prefix = args.output or os.path.splitext(args.run)[0]
        wrote = []
        if run.snapshots or run.failure:
            try:
                snap = run.snapshot(args.snapshot if run.snapshots or args.snapshot != "last" else "failure")
            except KeyError as e:
                raise SystemExit(f"plot_run.py: {e.args[0]}")
            field = args.field
            if field == "temperature" and "temperature" not in snap:
                field = "speed" if "velocity" in snap else "position_x"
            try:
                field_values(snap, field)
            except KeyError as e:
                raise SystemExit(f"plot_run.py: {e.args[0]}")
            plot_particles(run, snap, field, prefix + "_particles.png")
            wrote.append(prefix + "_particles.png")
            if run.dim == 3:  # the projection hides the inside: three slices normal to z as well
                plot_slices(run, snap, field, prefix + "_slices.png")
                wrote.append(prefix + "_slices.png")
        else:
            print("plot_run.py: no snapshots in this run; no particle picture", file=sys.stderr)
        columns = run.series.columns
        if columns and len(run.series) > 0:
            chosen = args.series or [c for c in columns if c != "time"]
            missing = [c for c in chosen if c not in columns]
            if missing:
                raise SystemExit(f"plot_run.py: no series {', '.join(missing)}; available: {', '.join(columns)}")
            if chosen:
                plot_series(run, chosen, prefix + "_series.png")
                wrote.append(prefix + "_series.png")
        else:
            print("plot_run.py: no series in this run; no series chart", file=sys.stderr)
    for path in wrote:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
