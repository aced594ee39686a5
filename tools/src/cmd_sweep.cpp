// `dualgrid sweep`: a scenario (or the tangential generator) over a grid of key values and
// seeds, run locally (-j), or emitted as a run list / Slurm job array; `dualgrid collect` merges
// the finished runs into tidy and aggregated tables and metric-vs-value figures.
// docs/stress.md ("Sweeps").
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "cli_checks.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/read_results.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/scenario/sweep_spec.hpp"
#include "dualgrid/viz/charts.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

using scenario::ParseNumber;
using scenario::ParseSweepAxis;
using scenario::SweepAxis;
using scenario::SweepSettings;

namespace {

namespace fs = std::filesystem;
constexpr const char* kGenerator = "tangential";
constexpr const char* kMetrics[] = {"D", "D_v", "delta_x", "delta_v", "t_d"};

// The unit of a metric of the tables (docs/output.md).
std::string MetricUnit(const std::string& metric) {
  if (metric == "D" || metric == "D_v") return "%";
  if (metric == "delta_x") return "m";
  if (metric == "delta_v") return "m/s";
  return "s";
}

// The unit of a swept key, for the figures' x axis: the generator's options (docs/stress.md) and
// the scenario keys with a unit (docs/scenarios.md, FilterParams); "" for a key without one
// (a count, a name, a switch) or one not listed here.
std::string SweepKeyUnit(const std::string& key) {
  static const std::map<std::string, std::string> kUnits = {
      {"tangential.angle", "deg"},
      {"tangential.range", "m"},
      {"tangential.speed", "m/s"},
      {"tangential.ego_speed", "m/s"},
      {"tangential.interval", "s"},
      {"tangential.grid_width", "m"},
      {"tangential.first_distance", "m"},
      {"tangential.spacing", "m"},
      {"duration", "s"},
      {"step_length", "s"},
      {"filter.length_x", "m"},
      {"filter.width_y", "m"},
      {"filter.resolution", "m"},
      {"filter.ahead", "m"},
      {"filter.left", "m"},
      {"filter.realign_deg", "deg"},
      {"filter.process_noise_position", "m/sqrt(s)"},
      {"filter.process_noise_velocity", "m/s/sqrt(s)"},
      {"filter.birth_max_tangential_speed", "m/s"},
      {"filter.birth_sigma_radial", "m/s"},
      {"filter.max_speed", "m/s"},
      {"filter.sigma_f", "m"},
      {"filter.sigma_static_distance", "m"},
      {"filter.sigma_static_velocity", "m/s"},
      {"filter.sigma_v", "m/s"},
      {"filter.free_angle_bin", "rad"},
      {"filter.static_speed", "m/s"},
      {"ego.speed", "m/s"},
      {"ego.position", "m"},
  };
  const auto it = kUnits.find(key);
  return it == kUnits.end() ? "" : it->second;
}

// What a sweep figure draws (viz::RenderLineChart: lines through the means, error bars, no
// markers), for its caption.
std::string SweepCaption(int most_seeds) {
  std::string c =
      "Lines: the mean over the seeds of each setting, joined from setting to setting (a setting "
      "without a finished run is left out); colour: the filter's weight mode.";
  c += most_seeds > 1 ? " Error bars: 95 % confidence interval of the mean (Student t)."
                      : " No error bars: one seed per setting.";
  return c;
}

}  // namespace

