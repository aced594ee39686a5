// CoSimulation and RecordedSimulation for Python: dualgrid::cosim stepped one step per call
// (docs/python.md, "Step by step"), each step a Step (step_bindings.cpp); results() at the end is
// run_scenario's / run_recorded's dict, from the same code.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "run_results.hpp"
#include "run_setup.hpp"
#include "step_data.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

// One stepped run. Lifetime: running (SUMO held) -> ended or closed (results kept, SUMO and the
// filters released) or failed (an error in a step: everything released, every later call raises).
// Calls are serialised by a lock that a second thread never waits for: it gets RuntimeError.
class Simulation {
 public:
  // A scenario file on SUMO.
  Simulation(const scenario::ScenarioConfig& config, const cosim::CoSimOptions& options,
             bool velocities, const fs::path& networks, const std::optional<fs::path>& work_dir)
      : name_("CoSimulation"), config_(config), collector_(velocities) {
    sumo_ = std::make_unique<SumoClaim>(name_);
    work_ = WorkDir::Make(work_dir, config, networks);
    cs_ = std::make_unique<cosim::CoSimulation>(config_, options);
    {
      py::gil_scoped_release nogil;
      cs_->Start(networks, work_.path);
    }
    Observe();
  }
  // A recorded sequence.
  Simulation(std::unique_ptr<RecordedSetup> setup, const cosim::CoSimOptions& options,
             bool velocities)
      : name_("RecordedSimulation"),
        config_(setup->config),
        collector_(velocities),
        recorded_(std::move(setup)) {
    const RecordedSetup& s = *recorded_;
    cs_ = std::make_unique<cosim::CoSimulation>(
        config_, options, [&s](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
          return std::make_unique<cosim::RecordedSource>(s.input.sequence, s.options);
        });
    cs_->Start({}, {});
    Observe();
  }

  // The next step; at the end None (`iterating`: StopIteration). After the end: RuntimeError
  // (`iterating`: StopIteration, as Python's iterators do).
  py::object Next(bool iterating) {
    std::unique_lock<std::mutex> lock = Lock("step");
    if (state_ == State::kFailed) throw Failed("step");
    if (state_ != State::kRunning) {
      if (iterating) throw py::stop_iteration();
      throw std::runtime_error(std::string(name_) + ".step(): the run has " +
                               (state_ == State::kEnded ? "ended" : "been closed") + " after " +
                               std::to_string(steps_.load()) + " steps; results() has its results");
    }
    bool more = false;
    try {
      py::gil_scoped_release nogil;
      more = cs_->Step();
    } catch (const std::exception& e) {
      Fail(e.what());
      throw;
    }
    if (!more) {
      End(State::kEnded);
      if (iterating) throw py::stop_iteration();
      return py::none();
    }
    ++steps_;
    return WrapStep(collector_.Take());
  }

  py::dict Run() {
    {
      std::unique_lock<std::mutex> lock = Lock("run");
      if (state_ == State::kFailed) throw Failed("run");
      if (state_ == State::kRunning) {
        collector_.set_active(false);  // no Step objects: only the results
        try {
          py::gil_scoped_release nogil;
          while (cs_->Step()) ++steps_;
        } catch (const std::exception& e) {
          Fail(e.what());
          throw;
        }
        End(State::kEnded);
      }
    }
    return Results();
  }

  void Close() {
    std::unique_lock<std::mutex> lock = Lock("close");
    if (state_ == State::kRunning) End(State::kClosed);
  }

  py::dict Results() {
    std::unique_lock<std::mutex> lock = Lock("results");
    if (state_ == State::kFailed) throw Failed("results");
    if (state_ == State::kRunning)
      throw std::runtime_error(std::string(name_) + ".results(): the run has not ended (" +
                               std::to_string(steps_.load()) +
                               " steps done): iterate to the end, or call run() or close() "
                               "first; metrics() gives the scores so far");
    return py::module_::import("copy").attr("deepcopy")(results_);
  }

  py::dict Metrics() {
    std::unique_lock<std::mutex> lock = Lock("metrics");
    if (state_ == State::kFailed) throw Failed("metrics");
    if (state_ != State::kRunning)
      return py::module_::import("copy").attr("deepcopy")(results_["metrics"]);
    const std::vector<eval::ScenarioMetrics> metrics = cs_->Metrics();
    nlohmann::json j = nlohmann::json::object();
    for (std::size_t m = 0; m < metrics.size(); ++m) j[cs_->mode_names()[m]] = metrics[m];
    return FromJson(j);
  }

