#pragma once
// Which thread filters and scores which weight mode in one co-simulation step.
//
// Fixed for a given (modes, threads), so that a filter runs on the same thread every step and its
// state stays in that core's cache (docs/performance.md, "Issue 25, round 3"). Results never depend
// on it: every value is computed by one thread from the same inputs.
#include <vector>

namespace dualgrid::cosim {

class ModeSchedule {
 public:
  /// `modes` >= 1 filters on `threads` in [1, modes] threads. Filter m runs on thread
  /// m % threads (in increasing m). Each mode is scored on the thread that filtered it, except
  /// that the first filter of every thread with one more filter than others is scored by a
  /// thread with fewer (3 modes on 2 threads: thread 0 filters 0 and 2 and scores 2; thread 1
  /// filters 1 and scores 1 and 0). The ground truth of the step is computed by the last thread,
  /// right after its first filter (it has the fewest filters).
  /// Throws std::invalid_argument outside these ranges.
  ModeSchedule(int modes, int threads);

  /// Modes filtered by thread `t`, in order.
  const std::vector<int>& filters(int t) const { return filters_.at(t); }
  /// Modes scored by thread `t`, in order (after its filters).
  const std::vector<int>& scores(int t) const { return scores_.at(t); }
  /// The thread that computes the step's ground truth after its first filter.
  int truth_thread() const { return static_cast<int>(filters_.size()) - 1; }

 private:
  std::vector<std::vector<int>> filters_, scores_;
};

}  // namespace dualgrid::cosim
