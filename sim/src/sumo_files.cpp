#include "dualgrid/sim/sumo_files.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <stdlib.h>

#include "dualgrid/sim/sumo_tools.hpp"
#include "dualgrid/sim/vehicle_ranges.hpp"
#include "dualgrid/sim/xml_scan.hpp"

namespace dualgrid::sim {
namespace {

std::vector<std::filesystem::path> PathList(const std::string& list,
                                            const std::filesystem::path& base) {
  std::vector<std::filesystem::path> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    if (b == std::string::npos) continue;
    const std::filesystem::path p(item.substr(b, e - b + 1));
    out.push_back((p.is_absolute() ? p : base / p).lexically_normal());
  }
  return out;
}

// A SUMO time or count attribute as a finite number; std::nullopt when absent or not a plain
// number (SUMO also reads "1:00:00" and "exp(0.1)": then the count depends on SUMO).
std::optional<double> Number(const char* text) {
  if (text == nullptr || *text == '\0') return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

// A <flow>'s time between departures [s]: period, or 3600 / vehsPerHour; std::nullopt when
// chance decides (probability) or it is not a plain number.
std::optional<double> FlowPeriod(const XmlElement& e) {
  std::optional<double> period = Number(e.Attribute("period"));
  if (!period)
    if (const auto vph = Number(e.Attribute("vehsPerHour")); vph && *vph > 0)
      period = 3600.0 / *vph;
  return period && *period > 0.0 ? period : std::nullopt;
}

// How many vehicles a <flow> creates (SUMO's rules: `number`; else departures from begin every
// period, 3600 / vehsPerHour, before end); std::nullopt when chance or the run decides.
std::optional<long> FlowMembers(const XmlElement& e, double begin) {
  if (const auto n = Number(e.Attribute("number"))) return std::max(0L, std::lround(*n));
  const auto end = Number(e.Attribute("end"));
  const std::optional<double> period = FlowPeriod(e);
  if (!end || !period) return std::nullopt;
  if (!(*end > begin)) return 0L;
  return static_cast<long>(std::ceil((*end - begin) / *period - 1e-9));
}

// Elements whose id names something that is not a vehicle (for "'x' is a vType").
bool NamesOther(std::string_view tag) {
  static const char* kTags[] = {"vType",  "vTypeDistribution", "route",     "routeDistribution",
                                "person", "personFlow",        "container", "containerFlow"};
  return std::find(std::begin(kTags), std::end(kTags), tag) != std::end(kTags);
}

std::string Quote(const std::string& s) { return "'" + s + "'"; }

}  // namespace

namespace {

// A SUMO time option's text in seconds: a number, or SUMO's clock form [[[D:]H:]M:]S
// ("7:00:00"); std::nullopt for anything else.
std::optional<double> SumoTime(const std::string& text) {
  if (const auto plain = Number(text.c_str())) return plain;
  std::vector<double> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ':')) {
    const auto v = Number(part.c_str());
    if (!v) return std::nullopt;
    parts.push_back(*v);
  }
  if (parts.size() < 2 || parts.size() > 4) return std::nullopt;
  static const double kUnit[] = {86400.0, 3600.0, 60.0, 1.0};  // D, H, M, S [s]
  double total = 0.0;
  for (std::size_t i = 0; i < parts.size(); ++i) total += parts[i] * kUnit[4 - parts.size() + i];
  return total;
}

// SUMO's own reading of `cfg`: `sumo -c CFG --save-configuration OUT` writes every option it
// took, under its canonical name, with paths resolved against the configuration's folder (and
// exits without simulating). Returns option name -> value text.
std::map<std::string, std::string> AskSumo(const std::filesystem::path& cfg) {
  namespace fs = std::filesystem;
  std::string folder = (fs::temp_directory_path() / "dualgrid_sumocfg.XXXXXX").string();
  if (!mkdtemp(folder.data()))
    throw std::runtime_error("cannot create a temporary folder in " +
                             fs::temp_directory_path().string());
  struct Remove {
    fs::path dir;
    ~Remove() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } remove{folder};
  const fs::path saved = fs::path(folder) / "saved.sumocfg", log = fs::path(folder) / "sumo.log";
  const int rc = RunSumoTool({"sumo", "-c", fs::absolute(cfg).string(), "--save-configuration",
                              saved.string(), "--xml-validation", "never"},
                             log);
  if (rc != 0 || !fs::is_regular_file(saved))
    throw std::invalid_argument(cfg.string() +
                                ": SUMO cannot read this configuration: " + FirstErrorLine(log));
  std::map<std::string, std::string> options;
  ScanXml(saved, "SUMO's reading of " + cfg.string(), [&](const XmlElement& e) {
    if (e.depth() == 2 && e.Attribute("value"))
      options[std::string(e.tag())] = e.Attribute("value");
    return true;
  });
  return options;
}

}  // namespace

