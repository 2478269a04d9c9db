"""Particle snapshots of a run: /snapshots/NNNNNN and /failure."""
import numpy as np

from ._h5 import text


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
