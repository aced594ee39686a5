// One run's data path: a detection source (SUMO and the radar model, or a recorded sequence:
// detection_source.hpp) gives each step's detections, and they become the inputs of any number
// of grid filters (one per weight mode), in the grid frame. CoSimulation (cosimulation.hpp) runs
// the filters and the scoring on top of it.
#pragma once

#include <array>
#include <exception>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dualgrid/core/grid_frame.hpp"
#include "dualgrid/cosim/detection_source.hpp"
#include "dualgrid/eval/association.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace dualgrid::cosim {

/// Stable integer ids for named things (radar source ids, evaluation object ids): static
/// obstacles first, vehicles in order of first appearance (deterministic: frames are sorted).
class IdRegistry {
 public:
  int Id(const std::string& name);
  /// The id of a name already registered.
  std::optional<int> Find(const std::string& name) const;
  const std::string& Name(int id) const;  ///< "clutter" for -1

 private:
  std::map<std::string, int> ids_;
  std::vector<std::string> names_;
};

/// Throws std::invalid_argument, naming the scenario file and its filter keys, when `modes`
/// filters of `config` would need more than 80 % of this machine's physical memory
/// (FilterParams::MemoryBytes). Called once, by the Pipeline constructor, before anything is
/// allocated or written.
void CheckFilterMemory(const scenario::ScenarioConfig& config, std::size_t modes);

/// Lifetime: construct (validates and allocates the filters; SUMO not started), Start() (SUMO),
/// then Advance() / UpdateFilter() per step. Not copyable; one SUMO instance per process
/// (libsumo is a process-wide singleton), so one started Pipeline on SUMO at a time.
class Pipeline {
 public:
  /// The co-simulation (SumoSource). Throws std::invalid_argument for a configuration that
  /// cannot run (memory, sensors). The filters' cycle is the step length (FilterFor).
  Pipeline(const scenario::ScenarioConfig& config, std::vector<filter::WeightMode> modes);
  /// Another source (a recorded sequence): `make_source` builds it from the pipeline's copy of
  /// `config` and its IdRegistry. The filters' per-cycle factors refer to config.filter.cycle
  /// (FilterParams::cycle), not to the step length.
  using SourceFactory = std::function<std::unique_ptr<DetectionSource>(
      const scenario::ScenarioConfig& config, IdRegistry& ids)>;
  Pipeline(const scenario::ScenarioConfig& config, std::vector<filter::WeightMode> modes,
           const SourceFactory& make_source);
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Starts SUMO on the scenario's network, looked up in `network_dir` (a network named by a
  /// path is read relative to the scenario file). `work_dir` receives SUMO's route file and log
  /// (sumo.log). Throws std::invalid_argument for a missing network, std::runtime_error for a
  /// SUMO error. Call once.
  void Start(const std::filesystem::path& network_dir, const std::filesystem::path& work_dir);
  bool started() const { return source_->started(); }
  /// Ends SUMO (sim::SumoSimulation::Close: its outputs are written); everything read from the
  /// last step stays readable, Advance() must not be called again. No-op before Start().
  void Finish();

