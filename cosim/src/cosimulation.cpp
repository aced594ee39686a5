#include "dualgrid/cosim/cosimulation.hpp"

#include "dualgrid/cosim/mode_schedule.hpp"

#include "step_region.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>

namespace dualgrid::cosim {

CoSimulation::CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options)
    : pipeline_(config, options.modes), threads_(options.threads), read_ahead_(options.read_ahead) {
  for (filter::WeightMode m : options.modes) {
    mode_names_.emplace_back(filter::ToString(m));
    scorers_.emplace_back(config.evaluation);
  }
  snapshots_.resize(options.modes.size());
}

CoSimulation::CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options,
                           const Pipeline::SourceFactory& make_source)
    : pipeline_(config, options.modes, make_source),
      threads_(options.threads),
      read_ahead_(options.read_ahead) {
  for (filter::WeightMode m : options.modes) {
    mode_names_.emplace_back(filter::ToString(m));
    scorers_.emplace_back(config.evaluation);
  }
  snapshots_.resize(options.modes.size());
}

void CoSimulation::Start(const std::filesystem::path& network_dir,
                         const std::filesystem::path& work_dir) {
  pipeline_.Start(network_dir, work_dir);
}

void CoSimulation::AddObserver(StepObserver* observer) { observers_.push_back(observer); }

bool CoSimulation::Step() {
  if (!pipeline_.Advance()) return false;
  const sim::Frame& f = pipeline_.frame();
  total_detections_ += pipeline_.detections().size();
  bool with_velocities = false;
  // Every observer is asked (no short cut): each may keep its own schedule.
  for (StepObserver* o : observers_)
    with_velocities = o->WantsVelocities(steps_, f.time) || with_velocities;
  // The view refers to members the region fills (snapshots, scorers, objects, truth classes).
  const StepView view{steps_,   f,        pipeline_,      mode_names_,    snapshots_,
                      scorers_, objects_, truth_classes_, with_velocities};
  const std::vector<std::exception_ptr> early = FilterAndScore(view);
  ++steps_;
  for (std::size_t i = 0; i < observers_.size(); ++i) {
    if (early[i]) std::rethrow_exception(early[i]);  // where its OnStep would have thrown
    observers_[i]->OnStep(view);
  }
  return true;
}

