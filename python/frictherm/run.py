"""A run file written by `frictherm run` (coupling/include/frictherm/coupling/h5_output.hpp)."""
import numpy as np

from ._h5 import plain, text
from .ranks import JoinedGroup, joined_groups, open_rank_files
from .snapshot import Snapshot
from .table import Table

# /meta keys that make up the energy books of a coupled run (docs/coupling.md).
ENERGY_BOOK_KEYS = ("work_received", "heat_delivered", "plastic_work_received", "plastic_heat_received",
                    "plastic_heat_delivered", "reaction_heat_released", "particle_reaction_heat", "heat_relocated",
                    "heat_pending", "nodal_energy_change", "particle_energy_change", "max_assembly_residual")
SUPPORTED_FORMAT_VERSION = 2


class Run:
    """The results of one run. Open with ``frictherm.open(path)``; use as a context manager or
    call ``close()``.

    ``dim``, ``format_version``, ``meta`` (dict: str, int or float), ``status``, ``series``,
    ``hotspots``, ``hotspot_fates`` (Table), ``energy_books`` (dict), ``snapshots`` (list of
    Snapshot), ``snapshot_times`` (array), ``failure`` (Snapshot or None), ``snapshot(i)``,
    ``snapshot_at(time)``. A decomposed run's snapshots are read from its rank files
    (OUT.rank<r>.h5, frictherm/ranks.py), joined and ordered by particle id.
    """

    def __init__(self, h5file, path):
        self.file = h5file
        self.path = path
        a = h5file.attrs
        self.format = text(a["format"]) if "format" in a else "frictherm-output"
        self.format_version = int(a["format_version"]) if "format_version" in a else 1
        if self.format_version > SUPPORTED_FORMAT_VERSION:
            raise ValueError(f"{path}: format version {self.format_version} is newer than this reader "
                             f"({SUPPORTED_FORMAT_VERSION}); update the frictherm Python package")
        self._meta = None
        self._series = None
        self._tables = {}
        self._snapshots = None
        self._rank_files = None  # a decomposed run's OUT.rank<r>.h5, opened on first use
        if "dim" in a:
            self.dim = int(a["dim"])
        elif "meta" in h5file and "dimension" in h5file["meta"]:
            self.dim = int(h5file["meta"]["dimension"][()])
        else:
            first = self.snapshots[0] if self.snapshots else None
            self.dim = int(first.raw("position").shape[1]) if first is not None and "position" in first else 2

    # ---- life time ----
    def close(self):
        for f in self._rank_files or []:
            f.close()
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        return (f"Run('{self.path}', {self.dim}D, status {self.status}, {len(self.snapshots)} snapshots, "
                f"{len(self.series)} series rows)")

    # ---- metadata ----
    @property
    def meta(self):
        """/meta decoded: strings as str, counts as int, the rest as float."""
        if self._meta is None:
            m = self.file["meta"] if "meta" in self.file else {}
            self._meta = {k: plain(m[k][()]) for k in m}
        return self._meta

    @property
    def status(self):
        """completed, stopped_at_max_steps, failed, interrupted, or running (a run still going or killed)."""
        return self.meta.get("status", "unknown")

    @property
    def energy_books(self):
        """The coupled run's energy books from /meta (J, or J per m of thickness in 2D); empty for a
        mechanics-only run. heat_delivered equals particle_energy_change when the books close."""
        return {k: self.meta[k] for k in ENERGY_BOOK_KEYS if k in self.meta}

    @property
    def scene_json(self):
        """The scene as run (overrides applied) as plain JSON text: ``json.loads`` reads it. Files
        written before /meta/scene_json give the scene file's text (which may hold comments)."""
        return self.meta.get("scene_json", self.meta.get("scene", ""))

    @property
    def scene(self):
        """The scene as run, as a dict (from /meta/scene_json)."""
        import json
        return json.loads(self.scene_json)

    @property
    def grid(self):
        """{"lo", "hi", "cells", "cell_size"} as arrays (m; cells: counts), from /meta/grid_* or, in
        older files, the text /meta/grid."""
        m = self.meta
        if "grid_lo" in m:
            return {k: np.asarray(m["grid_" + k]) for k in ("lo", "hi", "cells", "cell_size")}
        parts = dict(p.strip().split(" ", 1) for p in m.get("grid", "").split(";") if p.strip())
        return {k: np.array(parts[k].split(), dtype=np.int64 if k == "cells" else float) for k in parts}

    @property
    def materials(self):
        """Material names by id (/meta/material_names, or the older text /meta/materials)."""
        if "material_names" in self.meta:
            return list(self.meta["material_names"])
        return [p.split()[1] for p in self.meta.get("materials", "").split(";") if len(p.split()) >= 2]

    def unit_of(self, name):
        """The units of a series column, snapshot field or /meta entry ("" when unknown): the
        file's `units` attribute, or for files written before them the known SI units."""
        if name in self.series.units:
            return self.series.units[name]
        if self.snapshots and name in self.snapshots[0]:
            return self.snapshots[0].unit_of(name)
        if "meta" in self.file and name in self.file["meta"] and "units" in self.file["meta"][name].attrs:
            return text(self.file["meta"][name].attrs["units"])
        from .fields import unit_of
        return unit_of(name)

    def to_xarray(self, snapshots=True):
        """The run as an xarray.Dataset: series on ``time``, snapshot fields on (``snapshot``,
        ``particle``, ...) with units (frictherm/xr.py)."""
        from .xr import run_to_xarray
        return run_to_xarray(self, snapshots)

    # ---- tables ----
    @property
    def series(self):
        if self._series is None:
            self._series = Table.read(self.file, "series")
        return self._series

    def table(self, name):
        """Any column group of the file (/hotspots, /hotspot_fates, ...); empty when absent."""
        if name not in self._tables:
            self._tables[name] = Table.read(self.file, name)
        return self._tables[name]

    @property
    def hotspots(self):
        """/hotspots: one row per hot spot per coupling window (time, id, particle_count, peak and mean
        temperature, size, equivalent_diameter, centroid_*, birth_time, duration, excess_energy,
        material_mask)."""
        return self.table("hotspots")

    @property
    def hotspot_fates(self):
        """/hotspot_fates of the thermal-only continuation (fate 0 undecided, 1 dying, 2 runaway;
        ``hotspot_fates.names_of("fate")`` gives the names, the DataFrame has them in ``fate_name``)."""
        return self.table("hotspot_fates")

    # ---- snapshots ----
    @property
    def ranks(self):
        """How many ranks wrote the run (1: a serial run, its snapshots in this file)."""
        return int(self.meta.get("ranks", 1))

    def _decomposed_files(self):
        if self._rank_files is None:
            self._rank_files = open_rank_files(self.path, self.ranks)
        return self._rank_files

    @property
    def snapshots(self):
        """The ended regular snapshots in time order (the failure state is ``failure``)."""
        if self._snapshots is None:
            if self.ranks > 1:
                groups = joined_groups(self._decomposed_files(), "snapshots")
            else:
                g = self.file["snapshots"] if "snapshots" in self.file else {}
                groups = {n: g[n] for n in sorted(g.keys())} if g else {}
            self._snapshots = [Snapshot(self, grp, n, i) for i, (n, grp) in enumerate(groups.items())]
        return self._snapshots

    @property
    def snapshot_times(self):
        return np.array([s.time for s in self.snapshots], dtype=float)

    @property
    def failure(self):
        if self.ranks > 1:
            files = self._decomposed_files()
            if all("failure" in f for f in files):
                return Snapshot(self, JoinedGroup([f["failure"] for f in files]), "failure", None)
            return None
        return Snapshot(self, self.file["failure"], "failure", None) if "failure" in self.file else None

    def snapshot(self, which="last"):
        """A snapshot by index (negative counts from the end), "last" or "failure"."""
        if which == "failure":
            if self.failure is None:
                raise KeyError(f"{self.path}: this run has no failure snapshot")
            return self.failure
        if not self.snapshots:
            raise KeyError(f"{self.path}: this run has no snapshots")
        if which == "last":
            return self.snapshots[-1]
        try:
            return self.snapshots[int(which)]
        except (ValueError, IndexError):
            raise KeyError(f"{self.path}: no snapshot '{which}' ({len(self.snapshots)} snapshots; use an index, "
                           "'last' or 'failure')") from None

    def snapshot_at(self, time):
        """The regular snapshot whose time is nearest `time` (s)."""
        if not self.snapshots:
            raise KeyError(f"{self.path}: this run has no snapshots")
        return self.snapshots[int(np.argmin(np.abs(self.snapshot_times - time)))]
