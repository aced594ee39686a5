// Traffic for a network that comes without any (an OpenDRIVE map, a bare .net.xml): SUMO's
// randomTrips.py (sumo-tools) with duarouter, seeded by the scenario's seed (docs/scenarios.md,
// "OpenDRIVE maps").
#pragma once

#include <filesystem>

#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::sim {

/// Writes `work_dir`/random_trips.rou.xml: `randomTrips.py -n NETWORK --seed SEED --begin B
/// --end B+D --period P --prefix rt --allow-fringe -r ...` (trips may begin and end on the
/// map's boundary edges, where traffic enters and leaves a map) for spec.random_trips (vehicles
/// rt0, rt1, ... with routes duarouter found; trips without a route are dropped), and returns its
/// path. The same network, seed, window and period give the same vehicles. Throws
/// std::invalid_argument with the tool's first error line when it fails, std::runtime_error when it
/// cannot be started (sumo-tools not installed: the message says so).
std::filesystem::path WriteRandomTrips(const std::filesystem::path& network,
                                       const ScenarioSpec& spec,
                                       const std::filesystem::path& work_dir);

}  // namespace dualgrid::sim
