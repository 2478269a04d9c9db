#!/usr/bin/env python3
"""Bad-input sweep (issue 15): bad scenes and command lines of every class the issue names.

Each case must be refused by the frictherm program with exit code 2 and a message whose first line
starts with "frictherm: ...: KEY" (the key path, or the option, it is about), within CPU_LIMIT
seconds of CPU time and RSS_LIMIT_MB of peak resident memory (the issue's bounds: under a second,
under 200 MB). Each case runs in a fresh temporary folder that also holds the files it refers to.

    bad_inputs.py FRICTHERM_EXE [--keep DIR] [-k SUBSTRING]

Prints one line per case (exit code, CPU and wall seconds, peak MB, the message) and exits 1 when a
case is not refused as expected. Sanitizer builds: set BAD_INPUTS_RSS_MB (their shadow memory and
quarantine count as resident).
"""
import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib

CPU_LIMIT = float(os.environ.get("BAD_INPUTS_CPU_S", "1"))
RSS_LIMIT_MB = float(os.environ.get("BAD_INPUTS_RSS_MB", "200"))

BASE = {
    "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.01},
    "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6,
                           "poisson_ratio": 0.3}},
    "bodies": [{"name": "block", "material": "soft", "velocity": [1, 0],
                "shape": {"type": "rectangle", "lo": [0.02, 0.01], "hi": [0.06, 0.04]}}],
    "run": {"end_time": 2e-3, "threads": 1},
    "output": {"snapshot_count": 4},
}


HERE = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(HERE, "..", "..", "examples", "pbx_microstructure_small.json")) as f:
    PACKING = f.read()  # a scene with an ellipse_packing body


def scene(**changes):
    """BASE with top-level sections replaced (a value None removes the key)."""
    s = json.loads(json.dumps(BASE))
    for k, v in changes.items():
        if v is None:
            s.pop(k, None)
        else:
            s[k] = v
    return json.dumps(s)


def image_scene(file, levels=None, **extra):
    s = json.loads(scene(materials={"a": BASE["materials"]["soft"], "b": BASE["materials"]["soft"]}))
    s["bodies"] = [{"name": "img", "particles_per_cell": 1,
                    "shape": {"type": "image", "file": file, "origin": [0, 0], "pixel_size": 0.01,
                              "levels": levels or [{"range": [0, 127], "material": "a"},
                                                   {"range": [128, 255], "material": "b"}]}}]
    s.update(extra)
    return json.dumps(s)


def png_bytes(width, height, idat=b""):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(idat)) + chunk(b"IEND", b"")


