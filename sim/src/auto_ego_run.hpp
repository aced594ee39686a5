// The first run of SUMO that chooses `ego: {from_routes: auto}` (sim internal).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dualgrid/sim/auto_ego.hpp"
#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::sim {

/// Starts SUMO with `args`, runs it over the scenario's steps and closes it. Candidates: the
/// road vehicles (not pedestrians, trams, trains, ships) of the user's files that depart in the
/// run. The chosen one has another road vehicle in its spec.auto_ego_view for the most steps;
/// ties go to the longer time in the run (a vehicle that never arrives stays to the end), then
/// to the earlier departure (so with no traffic anywhere: the longest in the run, and the
/// choice's with_traffic is 0). std::nullopt when no candidate departed. Throws what libsumo
/// throws.
std::optional<AutoEgoChoice> ChooseAutoEgo(const ScenarioSpec& spec,
                                           const std::vector<std::string>& args);

}  // namespace dualgrid::sim
