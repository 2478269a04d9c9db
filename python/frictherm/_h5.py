"""Small decoding helpers shared by the readers: HDF5 values as plain Python values."""
import numpy as np

# Mirrors H5Output::is_count_column (coupling/include/frictherm/coupling/h5_output.hpp): the columns
# frictherm writes as int64 from format version 2 on. Version 1 files stored them as doubles; the
# readers give them the same integer dtype so scripts see one layout.
_COUNT_NAMES = {"step", "id", "fate", "seed", "status", "steps", "runaway", "dying", "material_mask", "hotspots"}


def is_count_column(name):
    """True for the series and table columns holding steps, ids or counts (int64 on disk)."""
    if name.startswith("penalty_contacts."):
        return True
    if "." in name:  # per-body and per-pair columns carry user names
        return False
    return name in _COUNT_NAMES or name.endswith(("_count", "_nodes", "_windows"))


def text(value):
    """A string from an HDF5 string value (bytes, numpy bytes or a 0-d array)."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bytes, np.bytes_)):
        return bytes(value).decode("utf-8", "replace")
    return str(value)


def plain(value):
    """A stored scalar as str, int or float (arrays are returned as numpy arrays)."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bytes, np.bytes_, str)):
        return text(value)
    if isinstance(value, (np.integer, int)) and not isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "S":
            return [text(v) for v in value]
        return value
    return value


def column_names(group):
    """Column names of a column group (its `columns` attribute; else every dataset, "time" first)."""
    if "columns" in group.attrs:
        return [text(c) for c in group.attrs["columns"]]
    names = sorted(k for k in group.keys() if hasattr(group[k], "shape"))
    return sorted(names, key=lambda n: n != "time")