def png_zero_bytes(width, height):
    """A valid 8-bit grey PNG of zero pixels, a deflate bomb (about 1000:1). Blocks of 1000 rows are
    compressed once and repeated (a full flush makes each one independent), then closed by an empty
    final block and the Adler-32 of the whole stream."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    rows = b"\0" * ((width + 1) * 1000)  # filter byte + pixels, 1000 rows
    assert height % 1000 == 0
    z = zlib.compressobj(9)
    first = z.compress(rows) + z.flush(zlib.Z_FULL_FLUSH)
    again = z.compress(rows) + z.flush(zlib.Z_FULL_FLUSH)
    adler = ((len(rows) * (height // 1000)) % 65521) << 16 | 1  # Adler-32 of zeros: A = 1, B = length
    idat = first + again * (height // 1000 - 1) + b"\x03\x00" + struct.pack(">I", adler)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def bmp_bytes(width, height):
    header = b"BM" + struct.pack("<IHHI", 54 + 8, 0, 0, 54)
    info = struct.pack("<IiiHHIIiiII", 40, width, height, 1, 24, 0, 0, 0, 0, 0, 0)
    return header + info + b"\0" * 8


def deep(n):
    return "[" * n + "]" * n


# (name, scene text or None, extra files {name: bytes}, argv after the program (SCENE = the scene file),
#  expected start of the message after "frictherm: ...: ")
CASES = [
    # --- resource bombs -------------------------------------------------------------------------
    ("particles 7000x7000 cells x 100 per cell",
     scene(grid={"lo": [0, 0], "hi": [7, 7], "cell_size": 0.001},
           bodies=[{"name": "b", "material": "soft", "particles_per_cell": 10,
                    "shape": {"type": "rectangle", "lo": [0, 0], "hi": [6.9, 6.9]}}]),
     {}, ["validate", "SCENE"], "bodies[0]"),
    ("3D 1000 particles per cell",
     json.dumps({"dimension": 3, "grid": {"lo": [0, 0, 0], "hi": [1, 1, 1], "cell_size": 0.01},
                 "materials": BASE["materials"], "run": {"end_time": 1e-3},
                 "bodies": [{"name": "b", "material": "soft", "particles_per_cell": 10,
                             "shape": {"type": "box", "lo": [0, 0, 0], "hi": [1, 1, 1]}}]}),
     {}, ["validate", "SCENE"], "bodies[0]"),
    ("particles_per_cell 1e9", scene(bodies=[dict(BASE["bodies"][0], particles_per_cell=1000000000)]),
     {}, ["validate", "SCENE"], "bodies[0]"),
    ("mostly empty grid of 4.9e7 nodes", scene(grid={"lo": [0, 0], "hi": [70, 70], "cell_size": 0.01}),
     {}, ["validate", "SCENE"], "grid"),
    ("PGM header 100000x100000, 8 pixel bytes", image_scene("big.pgm"),
     {"big.pgm": b"P5\n100000 100000\n255\n" + b"\x80" * 8}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("BMP header 1000000x1000000", image_scene("big.bmp"),
     {"big.bmp": bmp_bytes(1000000, 1000000)}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("PNG header 1000000x1000000", image_scene("big.png"),
     {"big.png": png_bytes(1000000, 1000000, b"\0" * 100)}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("--set grows an array to 2e8", scene(), {}, ["validate", "SCENE", "--set", "bodies[200000000]=1"],
     "--set bodies[200000000]"),
    ("--set index beyond 2^64", scene(), {}, ["validate", "SCENE", "--set", "bodies[99999999999999999999999]=1"],
     "--set bodies[99999999999999999999999]"),
    ("--set negative index", scene(), {}, ["validate", "SCENE", "--set", "bodies[-1].velocity=[0,0]"],
     "--set bodies[-1]"),
    ("ellipse packing far larger than the grid",
     json.dumps(dict(json.loads(scene()), materials={"hmx": BASE["materials"]["soft"], "binder": BASE["materials"]["soft"]},
                     bodies=[{"name": "pbx", "particles_per_cell": 1,
                              "shape": {"type": "ellipse_packing", "origin": [0, 0], "size": [100, 100],
                                        "pixel_size": 0.001, "seed": 1, "fraction": 0.5,
                                        "major_axis": {"distribution": "uniform", "min": 0.002, "max": 0.004},
                                        "grain_material": "hmx", "binder_material": "binder"}}])),
     {}, ["validate", "SCENE"], "bodies[0].shape"),
    ("ellipse packing of 1e10 pixels",
     json.dumps(dict(json.loads(scene()), materials={"hmx": BASE["materials"]["soft"], "binder": BASE["materials"]["soft"]},
                     bodies=[{"name": "pbx", "particles_per_cell": 1,
                              "shape": {"type": "ellipse_packing", "origin": [0, 0], "size": [0.1, 0.05],
                                        "pixel_size": 1e-6, "seed": 1, "fraction": 0.5,
                                        "major_axis": {"distribution": "uniform", "min": 0.01, "max": 0.02},
                                        "grain_material": "hmx", "binder_material": "binder"}}])),
     {}, ["validate", "SCENE"], "bodies[0].shape"),
    ("PNG of 20000x20000 zero pixels (deflate bomb)", image_scene("bomb.png"),
     {"bomb.png": lambda: png_zero_bytes(20000, 20000)}, ["validate", "SCENE"], "bodies[0].shape.file"),
    # --- endless runs ---------------------------------------------------------------------------
    ("snapshot_interval 1e-300", scene(output={"snapshot_interval": 1e-300}), {}, ["validate", "SCENE"], "output"),
    ("snapshot_count 1e6", scene(output={"snapshot_count": 1000000}), {}, ["validate", "SCENE"], "output"),
    ("max_time_step 1e-300", scene(solver={"max_time_step": 1e-300}), {}, ["validate", "SCENE"], "run.end_time"),
    ("end_time 1e300 at rest", scene(run={"end_time": 1e300},
                                     bodies=[dict(BASE["bodies"][0], velocity=[0, 0])]),
     {}, ["validate", "SCENE"], "run.end_time"),
    ("damping rate 1e300", scene(solver={"damping": {"rate": 1e300, "until": 1e-3}}), {}, ["validate", "SCENE"],
     "run.end_time"),
    # --- numbers --------------------------------------------------------------------------------
    ("1e999 density", scene().replace('"density": 1000', '"density": 1e999'), {}, ["validate", "SCENE"],
     "materials.soft.density"),
    ("-1e999 in grid.lo", scene().replace('"lo": [0, 0]', '"lo": [-1e999, 0]'), {}, ["validate", "SCENE"], "grid.lo"),
    ("max_steps 2^63 as a float", scene(run={"end_time": 2e-3, "max_steps": 9.223372036854775808e18}), {},
     ["validate", "SCENE"], "run.max_steps"),
    ("max_steps 2^64 as an integer", scene(run={"end_time": 2e-3}).replace('"end_time": 0.002', '"end_time": 0.002, "max_steps": 18446744073709551616'),
     {}, ["validate", "SCENE"], "run.max_steps"),
    ("snapshot_count -3", scene(output={"snapshot_count": -3}), {}, ["validate", "SCENE"], "output.snapshot_count"),
    ("particles_per_cell 0", scene(bodies=[dict(BASE["bodies"][0], particles_per_cell=0)]), {}, ["validate", "SCENE"],
     "bodies[0].particles_per_cell"),
    ("threads -1", scene(run={"end_time": 2e-3, "threads": -1}), {}, ["validate", "SCENE"], "run.threads"),
    ("density 1e-300", scene().replace('"density": 1000', '"density": 1e-300'), {}, ["validate", "SCENE"],
     "run.end_time"),
    ("velocity 1e300", scene(bodies=[dict(BASE["bodies"][0], velocity=[1e300, 0])]), {}, ["validate", "SCENE"],
     "bodies[0].velocity"),
    ("NaN literal", scene().replace('"density": 1000', '"density": NaN'), {}, ["validate", "SCENE"], "malformed JSON at line 1"),
    ("cell_size 0", scene(grid={"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0}), {}, ["validate", "SCENE"],
     "grid.cell_size"),
    ("dimension 2.5", scene(dimension=2.5), {}, ["validate", "SCENE"], "dimension"),
    ("dimension 1e19", scene(dimension=1e19), {}, ["validate", "SCENE"], "dimension"),
    ("duplicate key grid", scene().replace('"grid":', '"grid": {"lo": [0, 0], "hi": [1, 1], "cell_size": 0.1}, "grid":'),
     {}, ["validate", "SCENE"], "grid"),
    ("duplicate key in a material", scene().replace('"density": 1000', '"density": 1000, "density": 2000'), {},
     ["validate", "SCENE"], "materials.soft.density"),
    ("P2 pixel above maxval", image_scene("hi.pgm"), {"hi.pgm": b"P2\n2 1\n255\n10 300\n"}, ["validate", "SCENE"],
     "bodies[0].shape.file"),
    ("P2 negative pixel", image_scene("neg.pgm"), {"neg.pgm": b"P2\n2 1\n255\n10 -1\n"}, ["validate", "SCENE"],
     "bodies[0].shape.file"),
    ("PGM maxval 0", image_scene("zero.pgm"), {"zero.pgm": b"P2\n2 1\n0\n0 0\n"}, ["validate", "SCENE"],
     "bodies[0].shape.file"),
    ("level range beyond maxval", image_scene("ok.pgm", levels=[{"range": [0, 70000], "material": "a"}]),
     {"ok.pgm": b"P2\n2 1\n255\n10 200\n"}, ["validate", "SCENE"], "bodies[0].shape.levels[0].range[1]"),
    # --- bad images and files -------------------------------------------------------------------
    ("image file is a folder", image_scene("sub"), {"sub/x": b""}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("image file /dev/zero", image_scene("/dev/zero"), {}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("image file /dev/urandom", image_scene("/dev/urandom"), {}, ["validate", "SCENE"], "bodies[0].shape.file"),
    ("truncated PNG", image_scene("cut.png"), {"cut.png": png_bytes(4, 4, b"\0" * 20)[:40]}, ["validate", "SCENE"],
     "bodies[0].shape.file"),
    ("scene file /dev/zero", None, {}, ["validate", "/dev/zero"], "/dev/zero"),
    ("scene file is a folder", None, {"d/x": b""}, ["validate", "d"], "d"),
    # --- deep nesting and huge strings ----------------------------------------------------------
    ("100000 nested arrays in description", scene().replace('"dimension": 2', '"description": ' + deep(100000) + ', "dimension": 2'),
     {}, ["validate", "SCENE"], "description"),
    ("100000 nested arrays as the scene", deep(100000), {}, ["validate", "SCENE"], "scene"),
    ("50000 nested arrays in --set", scene(), {}, ["validate", "SCENE", "--set", "description=" + deep(50000)],
     "--set description"),
    ("20 MB unknown key", scene().replace('"dimension": 2', '"' + "k" * 20000000 + '": 1, "dimension": 2'), {},
     ["validate", "SCENE"], "scene"),
    ("300-character key in a material", scene().replace('"density": 1000', '"' + "d" * 300 + '": 1, "density": 1000'), {},
     ["validate", "SCENE"], "materials.soft: a key of 300 characters"),
    ("2 MB description string", scene(description="x" * 2000000), {}, ["validate", "SCENE"], "description: a string of"),
    ("1 MB material name in a body", scene(bodies=[dict(BASE["bodies"][0], material="m" * 1000000)]), {},
     ["validate", "SCENE"], "bodies[0].material"),
    # --- wrong types at every level -------------------------------------------------------------
    ("top level an array", json.dumps([BASE]), {}, ["validate", "SCENE"], "scene"),
    ("grid a number", scene(grid=1), {}, ["validate", "SCENE"], "grid"),
    ("grid.lo of 3 numbers in 2D", scene(grid={"lo": [0, 0, 0], "hi": [0.1, 0.05], "cell_size": 0.01}), {},
     ["validate", "SCENE"], "grid.lo"),
    ("materials an array", scene(materials=[1]), {}, ["validate", "SCENE"], "materials"),
    ("material density a string", scene().replace('"density": 1000', '"density": "1000"'), {}, ["validate", "SCENE"],
     "materials.soft.density"),
    ("bodies an object", scene(bodies={"a": 1}), {}, ["validate", "SCENE"], "bodies"),
    ("body shape a string", scene(bodies=[dict(BASE["bodies"][0], shape="rectangle")]), {}, ["validate", "SCENE"],
     "bodies[0].shape"),
    ("velocity of strings", scene(bodies=[dict(BASE["bodies"][0], velocity=["1", "0"])]), {}, ["validate", "SCENE"],
     "bodies[0].velocity"),
    ("run.end_time null", scene(run={"end_time": None}), {}, ["validate", "SCENE"], "run.end_time"),
    ("output.fields an object", scene(output={"snapshot_count": 4, "fields": {"a": 1}}), {}, ["validate", "SCENE"],
     "output.fields"),
    # --- output over inputs and absurd command lines --------------------------------------------
    ("run -o the scene itself", scene(), {}, ["run", "SCENE", "-o", "SCENE"], "refusing to write"),
    ("run -o the image it reads", image_scene("ok.pgm"), {"ok.pgm": b"P2\n2 1\n255\n10 200\n"},
     ["run", "SCENE", "-o", "ok.pgm"], "refusing to write"),
    ("microstructure -o the scene itself", PACKING, {}, ["microstructure", "SCENE", "-o", "SCENE"], "refusing to write"),
    ("--threads 1e9", scene(), {}, ["run", "SCENE", "--threads", "1000000000"], "option '--threads'"),
    ("--set value 1e999", scene(), {}, ["validate", "SCENE", "--set", "run.end_time=1e999"], "--set run.end_time"),
    ("--set duplicate key in the value", scene(), {}, ["validate", "SCENE", "--set", 'run={"end_time": 1, "end_time": 2}'],
     "--set run.end_time"),
    ("--set without =", scene(), {}, ["validate", "SCENE", "--set", "solver.cfl"], "--set solver.cfl"),
    ("--set into a number", scene(), {}, ["validate", "SCENE", "--set", "dimension.x=1"], "--set dimension.x"),
    ("contact.boundary_spacing 1e-12 (2e11 boundary points)", scene(contact={"boundary_spacing": 1e-12}), {},
     ["validate", "SCENE"], "contact.boundary_spacing"),
    ("continuation of 1e7 intervals", scene(
        materials={"soft": BASE["materials"]["soft"]},
        thermal={"materials": {"soft": {"heat_capacity": 1000, "conductivity": 1}}},
        coupling={"continuation": {"duration": 1e-3, "intervals": 10000000}}), {}, ["validate", "SCENE"],
     "coupling.continuation.intervals"),
    ("material name with a slash", scene().replace('"soft"', '"so/ft"'), {}, ["validate", "SCENE"], "materials.so/ft"),
    ("body name with a slash", scene(bodies=[dict(BASE["bodies"][0], name="bl/ock")]), {}, ["validate", "SCENE"],
     "bodies[0].name"),
    ("-o followed by an option", scene(), {}, ["run", "SCENE", "-o", "--force"], "option '-o'"),
]

# --- every command refuses bad input by its key, fast (issue 34 item 6) ------------------------
THERMAL_FOR_SETUP = json.dumps(dict(json.loads(scene()),
                                    thermal={"materials": {"soft": {"heat_capacity": 1000, "conductivity": 1}}},
                                    coupling={"continuation": {"duration": 1e-3, "intervals": 2}},
                                    run={"end_time": 5e-4, "threads": 1}))


def many_materials(n):
    """n materials, the last one's Poisson ratio out of range: refused in time linear in n."""
    mats = {"m%d" % k: BASE["materials"]["soft"] for k in range(n)}
    mats["m%d" % (n - 1)] = dict(BASE["materials"]["soft"], poisson_ratio=0.7)
    return scene(materials=mats)


