#!/usr/bin/python3
"""Writes examples/pbx_3d.json: a 3D PBX-like specimen for `mpirun -n K frictherm run` (issue 16).

An 80 um cube of axis-aligned ellipsoidal HMX grains (each its own material, hmx_1, hmx_2, ...: the
table-1 Mie-Gruneisen/J2 HMX of examples/materials/pbx_table1.json) in a Mie-Gruneisen binder box,
closed by five fixed rigid boundary walls and a rigid piston moving down (-z). The grains are placed
by random sequential addition with a seeded generator: semi-axes uniform in [SEMI_MIN, SEMI_MAX] per
axis, drawn for every grain first and placed largest first, each at a centre drawn uniformly where
the grain fits inside the specimen, kept when it stays GAP away from every grain placed before, tested on a lattice of LATTICE spacing over the
overlap of the bounding boxes with every semi-axis grown by GAP (a lattice point inside both grown
grains means too close). The same seed always writes the same scene.

Usage: /usr/bin/python3 examples/pbx_3d_generate.py [--seed N] [--grains N] [-o FILE]
"""
import argparse
import json
import random

import numpy as np

UM = 1e-6
SPECIMEN_LO, SPECIMEN_HI = 8 * UM, 88 * UM  # the 80 um cube between the walls (every axis)
WALL = 4 * UM                               # wall thickness: one cell
CELL = 4 * UM
SEMI_MIN, SEMI_MAX = 8 * UM, 16 * UM
GAP = 1 * UM
LATTICE = 0.5 * UM
PISTON_SPEED = 50.0   # m/s, -z: 1.6 % of the HMX bulk wave speed C0 = 3070 m/s
END_TIME = 300e-9     # s: the piston moves 15 um, a 19 % strain


