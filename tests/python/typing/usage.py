"""Typed use of dualgrid, checked by mypy --strict against the stubs (python_stubs). Not run."""
import numpy as np
import numpy.typing as npt

import dualgrid


def first_grid(path: str) -> npt.NDArray[np.float32]:
    sim = dualgrid.CoSimulation(path, modes=["dual"], seed=1, duration=2.0)
    for step in sim:
        grid: dualgrid.StepGrid = step.grids["dual"]
        dv: float = sim.metrics()["dual"]["tracked_fraction_v"]
        print(step.time, step.ego_pose[2], grid.extent[0], dv, len(step.detections))
        return grid.masses
    raise RuntimeError("no step")


def filter_once() -> int:
    params = dualgrid.preset("dualgrid")
    params.num_particles = 2000
    grid = dualgrid.DynamicGrid(params, seed=1)
    radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8),
                                options=dualgrid.ModelOptions(noise=False), seed=1)
    ego = dualgrid.EgoMotion(pose=(0.0, 0.0, 0.0), velocity=(10.0, 0.0), length=4.5, width=1.8)
    dets = radar.scan(ego, {"targets": [dict(id=1, x=30.0, y=0.0, length=4.5, width=1.8)]},
                      step=0, time=0.0)
    grid.update(ego_pose=ego.pose, detections=dualgrid.detections_to_measurements(dets),
                coverage=radar.coverage(ego.pose), dt=0.05)
    classes = dualgrid.classify_cells(grid.masses(), threshold=0.6)
    clusters = dualgrid.cluster_particles(dualgrid.dynamic_particles(grid, classes))
    return len(clusters["x"])
