#include "dualgrid/sim/opendrive.hpp"

#include <unistd.h>

#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "dualgrid/core/digest.hpp"
#include "dualgrid/core/input_file.hpp"
#include "dualgrid/sim/sumo_tools.hpp"

namespace dualgrid::sim {

bool IsOpenDrive(const std::string& network) { return network.ends_with(".xodr"); }

std::filesystem::path NetworkCacheDir() {
  const auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v ? v : "";
  };
  if (const std::string dir = env("DUALGRID_CACHE_DIR"); !dir.empty())
    return std::filesystem::path(dir) / "networks";
  if (const std::string dir = env("XDG_CACHE_HOME"); !dir.empty())
    return std::filesystem::path(dir) / "dualgrid" / "networks";
  if (const std::string home = env("HOME"); !home.empty())
    return std::filesystem::path(home) / ".cache" / "dualgrid" / "networks";
  throw std::runtime_error(
      "no folder for converted OpenDRIVE maps: set DUALGRID_CACHE_DIR (or HOME)");
}

std::filesystem::path ConvertOpenDrive(const std::filesystem::path& xodr) {
  namespace fs = std::filesystem;
  Fnv1a64 digest;
  ReadInputChunks(xodr, "OpenDRIVE map", [&](std::string_view bytes) { digest.Add(bytes); });
  digest.Add(kOpenDriveOptions);
  const fs::path dir = NetworkCacheDir();
  const std::string name = xodr.stem().string() + "-" + digest.Hex();
  const fs::path net = dir / (name + ".net.xml"), log = dir / (name + ".netconvert.log");
  if (fs::is_regular_file(net)) return net;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("cannot create the network cache " + dir.string() + ": " +
                             ec.message() + " (set DUALGRID_CACHE_DIR to a writable folder)");
  const fs::path partial = dir / (name + ".net.xml.part" + std::to_string(getpid()));
  std::vector<std::string> args = {"netconvert", "--opendrive-files", fs::absolute(xodr).string(),
                                   "--output-file", partial.string()};
  std::istringstream options(kOpenDriveOptions);
  for (std::string word; options >> word;) args.push_back(word);
  const int rc = RunSumoTool(args, log);
  if (rc != 0 || !fs::is_regular_file(partial)) {
    fs::remove(partial, ec);
    throw std::invalid_argument(xodr.string() + ": netconvert cannot convert this OpenDRIVE map: " +
                                FirstErrorLine(log) + " (its log: " + log.string() + ")");
  }
  fs::rename(partial, net, ec);
  if (ec) {
    fs::remove(partial, ec);
    throw std::runtime_error("cannot write " + net.string() + ": " + ec.message());
  }
  return net;
}

}  // namespace dualgrid::sim
