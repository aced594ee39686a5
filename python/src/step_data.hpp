// One co-simulation step as Python sees it (dualgrid.CoSimulation, stepping_bindings.cpp): a
// copy of what the observers see (cosim::StepView, whose storage the next step reuses), owned by
// one StepData that every numpy array of the step views without a further copy.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "dualgrid/cosim/cosimulation.hpp"

namespace dualgrid::python {

/// One detection, world frame (numpy structured dtype of the same fields).
struct DetectionRow {
  std::int32_t sensor;
  double range, azimuth, range_rate, snr_db;  ///< measured [m, rad sensor frame, m/s]
  double x, y;                                ///< world [m]
  double x_ego, y_ego;                        ///< ego frame [m]
  double radial_speed_compensated;            ///< over ground [m/s]
  double v_rx, v_ry;                          ///< eq. (1) [m/s], world
  double sensor_x, sensor_y;                  ///< world [m]
  std::int32_t source_id;                     ///< object id, -1 clutter or ghost
  bool is_clutter;
  std::int32_t label;  ///< recorded label_id, -1 none
};

/// One ground-truth object as scored, world frame.
struct TruthRow {
  std::int32_t id;       ///< Step.names key
  double x, y, yaw;      ///< box centre [m], heading [rad]
  double length, width;  ///< [m]
  double vx, vy;         ///< [m/s]
  bool in_grid, in_coverage, detected_in_grid;
};

/// One cluster of a mode, world frame (clusters.csv's row).
struct ClusterRow {
  double x, y;    ///< weighted mean position [m]
  double vx, vy;  ///< weighted mean velocity [m/s]
  double weight;  ///< summed dynamic mass
  std::int32_t particles;
  std::int8_t role;     ///< 0 matched, 1 duplicate, 2 false (ROLE_NAMES)
  std::int32_t object;  ///< matched truth id, -1 none
};

/// One mode's grid after the step, grid frame, row-major [iy][ix].
struct GridData {
  int cells_x = 0, cells_y = 0;
  double resolution = 0.0;                    ///< [m]
  std::int64_t origin_ix = 0, origin_iy = 0;  ///< global index of cell (0, 0)
  std::vector<float> masses;                  ///< (ny, nx, 3): free, static, dynamic
  std::vector<float> velocity;                ///< (ny, nx, 2) [m/s]; empty when not taken
  std::vector<std::uint8_t> classes, observed;
  std::vector<double> x, y;  ///< cell centres [m], nx and ny entries
  std::vector<ClusterRow> clusters;
  std::int64_t confusion[3][4] = {};  ///< this step's cells [truth][predicted], observed only
  int matched = 0, duplicate = 0, false_clusters = 0, objects_matched = 0;
};

struct StepData {
  int step = 0;
  double time = 0.0;                                                 ///< [s]
  double ego_x = 0, ego_y = 0, ego_yaw = 0, ego_vx = 0, ego_vy = 0;  ///< world [m, rad, m/s]
  double grid_yaw = 0.0;  ///< the grid frame's x axis, world heading [rad]
  std::vector<DetectionRow> detections;
  std::vector<TruthRow> truth;
  std::vector<std::pair<int, std::string>> names;  ///< truth and cluster object ids -> names
  std::vector<std::uint8_t> truth_classes;         ///< (ny, nx), the same for every mode
  std::vector<std::string> modes;
  std::vector<GridData> grids;  ///< per mode
};

/// Copies what `v` shows (velocities only when the snapshots hold them).
std::shared_ptr<const StepData> CopyStep(const cosim::StepView& v);

/// Keeps the last step's copy (the observer of a stepped CoSimulation).
class StepCollector : public cosim::StepObserver {
 public:
  explicit StepCollector(bool velocities) : velocities_(velocities) {}
  bool WantsVelocities(int, double) override { return active_ && velocities_; }
  void OnStep(const cosim::StepView& v) override {
    if (fail_next_) {
      fail_next_ = false;
      throw std::runtime_error("failure injected by _fail_next_step() (a test aid)");
    }
    if (active_) last_ = CopyStep(v);
  }
  /// Testing aid: the next OnStep throws, as an observer's error would (the error path of
  /// CoSimulation::Step).
  void FailNextStep() { fail_next_ = true; }
  /// Inactive: no copies (a run to the end that wants only the results).
  void set_active(bool active) { active_ = active; }
  std::shared_ptr<const StepData> Take() { return std::move(last_); }

 private:
  bool velocities_;
  bool active_ = true;
  bool fail_next_ = false;
  std::shared_ptr<const StepData> last_;
};

/// Registers the numpy dtypes and binds Step and StepGrid (step_bindings.cpp; the arrays are
/// read-only views of the StepData).
void BindStep(py::module_& m);
/// A Python Step owning `d`.
py::object WrapStep(std::shared_ptr<const StepData> d);

}  // namespace dualgrid::python