def too_close(a, b):
    """True when grains a and b, each (centre, semi_axes) in m, come closer than GAP."""
    (ca, sa), (cb, sb) = a, b
    distance = float(np.linalg.norm(ca - cb))
    if distance > sa.max() + sb.max() + GAP:  # the bounding spheres keep the gap
        return False
    if distance < sa.min() + sb.min() + GAP:  # the inscribed spheres do not
        return True
    ga, gb = sa + GAP, sb + GAP
    lo = np.maximum(ca - ga, cb - gb)
    hi = np.minimum(ca + ga, cb + gb)
    if np.any(lo >= hi):
        return False
    axes = [np.arange(lo[d], hi[d] + LATTICE, LATTICE) for d in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    p = np.stack([x, y, z], axis=-1)
    inside_a = (((p - ca) / ga) ** 2).sum(axis=-1) <= 1.0
    inside_b = (((p - cb) / gb) ** 2).sum(axis=-1) <= 1.0
    return bool(np.any(inside_a & inside_b))


def place_grains(seed, count, tries=1000):
    """The grains' semi-axes drawn first and placed largest first (denser than in drawing order), each
    at the first of up to `tries` random centres where it keeps GAP from the grains already placed."""
    rng = random.Random(seed)
    sizes = [np.array([rng.uniform(SEMI_MIN, SEMI_MAX) for _ in range(3)]) for _ in range(count)]
    sizes.sort(key=lambda s: -float(np.prod(s)))
    grains = []
    for semi in sizes:
        for _ in range(tries):
            centre = np.array([rng.uniform(SPECIMEN_LO + semi[d], SPECIMEN_HI - semi[d]) for d in range(3)])
            if not any(too_close((centre, semi), g) for g in grains):
                grains.append((centre, semi))
                break
    return grains


def scene(seed, count):
    grains = place_grains(seed, count)
    volume = sum(4.0 / 3.0 * np.pi * np.prod(s) for _, s in grains)
    fraction = volume / (SPECIMEN_HI - SPECIMEN_LO) ** 3
    hmx = {"type": "mie_gruneisen", "density": 1891.0, "C0": 3070.0, "S1": 1.79, "S2": 0.0, "gamma0": 0.7,
           "shear_modulus": 4.81e9, "yield_stress": 2.60e8, "hardening_modulus": 0.0}
    materials = {}
    thermal = {}
    bodies = []
    for k, (c, s) in enumerate(grains, start=1):
        name = "hmx_%d" % k
        materials[name] = dict(hmx)
        thermal[name] = {"heat_capacity": 950.0, "conductivity": 0.45}
        bodies.append({"name": "grain_%d" % k, "material": name, "temperature": 300.0,
                       "shape": {"type": "ellipsoid", "center": [round(v, 9) for v in c],
                                 "semi_axes": [round(v, 9) for v in s]}})
    materials["binder"] = {"type": "mie_gruneisen", "density": 935.0, "C0": 1222.0, "S1": 3.4463, "S2": -3.447,
                           "gamma0": 0.583, "shear_modulus": 1.0e9}
    thermal["binder"] = {"heat_capacity": 2280.0, "conductivity": 0.18}
    lo, hi = SPECIMEN_LO, SPECIMEN_HI
    bodies.append({"name": "binder", "material": "binder", "temperature": 300.0,
                   "shape": {"type": "box", "lo": [lo, lo, lo], "hi": [hi, hi, hi]}})
    # Walls: x and y walls span the full height (the piston slides between them), the floor and the
    # piston fill the inside of the x-y walls.
    materials["x_wall"] = {"type": "rigid", "boundary": True, "velocity": [0.0, None, None]}
    materials["y_wall"] = {"type": "rigid", "boundary": True, "velocity": [None, 0.0, None]}
    materials["floor"] = {"type": "rigid", "boundary": True, "velocity": [None, None, 0.0]}
    materials["piston"] = {"type": "rigid", "boundary": True, "velocity": [None, None, -PISTON_SPEED]}
    a, b = lo - WALL, hi + WALL
    walls = [("x_min_wall", "x_wall", [a, a, a], [lo, b, b]), ("x_max_wall", "x_wall", [hi, a, a], [b, b, b]),
             ("y_min_wall", "y_wall", [lo, a, a], [hi, lo, b]), ("y_max_wall", "y_wall", [lo, hi, a], [hi, b, b]),
             ("floor", "floor", [lo, lo, a], [hi, hi, lo]), ("piston", "piston", [lo, lo, hi], [hi, hi, b])]
    for name, mat, wlo, whi in walls:
        bodies.append({"name": name, "material": mat,
                       "shape": {"type": "box", "lo": [round(v, 9) for v in wlo], "hi": [round(v, 9) for v in whi]}})
    return grains, fraction, {
        "units": "SI",
        "description": "3D PBX-like compaction: %d ellipsoidal HMX grains (%.0f %% by volume, seed %d) in binder, "
                       "80 um cube, rigid walls, piston at %g m/s for %g ns" % (len(grains), 100 * fraction, seed,
                                                                               PISTON_SPEED, END_TIME * 1e9),
        "dimension": 3,
        "grid": {"lo": [0.0, 0.0, 0.0], "hi": [96 * UM, 96 * UM, 96 * UM], "cell_size": CELL},
        "materials": materials,
        "bodies": bodies,
        "contact": {"normal": "mvg", "separation": "displacement", "law": {"type": "coulomb", "mu": 0.3},
                    "min_mass_fraction": 0.02},
        "thermal": {"integrator": "forward_euler", "materials": thermal},
        "coupling": {"heating_order": "second", "window": "every_step", "reuse_distance": 0.0,
                     "hotspots": {"mode": "rise", "threshold": 20.0, "min_particles": 2}},
        "solver": {"shape_function": "ugimp", "scheme": "usl", "cfl": 0.5},
        "run": {"end_time": END_TIME},
        "output": {"snapshot_count": 3, "series_interval": 2e-9},
    }


HEADER = """// 3D PBX-like compaction (issue 16), written by examples/pbx_3d_generate.py --seed {seed} --grains {count}
// (edit the script, not this file). SI units. An 80 um cube of {n} axis-aligned ellipsoidal HMX grains
// ({n} of the {count} drawn fitted; {pct:.0f} % by volume, semi-axes 8-16 um, at least 1 um apart, placed
// largest first by seeded random sequential addition), every grain its own material (hmx_1, hmx_2,
// ...) so that friction acts between grains and between grains and binder, in a binder box
// (listed after the grains: a body skips the points earlier bodies took). Table 1 properties of
// Nairn, Bardenhagen & Smith (2018), as examples/pbx_compaction.json and
// examples/materials/pbx_table1.json: Mie-Gruneisen pressure with elastic shear, HMX with J2
// plasticity. Five rigid boundary walls hold the cube (x and y walls fix their normal velocity, the
// floor its z velocity); a rigid piston on top moves down at {v} m/s (1.6 % of the HMX C0) for {t} ns:
// 15 um, a 19 % strain. 4 um cells with 2 x 2 x 2 uGIMP particles each (2 um particles), multimaterial
// contact with MVG normals, displacement separation and Coulomb mu = 0.3 for every pair, USL with
// FLIP, second-order frictional heating conducted by forward Euler every step (HMX k = 0.45, binder
// k = 0.18 W/(m K)), hot spots above a 20 K rise. Every feature runs decomposed:
//   mpirun -n 4 frictherm run examples/pbx_3d.json     (docs/distributed_pbx.md, section "3D PBX-like
// scene: runtime and projections", has its runtime on 1, 2 and 4 ranks).
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--grains", type=int, default=18)
    ap.add_argument("-o", "--output", default="examples/pbx_3d.json")
    args = ap.parse_args()
    grains, fraction, s = scene(args.seed, args.grains)
    if len(grains) < args.grains:
        print("note: placed %d of %d grains" % (len(grains), args.grains))
    text = HEADER.format(seed=args.seed, count=args.grains, n=len(grains), pct=100 * fraction, v=PISTON_SPEED,
                         t=END_TIME * 1e9)
    text += json.dumps(s, indent=1) + "\n"
    with open(args.output, "w") as f:
        f.write(text)
    print("wrote %s: %d grains, %.1f %% HMX by volume" % (args.output, len(grains), 100 * fraction))


if __name__ == "__main__":
    main()
