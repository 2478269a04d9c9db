"""Reading frictherm results: the one reader of the HDF5 layout the C++ writer produces.

    import frictherm
    with frictherm.open("results/sliding_block_heating.h5") as run:
        t, T = run.series["time"], run.series["max_temperature"]
        df = run.series.to_dataframe()              # pandas, indexed by time; df.attrs["units"]
        run.unit_of("max_temperature")              # 'K' (every dataset has units and long_name)
        ds = run.to_xarray()                        # the whole run as an xarray.Dataset
        last = run.snapshots[-1]                    # .step, .time, .fields, last["temperature"]
        spots = run.hotspots                        # a Table, like the series
        books = run.energy_books                    # heat_delivered, particle_energy_change, ...
        meta = run.meta                             # decoded: str, int, float

`open` also reads ensemble files (`frictherm ensemble`): an Ensemble with .members, .hotspots,
.summary and .member(seed). Needs numpy, h5py and pandas (Debian python3-numpy, python3-h5py,
python3-pandas); xarray only for to_xarray, matplotlib only for frictherm.plot.

Built with pybind11 (CMake build or install, not `pip install`), the package also runs scenes:
frictherm.load_scene(path or dict), scene.set(key, value), frictherm.validate(scene),
frictherm.run(scene, output=..., threads=..., observer=...) (frictherm/native.py).
"""
import h5py

from ._h5 import is_count_column
from .ensemble import Ensemble
from .run import ENERGY_BOOK_KEYS, SUPPORTED_FORMAT_VERSION, Run
from .snapshot import Snapshot, physical_shape
from .native import Scene, SceneError, load_scene, run, validate
from .table import FATE_NAMES, Table

__version__ = "0.1.0"
__all__ = ["open", "Run", "Ensemble", "Snapshot", "Table", "physical_shape", "is_count_column",
           "ENERGY_BOOK_KEYS", "SUPPORTED_FORMAT_VERSION", "FATE_NAMES",
           "Scene", "SceneError", "load_scene", "run", "validate"]


def open(path):  # noqa: A001  (frictherm.open, like h5py.File / io.open)
    """A Run (file of `frictherm run`) or an Ensemble (file of `frictherm ensemble`).

    Raises OSError when the file cannot be opened and ValueError when it is not a frictherm file."""
    f = h5py.File(path, "r")
    try:
        fmt = f.attrs.get("format", b"")
        fmt = fmt.decode() if isinstance(fmt, bytes) else str(fmt)
        if fmt == "frictherm-ensemble" or (not fmt and "members" in f):
            return Ensemble(f, path)
        if fmt == "frictherm-output" or (not fmt and ("series" in f or "snapshots" in f)):
            return Run(f, path)
        raise ValueError(f"{path}: not a frictherm file (root attribute format = '{fmt}')")
    except BaseException:
        f.close()
        raise
