// Entry points of the `_dualgrid` extension's parts (module.cpp calls them in order).
#pragma once

#include <pybind11/pybind11.h>

namespace dualgrid::python {

namespace py = pybind11;

/// FilterParams, presets, DynamicGrid (filter_bindings.cpp).
void BindFilter(py::module_& m);
/// SensorParams, default rigs, ModelOptions, EgoMotion, Scene, RadarModel (radar_bindings.cpp).
void BindRadar(py::module_& m);

/// run_scenario on dualgrid::cosim (cosim_bindings.cpp).
void BindCosim(py::module_& m);
/// run_recorded (recorded_bindings.cpp): the filters on a recorded sequence.
void BindRecorded(py::module_& m);
/// read_nuscenes, read_radarscenes (nuscenes_bindings.cpp): recorded data as numpy columns.
void BindNuScenes(py::module_& m);
/// classify_cells, score_cells, dynamic_particles, cluster_particles, associate
/// (eval_bindings.cpp).
void BindEval(py::module_& m);
/// CoSimulation, RecordedSimulation, Step, StepGrid (stepping_bindings.cpp, step_bindings.cpp).
void BindStepping(py::module_& m);

/// Applies the thread count chosen with dualgrid.set_num_threads (0: OpenMP's default) to the
/// calling thread. OpenMP's thread count is per calling thread, so every call that runs a parallel
/// C++ stage (grid update, radar scan) applies it first, on the thread doing the work.
void ApplyThreadCount();

/// `n` when it is a thread count the command line accepts ([0, 4 per core]: core/limits.hpp);
/// otherwise ValueError "<fn>: <key> must be >= 0 and <= N (...), got n".
int CheckThreads(int n, const char* fn, const char* key);

}  // namespace dualgrid::python
