#include "dualgrid/cosim/cosimulation.hpp"

#include <omp.h>

#include <algorithm>
#include <exception>

namespace dualgrid::cosim {

CoSimulation::CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options)
    : pipeline_(config, options.modes), threads_(options.threads) {
  for (filter::WeightMode m : options.modes) {
    mode_names_.emplace_back(filter::ToString(m));
    scorers_.emplace_back(config.evaluation);
  }
  snapshots_.resize(options.modes.size());
}

CoSimulation::CoSimulation(const scenario::ScenarioConfig& config, CoSimOptions options,
                           const Pipeline::SourceFactory& make_source)
    : pipeline_(config, options.modes, make_source), threads_(options.threads) {
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
  FilterAndScore(with_velocities);
  const StepView view{steps_,     f,        pipeline_, mode_names_,
                      snapshots_, scorers_, objects_,  with_velocities};
  ++steps_;
  for (StepObserver* o : observers_) o->OnStep(view);
  return true;
}

// The modes run concurrently as tasks, one thread each, in one parallel region per step instead
// of ~40 (the filters' regions and barriers, three times): robust when another process shares
// the cores (docs/performance.md). With one mode (or one thread) the filter's own loops are
// parallel instead.
void CoSimulation::FilterAndScore(bool with_velocities) {
  const std::size_t modes = mode_names_.size();
  objects_.clear();
  truth_classes_.clear();
  if (modes == 0) return;
  if (threads_ > 0) omp_set_num_threads(threads_);
  const int threads = omp_get_max_threads();
  const int team = std::min(static_cast<int>(modes), threads);
  // Threads beyond one per mode go to each filter's own loops (e.g. 8 threads, 3 modes: 3 x 2);
  // on 2 cores that is 1, and nested regions stay off.
  const int per_filter = std::max(1, threads / team);
  omp_set_max_active_levels(per_filter > 1 ? 2 : 1);
  const sim::Frame& f = pipeline_.frame();
  const OrientedBox ego_box = pipeline_.grid_frame().ToGrid(f.ego.box);
  // Labelled recorded points, scored per mode at their cells.
  const bool score_points = pipeline_.source().has_labels();
  point_positions_.clear();
  if (score_points)
    for (const radar::Detection& d : pipeline_.detections())
      point_positions_.push_back(pipeline_.grid_frame().ToGrid(d.position_world));
  // Exceptions must not leave a parallel region: kept per mode, rethrown after it.
  std::vector<std::exception_ptr> errors(modes);
  std::exception_ptr truth_error;
  auto guarded = [](std::exception_ptr& slot, auto&& work) {
    try {
      work();
    } catch (...) {
      slot = std::current_exception();
    }
  };
  // Tasks: filter m, then (after filter 0) the shared truth, then scoring m once both are done.
  // All filters share one grid geometry (centred on the same ego), so the ground truth per cell
  // and per object is computed once for the first and holds for every mode. A thread that
  // finished a filter scores while another still filters (3 modes on 2 cores).
  std::vector<char> filtered(modes), truth_done(1);
  char* const f_dep = filtered.data();
  char* const t_dep = truth_done.data();
  (void)f_dep;  // used only in depend clauses, which GCC 12's -Wunused-variable misses
  (void)t_dep;
#pragma omp parallel num_threads(team) if (team > 1)
#pragma omp single
  {
    for (std::size_t m = 0; m < modes; ++m) {
#pragma omp task depend(out : f_dep[m]) shared(errors)
      guarded(errors[m], [&] {
        if (team > 1) omp_set_num_threads(per_filter);  // this task's nested regions only
        pipeline_.UpdateFilter(m);
      });
      if (m == 0) {
#pragma omp task depend(in : f_dep[0]) depend(out : t_dep[0]) shared(truth_error, f)
        guarded(truth_error, [&] {
          objects_ = pipeline_.TruthObjects(pipeline_.grid(0));
          TakeSnapshot(pipeline_.grid(0), with_velocities, snapshots_[0]);
          truth_classes_ =
              TruthClasses(snapshots_[0], pipeline_.grid_frame(), f, pipeline_.config().sim);
        });
      }
#pragma omp task depend(in : f_dep[m], t_dep[0]) shared(errors, truth_error, f, ego_box)
      guarded(errors[m], [&] {
        if (truth_error || errors[m]) return;
        if (m > 0) TakeSnapshot(pipeline_.grid(m), with_velocities, snapshots_[m]);
        scorers_[m].AddFrame(f.time, pipeline_.grid(m), snapshots_[m], objects_, truth_classes_,
                             ego_box);
        if (score_points)
          scorers_[m].AddPoints(pipeline_.grid(m), snapshots_[m], point_positions_,
                                pipeline_.labels(), ego_box);
      });
    }
  }
  if (truth_error) std::rethrow_exception(truth_error);
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

bool CoSimulation::finished() const {
  const sim::SumoSimulation* sumo = pipeline_.sumo();
  return pipeline_.started() && steps_ > 0 && pipeline_.source().reached_end() &&
         !(sumo && sumo->ego_left());
}

std::vector<eval::ScenarioMetrics> CoSimulation::Metrics() const {
  std::vector<eval::ScenarioMetrics> out;
  for (const ModeScorer& s : scorers_) out.push_back(s.Result());
  return out;
}

}  // namespace dualgrid::cosim