  /// Advances SUMO one step, scans the due radars and prepares the filters' inputs, with their
  /// shared measurement grid (step 4, built once for every mode). False at the end (the duration
  /// reached, or the ego left the network). Needs Start(). When ReadAhead() has read this step
  /// already (a source that can_run_ahead()), the step is taken from there, and so is what
  /// happened reading it: the end (false) or the source's exception, thrown here, at the step it
  /// belongs to, as if the source had been read now.
  bool Advance();
  /// Updates filter `i` with the inputs of the last Advance(). Independent per filter, so callers
  /// may run the filters concurrently (a filter's loops then run on its thread alone, without an
  /// OpenMP team: dualgrid/core/parallel.hpp, docs/performance.md).
  void UpdateFilter(std::size_t i);
  /// Draws the filters' prediction normals (filter::PredictionNoise) once for every mode (they
  /// share seed and step): `ahead` = false for the cycle UpdateFilter runs next (call it before
  /// the filters of a step), true for the one after (may run while those filters run: another
  /// slot, and it reads no filter). UpdateFilter reads them when they match its cycle and draws
  /// its own otherwise, so calling this only saves work. No-op without filters or when drawn.
  void DrawNoise(bool ahead);
  /// For a source that can_run_ahead() (SUMO): reads the next step from the source itself (its
  /// Advance and Scan: SUMO's step and the radar scan), at most one step ahead (a second call
  /// does nothing). Call it on a thread with time to spare while the filters of a step run,
  /// after the step's last TruthObjects() call: it writes the source, ids() and its own buffers,
  /// reads none of the filters, and writes nothing the step's readers see (frame(),
  /// ego_motion(), detections(), scanned(), labels(), grid_frame() and reached_end() keep
  /// describing the current step). That step is the run's: the next Advance() hands it out, and
  /// an exception or the end met reading it surfaces there (see Advance()). Until then the
  /// source (sumo()) stands one step beyond frame(); when the run stops before it (a stop
  /// request, Finish()), SUMO has simulated that one step more. Other sources: no-op.
  void ReadAhead() noexcept;
  /// Builds the next step's measurement grid (step 4) for Advance() to take instead of building
  /// it, under the same conditions as ReadAhead(): for a source that can_run_ahead(), of the step
  /// ReadAhead() read (reading it first if needed); for a source with a Twin() (recorded data),
  /// of the next step read from that twin, a second source over the same data made at the first
  /// call (the source itself is read in Advance(); errors are not thrown: the speculation stops
  /// for the run, and Advance() meets any error of the data at its own step). Advance() takes
  /// the grid only when its own inputs (measurements, coverage, centre) are the same bits, so
  /// results never depend on it. Costs a second measurement grid (as large as the first), made
  /// at the first call. Other sources: no-op.
  void PrepareAhead() noexcept;
  /// Steps ReadAhead() read (not counting an end or an error met).
  std::uint64_t ahead_read() const { return ahead_.read_steps; }
  /// Steps whose measurement grid PrepareAhead() built, and those of them Advance() took.
  std::uint64_t ahead_prepared() const { return ahead_.prepared; }
  std::uint64_t ahead_hits() const { return ahead_hits_; }

  /// The scenario as given: never rewritten (the rig as mounted is radar().sensors()).
  const scenario::ScenarioConfig& config() const { return config_; }
  /// Ground truth of the last Advance() (a copy: the source may be read ahead). Needs Start().
  const sim::Frame& frame() const { return current_.frame; }
  /// The source had reached its own end (DetectionSource::reached_end) with the last Advance()'s
  /// step, or when Advance() returned false; what the source says now may be a step ahead.
  bool reached_end() const { return current_.reached_end; }
  /// SUMO; throws std::logic_error for a source without it (recorded data): see sumo().
  const sim::SumoSimulation& simulation() const;
  /// SUMO, or nullptr for a recorded sequence. SUMO's own state (its clock, ego_left()) may stand
  /// one step beyond frame() while a step is read ahead (ReadAhead).
  const sim::SumoSimulation* sumo() const { return source_->sumo(); }
  const DetectionSource& source() const { return *source_; }
  /// The radars as mounted on the ego's box as SUMO simulates it: built once, at the ego's
  /// departure (the first Advance()); for recorded data as the sequence's sensors say. Needs one
  /// Advance().
  const radar::RadarModel& radar() const { return source_->radar(); }
  bool has_radar() const { return source_->has_radar(); }
  /// Labels of the last step's detections (recorded data; empty otherwise).
  const PointLabels& labels() const { return current_.labels; }
  /// Detections of the last step (only sensors that were due), world frame.
  const std::vector<radar::Detection>& detections() const { return current_.detections; }
  /// Sensors that scanned in the last step.
  const std::vector<int>& scanned() const { return current_.scanned; }
  const radar::EgoMotion& ego_motion() const { return current_.ego; }
  std::size_t num_filters() const { return filters_.size(); }
  filter::WeightMode mode(std::size_t i) const { return modes_[i]; }
  const filter::DynamicGrid& grid(std::size_t i) const { return *filters_[i]; }
  IdRegistry& ids() { return ids_; }
  const IdRegistry& ids() const { return ids_; }

  /// The grid frame (docs/algorithm.md, "Grid frame") of the last Advance(): set at the first
  /// from the scenario's `filter.frame` and the ego's heading then; with `frame: follow` turned
  /// again whenever the ego's lane has turned by `filter.realign_deg`. Identity before.
  const GridFrame& grid_frame() const { return grid_frame_; }
  /// The grid frame turned in the last Advance() (the filters turn with it in UpdateFilter).
  bool grid_realigned() const { return realign_angle_ != 0.0; }
  /// Turns of the grid frame so far.
  int grid_realignments() const { return realignments_; }
  /// The grid's footprint in the world after the last step's filter cycles: centre [m], yaw (the
  /// grid frame's) [rad], length_x and width_y [m]. With filters, the lattice the first filter
  /// actually covers (it moves by whole cells); without, where it would lie. Needs one Advance().
  OrientedBox GridFootprint() const;