SumoConfigInputs ReadSumoConfig(const std::filesystem::path& cfg) {
  // The file itself first: a regular file, bounded, well-formed XML (SUMO would block on a FIFO
  // and name no file for a broken one).
  ScanXml(cfg, "SUMO configuration", [](const XmlElement&) { return true; });
  const std::map<std::string, std::string> options = AskSumo(cfg);
  const auto option = [&](const char* name) -> std::optional<std::string> {
    const auto it = options.find(name);
    return it == options.end() ? std::nullopt : std::optional<std::string>(it->second);
  };
  const std::filesystem::path base = std::filesystem::absolute(cfg).parent_path();
  SumoConfigInputs in;
  const auto net = option("net-file");
  const auto nets = net ? PathList(*net, base) : std::vector<std::filesystem::path>{};
  if (nets.empty())
    throw std::invalid_argument(cfg.string() +
                                ": element <net-file value=\"...\"/> (or <net value=...>) "
                                "expected in <input>");
  // SUMO would merge several networks into one; the radar's map and the scoring take one file.
  if (nets.size() > 1)
    throw std::invalid_argument(cfg.string() + ": element <net-file value=\"" + *net +
                                "\"/>: expected one network file, got " +
                                std::to_string(nets.size()) +
                                " (merge them with netconvert into one .net.xml)");
  in.net_file = nets.front();
  if (const auto routes = option("route-files")) in.route_files = PathList(*routes, base);
  if (const auto additional = option("additional-files"))
    in.additional_files = PathList(*additional, base);
  if (const auto step = option("step-length")) {
    in.step_length = Number(step->c_str());
    if (!in.step_length || !(*in.step_length > 0.0))
      throw std::invalid_argument(cfg.string() + ": element <step-length value=\"" + *step +
                                  "\"/>: expected a positive number of seconds");
  }
  const auto time = [&](const char* name) -> std::optional<double> {
    const auto text = option(name);
    if (!text) return std::nullopt;
    const auto t = SumoTime(*text);
    if (!t)
      throw std::invalid_argument(cfg.string() + ": element <" + name + " value=\"" + *text +
                                  "\"/>: expected a time in seconds (SUMO time)");
    return t;
  };
  in.begin = time("begin").value_or(0.0);
  in.end = time("end");
  if (const auto port = option("remote-port")) in.remote_port = *port;
  return in;
}

namespace {

// The numeric attributes of `e` and its vClass in the ranges of vehicle_ranges.hpp (libsumo
// asserts on a NaN length and takes an infinite maxSpeed); throws std::invalid_argument
// "<file>:<line>: <vType id="x"> length="nan": expected in (0, 30] m".
void CheckNumbers(const std::string& file, const XmlElement& e) {
  const std::string_view tag = e.tag();
  const bool type = tag == "vType" || tag.rfind("carFollowing-", 0) == 0;
  const bool vehicle = tag == "vehicle" || tag == "trip" || tag == "flow" || tag == "stop";
  if (!type && !vehicle) return;
  const auto where = [&](std::string_view attribute, const char* value) {
    const char* id = e.Attribute("id");
    return file + ":" + std::to_string(e.line()) + ": <" + std::string(tag) +
           (id ? std::string(" id=\"") + id + "\"" : std::string()) + "> " +
           std::string(attribute) + "=\"" + value + "\": ";
  };
  for (const char* const* a = e.attributes(); a != nullptr && a[0] != nullptr; a += 2) {
    const std::optional<NumberRange> range =
        type ? VTypeAttributeRange(a[0]) : VehicleAttributeRange(a[0]);
    if (range)
      if (const auto problem = SumoNumberProblem(a[1], *range))
        throw std::invalid_argument(where(a[0], a[1]) + *problem);
  }
  if (const char* vclass = e.Attribute("vClass"); vclass && tag == "vType")
    if (!IsSumoVehicleClass(vclass))
      throw std::invalid_argument(where("vClass", vclass) + "expected a SUMO vehicle class, " +
                                  SumoVehicleClassList());
}

// Indexes one file into `index`. `what` names its role in messages.
void IndexFile(const std::string& file, const std::string& what, RouteFileIndex* index) {
  std::map<std::string, std::size_t> unhonoured, unseen;  // tag -> count
  ScanXml(file, what, [&](const XmlElement& e) {
    const std::string_view tag = e.tag();
    CheckNumbers(file, e);
    const char* id = e.Attribute("id");
    if (tag == "person" || tag == "personFlow" || tag == "container" || tag == "containerFlow")
      ++unhonoured[std::string(tag)];
    if (tag == "poly" || tag == "poi") ++unseen[std::string(tag)];
    if (id == nullptr) return true;
    if (tag == "vehicle" || tag == "trip") {
      const auto depart = Number(e.Attribute("depart"));
      index->vehicles.push_back({id, depart.value_or(0.0), depart.has_value(), file});
    } else if (tag == "flow") {
      const double begin = Number(e.Attribute("begin")).value_or(0.0);
      index->flows.push_back(
          {id, FlowMembers(e, begin), begin, Number(e.Attribute("end")), FlowPeriod(e), file});
    } else if (NamesOther(tag)) {
      index->others.emplace(id, std::string(tag));
      if (tag == "vType" || tag == "vTypeDistribution") index->types.insert(id);
    }
    return true;
  });
  for (const auto& [tag, n] : unhonoured)
    index->warnings.push_back(file + ": " + std::to_string(n) + " <" + tag +
                              "> element(s): SUMO simulates them, but the radar model and the "
                              "scoring see vehicles only, so they are neither detected nor scored");
  for (const auto& [tag, n] : unseen)
    index->warnings.push_back(file + ": " + std::to_string(n) + " <" + tag +
                              "> element(s): SUMO loads them, but the radar model does not see "
                              "them (it sees vehicles and the scenario's guard rails and parked "
                              "boxes), so they give no detections");
}

}  // namespace

