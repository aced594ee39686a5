// The section readers of the scenario loader (internal): each reads one part of the scenario
// file through a MapReader and fills its structs; the helpers they share.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>

#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_files.hpp"
#include "yaml_reader.hpp"

namespace dualgrid::scenario::detail {

/// A number as printf's %g shows it.
std::string Shown(double v);

// A validator's field name and the key users write for it; `degrees`: the key is an angle in
// degrees that the validator checks in radians.
struct KeyAlias {
  std::string_view field, key;
  bool degrees = false;
};

// Turns an IsValid message into a ConfigError naming the key under `section`. FieldCheck
// messages, "field = value: expected what", read as the parser's own: "key '<section>.field'
// expected what, got value"; other validators write "field: message" or "field message". A field
// of `aliases` is named by its key, and a degrees key's value and interval ("in (0, 2 pi] rad")
// are written in degrees ("in (0, 360] deg, got 400").
[[noreturn]] void Invalid(const std::string& file, const std::string& section,
                          const std::string& error, std::span<const KeyAlias> aliases = {});

/// The top-level keys and the `ego`, `traffic`, `actions` and `obstacles` sections
/// (sim_section.cpp).
void ReadSim(MapReader& root, sim::ScenarioSpec* s);
// The user's SUMO route and additional files, indexed once (std::nullopt when there are none):
// ids the scenario names must be vehicles SUMO will simulate and types it gives an RCS must exist
// (a typo would otherwise fail at run time, or silently pick another vehicle or none).
std::optional<sim::RouteFileIndex> IndexUserFiles(MapReader& root, const std::string& name,
                                                  sim::ScenarioSpec& s);
/// The `sensors:` section (radar_section.cpp).
void ReadRadar(MapReader& root, const sim::ScenarioSpec& spec, RadarConfig* radar);
/// The `filter:` section (filter_section.cpp).
void ReadFilter(MapReader& root, ScenarioConfig* config);
/// The `evaluation:` section (evaluation_section.cpp).
void ReadEvaluation(MapReader& root, EvaluationConfig* e);
/// overrides.cpp: sets `o.key` in `doc` to the YAML value `o.value`, creating maps on the way.
void ApplyOverride(YAML::Node doc, const Override& o);

}  // namespace dualgrid::scenario::detail
