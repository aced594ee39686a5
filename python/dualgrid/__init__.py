"""dualgrid: radar-only dual-weight particle-filter dynamic occupancy grid and its radar model.

The compiled extension ``dualgrid._dualgrid`` does the work; this package re-exports it and adds
small pure-Python conveniences. Units: metres, seconds, m/s, radians; angles counter-clockwise
from +x. See docs/python.md for the API, frames and a worked example.

    import dualgrid
    grid = dualgrid.DynamicGrid(dualgrid.preset("dualgrid"), seed=1)
    radar = dualgrid.RadarModel(dualgrid.default_rig(4.5, 1.8), seed=1)
    ego = dualgrid.EgoMotion(pose=(0.0, 0.0, 0.0), velocity=(10.0, 0.0), length=4.5, width=1.8)
    car = dict(id=1, x=30.0, y=0.0, yaw=0.0, length=4.5, width=1.8, vx=15.0, vy=0.0)
    dets = radar.scan(ego, {"targets": [car]}, step=0, time=0.0, step_length=0.05)
    grid.update(ego_pose=ego.pose, ego_velocity=ego.velocity,
                detections=dualgrid.detections_to_measurements(dets, ego_box=ego),
                coverage=radar.coverage(ego.pose, radar.sensors_due(0.0, 0.05)), dt=0.05)
    grid.masses()["dynamic"]   # (cells_y, cells_x) float32
"""

import os as _os
import sys as _sys
from typing import Any, Dict, Mapping, Optional, Sequence, Union

from ._build_info import BUILT_FOR as _BUILT_FOR
from ._build_info import BUILT_VERSION as _BUILT_VERSION
from ._build_info import EXT_SUFFIX as _EXT_SUFFIX


def _this_interpreter() -> str:
    return f"{_sys.executable} (Python {_sys.version.split()[0]})"


def _built_for() -> str:
    return f"{_BUILT_FOR} (Python {_BUILT_VERSION}, extension suffix {_EXT_SUFFIX})"


try:
    import numpy as _np
    import numpy.typing as _npt
except ImportError as _e:
    raise ImportError(
        f"dualgrid needs numpy, which this interpreter, {_this_interpreter()}, cannot import "
        f"({_e}). The module was built for {_built_for()}: run that interpreter, or a virtual "
        f"environment made from it with --system-site-packages (Debian's numpy), or rebuild for "
        f"this one (docs/python.md, 'Installation')") from _e

try:
    from ._dualgrid import (
        CELL_CLASSES,
        ROLE_NAMES,
        CoSimulation,
        DynamicGrid,
        EgoMotion,
        FilterParams,
        ModelOptions,
        MultipathParams,
        RadarModel,
        RecordedSimulation,
        Scene,
        SensorParams,
        Simulation,
        Step,
        StepGrid,
        __version__,
        associate,
        classify_cells,
        cluster_particles,
        default_long_range_radar,
        default_rig,
        default_short_range_radar,
        dynamic_particles,
        export_radarscenes,
        get_num_threads,
        preset,
        preset_names,
        read_nuscenes,
        read_radarscenes,
        read_recorded,
        run_recorded,
        score_cells,
        set_num_threads,
    )
    from ._dualgrid import run_scenario as _run_scenario
except ImportError as _e:
    _here = _os.path.dirname(_os.path.abspath(__file__))
    _found = sorted(f for f in _os.listdir(_here) if f.startswith("_dualgrid"))
    import sysconfig as _sysconfig
    raise ImportError(
        f"dualgrid's compiled module did not load in {_this_interpreter()}, which needs "
        f"_dualgrid{_sysconfig.get_config_var('EXT_SUFFIX')} ({_e}). This package in {_here} "
        f"holds {_found or 'no _dualgrid module'}, built for {_built_for()}: run that "
        f"interpreter, or a virtual environment made from it with --system-site-packages, or "
        f"rebuild for this one (cmake -DPython3_EXECUTABLE={_sys.executable}, or pip install "
        f"--no-build-isolation . with it; docs/python.md, 'Installation')") from _e


def installed_network_dir() -> Optional[str]:
    """The built SUMO networks of the installation this package belongs to.

    A package installed by pip holds them in dualgrid/networks; one installed by cmake --install
    lives in PREFIX/lib/python3/dist-packages/dualgrid, its networks in
    PREFIX/share/dualgrid/networks. None when neither exists (a build-tree package: run_scenario
    then uses the build tree's networks, or $DUALGRID_NETWORK_DIR).
    """
    here = _os.path.dirname(_os.path.abspath(__file__))
    prefix = _os.path.normpath(_os.path.join(here, "..", "..", "..", ".."))
    for candidate in (_os.path.join(here, "networks"),
                      _os.path.join(prefix, "share", "dualgrid", "networks")):
        if _os.path.isdir(candidate):
            return candidate
    return None