def many_materials_in_contact(n):
    """n valid materials in contact: contact's dense materials x materials tables (37 B per pair on one
    thread) refused by the cost estimate before they exist (issue 34: 50,000 ended in std::bad_alloc).
    run.max_memory makes the refusal independent of the machine's memory."""
    mats = {"m%d" % k: BASE["materials"]["soft"] for k in range(n)}
    s = json.loads(scene(materials=mats))
    s["bodies"][0]["material"] = "m0"
    s["contact"] = {}
    s["run"]["max_memory"] = 1e9
    return json.dumps(s)


def many_constants(n):
    """An expression law with n named constants whose expression names an unknown variable."""
    soft = BASE["materials"]["soft"]
    s = json.loads(scene(materials={"base": soft, "block": soft}))
    s["bodies"][0]["material"] = "block"
    s["contact"] = {"pairs": [{"materials": ["base", "block"],
                               "law": {"type": "expression", "sliding_traction": "k0*N + undefined_name",
                                       "constants": {"k%d" % k: 0.1 for k in range(n)}}}]}
    return json.dumps(s)


def foreign_h5(workdir):
    import h5py
    with h5py.File(os.path.join(workdir, "foreign.h5"), "w") as f:
        f["x"] = [1.0, 2.0]


def collision_scene():
    soft = BASE["materials"]["soft"]
    s = json.loads(scene(materials={"a": soft, "b.c": soft, "a.b": soft, "c": soft}))
    s["bodies"][0]["material"] = "a"
    s["contact"] = {"pairs": [{"materials": ["a", "b.c"], "law": {"type": "coulomb", "mu": 0.3}},
                              {"materials": ["a.b", "c"], "law": {"type": "coulomb", "mu": 0.3}}]}
    return json.dumps(s)