// Sets one `tangential.KEY` option of the generator; throws std::invalid_argument.
void SetGeneratorOption(TangentialOptions* o, const std::string& key, const std::string& value) {
  const auto number = [&](double lo, double hi, bool lo_open) {
    double v = 0.0;
    if (!ParseNumber(value, &v) || (lo_open ? v <= lo : v < lo) || v > hi)
      throw std::invalid_argument("tangential." + key + ": expected a number in " +
                                  (lo_open ? "(" : "[") + Exact(lo) + ", " + Exact(hi) +
                                  "], got '" + value + "'");
    return v;
  };
  const auto one_of = [&](std::initializer_list<const char*> allowed) {
    std::string all;
    for (const char* a : allowed) {
      if (value == a) return value;
      all += (all.empty() ? "" : ", ") + std::string(a);
    }
    throw std::invalid_argument("tangential." + key + ": expected one of " + all + ", got '" +
                                value + "'");
  };
  if (key == "kind")
    o->kind = one_of({"crossing", "parallel", "aspect"});
  else if (key == "sensor")
    o->sensor = one_of({"front", "front_left", "front_right", "rear_left", "rear_right"});
  else if (key == "target")
    o->target = one_of({"car", "truck", "cyclist"});
  else if (key == "angle")
    o->angle = number(0.0, 180.0, false);
  else if (key == "range")
    o->range = number(1.0, 200.0, false);
  else if (key == "speed")
    o->speed = number(0.0, 40.0, true);
  else if (key == "ego_speed")
    o->ego_speed = number(0.0, 40.0, false);
  else if (key == "count")
    o->count = static_cast<int>(number(1.0, 12.0, false));
  else if (key == "interval")
    o->interval = number(1.0, 60.0, false);
  else if (key == "grid_width")
    o->grid_width = number(5.0, 400.0, false);
  else if (key == "first_distance")
    o->first_distance = number(10.0, 600.0, false);
  else if (key == "spacing")
    o->spacing = number(0.0, 600.0, true);
  else if (key == "seed")
    o->seed = static_cast<std::uint64_t>(number(0.0, 9007199254740991.0, false));
  else
    throw std::invalid_argument(
        "tangential." + key +
        ": unknown generator option (expected kind, sensor, target, angle, range, speed, "
        "ego_speed, count, interval, grid_width, first_distance, spacing, seed)");
}

namespace {

std::string SettingLabel(const std::vector<SweepAxis>& axes, const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < axes.size(); ++i)
    s += (s.empty() ? "" : ", ") + axes[i].key + "=" + v[i];
  return s;
}

std::string CsvCell(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string ShellQuote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

}  // namespace

