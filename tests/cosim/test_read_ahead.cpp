// Reading a recorded source ahead (Pipeline::PrepareAhead, CoSimOptions::read_ahead) is a
// performance switch only: the co-simulation's results are the same bits with it on or off, the
// grid read ahead is taken in (nearly) every step, and a twin that reads other data is never
// taken.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <typeinfo>

#include <nlohmann/json.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/recorded/recorded_run.hpp"

using namespace dualgrid;

namespace {

// A short sequence like bench_recorded's: four corner radars scanning in turn (18.75 ms apart),
// the ego at 10 m/s, three labelled cars passing, static returns around; 0-60 detections per
// scan (some scans empty). `turn_rate` [rad/s]: the ego drives a circle, its lane turning with
// it, so that the grid (frame: follow) turns now and then.
cosim::RecordedSequence MakeSequence(double duration, double turn_rate) {
  cosim::RecordedSequence s;
  s.name = "sequence_read_ahead";
  const double mounts[4][3] = {
      {2.2, -0.87, -1.48}, {2.4, -0.70, -0.44}, {2.4, 0.70, 0.44}, {2.2, 0.87, 1.48}};
  for (int k = 0; k < 4; ++k) {
    radar::SensorParams p;
    p.name = "radar_" + std::to_string(k + 1);
    p.mount = {{mounts[k][0], mounts[k][1]}, mounts[k][2]};
    p.fov = DegToRad(120.0);
    p.max_range = 100.0;
    s.sensors.push_back(p);
  }
  s.track_names = {"car-1", "car-2", "car-3"};
  s.has_labels = true;
  CounterRng rng(7, RngPurpose::kTest, 0, 0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); };
  const std::int64_t t0 = 1'000'000;
  for (int i = 0; t0 + i * 18'750 < t0 + static_cast<std::int64_t>(duration * 1e6); ++i) {
    cosim::RecordedScan scan;
    scan.timestamp_us = t0 + i * 18'750;
    const double t = (scan.timestamp_us - t0) / 1e6;
    scan.sensor = i % 4;
    const double yaw = turn_rate * t;
    scan.ego_pose = {turn_rate == 0.0 ? Position(10.0 * t, 0.0)
                                      : Position(10.0 / turn_rate * std::sin(yaw),
                                                 10.0 / turn_rate * (1.0 - std::cos(yaw))),
                     yaw};
    scan.ego_velocity = 10.0 * UnitVector(yaw);
    scan.lane_yaw = yaw;
    scan.begin = s.points.size();
    const Pose2 sensor = scan.ego_pose.Compose(s.sensors[scan.sensor].mount);
    const int count = static_cast<int>(uniform(0.0, 61.0));
    for (int d = 0; d < count; ++d) {
      cosim::RecordedPoint p;
      const int track = d < 12 ? d / 4 : -1;
      Velocity v = Velocity::Zero();
      if (track >= 0) {
        const double speed = 12.0 + 3.0 * track;
        // Beside the ego, along its heading.
        p.position =
            scan.ego_pose.ToParent({20.0 + 15.0 * track + (speed - 10.0) * t + uniform(-2, 2),
                                    (track - 1) * 3.5 + uniform(-0.8, 0.8)});
        v = speed * UnitVector(yaw);
      } else {
        p.position = sensor.ToParent(uniform(2, 60) * UnitVector(uniform(-1.0, 1.0)));
      }
      const Vector2 rel = p.position - sensor.position;
      p.range = rel.norm();
      p.azimuth = WrapAngle(std::atan2(rel.y(), rel.x()) - sensor.yaw);
      p.radial_speed = v.dot(rel / p.range);
      p.range_rate = p.radial_speed - scan.ego_velocity.dot(rel / p.range);
      p.label = track >= 0 ? 0 : cosim::kStaticLabel;
      p.track = track;
      s.points.push_back(p);
    }
    scan.end = s.points.size();
    s.scans.push_back(scan);
  }
  s.time_origin_us = t0;
  return s;
}

// A source whose twin reads `other` instead of its own sequence.
class LyingSource : public cosim::RecordedSource {
 public:
  LyingSource(const cosim::RecordedSequence& own, const cosim::RecordedSequence& other,
              cosim::RecordedOptions o)
      : RecordedSource(own, o), other_(other), options_(o) {}
  std::unique_ptr<cosim::DetectionSource> Twin() const override {
    auto twin = std::make_unique<cosim::RecordedSource>(other_, options_);
    twin->Start();
    return twin;
  }