def thermal_scene(**thermal):
    return json.dumps(dict(json.loads(scene()),
                           thermal=dict({"materials": {"soft": {"heat_capacity": 1000, "conductivity": 1}}}, **thermal),
                           coupling={"continuation": {"duration": 1e-3, "intervals": 2}},
                           run={"end_time": 5e-4, "threads": 1}))


CASES += [
    ("output folder missing (validate)", scene(output={"snapshot_count": 4, "file": "nope/out.h5"}), {},
     ["validate", "SCENE"], "output.file: the folder 'nope'"),
    ("output folder missing (run)", scene(output={"snapshot_count": 4, "file": "nope/out.h5"}), {},
     ["run", "SCENE"], "output.file: the folder 'nope'"),
    ("output file is a folder (validate)", scene(output={"snapshot_count": 4, "file": "outdir"}),
     {"outdir/keep": b""}, ["validate", "SCENE"], "output.file: 'outdir' is a folder"),
    ("export-csv of a foreign HDF5 file", scene(), {}, ["export-csv", "foreign.h5", "-o", "s.csv"],
     "'foreign.h5' has no time series", [foreign_h5]),
    ("export-csv of a checkpoint", THERMAL_FOR_SETUP, {}, ["export-csv", "R.h5.checkpoint"],
     "'R.h5.checkpoint' has no time series (/series): it is a checkpoint", [["run", "SCENE", "-o", "R.h5", "-q"]]),
    ("resume: the checkpoint of another run", scene(run={"end_time": 2e-3, "threads": 1, "checkpoint_interval": 1e-3}),
     {}, ["resume", "R.h5"], "'R.h5' is the result of run ",
     [["run", "SCENE", "-o", "R.h5", "-q"], ["run", "SCENE", "-o", "S.h5", "-q"],
      lambda d: shutil.copyfile(os.path.join(d, "S.h5.checkpoint"), os.path.join(d, "R.h5.checkpoint"))]),
    ("end_time 5e-324", scene(run={"end_time": 5e-324}), {}, ["validate", "SCENE"], "run.end_time"),
    ("material names colliding once joined with '.'", collision_scene(), {}, ["validate", "SCENE"],
     "contact.pairs[1].materials: the names 'a.b' and 'c' joined"),
    ("key holding \\u0000", json.dumps(dict(json.loads(scene()), **{"ru\x00n": 1})), {}, ["validate", "SCENE"],
     "ru\\u0000n: unknown key"),
    ("50,000 materials", many_materials(50000), {}, ["validate", "SCENE"], "materials.m49999.poisson_ratio"),
    ("20,000 materials in contact", many_materials_in_contact(20000), {}, ["validate", "SCENE"],
     "materials: 20000 materials in contact need about 14.8 GB"),
    ("expression law with 200,000 constants", many_constants(200000), {}, ["validate", "SCENE"],
     "contact.pairs[0].law.constants: expected at most 1000 named constants, got 200000"),
    ("expression law with 1,000 constants", many_constants(1000), {}, ["validate", "SCENE"],
     "contact.pairs[0].law.sliding_traction: unknown variable undefined_name"),
    ("continuation duration 1e300", thermal_scene().replace('"duration": 0.001', '"duration": 1e300'), {},
     ["validate", "SCENE"], "coupling.continuation.duration"),
    ("thermal rtol 1e-300", thermal_scene(rtol=1e-300), {}, ["validate", "SCENE"], "thermal.rtol"),
    # Found by exploratory testing (session 63): each was accepted, or refused only when the run started.
    ("polygon with its vertices on one line",
     scene(bodies=[{"name": "bar", "material": "soft",
                    "shape": {"type": "polygon", "vertices": [[0.01, 0.01], [0.02, 0.02], [0.03, 0.03]]}}]),
     {}, ["validate", "SCENE"], "bodies[0].shape.vertices: expected a polygon that encloses an area"),
    ("interface patch 200,000,000 cells across",
     json.dumps(dict(json.loads(thermal_scene()),
                     coupling={"interface_temperature": {"patch_length": 1e6}})),
     {}, ["validate", "SCENE"], "coupling.interface_temperature.patch_length: expected at most 64 cells"),
    ("--set null on an array element", scene(), {}, ["validate", "SCENE", "--set", "bodies[0]=null"],
     "--set bodies[0]=null: null removes an object's key"),
    ("--set without '.' after ']'", scene(), {}, ["validate", "SCENE", "--set", "bodies[0]velocity=[1,0]"],
     "--set bodies[0]velocity: expected '.' or '['"),
    ("a thermal section without a heated particle",
     scene(materials={"wall": {"type": "rigid", "velocity": [1, 0]}},
           bodies=[{"name": "w", "material": "wall", "shape": {"type": "rectangle", "lo": [0.01, 0.01], "hi": [0.03, 0.04]}}],
           thermal={"materials": {}}),
     {}, ["validate", "SCENE"], "thermal.materials: no particle has a material with thermal properties"),
]

