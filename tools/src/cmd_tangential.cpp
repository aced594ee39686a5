// `dualgrid tangential`: writes a stress scenario in which vehicles move perpendicular to a
// radar's line of sight (the paper's Fig. 3 cases). The generators live in scenarios/:
// crossing and parallel (scenario/tangential_case.hpp), guardrail (multipath,
// scenario/guardrail_case.hpp), aspect (any aspect angle, scenario/aspect_case.hpp).
#include <iostream>

#include "aspect_case.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/scenario/guardrail_case.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/scenario/tangential_case.hpp"

namespace dualgrid::tools {
namespace {

// The files the generator writes: the scenario, and for --kind aspect its network beside it.
// One that exists already is refused without --force (it may be the user's own scenario).
void CheckGeneratorFiles(const TangentialOptions& o) {
  if (o.force) return;
  std::vector<std::filesystem::path> files = {o.out};
  const std::filesystem::path base = o.out.parent_path() / o.out.stem();
  if (o.kind == "aspect")
    for (const char* ext : {".net.xml", ".nod.xml", ".edg.xml"})
      files.push_back(base.string() + ext);
  std::error_code ec;
  for (const auto& f : files)
    if (std::filesystem::exists(std::filesystem::symlink_status(f, ec)))
      throw std::invalid_argument("--out: " + f.string() +
                                  " exists; add --force to replace it, or choose another name");
}

void WriteAspect(const TangentialOptions& o) {
  scenario::AspectCase c;
  c.sensor = o.sensor;
  c.angle_deg = o.angle;
  c.range = o.range;
  c.speed = o.speed.value_or(15.0);
  c.ego_speed = o.ego_speed;
  c.target = o.target;
  c.count = o.count;
  c.interval = o.interval;
  c.grid_width = o.grid_width.value_or(25.0);
  c.auto_grid_width = !o.grid_width;
  c.seed = o.seed;
  CheckGeneratorFiles(o);
  if (o.out.has_parent_path()) std::filesystem::create_directories(o.out.parent_path());
  const std::string what = WriteAspectCase(c, o.out);
  scenario::LoadScenario(o.out);  // must load like any scenario; a failure is a generator bug
  if (!o.quiet) {
    // Its network is written beside it (the scenario names it relative to itself): say so.
    const std::filesystem::path base = o.out.parent_path() / o.out.stem();
    std::cout << "wrote " << o.out.string() << " (" << what
              << ") and its network beside it: " << base.string() << ".net.xml (netconvert, from "
              << base.filename().string() << ".nod.xml and " << base.filename().string()
              << ".edg.xml; log " << base.filename().string()
              << ".netconvert.log); run it with: dualgrid run " << o.out.string() << " --out run/"
              << o.out.stem().string() << "\n";
  }
}

// The crossing and parallel kinds' generator options.
scenario::TangentialCase Case(const TangentialOptions& o) {
  scenario::TangentialCase c;
  c.kind = o.kind;
  c.count = o.count;
  c.ego_speed = o.ego_speed;
  c.speed = o.speed;
  c.first_distance = o.first_distance;
  c.spacing = o.spacing;
  c.seed = o.seed;
  return c;
}

void WriteGuardRail(const TangentialOptions& o) {
  const scenario::TangentialCase t = Case(o);
  scenario::GuardRailCase c;
  c.offset = o.offset;
  c.rail_angle = o.rail_angle;
  c.ego_speed = o.ego_speed;
  c.speed = t.Speed();
  c.count = o.count;
  c.spacing = t.Spacing();
  c.seed = o.seed;
  const std::string text = scenario::GuardRailScenario(c);
  CheckGeneratorFiles(o);
  if (o.out.has_parent_path()) std::filesystem::create_directories(o.out.parent_path());
  WriteTextFile(o.out, text);
  scenario::LoadScenario(o.out);  // must load like any scenario; a failure is a generator bug
  if (!o.quiet)
    std::cout << "wrote " << o.out.string() << "; run it with: dualgrid run " << o.out.string()
              << " --set sensors.multipath=on --out run/" << o.out.stem().string() << "\n";
}

}  // namespace

int RunTangential(const TangentialOptions& o) {
  if (o.out.extension() != ".yaml" && o.out.extension() != ".yml")
    throw std::invalid_argument("--out must name a .yaml file, got '" + o.out.string() + "'");
  if (o.kind == "aspect") {
    WriteAspect(o);
    return 0;
  }
  if (o.kind == "guardrail") {
    WriteGuardRail(o);
    return 0;
  }
  const std::string text = scenario::TangentialScenario(Case(o));
  CheckGeneratorFiles(o);
  if (o.out.has_parent_path()) std::filesystem::create_directories(o.out.parent_path());
  WriteTextFile(o.out, text);
  // The generated file must load like any scenario; a failure here is a generator bug.
  scenario::LoadScenario(o.out);
  if (!o.quiet)
    std::cout << "wrote " << o.out.string() << "; run it with: dualgrid run " << o.out.string()
              << " --out run/" << o.out.stem().string() << "\n";
  return 0;
}

Command AddTangentialCommand(CLI::App& app, const CliContext&) {
  auto o = std::make_shared<TangentialOptions>();
  auto* cmd =
      app.add_subcommand("tangential",
                         "Write a tangential-motion stress scenario (traffic crossing ahead of the "
                         "ego, or driving alongside it), to run with `dualgrid run`");
  Opt(cmd, "--kind", &o->kind,
      "crossing (ahead, across the front radar), parallel (alongside, across the corner "
      "radars), aspect (any --angle to any --sensor's line of sight), or guardrail (traffic "
      "passing the ego on the side away from a guard rail: multipath ghosts; docs/stress.md)")
      ->check(CLI::IsMember({"crossing", "parallel", "aspect", "guardrail"}));
  Opt(cmd, "--offset", &o->offset,
      "guardrail: distance from the ego's centre line to the rail, on its left [m]")
      ->check(Number(1.2, 20.0, false));
  Opt(cmd, "--rail-angle", &o->rail_angle,
      "guardrail: the rail's aspect, its angle to the road [deg] (+: turning away from the "
      "road ahead)")
      ->check(Number(-10.0, 10.0, false));
  Opt(cmd, "--sensor", &o->sensor, "aspect: the radar whose line of sight the angle refers to")
      ->check(CLI::IsMember({"front", "front_left", "front_right", "rear_left", "rear_right"}));
  Opt(cmd, "--angle", &o->angle,
      "aspect: angle between the targets' velocity over ground and the line of sight [deg] "
      "(0 receding, 90 across, 180 approaching)")
      ->check(Number(0.0, 180.0, false));
  Opt(cmd, "--range", &o->range,
      "aspect: distance sensor -> target centre when on the sensor's boresight [m]")
      ->check(Number(1.0, 200.0, false));
  Opt(cmd, "--target", &o->target, "aspect: car, truck or cyclist")
      ->check(CLI::IsMember({"car", "truck", "cyclist"}));
  Opt(cmd, "--interval", &o->interval, "aspect: seconds between the targets")
      ->check(Number(1.0, 60.0, false));
  cmd->add_option("--grid-width", o->grid_width,
                  "aspect: the grid's width (filter.width_y) [m] (default: the paper's 25, "
                  "widened when a target would not be scored in it)")
      ->check(Number(5.0, 400.0, false));
  Opt(cmd, "--count", &o->count, "Number of stress vehicles")->check(WholeNumber(1, 12));
  Opt(cmd, "--ego-speed", &o->ego_speed, "Ego speed [m/s] (0, a parked ego: aspect only)")
      ->check(Number(0.0, 40.0, false));
  cmd->add_option("--speed", o->speed,
                  "Stress vehicles' speed over ground [m/s] (default: crossing 15; parallel "
                  "ego speed + 0.3, so they stay alongside; guardrail ego speed + 5, so they "
                  "pass)")
      ->check(Number(0.0, 40.0, true));
  Opt(cmd, "--first-distance", &o->first_distance,
      "crossing: distance ahead of the ego of the first crossing [m]")
      ->check(Number(10.0, 600.0, false));
  cmd->add_option("--spacing", o->spacing,
                  "crossing: distance between crossings (default 20 m); parallel (default 40 m) "
                  "and guardrail (50 m): distance between vehicles of one lane [m]")
      ->check(Number(0.0, 600.0, true));
  Opt(cmd, "--seed", &o->seed, "Scenario seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  cmd->add_option("--out,-o", o->out,
                  "Scenario file to write (.yaml); --kind aspect also writes its network beside "
                  "it: NAME.net.xml, NAME.nod.xml, NAME.edg.xml and NAME.netconvert.log")
      ->required()
      ->check(NonEmptyPath());
  cmd->add_flag("--quiet,-q", o->quiet, "No summary");
  cmd->add_flag("--force", o->force,
                "Replace the scenario file (and an aspect case's network files) if they exist");
  return {cmd, [o, cmd] {
            // The aspect options imply --kind aspect; with another kind they would be ignored.
            bool aspect_options = false;
            for (const char* name :
                 {"--sensor", "--angle", "--range", "--target", "--interval", "--grid-width"})
              aspect_options = aspect_options || cmd->count(name) > 0;
            if (aspect_options && cmd->count("--kind") == 0) o->kind = "aspect";
            if (aspect_options && o->kind != "aspect")
              throw std::invalid_argument(
                  "--sensor, --angle, --range, --target, --interval and "
                  "--grid-width are options of --kind aspect, not " +
                  o->kind);
            if ((cmd->count("--offset") > 0 || cmd->count("--rail-angle") > 0) &&
                o->kind != "guardrail")
              throw std::invalid_argument(
                  "--offset and --rail-angle are options of --kind guardrail, not " + o->kind);
            return RunTangential(*o);
          }};
}

}  // namespace dualgrid::tools
