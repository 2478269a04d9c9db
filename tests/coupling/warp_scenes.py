"""The two runs the warp checks share (vtk_warp.py, paraview_warp.py): a soft disk thrown at a fixed
floor in 2D and a ball at a fixed bottom face in 3D; both squash and move, so the displacement varies
over the body."""

MATERIAL = {"type": "linear_elastic", "density": 1000, "youngs_modulus": 2e6, "poisson_ratio": 0.3}

SCENES = {
    # A soft disk thrown at a fixed floor: it squashes, so u and v vary over the body.
    2: {"dimension": 2,
        "grid": {"lo": [0, 0], "hi": [0.06, 0.05], "cell_size": 0.002},
        "materials": {"soft": MATERIAL},
        "bodies": [{"name": "disk", "material": "soft", "velocity": [1.0, -6.0],
                    "shape": {"type": "disk", "center": [0.03, 0.018], "radius": 0.012}}],
        "boundary": {"fixed": [{"face": "y_min"}]},
        "run": {"end_time": 1.6e-3, "threads": 1},
        "output": {"snapshot_count": 2}},
    3: {"dimension": 3,
        "grid": {"lo": [0, 0, 0], "hi": [0.04, 0.04, 0.04], "cell_size": 0.004},
        "materials": {"soft": MATERIAL},
        "bodies": [{"name": "ball", "material": "soft", "velocity": [0.5, 0.0, -6.0],
                    "shape": {"type": "sphere", "center": [0.02, 0.02, 0.016], "radius": 0.01}}],
        "boundary": {"fixed": [{"face": "z_min"}]},
        "run": {"end_time": 2e-3, "threads": 1},
        "output": {"snapshot_count": 2}},
}