# --- inputs of continue, resume and export-csv are never replaced, --force or not (issue 34) -----
# A sixth element: commands run first (each must succeed); the files they leave must be byte-equal
# after the refused command.
RESULT_SETUP = [["run", "SCENE", "-o", "R.h5", "-q"]]  # R.h5, R.xdmf and the end-of-loading R.h5.checkpoint
THERMAL = json.dumps(dict(json.loads(scene()),
                          thermal={"materials": {"soft": {"heat_capacity": 1000, "conductivity": 1}}},
                          coupling={"continuation": {"duration": 1e-3, "intervals": 2}},
                          run={"end_time": 5e-4, "threads": 1}))
CASES += [
    # The XDMF files a result is published with are results too (session 63: a serial run replaced them):
    # -o R.xdmf names an HDF5 result, which a later -o R.h5 must not write its XDMF file over.
    ("run -o R.h5 beside another run's R.xdmf", scene(), {}, ["run", "SCENE", "-o", "R.h5"], "'R.xdmf' exists",
     [["run", "SCENE", "-o", "R.xdmf", "-q"]]),
    ("run -o R.h5 beside an R_reference.xdmf", scene(), {}, ["run", "SCENE", "-o", "R.h5"], "'R_reference.xdmf' exists",
     [lambda d: open(os.path.join(d, "R_reference.xdmf"), "w").write("notes")]),
    ("run --force of the scene R_nodes.xdmf", scene(), {}, ["run", "R_nodes.xdmf", "-o", "R.h5", "--force"],
     "refusing to write 'R_nodes.xdmf'",
     [lambda d: shutil.copyfile(os.path.join(d, "scene.json"), os.path.join(d, "R_nodes.xdmf"))]),
    ("continue -o its input", THERMAL, {}, ["continue", "R.h5", "-o", "R.h5"], "refusing to write 'R.h5'",
     RESULT_SETUP),
    ("continue -o its input --force", THERMAL, {}, ["continue", "R.h5", "-o", "R.h5", "--force"],
     "refusing to write 'R.h5'", RESULT_SETUP),
    ("continue -o its checkpoint --force", THERMAL, {}, ["continue", "R.h5", "-o", "R.h5.checkpoint", "--force"],
     "refusing to write 'R.h5.checkpoint'", RESULT_SETUP),
    ("resume -o its checkpoint --force", THERMAL, {}, ["resume", "R.h5", "-o", "R.h5.checkpoint", "--force"],
     "refusing to write 'R.h5.checkpoint'", RESULT_SETUP),
    ("export-csv -o its input --force", THERMAL, {}, ["export-csv", "R.h5", "-o", "R.h5", "--force"],
     "refusing to write 'R.h5'", RESULT_SETUP),
    # A run's checkpoint and XDMF belong to it; by canonical path; by content (issue 34 leftover).
    ("export-csv -o its checkpoint --force", THERMAL, {}, ["export-csv", "R.h5", "-o", "R.h5.checkpoint", "--force"],
     "refusing to write 'R.h5.checkpoint': it is the checkpoint of 'R.h5'", RESULT_SETUP),
    ("export-csv -o ./its input --force", THERMAL, {}, ["export-csv", "R.h5", "-o", "./R.h5", "--force"],
     "refusing to write './R.h5': it is the input of 'R.h5'", RESULT_SETUP),
    ("export-csv -o its XDMF --force", THERMAL, {}, ["export-csv", "R.h5", "-o", "R.xdmf", "--force"],
     "refusing to write 'R.xdmf': it is the XDMF file of 'R.h5'", RESULT_SETUP),
    ("export-csv -o another run's result --force", THERMAL, {}, ["export-csv", "R.h5", "-o", "S.h5", "--force"],
     "refusing to write 'S.h5': it is a result of frictherm", RESULT_SETUP + [["run", "SCENE", "-o", "S.h5", "-q"]]),
    ("export-csv -o another run's checkpoint --force", THERMAL, {},
     ["export-csv", "R.h5", "-o", "S.bin", "--force"], "refusing to write 'S.bin': it is a checkpoint of frictherm",
     RESULT_SETUP + [["run", "SCENE", "-o", "S.h5", "-q"],
                     lambda d: shutil.copyfile(os.path.join(d, "S.h5.checkpoint"), os.path.join(d, "S.bin"))]),
    ("continue -o its XDMF --force", THERMAL, {}, ["continue", "R.h5", "-o", "R.xdmf", "--force"],
     "refusing to write 'R.xdmf': it is the XDMF file of 'R.h5'", RESULT_SETUP),
    ("resume -o another run's checkpoint --force", THERMAL, {}, ["resume", "R.h5", "-o", "S.h5.checkpoint", "--force"],
     "refusing to write 'S.h5.checkpoint': it is a checkpoint of frictherm", RESULT_SETUP + [["run", "SCENE", "-o", "S.h5", "-q"]]),
]


