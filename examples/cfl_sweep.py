#!/usr/bin/env python3
"""A CFL sweep from Python (frictherm.load_scene / Scene.set / frictherm.run, docs/python.md):
the vibrating bar at three CFL factors, the free end's peak velocity and the run's cost.
Needs the bindings: the package of the build tree (build/python, made with pybind11) is used."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "python"))
import frictherm  # noqa: E402

scene = frictherm.load_scene(os.path.join(os.path.dirname(os.path.abspath(__file__)), "bar_vibration.json"))
for cfl in (0.5, 0.25, 0.1):
    peak = []  # the observer sees every 10th step: the bar's fastest particle
    result = frictherm.run(scene.copy().set("solver.cfl", cfl), output=f"/tmp/bar_cfl{cfl}.h5", threads=1,
                           observer=lambda s: peak.append(abs(s.particles()["velocity"][:, 0]).max()), every=10)
    with frictherm.open(result["output"]) as run:
        ke = run.series.to_dataframe()["kinetic_energy"]
        print(f"C = {cfl}: {result['steps']} steps, {result['wall_time']:.2f} s, "
              f"kinetic energy {ke.iloc[0]:.4g} -> {ke.iloc[-1]:.4g} {run.unit_of('kinetic_energy')}, "
              f"fastest particle {max(peak):.3f} m/s")
