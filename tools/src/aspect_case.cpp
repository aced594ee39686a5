#include "aspect_case.hpp"

#include <stdexcept>
#include <string>

#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/sim/sumo_tools.hpp"

namespace dualgrid::tools {

std::string WriteAspectCase(const scenario::AspectCase& c, const std::filesystem::path& out) {
  const scenario::AspectCaseFiles f = scenario::MakeAspectCase(c, out.stem().string());
  const std::filesystem::path base = out.parent_path() / out.stem();
  const auto nod_path = base.string() + ".nod.xml", edg_path = base.string() + ".edg.xml",
             net_path = base.string() + ".net.xml", log_path = base.string() + ".netconvert.log";
  outputs::WriteTextFile(nod_path, f.nodes);
  outputs::WriteTextFile(edg_path, f.edges);
  // netconvert as found at build time, its output in the log (sim::RunSumoTool).
  const int rc = sim::RunSumoTool(
      {DUALGRID_NETCONVERT, "--node-files", nod_path, "--edge-files", edg_path, "--no-turnarounds",
       "true", "--offset.disable-normalization", "true", "--xml-validation", "never",
       "--no-warnings", "true", "--output-file", net_path},
      log_path);
  if (rc != 0)
    throw std::runtime_error("netconvert failed building " + net_path + " (see " + log_path +
                             "): " + sim::FirstErrorLine(log_path));
  outputs::WriteTextFile(out, f.scenario);
  return f.summary;
}

}  // namespace dualgrid::tools
