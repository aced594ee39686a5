// dualgrid::cosim linked directly: the step's observers see every step in order, get the cell
// velocities exactly when one asks, errors surface where documented, SUMO can be run again in
// the same process, and the metrics do not depend on the thread count.
#include <omp.h>
#include <catch2/catch.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <typeinfo>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/cosimulation.hpp"

using namespace dualgrid;

namespace {

scenario::ScenarioConfig Highway(double duration) {
  auto config = scenario::LoadScenario("scenarios/highway.yaml");
  config.sim.duration = duration;
  return config;
}

std::filesystem::path WorkDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("dualgrid_test_cosim_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

// A digest of what an observer sees of a step's results: every mode's masses and clusters, the
// ground truth. With two threads the scoring is spread over both (TaskBoard): the observers must
// see the same as on one thread.
double Digest(const cosim::StepView& v) {
  double d =
      static_cast<double>(v.objects.size()) + 1e-3 * static_cast<double>(v.truth_classes.size());
  for (std::uint8_t c : v.truth_classes) d += c;
  for (std::size_t m = 0; m < v.snapshots.size(); ++m) {
    for (float x : v.snapshots[m].dynamic) d += x;
    for (std::uint8_t c : v.snapshots[m].classes) d += 0.5 * c;
    d += 1e3 * static_cast<double>(v.scorers[m].clusters().size() * (m + 1));
  }
  return d;
}

// Records what it was shown; asks for velocities every `every`-th step.
struct Recorder : cosim::StepObserver {
  int every = 0;
  std::vector<int> steps;
  std::vector<double> times, digests;
  int with_velocity_steps = 0, velocity_mismatches = 0, detections = 0;
  bool WantsVelocities(int step, double) override { return every > 0 && step % every == 0; }
  void OnStep(const cosim::StepView& v) override {
    steps.push_back(v.step);
    times.push_back(v.frame.time);
    digests.push_back(Digest(v));
    detections += static_cast<int>(v.pipeline.detections().size());
    const bool asked = every > 0 && v.step % every == 0;
    with_velocity_steps += v.with_velocities ? 1 : 0;
    for (const auto& s : v.snapshots)
      if (s.mean_vx.empty() == asked || s.mean_vx.size() != (asked ? s.free.size() : 0u))
        ++velocity_mismatches;
  }
};

struct Thrower : cosim::StepObserver {
  int at = 0;
  void OnStep(const cosim::StepView& v) override {
    if (v.step == at) throw std::runtime_error("observer failed");
  }
};

std::vector<eval::ScenarioMetrics> RunHighway(int threads, const std::string& work,
                                              Recorder* recorder) {
  cosim::CoSimulation cs(Highway(6.0), {.threads = threads});
  cs.Start(sim::DefaultNetworkDir(), WorkDir(work));
  cs.AddObserver(recorder);
  while (cs.Step()) {
  }
  CHECK(cs.finished());
  CHECK(cs.steps() == cs.config().sim.StepCount());
  CHECK(cs.total_detections() == static_cast<std::size_t>(recorder->detections));
  return cs.Metrics();
}

}  // namespace

TEST_CASE("CoSimulation: observers, velocities on demand, determinism over threads",
          "[cosim][sumo]") {
  Recorder one, two;
  one.every = 7;
  two.every = 0;
  const auto m1 = RunHighway(1, "t1", &one);
  // A second SUMO in the same process, after the first has ended (the Python module relies on it).
  const auto m2 = RunHighway(2, "t2", &two);

  const double dt = Highway(6.0).sim.step_length;
  const int n = Highway(6.0).sim.StepCount();
  REQUIRE(n == static_cast<int>(std::lround(6.0 / dt)));
  REQUIRE(one.steps.size() == static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < one.steps.size(); ++i) {
    CHECK(one.steps[i] == static_cast<int>(i));
    CHECK(one.times[i] == Approx(dt * (i + 1)));
  }
  CHECK(one.with_velocity_steps == (n - 1) / 7 + 1);  // steps 0, 7, 14, ...
  CHECK(two.with_velocity_steps == 0);
  CHECK(one.velocity_mismatches == 0);
  CHECK(two.velocity_mismatches == 0);

  // The same detections and the same metrics, whatever the thread count and velocity requests.
  CHECK(one.detections == two.detections);
  CHECK(one.digests == two.digests);
  REQUIRE(m1.size() == 3u);
  REQUIRE(m2.size() == 3u);
  // Every field, per object too, as written to metrics.json.
  for (std::size_t m = 0; m < 3; ++m) CHECK(nlohmann::json(m1[m]) == nlohmann::json(m2[m]));
  // The run saw and tracked its vehicles: the comparison is not vacuous.
  CHECK(m1[2].objects_scored > 0);
  CHECK(m1[2].matches > 0);
  CHECK(m1[2].cells.has_value());
}

// Checks, in each Prepare part, that the part's inputs are complete (docs: StepObserver): the
// truth and the read-ahead before the step part, mode m's filter cycle before its filtered part,
// its scoring before its scored part, every part once and before OnStep. With 3 modes on 2
// threads the parts run while other filters still run, on either thread: a part started before
// its filter ended would see the filter's step count of the previous cycle.
struct PartChecker : cosim::StepObserver {
  explicit PartChecker(int modes, std::size_t cells, int steps)
      : modes(modes), cells(cells), last_step(steps - 1), seen(modes) {
    for (auto& mode : seen)
      for (auto& part : mode) part.store(-1);
  }
  int modes;
  std::size_t cells;
  int last_step;
  bool read_ahead = true;
  std::atomic<int> step_part{-1};
  std::vector<std::array<std::atomic<int>, 2>> seen;  // per mode: filtered, scored (last step)
  std::atomic<int> bad{0}, parts{0};
  std::mutex mutex;
  std::vector<std::string> failures;
  void Fail(const std::string& what, int step, int mode) {
    bad.fetch_add(1);
    const std::lock_guard<std::mutex> lock(mutex);
    failures.push_back(what + " at step " + std::to_string(step) + ", mode " +
                       std::to_string(mode));
  }
  bool WantsVelocities(int step, double) override { return step % 3 == 0; }
  void Prepare(const cosim::StepView& v, Part part, int mode) override {
    parts.fetch_add(1);
    if (part == Part::kStep) {
      if (v.truth_classes.size() != cells) Fail("the truth was not complete", v.step, mode);
      // The next step was read ahead (in the region of the step before the last).
      if (read_ahead && v.step < last_step && v.pipeline.ahead_read() != std::uint64_t(v.step) + 1)
        Fail("the next step was not read ahead yet", v.step, mode);
      if (step_part.exchange(v.step) != v.step - 1) Fail("the step part twice", v.step, mode);
      return;
    }
    if (step_part.load() != v.step) Fail("a mode's part before the step part", v.step, mode);
    const auto k = static_cast<std::size_t>(mode);
    // The filter has finished this step's cycle (its step count counts the cycles).
    if (v.pipeline.grid(k).step() != std::uint64_t(v.step) + 1)
      Fail("a part before its filter's cycle ended", v.step, mode);
    if (part == Part::kFiltered) {
      if (seen[k][0].exchange(v.step) != v.step - 1) Fail("filtered part twice", v.step, mode);
      return;
    }
    if (seen[k][0].load() != v.step) Fail("scored part before the filtered part", v.step, mode);
    if (seen[k][1].exchange(v.step) != v.step - 1) Fail("scored part twice", v.step, mode);
    // The scoring ran: with velocities asked, they are in the snapshot (taken by the score).
    const auto& s = v.snapshots[k];
    if (v.with_velocities && s.mean_vx.size() != s.free.size())
      Fail("a scored part before its mode's velocities", v.step, mode);
  }
  void OnStep(const cosim::StepView& v) override {
    if (step_part.load() != v.step) Fail("OnStep before the step part", v.step, -1);
    for (int k = 0; k < modes; ++k)
      if (seen[k][1].load() != v.step) Fail("OnStep before a scored part", v.step, k);
  }
};

TEST_CASE("CoSimulation: observers' Prepare parts run after their inputs, before OnStep",
          "[cosim][sumo]") {
  for (int threads : {1, 2}) {
    INFO(threads << " threads");
    auto config = Highway(3.0);
    cosim::CoSimulation cs(config, {.threads = threads});
    cs.Start(sim::DefaultNetworkDir(), WorkDir("parts" + std::to_string(threads)));
    PartChecker c(3, static_cast<std::size_t>(config.filter.CellsX() * config.filter.CellsY()),
                  config.sim.StepCount());
    c.read_ahead = threads == 2;  // 3 modes on 1 thread: nothing to spare, nothing read ahead
    Recorder r;
    cs.AddObserver(&c);
    cs.AddObserver(&r);
    while (cs.Step()) {
    }
    REQUIRE(cs.steps() == config.sim.StepCount());
    for (const auto& f : c.failures) UNSCOPED_INFO(f);
    CHECK(c.bad.load() == 0);
    CHECK(c.parts.load() == cs.steps() * (1 + 2 * 3));
    CHECK(r.steps.size() == static_cast<std::size_t>(cs.steps()));
  }
}

// Called inside the caller's own active parallel region, the step's region gets one thread
// (nested regions stay off) although the schedule plans two: the filters planned for the missing
// thread are taken by the one there (StepRegion: a filter whose owner has not started it), as a
// late or preempted owner's are. Before, they were never run and the step waited for them for
// ever: the other thread of this team stops the test then instead of letting it hang.
TEST_CASE("CoSimulation: inside the caller's parallel region one thread filters every mode",
          "[cosim][sumo]") {
  auto config = Highway(2.0);
  Recorder two;
  const auto m2 = [&] {
    cosim::CoSimulation cs(config, {.threads = 2});
    cs.Start(sim::DefaultNetworkDir(), WorkDir("nested_ref"));
    cs.AddObserver(&two);
    while (cs.Step()) {
    }
    return cs.Metrics();
  }();
  Recorder nested;
  PartChecker c(3, static_cast<std::size_t>(config.filter.CellsX() * config.filter.CellsY()),
                config.sim.StepCount());
  std::vector<eval::ScenarioMetrics> m1;
  int steps = 0;
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
#pragma omp parallel num_threads(2)
  {
    if (omp_get_thread_num() == 0) {
      cosim::CoSimulation cs(config, {.threads = 2});
      cs.Start(sim::DefaultNetworkDir(), WorkDir("nested"));
      cs.AddObserver(&c);
      cs.AddObserver(&nested);
      while (cs.Step()) {
      }
      steps = cs.steps();
      m1 = cs.Metrics();
      const std::lock_guard<std::mutex> lock(mutex);
      done = true;
      cv.notify_all();
    } else {
      std::unique_lock<std::mutex> lock(mutex);
      if (!cv.wait_for(lock, std::chrono::seconds(300), [&] { return done; })) {
        std::fprintf(stderr, "test_cosim: the step inside a parallel region hangs\n");
        std::abort();
      }
    }
  }
  REQUIRE(steps == config.sim.StepCount());
  for (const auto& f : c.failures) UNSCOPED_INFO(f);
  CHECK(c.bad.load() == 0);
  CHECK(c.parts.load() == steps * (1 + 2 * 3));
  CHECK(nested.digests == two.digests);
  REQUIRE(m1.size() == 3u);
  REQUIRE(m2.size() == 3u);
  for (std::size_t m = 0; m < 3; ++m) CHECK(nlohmann::json(m1[m]) == nlohmann::json(m2[m]));
}

struct PrepareThrower : cosim::StepObserver {
  int at = 0;
  int on_steps = 0;
  void Prepare(const cosim::StepView& v, Part part, int mode) override {
    if (v.step == at && part == Part::kScored && mode == 1)
      throw std::runtime_error("prepare failed");
  }
  void OnStep(const cosim::StepView&) override { ++on_steps; }
};

TEST_CASE("CoSimulation: an exception of a Prepare part leaves Step() where its OnStep would run",
          "[cosim][sumo]") {
  cosim::CoSimulation cs(Highway(1.0), {.threads = 2});
  cs.Start(sim::DefaultNetworkDir(), WorkDir("prepare_throw"));
  Recorder before, after;
  PrepareThrower t;
  t.at = 1;
  cs.AddObserver(&before);
  cs.AddObserver(&t);
  cs.AddObserver(&after);
  CHECK(cs.Step());
  CHECK_THROWS_WITH(cs.Step(), "prepare failed");
  CHECK(before.steps == std::vector<int>{0, 1});  // the observers before it ran
  CHECK(t.on_steps == 1);                         // its own OnStep did not
  CHECK(after.steps == std::vector<int>{0});      // nor those after it
  CHECK(cs.Step());
  CHECK(after.steps == std::vector<int>{0, 2});
}

TEST_CASE("CoSimulation: errors before SUMO starts, and an observer's error", "[cosim][sumo]") {
  SECTION("memory beyond the machine is refused before anything is allocated or started") {
    auto config = Highway(1.0);
    config.filter.num_particles = 2'000'000'000;
    CHECK_THROWS_AS(cosim::CoSimulation(config), std::invalid_argument);
    CHECK_THROWS_WITH(cosim::CoSimulation(config), Catch::Contains("filter.num_particles"));
  }
  SECTION("an invalid sensor is named") {
    auto config = Highway(1.0);
    config.radar.sensors.front().fov = -1.0;
    CHECK_THROWS_WITH(cosim::CoSimulation(config),
                      Catch::Contains(config.radar.sensors.front().name));
  }
  SECTION("stepping before Start is misuse") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {}});
    CHECK_THROWS_AS(cs.Step(), std::logic_error);
  }
  SECTION("a missing network is bad input") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {}});
    CHECK_THROWS_AS(cs.Start(WorkDir("nonet") / "none", WorkDir("nonet")), std::invalid_argument);
  }
  SECTION("an observer's exception leaves Step() after the step was done") {
    cosim::CoSimulation cs(Highway(1.0), {.modes = {filter::WeightMode::kDual}});
    cs.Start(sim::DefaultNetworkDir(), WorkDir("throw"));
    Thrower t;
    t.at = 2;
    cs.AddObserver(&t);
    CHECK(cs.Step());
    CHECK(cs.Step());
    CHECK_THROWS_WITH(cs.Step(), "observer failed");
    CHECK(cs.steps() == 3);
  }
  SECTION("the same with three modes on two threads (the scoring spread over both)") {
    cosim::CoSimulation cs(Highway(1.0), {.threads = 2});
    cs.Start(sim::DefaultNetworkDir(), WorkDir("throw2"));
    Thrower t;
    t.at = 2;
    Recorder r;
    cs.AddObserver(&t);
    cs.AddObserver(&r);
    CHECK(cs.Step());
    CHECK(cs.Step());
    CHECK_THROWS_WITH(cs.Step(), "observer failed");
    CHECK(cs.steps() == 3);
    CHECK(r.steps == std::vector<int>{0, 1});  // the observers after the thrower were not run
    // The run goes on: the next step (read ahead during the observed one) is the fourth.
    CHECK(cs.Step());
    CHECK(cs.steps() == 4);
    CHECK(r.steps == std::vector<int>{0, 1, 3});
    CHECK(cs.pipeline().ahead_read() == 4u);  // steps 1 to 4
  }
}

