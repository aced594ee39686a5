// The co-simulation step: SUMO -> radar -> one grid filter per weight mode -> scoring, with hooks
// (StepObserver) for what a caller does after each step (writers, a replay recorder, figures).
// The data's way: scenario -> CoSimulation::Step() -> observers; results by Metrics().
//
//   cosim::CoSimulation cs(config, {.modes = {filter::WeightMode::kDual}});
//   cs.Start(sim::DefaultNetworkDir(), work_dir);   // SUMO
//   MyWriter w;  cs.AddObserver(&w);
//   while (cs.Step()) {}
//   const auto metrics = cs.Metrics();              // one eval::ScenarioMetrics per mode
#pragma once

#include <cstdint>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/cosim/mode_schedule.hpp"
#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/eval/metrics.hpp"

namespace dualgrid::cosim {

struct CoSimOptions {
  /// Weight modes run side by side on the same detections; empty: SUMO and the radar only.
  std::vector<filter::WeightMode> modes = {
      filter::WeightMode::kPosition, filter::WeightMode::kVelocity, filter::WeightMode::kDual};
  /// OpenMP threads; 0: the OpenMP default. The modes run concurrently, each on a fixed thread
  /// (ModeSchedule, planned from the filters' measured times after the first steps and re-planned
  /// now and then); threads beyond one per mode go to each filter's own loops. Results do not
  /// depend on it.
  int threads = 0;
  /// Performance switch: when a thread runs fewer filters than the others (3 modes on 2
  /// threads), the step's region also reads the next step (SUMO's step and the radar scan; for
  /// recorded data a twin of the source) and builds that step's measurement grid, on whichever
  /// thread is free (Pipeline::ReadAhead, PrepareAhead; StepRegion; for SUMO the grid only while
  /// another thread has work left in the region, else Advance builds it with every thread).
  /// Results do not depend on it:
  /// the grid is taken only for the same inputs, and an error or the end met reading ahead
  /// surfaces at the next Step(), where it would have without it. SUMO then stands one step ahead
  /// between steps: a run stopped early has simulated that step too (sumo(), SUMO's own
  /// outputs). Its gain is measured in docs/performance.md.
  bool read_ahead = true;
};

/// What observers see after a step. Every reference is valid during OnStep() only.
struct StepView {
  int step = 0;  ///< 0 for the first step of the run
  const sim::Frame& frame;
  const Pipeline& pipeline;  ///< detections, radar, grids, grid frame, ids
  const std::vector<std::string>& mode_names;
  /// Per mode: the cell masses (and mean velocities if some observer asked, see
  /// StepObserver::WantsVelocities) after this step's filter cycle.
  const std::vector<GridSnapshot>& snapshots;
  /// Per mode: this step's clusters and their association (ModeScorer::clusters()).
  const std::vector<ModeScorer>& scorers;
  /// Ground-truth objects in the grid frame, as scored (the same for every mode).
  const std::vector<eval::TruthObject>& objects;
  /// Ground-truth eval::CellClass per cell of the grid (TruthClasses; the same geometry for every
  /// mode, index y * cells_x + x); empty without modes.
  const std::vector<std::uint8_t>& truth_classes;
  bool with_velocities = false;
};

/// A hook run after every step, on the calling thread, in the order added. Exceptions thrown by
/// OnStep propagate out of CoSimulation::Step() (the step itself is complete by then).
///
/// Work of a step that needs only part of it may be done earlier, in Prepare, inside the step's
/// parallel region on whichever thread is free (StepRegion), while other modes' filters still
/// run. Per step, every observer gets Prepare(view, kStep, -1), then for every mode m
/// Prepare(view, kFiltered, m) and after it Prepare(view, kScored, m), all before its OnStep. The
/// parts' inputs are complete when they run, and nothing that runs with them writes them:
/// - kStep: the step's data (frame, detections, labels, the pipeline's current step and grid
///   frame) and the ground truth (objects, truth_classes). The next step has been read ahead
///   by then (CoSimOptions::read_ahead), so pipeline.ids() and sumo() read as in OnStep.
/// - kFiltered, mode m: also grid(m) after its cycle and snapshots[m]'s masses and classes.
/// - kScored, mode m: also scorers[m] and snapshots[m]'s mean velocities (when asked).
/// Other modes' grids, snapshots and scorers may be in the making during a part: it must not
/// read them. Parts of one step may run at the same time on different threads (other modes',
/// other observers'), so each writes only state of its own for that part (e.g. one slot per
/// mode); OnStep then reads it on the calling thread. What a part computes must not depend on
/// the thread or the time it runs (the run's files are the same bytes on 1, 2 or 4 threads). An
/// exception thrown by a part is thrown by Step() where this observer's OnStep would have run
/// (after the earlier observers' OnStep; this observer's OnStep does not run then). When a
/// filter or the ground truth failed, Step() throws that error and some parts may not run.
class StepObserver {
 public:
  enum class Part { kStep, kFiltered, kScored };
  virtual ~StepObserver() = default;
  /// Asked after SUMO and the radar advanced, before the filters run: whether OnStep of this
  /// step needs the cells' mean velocities in the snapshots (a pass over every particle, so only
  /// when drawn or recorded).
  virtual bool WantsVelocities(int /*step*/, double /*time*/) { return false; }
  /// Early work of this step (see the class comment); the default does none.
  virtual void Prepare(const StepView& /*view*/, Part /*part*/, int /*mode*/) {}
  virtual void OnStep(const StepView& view) = 0;
};

class CoSimulation {
 public:
  /// Validates (memory, sensors; std::invalid_argument) and allocates the filters. SUMO is not
  /// started: nothing is written until Start().
  CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options = {});
  /// The same loop on another detection source (a recorded sequence: recorded_source.hpp).
  /// With labelled points, every mode also gets the point-level scores (ScenarioMetrics::points).
  CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options,
               const Pipeline::SourceFactory& make_source);

  /// Starts SUMO (Pipeline::Start): `work_dir` receives sumo.log.
  void Start(const std::filesystem::path& network_dir, const std::filesystem::path& work_dir);
  /// `observer` is not owned and must outlive the run.
  void AddObserver(StepObserver* observer);

  /// One step: SUMO, radar and the measurement grid (unless read ahead in the last step's
  /// region), then one parallel region: every mode's filter cycle (each on the thread
  /// ModeSchedule names), the shared ground truth, every mode's scoring and, with read_ahead, the
  /// next step's SUMO step and radar scan and (while another thread is busy) its measurement
  /// grid, and the observers' Prepare parts, each taken by whichever thread is free
  /// (StepRegion); then the observers' OnStep. False at the end
  /// of the run (nothing done then). An exception of SUMO or the radar is thrown by the Step() of
  /// the step it belongs to, after the observers of every earlier step ran.
  bool Step();
  /// Ends the run: SUMO closes and writes its own outputs (Pipeline::Finish). Results, the last
  /// frame and the end state stay readable; Step() must not be called again.
  void Finish() { pipeline_.Finish(); }

  const Pipeline& pipeline() const { return pipeline_; }
  const scenario::ScenarioConfig& config() const { return pipeline_.config(); }
  const std::vector<std::string>& mode_names() const { return mode_names_; }
  const std::vector<ModeScorer>& scorers() const { return scorers_; }
  /// Steps done so far.
  int steps() const { return steps_; }
  /// Simulated time of the steps done [s] (recorded data: steps x their mean cycle).
  double simulated() const { return steps_ * config().sim.step_length; }
  /// SUMO reached the scenario's duration with the ego in the network (its frames start at the
  /// ego's departure, so a late departure still finishes). False while running, and when the
  /// ego left the network early (pipeline().simulation().ego_left()).
  bool finished() const;
  std::size_t total_detections() const { return total_detections_; }
  /// Per mode, the paper's metrics over the steps done so far.
  std::vector<eval::ScenarioMetrics> Metrics() const;

 private:
  friend class StepRegion;  // one step's parallel region (step_region.hpp)
  // The step's filters, scoring and the observers' Prepare parts; returns per observer the first
  // exception of its parts (null if none).
  std::vector<std::exception_ptr> FilterAndScore(const StepView& view);
  // The schedule of this step for `team` threads: round robin at first, then re-planned from the
  // filters' measured times (cosimulation.cpp, before ScheduleFor's definition).
  const ModeSchedule& ScheduleFor(int modes, int team);

  Pipeline pipeline_;
  std::vector<std::string> mode_names_;
  std::vector<ModeScorer> scorers_;
  std::vector<GridSnapshot> snapshots_;  // storage reused every step
  std::vector<eval::TruthObject> objects_;
  std::vector<std::uint8_t> truth_classes_;
  std::vector<Position> point_positions_;  // this step's detections, grid frame (labelled data)
  std::vector<StepObserver*> observers_;
  int threads_ = 0;
  bool read_ahead_ = true;
  int steps_ = 0;
  std::optional<ModeSchedule> schedule_;
  int schedule_team_ = 0;
  std::vector<double> filter_seconds_;  // per mode, since the last plan [s]
  int timed_steps_ = 0, next_plan_ = 0, replan_every_ = 0;
  bool warming_up_ = true;
  std::size_t total_detections_ = 0;
};

}  // namespace dualgrid::cosim