  /// Ground-truth vehicles (ego excluded) as evaluation objects for a grid, in the grid frame
  /// (boxes and velocities: the clusters' frame): in_grid when the centre lies in the grid,
  /// in_coverage when the centre lies in some radar's field of view. Reads only: safe to call
  /// from several threads once Advance() returned.
  std::vector<eval::TruthObject> TruthObjects(const filter::DynamicGrid& grid) const;

 private:
  // At the first step: the grid frame.
  void FixFrame(const sim::Frame& f);
  void MakeFilters(bool cycle_is_step);
  // With `filter.frame: follow`, the grid frame's new yaw when the road of frame `f` has turned
  // from the current grid frame; nullopt otherwise. Reads only.
  std::optional<double> TurnedYaw(const sim::Frame& f) const;
  // One step as read from a source: everything the run reads of it per step, copied out, so
  // that the source may run a step ahead (current_ and ahead_.step: a double buffer).
  struct StepData {
    sim::Frame frame;
    radar::EgoMotion ego;
    std::vector<radar::Detection> detections;
    std::vector<int> scanned;
    PointLabels labels;
    bool reached_end = false;
  };
  // Advances `source` and scans its new step into `step`; false at the source's end (`step`
  // untouched). Exceptions of the source propagate (`step` may then hold part of the step).
  static bool ReadStep(DetectionSource& source, IdRegistry& ids, StepData* step);
  // The next step into current_: the one ReadAhead read (or its end or exception), else the
  // source's next.
  bool NextStep();
  // PrepareAhead for a source with a Twin(): reads the twin's next step into ahead_.step.
  void ReadTwinAhead() noexcept;
  // Builds the measurement grid of ahead_.step (seen by `radar`) into ahead_.grid, in the grid
  // frame that step will have. Throws what FilterInputs and Build throw.
  void BuildAhead(const radar::RadarModel& radar);
  // Step 4's inputs of `step` (seen by `radar`) in the grid frame `g`; returns the grid centre.
  // Reads only.
  Position FilterInputs(const StepData& step, const radar::RadarModel& radar, const GridFrame& g,
                        std::vector<filter::Measurement>* measurements,
                        std::vector<filter::SensorCoverage>* coverage) const;

  scenario::ScenarioConfig config_;
  IdRegistry ids_;
  std::unique_ptr<DetectionSource> source_;
  std::vector<filter::WeightMode> modes_;
  std::vector<std::unique_ptr<filter::DynamicGrid>> filters_;
  // This step's measurement grid, shared by the filters that share its geometry (all of ours),
  // and the parameters it was made with.
  std::unique_ptr<filter::MeasurementGrid> measurement_;
  filter::FilterParams measurement_params_;
  // Prediction normals shared by the modes, by cycle parity (DrawNoise).
  std::array<filter::PredictionNoise, 2> noise_;
  std::uint64_t noise_cycle_ = 0;  // the filters' cycle at the last DrawNoise(false)
  StepData current_;               // the step of the last Advance()
  std::vector<filter::Measurement> measurements_;
  std::vector<filter::SensorCoverage> coverage_;
  double last_time_ = 0.0;
  bool first_step_ = true;
  double dt_ = 0.0;  // of the last Advance() [s]
  GridFrame grid_frame_;
  double realign_angle_ = 0.0;  // the grid frame's turn in the last Advance() [rad]
  int realignments_ = 0;
  Vector2 centre_offset_ = Vector2::Zero();  // ego -> grid centre, grid frame [m]
  std::uint64_t advances_ = 0;               // Advance() calls that returned true
  // PrepareAhead's state: the next step (read from the source itself, `read`; or from the
  // source's twin, with its own ids, `advances` calls), and its inputs and measurement grid, for
  // Advance() number `advances` when `ready`.
  struct Ahead {
    // What ReadAhead read from the source itself, for the next Advance() to hand out.
    enum class Read { kNothing, kStep, kEnd, kError };
    Read read = Read::kNothing;
    std::exception_ptr error;  // with kError
    std::unique_ptr<DetectionSource> source;
    IdRegistry ids;
    std::uint64_t advances = 0, prepared = 0, read_steps = 0;
    bool given_up = false;  // no twin, the end reached, or an error: no more reading ahead
    bool ready = false;
    StepData step;
    std::vector<filter::Measurement> measurements;
    std::vector<filter::SensorCoverage> coverage;
    Position centre = Position::Zero();
    std::unique_ptr<filter::MeasurementGrid> grid;
  } ahead_;
  std::uint64_t ahead_hits_ = 0;
};

}  // namespace dualgrid::cosim
