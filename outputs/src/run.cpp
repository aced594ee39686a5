#include "dualgrid/outputs/run.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_config.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/outputs/run_observers.hpp"
#include "dualgrid/outputs/video.hpp"
#include "dualgrid/outputs/viewer.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "pictures.hpp"

namespace dualgrid::outputs {

void RunFolderOptions::Validate() const {
  if (out.empty()) throw std::invalid_argument("--out: expected a folder, got an empty path");
  DetectionPath(out, detections);  // names --detections
  for (const std::string& f : figure_formats)
    if (std::find(kFigureFormats.begin(), kFigureFormats.end(), f) == kFigureFormats.end())
      throw std::invalid_argument("--figure-formats: expected png, svg or pdf, got '" + f + "'");
  if (!(record_interval > 0.0))
    throw std::invalid_argument("--record-interval: expected a time > 0 s, got " +
                                FormatSignificant(record_interval, 6));
  if (record_particles < 0)
    throw std::invalid_argument("--record-particles: expected 0 or more, got " +
                                std::to_string(record_particles));
  if ((video || viewer) && !record)
    throw std::invalid_argument(
        "--video and --viewer need the recording: drop --no-record / --no-figures");
}

std::vector<double> SnapshotTimes(const std::vector<double>& requested,
                                  const scenario::ScenarioConfig& config) {
  std::vector<double> times = requested;
  if (times.empty())
    for (double t : config.evaluation.snapshot_times)
      if (t > 0.0 && t <= config.sim.duration) times.push_back(t);
  if (times.empty())
    for (double f : {0.25, 0.5, 0.75}) times.push_back(f * config.sim.duration);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  for (double t : times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw std::invalid_argument("--snapshots: time " + FormatFixed(t, 2) +
                                  " s is outside the run (0, " +
                                  FormatFixed(config.sim.duration, 2) + "] s of run time");
  return times;
}

namespace {

// The observers of a run, added to the co-simulation in the order they run after each step.
struct RunObservers {
  RunObservers(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
               const RunFolderOptions& o, std::vector<std::string>* warnings)
      : worker(o.output_thread),
        trace_mode(TraceMode(cosim.mode_names())),
        files(o.out, DetectionPath(o.out, o.detections), config.radar.options.multipath.enabled,
              trace_mode, config.evaluation.focus_object, ExactDetections(o.detections)),
        pictures(o.out, SnapshotTimes(o.snapshots, config), o, warnings, worker) {
    cosim.AddObserver(&files);
    if (o.record) {
      recording.emplace(o.out, config, o.record_interval, o.record_particles,
                        WordsFor(o.references).legend, warnings, worker);
      cosim.AddObserver(&*recording);
    }
    if (o.check_invariants) {
      invariants.emplace(config.sim.step_length);
      cosim.AddObserver(&*invariants);
    }
    cosim.AddObserver(&pictures);
  }
  // Weight traces (paper Fig. 4) of the dual filter, or of the last mode if dual is not run.
  static std::size_t TraceMode(const std::vector<std::string>& modes) {
    const auto dual = std::find(modes.begin(), modes.end(), "dual");
    return dual != modes.end() ? static_cast<std::size_t>(dual - modes.begin()) : modes.size() - 1;
  }

  // First: destroyed last, after the observers whose jobs it may still run (an error ending the
  // run early still finishes the pictures and frames handed over).
  OutputWorker worker;
  std::size_t trace_mode;
  RunFilesObserver files;
  std::optional<RecordingObserver> recording;
  std::optional<InvariantObserver> invariants;
  PictureObserver pictures;
};

// Notes for the table: the objects that were in the grid but too briefly to be scored.
std::vector<std::string> UnscoredNotes(const std::vector<eval::ScenarioMetrics>& metrics,
                                       const cosim::IdRegistry& ids, int min_frames_in_grid) {
  // Every mode sees the same vehicles in the same grid: the first mode's objects suffice.
  if (metrics.empty()) return {};
  std::string list;
  int count = 0;
  for (const auto& o : metrics.front().objects) {
    if (o.scored) continue;
    if (++count <= 12)
      list += (list.empty() ? "" : ", ") + ids.Name(o.id) + " (" +
              std::to_string(o.frames_in_grid) + ")";
  }
  if (count == 0) return {};
  if (count > 12) list += ", and " + std::to_string(count - 12) + " more";
  return {"Not scored, fewer than " + std::to_string(min_frames_in_grid) +
          " frames in the grid (`evaluation.min_frames_in_grid`): " + list +
          ". Their frames are in objects.csv."};
}

// The table notes of a recorded run: the point-level scores per mode, or what cannot be scored
// without labels, and the skipped detections.
std::vector<std::string> RecordedNotes(const RecordedRun& r, const std::vector<std::string>& modes,
                                       const std::vector<eval::ScenarioMetrics>& metrics) {
  std::vector<std::string> notes;
  if (!r.labels) {
    notes.push_back(
        "Recorded data without labels (label_id): no point-level scores and no tracks, so D, "
        "D_v and the cell scores are empty; the grids, clusters and figures are complete.");
  }
  for (std::size_t m = 0; m < modes.size() && r.labels; ++m) {
    const auto& p = metrics[m].points;
    if (!p) continue;
    auto f = [](const std::optional<double>& v) { return v ? FormatFixed(*v, 3) : "—"; };
    notes.push_back(
        "Point-level dynamic classification, " + modes[m] + ": precision " + f(p->precision) +
        ", recall " + f(p->recall) + ", F1 " + f(p->f1) + " (" + std::to_string(p->true_positives) +
        " TP, " + std::to_string(p->false_positives) + " FP, " +
        std::to_string(p->false_negatives) + " FN over " + std::to_string(p->frames) + " cycles; " +
        (r.annotated ? std::string("D and D_v per instance against its annotated boxes).")
                     : std::string("D and D_v per track_id against boxes estimated from "
                                   "the tracks' points).")));
  }
  notes.insert(notes.end(), r.notes.begin(), r.notes.end());
  if (r.skipped_points > 0)
    notes.push_back(std::to_string(r.skipped_points) +
                    " detection(s) skipped: NaN position, azimuth, range or velocity.");
  return notes;
}

// metrics.json's content.
nlohmann::json MetricsJson(const cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                           const std::vector<eval::ScenarioMetrics>& metrics) {
  const std::vector<std::string>& modes = cosim.mode_names();
  const cosim::IdRegistry& ids = cosim.pipeline().ids();
  nlohmann::json mj;
  for (std::size_t m = 0; m < modes.size(); ++m) mj["modes"][modes[m]] = metrics[m];
  mj["scenario"] = config.sim.name;
  mj["seed"] = config.sim.seed;
  mj["steps"] = cosim.steps();
  mj["detections_per_step"] =
      cosim.steps() ? static_cast<double>(cosim.total_detections()) / cosim.steps() : 0.0;
  for (const auto& o : metrics.front().objects)
    mj["object_names"][std::to_string(o.id)] = ids.Name(o.id);
  return mj;
}

// metrics.json, objects.csv, table.md|csv|json, weights.csv. Returns table.md's text.
std::string WriteResults(const cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                         const std::filesystem::path& out, const RecordedRun* recorded,
                         const std::vector<eval::ScenarioMetrics>& metrics,
                         const nlohmann::json& metrics_json, const std::string& status,
                         const WeightTraces& traces) {
  const std::vector<std::string>& modes = cosim.mode_names();
  const cosim::IdRegistry& ids = cosim.pipeline().ids();
  WriteTextFile(out / "metrics.json", metrics_json.dump(2) + "\n");
  WriteObjects(modes, metrics, ids, out / "objects.csv",
               recorded && !recorded->categories.empty() ? &recorded->categories : nullptr);
  std::vector<eval::ModeRuns> runs;
  for (std::size_t m = 0; m < modes.size(); ++m) runs.push_back({modes[m], {metrics[m]}});
  eval::ComparisonTable table = eval::MakeComparisonTable(config.sim.name, runs);
  table.SetStatus(status);
  for (std::string& note :
       UnscoredNotes(metrics, ids, config.evaluation.tracking.min_frames_in_grid))
    table.AddNote(std::move(note));
  if (recorded)
    for (std::string note : RecordedNotes(*recorded, modes, metrics))
      table.AddNote(std::move(note));
  WriteTables(table, out);
  const std::string focus = traces.Focus();
  if (!focus.empty()) WriteWeights(traces.by_vehicle.at(focus), focus, out / "weights.csv");
  return table.ToMarkdown();
}

// figures/weights.* and figures/tracked_share{,_v}.*, drawn by Draw on any one thread (the run's
// output worker) from copies of what they show: the job outlives nothing it reads. A figure that
// fails leaves its warning in `failures`, for the caller to publish in order.
struct EndFigures {
  EndFigures(const cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
             const RunFolderOptions& o, const std::vector<eval::ScenarioMetrics>& metrics,
             const WeightTraces& traces, std::size_t trace_mode)
      : dir(o.out / "figures"),
        formats(o.figure_formats),
        captions(o.figure_captions),
        words(WordsFor(o.references)),
        modes(cosim.mode_names()),
        trace_mode_name(modes[trace_mode]),
        focus(traces.Focus()),
        likelihood(config.filter.velocity_likelihood),
        title_start(config.sim.name + ": tracked share "),
        title_end(" per object (seed " + std::to_string(config.sim.seed) + ")") {
    if (!focus.empty()) trace = traces.by_vehicle.at(focus);
    for (const bool v : {false, true})
      shares.push_back(RunTrackedShares(metrics, cosim.pipeline().ids(), v));
  }

  // The files Draw writes, relative to the run folder (in the order drawn).
  std::vector<std::string> Files() const {
    std::vector<std::string> files;
    for (const std::string stem : {"weights", "tracked_share", "tracked_share_v"})
      if (stem != "weights" || !focus.empty())
        for (const std::string& f : formats) files.push_back("figures/" + stem + "." + f);
    return files;
  }

  void Draw() {
    if (!focus.empty())
      Keep(DrawFigures(dir / "weights.png", formats, [&](const auto& p) {
        RenderWeightTrace(trace, focus, trace_mode_name, likelihood, p, captions);
      }));
    for (const bool v : {false, true}) {
      const std::string what = v ? "D_v (tracked with the right velocity)" : "D";
      Keep(DrawFigures(
          dir / (v ? "tracked_share_v.png" : "tracked_share.png"), formats, [&](const auto& p) {
            RenderTrackedShares(modes, shares[v], title_start + what + title_end,
                                "tracked share " + what + " [%]", p, {}, captions, words);
          }));
    }
  }
  void Keep(const std::vector<std::string>& f) {
    failures.insert(failures.end(), f.begin(), f.end());
  }

  std::filesystem::path dir;
  std::vector<std::string> formats;
  bool captions;
  ReferenceWords words;
  std::vector<std::string> modes;
  std::string trace_mode_name, focus;
  filter::VelocityLikelihood likelihood;
  std::string title_start, title_end;
  WeightTrace trace;
  std::vector<TrackedShares> shares;  // D, then D_v
  std::vector<std::string> failures;
};

// replay.html and replay.mp4 from the finished recording: failures are warnings.
void WriteReplayFiles(const RunFolderOptions& o, const Callbacks& callbacks,
                      std::vector<std::string>* warnings) {
  std::signal(SIGPIPE, SIG_IGN);  // a failing ffmpeg must not kill the run before summary.json
  try {
    const replay::Reader reader(o.out);
    if (o.viewer) WriteViewer(reader, ReplayOptions{});
    if (o.video) WriteVideo(reader, ReplayOptions{}, callbacks);
  } catch (const std::exception& e) {
    warnings->push_back(std::string("replay not written: ") + e.what());
    std::cerr << "dualgrid: warning: " << warnings->back() << "\n";
  }
}

// summary.json's content besides the end record.
void AddSummary(const cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                const RunFolderResult& r, const RunObservers& observers,
                const RecordedRun* recorded, nlohmann::json* summary) {
  summary->update(nlohmann::json{{"status", r.status},
                                 {"scenario", config.sim.name},
                                 {"seed", config.sim.seed},
                                 {"steps", r.steps},
                                 {"simulated_s", cosim.simulated()},
                                 {"requested_s", config.sim.duration},
                                 {"wall_s", r.wall_s},
                                 {"warnings", r.warnings}});
  nlohmann::json& s = *summary;
  if (observers.invariants) {
    s["invariants_checked_steps"] = r.steps;
    s["rss_mb"] = observers.invariants->Samples(cosim.simulated());
  }
  // The grid frame at the end, and how often it turned (grid.csv: every step's).
  s["grid_frame"] = {{"frame", scenario::ToString(config.grid.frame)},
                     {"yaw_deg", RadToDeg(cosim.pipeline().grid_frame().yaw())},
                     {"realignments", cosim.pipeline().grid_realignments()}};
  // The radars as mounted on the ego's box as SUMO simulated it (config.json holds the rig as
  // read, on the scenario type's box: they differ for an ego of the user's route files).
  s["sensors_mounted"] = nlohmann::json::array();
  if (cosim.pipeline().has_radar())  // mounted at the ego's departure
    for (const auto& sensor : cosim.pipeline().radar().sensors())
      s["sensors_mounted"].push_back({{"name", sensor.name},
                                      {"x", sensor.mount.position.x()},
                                      {"y", sensor.mount.position.y()},
                                      {"yaw_deg", RadToDeg(sensor.mount.yaw)}});
  if (recorded) s["input"] = recorded->input;
}

// Steps the co-simulation to its end or a stop request, with progress.
void Simulate(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
              const RecordedRun* recorded, const Callbacks& callbacks) {
  callbacks.Begin((recorded ? "filter " : "run ") + config.sim.name + " seed " +
                      std::to_string(config.sim.seed),
                  config.sim.StepCount());
  while (!callbacks.StopRequested() && cosim.Step())
    callbacks.Progress(cosim.steps(), "t=" + FormatFixed(cosim.pipeline().frame().time, 1) + " s");
  callbacks.End();
  cosim.Finish();
}

}  // namespace

RunFolderResult WriteRunFolder(cosim::CoSimulation& cosim, const scenario::ScenarioConfig& config,
                               const RunFolderOptions& o, const RecordedRun* recorded,
                               const Callbacks& callbacks) {
  o.Validate();
  SnapshotTimes(o.snapshots, config);  // bad --snapshots: before anything is written
  // A missing network is found before the folder is made: the next attempt needs no --force.
  if (!recorded) sim::ResolveNetwork(config.sim.network, o.network_dir);
  InputSet inputs = o.inputs;
  inputs.AddScenario(config, o.network_dir);
  CheckOutputApart(o.out, inputs, o.out_option);
  PrepareOutputFolder(o.out,
                      {.force = o.force, .option = o.out_option, .force_flag = o.force_flag});
  std::filesystem::create_directories(o.out / "figures");
  if (!recorded || !config.file.empty()) CopyScenario(config, o.out);
  WriteTextFile(o.out / "config.json", ConfigJson(config, cosim.mode_names()).dump(2) + "\n");

  const auto wall_start = std::chrono::steady_clock::now();
  cosim.Start(o.network_dir, o.out);
  PrintAutoEgoNote(cosim.pipeline(), o.quiet);
  RunFolderResult r;
  RunObservers observers(cosim, config, o, &r.warnings);
  Simulate(cosim, config, recorded, callbacks);
  r.stop = callbacks.StopRequested();
  r.steps = cosim.steps();
  nlohmann::json summary = EndRecord(cosim, r.stop, &r.status);
  r.complete = summary.at("complete");
  observers.files.Close();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (FaultInjected("run-seed:" + std::to_string(config.sim.seed)))
    throw std::runtime_error("injected fault (DUALGRID_FAULT) after the simulation");

  // Results first: nothing below may be lost to a figure that fails.
  const std::vector<eval::ScenarioMetrics> metrics = cosim.Metrics();
  const nlohmann::json metrics_json = MetricsJson(cosim, config, metrics);
  r.table_markdown = WriteResults(cosim, config, o.out, recorded, metrics, metrics_json, r.status,
                                  observers.files.traces());
  // The end figures go to the output worker behind the step pictures (cairo numbers its
  // surfaces process-wide: every figure is drawn on that one thread, in the same order as ever),
  // and are drawn while this thread finishes the recording and digests the files before them.
  std::shared_ptr<EndFigures> figures;
  std::future<void> figures_done;
  if (o.figures && !r.stop) {
    figures = std::make_shared<EndFigures>(cosim, config, o, metrics, observers.files.traces(),
                                           observers.trace_mode);
    figures_done = observers.worker.Post([figures] { figures->Draw(); });
  }
  // The step pictures' warnings, then the recording's (as they came when drawn in line).
  observers.pictures.Finish();
  // After the results: a failure here costs only the replay.
  const bool recording = observers.recording &&
                         observers.recording->Finish(metrics_json["modes"], cosim.pipeline().ids(),
                                                     r.complete, r.status);
  // Every file but the end figures is final now: digested while the worker draws those.
  const FileDigests early =
      FolderDigests(o.out, figures ? figures->Files() : std::vector<std::string>{});
  if (figures) {
    figures_done.get();  // Draw keeps its failures: it does not throw
    for (const std::string& failure : figures->failures) PublishWarning(failure, &r.warnings);
  }
  if (recording && !r.stop && (o.video || o.viewer)) WriteReplayFiles(o, callbacks, &r.warnings);

  // Written last: a run folder without summary.json did not finish.
  AddSummary(cosim, config, r, observers, recorded, &summary);
  summary["digests"] = OutputDigests(o.out, early);
  SealOutputFolder(o.out);
  WriteTextFile(o.out / "summary.json", summary.dump(2) + "\n");
  return r;
}

}  // namespace dualgrid::outputs
