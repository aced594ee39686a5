#pragma once
// Which thread filters which weight mode in one co-simulation step.
//
// Fixed for a given (modes, threads, costs), so that a filter runs on the same thread every step
// and its state stays in that core's cache; the co-simulation re-plans it from measured filter
// times now and then (docs/performance.md). Results never depend on it: every value is computed
// by one thread from the same inputs.
#include <span>
#include <vector>

namespace dualgrid::cosim {

class ModeSchedule {
 public:
  /// `modes` >= 1 filters on `threads` in [1, modes] threads. Threads t < modes % threads filter
  /// one mode more than the others. Without `costs`, filter m runs on thread m % threads. With
  /// `costs` (one per mode, finite and >= 0: e.g. measured seconds per cycle), the modes are
  /// placed so that the largest sum of costs on a thread is smallest (exhaustive search, up to 8
  /// modes; more keep m % threads; ties and anything not strictly better than m % threads keep
  /// m % threads). Only the filters are placed: the rest of a step (the truth, the scoring, the
  /// reading ahead) goes to whichever thread is free (StepRegion, TaskBoard). A thread filters
  /// its modes in increasing m; another thread takes one only when that thread has not started
  /// it and the other has nothing else left to do (StepRegion).
  /// Throws std::invalid_argument outside these ranges, for a cost count other than `modes` or a
  /// negative or non-finite cost.
  ModeSchedule(int modes, int threads, std::span<const double> costs = {});

  /// Modes filtered by thread `t`, in order.
  const std::vector<int>& filters(int t) const { return filters_.at(t); }
  /// The largest sum of `costs` (one per mode) over the modes a thread filters.
  double MaxLoad(std::span<const double> costs) const;
  bool operator==(const ModeSchedule& o) const { return filters_ == o.filters_; }

 private:
  std::vector<std::vector<int>> filters_;
};

}  // namespace dualgrid::cosim