 private:
  const cosim::RecordedSequence& other_;
  cosim::RecordedOptions options_;
};

// FNV-1a over every mode's cell masses and clusters, step by step.
struct Digest : cosim::StepObserver {
  std::uint64_t h = 1469598103934665603ull;
  void Add(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  void OnStep(const cosim::StepView& v) override {
    for (const cosim::GridSnapshot& s : v.snapshots) {
      Add(s.free.data(), s.free.size() * sizeof(float));
      Add(s.static_occ.data(), s.static_occ.size() * sizeof(float));
      Add(s.dynamic.data(), s.dynamic.size() * sizeof(float));
    }
    for (const cosim::ModeScorer& m : v.scorers)
      for (const eval::Cluster& c : m.clusters()) {
        Add(c.position.data(), 2 * sizeof(double));
        Add(c.velocity.data(), 2 * sizeof(double));
        Add(&c.weight, sizeof c.weight);
      }
  }
};

struct Outcome {
  std::uint64_t digest = 0;
  std::vector<nlohmann::json> metrics;
  std::uint64_t prepared = 0, hits = 0;
  int steps = 0, realignments = 0;
};

Outcome Run(const cosim::RecordedSequence& seq, const cosim::RecordedSequence& twin_data,
            bool read_ahead, double batch_window = 0.001) {
  scenario::ScenarioConfig config = cosim::DefaultRecordedConfig();
  config.filter.num_particles = 4000;
  config.filter.num_birth = 400;
  REQUIRE(config.grid.frame == scenario::GridPlacement::Frame::kFollow);
  const cosim::RecordedOptions o = cosim::FitConfig(seq, batch_window, &config);
  cosim::CoSimulation cs(config, {.threads = 2, .read_ahead = read_ahead},
                         [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                           return std::make_unique<LyingSource>(seq, twin_data, o);
                         });
  Digest digest;
  cs.AddObserver(&digest);
  cs.Start({}, {});
  while (cs.Step()) {
  }
  Outcome out{digest.h,
              {},
              cs.pipeline().ahead_prepared(),
              cs.pipeline().ahead_hits(),
              cs.steps(),
              cs.pipeline().grid_realignments()};
  for (const auto& m : cs.Metrics()) out.metrics.emplace_back(m);
  return out;
}

}  // namespace

TEST_CASE("Reading a recorded source ahead: the same results, bit for bit, and used",
          "[cosim][recorded]") {
  struct Case {
    const char* name;
    double turn_rate, batch_window;
  };
  // A scan per step; and a turning ego with two or three scans per step (a 40 ms window), so that
  // steps differ in their sensors and detection counts and the grid turns between steps.
  for (const Case c : {Case{"straight, a scan per step", 0.0, 0.001},
                       Case{"turning, scans batched", 0.25, 0.04}}) {
    SECTION(c.name) {
      const cosim::RecordedSequence seq = MakeSequence(3.0, c.turn_rate);
      const Outcome off = Run(seq, seq, false, c.batch_window);
      const Outcome on = Run(seq, seq, true, c.batch_window);
      REQUIRE(off.steps > 50);
      CHECK(off.prepared == 0);
      CHECK(off.hits == 0);
      // Every step but the first (nothing read before it) takes the grid read ahead.
      CHECK(on.prepared == static_cast<std::uint64_t>(on.steps - 1));
      CHECK(on.hits == on.prepared);
      CHECK(on.steps == off.steps);
      CHECK(on.digest == off.digest);
      REQUIRE(on.metrics.size() == 3u);
      for (std::size_t m = 0; m < 3; ++m) CHECK(on.metrics[m] == off.metrics[m]);
      // The run tracked its cars, and the turning one turned its grid: not vacuous.
      CHECK(off.metrics[2]["matches"].get<int>() > 0);
      CHECK((c.turn_rate == 0.0 ? on.realignments == 0 : on.realignments >= 2));
      CHECK(on.realignments == off.realignments);
    }
  }
}

