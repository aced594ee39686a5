"""dualgrid: radar-only dynamic occupancy grid with dual-weight particle filter, and its radar model.

The compiled extension ``dualgrid._dualgrid`` does the work; this package re-exports it and adds
small pure-Python conveniences. Units: metres, seconds, m/s, radians; angles counter-clockwise
from +x. See docs/python.md for the API, frames and a worked example.

    import dualgrid, numpy as np
    grid = dualgrid.DynamicGrid(dualgrid.preset("dualgrid"), seed=1)
    radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=1)
    dets = radar.scan(ego, scene, step=0, time=0.0, step_length=0.05)
    grid.update(ego_pose=(0, 0, 0), ego_velocity=(0, 0),
                detections=dualgrid.detections_to_measurements(dets),
                coverage=radar.coverage((0, 0, 0), radar.sensors_due(0.0, 0.05)), dt=0.05)
    grid.masses()["dynamic"]   # (cells_y, cells_x) float32
"""

import numpy as _np

from ._dualgrid import (
    DynamicGrid,
    FilterParams,
    __version__,
    get_num_threads,
    preset,
    preset_names,
    set_num_threads,
)

# TODO(cosim): re-export run_scenario once _dualgrid binds dualgrid::cosim (see module.cpp).

#: Columns of DynamicGrid.update()'s detections array, in order.
MEASUREMENT_COLUMNS = ("x", "y", "v_rx", "v_ry", "sensor_x", "sensor_y")
#: Columns of DynamicGrid.update()'s coverage array, in order.
COVERAGE_COLUMNS = ("origin_x", "origin_y", "boresight", "half_fov", "min_range", "max_range")

__all__ = [
    "COVERAGE_COLUMNS",
    "DynamicGrid",
    "FilterParams",
    "MEASUREMENT_COLUMNS",
    "__version__",
    "get_num_threads",
    "preset",
    "preset_names",
    "set_num_threads",
]
