#include "dualgrid/sim/random_trips.hpp"

#include <stdexcept>

#include "dualgrid/core/text.hpp"
#include "dualgrid/sim/sumo_tools.hpp"

namespace dualgrid::sim {

std::filesystem::path WriteRandomTrips(const std::filesystem::path& network,
                                       const ScenarioSpec& spec,
                                       const std::filesystem::path& work_dir) {
  namespace fs = std::filesystem;
  const fs::path script = SumoHome() / "tools" / "randomTrips.py";
  if (!fs::is_regular_file(script))
    throw std::runtime_error("traffic.random_trips needs SUMO's randomTrips.py, not found at " +
                             script.string() + " (Debian package sumo-tools; or set SUMO_HOME)");
  const fs::path routes = work_dir / "random_trips.rou.xml", log = work_dir / "random_trips.log";
  const auto num = [](double v) { return FormatSignificant(v, 10); };
  const int rc =
      RunSumoTool({"python3", script.string(), "--net-file", network.string(), "--output-trip-file",
                   (work_dir / "random_trips.trips.xml").string(), "--route-file", routes.string(),
                   "--seed", std::to_string(spec.seed % 2147483647), "--begin", num(spec.begin),
                   "--end", num(spec.begin + spec.duration), "--period",
                   num(spec.random_trips->period), "--prefix", "rt", "--allow-fringe"},
                  log);
  if (rc != 0 || !fs::is_regular_file(routes))
    throw std::invalid_argument("traffic.random_trips: randomTrips.py failed on " +
                                network.string() + ": " + FirstErrorLine(log) + " (see " +
                                log.string() + ")");
  return routes;
}

}  // namespace dualgrid::sim
