// `dualgrid filter`: the weight modes on recorded detections (a RadarScenes sequence, or a
// dualgrid run folder recorded with --detections exact), written as `run` writes its folder.
#include <iostream>
#include <memory>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/outputs/output_guard.hpp"
#include "dualgrid/outputs/run.hpp"
#include "dualgrid/recorded/recorded_run.hpp"

namespace dualgrid::tools {

namespace {

struct FilterInputOptions {
  FilterRunOptions run;
  std::filesystem::path input;
  std::optional<std::filesystem::path> sensors;
  double batch_window = 0.001;
  std::optional<std::string> scene;  // a nuScenes root's scene
  recorded::NuScenesOptions nuscenes;
  std::string invalid_states = "0", dynprop_states = "all", ambig_states = "3";
};

// "all" (keep every value) or a comma-separated list of whole numbers.
std::vector<int> StateList(const std::string& option, const std::string& text) {
  if (text == "all") return {};
  std::vector<int> v;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string w = text.substr(start, comma == std::string::npos ? comma : comma - start);
    std::size_t used = 0;
    int x = -1;
    try {
      x = std::stoi(w, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != w.size() || x < 0)
      throw std::invalid_argument(option +
                                  ": expected 'all' or whole numbers separated by "
                                  "commas, got '" +
                                  text + "'");
    v.push_back(x);
    if (comma == std::string::npos) return v;
    start = comma + 1;
  }
}

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

// summary.json's and the table notes' account of a nuScenes scene: what the devkit's filters
// removed, which instances are references, and that their velocities are estimated.
void NuScenesInput(const recorded::NuScenesScene& n, const recorded::RecordedSequence& seq,
                   outputs::RecordedRun* r) {
  r->input["scene_token"] = n.scene_token;
  for (const recorded::NuScenesAnnotation& a : n.annotations)
    r->categories[a.instance] = a.category;
  r->input["sample_data"] = n.sample_data;
  r->input["filtered_points"] = n.filtered_points;
  r->input["empty_clouds"] = n.empty_clouds;
  r->input["moving_instances"] = n.moving_instances;
  r->input["static_instances"] = n.static_instances;
  r->input["skipped_instances"] = n.skipped_instances;
  r->input["ego_velocity_estimated"] = n.ego_velocity_estimated;
  r->input["reference_velocity"] =
      "estimated: annotations at 2 Hz, devkit box_velocity, interpolated";
  r->notes.push_back(
      "nuScenes scene " + seq.name + ": D, D_v and t_d per annotated instance (" +
      std::to_string(n.moving_instances) + " moving, " + std::to_string(n.static_instances) +
      " parked or stopped (static), " + std::to_string(n.skipped_instances) +
      " skipped: fewer than 2 annotations). The reference velocities are estimated (the devkit's "
      "differences of 2 Hz annotations, interpolated): D_v and Delta v carry their error "
      "(docs/recorded-data.md, \"nuScenes\").");
  if (n.filtered_points > 0 || n.empty_clouds > 0)
    r->notes.push_back(std::to_string(n.filtered_points) +
                       " point(s) removed by the devkit's filters (invalid_state, dyn_prop, "
                       "ambig_state); " +
                       std::to_string(n.empty_clouds) + " empty cloud(s).");
}

// What `dualgrid filter` reads besides the scenario: the data, the sensors file (given, or a
// RadarScenes root's), the scenario that travelled with an export.
outputs::InputSet RecordedInputs(const FilterInputOptions& o, const recorded::RecordedInput& in) {
  outputs::InputSet inputs;
  inputs.Add(o.input, "recorded data");
  if (o.sensors) inputs.Add(*o.sensors, "sensors file");
  if (in.radarscenes && !o.sensors)
    inputs.Add(o.input.parent_path().parent_path() / "sensors.json", "sensors file");
  if (in.scenario) inputs.Add(*in.scenario, "scenario");
  return inputs;
}

// The file `dualgrid export --allow-incomplete` leaves at a dataset's root, if the input has one.
std::optional<std::filesystem::path> IncompleteMark(const FilterInputOptions& o, bool radarscenes) {
  const std::filesystem::path root =
      radarscenes ? o.input.lexically_normal().parent_path().parent_path() : o.input;
  const auto mark = root / outputs::kIncompleteMark;
  std::error_code ec;
  if (std::filesystem::is_regular_file(mark, ec)) return mark;
  return std::nullopt;
}

}  // namespace

int RunFilterCommand(FilterInputOptions o) {
  const std::vector<filter::WeightMode> modes = ParseModes(o.run.modes);
  std::optional<recorded::NuScenesOptions> nuscenes;
  if (o.scene) {
    nuscenes = o.nuscenes;
    nuscenes->scene = *o.scene;
    nuscenes->invalid_states = StateList("--invalid-states", o.invalid_states);
    nuscenes->dynprop_states = StateList("--dynprop-states", o.dynprop_states);
    nuscenes->ambig_states = StateList("--ambig-states", o.ambig_states);
  }
  const recorded::RecordedInput in = recorded::ReadRecordedInput(o.input, o.sensors, nuscenes);
  if (o.run.run.scenario.empty() && in.scenario) {
    o.run.run.scenario = *in.scenario;  // the run's settings travelled with its export
    if (!o.run.run.quiet)
      std::cout << "filter settings: " << in.scenario->string() << " (travelled with the export)\n";
  }
  o.run.folder.references = in.sequence.annotated ? "annotated" : "tracks";
  scenario::ScenarioConfig config = RecordedConfig(o.run);
  const cosim::RecordedSequence& seq = in.sequence;
  const cosim::RecordedOptions ropts = cosim::FitConfig(seq, o.batch_window, &config);
  const cosim::RecordedSource probe(seq, ropts);
  cosim::CoSimulation cosim(config, {modes, o.run.threads},
                            [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
                              return std::make_unique<cosim::RecordedSource>(seq, ropts);
                            });
  outputs::RecordedRun r;
  r.labels = seq.has_labels;
  r.annotated = seq.annotated;
  r.skipped_points = seq.skipped_points;
  std::vector<std::string> sensors;
  for (const auto& s : seq.sensors) sensors.push_back(s.name);
  r.input = {{"kind", in.kind},
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
             {"filter_cycle_s", config.filter.cycle},
             {"scenario", o.run.run.scenario.empty() ? "" : o.run.run.scenario.string()}};
  if (seq.has_labels && !seq.annotated)
    r.input["reference_velocity"] =
        "estimated from each track's labelled points (docs/recorded-data.md, \"Track velocity\")";
  if (in.nuscenes) NuScenesInput(*in.nuscenes, in.sequence, &r);
  if (const auto mark = IncompleteMark(o, in.radarscenes)) {
    r.input["source_incomplete"] = true;
    r.notes.push_back("The data were exported from a run that did not finish (" + mark->string() +
                      ").");
    std::cerr << "dualgrid: warning: " << o.input.string()
              << " was exported from a run that did not finish (" << mark->string() << ")\n";
  }
  o.run.folder.inputs = RecordedInputs(o, in);
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
      "radar_data.h5), a nuScenes root with --scene, or a dualgrid run folder recorded with "
      "--detections exact; writes the "
      "same run folder as `run` (docs/recorded-data.md)");
  cmd->add_option("input", o->input,
                  "Sequence folder (data/sequence_N), run folder, or nuScenes root (with --scene)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out,-o", o->run.run.out, "Run folder (metrics, tables, figures)")
      ->required()
      ->check(NonEmptyPath());
  cmd->add_option(
         "--sensors", o->sensors,
         "RadarScenes sensors.json (default: the dataset root's, two folders above the sequence)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene,
                  "nuScenes: the scene's name or token; INPUT is then the dataset root");
  Opt(cmd, "--version", &o->nuscenes.version, "nuScenes: the version folder under the root")
      ->check(NonEmptyPath());
  Opt(cmd, "--invalid-states", &o->invalid_states,
      "nuScenes: invalid_state values kept ('all' or a list; the devkit's default: 0)");
  Opt(cmd, "--dynprop-states", &o->dynprop_states,
      "nuScenes: dyn_prop values kept ('all' or a list, e.g. 0,2,6 for moving only)");
  Opt(cmd, "--ambig-states", &o->ambig_states,
      "nuScenes: ambig_state values kept ('all' or a list; the devkit's default: 3)");
  Opt(cmd, "--scenario", &o->run.run.scenario,
      "Scenario file whose filter, grid and evaluation keys to use (default: the one that "
      "travelled with a dualgrid export, else the defaults with a 100 m x 60 m grid); its step "
      "is the filter's reference cycle")
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
  AddForceFlag(cmd, &o->run.run.force);
  AddFilterOptions(cmd, &o->run, no_figures.get());
  cmd->add_flag("--no-record", *no_record, "Do not record the replay frames (RUN_DIR/replay/)");
  cmd->add_flag("--viewer", o->run.folder.viewer,
                "Also write the interactive viewer (replay.html)");
  return {cmd, [o, no_figures, no_record] {
            o->run.folder.figures = !*no_figures;
            o->run.folder.record = o->run.folder.figures && !*no_record;
            if (o->run.folder.viewer && !o->run.folder.record)
              throw std::invalid_argument("--viewer needs the recording: drop --no-record");
            if (!o->scene &&
                (o->nuscenes.version != recorded::NuScenesOptions().version ||
                 o->invalid_states != "0" || o->dynprop_states != "all" || o->ambig_states != "3"))
              throw std::invalid_argument(
                  "--version, --invalid-states, --dynprop-states, --ambig-states: only with "
                  "--scene (a nuScenes root)");
            return RunFilterCommand(*o);
          }};
}

}  // namespace dualgrid::tools
