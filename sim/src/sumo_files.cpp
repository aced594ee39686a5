#include "dualgrid/sim/sumo_files.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace dualgrid::sim {
namespace {

std::string ReadAll(const std::filesystem::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path.string() + ": cannot read this " + what);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The value attribute of the first element <tag value="..."/> of `xml` (either quote), outside
// comments; std::nullopt when absent.
std::optional<std::string> ValueOf(const std::string& xml, const std::string& tag) {
  std::size_t at = 0;
  while ((at = xml.find("<" + tag, at)) != std::string::npos) {
    const std::size_t comment = xml.rfind("<!--", at);
    if (comment != std::string::npos && xml.find("-->", comment) > at) {  // inside a comment
      at = xml.find("-->", comment);
      continue;
    }
    const std::size_t end = xml.find('>', at);
    const std::string element = xml.substr(at, end - at);
    at = end;
    const std::size_t v = element.find("value=");
    if (v == std::string::npos || v + 6 >= element.size()) continue;
    const char quote = element[v + 6];
    const std::size_t close = element.find(quote, v + 7);
    if (close == std::string::npos) continue;
    return element.substr(v + 7, close - v - 7);
  }
  return std::nullopt;
}

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

// Elements outside comments whose tag is exactly `tag`.
std::size_t CountElements(const std::string& xml, const std::string& tag) {
  std::size_t n = 0, at = 0;
  while ((at = xml.find("<" + tag, at)) != std::string::npos) {
    const std::size_t after = at + 1 + tag.size();
    const std::size_t comment = xml.rfind("<!--", at);
    const bool in_comment = comment != std::string::npos && xml.find("-->", comment) > at;
    if (!in_comment && after < xml.size() &&
        (xml[after] == ' ' || xml[after] == '>' || xml[after] == '/' || xml[after] == '\n' ||
         xml[after] == '\t' || xml[after] == '\r'))
      ++n;
    at = after;
  }
  return n;
}

}  // namespace

SumoConfigInputs ReadSumoConfig(const std::filesystem::path& cfg) {
  const std::string xml = ReadAll(cfg, "SUMO configuration");
  const std::filesystem::path base = std::filesystem::absolute(cfg).parent_path();
  SumoConfigInputs in;
  const auto net = ValueOf(xml, "net-file");
  const auto nets = net ? PathList(*net, base) : std::vector<std::filesystem::path>{};
  if (nets.empty())
    throw std::invalid_argument(cfg.string() +
                                ": element <net-file value=\"...\"/> expected in <input>");
  in.net_file = nets.front();
  if (const auto r = ValueOf(xml, "route-files")) in.route_files = PathList(*r, base);
  if (const auto a = ValueOf(xml, "additional-files")) in.additional_files = PathList(*a, base);
  if (const auto s = ValueOf(xml, "step-length")) {
    try {
      in.step_length = std::stod(*s);
    } catch (const std::exception&) {
      throw std::invalid_argument(cfg.string() + ": element <step-length value=\"" + *s +
                                  "\"/>: expected a number of seconds");
    }
  }
  return in;
}

std::vector<std::string> RouteFileWarnings(const std::vector<std::string>& route_files) {
  std::vector<std::string> out;
  for (const std::string& file : route_files) {
    const std::string xml = ReadAll(file, "SUMO route file");
    for (const char* tag : {"person", "personFlow", "container", "containerFlow"}) {
      const std::size_t n = CountElements(xml, tag);
      if (n == 0) continue;
      out.push_back(file + ": " + std::to_string(n) + " <" + tag +
                    "> element(s): SUMO simulates them, but the radar model and the scoring see "
                    "vehicles only, so they are neither detected nor scored");
    }
  }
  return out;
}

bool RouteFilesDefine(const std::vector<std::string>& route_files, const std::string& id) {
  for (const std::string& file : route_files) {
    const std::string xml = ReadAll(file, "SUMO route file");
    if (xml.find("id=\"" + id + "\"") != std::string::npos ||
        xml.find("id='" + id + "'") != std::string::npos)
      return true;
  }
  return false;
}

}  // namespace dualgrid::sim
