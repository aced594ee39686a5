#pragma once
// One co-simulation step's parallel region (CoSimulation::FilterAndScore): the whole step as
// tasks that the region's threads take (a TaskBoard). Each mode's filter cycle (with its snapshot
// and classes) is a task that the thread the ModeSchedule names claims first, in its order
// (Work's `own`: the filter's state stays in that core's cache); any other thread takes it only
// when it has nothing else left to take and the owner has not started it (the owner was
// preempted, or the region got fewer threads than planned: then one thread runs every filter).
// The rest of the step is taken by whichever thread is free first, in this order of priority:
// the ground truth (from any filter finished: they share one geometry), the next step read ahead
// (SUMO's step and the radar scan, or a recorded source's twin), the next step's measurement grid
// (for SUMO only while another thread is busy), each mode's scoring, the observers' Prepare parts
// (StepObserver: the step's, then per mode the filtered and the scored part), the next cycle's
// prediction noise, and last the filters not yet claimed by their owners. A task starts once its
// inputs are complete (a score after its filter and the truth; the read-ahead after the truth,
// which reads the source's ids; the grid after the read-ahead; the observers' step part after the
// truth and the read-ahead, so that the ids and SUMO stand as OnStep sees them; a mode's filtered
// part after its filter and the step part, its scored part after its score and its filtered
// part), so no value depends on the thread that computes it. Exceptions never leave a thread:
// kept per task and rethrown by Rethrow after the region (the observers' by CoSimulation::Step,
// where their OnStep would run).
#include <atomic>
#include <exception>
#include <memory>
#include <span>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/task_board.hpp"

namespace dualgrid::cosim {

class StepRegion {
 public:
  /// Before the region, on the calling thread. `read_ahead`: this step reads the next one ahead
  /// (CoSimOptions::read_ahead, and a thread has time to spare).
  StepRegion(CoSimulation& cs, const StepView& view, bool read_ahead);
  /// Takes tasks until none is left to take (TaskBoard::Work); every thread of the region, each
  /// with the modes `own` the ModeSchedule gives it: their filters first (in the order given),
  /// then the observers' parts of these modes before other tasks (they read the filter's
  /// particles and cells, still in this core's cache).
  void Work(std::span<const int> own);
  /// After the region: the first error of the truth, the noise or a mode (in mode order).
  void Rethrow() const;
  /// After the region: per observer, the first error of its Prepare parts (step part first,
  /// then by mode, filtered before scored), null if none.
  std::vector<std::exception_ptr> ObserverErrors() const;

  /// Runs `work`, keeping what it throws in `slot` (which it overwrites).
  template <typename Work>
  static void Guarded(std::exception_ptr& slot, Work&& work) {
    try {
      work();
    } catch (...) {
      slot = std::current_exception();
    }
  }

 private:
  // Task indices, in order of priority: mode m's score at kFirstScore + m, then the observers'
  // step part, their filtered parts by mode, their scored parts by mode, the noise, and the
  // filters last (their owners claim them first: Work).
  enum Task { kTruth, kReadAhead, kPrepareAhead, kFirstScore };
  int ObserveStepTask() const { return kFirstScore + modes_; }
  int FilteredTask(int m) const { return ObserveStepTask() + 1 + m; }
  int ScoredTask(int m) const { return ObserveStepTask() + 1 + modes_ + m; }
  int NoiseTask() const { return ObserveStepTask() + 1 + 2 * modes_; }
  int FilterTask(int m) const { return NoiseTask() + 1 + m; }
  // Mode m's filter cycle, snapshot and classes (task FilterTask(m)).
  void Filter(int m);
  bool Ready(int task) const;
  void Run(int task);
  void Truth();
  void Score(int m);
  // The observers' part `part` (of mode m, -1 for the step's) into errors slot `slot`.
  void Observe(StepObserver::Part part, int m, int slot);
  // Whether another thread has work besides the caller's task: a filter still runs, or another
  // task is not done.
  bool OthersBusy() const;

  CoSimulation& cs_;
  const StepView& view_;
  const int modes_;
  const bool with_velocities_, read_ahead_;
  OrientedBox ego_box_;
  bool score_points_;
  std::vector<std::exception_ptr> errors_;  // per mode: its filter's or its scoring's
  std::exception_ptr truth_error_, noise_error_;
  // The observers' parts' errors: observer o, part slot k at o * (1 + 2 * modes) + k, k = 0 the
  // step part, 1 + 2m mode m's filtered, 2 + 2m its scored part.
  std::vector<std::exception_ptr> observer_errors_;
  // Per mode: 0 until its filter ran, then kFilterOk or kFilterFailed.
  static constexpr int kFilterOk = 1, kFilterFailed = 2;
  std::unique_ptr<std::atomic<int>[]> filtered_;
  std::atomic<int> filters_done_{0}, filters_ok_{0};
  bool truth_ok_ = false;  // written by the truth task, read by scores after it
  TaskBoard board_;
};

}  // namespace dualgrid::cosim
