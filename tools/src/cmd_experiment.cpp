// `dualgrid experiment`: `dualgrid run` over several seeds (separate processes: libsumo holds one
// simulation per process), then the paper-style tables with 95 % confidence intervals.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "cli_checks.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/read_back.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "exit_codes.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {
namespace {

// Starts `dualgrid run` for one seed with its output and log in `dir`.
// A seed run's output log: seeds/seed_N.log beside its folder seeds/seed_N/.
std::filesystem::path LogPath(const std::filesystem::path& seed_dir) {
  return seed_dir.parent_path() / (seed_dir.filename().string() + ".log");
}

std::vector<std::string> RunArgs(const ExperimentOptions& o, std::uint64_t seed,
                                 const std::filesystem::path& dir, bool figures, int threads) {
  std::vector<std::string> args = {o.executable,
                                   "run",
                                   o.run.run.scenario.string(),
                                   "--out",
                                   dir.string(),
                                   "--seed",
                                   std::to_string(seed),
                                   "--quiet",
                                   "--network-dir",
                                   o.run.run.network_dir.string()};
  if (o.run.run.duration) args.insert(args.end(), {"--duration", Exact(*o.run.run.duration)});
  if (o.run.run.begin) args.insert(args.end(), {"--begin", Exact(*o.run.run.begin)});
  for (const std::string& set : o.run.run.sets) args.insert(args.end(), {"--set", set});
  std::string modes;
  for (const auto& m : o.run.modes) modes += (modes.empty() ? "" : ",") + m;
  args.insert(args.end(), {"--modes", modes});
  if (!figures) args.push_back("--no-figures");
  if (!o.run.folder.snapshots.empty()) {
    std::string times;
    for (double t : o.run.folder.snapshots) times += (times.empty() ? "" : ",") + Exact(t);
    args.insert(args.end(), {"--snapshots", times});
  }
  args.insert(args.end(), {"--detections", o.run.folder.detections});
  std::string formats;
  for (const auto& f : o.run.folder.figure_formats) formats += (formats.empty() ? "" : ",") + f;
  if (figures) args.insert(args.end(), {"--figure-formats", formats});
  if (figures && !o.run.folder.figure_captions)
    args.insert(args.end(), {"--figure-captions", "off"});
  if (o.run.folder.write_particles) args.push_back("--write-particles");
  if (o.run.folder.check_invariants) args.push_back("--check-invariants");
  args.insert(args.end(), {"--threads", std::to_string(threads)});
  return args;
}

}  // namespace

