"""Column tables (/series, /hotspots, /hotspot_fates, an ensemble's /members and /hotspots)."""
import numpy as np

from ._h5 import column_names, is_count_column, text

# Units of columns in files written before the `units` attributes (the same as the C++ catalogue,
# coupling/src/output/output_quantities.cpp, for the columns every run has).
FALLBACK_UNITS = {"time": "s", "step": "1", "dt": "s", "kinetic_energy": "J", "strain_energy": "J", "total_energy": "J",
                  "external_work": "J", "momentum_x": "kg m/s", "momentum_y": "kg m/s", "momentum_z": "kg m/s",
                  "max_temperature": "K", "heat_delivered": "J", "thermal_energy_change": "J", "id": "1",
                  "peak_temperature": "K", "mean_temperature": "K", "fate": "1"}
# The hot-spot fates (coupling/include/frictherm/coupling/hotspot_fates.hpp, HotSpotFate).
FATE_NAMES = {0: "undecided", 1: "dying", 2: "runaway"}
FALLBACK_FLAGS = {"fate": FATE_NAMES}


class Table:
    """Named 1-D columns of equal length, in the order the writer declared them.

    ``t["time"]`` is a numpy array, ``t.columns`` the names, ``len(t)`` the number of rows,
    ``t.to_dataframe()`` a pandas DataFrame (pandas is optional), ``t.where(mask)`` a row subset.
    Count and id columns are int64, the rest float64.
    """

    def __init__(self, name, columns, units=None, long_names=None, flags=None, index=None):
        self.name = name
        self._data = dict(columns)
        self.units = dict(units or {})  # column: units (the file's `units` attributes, SI; "1" counts)
        self.long_names = dict(long_names or {})  # column: readable name (`long_name` attributes)
        self.flags = dict(flags or {})  # categorical column: {code: name} (flag_values / flag_meanings)
        self.index = index  # the column to_dataframe() indexes by ("time" for /series), or None

    @classmethod
    def read(cls, file, group_name):
        """The column group /group_name of an open h5py file; an empty table when it is absent."""
        if group_name not in file:
            return cls(group_name, {})
        g = file[group_name]
        names = column_names(g)
        data, units, long_names, flags = {}, {}, {}, {}
        for n in names:
            a = np.asarray(g[n][()])
            attrs = g[n].attrs
            if "units" in attrs:
                units[n] = text(attrs["units"])
            elif n in FALLBACK_UNITS:  # files written before the attributes (frictherm 0.1, issue 33)
                units[n] = FALLBACK_UNITS[n]
            if "long_name" in attrs:
                long_names[n] = text(attrs["long_name"])
            if "flag_values" in attrs and "flag_meanings" in attrs:
                flags[n] = dict(zip((int(v) for v in attrs["flag_values"]), text(attrs["flag_meanings"]).split()))
            elif n in FALLBACK_FLAGS:
                flags[n] = dict(FALLBACK_FLAGS[n])
            if is_count_column(n) and a.dtype.kind == "f":  # format version 1 stored counts as doubles
                if np.all(np.isfinite(a)):
                    a = np.rint(a).astype(np.int64)
            elif a.dtype.kind == "f":
                a = a.astype(np.float64, copy=False)
            data[n] = a
        rows = min((len(a) for a in data.values()), default=0)  # a crashed run: cut to the shortest
        index = "time" if group_name == "series" and "time" in data else None
        return cls(group_name, {n: a[:rows] for n, a in data.items()}, units, long_names, flags, index)

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
        return Table(self.name, {n: a[mask] for n, a in self._data.items()}, self.units, self.long_names, self.flags,
                     self.index)

    def unit_of(self, name):
        """The units of a column ("" when the file does not say)."""
        return self.units.get(name, "")

    def names_of(self, name):
        """A categorical column (e.g. the hot-spot ``fate``) as names: an array of str."""
        codes = self[name]
        table = self.flags.get(name)
        if table is None:
            raise KeyError(f"/{self.name}/{name} is not a categorical column (no flag_meanings)")
        return np.array([table.get(int(c), str(int(c))) for c in codes], dtype=object)

    def to_dataframe(self, index="default"):
        """The table as a pandas DataFrame (Debian python3-pandas). The series is indexed by
        ``time`` (index=None keeps the row numbers and ``time`` as a column). ``df.attrs`` holds
        ``units`` and ``long_names`` (column: str); a categorical column such as ``fate`` also comes
        as names in ``fate_name``."""
        try:
            import pandas as pd
        except ImportError as e:  # pandas is optional
            raise ImportError("Table.to_dataframe needs pandas (Debian package python3-pandas)") from e
        df = pd.DataFrame(self._data, columns=self.columns)
        for name in self.flags:
            if name in df:
                df[name + "_name"] = pd.Categorical(self.names_of(name), categories=list(self.flags[name].values()))
        if index == "default":
            index = self.index
        if index is not None and index in df:
            df = df.set_index(index)
        df.attrs["units"] = {n: self.units[n] for n in self.columns if n in self.units}
        df.attrs["long_names"] = {n: self.long_names[n] for n in self.columns if n in self.long_names}
        return df