namespace {

// The axes of --set, checked: no key twice, generator keys only for the generator, and the
// product of settings (and runs) within bounds, counted before anything is built.
std::vector<SweepAxis> SweepAxes(const SweepOptions& o) {
  std::vector<SweepAxis> axes;
  for (const auto& s : o.sets) {
    SweepAxis a = ParseSweepAxis(s);
    for (const auto& b : axes)
      if (b.key == a.key) throw std::invalid_argument("--set " + s + ": key given twice");
    axes.push_back(std::move(a));
  }
  const bool generator = o.scenario == kGenerator;
  if (!generator && !fs::is_regular_file(o.scenario))
    throw std::invalid_argument("scenario '" + o.scenario + "' not found (a file, or '" +
                                kGenerator + "' to sweep the stress-case generator)");
  for (const auto& a : axes)
    if (!generator && a.key.rfind("tangential.", 0) == 0)
      throw std::invalid_argument("--set " + a.key + ": generator keys need the scenario '" +
                                  std::string(kGenerator) + "'");
  // A product of a million settings is refused at once, not after minutes of validation (or an
  // allocation failure).
  std::size_t count = 1;
  std::string shape;
  for (const auto& a : axes) {
    count = count > kMaxSweepSettings ? count : count * a.values.size();
    shape += (shape.empty() ? "" : " x ") + std::to_string(a.values.size());
  }
  if (count > kMaxSweepSettings)
    throw std::invalid_argument("--set: " + shape + " values make more than " +
                                std::to_string(kMaxSweepSettings) +
                                " settings, expected at most that many (split the study into "
                                "several sweeps)");
  if (count * static_cast<std::size_t>(o.seeds) > kMaxSweepRuns)
    throw std::invalid_argument("--set, --seeds: " + std::to_string(count) + " settings x " +
                                std::to_string(o.seeds) + " seeds, expected at most " +
                                std::to_string(kMaxSweepRuns) + " runs");
  return axes;
}

// The plan without settings and runs; the folder `out` made ready for it. Resumable: an earlier
// sweep folder is kept (its finished runs are skipped), but only if it was a sweep of this plan.
SweepPlan OpenSweep(const SweepOptions& o, const std::vector<SweepAxis>& axes,
                    const fs::path& out) {
  SweepPlan plan;
  plan.scenario =
      o.scenario == kGenerator ? std::string(kGenerator) : fs::absolute(o.scenario).string();
  for (const auto& a : axes) plan.axes.push_back({a.key, a.values});
  plan.seeds = o.seeds;
  plan.first_seed = o.first_seed;
  plan.modes = o.modes;
  plan.duration = o.duration;
  if (o.scenario != kGenerator) {
    outputs::InputSet inputs;
    inputs.Add(o.scenario, "scenario");
    outputs::CheckOutputApart(out, inputs);
  }
  const fs::path plan_file = out / "plan.json";
  if (!fs::exists(plan_file) || o.force) {
    PrepareOutputFolder(out, {.force = o.force});
    return plan;
  }
  SweepPlan old;
  try {
    old = ReadSweepPlan(plan_file);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(
        std::string(e.what()) +
        " (an earlier sweep's plan; use a new --out, or --force to replace it)");
  }
  if (SweepPlanIdentity(old) != SweepPlanIdentity(plan))
    throw std::invalid_argument(out.string() +
                                " holds a sweep of another plan (plan.json differs); use a new "
                                "--out, or --force to replace it");
  return plan;
}

// A run of the sweep: its command and its folder.
using SweepRun = std::pair<std::vector<std::string>, fs::path>;

// The `dualgrid run` command of one setting and seed.
std::vector<std::string> SweepRunArgs(const SweepOptions& o, const fs::path& scenario,
                                      const fs::path& folder, std::uint64_t seed,
                                      const std::vector<std::string>& sets) {
  std::vector<std::string> args = {o.executable,
                                   "run",
                                   scenario.string(),
                                   "--out",
                                   folder.string(),
                                   "--force",  // the sweep's own folder: a resumed run replaces it
                                   "--seed",
                                   std::to_string(seed),
                                   "-q",
                                   "--no-figures",
                                   "--threads",
                                   "1",
                                   "--network-dir",
                                   o.network_dir.string()};
  std::string modes;
  for (const auto& m : o.modes) modes += (modes.empty() ? "" : ",") + m;
  args.insert(args.end(), {"--modes", modes});
  if (o.duration) args.insert(args.end(), {"--duration", Exact(*o.duration)});
  for (const auto& s : sets) args.insert(args.end(), {"--set", s});
  return args;
}

// Setting `si` (id s001, ...): its scenario (generated or given, validated with its overrides),
// its entry in the plan, and a run per seed (appended to `runs` and to runs.txt's `list`).
void AddSetting(const SweepOptions& o, const std::vector<SweepAxis>& axes,
                const std::vector<std::string>& values, std::size_t si, const fs::path& out,
                SweepPlan* plan, std::vector<SweepRun>* runs, std::ostringstream* list) {
  const bool generator = o.scenario == kGenerator;
  char id[24];
  std::snprintf(id, sizeof id, "s%03zu", si + 1);
  const std::string label = SettingLabel(axes, values);
  const fs::path generated = fs::path("scenarios") / (std::string(id) + ".yaml");
  const fs::path scenario = generator ? out / generated : fs::absolute(o.scenario);
  std::vector<std::string> sets;
  TangentialOptions gen;
  gen.kind = "aspect";
  gen.quiet = true;
  gen.force = true;  // inside the sweep's own folder (a resumed sweep writes it again)
  for (std::size_t k = 0; k < axes.size(); ++k) {
    if (axes[k].key.rfind("tangential.", 0) == 0)
      SetGeneratorOption(&gen, axes[k].key.substr(11), values[k]);
    else
      sets.push_back(axes[k].key + "=" + values[k]);
  }
  try {
    if (generator) {
      gen.out = scenario;
      RunTangential(gen);
    }
    std::vector<scenario::Override> overrides;
    for (const auto& s : sets) overrides.push_back(scenario::ParseOverride(s));
    scenario::LoadScenario(scenario, overrides);
  } catch (const std::exception& e) {
    throw std::invalid_argument("setting " + std::string(id) + " (" + label + "): " + e.what());
  }
  // A generated scenario is named relative to the sweep folder: a copied folder uses its own.
  plan->settings.push_back({id, values, label, generator ? generated.string() : scenario.string()});
  for (int k = 0; k < o.seeds; ++k) {
    const std::uint64_t seed = o.first_seed + k;
    const fs::path folder = RunFolder(out, id, seed);
    std::vector<std::string> args = SweepRunArgs(o, scenario, folder, seed, sets);
    std::string line;
    for (const auto& a : args) {
      if (!line.empty()) line += ' ';
      line += ShellQuote(a);
    }
    *list << line << " > " << ShellQuote(folder.string() + ".log") << " 2>&1\n";
    plan->runs.push_back({id, seed});
    runs->emplace_back(std::move(args), folder);
  }
}

// slurm.sh: a Slurm job array, one task per line of runs.txt.
void WriteSlurm(const fs::path& out, std::size_t tasks) {
  std::ostringstream sh;
  sh << "#!/bin/bash\n# Slurm job array of the sweep in " << out.string()
     << ": one task per line of runs.txt (docs/stress.md).\n"
     << "#SBATCH --job-name=dualgrid-sweep\n#SBATCH --array=1-" << tasks << "\n"
     << "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n#SBATCH --mem=2G\n"
     << "#SBATCH --time=02:00:00\n#SBATCH --output=" << (out / "slurm").string()
     << "/task_%a.out\nexport OMP_NUM_THREADS=1\n"
     << "line=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" " << ShellQuote((out / "runs.txt").string())
     << ")\n[ -n \"$line\" ] || { echo \"no run $SLURM_ARRAY_TASK_ID\" >&2; exit 2; }\n"
     << "eval \"$line\"\n";
  fs::create_directories(out / "slurm");
  WriteTextFile(out / "slurm.sh", sh.str());
  std::cout << "wrote " << (out / "slurm.sh").string() << " (" << tasks
            << " tasks); submit: sbatch " << (out / "slurm.sh").string()
            << "; then: dualgrid collect " << out.string() << "\n";
}

// The runs not finished earlier, `o.jobs` at a time with one OpenMP thread each (processes x
// threads <= cores). Returns how many failed.
int RunLocally(const SweepOptions& o, const std::vector<SweepRun>& runs, std::size_t settings) {
  const CoreSplit split = SplitCores(o.jobs, 1, static_cast<int>(runs.size()));
  if (!o.quiet)
    std::cerr << "sweep: " << settings << " settings x " << o.seeds << " seeds = " << runs.size()
              << " runs, " << split.Describe() << "\n";
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (!ReadRunState(runs[i].second).complete) todo.push_back(i);
  if (!o.quiet && todo.size() < runs.size())
    std::cerr << "sweep: " << runs.size() - todo.size() << " runs finished earlier, skipped\n";
  Progress progress("sweep", static_cast<int>(todo.size()), !o.quiet);
  ChildPool pool(split.jobs, "the sweep's runs");
  std::size_t next = 0;
  int done = 0, failed = 0;
  while (true) {
    while (pool.Free() && next < todo.size()) {
      const auto& [args, folder] = runs[todo[next]];
      fs::create_directories(folder.parent_path());
      pool.Start(todo[next++], args, folder.string() + ".log");
    }
    const auto ended = pool.Wait();
    if (!ended) break;
    const std::size_t i = ended->tag;
    ++done;
    if (!ReadRunState(runs[i].second).complete) {
      ++failed;
      if (!StopSignal())
        std::cerr << "dualgrid: run " << runs[i].second.string()
                  << " failed: " << ChildFailure(*ended, runs[i].second.string() + ".log") << "\n";
    }
    progress.Update(done, std::to_string(done) + "/" + std::to_string(todo.size()) + " runs");
  }
  progress.Finish();
  return failed;
}

}  // namespace

