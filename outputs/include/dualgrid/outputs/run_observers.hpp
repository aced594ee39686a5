// What a run does after each co-simulation step, as cosim::StepObserver hooks: the CSV files, the
// weight traces, the replay recording, the invariant checks and the pictures. Each owns its
// files; WriteRunFolder (run.hpp) wires them to the CoSimulation.
#pragma once

#include <deque>
#include <filesystem>
#include <future>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/capture.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/outputs/output_worker.hpp"
#include "dualgrid/outputs/recording.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/outputs/weight_traces.hpp"

namespace dualgrid::outputs {

/// ground_truth.csv, grid.csv, detections (optional; with `exact` also scans.csv), clusters.csv,
/// and the weight traces of one mode.
class RunFilesObserver : public cosim::StepObserver {
 public:
  /// `detections`: the file for --detections, none if empty; `multipath`: the scenario's
  /// sensors.multipath is on (the detections get their path columns). `trace_mode`: the mode
  /// whose particles give the weight traces (paper Fig. 4); `focus`: the scenario's focus object.
  RunFilesObserver(const std::filesystem::path& out,
                   const std::optional<std::filesystem::path>& detections, bool multipath,
                   std::size_t trace_mode, const std::string& focus, bool exact = false);
  /// The step's part: ground_truth.csv's and the detection files' rows; mode m's filtered part:
  /// the weight traces (m = the trace mode); its scored part: its clusters.csv rows (kept per
  /// mode until OnStep).
  void Prepare(const cosim::StepView& v, Part part, int mode) override;
  /// grid.csv's row, and the modes' clusters.csv rows in mode order.
  void OnStep(const cosim::StepView& v) override;
  /// Checks every write (throws std::runtime_error naming the file).
  void Close();
  const WeightTraces& traces() const { return traces_; }

 private:
  GroundTruthWriter truth_;
  GridPoseWriter grid_;
  std::unique_ptr<DetectionWriter> detections_;
  std::unique_ptr<ScanWriter> scans_;  // with --detections exact
  ClusterWriter clusters_;
  std::vector<std::string> cluster_rows_;  // per mode: this step's rows, made by Prepare
  std::size_t trace_mode_;
  WeightTraces traces_;
};

/// The replay recording (RUN_DIR/replay/, docs/replay.md): a frame every `interval` steps and at
/// the last one, taken here and compressed and appended by `worker` (replay::Writer). A failed
/// write stops the recording with a warning, never the run.
class RecordingObserver : public cosim::StepObserver {
 public:
  /// `truth_label`: what the reference boxes are called (replay::Header::truth_label).
  RecordingObserver(const std::filesystem::path& out, const scenario::ScenarioConfig& config,
                    double interval_s, int max_particles, std::string truth_label,
                    std::vector<std::string>* warnings, OutputWorker& worker);
  /// Without Finish (a run ended by an error): waits for the frames in flight and warns if one
  /// failed.
  ~RecordingObserver() override;
  RecordingObserver(const RecordingObserver&) = delete;
  RecordingObserver& operator=(const RecordingObserver&) = delete;
  bool WantsVelocities(int step, double time) override;
  /// Mode m's scored part: its live counts and, at a recorded step, its part of the frame; the
  /// step's part: the frame's own part (and the header, at the first recorded step).
  void Prepare(const cosim::StepView& v, Part part, int mode) override;
  /// Hands the frame prepared to the worker.
  void OnStep(const cosim::StepView& v) override;
  /// Writes the index (the recording is usable only then); a failure costs only the replay.
  /// False when there is no recording to finish.
  bool Finish(const nlohmann::json& metrics, const cosim::IdRegistry& ids, bool complete,
              const std::string& status);

 private:
  bool Due(int step) const;

  std::filesystem::path out_;
  int every_ = 1;
  int step_count_ = 0;
  int max_particles_ = 0;
  std::string truth_label_;
  std::vector<std::string>* warnings_;
  OutputWorker& worker_;
  std::unique_ptr<replay::Writer> writer_;
  bool failed_ = false;
  replay::Header header_;
  bool header_made_ = false;
  // This step's frame (a recorded step), made by Prepare, and the first error making it (per
  // part: step, then mode m at 1 + m; rethrown by OnStep, where its capture used to run).
  replay::Frame frame_;
  std::vector<std::exception_ptr> capture_errors_;
  std::vector<replay::LiveCounter> counters_;
  std::vector<replay::Live> live_;
  std::set<int> ids_;
};

/// --check-invariants: every filter's invariants after every step (a violation throws
/// std::logic_error: exit 1), and the resident memory every 60 s simulated.
class InvariantObserver : public cosim::StepObserver {
 public:
  explicit InvariantObserver(double step_length) : step_length_(step_length) {}
  void OnStep(const cosim::StepView& v) override;
  /// [time s, resident MB] samples, the last at `end_time`.
  nlohmann::json Samples(double end_time) const;

 private:
  double step_length_;
  nlohmann::json rss_mb_ = nlohmann::json::array();
};

struct PictureJob;  // run_observers.cpp

/// The grid and scene pictures (and with --write-particles the particle files) at the picture
/// times. What a picture shows is taken in OnStep; `worker` draws and encodes it. Figures never
/// cost the run: a failure is a warning, printed and appended to `warnings` on the calling thread
/// at the next picture step or at Finish (or by the destructor), in the order of the pictures.
class PictureObserver : public cosim::StepObserver {
 public:
  PictureObserver(const std::filesystem::path& out, std::vector<double> times,
                  const RunFolderOptions& options, std::vector<std::string>* warnings,
                  OutputWorker& worker);
  /// Publishes what Finish would have (a run ended by an error).
  ~PictureObserver() override;
  PictureObserver(const PictureObserver&) = delete;
  PictureObserver& operator=(const PictureObserver&) = delete;
  bool WantsVelocities(int step, double time) override;
  void OnStep(const cosim::StepView& v) override;
  /// Waits for the pictures handed to the worker and publishes their warnings.
  void Finish();

 private:
  /// Waits for the pictures handed to the worker and publishes their warnings, in order.
  void Publish();

  std::filesystem::path out_;
  std::vector<double> times_;
  std::size_t next_ = 0;
  bool picture_ = false;  // this step is a picture step (decided in WantsVelocities)
  bool figures_, particles_;
  std::vector<std::string> formats_;
  bool captions_;
  ReferenceWords words_;
  std::vector<std::string>* warnings_;
  OutputWorker& worker_;
  /// Pictures handed to the worker, oldest first, with their job (its failures once done).
  std::deque<std::pair<std::future<void>, std::shared_ptr<PictureJob>>> pending_;
};

/// Resident memory of this process [MB] (/proc/self/statm), 0 if unreadable.
double ResidentMegabytes();

}  // namespace dualgrid::outputs