TEST_CASE("Reading ahead: a twin that reads other data is never taken", "[cosim][recorded]") {
  const cosim::RecordedSequence seq = MakeSequence(3.0, 0.0);
  const Outcome off = Run(seq, seq, false);
  // Inputs that differ from the step's in the measurements (every point 0.3 m away), or only in
  // the grid centre and the coverage (the ego 0.3 m away, its points where they were).
  cosim::RecordedSequence moved_points = seq, moved_ego = seq;
  for (cosim::RecordedPoint& p : moved_points.points) p.position.x() += 0.3;
  for (cosim::RecordedScan& scan : moved_ego.scans) scan.ego_pose.position.y() += 0.3;
  // A scan without detections has the same inputs in both (the ego did not move): those steps
  // after the first may take the grid read ahead, and only those.
  std::uint64_t empty = 0;
  for (std::size_t i = 1; i < seq.scans.size(); ++i)
    empty += seq.scans[i].begin == seq.scans[i].end;
  REQUIRE(empty > 0);
  for (const cosim::RecordedSequence* other : {&moved_points, &moved_ego}) {
    const Outcome lied_to = Run(seq, *other, true);
    // Prepared in every step (so the comparison was made), taken only where nothing differs.
    CHECK(lied_to.prepared == static_cast<std::uint64_t>(lied_to.steps - 1));
    CHECK(lied_to.hits == (other == &moved_points ? empty : 0u));
    CHECK(lied_to.digest == off.digest);
    for (std::size_t m = 0; m < 3; ++m) CHECK(lied_to.metrics[m] == off.metrics[m]);
  }
}

namespace {

// A source that can run ahead (as SUMO's can; no twin), over a recorded sequence, that fails on
// demand at its `at`-th Advance: that Advance or the Scan after it throws, or the source ends
// there. `advanced` counts its Advance calls, shared with the test.
class RunningAheadSource : public cosim::RecordedSource {
 public:
  enum class Fault { kNone, kAdvance, kScan, kEnd };
  RunningAheadSource(const cosim::RecordedSequence& s, cosim::RecordedOptions o, Fault fault,
                     int at, int* advanced)
      : RecordedSource(s, o), fault_(fault), at_(at), advanced_(advanced) {}
  bool can_run_ahead() const override { return true; }
  std::unique_ptr<cosim::DetectionSource> Twin() const override { return nullptr; }
  bool Advance(cosim::IdRegistry& ids) override {
    ++*advanced_;
    if (*advanced_ == at_ && fault_ == Fault::kEnd) return false;
    if (*advanced_ == at_ && fault_ == Fault::kAdvance)
      throw std::runtime_error("source failed at step " + std::to_string(at_));
    return RecordedSource::Advance(ids);
  }
  void Scan(cosim::IdRegistry& ids, std::vector<radar::Detection>* detections,
            std::vector<int>* scanned) override {
    if (*advanced_ == at_ && fault_ == Fault::kScan)
      throw std::invalid_argument("radar failed at step " + std::to_string(at_));
    RecordedSource::Scan(ids, detections, scanned);
  }

 private:
  Fault fault_;
  int at_;
  int* advanced_;
};

// Per observed step: how many steps the source had read by then, and the step's time and
// detection count as the observers see them.
struct SourceWatch : cosim::StepObserver {
  const int* advanced = nullptr;
  std::vector<int> read_by_then;
  std::vector<double> times;
  std::vector<std::size_t> detections;
  void OnStep(const cosim::StepView& v) override {
    read_by_then.push_back(*advanced);
    times.push_back(v.frame.time);
    detections.push_back(v.pipeline.detections().size());
  }
};

struct FaultOutcome {
  Outcome run;
  std::uint64_t read = 0;  // steps read ahead
  std::string error;       // type and message
  bool finished = false;
  SourceWatch watch;
};

FaultOutcome RunWithFault(const cosim::RecordedSequence& seq, RunningAheadSource::Fault fault,
                          int at, bool read_ahead, int threads = 2) {
  scenario::ScenarioConfig config = cosim::DefaultRecordedConfig();
  config.filter.num_particles = 4000;
  config.filter.num_birth = 400;
  const cosim::RecordedOptions o = cosim::FitConfig(seq, 0.001, &config);
  int advanced = 0;
  cosim::CoSimulation cs(config, {.threads = threads, .read_ahead = read_ahead},
                         [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                           return std::make_unique<RunningAheadSource>(seq, o, fault, at,
                                                                       &advanced);
                         });
  FaultOutcome out;
  Digest digest;
  out.watch.advanced = &advanced;
  cs.AddObserver(&digest);
  cs.AddObserver(&out.watch);
  cs.Start({}, {});
  try {
    while (cs.Step()) {
    }
  } catch (const std::exception& e) {
    out.error = std::string(typeid(e).name()) + ": " + e.what();
  }
  out.run = {digest.h,
             {},
             cs.pipeline().ahead_prepared(),
             cs.pipeline().ahead_hits(),
             cs.steps(),
             cs.pipeline().grid_realignments()};
  for (const auto& m : cs.Metrics()) out.run.metrics.emplace_back(m);
  out.finished = cs.finished();
  out.read = cs.pipeline().ahead_read();
  return out;
}

}  // namespace

