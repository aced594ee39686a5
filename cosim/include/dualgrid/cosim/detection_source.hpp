// Where a Pipeline's detections come from, step by step: SUMO and the radar model (SumoSource,
// the co-simulation) or a recorded sequence (RecordedSource, recorded_source.hpp). The Pipeline
// owns one and does the rest, the same for both: the grid frame, the filters' inputs and
// cycles, the ground truth as scored. Everything a source gives is in the world frame (for
// recorded data the sequence's frame).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "dualgrid/radar_model/radar_model.hpp"
#include "dualgrid/recorded/sequence.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/ground_truth.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace dualgrid::cosim {

class IdRegistry;

/// Per detection of a recorded step: its RadarScenes label (0-10 a moving road user's class,
/// 11 static, -1 unlabelled). Empty when the source has no labels.
using PointLabels = std::vector<int>;
using recorded::kStaticLabel;

/// The folders a source may need to start: where networks are looked up and where logs go. A
/// source uses what it needs (SumoSource both; RecordedSource neither).
struct SourceFolders {
  std::filesystem::path network_dir;  ///< networks named by name are looked up here
  std::filesystem::path work_dir;     ///< receives the source's logs (SUMO's route file, sumo.log)
};

/// One step's worth of detections and the ego's state. Lifetime: Start() once, then Advance()
/// until it returns false; Finish() at the end. Not copyable.
class DetectionSource {
 public:
  virtual ~DetectionSource() = default;

  /// Prepares the source (SUMO starts on its network in `folders.network_dir`, logging to
  /// `folders.work_dir`). Called by Pipeline::Start.
  virtual void Start(const SourceFolders& folders) = 0;
  virtual bool started() const = 0;
  /// Ends the source (SUMO writes its outputs); what was read stays readable.
  virtual void Finish() {}

  /// Advances one step: frame(), ego() and radar() then describe it. False at the end. `ids`
  /// receives every named object of the step (vehicles, tracks) in a deterministic order.
  virtual bool Advance(IdRegistry& ids) = 0;
  /// Scans the sensors due in the step just advanced: `detections` (world frame, ordered by
  /// sensor) and the sensors that scanned. Called once per Advance, after it.
  virtual void Scan(IdRegistry& ids, std::vector<radar::Detection>* detections,
                    std::vector<int>* scanned) = 0;

  /// The step: time, the ego (box centre, heading, lane direction) and the other objects where
  /// known (SUMO's vehicles; for recorded data the labelled tracks, estimated from their points).
  virtual const sim::Frame& frame() const = 0;
  virtual const radar::EgoMotion& ego() const = 0;
  /// The radars as mounted; valid from the first Advance().
  virtual const radar::RadarModel& radar() const = 0;
  virtual bool has_radar() const = 0;
  /// The filter cycle of the first step [s] (later cycles: the time between steps).
  virtual double first_dt() const = 0;
  /// SUMO, for a co-simulation; nullptr for recorded data.
  virtual const sim::SumoSimulation* sumo() const { return nullptr; }
  /// Labels of the last Scan()'s detections, in their order; empty without labels.
  virtual const PointLabels& labels() const {
    static const PointLabels kNone;
    return kNone;
  }
  /// The source's data say whether points are labelled (recorded data with label_id).
  virtual bool has_labels() const { return false; }
  /// The source reached its own end (SUMO: the duration; recorded: the last scan).
  virtual bool reached_end() const = 0;
  /// A second, independent source over the same data, started, at the first step: the Pipeline
  /// reads it one step ahead to build the next step's measurement grid on an idle thread
  /// (Pipeline::PrepareAhead). nullptr (the default) when the data cannot be read twice (SUMO:
  /// one simulation per process).
  virtual std::unique_ptr<DetectionSource> Twin() const { return nullptr; }
  /// The Pipeline may advance this very source one step before the run needs that step
  /// (Pipeline::ReadAhead, on a thread with time to spare while the filters run) and hand it
  /// out at the next Pipeline::Advance. The Pipeline copies each step out (frame, ego, labels,
  /// detections, scanned sensors, reached_end), so a source that says true must keep nothing
  /// else that the run reads per step: radar() must not change after the first Advance().
  /// False (the default): only a Twin() is read ahead.
  virtual bool can_run_ahead() const { return false; }
};

/// The co-simulation: SUMO steps, the radar model scans the ground truth. The radars are mounted
/// on the ego's box as SUMO simulates it, at the ego's departure (the first Advance).
class SumoSource : public DetectionSource {
 public:
  /// `config` must outlive the source. Registers the scenario's static obstacles in `ids` (they
  /// take the first ids).
  SumoSource(const scenario::ScenarioConfig& config, IdRegistry& ids);
  void Start(const SourceFolders& folders) override;
  bool started() const override { return simulation_ != nullptr; }
  void Finish() override;
  bool Advance(IdRegistry& ids) override;
  void Scan(IdRegistry& ids, std::vector<radar::Detection>* detections,
            std::vector<int>* scanned) override;
  const sim::Frame& frame() const override { return simulation_->frame(); }
  const radar::EgoMotion& ego() const override { return ego_; }
  const radar::RadarModel& radar() const override { return *radar_; }
  bool has_radar() const override { return radar_.has_value(); }
  double first_dt() const override { return config_.sim.step_length; }
  const sim::SumoSimulation* sumo() const override { return simulation_.get(); }
  bool reached_end() const override { return simulation_ && simulation_->reached_end(); }
  /// SUMO cannot be twinned (one per process), but it can run one step ahead of the run.
  bool can_run_ahead() const override { return true; }

 private:
  const scenario::ScenarioConfig& config_;
  std::unique_ptr<sim::SumoSimulation> simulation_;
  std::optional<radar::RadarModel> radar_;
  radar::Scene static_scene_;
  radar::EgoMotion ego_;
};

}  // namespace dualgrid::cosim
