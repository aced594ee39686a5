// `dualgrid run`: one SUMO run, one radar stream, three filters side by side, scored per step.
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <exception>
#include <fstream>
#include <iostream>
#include <set>

#include <nlohmann/json.hpp>

#include "capture.hpp"
#include "commands.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "figures.hpp"
#include "output.hpp"
#include "pipeline.hpp"
#include "progress.hpp"
#include "run_outputs.hpp"
#include "scoring.hpp"
#include "signals.hpp"
#include "video.hpp"
#include "viewer.hpp"

namespace dualgrid::tools {

std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names) {
  std::vector<filter::WeightMode> modes;
  for (const std::string& n : names) {
    const auto m = filter::ParseWeightMode(n);
    if (!m)
      throw std::invalid_argument("unknown mode '" + n + "' (expected position, velocity, dual)");
    if (std::find(modes.begin(), modes.end(), *m) != modes.end())
      throw std::invalid_argument("mode '" + n + "' given twice");
    modes.push_back(*m);
  }
  if (modes.empty()) throw std::invalid_argument("--modes needs at least one mode");
  return modes;
}

namespace {

// Everything the run actually used, so any result can be rerun or compared.
nlohmann::json ConfigJson(const scenario::ScenarioConfig& c, const FilterRunOptions& o) {
  nlohmann::json j = scenario::ConfigToJson(c);
  j["modes"] = o.modes;
  return j;
}

// Resident memory of this process [MB] (/proc/self/statm), 0 if unreadable.
double ResidentMegabytes() {
  std::ifstream in("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  if (!(in >> pages_total >> pages_resident)) return 0.0;
  return static_cast<double>(pages_resident) * static_cast<double>(sysconf(_SC_PAGE_SIZE)) / 1e6;
}

// The grid picture times: the command line's, else the scenario's within the run, else 1/4, 1/2
// and 3/4 of it; sorted and unique. Times asked for on the command line must lie in the run.
std::vector<double> SnapshotTimes(const FilterRunOptions& options,
                                  const scenario::ScenarioConfig& config) {
  std::vector<double> times = options.snapshots;
  if (times.empty())
    for (double t : config.evaluation.snapshot_times)
      if (t > 0.0 && t <= config.sim.duration) times.push_back(t);
  if (times.empty())
    for (double f : {0.25, 0.5, 0.75}) times.push_back(f * config.sim.duration);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  for (double t : times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw std::invalid_argument("--snapshots: time " + Fixed(t, 2) +
                                  " s is outside the run (0, " + Fixed(config.sim.duration, 2) +
                                  "] s");
  return times;
}

}  // namespace

int RunFilters(const FilterRunOptions& options) {
  if (options.threads > 0) omp_set_num_threads(options.threads);
  const std::vector<filter::WeightMode> modes = ParseModes(options.modes);
  std::vector<std::string> mode_names;
  for (auto m : modes) mode_names.emplace_back(filter::ToString(m));
  scenario::ScenarioConfig config = LoadConfig(options.run);
  CheckFilterMemory(config, modes.size());
  const std::vector<double> snapshot_times = SnapshotTimes(options, config);
  const auto detections_path = DetectionPath(options.run.out, options.detections);
  const auto& out = options.run.out;
  PrepareOutputFolder(out);
  std::filesystem::create_directories(out / "figures");
  CopyScenario(config, out);
  WriteTextFile(out / "config.json", ConfigJson(config, options).dump(2) + "\n");

  const auto wall_start = std::chrono::steady_clock::now();
  Pipeline pipeline(config, options.run.network_dir, out, modes);
  GroundTruthWriter truth(out / "ground_truth.csv");
  std::unique_ptr<DetectionWriter> detections;
  if (detections_path) detections = std::make_unique<DetectionWriter>(*detections_path);
  ClusterWriter clusters(out / "clusters.csv");
  std::vector<ModeScorer> scorers(modes.size(), ModeScorer(config.evaluation));
  std::vector<std::string> warnings;  // figures that could not be drawn
  std::size_t next_snapshot = 0;

  // Weight traces (paper Fig. 4) of the dual filter, or of the last mode if dual is not run.
  const auto dual = std::find(modes.begin(), modes.end(), filter::WeightMode::kDual);
  const std::size_t trace_mode = dual != modes.end() ? dual - modes.begin() : modes.size() - 1;
  WeightTraces traces(config.evaluation.focus_object);
  nlohmann::json rss_mb = nlohmann::json::array();  // [time s, resident MB] with --check-invariants

  Progress progress("run " + config.sim.name + " seed " + std::to_string(config.sim.seed),
                    config.sim.StepCount(), !options.run.quiet);
  int steps = 0;
  std::size_t total_detections = 0;
  std::vector<GridSnapshot> snaps(modes.size());  // storage reused every step
  // The modes run concurrently as tasks, one thread each, in one parallel region per step instead
  // of ~40 (the filters' regions and barriers, three times): robust when another process shares
  // the cores (docs/performance.md).
  // With one mode (or one thread) the filter's own loops are parallel instead.
  const int threads = omp_get_max_threads();
  const int team = std::min(static_cast<int>(modes.size()), threads);
  // Threads beyond one per mode go to each filter's own loops (e.g. 8 threads, 3 modes: 3 x 2);
  // on 2 cores that is 1, and nested regions stay off.
  const int per_filter = std::max(1, threads / team);
  omp_set_max_active_levels(per_filter > 1 ? 2 : 1);
  std::vector<std::exception_ptr> errors(modes.size());
  // The replay recording (docs/replay.md): opened at the first recorded step, once the grid
  // frame is fixed.
  const int record_every =
      std::max(1, static_cast<int>(std::lround(options.record_interval / config.sim.step_length)));
  std::unique_ptr<replay::Writer> recorder;
  bool record_failed = false;
  replay::Header record_header;
  std::vector<replay::LiveCounter> counters(modes.size(),
                                            replay::LiveCounter(config.evaluation.tracking));
  std::vector<replay::Live> live(modes.size());
  std::set<int> recorded_ids;
  while (!StopSignal() && pipeline.Advance()) {
    const sim::Frame& f = pipeline.frame();
    truth.Write(f);
    if (detections) detections->Write(pipeline);
    total_detections += pipeline.detections().size();
    // Several requested times may fall into one step: one picture for all of them.
    bool picture = false;
    while (next_snapshot < snapshot_times.size() &&
           f.time + 1e-9 >= snapshot_times[next_snapshot]) {
      picture = true;
      ++next_snapshot;
    }
    // Every record_every-th step, and the last one (a run shorter than the interval still has a
    // frame). Off for good once a recording write failed.
    const bool record_now =
        options.record && !record_failed &&
        ((steps + 1) % record_every == 0 || steps + 1 == config.sim.StepCount());
    const bool with_velocity =
        (picture && (options.figures || options.write_particles)) || record_now;
    // All filters share one grid geometry (centred on the same ego), so the ground truth per cell
    // and per object is computed once for the first and holds for every mode.
    std::vector<std::uint8_t> truth_classes;
    std::vector<eval::TruthObject> objects;
    // Exceptions must not leave a parallel region: kept per mode, rethrown after it.
    auto guarded = [&](std::size_t m, auto&& work) {
      try {
        work();
      } catch (...) {
        errors[m] = std::current_exception();
      }
    };
    // Tasks: filter m, then (after filter 0) the shared truth, then scoring m once both are done.
    // A thread that finished a filter scores while another still filters (3 modes on 2 cores).
    std::vector<char> filtered(modes.size()), truth_done(1);
    std::exception_ptr truth_error;
    char* const f_dep = filtered.data();
    char* const t_dep = truth_done.data();
    (void)f_dep;  // used only in depend clauses, which GCC 12's -Wunused-variable misses
    (void)t_dep;
#pragma omp parallel num_threads(team) if (team > 1)
#pragma omp single
    {
      for (std::size_t m = 0; m < modes.size(); ++m) {
#pragma omp task depend(out : f_dep[m]) shared(pipeline, errors)
        guarded(m, [&] {
          if (team > 1) omp_set_num_threads(per_filter);  // this task's nested regions only
          pipeline.UpdateFilter(m);
        });
        if (m == 0) {
          // clang-format off
#pragma omp task depend(in: f_dep[0]) depend(out: t_dep[0]) \
    shared(pipeline, truth_error, objects, truth_classes, snaps, f)
          // clang-format on
          try {
            objects = pipeline.TruthObjects(pipeline.grid(0));
            TakeSnapshot(pipeline.grid(0), with_velocity, snaps[0]);
            truth_classes = TruthClasses(snaps[0], pipeline.grid_frame(), f, config.sim);
          } catch (...) {
            truth_error = std::current_exception();
          }
        }
        // clang-format off
#pragma omp task depend(in: f_dep[m], t_dep[0]) \
    shared(pipeline, errors, truth_error, objects, truth_classes, snaps, scorers, f)
        // clang-format on
        guarded(m, [&] {
          if (truth_error || errors[m]) return;
          if (m > 0) TakeSnapshot(pipeline.grid(m), with_velocity, snaps[m]);
          scorers[m].AddFrame(f.time, pipeline.grid(m), snaps[m], objects, truth_classes,
                              pipeline.grid_frame().ToGrid(f.ego.box));
        });
      }
    }
    if (truth_error) std::rethrow_exception(truth_error);
    for (auto& e : errors)
      if (e) std::rethrow_exception(e);
    for (std::size_t m = 0; m < modes.size(); ++m)
      clusters.Write(f, pipeline.grid_frame(), mode_names[m], scorers[m], objects, pipeline.ids());
    traces.Add(pipeline, trace_mode);
    if (options.record)
      for (std::size_t m = 0; m < modes.size(); ++m)
        live[m] = counters[m].Count(scorers[m], objects);
    if (record_now) {
      // The replay must never cost the run: a failed write (a full disk) stops the recording
      // with a warning; replay/ is then left without index.json, so it reads as unusable.
      try {
        if (!recorder) {
          record_header =
              replay::MakeHeader(pipeline, mode_names, record_every * config.sim.step_length,
                                 options.record_particles);
          recorder = std::make_unique<replay::Writer>(out / "replay", record_header);
        }
        recorder->Add(
            replay::Capture(pipeline, snaps, scorers, counters, live, objects, record_header));
        for (const auto& o : objects) recorded_ids.insert(o.id);
      } catch (const std::exception& e) {
        warnings.push_back(std::string("replay recording stopped: ") + e.what());
        std::cerr << "dualgrid: warning: " << warnings.back() << "\n";
        recorder.reset();
        record_failed = true;
      }
    }
    if (options.check_invariants) {
      for (std::size_t m = 0; m < modes.size(); ++m)
        if (const auto broken = pipeline.grid(m).CheckInvariants())
          throw std::logic_error("filter invariant broken at t = " + Fixed(f.time, 2) + " s (" +
                                 mode_names[m] + "): " + *broken);
      if (steps % std::max(1, static_cast<int>(std::lround(60.0 / config.sim.step_length))) == 0)
        rss_mb.push_back({f.time, ResidentMegabytes()});
    }
    const std::string stamp = Fixed(f.time, 2);
    if (options.figures && picture) {
      const auto grid_png = out / "figures" / ("grid_t" + stamp + ".png");
      TryFigures(
          grid_png, options.figure_formats,
          [&](const auto& p) {
            RenderGridFigure(mode_names, snaps, scorers, pipeline.grid_frame(), f, f.time, p);
          },
          &warnings);
      const auto scene_png = out / "figures" / ("scene_t" + stamp + ".png");
      TryFigures(
          scene_png, options.figure_formats,
          [&](const auto& p) { RenderScene(pipeline, p, 60, 140, 22); }, &warnings);
    }
    if (options.write_particles && picture)
      for (std::size_t m = 0; m < modes.size(); ++m)
        WriteParticles(pipeline, m, snaps[m],
                       out / "figures" / ("particles_" + mode_names[m] + "_t" + stamp + ".csv"));
    ++steps;
    progress.Update(steps, "t=" + Fixed(f.time, 1) + " s");
  }
  progress.Finish();
  const int stop = StopSignal();
  const double simulated = steps * config.sim.step_length;
  const bool complete = !stop && steps == config.sim.StepCount();
  std::string status;
  if (stop)
    status = "Incomplete run: stopped by signal " + std::to_string(stop) +
             " at t = " + Fixed(simulated, 2) + " s of " + Fixed(config.sim.duration, 2) + " s";
  else if (!complete)
    status = "Shorter run than asked: SUMO ended at t = " + Fixed(simulated, 2) + " s of " +
             Fixed(config.sim.duration, 2) + " s (the ego left the network; see sumo.log)";
  truth.Close();
  if (detections) detections->Close();
  clusters.Close();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  if (FaultInjected("run-seed:" + std::to_string(config.sim.seed)))
    throw std::runtime_error("injected fault (DUALGRID_FAULT) after the simulation");

  // Results first: nothing below may be lost to a figure that fails.
  std::vector<eval::ScenarioMetrics> metrics;
  std::vector<eval::ModeRuns> runs;
  nlohmann::json mj;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    metrics.push_back(scorers[m].Result());
    runs.push_back({mode_names[m], {metrics.back()}});
    mj["modes"][mode_names[m]] = metrics.back();
  }
  mj["scenario"] = config.sim.name;
  mj["seed"] = config.sim.seed;
  mj["steps"] = steps;
  mj["detections_per_step"] = steps ? static_cast<double>(total_detections) / steps : 0.0;
  for (const auto& o : metrics.front().objects)
    mj["object_names"][std::to_string(o.id)] = pipeline.ids().Name(o.id);
  WriteTextFile(out / "metrics.json", mj.dump(2) + "\n");
  WriteObjects(mode_names, metrics, pipeline.ids(), out / "objects.csv");
  eval::ComparisonTable table = eval::MakeComparisonTable(config.sim.name, runs);
  table.SetStatus(status);
  for (std::string& note :
       UnscoredNotes(metrics, pipeline.ids(), config.evaluation.tracking.min_frames_in_grid))
    table.AddNote(std::move(note));
  WriteTables(table, out);
  const std::string focus = traces.Focus();
  if (!focus.empty()) WriteWeights(traces.by_vehicle.at(focus), focus, out / "weights.csv");
  if (!options.run.quiet) std::cout << table.ToMarkdown() << "\n";
  if (recorder) {
    // After the results, before the figures: a failure here costs only the replay.
    try {
      record_header.metrics = mj["modes"];
      for (int id : recorded_ids) record_header.names[std::to_string(id)] = pipeline.ids().Name(id);
      record_header.complete = complete;
      record_header.status = status;
      recorder->Finish(record_header);
    } catch (const std::exception& e) {
      warnings.push_back(std::string("replay recording not written: ") + e.what());
      std::cerr << "dualgrid: warning: " << warnings.back() << "\n";
      recorder.reset();
    }
  }

  if (options.figures && !stop) {
    if (!focus.empty()) {
      const auto png = out / "figures" / "weights.png";
      TryFigures(
          png, options.figure_formats,
          [&](const auto& p) {
            RenderWeightTrace(traces.by_vehicle.at(focus), focus, mode_names[trace_mode],
                              config.filter.velocity_likelihood, p);
          },
          &warnings);
    }
    for (const bool v : {false, true}) {
      const auto png = out / "figures" / (v ? "tracked_share_v.png" : "tracked_share.png");
      const std::string what = v ? "D_v (tracked with the right velocity)" : "D";
      TryFigures(
          png, options.figure_formats,
          [&](const auto& p) {
            RenderTrackedShares(mode_names, RunTrackedShares(metrics, pipeline.ids(), v),
                                config.sim.name + ": tracked share " + what + " per object (seed " +
                                    std::to_string(config.sim.seed) + ")",
                                "tracked share " + what, p);
          },
          &warnings);
    }
  }

  if (recorder && !stop && (options.video || options.viewer)) {
    std::signal(SIGPIPE, SIG_IGN);  // a failing ffmpeg must not kill the run before summary.json
    ReplayOptions ro;
    ro.run_dir = out;
    ro.quiet = options.run.quiet;
    try {
      const replay::Reader reader(out);
      if (options.viewer) WriteViewer(reader, ro);
      if (options.video) WriteVideo(reader, ro);
    } catch (const std::exception& e) {
      warnings.push_back(std::string("replay not written: ") + e.what());
      std::cerr << "dualgrid: warning: " << warnings.back() << "\n";
    }
  }

  // Written last: a run folder without summary.json did not finish.
  nlohmann::json summary = {{"complete", complete},
                            {"status", status},
                            {"scenario", config.sim.name},
                            {"seed", config.sim.seed},
                            {"steps", steps},
                            {"simulated_s", simulated},
                            {"requested_s", config.sim.duration},
                            {"wall_s", wall},
                            {"warnings", warnings}};
  if (options.check_invariants) {
    rss_mb.push_back({steps * config.sim.step_length, ResidentMegabytes()});
    summary["invariants_checked_steps"] = steps;
    summary["rss_mb"] = rss_mb;
  }
  // The grid frame as resolved at the ego's departure (docs/algorithm.md, "Grid frame").
  summary["grid_frame"] = {{"frame", scenario::ToString(config.grid.frame)},
                           {"yaw_deg", RadToDeg(pipeline.grid_frame().yaw())}};
  // The radars as mounted on the ego's box as SUMO simulated it (config.json holds the rig as
  // read, on the scenario type's box: they differ for an ego of the user's route files).
  summary["sensors_mounted"] = nlohmann::json::array();
  for (const auto& s : pipeline.radar().sensors())
    summary["sensors_mounted"].push_back({{"name", s.name},
                                          {"x", s.mount.position.x()},
                                          {"y", s.mount.position.y()},
                                          {"yaw_deg", RadToDeg(s.mount.yaw)}});
  summary["digests"] = OutputDigests(out);
  WriteTextFile(out / "summary.json", summary.dump(2) + "\n");
  if (!status.empty())
    std::cerr << "dualgrid: " << status << "; results in " << out.string() << "\n";
  if (stop) return StopExitCode();
  if (!options.run.quiet)
    std::cout << config.sim.name << ": " << steps << " steps in " << Fixed(wall, 1)
              << " s; results in " << out.string()
              << (warnings.empty() ? ""
                                   : " (" + std::to_string(warnings.size()) +
                                         " figure(s) not drawn, see the warnings above)")
              << "\n";
  return 0;
}

}  // namespace dualgrid::tools
