#pragma once
// One co-simulation step's parallel region (CoSimulation::FilterAndScore): every mode's filter
// cycle on the thread the ModeSchedule names (Filter), and the rest of the step as tasks that
// whichever thread is free first takes (Work, a TaskBoard), in this order of priority: the ground
// truth (from any filter finished: they share one geometry), the next step read ahead (SUMO's
// step and the radar scan, or a recorded source's twin), the next step's measurement grid (for
// SUMO only while a filter still runs), each mode's scoring, the next cycle's prediction noise. A
// task starts once its inputs are complete (a score after its filter and the truth, the
// read-ahead after the truth, which reads the source's ids, the grid after the read-ahead), so no
// value depends on the thread that computes it. Exceptions never leave a thread: kept per task
// and rethrown by Rethrow after the region.
#include <atomic>
#include <exception>
#include <memory>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/task_board.hpp"

namespace dualgrid::cosim {

class StepRegion {
 public:
  /// Before the region, on the calling thread. `read_ahead`: this step reads the next one ahead
  /// (CoSimOptions::read_ahead, and a thread has time to spare).
  StepRegion(CoSimulation& cs, bool with_velocities, bool read_ahead);
  /// Mode m's filter cycle, snapshot and classes; once per mode per step, on any one thread.
  void Filter(int m);
  /// Takes tasks until none is left to take (TaskBoard::Work); every thread of the region, after
  /// its filters.
  void Work();
  /// After the region: the first error of the truth, the noise or a mode (in mode order).
  void Rethrow() const;

 private:
  // Task indices, in order of priority: then mode m's score at kFirstScore + m, the noise last.
  enum Task { kTruth, kReadAhead, kPrepareAhead, kFirstScore };
  int NoiseTask() const { return kFirstScore + modes_; }
  bool Ready(int task) const;
  void Run(int task);
  void Truth();
  void Score(int m);

  CoSimulation& cs_;
  const int modes_;
  const bool with_velocities_, read_ahead_;
  OrientedBox ego_box_;
  bool score_points_;
  std::vector<std::exception_ptr> errors_;  // per mode: its filter's or its scoring's
  std::exception_ptr truth_error_, noise_error_;
  std::unique_ptr<std::atomic<int>[]> filtered_;  // per mode: 1 once its filter ran (or failed)
  std::atomic<int> filters_done_{0}, filters_ok_{0};
  bool truth_ok_ = false;  // written by the truth task, read by scores after it
  TaskBoard board_;
};

}  // namespace dualgrid::cosim
