// The result files that dualgrid reads back from its own folders, each through the checked reader
// (read_back.hpp): a run's or experiment's table.json and summary.json, and a sweep's plan.json.
// Every function throws std::invalid_argument of one line naming the file, the key and what was
// expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/eval/regression.hpp"
#include "dualgrid/outputs/read_back.hpp"

namespace dualgrid::outputs {

/// One metric of a table.json, per mode; a mode whose mean is null (undefined in that run, e.g.
/// no detection time) is absent.
struct TableMetric {
  std::string key, unit;
  std::map<std::string, eval::MetricValue> modes;
};

/// The metrics of a table.json (`dualgrid run` or `experiment`), in the file's order.
std::vector<TableMetric> ReadTableJson(const std::filesystem::path& file);
std::vector<TableMetric> ParseTableJson(const JsonFile& doc);

/// What a run folder's summary.json says: finished ("complete": true) or why not.
struct RunState {
  bool complete = false;
  std::string why;  ///< "" when complete; "not run", the file's error or its "status" otherwise
};
RunState ReadRunState(const std::filesystem::path& run_dir);

/// A sweep's plan (plan.json, docs/stress.md "Sweeps"). Run folders are not stored as paths: a
/// run of setting S and seed K lives in SWEEP/runs/S/seed_K (RunFolder), so a copied or moved
/// sweep folder reads its own runs.
struct SweepPlan {
  struct Axis {
    std::string key;
    std::vector<std::string> values;
  };
  struct Setting {
    std::string id;  ///< "s001", ...
    std::vector<std::string> values;
    std::string label;
    std::string scenario;  ///< the scenario file (a generated one relative to the sweep folder)
  };
  struct Run {
    std::string setting;
    std::uint64_t seed = 0;
  };
  std::string scenario;  ///< the scenario given, or "tangential"
  std::vector<Axis> axes;
  int seeds = 1;
  std::uint64_t first_seed = 1;
  std::vector<std::string> modes;
  std::optional<double> duration;
  std::vector<Setting> settings;
  std::vector<Run> runs;
};

/// Most settings a sweep may have (each is validated before anything runs) and most runs
/// (settings x seeds).
inline constexpr std::size_t kMaxSweepSettings = 10000;
inline constexpr std::size_t kMaxSweepRuns = 100000;

nlohmann::json SweepPlanJson(const SweepPlan& plan);
/// The plan without its settings and runs: what must match for a sweep to resume in a folder.
nlohmann::json SweepPlanIdentity(const SweepPlan& plan);
SweepPlan ReadSweepPlan(const std::filesystem::path& file);
SweepPlan ParseSweepPlan(const JsonFile& doc);

/// SWEEP/runs/SETTING/seed_SEED.
std::filesystem::path RunFolder(const std::filesystem::path& sweep_dir, const std::string& setting,
                                std::uint64_t seed);

}  // namespace dualgrid::outputs