TEST_CASE("Running a source ahead: its end and its errors surface at their own step",
          "[cosim][recorded]") {
  using Fault = RunningAheadSource::Fault;
  const cosim::RecordedSequence seq = MakeSequence(1.5, 0.0);
  struct Case {
    const char* name;
    Fault fault;
    const char* message;
  };
  constexpr int kAt = 30;  // the 30th step fails: 29 are done
  for (const Case c :
       {Case{"the source's step throws", Fault::kAdvance, "source failed at step 30"},
        Case{"the scan throws (bad input)", Fault::kScan, "radar failed at step 30"},
        Case{"the source ends early", Fault::kEnd, ""}}) {
    SECTION(c.name) {
      const FaultOutcome off = RunWithFault(seq, c.fault, kAt, false);
      const FaultOutcome on = RunWithFault(seq, c.fault, kAt, true);
      // Read ahead: after every step, the source stood one step further than without.
      REQUIRE(on.watch.read_by_then.size() == static_cast<std::size_t>(kAt - 1));
      for (std::size_t k = 0; k < on.watch.read_by_then.size(); ++k) {
        CHECK(off.watch.read_by_then[k] == static_cast<int>(k) + 1);
        CHECK(on.watch.read_by_then[k] == static_cast<int>(k) + 2);
      }
      CHECK(on.read == static_cast<std::uint64_t>(kAt - 2));
      CHECK(off.read == 0u);
      // Its grid is built ahead only while another thread still filters: taken or not.
      CHECK(on.run.hits <= on.read);
      CHECK(off.run.hits == 0u);
      // The same steps done and seen, the same error at the same step, nothing lost.
      CHECK(on.run.steps == kAt - 1);
      CHECK(off.run.steps == kAt - 1);
      CHECK(on.error == off.error);
      CHECK(on.error.find(c.message) != std::string::npos);
      CHECK(on.error.empty() == (c.fault == Fault::kEnd));
      CHECK(on.watch.times == off.watch.times);
      CHECK(on.watch.detections == off.watch.detections);
      CHECK(on.run.digest == off.run.digest);
      REQUIRE(on.run.metrics.size() == 3u);
      for (std::size_t m = 0; m < 3; ++m) CHECK(on.run.metrics[m] == off.run.metrics[m]);
      CHECK_FALSE(on.finished);
      CHECK_FALSE(off.finished);
    }
  }
  SECTION("to the sequence's end, on one, two and three threads") {
    const FaultOutcome one = RunWithFault(seq, Fault::kNone, 0, true, 1);
    const FaultOutcome two = RunWithFault(seq, Fault::kNone, 0, true, 2);
    const FaultOutcome three = RunWithFault(seq, Fault::kNone, 0, true, 3);
    CHECK(one.read == 0u);  // no thread with time to spare: read in Advance
    CHECK(three.read == 0u);
    CHECK(two.read == static_cast<std::uint64_t>(two.run.steps - 1));
    REQUIRE(two.run.steps > 60);
    for (const FaultOutcome* o : {&one, &three}) {
      CHECK(o->run.steps == two.run.steps);
      CHECK(o->run.digest == two.run.digest);
      CHECK(o->finished);
      for (std::size_t m = 0; m < 3; ++m) CHECK(o->run.metrics[m] == two.run.metrics[m]);
    }
    CHECK(two.finished);
    CHECK(two.error.empty());
  }
}
