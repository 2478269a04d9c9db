"""Particle snapshots of a run: /snapshots/NNNNNN and /failure."""
import numpy as np

from ._h5 import text

AXES = "xyz"


def physical_shape(data, dim):
    """A stored per-particle array in its physical shape: (n,) scalars, (n, dim) vectors,
    (n, dim, dim) tensors. Vectors of a 2D run may be stored with 2 components or padded to 3
    (z = 0, for VTK); tensors with dim*dim, 9 (3x3 padded) or 6 symmetric components (XDMF
    Tensor6 order xx, xy, xz, yy, yz, zz). Other shapes are returned as stored."""
    if data.ndim == 1:
        return data
    n, c = data.shape[0], data.shape[1]
    if c == dim:
        return data
    if dim == 2 and c == 3:
        return data[:, :2]
    if c == dim * dim:
        return data.reshape(n, dim, dim)
    if c == 9:
        return data.reshape(n, 3, 3)[:, :dim, :dim]
    if c == 6:
        full = np.empty((n, 3, 3), dtype=data.dtype)
        for k, (i, j) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
            full[:, i, j] = full[:, j, i] = data[:, k]
        return full[:, :dim, :dim]
    return data


class Snapshot:
    """One stored particle state: ``step``, ``time`` (s), ``fields`` (names), ``snap["temperature"]``.

    ``snap[name]`` gives the field in its physical shape (see physical_shape); ``snap.raw(name)``
    the array as stored. ``label`` is the group name ("000003", or "failure" for the state a failed
    run stopped in, which also has ``message``).
    """

    def __init__(self, run, group, label, index):
        self._run = run
        self._group = group
        self.label = label
        self.index = index  # position among the regular snapshots; None for the failure state
        self.step = int(group.attrs.get("step", -1))
        self.time = float(group.attrs.get("time", float("nan")))
        self.message = text(group.attrs["message"]) if "message" in group.attrs else None

    @property
    def is_failure(self):
        return self.label == "failure"

    @property
    def fields(self):
        return list(self._group.keys())

    @property
    def particle_count(self):
        for name in self._group:
            return int(self._group[name].shape[0])
        return 0

    def __contains__(self, name):
        return name in self._group

    def raw(self, name):
        if name not in self._group:
            raise KeyError(f"snapshot {self.label} has no field '{name}'; fields: {', '.join(self.fields)}")
        return np.asarray(self._group[name][()])

    def __getitem__(self, name):
        return physical_shape(self.raw(name), self._run.dim)

    def unit_of(self, name):
        """The units of a stored field (its `units` attribute; for older files the known SI units)."""
        if name in self._group and "units" in self._group[name].attrs:
            return text(self._group[name].attrs["units"])
        from .fields import unit_of
        return unit_of(name)

    def long_name(self, name):
        if name in self._group and "long_name" in self._group[name].attrs:
            return text(self._group[name].attrs["long_name"])
        return name.replace("_", " ")

    def columns(self):
        """{column name: (n,) array}: scalars by their name, vector components as name_x, name_y
        (name_z in 3D), tensor components as name_xx, name_xy, ... in the run's dimension."""
        out = {}
        for name in self.fields:
            data = self[name]
            if data.ndim == 1:
                out[name] = data
            elif data.ndim == 2:
                for i in range(data.shape[1]):
                    out[f"{name}_{AXES[i] if data.shape[1] <= 3 else i}"] = data[:, i]
            else:
                for i in range(data.shape[1]):
                    for j in range(data.shape[2]):
                        out[f"{name}_{AXES[i]}{AXES[j]}"] = data[:, i, j]
        return out

    def to_dataframe(self):
        """The particles as a pandas DataFrame, one row per particle (columns as ``columns()``);
        ``df.attrs["units"]`` gives each column's units, ``df.attrs["time"]`` and ``["step"]`` the
        snapshot's."""
        import pandas as pd
        cols = self.columns()
        df = pd.DataFrame(cols)
        df.index.name = "particle"
        units = {}
        for c in cols:
            base = c if c in self else c.rpartition("_")[0]
            units[c] = self.unit_of(base)
        df.attrs.update(units=units, time=self.time, step=self.step)
        return df

    def _node_group(self):
        """/nodes/<label> of the file, or of a decomposed run's rank files joined (each rank holds the
        nodes it owns, each node once: frictherm/ranks.py); None when there is none."""
        if self.index is None:
            return None
        if self._run.ranks > 1:
            from .ranks import joined_groups
            return joined_groups(self._run._decomposed_files(), "nodes").get(self.label)
        f = self._group.file
        return f["nodes"][self.label] if "nodes" in f and self.label in f["nodes"] else None

    @property
    def has_nodes(self):
        """True when the result holds the thermal grid's nodes at this snapshot (/nodes, runs with heat)."""
        return self._node_group() is not None

    def nodes(self):
        """The thermal grid's nodes at this snapshot as a pandas DataFrame, one row per node that is
        a thermal unknown: position_x, position_y (position_z), temperature (K, the nodal T_i at the
        snapshot time), heat_capacity (J/K, M_i) and lattice_x, ... (grid node coordinates), in grid
        node order (x fastest; a decomposed run's ranks joined); ``df.attrs`` as for to_dataframe.
        KeyError when the result has none (runs without heat, the failure state)."""
        import pandas as pd
        g = self._node_group()
        if g is None:
            raise KeyError(f"snapshot {self.label} has no thermal grid nodes (/nodes/{self.label})")
        names = [n for n in g if n != "connectivity"]
        order = slice(None)
        if self._run.ranks > 1 and "lattice" in names:  # the serial order: grid node number, x fastest
            lattice = np.asarray(g["lattice"][()])
            order = np.lexsort(tuple(lattice[:, i] for i in range(lattice.shape[1])))
        cols, units = {}, {}
        for name in names:
            data = np.asarray(g[name][()])[order]
            unit = text(g[name].attrs["units"]) if "units" in g[name].attrs else ""
            if data.ndim == 1:
                cols[name], units[name] = data, unit
            else:
                for i in range(data.shape[1]):
                    cols[f"{name}_{AXES[i]}"], units[f"{name}_{AXES[i]}"] = data[:, i], unit
        df = pd.DataFrame(cols)
        df.index.name = "node"
        df.attrs.update(units=units, time=self.time, step=self.step)
        return df

    def stress_tensor(self):
        """The Cauchy stress as (n, 3, 3); in 2D the out-of-plane stress_zz when stored (plane
        strain), else 0 (plane stress)."""
        s = self["stress"].astype(float)
        n, d = s.shape[0], self._run.dim
        full = np.zeros((n, 3, 3))
        full[:, :d, :d] = s
        if d == 2 and "stress_zz" in self:
            full[:, 2, 2] = self["stress_zz"].reshape(n)
        return full

    def __repr__(self):
        return f"Snapshot({self.label}, step {self.step}, t = {self.time:.6g} s, fields {self.fields})"