  void FailNextStep() {
    std::unique_lock<std::mutex> lock = Lock("_fail_next_step");
    collector_.FailNextStep();
  }
  int steps() const { return steps_; }
  std::string state() const {
    static const char* kNames[] = {"running", "ended", "closed", "failed"};
    return kNames[static_cast<int>(state_)];
  }
  const scenario::ScenarioConfig& config() const { return config_; }
  std::vector<std::string> modes() const { return modes_; }

 private:
  enum class State { kRunning, kEnded, kClosed, kFailed };

  void Observe() {
    modes_ = cs_->mode_names();
    cs_->AddObserver(&collector_);
    cs_->AddObserver(&clusters_);
  }
  std::unique_lock<std::mutex> Lock(const char* what) {
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock)
      throw std::runtime_error(std::string(name_) + "." + what +
                               "(): the simulation is busy in another thread; one simulation "
                               "serves one thread at a time (make one per thread)");
    return lock;
  }
  std::runtime_error Failed(const char* what) const {
    return std::runtime_error(
        std::string(name_) + "." + what + "(): unusable after an error in step " +
        std::to_string(steps_.load()) + ": " + error_ + " (make a new simulation)");
  }
  // Releases SUMO and the filters after an error; the work folder stays (sumo.log).
  void Fail(const std::string& what) {
    state_ = State::kFailed;
    error_ = what;
    cs_.reset();
    if (sumo_) sumo_->Release();
  }
  void End(State state) {
    {
      py::gil_scoped_release nogil;
      cs_->Finish();
    }
    results_ = python::Results(*cs_, config_, clusters_);
    if (recorded_) results_["input"] = RecordedInputInfo(recorded_->input);
    cs_.reset();
    if (sumo_) sumo_->Release();
    work_.Remove();
    state_ = state;
  }

  const char* name_;
  scenario::ScenarioConfig config_;
  std::unique_ptr<SumoClaim> sumo_;
  WorkDir work_;
  StepCollector collector_;
  ClusterColumns clusters_;
  std::unique_ptr<RecordedSetup> recorded_;  // before cs_: its source reads the sequence
  std::unique_ptr<cosim::CoSimulation> cs_;
  std::vector<std::string> modes_;
  std::mutex mutex_;
  State state_ = State::kRunning;
  std::string error_;
  std::atomic<int> steps_{0};  // read by `steps` without the lock
  py::dict results_;
};

// The two kinds, one Python class each (pybind11 registers a C++ type once).
struct ScenarioSimulation : Simulation {
  using Simulation::Simulation;
};
struct SequenceSimulation : Simulation {
  using Simulation::Simulation;
};

// Step results typed for signatures and the stub.
DUALGRID_ARG_TAG(StepTag, "Step");
DUALGRID_ARG_TAG(OptionalStepTag, "Optional[Step]");
using StepResult = Arg<StepTag>;
using OptionalStepResult = Arg<OptionalStepTag>;

// __iter__ and __enter__ return the object itself: bound on the most derived class, so that
// pybind11 finds the existing Python object (a base-class reference would get a new wrapper).
template <typename S>
void BindSelfReturns(py::class_<S, Simulation>& cls) {
  cls.def(
      "__iter__", [](S& self) -> S& { return self; }, py::return_value_policy::reference);
  cls.def(
      "__enter__", [](S& self) -> S& { return self; }, py::return_value_policy::reference);
}

const char* kCommonDoc = R"doc(
Iterate (`for step in sim:`) or call step(): each step is a dualgrid.Step (time, ego pose,
detections, truth, grids[mode], clusters, scores). results() after the end returns what
run_scenario / run_recorded return, the same numbers. close() ends early (also `with sim:`);
run() runs to the end without Step objects. velocities=False skips the cells' mean velocities
(StepGrid.velocity None; a pass over every particle per step and mode). Not for two threads at
once (RuntimeError); after an error every call raises RuntimeError.)doc";

