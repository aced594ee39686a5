// Turns one step of a running co-simulation into a replay frame (recording.hpp): the run's side of
// the recording, kept out of cmd_run.cpp.
#pragma once

#include <vector>

#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/outputs/recording.hpp"

namespace dualgrid::outputs::replay {

/// Running per-mode totals for the live metrics; Count() every step (recorded or not).
class LiveCounter {
 public:
  explicit LiveCounter(const eval::TrackingMetricsParams& params) : params_(params) {}
  /// This step's counts for the scorer's last frame; adds them to the totals.
  Live Count(const cosim::ModeScorer& scorer, const std::vector<eval::TruthObject>& objects);
  /// Whether cluster c of the scorer's last frame matches an object within the D_v tolerance.
  bool VelocityOk(const cosim::ModeScorer& scorer, const std::vector<eval::TruthObject>& objects,
                  std::size_t c) const;

 private:
  eval::TrackingMetricsParams params_;
  long in_grid_ = 0, tracked_ = 0, tracked_v_ = 0;
};

/// The header for `pipeline`'s recording (before the first step: geometry from the scenario).
Header MakeHeader(const cosim::Pipeline& pipeline, const std::vector<std::string>& modes,
                  double interval, int max_particles);

/// One frame from the pipeline's current step. `snapshots` must hold velocities
/// (TakeSnapshot(..., true, ...)); `live` per mode from LiveCounter::Count for this step.
Frame Capture(const cosim::Pipeline& pipeline, const std::vector<cosim::GridSnapshot>& snapshots,
              const std::vector<cosim::ModeScorer>& scorers,
              const std::vector<LiveCounter>& counters, const std::vector<Live>& live,
              const std::vector<eval::TruthObject>& objects, const Header& header);

}  // namespace dualgrid::outputs::replay
