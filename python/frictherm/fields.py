"""Per-particle values of a snapshot by name: stored fields, their components, and derived ones.

  speed                   |velocity|
  displacement_magnitude  |displacement| (or |position - initial_position|)
  von_mises               sqrt(3/2 s:s) of the Cauchy stress
  pressure                -trace(stress)/3
  velocity_x, stress_xy   one component (or velocity_0 ...)
"""
import numpy as np

AXES = "xyz"
UNITS = {"temperature": "K", "speed": "m/s", "velocity": "m/s", "position": "m", "displacement": "m",
         "displacement_magnitude": "m", "stress": "Pa", "stress_zz": "Pa", "von_mises": "Pa", "pressure": "Pa",
         "mass": "kg", "volume": "m^3", "initial_position": "m"}
DERIVED = ("speed", "displacement_magnitude", "von_mises", "pressure")


def unit_of(name):
    return UNITS.get(name, UNITS.get(name.rpartition("_")[0], ""))


def field_values(snap, name):
    """(values per particle as float, label). Raises KeyError naming the available fields."""
    dim = snap._run.dim
    if name in snap:
        data = snap[name].astype(float)
        if data.ndim == 1:
            return data, name
        return np.linalg.norm(data.reshape(len(data), -1), axis=1), f"|{name}|"
    if name == "speed" and "velocity" in snap:
        return np.linalg.norm(snap["velocity"].astype(float), axis=1), "speed"
    if name == "displacement_magnitude":
        if "displacement" in snap:
            return np.linalg.norm(snap["displacement"].astype(float), axis=1), name
        if "initial_position" in snap:
            d = snap["position"].astype(float) - snap["initial_position"].astype(float)
            return np.linalg.norm(d, axis=1), name
    if name in ("von_mises", "pressure") and "stress" in snap:
        s = snap.stress_tensor()
        trace = np.trace(s, axis1=1, axis2=2)
        if name == "pressure":
            return -trace / 3.0, "pressure"
        dev = s - trace[:, None, None] / 3.0 * np.eye(3)
        return np.sqrt(1.5 * np.einsum("nij,nij->n", dev, dev)), "von Mises stress"
    base, _, suffix = name.rpartition("_")
    if base in snap and suffix:
        data = snap[base].astype(float)
        if data.ndim == 2 and len(suffix) == 1 and (suffix in AXES[:dim] or suffix.isdigit()):
            i = int(suffix) if suffix.isdigit() else AXES.index(suffix)
            if i < data.shape[1]:
                return data[:, i], name
        if data.ndim == 3 and len(suffix) == 2 and all(c in AXES[:dim] for c in suffix):
            return data[:, AXES.index(suffix[0]), AXES.index(suffix[1])], name
        if data.ndim == 3 and suffix.isdigit() and int(suffix) < dim * dim:
            return data.reshape(len(data), -1)[:, int(suffix)], name
    available = sorted(set(snap.fields) | set(DERIVED))
    raise KeyError(f"no field '{name}' in snapshot {snap.label}; available: {', '.join(available)} "
                   "(and components such as velocity_x, stress_xy)")