TEST_CASE("CoSimulation without modes: SUMO and the radar only", "[cosim][sumo]") {
  cosim::CoSimulation cs(Highway(2.0), {.modes = {}});
  cs.Start(sim::DefaultNetworkDir(), WorkDir("nomodes"));
  Recorder r;
  cs.AddObserver(&r);
  while (cs.Step()) {
  }
  CHECK(static_cast<int>(r.steps.size()) == cs.config().sim.StepCount());
  CHECK(r.detections > 0);
  CHECK(cs.Metrics().empty());
  CHECK(cs.pipeline().has_radar());
  CHECK(cs.pipeline().radar().sensors().size() == cs.config().radar.sensors.size());
}

namespace {

// What a run shows of its end; the tests below compare it with reading ahead on and off.
struct Ending {
  int steps = 0;
  bool finished = false, ego_left = false;
  double last_time = 0.0;
  std::string error;  // the exception's type and message, empty without one
  std::vector<double> observed_times;
  std::vector<nlohmann::json> metrics;
  std::uint64_t read = 0, hits = 0;
  double sumo_time = 0.0;  // SUMO's own frame after the run
};

// Runs `config` on two threads with three modes (one thread has time to spare) until its end,
// an exception, or `stop_after` steps (a stop request between steps), then Finish().
Ending RunUntilEnd(const scenario::ScenarioConfig& config, bool read_ahead, const std::string& work,
                   int stop_after = -1) {
  cosim::CoSimulation cs(config, {.threads = 2, .read_ahead = read_ahead});
  cs.Start(sim::DefaultNetworkDir(), WorkDir(work));
  Recorder r;
  cs.AddObserver(&r);
  Ending e;
  try {
    while ((stop_after < 0 || cs.steps() < stop_after) && cs.Step()) {
    }
  } catch (const std::exception& x) {
    e.error = std::string(typeid(x).name()) + ": " + x.what();
  }
  cs.Finish();
  e.steps = cs.steps();
  e.finished = cs.finished();
  e.ego_left = cs.pipeline().simulation().ego_left();
  e.last_time = cs.pipeline().frame().time;
  e.observed_times = r.times;
  for (const auto& m : cs.Metrics()) e.metrics.emplace_back(m);
  e.read = cs.pipeline().ahead_read();
  e.hits = cs.pipeline().ahead_hits();
  e.sumo_time = cs.pipeline().simulation().frame().time;
  return e;
}

// Small filters: these tests are about the order of the step's parts, not about tracking.
scenario::ScenarioConfig Small(scenario::ScenarioConfig config) {
  config.filter.num_particles = 3000;
  config.filter.num_birth = 300;
  return config;
}

void CheckSameEnding(const Ending& off, const Ending& on) {
  CHECK(on.steps == off.steps);
  CHECK(on.finished == off.finished);
  CHECK(on.ego_left == off.ego_left);
  CHECK(on.last_time == off.last_time);
  CHECK(on.error == off.error);
  CHECK(on.observed_times == off.observed_times);
  REQUIRE(on.metrics.size() == off.metrics.size());
  for (std::size_t m = 0; m < on.metrics.size(); ++m) CHECK(on.metrics[m] == off.metrics[m]);
  CHECK(off.read == 0u);
  CHECK(off.hits == 0u);
  // The grid read ahead is built only while another thread has work (timing): taken or not.
  CHECK(on.hits <= on.read);
}

}  // namespace