# --- damaged checkpoints: every array's size and finiteness checked before any step (issue 34) ----
def damage(name, change):
    """A setup step: rewrites dataset `name` of R.h5.checkpoint with change(old values)."""
    def apply(workdir):
        import h5py
        import numpy
        with h5py.File(os.path.join(workdir, "R.h5.checkpoint"), "r+") as f:
            data = change(numpy.array(f[name][...]))
            del f[name]
            # With a Fletcher32 checksum as frictherm writes it (format 3): the damage is what is refused.
            f.create_dataset(name, data=data, chunks=True if data.size else None, fletcher32=data.size > 0)
    return apply


def with_nan(values):
    values = values.astype(float)
    values.flat[min(7, values.size - 1)] = float("nan")
    return values


CASES += [
    ("checkpoint: 10 nodal temperatures", THERMAL, {}, ["resume", "R.h5"],
     "checkpoint 'R.h5.checkpoint': /nodal_temperature holds 10 items, expected",
     RESULT_SETUP + [damage("nodal_temperature", lambda v: v[:10])]),
    ("checkpoint: 1e7 work_first", THERMAL, {}, ["continue", "R.h5"],
     "checkpoint 'R.h5.checkpoint': /mechanics/work_first holds 10000000 items, expected",
     RESULT_SETUP + [damage("mechanics/work_first", lambda v: __import__("numpy").zeros(10 ** 7))]),
    ("checkpoint: NaN velocity", THERMAL, {}, ["resume", "R.h5"],
     "checkpoint 'R.h5.checkpoint': /mechanics/particles/velocity holds a non-finite value",
     RESULT_SETUP + [damage("mechanics/particles/velocity", with_nan)]),
    ("checkpoint: 10 particle masses", THERMAL, {}, ["resume", "R.h5"],
     "checkpoint 'R.h5.checkpoint': /mechanics/particles/mass holds 10 items, expected",
     RESULT_SETUP + [damage("mechanics/particles/mass", lambda v: v[:10])]),
    ("checkpoint: infinite time", THERMAL, {}, ["resume", "R.h5"],
     "checkpoint 'R.h5.checkpoint': /mechanics/time holds a non-finite value",
     RESULT_SETUP + [damage("mechanics/time", lambda v: v * float("inf"))]),
]


