"""A whole run as an xarray.Dataset (Debian python3-xarray): Run.to_xarray()."""
import numpy as np

AXES = ("x", "y", "z")


def run_to_xarray(run, snapshots=True):
    """The series on the dimension ``time``; with ``snapshots`` every regular snapshot's fields on
    (``snapshot``, ``particle``[, ``axis``[, ``axis2``]]), with the coordinates ``snapshot_time`` and
    ``snapshot_step``. Every variable carries ``units`` and ``long_name`` attributes; the /meta
    numbers and strings become the Dataset's attributes. Snapshot fields are included only when
    every snapshot has the same particles (a serial run); a field named like a series column is
    prefixed with ``particle_``."""
    try:
        import xarray as xr
    except ImportError as e:
        raise ImportError("Run.to_xarray needs xarray (Debian package python3-xarray)") from e
    s = run.series
    data_vars, coords = {}, {}
    if s:
        coords["time"] = ("time", s["time"], {"units": s.unit_of("time"), "long_name": "time"})
        for c in s.columns:
            if c == "time":
                continue
            data_vars[c] = (("time",), s[c], {"units": s.unit_of(c), "long_name": s.long_names.get(c, c)})
    snaps = run.snapshots if snapshots else []
    if snaps and len({sn.particle_count for sn in snaps}) == 1:
        d = run.dim
        coords["snapshot_time"] = ("snapshot", run.snapshot_times, {"units": "s", "long_name": "snapshot time"})
        coords["snapshot_step"] = ("snapshot", np.array([sn.step for sn in snaps]), {"units": "1"})
        coords["axis"] = ("axis", list(AXES[:d]))
        coords["axis2"] = ("axis2", list(AXES[:d]))
        first = snaps[0]
        for name in first.fields:
            stack = np.stack([sn[name] for sn in snaps])
            dims = ("snapshot", "particle", "axis", "axis2")[:stack.ndim]
            if stack.ndim >= 3 and stack.shape[2] != d:
                dims = ("snapshot", "particle", name + "_component")
            var = name if name not in data_vars and name not in coords else "particle_" + name
            data_vars[var] = (dims, stack, {"units": first.unit_of(name), "long_name": first.long_name(name)})
    attrs = {k: v for k, v in run.meta.items() if isinstance(v, (int, float, str)) and k not in ("scene", "scene_json")}
    attrs.update(dim=run.dim, format_version=run.format_version)
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)