TEST_CASE("CoSimulation reading SUMO ahead: the same steps, ends, errors and stops",
          "[cosim][sumo]") {
  const double dt = Highway(1.0).sim.step_length;
  SECTION("the end of the duration") {
    const auto config = Small(Highway(2.0));
    const Ending off = RunUntilEnd(config, false, "end_off");
    const Ending on = RunUntilEnd(config, true, "end_on");
    CheckSameEnding(off, on);
    CHECK(on.steps == config.sim.StepCount());
    CHECK(on.finished);
    // SUMO's step and the scan were read ahead for every step but the first.
    CHECK(on.read == static_cast<std::uint64_t>(on.steps - 1));
    CHECK(on.sumo_time == off.sumo_time);
  }
  SECTION("a SUMO error (an action naming a vehicle not on the road yet) at its own step") {
    auto config = Small(Highway(3.0));
    // left_car departs at 36 s: the action at 1.0 s (the 20th step) fails in SUMO's step.
    sim::ActionSpec action;
    action.time = 1.0;
    action.vehicle = "left_car";
    action.set_speed = 30.0;
    config.sim.actions.insert(config.sim.actions.begin(), action);
    const Ending off = RunUntilEnd(config, false, "err_off");
    const Ending on = RunUntilEnd(config, true, "err_on");
    CheckSameEnding(off, on);
    CHECK(off.error.find("action at run time 1 s names vehicle 'left_car'") != std::string::npos);
    // Every step before it was done and observed (nothing lost); the error came with the 20th.
    CHECK(on.steps == 19);
    CHECK(on.observed_times.size() == 19u);
    CHECK(on.last_time == Approx(19 * dt));
    CHECK(on.read == 18u);
    CHECK_FALSE(on.finished);
  }
  SECTION("the ego leaving the network") {
    const auto dir = WorkDir("short_route");
    // The route ends about 450 m ahead of the ego, at 27.78 m/s: SUMO ends near 16 s, before 20 s.
    std::ofstream(dir / "short.yaml")
        << "network: highway\nduration: 20.0\nroutes: {short: [east_1, east_2]}\n"
           "ego: {type: car, route: short, lane: 1, position: 1350, speed: 27.78,\n"
           "      speed_policy: {mode: fixed, speed: 27.78}}\n";
    const auto config = Small(scenario::LoadScenario(dir / "short.yaml"));
    const Ending off = RunUntilEnd(config, false, "left_off");
    const Ending on = RunUntilEnd(config, true, "left_on");
    CheckSameEnding(off, on);
    CHECK(on.ego_left);
    CHECK_FALSE(on.finished);
    CHECK(on.error.empty());
    CHECK(on.steps > 100);
    CHECK(on.steps < config.sim.StepCount());
    CHECK(on.read == static_cast<std::uint64_t>(on.steps - 1));
  }
  SECTION("a stop between steps") {
    const auto config = Small(Highway(3.0));
    const Ending off = RunUntilEnd(config, false, "stop_off", 25);
    const Ending on = RunUntilEnd(config, true, "stop_on", 25);
    CheckSameEnding(off, on);
    CHECK(on.steps == 25);
    CHECK_FALSE(on.finished);
    CHECK(on.last_time == Approx(25 * dt));
    // As documented (CoSimOptions::read_ahead): SUMO itself had simulated the step after.
    CHECK(off.sumo_time == Approx(25 * dt));
    CHECK(on.sumo_time == Approx(26 * dt));
  }
}
