// A nuScenes scene's vehicle annotations: read per instance, their velocity as the devkit's
// box_velocity derives it, and interpolated to any time between two annotations
// (docs/recorded-data.md, "nuScenes", "References").
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/recorded/nuscenes.hpp"
#include "nuscenes_tables.hpp"

namespace dualgrid::recorded::nuscenes {

/// The annotations of one instance, in time order.
struct Instance {
  std::string token, category;
  int label = -1;  ///< RadarScenes label of the category
  bool moving = false;
  std::vector<NuScenesAnnotation> keys;
};

struct SceneInstances {
  std::vector<Instance> instances;  ///< sorted by token
  std::size_t skipped = 0;          ///< vehicle instances with too few annotations
};

/// The vehicle instances annotated in the scene's samples (`sample_time`: sample token ->
/// timestamp [us]). Throws std::invalid_argument naming the file and field.
SceneInstances ReadInstances(Tables& tables, const std::map<std::string, std::int64_t>& sample_time,
                             const NuScenesOptions& options);

/// The instance's box and velocity at `t` [us]: linear in position and velocity, the shorter way
/// round in yaw, the later annotation's size; nullopt outside its first..last annotation.
std::optional<ReferenceObject> Interpolate(const Instance& instance, std::int64_t t);

}  // namespace dualgrid::recorded::nuscenes
