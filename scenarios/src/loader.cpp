#include "dualgrid/scenario/loader.hpp"

#include <cmath>
#include <functional>

#include "dualgrid/core/input_file.hpp"
#include "sections.hpp"

namespace dualgrid::scenario {

using namespace detail;

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out);

Vector2 GridPlacement::CentreOffset(double length_x, double width_y) const {
  const double a = std::isnan(ahead) ? 0.5 * length_x : ahead;
  const double l = std::isnan(left) ? 0.5 * width_y : left;
  // Centre = ego + (ahead - L/2, left - W/2); exactly zero for a centred ego.
  return {a - 0.5 * length_x, l - 0.5 * width_y};
}

std::string_view ToString(GridPlacement::Frame f) {
  switch (f) {
    case GridPlacement::Frame::kWorld:
      return "world";
    case GridPlacement::Frame::kHeading:
      return "heading";
    case GridPlacement::Frame::kFollow:
      break;
  }
  return "follow";
}

filter::FilterParams ScenarioConfig::FilterFor(filter::WeightMode mode) const {
  filter::FilterParams p = filter;
  p.mode = mode;
  // The co-simulation's cycle is its step: the per-cycle factors are per step, as given.
  p.cycle = sim.step_length;
  if (const auto it = birth_velocity_by_mode.find(mode); it != birth_velocity_by_mode.end())
    p.birth_velocity = it->second;
  return p;
}

namespace {

ScenarioConfig LoadDocument(const std::function<YAML::Node()>& parse,
                            const std::filesystem::path& file) {
  const std::string name = file.string();
  YAML::Node doc;
  try {
    doc = parse();
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  ScenarioConfig config;
  config.file = file;
  try {
    ReadAll(doc, name, &config);
  } catch (const YAML::Exception& e) {
    // Conversions inside yaml-cpp (e.g. a non-text map key) still get the file and the place.
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  return config;
}

}  // namespace

ScenarioConfig LoadScenario(const std::filesystem::path& file,
                            const std::vector<Override>& overrides) {
  // Bounded, and a FIFO or device is refused before it could block (core/input_file.hpp).
  std::string text;
  try {
    text = ReadInputText(file, "scenario file");
  } catch (const std::invalid_argument& e) {
    throw ConfigError(e.what());
  }
  return LoadDocument(
      [&] {
        YAML::Node doc = YAML::Load(text);
        for (const Override& o : overrides) ApplyOverride(doc, o);
        return doc;
      },
      file);
}

ScenarioConfig LoadScenarioText(const std::string& text, const std::filesystem::path& file) {
  return LoadDocument([&] { return YAML::Load(text); }, file);
}

namespace {

// The `auto` rule looks for traffic in the grid as the filter places it round the ego.
void SetAutoEgoView(ScenarioConfig* config) {
  const Vector2 off = config->grid.CentreOffset(config->filter.length_x, config->filter.width_y);
  const double ahead = 0.5 * config->filter.length_x + off.x();
  const double left = 0.5 * config->filter.width_y + off.y();
  config->sim.auto_ego_view = {ahead, config->filter.length_x - ahead, left,
                               config->filter.width_y - left};
}

}  // namespace

void ReadAll(const YAML::Node& doc, const std::string& name, ScenarioConfig* out) {
  ScenarioConfig& config = *out;
  MapReader root(doc, name, "");
  config.sim.file = name;
  ReadSim(root, &config.sim);
  if (config.sim.name.empty()) config.sim.name = std::filesystem::path(name).stem().string();
  std::string error;
  if (!config.sim.IsValid(&error)) Invalid(name, "", error);
  const std::optional<sim::RouteFileIndex> routes = IndexUserFiles(root, name, config.sim);
  // Again, with the ego's departure from the files against the run's window.
  if (!config.sim.IsValid(&error)) Invalid(name, "", error);
  ReadRadar(root, config.sim, &config.radar);
  ReadFilter(root, &config);
  SetAutoEgoView(&config);
  ReadEvaluation(root, &config.evaluation);
  root.Finish();
  // Names the evaluation uses must exist: a typo would silently pick another vehicle.
  const auto& focus = config.evaluation.focus_object;
  if (!focus.empty()) {
    bool found = focus == config.sim.ego.id;
    for (const auto& v : config.sim.vehicles) found = found || v.id == focus;
    // A flow's vehicles are named by SUMO "<flow id>.<k>".
    for (const auto& f : config.sim.flows)
      found =
          found || (focus.rfind(f.id + ".", 0) == 0 && focus.size() > f.id.size() + 1 &&
                    focus.find_first_not_of("0123456789", f.id.size() + 1) == std::string::npos);
    // A vehicle of the user's route files (or of one of their flows).
    if (!found && routes) found = !sim::VehicleIdProblem(*routes, focus);
    if (!found || focus == config.sim.ego.id)
      throw ConfigError(name + ": key 'evaluation.focus_object' names '" + focus +
                        "', which is no vehicle of the scenario (expected an id of "
                        "traffic.vehicles, or <flow id>.<k> for the k-th vehicle of a flow)");
  }
  for (double t : config.evaluation.snapshot_times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw ConfigError(
          name + ": key 'evaluation.snapshot_times' holds " + std::to_string(t) +
          " s, outside the run (0, duration = " + std::to_string(config.sim.duration) +
          "] s (run time: seconds from the begin)");
}
}  // namespace dualgrid::scenario