void BindSimulationMethods(py::module_& m) {
  py::class_<Simulation> cls(
      m, "Simulation",
      (std::string("Base of CoSimulation and RecordedSimulation.") + kCommonDoc).c_str());
  cls.def("__next__", [](Simulation& s) { return StepResult{s.Next(true)}; });
  cls.def(
      "step", [](Simulation& s) { return OptionalStepResult{s.Next(false)}; },
      "The next Step; None when this call found the end of the run; RuntimeError after that.");
  cls.def("run", &Simulation::Run,
          "Runs the remaining steps (no Step objects) and returns results().");
  cls.def("close", &Simulation::Close,
          "Ends the run now: SUMO closes, results() then holds the steps done (complete False "
          "unless the end was reached). No-op when ended.");
  cls.def("results", &Simulation::Results,
          "run_scenario's dict (run_recorded's for a RecordedSimulation) once the run ended or "
          "was closed; RuntimeError before.");
  cls.def("metrics", &Simulation::Metrics,
          "{mode: metrics.json's entry} over the steps done so far.");
  cls.def_property_readonly("steps", &Simulation::steps, "Steps done.");
  cls.def("_fail_next_step", &Simulation::FailNextStep,
          "Testing aid: the next step raises RuntimeError as an error inside a step would.");
  cls.def_property_readonly("state", &Simulation::state,
                            "'running', 'ended', 'closed' or 'failed'.");
  cls.def_property_readonly("modes", &Simulation::modes, "The weight modes, in order.");
  cls.def_property_readonly(
      "seed", [](const Simulation& s) { return s.config().sim.seed; }, "The run's seed.");
  cls.def_property_readonly(
      "step_length", [](const Simulation& s) { return s.config().sim.step_length; },
      "The co-simulation's step [s] (recorded data: the mean cycle).");
  cls.def_property_readonly(
      "duration", [](const Simulation& s) { return s.config().sim.duration; },
      "The requested duration [s].");
  cls.def("__exit__", [](Simulation& s, py::args) { s.Close(); });
}

}  // namespace

void BindStepping(py::module_& m) {
  BindStep(m);
  BindSimulationMethods(m);
  py::class_<ScenarioSimulation, Simulation> cls(m, "CoSimulation",
                                                 (std::string(R"doc(
A scenario file run step by step through SUMO, the radar model and one filter per weight mode,
as `dualgrid run` and run_scenario run it (docs/python.md, "Step by step"). Arguments as
run_scenario's; SUMO starts here (one SUMO co-simulation per process at a time: RuntimeError
otherwise).)doc") + kCommonDoc)
                                                     .c_str());
  cls.def(
      py::init([](const fs::path& scenario, const std::vector<std::string>& modes,
                  std::optional<Seed> seed, std::optional<double> duration,
                  const std::vector<std::string>& overrides, std::optional<fs::path> network_dir,
                  std::optional<fs::path> work_dir, int threads, bool velocities) {
        const scenario::ScenarioConfig config =
            LoadRunConfig(scenario, seed, duration, overrides, "CoSimulation");
        const cosim::CoSimOptions options = RunOptions(modes, threads, "CoSimulation");
        return std::make_unique<ScenarioSimulation>(config, options, velocities,
                                                    NetworkDir(network_dir), work_dir);
      }),
      py::arg("scenario"),
      py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
      py::arg("seed") = py::none(), py::arg("duration") = py::none(),
      py::arg("overrides") = std::vector<std::string>{}, py::arg("network_dir") = py::none(),
      py::arg("work_dir") = py::none(), py::arg("threads") = 0, py::arg("velocities") = true);
  BindSelfReturns(cls);

  py::class_<SequenceSimulation, Simulation> rec(m, "RecordedSimulation",
                                                 (std::string(R"doc(
A recorded sequence (RadarScenes sequence folder, or a run folder recorded with --detections
exact) filtered step by step, as `dualgrid filter` and run_recorded run it. Arguments as
run_recorded's.)doc") + kCommonDoc)
                                                     .c_str());
  rec.def(py::init([](const fs::path& path, std::optional<fs::path> sensors,
                      std::optional<fs::path> scenario, const std::vector<std::string>& overrides,
                      std::optional<Seed> seed, const std::vector<std::string>& modes,
                      double batch_window, int threads, bool velocities) {
            auto setup = std::make_unique<RecordedSetup>(LoadRecorded(
                path, sensors, scenario, overrides, seed, batch_window, "RecordedSimulation"));
            const cosim::CoSimOptions options = RunOptions(modes, threads, "RecordedSimulation");
            return std::make_unique<SequenceSimulation>(std::move(setup), options, velocities);
          }),
          py::arg("path"), py::arg("sensors") = py::none(), py::arg("scenario") = py::none(),
          py::arg("overrides") = std::vector<std::string>{}, py::arg("seed") = py::none(),
          py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
          py::arg("batch_window") = 0.001, py::arg("threads") = 0, py::arg("velocities") = true);
  BindSelfReturns(rec);
}

}  // namespace dualgrid::python