def run_scenario(path: Union[str, "_os.PathLike[str]"], seed: Optional[int] = None,
                 duration: Optional[float] = None,
                 modes: Sequence[str] = ("position", "velocity", "dual"),
                 overrides: Sequence[str] = (),
                 network_dir: Optional[Union[str, "_os.PathLike[str]"]] = None,
                 work_dir: Optional[Union[str, "_os.PathLike[str]"]] = None,
                 threads: int = 0,
                 out: Optional[Union[str, "_os.PathLike[str]"]] = None) -> Dict[str, Any]:
    """Runs a scenario file as `dualgrid run` does and returns its results as a dict.

    The same scenario and seed give the command line's numbers (metrics, objects, clusters).
    out: a folder to write the run folder of `dualgrid run --out` to (the same files).
    network_dir defaults to $DUALGRID_NETWORK_DIR, else this installation's networks
    (installed_network_dir()), else the build tree's. Full description:
    help(dualgrid._dualgrid.run_scenario) and docs/python.md.
    """
    if network_dir is None and not _os.environ.get("DUALGRID_NETWORK_DIR"):
        network_dir = installed_network_dir()
    return _run_scenario(str(path), seed=seed, duration=duration, modes=list(modes),
                         overrides=list(overrides), network_dir=network_dir, work_dir=work_dir,
                         threads=threads, out=None if out is None else str(out))



#: Columns of DynamicGrid.update()'s detections array, in order.
MEASUREMENT_COLUMNS = ("x", "y", "v_rx", "v_ry", "sensor_x", "sensor_y")
#: Columns of DynamicGrid.update()'s coverage array, in order.
COVERAGE_COLUMNS = ("origin_x", "origin_y", "boresight", "half_fov", "min_range", "max_range")
#: Columns of a target table (Scene), in order.
TARGET_COLUMNS = ("id", "x", "y", "yaw", "length", "width", "vx", "vy", "yaw_rate", "rcs_dbsm")


def detections_to_measurements(detections: Mapping[str, Any],
                               ego_box: Union["EgoMotion", Sequence[float], None] = None,
                               include_clutter: bool = True) -> "_npt.NDArray[_np.float64]":
    """The (N, 6) float64 array DynamicGrid.update() takes, from RadarModel.scan()'s dict.

    detections: the dict of columns of RadarModel.scan()/scan_sensor() (or a pandas.DataFrame of
        it); the result's columns are MEASUREMENT_COLUMNS: x, y [m], v_rx, v_ry [m/s] (paper
        eq. (1): compensated radial speed times the line of sight), sensor_x, sensor_y [m].
    ego_box: optional ego body to drop detections inside of, as the co-simulation does (nothing
        but the ego can be there; clutter drawn down to the sensors' minimum range would feed
        particles riding along with the ego): an EgoMotion with length and width > 0, or
        (x, y, yaw, length, width) [m, m, rad, m, m].
    include_clutter: False drops the model's false alarms (is_clutter), e.g. for a clean test.
    Returns a new array (a copy).
    """
    missing = [c for c in MEASUREMENT_COLUMNS if c not in detections]
    if missing:
        raise ValueError(
            f"detections: missing column(s) {missing} (expected RadarModel.scan()'s dict)")
    cols = [_np.asarray(detections[c], dtype=_np.float64).ravel() for c in MEASUREMENT_COLUMNS]
    keep = _np.ones(cols[0].shape[0], dtype=bool)
    if not include_clutter:
        if "is_clutter" not in detections:
            raise ValueError("detections: include_clutter=False needs the column 'is_clutter'")
        keep &= ~_np.asarray(detections["is_clutter"], dtype=bool).ravel()
    if ego_box is not None:
        if isinstance(ego_box, EgoMotion):
            (bx, by, byaw), length, width = ego_box.pose, ego_box.length, ego_box.width
        else:
            box = _np.asarray(ego_box, dtype=_np.float64).ravel()
            if box.shape != (5,):
                raise ValueError(
                    "ego_box: expected an EgoMotion or (x, y, yaw, length, width) "
                    f"[m, m, rad, m, m], got {ego_box!r}")
            bx, by, byaw, length, width = box
        # The inside test of core/types.hpp's BoxTest: |R^T (p - c)| <= (L/2, W/2).
        c, s = _np.cos(byaw), _np.sin(byaw)
        dx, dy = cols[0] - bx, cols[1] - by
        along, across = c * dx + s * dy, -s * dx + c * dy
        keep &= ~((_np.abs(along) <= 0.5 * length) & (_np.abs(across) <= 0.5 * width))
    out: "_npt.NDArray[_np.float64]" = (_np.column_stack(cols)[keep] if cols[0].size
                                        else _np.empty((0, 6)))
    return out


__all__ = [
    "MultipathParams",
    "associate",
    "classify_cells",
    "cluster_particles",
    "dynamic_particles",
    "export_radarscenes",
    "read_recorded",
    "score_cells",
    "CELL_CLASSES",
    "CoSimulation",
    "ROLE_NAMES",
    "RecordedSimulation",
    "Simulation",
    "Step",
    "StepGrid",
    "COVERAGE_COLUMNS",
    "DynamicGrid",
    "EgoMotion",
    "FilterParams",
    "MEASUREMENT_COLUMNS",
    "ModelOptions",
    "RadarModel",
    "Scene",
    "SensorParams",
    "TARGET_COLUMNS",
    "__version__",
    "default_long_range_radar",
    "default_rig",
    "default_short_range_radar",
    "detections_to_measurements",
    "get_num_threads",
    "installed_network_dir",
    "preset",
    "preset_names",
    "run_recorded",
    "read_nuscenes",
    "read_radarscenes",
    "run_scenario",
    "set_num_threads",
]