namespace {

std::filesystem::path SeedDir(const std::filesystem::path& out, std::uint64_t seed) {
  return out / "seeds" / ("seed_" + std::to_string(seed));
}

// What became of the seed runs.
struct SeedRuns {
  std::vector<std::uint64_t> finished;
  std::vector<std::pair<std::uint64_t, std::string>> failed;  // seed, its error
  // A seed run that refused its input (exit code 2): every seed has the same input, so no more
  // are started, and if none finished the experiment reports that one error as its own.
  std::string bad_input;
  std::vector<std::uint64_t> cut_short;  // stopped by a signal: partial, not aggregated
};

// Runs the seeds, `split.jobs` at a time; seed `first_seed` also draws its figures.
SeedRuns RunSeeds(const ExperimentOptions& o, const CoreSplit& split, const std::string& name) {
  const auto& out = o.run.run.out;
  Progress progress("experiment " + name, o.seeds, !o.run.run.quiet);
  ChildPool pool(split.jobs, "the seed runs");
  SeedRuns s;
  int next = 0, done = 0;
  while (true) {
    while (pool.Free() && next < o.seeds && s.bad_input.empty()) {
      const std::uint64_t seed = o.first_seed + next++;
      const auto dir = SeedDir(out, seed);
      std::filesystem::create_directories(dir.parent_path());
      // The log beside the run folder, which the run itself prepares (docs/output.md).
      pool.Start(seed,
                 RunArgs(o, seed, dir, o.run.folder.figures && seed == o.first_seed, split.threads),
                 LogPath(dir));
    }
    const auto ended = pool.Wait();
    if (!ended) break;  // all done, or stopped before every seed was started
    const std::uint64_t seed = ended->tag;
    ++done;
    const int code = ended->code;
    if (code == 0 && RunComplete(SeedDir(out, seed))) {
      s.finished.push_back(seed);
    } else if (StopSignal() && (code == 130 || code == 143)) {
      s.cut_short.push_back(seed);
    } else {
      // Its stderr as the pool read it: the log may not have been writable (a full disk).
      const std::string why = ChildFailure(*ended, LogPath(SeedDir(out, seed)));
      s.failed.emplace_back(seed, why);
      if (code == kExitBadInput && !ended->signal) {
        if (s.bad_input.empty()) s.bad_input = why;
      } else {
        std::cerr << "dualgrid: seed " << seed << " failed: " << why << "\n";
      }
    }
    progress.Update(done, std::to_string(done) + "/" + std::to_string(o.seeds) + " seeds");
  }
  progress.Finish();
  std::sort(s.finished.begin(), s.finished.end());
  return s;
}

// The table's status after a stop signal ("" without one).
std::string StopStatus(const ExperimentOptions& o, const SeedRuns& s) {
  if (!StopSignal()) return "";
  std::string list;
  for (auto seed : s.cut_short) list += (list.empty() ? "" : ", ") + std::to_string(seed);
  return "Incomplete experiment: stopped by signal " + std::to_string(StopSignal()) + "; " +
         std::to_string(s.finished.size()) + " of " + std::to_string(o.seeds) + " seeds finished" +
         (list.empty() ? "" : "; cut short: " + list) + "; never started: " +
         std::to_string(o.seeds -
                        static_cast<int>(s.finished.size() + s.cut_short.size() + s.failed.size()));
}

// A finished seed's results, read back.
struct SeedResult {
  std::uint64_t seed;
  nlohmann::json metrics;
  double wall_s;
  std::string end;
  double ended_s;
};

// Every finished seed's results; a seed whose files cannot be read becomes a failed seed.
std::vector<SeedResult> ReadSeeds(const ExperimentOptions& o, SeedRuns* s) {
  std::vector<SeedResult> results;
  for (const std::uint64_t seed : s->finished) {
    const auto dir = SeedDir(o.run.run.out, seed);
    try {
      const JsonFile metrics = ReadJsonFile(dir / "metrics.json", "run metrics");
      const JsonFile run_summary = ReadJsonFile(dir / "summary.json", "run summary");
      const JsonAt rs = run_summary.Root();
      SeedResult r{seed, metrics.doc(), 0.0, "", 0.0};
      if (const auto w = rs.Find("wall_s")) r.wall_s = w->Number(0.0);
      if (const auto e = rs.Find("end")) r.end = e->Text();
      if (const auto e = rs.Find("ended_s")) r.ended_s = e->Number();
      const JsonAt modes = metrics.Root()["modes"];
      for (const auto& mode : o.run.modes) {
        const JsonAt m = modes[mode];
        try {
          (void)m.raw().get<eval::ScenarioMetrics>();
        } catch (const nlohmann::json::exception&) {
          m.Fail("the metrics of a dualgrid run (docs/output.md)");
        }
      }
      if (!metrics.Root()["object_names"].raw().is_object())
        metrics.Root()["object_names"].Fail("an object");
      results.push_back(std::move(r));
    } catch (const std::invalid_argument& e) {
      s->failed.emplace_back(seed, e.what());
      std::cerr << "dualgrid: seed " << seed << " failed: " << e.what() << "\n";
    }
  }
  s->finished.clear();
  for (const auto& r : results) s->finished.push_back(r.seed);
  return results;
}

// Per mode, the metrics of every seed; object ids mapped by vehicle name (into `names`) so that
// per-object results line up across seeds.
struct Aggregate {
  cosim::IdRegistry names;
  std::vector<eval::ModeRuns> runs;
  double wall = 0.0;
  std::vector<std::string> ended_early;  // seeds whose ego left the network before the duration
};

Aggregate AggregateSeeds(const ExperimentOptions& o, const std::vector<SeedResult>& results) {
  Aggregate a;
  for (const auto& m : o.run.modes) a.runs.push_back({m, {}});
  for (const SeedResult& result : results) {
    const nlohmann::json& j = result.metrics;
    a.wall += result.wall_s;
    if (result.end == "ego_left")
      a.ended_early.push_back("seed " + std::to_string(result.seed) +
                              " at t = " + FormatFixed(result.ended_s, 2) + " s");
    for (auto& r : a.runs) {
      eval::ScenarioMetrics m = j.at("modes").at(r.mode).get<eval::ScenarioMetrics>();
      // (checked by ReadSeeds: "modes" holds every mode's metrics, "object_names" is an object)
      const nlohmann::json& object_names = j.at("object_names");
      for (auto& obj : m.objects) {
        std::string key = std::to_string(obj.id);
        const auto it = object_names.find(key);
        obj.id = a.names.Id(it != object_names.end() && it->is_string() ? it->get<std::string>()
                                                                        : key.insert(0, 1, '#'));
      }
      r.seeds.push_back(std::move(m));
    }
  }
  return a;
}

// table.md|csv|json with the failed seeds and early ends as notes; returns the table.
eval::ComparisonTable WriteExperimentTables(const std::string& name, const Aggregate& a,
                                            const SeedRuns& s, const std::string& stop_status,
                                            const std::filesystem::path& out) {
  eval::ComparisonTable table = eval::MakeComparisonTable(name, a.runs);
  table.SetStatus(stop_status);
  for (const auto& [seed, why] : s.failed)
    table.AddNote("Seed " + std::to_string(seed) + " failed and is not in the table: " + why);
  if (!a.ended_early.empty()) {
    std::string list;
    for (const std::string& e : a.ended_early) list += (list.empty() ? "" : ", ") + e;
    table.AddNote(
        "The ego left the network before the duration (its route ended; the run's "
        "results cover its time in the network): " +
        list);
  }
  WriteTables(table, out);
  return table;
}

// Per-object tracked share over seeds (paper Fig. 6), D and D_v: per_object.json and the two
// figures; the first seed's pictures are copied as the experiment's examples.
void WritePerObject(const ExperimentOptions& o, const std::string& name, const Aggregate& a,
                    std::size_t seeds, std::vector<std::string>* warnings) {
  const auto& out = o.run.run.out;
  std::map<int, std::vector<double>> rows[2];  // [velocity_aware][object] -> per mode
  std::map<int, std::vector<double>> half[2];  // the same for the 95 % CI half-widths
  nlohmann::json per_object;
  for (const bool v : {false, true})
    for (std::size_t m = 0; m < a.runs.size(); ++m)
      for (const auto& [id, s] : eval::PerObjectTrackedFraction(a.runs[m].seeds, v)) {
        rows[v].try_emplace(id, a.runs.size(), std::nan("")).first->second[m] = s.mean;
        half[v].try_emplace(id, a.runs.size(), std::nan("")).first->second[m] =
            s.half_width.value_or(std::nan(""));
        per_object[a.names.Name(id)][a.runs[m].mode][v ? "D_v" : "D"] = s;
      }
  WriteTextFile(out / "per_object.json", per_object.dump(2) + "\n");
  if (!o.run.folder.figures || StopSignal()) return;
  for (const bool v : {false, true}) {
    TrackedShares shares, errors;
    for (const auto& [id, r] : rows[v]) shares.emplace_back(a.names.Name(id), r);
    for (const auto& [id, r] : half[v]) errors.emplace_back(a.names.Name(id), r);
    const auto png = out / "figures" / (v ? "tracked_share_v.png" : "tracked_share.png");
    const std::string what = v ? "D_v (tracked with the right velocity)" : "D";
    TryFigures(
        png, o.run.folder.figure_formats,
        [&](const auto& p) {
          RenderTrackedShares(
              o.run.modes, shares,
              name + ": " + (v ? "D_v" : "D") + " per object, mean and 95 % CI over " +
                  std::to_string(seeds) + " seeds",
              "tracked share " + what + " [%]", p, errors, o.run.folder.figure_captions);
        },
        warnings);
  }
  // The first seed's pictures (grids, scene, weights) are the experiment's examples.
  const auto first = SeedDir(out, o.first_seed) / "figures";
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(first, ec))
    if (e.path().filename().string().rfind("tracked_share", 0) != 0)
      std::filesystem::copy_file(e.path(), out / "figures" / e.path().filename(),
                                 std::filesystem::copy_options::overwrite_existing);
}