int RunSweep(const SweepOptions& o) {
  if (o.sets.empty()) throw std::invalid_argument("--set: give at least one KEY=LIST to sweep");
  const std::vector<SweepAxis> axes = SweepAxes(o);
  const auto settings = SweepSettings(axes);
  const fs::path out = fs::absolute(o.out);
  SweepPlan plan = OpenSweep(o, axes, out);

  // Scenarios and run commands; every setting is validated before anything runs (a stop signal
  // ends the validation at once: nothing has run).
  std::ostringstream list;
  std::vector<SweepRun> runs;
  Progress checking("sweep: checking settings", static_cast<int>(settings.size()), !o.quiet);
  for (std::size_t si = 0; si < settings.size(); ++si) {
    if (StopSignal()) return StopExitCode();
    checking.Update(static_cast<int>(si));
    AddSetting(o, axes, settings[si], si, out, &plan, &runs, &list);
  }
  checking.Finish();
  // Every setting is valid: now the run folders' parents (logs sit beside the folders, and
  // runs.txt redirects into them).
  for (const auto& run : runs) fs::create_directories(run.second.parent_path());
  WriteTextFile(out / "plan.json", SweepPlanJson(plan).dump(2) + "\n");
  WriteTextFile(out / "runs.txt", list.str());
  if (o.emit == "slurm") {
    WriteSlurm(out, runs.size());
    return kExitOk;
  }
  if (o.emit == "list") {
    std::cout << "wrote " << (out / "runs.txt").string() << " (" << runs.size()
              << " runs); e.g. parallel -j " << Cores() << " < " << (out / "runs.txt").string()
              << "; then: dualgrid collect " << out.string() << "\n";
    return kExitOk;
  }
  const int failed = RunLocally(o, runs, settings.size());
  const int collected = RunCollect(CollectOptions{out, o.quiet, o.figure_captions});
  if (StopSignal()) return StopExitCode();
  return failed > 0 ? kExitSomeSeedsFailed : collected;
}

