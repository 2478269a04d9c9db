"""An ensemble file written by `frictherm ensemble` (coupling/include/frictherm/coupling/ensemble.hpp)."""
import math
import os

import numpy as np

from ._h5 import plain, text
from .table import Table


class Ensemble:
    """The aggregate of an ensemble: ``members`` and ``hotspots`` (Table), ``summary`` (the root
    attributes: members, completed, hotspots_total, hotspots_per_member_mean/std, critical_fraction
    (None when no hot spot had a decided fate), members_with_runaway, seed_key, scene),
    ``member_files`` and ``member(seed)`` (the member's Run)."""

    def __init__(self, h5file, path):
        self.file = h5file
        self.path = path
        self.summary = {k: plain(v) for k, v in h5file.attrs.items() if k not in ("format", "format_version")}
        cf = self.summary.get("critical_fraction")
        if isinstance(cf, float) and math.isnan(cf):
            self.summary["critical_fraction"] = None  # undefined: no hot spot with a known fate
        self.format_version = int(h5file.attrs["format_version"]) if "format_version" in h5file.attrs else 1
        self.members = Table.read(h5file, "members")
        self.hotspots = Table.read(h5file, "hotspots")

    @property
    def critical_fraction(self):
        return self.summary.get("critical_fraction")

    @property
    def member_files(self):
        """The member HDF5 files in /members row order (format version 2; older files: from the seeds)."""
        if "member_files" in self.file:
            return [text(v) for v in np.asarray(self.file["member_files"][()])]
        prefix = os.path.splitext(self.path)[0] + "_seed"
        return [f"{prefix}{int(s)}.h5" for s in self.members["seed"]]

    def member(self, seed):
        """The run of the member with this seed (a frictherm Run; close it after use)."""
        from . import open as open_file
        seeds = list(int(s) for s in self.members["seed"])
        if int(seed) not in seeds:
            raise KeyError(f"{self.path}: no member with seed {seed}; seeds {seeds}")
        path = self.member_files[seeds.index(int(seed))]
        if not os.path.isabs(path) and not os.path.exists(path):
            path = os.path.join(os.path.dirname(os.path.abspath(self.path)), os.path.basename(path))
        return open_file(path)

    def close(self):
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        return f"Ensemble('{self.path}', {len(self.members)} members, {len(self.hotspots)} hot spots)"