# --- runtime failures (issue 34) ---------------------------------------------------------------
# Scenes that pass validation and fail during the run. Each must end as a blow-up does: exit code 1,
# the first message line naming the key (and, for a friction law, the state N, v, A where it failed),
# the result published (OUT.h5 readable, /meta/status "failed", the state under /failure), its XDMF
# naming only files that exist, no temporary left behind.
def contact_scene(law, where="pair", thermal=False):
    """A block sliding at 0.1 m/s onto a fixed base: the pair's law is evaluated from step 0 at v = 0.1 m/s."""
    soft = BASE["materials"]["soft"]
    s = {"dimension": 2, "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.005},
         "materials": {"base": soft, "block": soft},
         "bodies": [{"name": "base", "material": "base", "shape": {"type": "rectangle", "lo": [0, 0], "hi": [0.1, 0.02]}},
                    {"name": "block", "material": "block", "velocity": [0.1, -0.02],
                     "shape": {"type": "rectangle", "lo": [0.02, 0.02], "hi": [0.05, 0.035]}}],
         "boundary": {"fixed": [{"face": "y_min"}]},
         "run": {"end_time": 5e-3, "threads": 1}, "output": {"snapshot_count": 4}}
    if where == "pair":
        s["contact"] = {"pairs": [{"materials": ["base", "block"], "normal": [0, 1], "law": law}]}
    else:
        s["contact"] = {"law": law}
    if thermal:
        s["thermal"] = {"materials": {m: {"heat_capacity": 1000, "conductivity": 1} for m in ("base", "block")}}
        s["coupling"] = {"continuation": {"duration": 1e-3, "intervals": 2}}
    return json.dumps(s)


def expression(text):
    return {"type": "expression", "sliding_traction": text}


# The validator samples v in {0, 1e-3, 1, 1e3} m/s: a law bad only for 2e-3 < v < 0.5 passes it.
RUNTIME_CASES = [
    ("expression law negative while sliding", contact_scene(expression("(v>2e-3 && v<0.5) ? -N : 0.3*N")),
     ["contact.pairs[0].law", "materials 'base' and 'block'", "returned S = -", "N = ", "sliding speed = 0.1"]),
    ("expression law NaN while sliding", contact_scene(expression("(v>2e-3 && v<0.5) ? sqrt(-1) : 0.3*N")),
     ["contact.pairs[0].law", "nan for N = ", "A_c = "]),
    ("expression law infinite while sliding", contact_scene(expression("(v>2e-3 && v<0.5) ? 1e308*N*N : 0.3*N")),
     ["contact.pairs[0].law", "returned S = inf"]),
    ("contact.law expression negative", contact_scene(expression("(v>2e-3 && v<0.5) ? -N : 0.3*N"), where="default"),
     ["contact.law", "returned S = -"]),
    ("expression law negative, thermal scene",
     contact_scene(expression("(v>2e-3 && v<0.5) ? -0.2*N : 0.2*N"), thermal=True),
     ["contact.pairs[0].law", "returned S = -"]),
]


def check_published(workdir, out):
    """Problems with the published result `out` of a failed run (empty list: none)."""
    import h5py  # only the runtime cases need it
    problems = []
    path = os.path.join(workdir, out)
    left = [f for f in os.listdir(workdir) if f.endswith(".part") or f.endswith(".tmp")]
    if left:
        problems.append("temporaries left behind: %s" % left)
    if not os.path.exists(path):
        return problems + ["%s was not published" % out]
    try:
        with h5py.File(path, "r") as f:
            status = f["meta/status"][()]
            status = status.decode() if isinstance(status, bytes) else str(status)
            if status != "failed":
                problems.append("/meta/status = %s (expected failed)" % status)
            if "failure" not in f or "position" not in f["failure"]:
                problems.append("no failing state under /failure")
            if "meta/failure" not in f:
                problems.append("no /meta/failure message")
    except Exception as e:  # noqa: BLE001 - any unreadable file is the finding
        problems.append("%s does not read: %s" % (out, e))
    xdmf = os.path.splitext(path)[0] + ".xdmf"
    if not os.path.exists(xdmf):
        problems.append("no XDMF file")
    else:
        import re
        with open(xdmf) as fx:
            named = set(re.findall(r">\s*([^<>:\s]+):/", fx.read()))
        for n in named:
            if not os.path.exists(os.path.join(workdir, n)):
                problems.append("the XDMF names %s, which does not exist" % n)
    return problems


def file_hashes(workdir):
    import hashlib
    out = {}
    for f in sorted(os.listdir(workdir)):
        path = os.path.join(workdir, f)
        if os.path.isfile(path) and not f.startswith("."):
            with open(path, "rb") as fh:
                out[f] = hashlib.sha1(fh.read()).hexdigest()
    return out


