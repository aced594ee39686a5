#include "dualgrid/outputs/read_results.hpp"

#include <set>
#include <stdexcept>

namespace dualgrid::outputs {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A setting id as the sweep writes it ("s001"): also a folder name, so nothing else is taken.
bool SettingIdOk(const std::string& id) {
  return id.size() >= 2 && id.size() <= 12 && id[0] == 's' &&
         id.find_first_not_of("0123456789", 1) == std::string::npos;
}

constexpr std::uint64_t kMaxSeedValue = (std::uint64_t{1} << 53) - 1;

}  // namespace

std::vector<TableMetric> ParseTableJson(const JsonFile& doc) {
  std::vector<TableMetric> out;
  for (const JsonAt& m : doc.Root()["metrics"].Items(1000)) {
    TableMetric tm;
    tm.key = m["key"].Text();
    tm.unit = m.Has("unit") ? m["unit"].Text() : "";
    for (const auto& [mode, v] : m["values"].Members()) {
      const std::optional<double> mean = v["mean"].NumberOrNull();
      if (!mean) continue;  // undefined in this run
      eval::MetricValue mv;
      mv.mean = *mean;
      if (v.Has("ci95_half_width")) mv.half_width = v["ci95_half_width"].NumberOrNull();
      mv.n = v.Has("n") ? static_cast<int>(v["n"].Integer(0, 1000000)) : 0;
      tm.modes[mode] = mv;
    }
    out.push_back(std::move(tm));
  }
  return out;
}

std::vector<TableMetric> ReadTableJson(const fs::path& file) {
  return ParseTableJson(ReadJsonFile(file, "result table"));
}

RunState ReadRunState(const fs::path& run_dir) {
  const fs::path file = run_dir / "summary.json";
  std::error_code ec;
  if (!fs::exists(file, ec)) return {false, "not run"};
  try {
    const JsonFile doc = ReadJsonFile(file, "run summary");
    const JsonAt root = doc.Root();
    if (root["complete"].Flag()) return {true, ""};
    const std::string status = root.Has("status") ? root["status"].Text() : "";
    return {false, status.empty() ? "incomplete" : status};
  } catch (const std::invalid_argument& e) {
    return {false, e.what()};
  }
}

fs::path RunFolder(const fs::path& sweep_dir, const std::string& setting, std::uint64_t seed) {
  return sweep_dir / "runs" / setting / ("seed_" + std::to_string(seed));
}

json SweepPlanIdentity(const SweepPlan& p) {
  json j;
  j["scenario"] = p.scenario;
  j["axes"] = json::array();
  for (const auto& a : p.axes) j["axes"].push_back({{"key", a.key}, {"values", a.values}});
  j["seeds"] = p.seeds;
  j["first_seed"] = p.first_seed;
  j["modes"] = p.modes;
  j["duration"] = p.duration ? json(*p.duration) : json(nullptr);
  return j;
}

json SweepPlanJson(const SweepPlan& p) {
  json j = SweepPlanIdentity(p);
  j["settings"] = json::array();
  for (const auto& s : p.settings)
    j["settings"].push_back(
        {{"id", s.id}, {"values", s.values}, {"label", s.label}, {"scenario", s.scenario}});
  j["runs"] = json::array();
  for (const auto& r : p.runs)
    j["runs"].push_back({{"setting", r.setting},
                         {"seed", r.seed},
                         {"folder", RunFolder("", r.setting, r.seed).relative_path().string()}});
  return j;
}

SweepPlan ParseSweepPlan(const JsonFile& doc) {
  const JsonAt root = doc.Root();
  SweepPlan p;
  p.scenario = root["scenario"].Text();
  std::set<std::string> keys;
  for (const JsonAt& a : root["axes"].Items(64)) {
    SweepPlan::Axis axis;
    axis.key = a["key"].Text();
    if (axis.key.empty() || !keys.insert(axis.key).second) a["key"].Fail("a key named once");
    for (const JsonAt& v : a["values"].Items(1000)) axis.values.push_back(v.Text());
    if (axis.values.empty()) a["values"].Fail("at least one value");
    p.axes.push_back(std::move(axis));
  }
  if (p.axes.empty()) root["axes"].Fail("at least one axis");
  p.seeds = static_cast<int>(root["seeds"].Integer(1, 10000));
  p.first_seed = root["first_seed"].Unsigned(kMaxSeedValue);
  if (p.first_seed > kMaxSeedValue - static_cast<std::uint64_t>(p.seeds - 1))
    root["first_seed"].Fail("first_seed + seeds - 1 <= " + std::to_string(kMaxSeedValue));
  for (const JsonAt& m : root["modes"].Items(3)) {
    const std::string mode = m.Text();
    if (mode != "position" && mode != "velocity" && mode != "dual")
      m.Fail("position, velocity or dual");
    p.modes.push_back(mode);
  }
  if (p.modes.empty()) root["modes"].Fail("at least one mode");
  p.duration = root["duration"].NumberOrNull();
  std::set<std::string> ids;
  for (const JsonAt& s : root["settings"].Items(kMaxSweepSettings)) {
    SweepPlan::Setting st;
    st.id = s["id"].Text();
    if (!SettingIdOk(st.id) || !ids.insert(st.id).second)
      s["id"].Fail("a setting id 's' followed by digits, named once");
    for (const JsonAt& v : s["values"].Tuple(p.axes.size())) st.values.push_back(v.Text());
    st.label = s["label"].Text();
    st.scenario = s["scenario"].Text();
    p.settings.push_back(std::move(st));
  }
  for (const JsonAt& r : root["runs"].Items(kMaxSweepRuns)) {
    SweepPlan::Run run;
    run.setting = r["setting"].Text();
    if (!ids.count(run.setting)) r["setting"].Fail("the id of one of the plan's settings");
    run.seed = r["seed"].Unsigned(kMaxSeedValue);
    p.runs.push_back(std::move(run));
  }
  return p;
}

SweepPlan ReadSweepPlan(const fs::path& file) {
  return ParseSweepPlan(ReadJsonFile(file, "sweep plan"));
}

}  // namespace dualgrid::outputs