// Checks the options and the scenario before anything is written; returns the configuration.
scenario::ScenarioConfig CheckExperiment(const ExperimentOptions& o) {
  if (o.run.run.seed)
    throw std::invalid_argument(
        "experiment runs seeds --first-seed .. --first-seed + --seeds - 1; "
        "--seed is for single runs");
  if (o.first_seed > kMaxSeed - static_cast<std::uint64_t>(o.seeds - 1))
    throw std::invalid_argument("--first-seed + --seeds - 1 must be <= " +
                                std::to_string(kMaxSeed));
  ParseModes(o.run.modes);  // fail early on a bad mode
  scenario::ScenarioConfig config = LoadConfig(o.run.run);
  cosim::CheckFilterMemory(config, o.run.modes.size());
  DetectionPath(o.run.run.out, o.run.folder.detections);  // fail early on a bad format
  return config;
}

}  // namespace

int RunExperiment(const ExperimentOptions& o) {
  const scenario::ScenarioConfig config = CheckExperiment(o);
  const auto& out = o.run.run.out;
  outputs::InputSet inputs;
  inputs.AddScenario(config, o.run.run.network_dir);
  outputs::CheckOutputApart(out, inputs);
  PrepareOutputFolder(out, {.force = o.run.run.force});
  std::filesystem::create_directories(out / "figures");
  const CoreSplit split = SplitCores(o.jobs, o.run.threads, o.seeds);
  if (!o.run.run.quiet)
    std::cerr << "experiment: " << o.seeds << " seeds, " << split.Describe() << "\n";
  SeedRuns s = RunSeeds(o, split, config.sim.name);
  const std::string stop_status = StopStatus(o, s);
  if (!stop_status.empty()) {
    std::cerr << "dualgrid: " << stop_status << "\n";
    if (s.finished.empty()) return StopExitCode();
  }
  if (s.finished.empty() && !s.bad_input.empty()) throw std::invalid_argument(s.bad_input);
  if (!s.bad_input.empty())
    std::cerr << "dualgrid: a seed run refused its input: " << s.bad_input << "\n";
  const std::vector<SeedResult> results = ReadSeeds(o, &s);
  if (s.finished.empty())
    throw std::runtime_error("all " + std::to_string(o.seeds) +
                             " seed runs failed; the first: " + s.failed.front().second +
                             " (logs: " + (out / "seeds").string() + "/seed_*.log)");

  const Aggregate a = AggregateSeeds(o, results);
  const eval::ComparisonTable table =
      WriteExperimentTables(config.sim.name, a, s, stop_status, out);
  std::vector<std::string> warnings;
  WritePerObject(o, config.sim.name, a, s.finished.size(), &warnings);
  if (!o.run.run.quiet) std::cout << table.ToMarkdown() << "\n";
  nlohmann::json summary = {{"complete", s.failed.empty() && !StopSignal()},
                            {"status", stop_status},
                            {"seeds_cut_short", s.cut_short},
                            {"scenario", config.sim.name},
                            {"seeds_finished", s.finished},
                            {"wall_s_of_runs", a.wall},
                            {"warnings", warnings}};
  for (const auto& [seed, why] : s.failed)
    summary["seeds_failed"].push_back({{"seed", seed}, {"error", why}});
  SealOutputFolder(out);
  WriteTextFile(out / "summary.json", summary.dump(2) + "\n");
  if (!o.run.run.quiet)
    std::cout << s.finished.size() << " of " << o.seeds << " seeds (" << FormatFixed(a.wall, 0)
              << " s of runs); results in " << out.string() << "\n";
  if (StopSignal()) return StopExitCode();
  if (!s.failed.empty()) {
    std::string list;
    for (const auto& [seed, why] : s.failed)
      list += (list.empty() ? "" : ", ") + std::to_string(seed);
    std::cerr << "dualgrid: error: " << s.failed.size() << " of " << o.seeds
              << " seed runs failed (seeds " << list << "; logs in " << (out / "seeds").string()
              << "/seed_*.log); the table aggregates the other " << s.finished.size() << "\n";
    return kExitSomeSeedsFailed;
  }
  return kExitOk;
}