def run_case(exe, workdir, case):
    name, text, files, argv, key = case[:5]
    setup = case[5] if len(case) > 5 else []
    for rel, data in files.items():
        path = os.path.join(workdir, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data() if callable(data) else data)
    scene_path = os.path.join(workdir, "scene.json")
    if text is not None:
        with open(scene_path, "w") as f:
            f.write(text)
    for command in setup:
        if callable(command):
            command(workdir)
            continue
        done = subprocess.run([exe] + [scene_path if a == "SCENE" else a for a in command], cwd=workdir,
                              stdin=subprocess.DEVNULL, capture_output=True)
        if done.returncode != 0:
            raise RuntimeError("setup %s failed: %s" % (command, done.stderr.decode(errors="replace")))
    args = [a.replace("SCENE", scene_path) if a == "SCENE" else a for a in argv]
    key = key.replace("SCENE", scene_path)
    t0 = time.monotonic()
    with open(os.path.join(workdir, ".stdout"), "w+b") as out, open(os.path.join(workdir, ".stderr"), "w+b") as err:
        proc = subprocess.Popen([exe] + args, cwd=workdir, stdin=subprocess.DEVNULL, stdout=out, stderr=err)
        # wait4: the exit status with this child's own CPU time and peak resident size.
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - t0 > 30:
                proc.kill()
            time.sleep(0.005)
        proc.returncode = os.waitstatus_to_exitcode(status)
        wall = time.monotonic() - t0
        out.seek(0)
        err.seek(0)
        text_out, text_err = out.read().decode(errors="replace"), err.read().decode(errors="replace")
    return proc.returncode, text_out, text_err, wall, usage, key


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("exe")
    ap.add_argument("--keep")
    ap.add_argument("-k", default="")
    a = ap.parse_args()
    failures = 0
    count = 0
    for case in CASES:
        if a.k not in case[0]:
            continue
        count += 1
        workdir = tempfile.mkdtemp(prefix="frictherm_bad_")
        before = None
        if len(case) > 5:  # the files of the setup commands, to compare after the refusal
            try:
                run_case(os.path.abspath(a.exe), workdir, case[:2] + ({}, ["--version"], "", case[5]))
            except RuntimeError as e:
                print("FAIL %s: %s" % (case[0], e))
                failures += 1
                continue
            before = file_hashes(workdir)
            case = case[:5]
        code, out, err, wall, usage, key = run_case(os.path.abspath(a.exe), workdir, case)
        cpu = usage.ru_utime + usage.ru_stime
        rss_mb = usage.ru_maxrss / 1024.0
        first = (err.strip().splitlines() or [""])[0]
        message = first.split(": ", 1)[1] if first.startswith("frictherm") and ": " in first else first
        # "frictherm: PATH: KEY..." or "frictherm run: option ...": the part after the scene path.
        after_path = first.split(": ", 2)[2] if first.count(": ") >= 2 else message
        problems = []
        if code != 2:
            problems.append("exit code %s (expected 2)" % code)
        if not (after_path.startswith(key) or message.startswith(key)):
            problems.append("message does not start with '%s'" % key)
        if cpu > CPU_LIMIT:
            problems.append("%.2f s CPU (limit %.1f)" % (cpu, CPU_LIMIT))
        if rss_mb > RSS_LIMIT_MB:
            problems.append("%.0f MB resident (limit %.0f)" % (rss_mb, RSS_LIMIT_MB))
        if before is not None:
            after = file_hashes(workdir)
            for f, h in before.items():
                if after.get(f) != h:
                    problems.append("%s was %s" % (f, "changed" if f in after else "removed"))
            if sorted(after) != sorted(before):
                problems.append("files left: %s" % sorted(set(after) - set(before)))
        status = "FAIL" if problems else "ok"
        shown = first if len(first) < 220 else first[:217] + "..."
        print("%-4s rc=%s cpu=%.2fs wall=%.2fs rss=%.0fMB  %-44s %s" % (status, code, cpu, wall, rss_mb, case[0], shown))
        for p in problems:
            print("     -> " + p)
        if problems:
            failures += 1
        if a.keep:
            shutil.copytree(workdir, os.path.join(a.keep, case[0].replace(" ", "_").replace("/", "_")), dirs_exist_ok=True)
        shutil.rmtree(workdir, ignore_errors=True)
    print("%d of %d bad inputs refused as expected" % (count - failures, count))
    runtime_failures = 0
    runtime_count = 0
    for name, text, keys in RUNTIME_CASES:
        if a.k not in name:
            continue
        runtime_count += 1
        workdir = tempfile.mkdtemp(prefix="frictherm_fail_")
        code, out, err, wall, usage, _ = run_case(os.path.abspath(a.exe), workdir,
                                                  (name, text, {}, ["run", "SCENE", "-o", "out.h5"], ""))
        first = (err.strip().splitlines() or [""])[0]
        problems = []
        if code != 1:
            problems.append("exit code %s (expected 1)" % code)
        for k in keys:
            if k not in first:
                problems.append("message does not name '%s'" % k)
        os.remove(os.path.join(workdir, "scene.json"))
        problems += check_published(workdir, "out.h5")
        shown = first if len(first) < 220 else first[:217] + "..."
        print("%-4s rc=%s wall=%.2fs  %-44s %s" % ("FAIL" if problems else "ok", code, wall, name, shown))
        for p in problems:
            print("     -> " + p)
        runtime_failures += 1 if problems else 0
        if a.keep:
            shutil.copytree(workdir, os.path.join(a.keep, name.replace(" ", "_").replace("/", "_")), dirs_exist_ok=True)
        shutil.rmtree(workdir, ignore_errors=True)
    print("%d of %d runtime failures ended cleanly" % (runtime_count - runtime_failures, runtime_count))
    return 1 if failures or runtime_failures else 0


if __name__ == "__main__":
    sys.exit(main())