namespace {

// What collect read from the sweep's run folders.
struct Collected {
  std::string tidy;  // tidy.csv: setting x seed x mode x metric
  // (setting, mode, metric) -> one sample per seed
  std::map<std::tuple<std::string, std::string, std::string>, std::vector<double>> samples;
  std::map<std::string, std::string> unit_of;  // metric -> unit, as the tables say
  std::vector<std::string> missing;
  int complete = 0;
};

// A finished run's table.json with a value for every mode of the plan; throws
// std::invalid_argument naming the file otherwise (a damaged table is a missing run).
std::vector<TableMetric> ReadRunTable(const fs::path& folder, const SweepPlan& plan) {
  std::vector<TableMetric> table = ReadTableJson(folder / "table.json");
  for (const TableMetric& m : table)
    for (const std::string& mode : plan.modes)
      if (!m.modes.count(mode) && m.key != "t_d")
        throw std::invalid_argument((folder / "table.json").string() + ": metric '" + m.key +
                                    "' has no value for mode '" + mode +
                                    "', expected one (the plan runs it)");
  if (table.empty())
    throw std::invalid_argument((folder / "table.json").string() +
                                ": key 'metrics': expected at least one metric");
  return table;
}

Collected CollectRuns(const SweepPlan& plan, const fs::path& out,
                      const std::map<std::string, const SweepPlan::Setting*>& setting_of) {
  Collected c;
  std::ostringstream tidy;
  tidy << "setting";
  for (const auto& a : plan.axes) tidy << "," << CsvCell(a.key);
  tidy << ",seed,mode,metric,unit,value\n";
  for (const auto& r : plan.runs) {
    const fs::path folder = RunFolder(out, r.setting, r.seed);
    const RunState state = ReadRunState(folder);
    if (!state.complete) {
      const std::string log = LastLine(folder.string() + ".log");
      c.missing.push_back(folder.string() + ": " +
                          (state.why == "not run" && !log.empty() ? log : state.why));
      continue;
    }
    // A run counts as complete only once its table is read.
    std::vector<TableMetric> table;
    try {
      table = ReadRunTable(folder, plan);
    } catch (const std::invalid_argument& e) {
      c.missing.push_back(e.what());
      continue;
    }
    ++c.complete;
    const auto& values = setting_of.at(r.setting)->values;
    for (const TableMetric& m : table) {
      c.unit_of[m.key] = m.unit.empty() ? MetricUnit(m.key) : m.unit;
      for (const auto& [mode, v] : m.modes) {
        tidy << r.setting;
        for (const auto& val : values) tidy << "," << CsvCell(val);
        tidy << "," << r.seed << "," << CsvCell(mode) << "," << CsvCell(m.key) << ","
             << CsvCell(c.unit_of[m.key]) << "," << Exact(v.mean) << "\n";
        c.samples[{r.setting, mode, m.key}].push_back(v.mean);
      }
    }
  }
  c.tidy = tidy.str();
  return c;
}

// aggregate.csv (mean and 95 % CI over the seeds per setting, mode and metric); returns the same
// rows for sweep.json.
nlohmann::json WriteAggregate(const SweepPlan& plan, const Collected& c, const fs::path& out,
                              const std::map<std::string, const SweepPlan::Setting*>& setting_of) {
  std::ostringstream agg;
  agg << "setting";
  for (const auto& a : plan.axes) agg << "," << CsvCell(a.key);
  agg << ",mode,metric,unit,n,mean,ci95_half_width\n";
  nlohmann::json aj = nlohmann::json::array();
  for (const auto& [key, xs] : c.samples) {
    const auto& [sid, mode, metric] = key;
    const eval::Summary s = eval::Summarize(xs);
    const auto& values = setting_of.at(sid)->values;
    const std::string& unit = c.unit_of.at(metric);
    agg << sid;
    for (const auto& val : values) agg << "," << CsvCell(val);
    agg << "," << CsvCell(mode) << "," << CsvCell(metric) << "," << CsvCell(unit) << "," << s.n
        << "," << Exact(s.mean) << "," << (s.half_width ? Exact(*s.half_width) : "") << "\n";
    aj.push_back({{"setting", sid},
                  {"values", values},
                  {"mode", mode},
                  {"metric", metric},
                  {"unit", unit},
                  {"n", s.n},
                  {"mean", s.mean},
                  {"ci95_half_width", s.half_width ? nlohmann::json(*s.half_width) : nullptr}});
  }
  WriteTextFile(out / "aggregate.csv", agg.str());
  return aj;
}

// The first axis with several values, all numbers: the figures' x axis; -1 when none is.
int FirstNumericAxis(const std::vector<SweepPlan::Axis>& axes) {
  for (std::size_t i = 0; i < axes.size(); ++i) {
    bool numeric = axes[i].values.size() > 1;
    for (const auto& v : axes[i].values) {
      double d;
      numeric = numeric && ParseNumber(v, &d);
    }
    if (numeric) return static_cast<int>(i);
  }
  return -1;
}

// One chart of `metric` against axis `xaxis` over the settings `ids`, a line per mode (mean)
// with 95 % CI error bars; no series when no setting has the metric.
viz::LineChart SweepChart(const SweepPlan& plan, const Collected& c, const char* metric, int xaxis,
                          const std::vector<std::string>& ids,
                          const std::map<std::string, const SweepPlan::Setting*>& setting_of,
                          int* most_seeds) {
  viz::LineChart chart;
  const std::string& key = plan.axes[xaxis].key;
  const std::string x_unit = SweepKeyUnit(key);
  chart.x_label = key + (x_unit.empty() ? "" : " [" + x_unit + "]");
  chart.y_label = std::string(metric) + " [" + MetricUnit(metric) + "]";
  for (const char* mode : {"position", "velocity", "dual"}) {
    viz::LineSeries mean;
    mean.name = mode;
    for (const auto& sid : ids) {
      const auto it = c.samples.find({sid, mode, metric});
      if (it == c.samples.end()) continue;
      const eval::Summary s = eval::Summarize(it->second);
      *most_seeds = std::max(*most_seeds, static_cast<int>(s.n));
      mean.x.push_back(std::stod(setting_of.at(sid)->values[xaxis]));
      mean.y.push_back(s.mean);
      mean.errors.push_back(s.half_width.value_or(std::nan("")));
    }
    if (!mean.x.empty()) chart.series.push_back(std::move(mean));
  }
  return chart;
}

// Figures: each metric against axis `xaxis`, one figure per combination of the other axes.
void DrawSweepFigures(const CollectOptions& o, const SweepPlan& plan, const Collected& c, int xaxis,
                      const fs::path& out,
                      const std::map<std::string, const SweepPlan::Setting*>& setting_of,
                      std::vector<std::string>* warnings) {
  fs::create_directories(out / "figures");
  const auto& axes = plan.axes;
  // Group settings by the values of the other axes; the same label for a title: spaced, so that
  // a long one wraps between the pairs.
  std::map<std::string, std::vector<std::string>> groups;  // label of others -> setting ids
  std::map<std::string, std::string> titles;
  for (const auto& s : plan.settings) {
    std::string others, title;
    for (std::size_t i = 0; i < axes.size(); ++i)
      if (static_cast<int>(i) != xaxis && axes[i].values.size() > 1) {
        others += (others.empty() ? "" : "_") + axes[i].key + "=" + s.values[i];
        title += (title.empty() ? "" : ", ") + axes[i].key + " = " + s.values[i];
      }
    groups[others].push_back(s.id);
    titles[others] = title;
  }
  const std::string& xkey = axes[xaxis].key;
  for (const char* metric : kMetrics) {
    for (const auto& [others, ids] : groups) {
      int most_seeds = 0;
      viz::LineChart chart = SweepChart(plan, c, metric, xaxis, ids, setting_of, &most_seeds);
      if (chart.series.empty()) continue;
      chart.title = std::string(metric) + " vs " + xkey +
                    (others.empty() ? "" : " (" + titles.at(others) + ")");
      if (o.figure_captions) chart.caption = SweepCaption(most_seeds);
      std::string name =
          std::string(metric) + "_vs_" + xkey + (others.empty() ? "" : "__" + others);
      for (char& ch : name)
        if (ch == '/' || ch == ' ' || ch == ',' || ch == '=') ch = ch == '=' ? '-' : '_';
      TryFigures(
          out / "figures" / (name + ".png"), kFigureFormats,
          [&](const auto& p) { viz::RenderLineChart(chart, p.string()); }, warnings);
    }
  }
}

}  // namespace