// The modes run concurrently, one thread each, in one parallel region per step instead of ~40 (the
// filters' regions and barriers, three times): robust when another process shares the cores
// (docs/performance.md). With one mode (or one thread) the filter's own loops are parallel
// instead. Which thread filters which mode is planned (ModeSchedule), not left to a task queue: a
// filter's state (~2-3 MB) then stays in the cache of the core that updated it last step, and its
// snapshot is taken there at once. With free tasks, a mode moved between cores from step to step
// and every pass over its cells paid for the move (+28 % CPU time on the recorded loop,
// docs/performance.md). Only a filter whose thread has not started it when another thread has
// nothing else left to do moves (StepRegion: its owner was preempted, e.g. by the output thread,
// or the region got fewer threads than planned). The rest of the step (StepRegion's tasks: the
// truth, the scoring, the next step's reading and measurement grid, the observers' Prepare
// parts, the next cycle's noise) is taken by whichever thread is free first (TaskBoard), so that
// a thread slowed down (by another process, or the output thread) does not leave the other idle
// at the region's end. Results do not depend on either: every value is computed by one thread
// from the same inputs.
std::vector<std::exception_ptr> CoSimulation::FilterAndScore(const StepView& view) {
  const int modes = static_cast<int>(mode_names_.size());
  objects_.clear();
  truth_classes_.clear();
  if (modes == 0) {  // no region: the observers' only part, here
    std::vector<std::exception_ptr> errors(observers_.size());
    for (std::size_t i = 0; i < observers_.size(); ++i)
      StepRegion::Guarded(errors[i],
                          [&] { observers_[i]->Prepare(view, StepObserver::Part::kStep, -1); });
    return errors;
  }
  if (threads_ > 0) omp_set_num_threads(threads_);
  const int threads = omp_get_max_threads();
  const int team = std::min(modes, threads);
  // Threads beyond one per mode go to each filter's own loops (e.g. 8 threads, 3 modes: 3 x 2);
  // on 2 cores that is 1, and nested regions stay off.
  const int per_filter = std::max(1, threads / team);
  omp_set_max_active_levels(per_filter > 1 ? 2 : 1);
  const ModeSchedule& schedule = ScheduleFor(modes, team);
  // The prediction normals are the same for every mode: drawn once (here only at the first step;
  // afterwards ahead, in the region, for the next cycle).
  pipeline_.DrawNoise(false);
  // Reading ahead only when a thread filters fewer modes than another (3 modes on 2 threads):
  // otherwise there is no time to spare in the region, and Advance does it all between regions.
  StepRegion region(*this, view, read_ahead_ && team > 1 && modes % team != 0);
  // Thread t filters its modes first; another takes one only when the owner is late (StepRegion).
  const auto run_thread = [&](int t) { region.Work(schedule.filters(t)); };
  if (team == 1) {
    // No enclosing region: an inactive one (if (false)) still counts as a nesting level, and
    // libgomp then started new threads for the filter's own regions in every step (measured:
    // thread creation in the profile, 2 threads slower than 1).
    run_thread(0);
  } else {
#pragma omp parallel num_threads(team)
    {
      omp_set_num_threads(per_filter);  // this thread's nested regions only
      run_thread(omp_get_thread_num());
    }
  }
  ++timed_steps_;
  region.Rethrow();
  return region.ObserverErrors();
}

// The first kWarmUp steps are not timed (the first cycles fill the grid and are not typical);
// the first plan comes kWindow steps later, and then one every `replan_every_` steps, adopted only
// when it shortens the most loaded thread by more than 3 % (moving a filter costs its cache:
// round 3). The period doubles after each adopted change, so that costs which depend on the
// placement itself cannot make the schedule flip back and forth often. Only the schedule
// changes, never a result.
constexpr int kWarmUp = 16, kWindow = 64;
constexpr double kReplanGain = 0.97;

const ModeSchedule& CoSimulation::ScheduleFor(int modes, int team) {
  const auto restart_timing = [&](int period) {
    next_plan_ = steps_ + period;
    filter_seconds_.assign(modes, 0.0);
    timed_steps_ = 0;
  };
  if (!schedule_ || schedule_team_ != team) {
    schedule_.emplace(modes, team);
    schedule_team_ = team;
    replan_every_ = kWindow;
    warming_up_ = true;
    restart_timing(kWarmUp);
  } else if (steps_ >= next_plan_ && warming_up_) {
    warming_up_ = false;
    restart_timing(kWindow);  // the warm-up's times are dropped
  } else if (steps_ >= next_plan_ && timed_steps_ > 0) {
    std::vector<double> costs(filter_seconds_);
    for (double& c : costs) c /= timed_steps_;
    const ModeSchedule plan(modes, team, costs);
    if (plan.MaxLoad(costs) < kReplanGain * schedule_->MaxLoad(costs)) {
      schedule_ = plan;
      replan_every_ *= 2;
    }
    restart_timing(replan_every_);
  }
  return *schedule_;
}

bool CoSimulation::finished() const {
  const sim::SumoSimulation* sumo = pipeline_.sumo();
  return pipeline_.started() && steps_ > 0 && pipeline_.reached_end() &&
         !(sumo && sumo->ego_left());
}

std::vector<eval::ScenarioMetrics> CoSimulation::Metrics() const {
  std::vector<eval::ScenarioMetrics> out;
  for (const ModeScorer& s : scorers_) out.push_back(s.Result());
  return out;
}

}  // namespace dualgrid::cosim
