#include "step_region.hpp"

#include <chrono>

namespace dualgrid::cosim {

StepRegion::StepRegion(CoSimulation& cs, const StepView& view, bool read_ahead)
    : cs_(cs),
      view_(view),
      modes_(static_cast<int>(cs.mode_names_.size())),
      with_velocities_(view.with_velocities),
      read_ahead_(read_ahead),
      ego_box_(cs.pipeline_.grid_frame().ToGrid(cs.pipeline_.frame().ego.box)),
      score_points_(cs.pipeline_.source().has_labels()),
      errors_(modes_),
      observer_errors_(cs.observers_.size() * static_cast<std::size_t>(1 + 2 * modes_)),
      filtered_(std::make_unique<std::atomic<int>[]>(modes_)),
      board_(FilterTask(modes_)) {
  // Labelled recorded points, scored per mode at their cells.
  Pipeline& p = cs_.pipeline_;
  cs_.point_positions_.clear();
  if (score_points_)
    for (const radar::Detection& d : p.detections())
      cs_.point_positions_.push_back(p.grid_frame().ToGrid(d.position_world));
}

void StepRegion::Filter(int m) {
  Pipeline& p = cs_.pipeline_;
  const auto start = std::chrono::steady_clock::now();
  Guarded(errors_[m], [&] {
    p.UpdateFilter(m);
    TakeSnapshot(p.grid(m), false, cs_.snapshots_[m]);
    // Here, not in the scorer: it may run on another core (ClassifySnapshot).
    ClassifySnapshot(p.config().evaluation.dynamic_threshold, cs_.snapshots_[m]);
  });
  // Mode m's own slot, read after the region (its end orders the accesses): ScheduleFor.
  cs_.filter_seconds_[m] +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // filtered_[m] first: a thread that sees the counts (Ready's truth) then sees it too (Truth).
  filtered_[m].store(errors_[m] ? kFilterFailed : kFilterOk, std::memory_order_release);
  if (!errors_[m]) filters_ok_.fetch_add(1, std::memory_order_acq_rel);
  filters_done_.fetch_add(1, std::memory_order_acq_rel);
}

void StepRegion::Work(std::span<const int> own) {
  std::vector<int> preferred;
  for (int m : own) preferred.push_back(FilterTask(m));
  for (int m : own) preferred.push_back(FilteredTask(m));
  for (int m : own) preferred.push_back(ScoredTask(m));
  board_.Work([this](int task) { return Ready(task); }, [this](int task) { Run(task); }, preferred);
}

bool StepRegion::Ready(int task) const {
  switch (task) {
    case kTruth:  // a filter that succeeded, or none left to wait for
      return filters_ok_.load(std::memory_order_acquire) > 0 ||
             filters_done_.load(std::memory_order_acquire) == modes_;
    case kReadAhead:  // the truth reads the source's ids, which reading ahead extends
      return board_.done(kTruth);
    case kPrepareAhead:
      return board_.done(kReadAhead);
    default:
      break;
  }
  if (task >= NoiseTask()) return true;  // the noise and the filters: inputs complete
  if (task == ObserveStepTask()) return board_.done(kTruth) && board_.done(kReadAhead);
  if (task >= ScoredTask(0)) {
    const int m = task - ScoredTask(0);
    return board_.done(kFirstScore + m) && board_.done(FilteredTask(m));
  }
  if (task >= FilteredTask(0)) {
    const int m = task - FilteredTask(0);
    return filtered_[m].load(std::memory_order_acquire) != 0 && board_.done(ObserveStepTask());
  }
  return filtered_[task - kFirstScore].load(std::memory_order_acquire) != 0 && board_.done(kTruth);
}

bool StepRegion::OthersBusy() const {
  // Besides the caller's own task: a task still to run or running (nothing waits for the
  // caller's, so another thread takes it), or a filter.
  return filters_done_.load(std::memory_order_acquire) < modes_ || board_.unfinished() > 1;
}

void StepRegion::Run(int task) {
  Pipeline& p = cs_.pipeline_;
  switch (task) {
    case kTruth:
      Truth();
      return;
    case kReadAhead:
      if (read_ahead_) p.ReadAhead();  // noexcept: an error waits for the next Advance
      return;
    case kPrepareAhead:
      // For SUMO, only while another thread is busy (a filter or a task): once every thread is
      // free, the next Advance builds the grid faster with all of them than this thread alone
      // (which of the two happens depends on timing, never a result). Recorded data: always (a
      // twin's read).
      if (read_ahead_ && (OthersBusy() || !p.source().can_run_ahead()))
        p.PrepareAhead();  // noexcept likewise
      return;
    default:
      break;
  }
  using Part = StepObserver::Part;
  if (task >= FilterTask(0)) {
    Filter(task - FilterTask(0));
  } else if (task == NoiseTask()) {
    Guarded(noise_error_, [&] { p.DrawNoise(true); });  // the other slot: no race
  } else if (task == ObserveStepTask()) {
    Observe(Part::kStep, -1, 0);
  } else if (task >= ScoredTask(0)) {
    const int m = task - ScoredTask(0);
    Observe(Part::kScored, m, 2 + 2 * m);
  } else if (task >= FilteredTask(0)) {
    const int m = task - FilteredTask(0);
    Observe(Part::kFiltered, m, 1 + 2 * m);
  } else {
    Score(task - kFirstScore);
  }
}

void StepRegion::Observe(StepObserver::Part part, int m, int slot) {
  // A failed truth, filter or score ends the step with its error (Rethrow): nothing to prepare.
  // The filtered part reads only the filter's outcome: the mode's score may be running.
  if (!truth_ok_) return;
  if (part == StepObserver::Part::kFiltered &&
      filtered_[m].load(std::memory_order_acquire) != kFilterOk)
    return;
  if (part == StepObserver::Part::kScored && errors_[m]) return;
  const std::size_t per_observer = static_cast<std::size_t>(1 + 2 * modes_);
  for (std::size_t o = 0; o < cs_.observers_.size(); ++o) {
    std::exception_ptr& error = observer_errors_[o * per_observer + static_cast<std::size_t>(slot)];
    Guarded(error, [&] { cs_.observers_[o]->Prepare(view_, part, m); });
  }
}

std::vector<std::exception_ptr> StepRegion::ObserverErrors() const {
  const std::size_t per_observer = static_cast<std::size_t>(1 + 2 * modes_);
  std::vector<std::exception_ptr> first(cs_.observers_.size());
  for (std::size_t o = 0; o < first.size(); ++o)
    for (std::size_t k = 0; k < per_observer && !first[o]; ++k)
      first[o] = observer_errors_[o * per_observer + k];
  return first;
}

// All filters share one grid geometry (centred on the same ego), so the ground truth per cell
// and per object is computed once, from the first mode whose filter succeeded, for every mode.
void StepRegion::Truth() {
  int from = -1;
  for (int m = 0; m < modes_ && from < 0; ++m)
    if (filtered_[m].load(std::memory_order_acquire) != 0 && !errors_[m]) from = m;
  if (from < 0) return;  // every filter failed: nothing is scored
  const Pipeline& p = cs_.pipeline_;
  Guarded(truth_error_, [&] {
    cs_.objects_ = p.TruthObjects(p.grid(from));
    cs_.truth_classes_ =
        TruthClasses(cs_.snapshots_[from], p.grid_frame(), p.frame(), p.config().sim);
    truth_ok_ = true;
  });
}

void StepRegion::Score(int m) {
  const Pipeline& p = cs_.pipeline_;
  Guarded(errors_[m], [&] {
    if (errors_[m]) return;
    // The velocity moments (observers' pictures and files only) on the scoring thread: with
    // the filters of two modes on one thread, this spreads them over both.
    if (with_velocities_) TakeVelocities(p.grid(m), cs_.snapshots_[m]);
    if (!truth_ok_) return;
    ModeScorer& scorer = cs_.scorers_[m];
    scorer.AddFrame(p.frame().time, p.grid(m), cs_.snapshots_[m], cs_.objects_, cs_.truth_classes_,
                    ego_box_);
    if (score_points_)
      scorer.AddPoints(p.grid(m), cs_.snapshots_[m], cs_.point_positions_, p.labels(), ego_box_);
  });
}

void StepRegion::Rethrow() const {
  if (truth_error_) std::rethrow_exception(truth_error_);
  if (noise_error_) std::rethrow_exception(noise_error_);
  for (const auto& e : errors_)
    if (e) std::rethrow_exception(e);
}

}  // namespace dualgrid::cosim
