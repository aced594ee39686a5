#include "dualgrid/scenario/suite.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "dualgrid/core/input_file.hpp"
#include "yaml_reader.hpp"

namespace dualgrid::scenario {

namespace {

void ReadBands(MapReader& c, RegressionCase* rc) {
  auto bands = c.Map("bands");
  if (!bands) return;
  for (const std::string& key : bands->Keys()) {
    eval::Band b;
    try {
      b.metric = eval::ParseMetricRef(key);
    } catch (const std::invalid_argument& e) {
      bands->Fail(key, std::string("names no metric: ") + e.what());
    }
    if (!b.metric.case_name.empty()) bands->Fail(key, "is a band of this case: no 'case:' prefix");
    if (std::find(rc->modes.begin(), rc->modes.end(), b.metric.mode) == rc->modes.end())
      bands->Fail(key, "names mode '" + b.metric.mode + "', which the case does not run");
    auto r = bands->Map(key);
    if (!r) bands->Fail(key, "expected a map {min, max} or {reference, tolerance}");
    r->Read("min", &b.min);
    r->Read("max", &b.max);
    r->Read("reference", &b.reference);
    r->Read("tolerance", &b.tolerance);
    r->Finish();
    if (b.reference.has_value() != b.tolerance.has_value())
      r->Fail(b.reference ? "tolerance" : "reference", "is required with the other one");
    if (b.reference) {
      if ((b.min || b.max))
        r->Fail("reference", "give either {min, max} or {reference, tolerance}");
      if (!(*b.tolerance >= 0.0)) r->Fail("tolerance", "must be >= 0");
      b.min = *b.reference - *b.tolerance;
      b.max = *b.reference + *b.tolerance;
    }
    if (!b.min && !b.max) r->Fail("min", "a band needs min, max, or reference and tolerance");
    if (b.min && b.max && *b.min > *b.max) r->Fail("max", "is below min: the band is inverted");
    rc->bands.push_back(b);
  }
}

std::vector<eval::Ordering> ReadOrderings(MapReader& r) {
  std::vector<std::string> texts;
  r.Read("orderings", &texts);
  std::vector<eval::Ordering> out;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    try {
      out.push_back(eval::ParseOrdering(texts[i]));
    } catch (const std::invalid_argument& e) {
      r.Fail("orderings", "entry " + std::to_string(i) + ": " + e.what());
    }
  }
  return out;
}

}  // namespace

RegressionSuite LoadSuite(const std::filesystem::path& file) {
  std::string text;
  try {
    text = ReadInputText(file, "suite file");  // bounded; FIFOs and devices refused
  } catch (const std::invalid_argument& e) {
    throw ConfigError(e.what());
  }
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(file.string() + ":" + std::to_string(e.mark.line + 1) +
                      ": not valid YAML: " + e.msg);
  }
  RegressionSuite suite;
  suite.file = file;
  MapReader root(doc, file.string(), "");
  root.Read("name", &suite.name);
  if (suite.name.empty()) suite.name = file.stem().string();
  std::set<std::string> names;
  auto cases = root.MapList("cases");
  if (cases.empty()) root.Fail("cases", "must list at least one case");
  for (auto& c : cases) {
    RegressionCase rc;
    c.Require("name", &rc.name);
    // The name is a folder under --out and a JUnit suite name: letters, digits, '_' and '-',
    // not starting with '-' and not a name the reports use.
    const bool name_ok = !rc.name.empty() && rc.name.size() <= 64 && rc.name[0] != '-' &&
                         rc.name != "suite" &&
                         rc.name.find_first_not_of(
                             "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
                             std::string::npos;
    if (!name_ok)
      c.Fail("name",
             "expected 1-64 letters, digits, '_' or '-' (not starting with '-', not "
             "'suite'), got '" +
                 rc.name + "'");
    if (!names.insert(rc.name).second) c.Fail("name", "'" + rc.name + "' names two cases");
    std::string scenario;
    c.Require("scenario", &scenario);
    rc.scenario = scenario == "tangential" || std::filesystem::path(scenario).is_absolute()
                      ? std::filesystem::path(scenario)
                      : std::filesystem::absolute(file.parent_path() / scenario).lexically_normal();
    if (!rc.IsGenerator() && !InputExists(rc.scenario))  // a FIFO or loop: named when read
      c.Fail("scenario", "'" + scenario + "' not found (read relative to the suite file: " +
                             rc.scenario.string() + ")");
    c.Read("set", &rc.sets);
    c.Read("modes", &rc.modes);
    if (rc.modes.empty()) c.Fail("modes", "must list at least one mode");
    for (const std::string& m : rc.modes)
      if (!eval::IsModeName(m))
        c.Fail("modes", "unknown mode '" + m + "' (expected position, velocity or dual)");
    c.Read("duration", &rc.duration);
    if (rc.duration && !(*rc.duration > 0.0 && *rc.duration <= 3600.0))
      c.Fail("duration", "expected seconds in (0, 3600]");
    c.Read("seeds", &rc.seeds);
    if (rc.seeds < 1 || rc.seeds > 10000) c.Fail("seeds", "expected a whole number in [1, 10000]");
    c.Read("first_seed", &rc.first_seed);
    // Seeds run as `experiment` runs them: first_seed .. first_seed + seeds - 1, each at most
    // 2^53 - 1 (a seed is exact in JSON and in every tool that reads the outputs).
    constexpr std::uint64_t kMaxSeed = (std::uint64_t{1} << 53) - 1;
    if (rc.first_seed > kMaxSeed - static_cast<std::uint64_t>(rc.seeds - 1))
      c.Fail("first_seed", "expected a whole number with first_seed + seeds - 1 <= " +
                               std::to_string(kMaxSeed) + ", got " + std::to_string(rc.first_seed));
    c.Read("digest", &rc.digest);
    c.Read("record", &rc.record);
    for (const std::string& m : rc.record) {
      const auto& all = eval::RegressionMetricNames();
      if (std::find(all.begin(), all.end(), m) == all.end())
        c.Fail("record", "unknown metric '" + m + "'");
    }
    ReadBands(c, &rc);
    rc.orderings = ReadOrderings(c);
    c.Finish();
    // The scenario must load with the overrides: a bad key fails here, before anything runs.
    // (A generated scenario is checked when `regress` generates it, before anything runs.)
    std::vector<Override> overrides;
    try {
      for (const std::string& s : rc.sets) overrides.push_back(ParseOverride(s));
      if (!rc.IsGenerator()) LoadScenario(rc.scenario, overrides);
    } catch (const ConfigError& e) {
      throw ConfigError(file.string() + ": case '" + rc.name + "': " + e.what());
    }
    suite.cases.push_back(std::move(rc));
  }
  suite.orderings = ReadOrderings(root);
  root.Finish();
  // Orderings may only name cases and modes that exist.
  const auto check_ref = [&](const eval::MetricRef& r, const RegressionCase* own,
                             const std::string& where) {
    const RegressionCase* c = own;
    if (!r.case_name.empty()) {
      c = nullptr;
      for (const auto& x : suite.cases)
        if (x.name == r.case_name) c = &x;
      if (!c)
        throw ConfigError(file.string() + ": key '" + where + "' names unknown case '" +
                          r.case_name + "'");
    }
    if (!c)
      throw ConfigError(file.string() + ": key '" + where + "': '" + r.ToString() +
                        "' needs a case (case:mode.metric) outside a case");
    if (std::find(c->modes.begin(), c->modes.end(), r.mode) == c->modes.end())
      throw ConfigError(file.string() + ": key '" + where + "': case '" + c->name +
                        "' does not run mode '" + r.mode + "'");
  };
  for (std::size_t i = 0; i < suite.cases.size(); ++i)
    for (const auto& o : suite.cases[i].orderings) {
      const std::string where = "cases[" + std::to_string(i) + "].orderings";
      check_ref(o.lhs, &suite.cases[i], where);
      check_ref(o.rhs, &suite.cases[i], where);
    }
  for (const auto& o : suite.orderings) {
    check_ref(o.lhs, nullptr, "orderings");
    check_ref(o.rhs, nullptr, "orderings");
  }
  return suite;
}

