// Scenario files (YAML) -> parameter structs. The loader only fills structs and asks each struct
// to validate itself; the libraries never see YAML.
#pragma once

#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "dualgrid/eval/dbscan.hpp"
#include "dualgrid/eval/metrics.hpp"
#include "dualgrid/filter/params.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::scenario {

/// A malformed scenario: the message names the file, the key and what was expected.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The `sensors:` section: the radar rig and which model effects are on.
struct RadarConfig {
  std::vector<radar::SensorParams> sensors;  ///< default: radar::DefaultRig of the ego's box
  std::string accuracy = "datasheet";        ///< `sensors.accuracy`: "datasheet" or "clean"
  radar::ModelOptions options;
  /// The ego box [m] the default mounts were placed on (the scenario's ego type; PlaceRigOn
  /// moves them onto the box SUMO simulates, e.g. an ego of the user's route files).
  double rig_length = 0.0, rig_width = 0.0;
  /// Sensors whose `mount` the file gives: kept as given wherever the box is.
  std::set<std::string> mounts_given;
};

/// Places the default mounts of `radar` on an ego box of `length` x `width` [m] (the rig of
/// radar::DefaultRig for that box; given mounts stay). Returns whether a mount moved.
bool PlaceRigOn(RadarConfig* radar, double length, double width);

/// The `evaluation:` section (scoring as in the paper's Sec. V).
struct EvaluationConfig {
  double dynamic_threshold = 0.6;  ///< a cell is dynamic when P(dynamic) exceeds this
  eval::DbscanParams dbscan;
  /// Clusters lighter than this summed dynamic mass are not objects: the mass of three cells at
  /// the dynamic threshold (3 x 0.6), while a vehicle face seen by radar spans >= 4 cells of 0.5 m.
  double min_cluster_mass = 1.8;
  eval::TrackingMetricsParams tracking;
  /// Vehicle whose particle weights are plotted over time (paper Fig. 4); empty: the vehicle
  /// that stays longest in the grid.
  std::string focus_object;
  /// Times [s] of the grid pictures (paper Fig. 7); empty: 1/4, 1/2 and 3/4 of the duration.
  std::vector<double> snapshot_times;
  bool IsValid(std::string* error) const;
};

/// Where the grid lies (keys `filter.frame`, `filter.ahead`, `filter.left`; docs/algorithm.md,
/// "Grid frame"). The filter runs in the grid frame; the co-simulation maps SUMO's world into it.
struct GridPlacement {
  enum class Frame {
    kWorld,    ///< grid axes along the world's x and y
    kHeading,  ///< turned to the ego's heading when it enters (GridYawAlong); fixed
    kFollow,   ///< as kHeading, then turned again whenever the road has turned by realign_deg
  };
  Frame frame = Frame::kFollow;
  /// kFollow: the drift [deg] of the ego's lane direction from the grid's x axis that turns the
  /// grid (RealignedYaw, core/grid_frame.hpp); in (0, 90].
  double realign_deg = 5.0;
  /// Distance [m] from the ego to the grid's front edge (+x of the grid frame) and to its left
  /// edge (+y); NaN: half the extent (the ego centred). 0 <= ahead <= length_x,
  /// 0 <= left <= width_y.
  double ahead = std::numeric_limits<double>::quiet_NaN();
  double left = std::numeric_limits<double>::quiet_NaN();
  /// Offset [m] from the ego to the grid centre in the grid frame, for a grid of that extent.
  Vector2 CentreOffset(double length_x, double width_y) const;
};
std::string_view ToString(GridPlacement::Frame f);

struct ScenarioConfig {
  std::filesystem::path file;
  sim::ScenarioSpec sim;
  RadarConfig radar;
  filter::FilterParams filter;
  GridPlacement grid;
  /// `filter.birth_velocity` given per mode ({position: uniform, ...}); modes not listed use
  /// filter.birth_velocity.
  std::map<filter::WeightMode, filter::BirthVelocity> birth_velocity_by_mode;
  /// `filter.preset` as given ("" when none).
  std::string filter_preset;
  /// The command line's `--set KEY=VALUE` texts, as applied (recorded in config.json).
  std::vector<std::string> overrides;
  EvaluationConfig evaluation;

  /// The filter parameters of one weight mode: `filter` with that mode and its birth velocity.
  filter::FilterParams FilterFor(filter::WeightMode mode) const;
};

/// Every resolved parameter, for the run folder's config.json (same keys and units as the file).
nlohmann::json ConfigToJson(const ScenarioConfig& config);

/// One command-line override `--set KEY=VALUE`: KEY a dotted path into the file ("filter.sigma_v",
/// "traffic.vehicles.0.speed": a number indexes a list), VALUE any YAML value ("0.5", "paper",
/// "[1, 2]"). Applied to the document before it is read, so it is validated like the file.
struct Override {
  std::string key;
  std::string value;
};
/// Splits "KEY=VALUE"; throws ConfigError naming `text` when there is no '=' or no key.
Override ParseOverride(const std::string& text);

/// Loads and validates a scenario file, with `overrides` applied in order. Throws ConfigError.
ScenarioConfig LoadScenario(const std::filesystem::path& file,
                            const std::vector<Override>& overrides = {});

/// The same for a scenario's text; `file` names it in errors and anchors relative network paths.
/// Throws ConfigError and nothing else for any text (the fuzz target tests/fuzz/ checks this).
ScenarioConfig LoadScenarioText(const std::string& text, const std::filesystem::path& file);

}  // namespace dualgrid::scenario