Command AddExperimentCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<ExperimentOptions>();
  auto no_figures = std::make_shared<bool>(false);
  o->run.run.network_dir = ctx.network_dir;
  o->executable = ctx.executable;
  auto* cmd = app.add_subcommand(
      "experiment",
      "`run` over seeds first-seed .. first-seed + seeds - 1 (separate processes) and aggregate "
      "the tables with 95 % confidence intervals");
  AddRunOptions(cmd, &o->run.run, "Experiment folder", false);
  AddFilterOptions(cmd, &o->run, no_figures.get());
  Opt(cmd, "--seeds", &o->seeds, "Number of seeds")->check(WholeNumber(1, kMaxSeeds));
  Opt(cmd, "--first-seed", &o->first_seed, "First seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  cmd->add_option("--jobs,-j", o->jobs,
                  "Seed runs at a time (default: one per core, each with one OpenMP thread)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));
  return {cmd, [o, no_figures] {
            o->run.folder.figures = !*no_figures;
            // Parallel runs share the cores: one OpenMP thread each unless told otherwise.
            const int jobs = o->jobs > 0 ? o->jobs : Cores();
            if (o->run.threads == 0 && jobs > 1) o->run.threads = 1;
            return RunExperiment(*o);
          }};
}

}  // namespace dualgrid::tools
