"""Column tables (/series, /hotspots, /hotspot_fates, an ensemble's /members and /hotspots)."""
import numpy as np

from ._h5 import column_names, is_count_column


class Table:
    """Named 1-D columns of equal length, in the order the writer declared them.

    ``t["time"]`` is a numpy array, ``t.columns`` the names, ``len(t)`` the number of rows,
    ``t.to_dataframe()`` a pandas DataFrame (pandas is optional), ``t.where(mask)`` a row subset.
    Count and id columns are int64, the rest float64.
    """

    def __init__(self, name, columns):
        self.name = name
        self._data = dict(columns)

    @classmethod
    def read(cls, file, group_name):
        """The column group /group_name of an open h5py file; an empty table when it is absent."""
        if group_name not in file:
            return cls(group_name, {})
        g = file[group_name]
        names = column_names(g)
        data = {}
        for n in names:
            a = np.asarray(g[n][()])
            if is_count_column(n) and a.dtype.kind == "f":  # format version 1 stored counts as doubles
                if np.all(np.isfinite(a)):
                    a = np.rint(a).astype(np.int64)
            elif a.dtype.kind == "f":
                a = a.astype(np.float64, copy=False)
            data[n] = a
        rows = min((len(a) for a in data.values()), default=0)  # a crashed run: cut to the shortest
        return cls(group_name, {n: a[:rows] for n, a in data.items()})

    @property
    def columns(self):
        return list(self._data)

    def __getitem__(self, name):
        try:
            return self._data[name]
        except KeyError:
            raise KeyError(f"/{self.name} has no column '{name}'; columns: {', '.join(self._data) or 'none'}") from None

    def get(self, name, default=None):
        return self._data.get(name, default)

    def __contains__(self, name):
        return name in self._data

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(next(iter(self._data.values()))) if self._data else 0

    def __bool__(self):
        return len(self) > 0

    def __repr__(self):
        return f"Table('/{self.name}', {len(self)} rows, columns {self.columns})"

    def as_dict(self):
        return dict(self._data)

    def where(self, mask):
        """The rows where `mask` (a boolean array over rows) holds."""
        return Table(self.name, {n: a[mask] for n, a in self._data.items()})

    def to_dataframe(self):
        """The table as a pandas DataFrame (Debian python3-pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pandas is optional
            raise ImportError("Table.to_dataframe needs pandas (Debian package python3-pandas)") from e
        return pd.DataFrame(self._data, columns=self.columns)
