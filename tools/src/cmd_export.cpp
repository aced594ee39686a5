// `dualgrid export`: a simulated run (recorded with --detections exact) as a RadarScenes dataset
// root, for tools written for the public data set (docs/recorded-data.md, "Export").
#include <algorithm>
#include <iostream>
#include <memory>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/input_file.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder.hpp"
#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::tools {

namespace {

struct ExportOptions {
  std::filesystem::path run_dir;
  std::filesystem::path out;
  std::string format = "radarscenes";
  std::string sequence = "sequence_1";
  recorded::NuScenesWriteOptions nuscenes;
  bool force = false;             ///< --force: replace an earlier dualgrid output in `out`
  bool allow_incomplete = false;  ///< --allow-incomplete: export a run that did not finish
  bool quiet = false;
};

int RunExport(const ExportOptions& o) {
  SafeName(o.sequence, "--sequence");
  SafeName(o.nuscenes.scene, "--scene");
  SafeName(o.nuscenes.version, "--version");
  outputs::InputSet inputs;
  inputs.Add(o.run_dir, "run folder");
  outputs::CheckOutputApart(o.out, inputs);
  recorded::RecordedSequence seq = recorded::ReadRunFolder(o.run_dir);
  // After the data: a damaged file is named first.
  const std::string incomplete = outputs::CheckRunFinished(o.run_dir, o.allow_incomplete);
  // The run's settings travel with the export (docs/recorded-data.md, "Export").
  std::optional<std::filesystem::path> scenario;
  if (const auto copy = o.run_dir / "scenario.yaml"; InputExists(copy)) {
    // It travels with the export and is loaded by `filter`: refused now if it would be then.
    scenario::LoadScenario(copy);
    scenario = copy;
  }
  PrepareOutputFolder(o.out, {.force = o.force});
  if (!incomplete.empty())  // first: a reader sees it even if the export stops midway
    outputs::MarkIncomplete(o.out, o.run_dir, incomplete);
  std::filesystem::path written;
  if (o.format == "nuscenes") {
    const auto keys = recorded::ReadKeyFrames(o.run_dir, seq, 0.5);
    recorded::NuScenesWriteOptions n = o.nuscenes;
    n.scenario = scenario;
    recorded::WriteNuScenes(seq, keys, o.out, n);
    written = o.out / n.version;
  } else {
    seq.name = o.sequence;
    // The rear axle (RadarScenes' car origin) 1 m ahead of the ego's rear end.
    const double a = std::max(0.0, 0.5 * seq.ego_length - 1.0);
    recorded::WriteRadarScenes(seq, o.out, a);
    if (scenario) {
      std::error_code ec;
      std::filesystem::copy_file(*scenario, o.out / recorded::kTravellingScenario,
                                 std::filesystem::copy_options::overwrite_existing, ec);
      if (ec)
        throw std::runtime_error((o.out / recorded::kTravellingScenario).string() + ": " +
                                 ec.message());
    }
    written = o.out / "data" / seq.name;
  }
  SealOutputFolder(o.out);
  if (!incomplete.empty())
    std::cerr << "dualgrid: warning: exported an incomplete run (" << incomplete
              << "); the dataset is marked by " << (o.out / outputs::kIncompleteMark).string()
              << "\n";
  if (!o.quiet)
    std::cout << "exported " << seq.scans.size() << " scans, " << seq.points.size()
              << " detections, " << seq.track_names.size() << " tracks of " << o.run_dir.string()
              << " to " << written.string() << "\n";
  return 0;
}

}  // namespace

Command AddExportCommand(CLI::App& app, const CliContext&) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand(
      "export",
      "Write a run (recorded with --detections exact) as a RadarScenes dataset root "
      "(sensors.json, sequences.json, data/<sequence>/) or a nuScenes root (<version>/*.json, "
      "samples/, sweeps/); the run's scenario travels with it");
  cmd->add_option("run_dir", o->run_dir, "Run folder of `dualgrid run` or `dualgrid sim`")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out,-o", o->out, "Dataset root to write")->required()->check(NonEmptyPath());
  Opt(cmd, "--format", &o->format, "Output format (radarscenes, nuscenes)")
      ->check(CLI::IsMember({"radarscenes", "nuscenes"}));
  Opt(cmd, "--sequence", &o->sequence, "RadarScenes: name of the sequence folder under data/")
      ->check(NonEmptyPath());
  Opt(cmd, "--scene", &o->nuscenes.scene, "nuScenes: the scene's name")->check(NonEmptyPath());
  Opt(cmd, "--version", &o->nuscenes.version, "nuScenes: the version folder")
      ->check(NonEmptyPath());
  cmd->add_flag("--pcd-float64", o->nuscenes.float64,
                "nuScenes: positions and velocities as float64 in the PCD files (the published "
                "files have float32, which round the run's values)");
  cmd->add_flag("--quiet,-q", o->quiet, "No summary output");
  AddForceFlag(cmd, &o->force);
  cmd->add_flag("--allow-incomplete", o->allow_incomplete,
                "Export a run that did not finish (no summary.json, or complete: false); the "
                "dataset is marked by INCOMPLETE.txt at its root");
  return {cmd, [o] { return RunExport(*o); }};
}

}  // namespace dualgrid::tools
