// `dualgrid tangential --kind aspect`: the aspect case (scenario::MakeAspectCase) written to disk,
// its network built with netconvert (DUALGRID_NETCONVERT) next to the scenario.
#pragma once

#include <filesystem>
#include <string>

#include "dualgrid/scenario/aspect_case.hpp"

namespace dualgrid::tools {

/// Writes `out` (.yaml) and `out`'s stem + .nod.xml/.edg.xml/.net.xml beside it. Throws
/// std::invalid_argument as MakeAspectCase, std::runtime_error when a write or netconvert fails.
/// Returns a summary line of the geometry.
std::string WriteAspectCase(const scenario::AspectCase& c, const std::filesystem::path& out);

}  // namespace dualgrid::tools
