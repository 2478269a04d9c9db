"""Running scenes from Python: the bindings to the frictherm library (frictherm/_native, pybind11).

    import frictherm
    scene = frictherm.load_scene("examples/bar_vibration.json")   # or a dict
    scene.set("solver.cfl", 0.25)                                 # as `frictherm run --set`
    frictherm.validate(scene)                                     # raises frictherm.SceneError(key, ...)
    result = frictherm.run(scene, output="bar.h5", threads=1,
                           observer=lambda s: print(s.step, s.time, s.kinetic_energy))

Built with the C++ library when CMake finds pybind11 (Debian pybind11-dev): the module lives in the
build tree (build/python/frictherm) and in the CMake install; `pip install ./python` copies it into the
environment when it finds it (FRICTHERM_BUILD_DIR, python/setup.py, docs/python.md "Installing").
"""
import json
import os
import warnings

try:
    from . import _native
except ImportError as e:  # the reader works without the bindings
    _native = None
    _IMPORT_ERROR = e


def _need_native():
    if _native is None:
        raise ImportError("frictherm was installed without its compiled part (frictherm/_native): build frictherm with "
                          f"CMake and pybind11 (Debian pybind11-dev) and use build/python, the CMake install, or "
                          f"FRICTHERM_BUILD_DIR=<build> pip install ./python ({_IMPORT_ERROR})")
    return _native


class SceneError(ValueError):
    """A scene that does not validate. ``key`` is the scene key path the message starts with
    (e.g. ``solver.cfl``), ``message`` the whole text."""

    def __init__(self, message):
        super().__init__(message)
        self.message = message
        head = message.split(":", 1)[0].strip()
        self.key = head[len("--set "):] if head.startswith("--set ") else head


class Scene:
    """A scene's JSON text plus the changes made with ``set`` (applied as `--set` overrides, so
    error messages name the same key paths as the program's)."""

    def __init__(self, text, source="<dict>", base_dir=".", name="scene"):
        self.text, self.source, self.base_dir, self.name = text, source, base_dir, name
        self.overrides = []  # (key path, JSON text)

    def set(self, key, value):
        """Changes one value (``"solver.cfl"``, ``"bodies[0].velocity"``); ``None`` removes a key.
        Returns the scene, so calls chain."""
        self.overrides.append((key, json.dumps(value)))
        return self

    def copy(self):
        s = Scene(self.text, self.source, self.base_dir, self.name)
        s.overrides = list(self.overrides)
        return s

    def to_dict(self):
        """The scene as it would run (overrides applied), validated."""
        return json.loads(validate(self)["json"])

    def _args(self):
        return (self.text, self.source, self.base_dir, self.name, list(self.overrides))

    def __repr__(self):
        return f"Scene('{self.source}', {len(self.overrides)} changes)"


def load_scene(path_or_dict):
    """A Scene from a scene file (comments allowed; images relative to its folder) or a dict."""
    if isinstance(path_or_dict, Scene):
        return path_or_dict.copy()
    if isinstance(path_or_dict, dict):
        return Scene(json.dumps(path_or_dict), "<dict>", os.getcwd(), "scene")
    path = os.fspath(path_or_dict)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    name = os.path.splitext(os.path.basename(path))[0]
    return Scene(text, path, os.path.dirname(os.path.abspath(path)), name)


def _translate(call, *args):
    native = _need_native()
    try:
        return call(native, *args)
    except native.SceneError as e:
        raise SceneError(str(e)) from None


def validate(scene):
    """Parses and validates the scene as the program does; returns {"json", "dimension",
    "end_time", "name", "notes"}: "notes" lists settings the scene runs with but that are known to
    fail or mislead, each naming its key (what `frictherm validate` prints as notes). Raises
    SceneError naming the key."""
    scene = load_scene(scene) if not isinstance(scene, Scene) else scene
    return _translate(lambda n, *a: n.validate(*a), *scene._args())


def run(scene, output, threads=1, observer=None, overwrite=True, every=1):
    """Runs the scene to its end time, writing `output` (HDF5, as `frictherm run -o`). `observer`,
    if given, is called every `every` mechanics steps with a Step: ``step``, ``time``, ``dt``,
    ``kinetic_energy``, ``strain_energy``, ``series`` (the latest /series row as {column: value};
    ``series_new``: this step wrote it) and ``particles()`` (NumPy views, valid during the call).
    Ctrl-C (SIGINT, or SIGTERM) ends the run after the current step, writes its series and a last
    snapshot (status ``interrupted``) and raises KeyboardInterrupt; a second Ctrl-C ends the process
    at once, as for the program. The handlers are Python's again after the run. Returns {"status", "output", "steps", "time", "wall_time", "snapshots",
    "series_rows", "particles", "message", "notes"} (the scene's notes, also warned as UserWarning)."""
    scene = load_scene(scene) if not isinstance(scene, Scene) else scene
    result = _translate(lambda n, *a: n.run(*a), *scene._args(), os.fspath(output), int(threads), bool(overwrite),
                        observer, int(every))
    for note in result.get("notes", []):  # as `frictherm run` prints them (a UserWarning each)
        warnings.warn(note, stacklevel=2)
    if result["status"] == "interrupted":  # Ctrl-C: the run ended cleanly, the file is complete to here
        raise KeyboardInterrupt(f"{result['message']}; {result['output']} holds the run so far (status interrupted)")
    return result