void IndexSumoFiles(const std::vector<std::string>& files, const std::string& what,
                    RouteFileIndex* index) {
  for (const std::string& file : files) IndexFile(file, what, index);
}

RouteFileIndex IndexRouteFiles(const std::vector<std::string>& route_files,
                               const std::vector<std::string>& additional_files) {
  RouteFileIndex index;
  IndexSumoFiles(additional_files, "SUMO additional file", &index);
  IndexSumoFiles(route_files, "SUMO route file", &index);
  return index;
}

std::optional<std::string> VehicleIdProblem(const RouteFileIndex& index, const std::string& id) {
  for (const auto& v : index.vehicles)
    if (v.id == id) return std::nullopt;
  for (const auto& f : index.flows) {
    if (f.id == id)
      return "is a flow, not a vehicle: SUMO names its vehicles " + Quote(id + ".0") + ", " +
             Quote(id + ".1") + ", ...";
  }
  // FLOW.k: the longest flow id that prefixes it (flow ids may contain dots themselves).
  const auto dot = id.rfind('.');
  if (dot != std::string::npos && dot + 1 < id.size() &&
      id.find_first_not_of("0123456789", dot + 1) == std::string::npos) {
    const std::string flow = id.substr(0, dot);
    for (const auto& f : index.flows) {
      if (f.id != flow) continue;
      const long k = std::strtol(id.c_str() + dot + 1, nullptr, 10);
      if (f.members && *f.members == 0)
        return "is no member of flow " + Quote(flow) + ", which creates no vehicle";
      if (f.members && k >= *f.members)
        return "is no member of flow " + Quote(flow) + ", which creates " +
               std::to_string(*f.members) + " vehicle(s): " + Quote(flow + ".0") + " to " +
               Quote(flow + "." + std::to_string(std::max(0L, *f.members - 1)));
      return std::nullopt;
    }
  }
  if (const auto it = index.others.find(id); it != index.others.end())
    return "is a <" + it->second + ">, not a vehicle";
  return "is no vehicle, trip or flow member of the route files";
}

std::optional<FileDeparture> DepartureOf(const RouteFileIndex& index, const std::string& id) {
  for (const auto& v : index.vehicles)
    if (v.id == id) {
      if (!v.timed) return std::nullopt;
      FileDeparture d;
      d.depart = v.depart;
      return d;
    }
  const auto dot = id.rfind('.');
  if (dot == std::string::npos) return std::nullopt;
  for (const auto& f : index.flows) {
    if (f.id != id.substr(0, dot) || !f.period) continue;
    const long k = std::strtol(id.c_str() + dot + 1, nullptr, 10);
    return FileDeparture{f.begin, f.period, k, f.end};
  }
  return std::nullopt;
}

std::string ExampleVehicleIds(const RouteFileIndex& index, std::size_t n) {
  struct Candidate {
    double depart;
    std::string id;
  };
  std::vector<Candidate> all;
  for (const auto& v : index.vehicles) all.push_back({v.depart, v.id});
  for (const auto& f : index.flows)
    if (!f.members || *f.members > 0) all.push_back({f.begin, f.id + ".0"});
  std::stable_sort(all.begin(), all.end(),
                   [](const Candidate& a, const Candidate& b) { return a.depart < b.depart; });
  std::string out;
  for (std::size_t i = 0; i < all.size() && i < n; ++i)
    out += (out.empty() ? "" : ", ") + Quote(all[i].id);
  if (all.size() > n) out += ", ...";
  return out.empty() ? "none" : out;
}

}  // namespace dualgrid::sim
