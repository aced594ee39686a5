// The results of a run through dualgrid::cosim as Python objects, shared by run_scenario
// (cosim_bindings.cpp) and run_recorded (recorded_bindings.cpp): the same dict for both.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "dualgrid/cosim/cosimulation.hpp"

namespace dualgrid::python {

/// Every cluster of every step and mode, as clusters.csv holds them (world frame).
struct ClusterColumns : cosim::StepObserver {
  std::vector<int> step;
  std::vector<double> time, x, y, vx, vy, weight;
  std::vector<int> particles;
  std::vector<std::string> mode, role, object;

  void OnStep(const cosim::StepView& v) override;
  py::dict Columns() const;
};

/// JSON as Python objects (dicts, lists, numbers, None).
py::object FromJson(const nlohmann::json& j);

/// The result dict of a finished run: scenario, seed, steps, simulated_s, requested_s,
/// complete, detections_per_step, metrics, object_names, objects, clusters.
py::dict Results(const cosim::CoSimulation& cs, const scenario::ScenarioConfig& config,
                 const ClusterColumns& clusters);

}  // namespace dualgrid::python
