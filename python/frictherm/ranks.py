"""The particle snapshots of a decomposed run (`mpirun -n K frictherm run`): each rank writes its
particles to OUT.rank<r>.h5 (docs/distributed_run.md), OUT.h5 holds the series, hot spots and /meta
with ``ranks``. A snapshot group of the rank files, read as one: the particles of every rank, ordered
by ``id`` (particles migrate between ranks, so the rank order changes from snapshot to snapshot)."""
import os

import h5py
import numpy as np


def rank_file(path, rank):
    """OUT.rank<r>.h5 beside OUT.h5 (the C++ DecomposedOutput::rank_file naming)."""
    for ext in (".h5", ".hdf5", ".he5"):
        if path.endswith(ext) and len(path) > len(ext):
            return f"{path[:-len(ext)]}.rank{rank}.h5"
    return f"{path}.rank{rank}.h5"


def open_rank_files(path, ranks):
    """The K rank files, opened read-only; FileNotFoundError naming the first one missing."""
    files = []
    try:
        for r in range(ranks):
            name = rank_file(path, r)
            if not os.path.exists(name):
                raise FileNotFoundError(f"{path}: a decomposed run on {ranks} ranks; its snapshot file {name} "
                                        "is missing (keep OUT.rank<r>.h5 beside OUT.h5)")
            files.append(h5py.File(name, "r"))
    except BaseException:
        for f in files:
            f.close()
        raise
    return files


class JoinedArray:
    """One field over the ranks, as an h5py dataset reads: ``shape`` and ``[()]``."""

    def __init__(self, group, name):
        self._group, self._name = group, name

    @property
    def attrs(self):  # units, long_name: the same in every rank file
        return self._group.parts[0][self._name].attrs

    @property
    def shape(self):
        parts = [g[self._name].shape for g in self._group.parts]
        return (sum(p[0] for p in parts),) + tuple(parts[0][1:])

    def __getitem__(self, key):
        if self._name == "connectivity":  # the XDMF polyvertex indices of one file: 0..n-1 again
            data = np.arange(self.shape[0], dtype=self._group.parts[0][self._name].dtype)
        else:
            data = np.concatenate([np.asarray(g[self._name][()]) for g in self._group.parts])[self._group.order]
        return data if key == () else data[key]


class JoinedGroup:
    """The same snapshot group (e.g. snapshots/000003) of every rank file, read as one group."""

    def __init__(self, parts):
        self.parts = parts
        self.attrs = parts[0].attrs
        names = [k for k in parts[0].keys() if all(k in g for g in parts[1:])]
        self._names = names
        self._order = None

    @property
    def order(self):
        """The joined rows sorted by particle id, read on first use (listing snapshots reads no data)."""
        if self._order is None:
            if "id" in self._names:
                ids = np.concatenate([np.asarray(g["id"][()]) for g in self.parts])
                self._order = np.argsort(ids, kind="stable")
            else:
                self._order = slice(None)
        return self._order

    def keys(self):
        return list(self._names)

    def __iter__(self):
        return iter(self._names)

    def __contains__(self, name):
        return name in self._names

    def __getitem__(self, name):
        if name not in self._names:
            raise KeyError(name)
        return JoinedArray(self, name)


def joined_groups(files, where):
    """{name: JoinedGroup} of the groups under `where` ("snapshots") present in every rank file."""
    if not all(where in f for f in files):
        return {}
    names = [n for n in files[0][where].keys() if all(n in f[where] for f in files[1:])]
    return {n: JoinedGroup([f[where][n] for f in files]) for n in sorted(names)}
