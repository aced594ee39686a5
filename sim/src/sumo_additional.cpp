#include "dualgrid/sim/sumo_additional.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "dualgrid/sim/xml_scan.hpp"

namespace dualgrid::sim {
namespace {

struct PathAttribute {
  std::string_view element, attribute;
};

// SUMO 1.15's output attributes of additional files (data/xsd/additional_file.xsd: the types
// e1Detector, e2Detector, e3Detector, instantInductionLoop, routeProbe, vTypeProbe, meandata,
// calibrator and timedEvent; element synonyms included).
constexpr PathAttribute kOutputs[] = {{"e1Detector", "file"},
                                      {"inductionLoop", "file"},
                                      {"e2Detector", "file"},
                                      {"laneAreaDetector", "file"},
                                      {"e3Detector", "file"},
                                      {"entryExitDetector", "file"},
                                      {"instantInductionLoop", "file"},
                                      {"routeProbe", "file"},
                                      {"vTypeProbe", "file"},
                                      {"edgeData", "file"},
                                      {"laneData", "file"},
                                      {"edgeRelation", "file"},
                                      {"tazRelation", "file"},
                                      {"calibrator", "output"},
                                      {"timedEvent", "dest"}};
// Attributes that name files SUMO reads, relative to the file naming them.
constexpr PathAttribute kInputs[] = {{"include", "href"},  {"calibrator", "file"},
                                     {"rerouter", "file"}, {"variableSpeedSign", "file"},
                                     {"poly", "imgFile"},  {"poi", "imgFile"},
                                     {"vType", "imgFile"}, {"vType", "osgFile"}};

constexpr int kMaxIncludeDepth = 8;

template <std::size_t N>
bool InTable(const PathAttribute (&table)[N], std::string_view element,
             std::string_view attribute) {
  return std::any_of(std::begin(table), std::end(table), [&](const PathAttribute& p) {
    return p.element == element && p.attribute == attribute;
  });
}

bool IsNullDevice(std::string_view v) { return v == "NUL" || v == "nul" || v == "/dev/null"; }

class Preparer {
 public:
  // Absolute: SUMO reads a relative output path relative to the additional file naming it (the
  // copy inside work_dir), so a relative work_dir would be counted twice.
  explicit Preparer(const std::filesystem::path& work_dir)
      : copies_(std::filesystem::absolute(work_dir) / "sumo_additional"),
        outputs_dir_(std::filesystem::absolute(work_dir) / "sumo_outputs") {}

  // The file SUMO should load for `file`: `file` itself or a prepared copy.
  std::string Prepare(const std::filesystem::path& file, int depth) {
    const std::filesystem::path dir = std::filesystem::absolute(file).parent_path();
    std::filesystem::create_directories(copies_);
    std::string name = file.filename().string();
    if (name.size() > 3 && name.ends_with(".gz")) name.resize(name.size() - 3);  // copies are plain
    const std::filesystem::path copy = copies_ / (std::to_string(++copies_made_) + "_" + name);
    std::size_t changed = 0;
    try {
      changed = CopyXml(
          file, "SUMO additional file", copy,
          [&](const XmlElement& e, std::vector<std::pair<std::string, std::string>>* changes) {
            Edit(file, dir, depth, e, changes);
          });
    } catch (...) {
      std::error_code ignored;
      std::filesystem::remove(copy, ignored);
      throw;
    }
    if (changed > 0) return copy.string();
    std::filesystem::remove(copy);
    return file.string();
  }

  std::vector<RedirectedOutput> outputs;

 private:
  void Edit(const std::filesystem::path& file, const std::filesystem::path& dir, int depth,
            const XmlElement& e, std::vector<std::pair<std::string, std::string>>* changes) {
    for (std::string_view attribute : {"file", "output", "dest", "href", "imgFile", "osgFile"}) {
      const char* value = e.Attribute(attribute);
      if (value == nullptr || *value == '\0') continue;
      const std::string v = value;
      if (InTable(kOutputs, e.tag(), attribute)) {
        if (IsNullDevice(v)) continue;
        const std::string to = Redirect((dir / v).lexically_normal());
        outputs.push_back({file.string(), std::string(e.tag()), std::string(attribute), v, to});
        changes->emplace_back(attribute, to);
      } else if (e.tag() == "include" && attribute == "href") {
        if (depth >= kMaxIncludeDepth)
          throw std::invalid_argument(file.string() + ":" + std::to_string(e.line()) +
                                      ": <include href> nested more than " +
                                      std::to_string(kMaxIncludeDepth) + " levels deep");
        changes->emplace_back(attribute, Prepare((dir / v).lexically_normal(), depth + 1));
      } else if (InTable(kInputs, e.tag(), attribute) && std::filesystem::path(v).is_relative()) {
        changes->emplace_back(attribute, (dir / v).lexically_normal().string());
      }
    }
  }

  // One file in the outputs folder per original path (SUMO writes outputs of one path into one
  // device); names stay the original's unless two originals share one.
  std::string Redirect(const std::filesystem::path& original) {
    if (const auto it = redirected_.find(original.string()); it != redirected_.end())
      return it->second;
    std::filesystem::create_directories(outputs_dir_);
    std::string name = original.filename().string();
    for (int k = 2; used_.count(name); ++k)
      name = std::to_string(k) + "_" + original.filename().string();
    used_.insert(name);
    const std::string to = (outputs_dir_ / name).string();
    redirected_.emplace(original.string(), to);
    return to;
  }

  std::filesystem::path copies_, outputs_dir_;
  int copies_made_ = 0;
  std::map<std::string, std::string> redirected_;
  std::set<std::string> used_;
};

}  // namespace

PreparedAdditionalFiles PrepareAdditionalFiles(const std::vector<std::string>& files,
                                               const std::filesystem::path& work_dir) {
  Preparer p(work_dir);
  PreparedAdditionalFiles out;
  for (const std::string& f : files) out.files.push_back(p.Prepare(f, 0));
  out.outputs = std::move(p.outputs);
  return out;
}

}  // namespace dualgrid::sim