std::string SuiteToYaml(const RegressionSuite& suite, const std::filesystem::path& relative_to) {
  YAML::Emitter y;
  y.SetDoublePrecision(6);
  y << YAML::BeginMap << YAML::Key << "name" << YAML::Value << suite.name;
  y << YAML::Key << "cases" << YAML::Value << YAML::BeginSeq;
  for (const RegressionCase& c : suite.cases) {
    y << YAML::BeginMap;
    y << YAML::Key << "name" << YAML::Value << c.name;
    y << YAML::Key << "scenario" << YAML::Value
      << (c.IsGenerator() ? c.scenario.string()
                          : std::filesystem::relative(c.scenario, relative_to).string());
    if (!c.sets.empty()) y << YAML::Key << "set" << YAML::Value << YAML::Flow << c.sets;
    y << YAML::Key << "modes" << YAML::Value << YAML::Flow << c.modes;
    if (c.duration) y << YAML::Key << "duration" << YAML::Value << *c.duration;
    y << YAML::Key << "seeds" << YAML::Value << c.seeds;
    y << YAML::Key << "first_seed" << YAML::Value << c.first_seed;
    if (!c.digest.empty()) y << YAML::Key << "digest" << YAML::Value << c.digest;
    if (!c.record.empty()) y << YAML::Key << "record" << YAML::Value << YAML::Flow << c.record;
    if (!c.bands.empty()) {
      y << YAML::Key << "bands" << YAML::Value << YAML::BeginMap;
      for (const eval::Band& b : c.bands) {
        y << YAML::Key << b.metric.ToString() << YAML::Value << YAML::Flow << YAML::BeginMap;
        if (b.reference) {
          y << YAML::Key << "reference" << YAML::Value << *b.reference;
          y << YAML::Key << "tolerance" << YAML::Value << *b.tolerance;
        } else {
          if (b.min) y << YAML::Key << "min" << YAML::Value << *b.min;
          if (b.max) y << YAML::Key << "max" << YAML::Value << *b.max;
        }
        y << YAML::EndMap;
      }
      y << YAML::EndMap;
    }
    if (!c.orderings.empty()) {
      y << YAML::Key << "orderings" << YAML::Value << YAML::BeginSeq;
      for (const auto& o : c.orderings) y << o.text;
      y << YAML::EndSeq;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndSeq;
  if (!suite.orderings.empty()) {
    y << YAML::Key << "orderings" << YAML::Value << YAML::BeginSeq;
    for (const auto& o : suite.orderings) y << o.text;
    y << YAML::EndSeq;
  }
  y << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

}  // namespace dualgrid::scenario