int RunCollect(const CollectOptions& o) {
  const fs::path out = fs::absolute(o.dir);
  if (!fs::exists(out / "plan.json"))
    throw std::invalid_argument(out.string() + ": no plan.json (not a sweep folder)");
  const SweepPlan plan = ReadSweepPlan(out / "plan.json");
  std::map<std::string, const SweepPlan::Setting*> setting_of;
  for (const auto& s : plan.settings) setting_of[s.id] = &s;
  const Collected c = CollectRuns(plan, out, setting_of);
  WriteTextFile(out / "tidy.csv", c.tidy);
  const nlohmann::json aj = WriteAggregate(plan, c, out, setting_of);
  const int total = static_cast<int>(plan.runs.size());
  nlohmann::json summary = {{"complete", c.complete == total},
                            {"runs", total},
                            {"runs_complete", c.complete},
                            {"missing", c.missing},
                            {"aggregate", aj}};
  WriteTextFile(out / "sweep.json", summary.dump(2) + "\n");

  // Figures are redrawn from the tables each time: earlier ones (other groupings) go first.
  std::vector<std::string> warnings;
  const int xaxis = FirstNumericAxis(plan.axes);
  fs::remove_all(out / "figures");
  if (xaxis >= 0) DrawSweepFigures(o, plan, c, xaxis, out, setting_of, &warnings);
  if (!o.quiet) {
    std::cerr << "collect: " << c.complete << " of " << total << " runs complete; tables in "
              << out.string() << " (tidy.csv, aggregate.csv, sweep.json)";
    if (xaxis >= 0) std::cerr << ", figures/";
    std::cerr << "\n";
    for (const auto& m : c.missing) std::cerr << "collect: missing " << m << "\n";
  }
  if (c.complete == total) return kExitOk;
  // Said even under -q: a sweep with missing runs is not a result to use silently.
  std::cerr << "dualgrid: error: collect: " << total - c.complete << " of " << total
            << " runs missing or unreadable (the first: " << c.missing.front() << "); listed in "
            << (out / "sweep.json").string() << "\n";
  return kExitSomeSeedsFailed;
}

