// `dualgrid filter`: the weight modes on recorded detections (a RadarScenes sequence, or a
// dualgrid run folder recorded with --detections exact), written as `run` writes its folder.
#include <iostream>
#include <memory>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/recorded/recorded_run.hpp"

namespace dualgrid::tools {

namespace {

struct FilterInputOptions {
  FilterRunOptions run;
  std::filesystem::path input;
  std::optional<std::filesystem::path> sensors;
  double batch_window = 0.001;
};

// The configuration of a recorded run: the scenario file's filter, grid and evaluation keys
// (its per-cycle factors refer to its step), else DefaultRecordedConfig.
scenario::ScenarioConfig RecordedConfig(const FilterRunOptions& o) {
  if (o.run.scenario.empty()) {
    if (!o.run.sets.empty())
      throw std::invalid_argument("--set: needs --scenario FILE (the keys it overrides)");
    scenario::ScenarioConfig c = cosim::DefaultRecordedConfig();
    if (o.run.seed) c.sim.seed = *o.run.seed;
    return c;
  }
  scenario::ScenarioConfig c = LoadConfig(o.run);
  c.filter.cycle = c.sim.step_length;
  return c;
}

}  // namespace

int RunFilterCommand(const FilterInputOptions& o) {
  const std::vector<filter::WeightMode> modes = ParseModes(o.run.modes);
  scenario::ScenarioConfig config = RecordedConfig(o.run);
  const recorded::RecordedInput in = recorded::ReadRecordedInput(o.input, o.sensors);
  const cosim::RecordedSequence& seq = in.sequence;
  const cosim::RecordedOptions ropts = cosim::FitConfig(seq, o.batch_window, &config);
  const cosim::RecordedSource probe(seq, ropts);
  cosim::CoSimulation cosim(config, {modes, o.run.threads},
                            [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                              return std::make_unique<cosim::RecordedSource>(seq, ropts);
                            });
  outputs::RecordedRun r;
  r.labels = seq.has_labels;
  r.skipped_points = seq.skipped_points;
  std::vector<std::string> sensors;
  for (const auto& s : seq.sensors) sensors.push_back(s.name);
  r.input = {{"kind", in.radarscenes ? "radarscenes" : "run"},
             {"path", std::filesystem::absolute(o.input).string()},
             {"sequence", seq.name},
             {"scans", seq.scans.size()},
             {"cycles", probe.StepCount()},
             {"batch_window_s", o.batch_window},
             {"first_s", probe.first_time()},
             {"last_s", probe.last_time()},
             {"detections", seq.points.size()},
             {"skipped_detections", seq.skipped_points},
             {"labels", seq.has_labels},
             {"tracks", seq.track_names.size()},
             {"sensors", sensors},
             {"filter_cycle_s", config.filter.cycle}};
  return WriteRunFolderAndReport(cosim, config, o.run.FolderOptions(), &r);
}

Command AddFilterCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<FilterInputOptions>();
  auto no_figures = std::make_shared<bool>(false);
  auto no_record = std::make_shared<bool>(false);
  o->run.run.network_dir = ctx.network_dir;
  auto* cmd = app.add_subcommand(
      "filter",
      "Run the grid filters on recorded detections: a RadarScenes sequence folder (scenes.json, "
      "radar_data.h5) or a dualgrid run folder recorded with --detections exact; writes the "
      "same run folder as `run` (docs/recorded-data.md)");
  cmd->add_option("input", o->input, "Sequence folder (data/sequence_N) or run folder")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out,-o", o->run.run.out, "Run folder (metrics, tables, figures)")
      ->required()
      ->check(NonEmptyPath());
  cmd->add_option(
         "--sensors", o->sensors,
         "RadarScenes sensors.json (default: the dataset root's, two folders above the sequence)")
      ->check(CLI::ExistingFile);
  Opt(cmd, "--scenario", &o->run.run.scenario,
      "Scenario file whose filter, grid and evaluation keys to use (default: the defaults with "
      "a 100 m x 60 m grid); its step is the filter's reference cycle")
      ->check(CLI::ExistingFile);
  cmd->add_option("--set", o->run.run.sets, "Override a key of --scenario, KEY=VALUE (repeatable)")
      ->check(OverrideSpec());
  cmd->add_option("--seed", o->run.run.seed, "Filter seed (default: the scenario's, else 1)")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  Opt(cmd, "--batch-window", &o->batch_window,
      "Scans within this time [s] of a cycle's first scan are filtered together (0: every "
      "scan alone)")
      ->check(Number(0.0, 1.0, false));
  cmd->add_flag("--quiet,-q", o->run.run.quiet, "No progress or summary output");
  AddFilterOptions(cmd, &o->run, no_figures.get());
  cmd->add_flag("--no-record", *no_record, "Do not record the replay frames (RUN_DIR/replay/)");
  cmd->add_flag("--viewer", o->run.folder.viewer,
                "Also write the interactive viewer (replay.html)");
  return {cmd, [o, no_figures, no_record] {
            o->run.folder.figures = !*no_figures;
            o->run.folder.record = o->run.folder.figures && !*no_record;
            if (o->run.folder.viewer && !o->run.folder.record)
              throw std::invalid_argument("--viewer needs the recording: drop --no-record");
            return RunFilterCommand(*o);
          }};
}

}  // namespace dualgrid::tools
