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

/// The step's part of a frame of the pipeline's current step (time, frame, ego, `objects` as
/// scored, detections) with `modes` empty mode frames for CaptureMode.
Frame CaptureStep(const cosim::Pipeline& pipeline, const std::vector<eval::TruthObject>& objects,
                  std::size_t modes);
/// Mode m's part of `f` (made by CaptureStep): f->modes[m] from mode m's grid, `snapshot` (with
/// velocities), `scorer`, `counter` and this step's `live` counts; mode 0 also sets f's origin
/// (every mode's grid lies on the same cells). Reads nothing of other modes and writes only
/// f->modes[m] (and the origin for m = 0), so different modes may be captured concurrently.
void CaptureMode(const cosim::Pipeline& pipeline, std::size_t m,
                 const cosim::GridSnapshot& snapshot, const cosim::ModeScorer& scorer,
                 const LiveCounter& counter, const Live& live,
                 const std::vector<eval::TruthObject>& objects, const Header& header, Frame* f);

}  // namespace dualgrid::outputs::replay