Command AddSweepCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<SweepOptions>();
  o->network_dir = ctx.network_dir;
  o->executable = ctx.executable;
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a scenario (or the tangential generator) over a grid of key values and seeds: "
      "locally, or as a run list / Slurm job array (docs/stress.md)");
  cmd->add_option("scenario", o->scenario,
                  "Scenario file, or 'tangential' to sweep the stress-case generator "
                  "(keys tangential.angle, tangential.sensor, ...)")
      ->required();
  cmd->add_option("--out,-o", o->out, "Sweep folder (resumable: finished runs are kept)")
      ->required()
      ->check(NonEmptyPath());
  cmd->add_option("--set", o->sets,
                  "KEY=LIST to sweep (repeatable): values a,b,c and/or ranges first:step:last, "
                  "e.g. filter.sigma_v=0.5,1,2 or tangential.angle=0:15:90")
      ->required();
  Opt(cmd, "--seeds", &o->seeds, "Seeds per setting")->check(WholeNumber(1, kMaxSeeds));
  Opt(cmd, "--first-seed", &o->first_seed, "First seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  cmd->add_option("--modes", o->modes, "Weight modes (default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"position", "velocity", "dual"}));
  cmd->add_option("--duration", o->duration, "Simulated time per run [s]")
      ->check(Number(0.0, kMaxDuration, true));
  cmd->add_option("--jobs,-j", o->jobs, "Runs at a time (default: one per core, 1 thread each)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));
  cmd->add_option("--emit", o->emit,
                  "Do not run: 'list' writes runs.txt (one shell command per run, e.g. for GNU "
                  "parallel), 'slurm' also slurm.sh (a job array); then `dualgrid collect`")
      ->check(CLI::IsMember({"list", "slurm"}));
  Opt(cmd, "--network-dir", &o->network_dir, "Folder of the built networks")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress output");
  cmd->add_flag("--force", o->force,
                "Replace an earlier dualgrid output in --out (its own files only) instead of "
                "resuming it");
  AddCaptionOption(cmd, &o->figure_captions);
  return {cmd, [o] { return RunSweep(*o); }};
}

Command AddCollectCommand(CLI::App& app, const CliContext&) {
  auto o = std::make_shared<CollectOptions>();
  auto* cmd = app.add_subcommand(
      "collect", "Merge the finished runs of a sweep folder into tables and figures");
  cmd->add_option("dir", o->dir, "Sweep folder")->required()->check(CLI::ExistingDirectory);
  cmd->add_flag("--quiet,-q", o->quiet, "No summary output");
  AddCaptionOption(cmd, &o->figure_captions);
  return {cmd, [o] { return RunCollect(*o); }};
}

}  // namespace dualgrid::tools
