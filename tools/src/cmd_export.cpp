// `dualgrid export`: a simulated run (recorded with --detections exact) as a RadarScenes dataset
// root, for tools written for the public data set (docs/recorded-data.md, "Export").
#include <algorithm>
#include <iostream>
#include <memory>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder.hpp"

namespace dualgrid::tools {

namespace {

struct ExportOptions {
  std::filesystem::path run_dir;
  std::filesystem::path out;
  std::string format = "radarscenes";
  std::string sequence = "sequence_1";
  bool quiet = false;
};

int RunExport(const ExportOptions& o) {
  recorded::RecordedSequence seq = recorded::ReadRunFolder(o.run_dir);
  seq.name = o.sequence;
  PrepareOutputFolder(o.out);
  // The rear axle (RadarScenes' car origin) 1 m ahead of the ego's rear end.
  const double a = std::max(0.0, 0.5 * seq.ego_length - 1.0);
  recorded::WriteRadarScenes(seq, o.out, a);
  if (!o.quiet)
    std::cout << "exported " << seq.scans.size() << " scans, " << seq.points.size()
              << " detections, " << seq.track_names.size() << " tracks of " << o.run_dir.string()
              << " to " << (o.out / "data" / seq.name).string() << "\n";
  return 0;
}

}  // namespace

Command AddExportCommand(CLI::App& app, const CliContext&) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand(
      "export",
      "Write a run (recorded with --detections exact) as a RadarScenes dataset root: "
      "sensors.json, sequences.json, data/<sequence>/scenes.json and radar_data.h5");
  cmd->add_option("run_dir", o->run_dir, "Run folder of `dualgrid run` or `dualgrid sim`")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out,-o", o->out, "Dataset root to write")->required()->check(NonEmptyPath());
  Opt(cmd, "--format", &o->format, "Output format (radarscenes)")
      ->check(CLI::IsMember({"radarscenes"}));
  Opt(cmd, "--sequence", &o->sequence, "Name of the sequence folder under data/")
      ->check(NonEmptyPath());
  cmd->add_flag("--quiet,-q", o->quiet, "No summary output");
  return {cmd, [o] { return RunExport(*o); }};
}

}  // namespace dualgrid::tools
