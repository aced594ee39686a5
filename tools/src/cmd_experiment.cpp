// `dualgrid experiment`: `dualgrid run` over several seeds (separate processes: libsumo holds one
// simulation per process), then the paper-style tables with 95 % confidence intervals.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iostream>
#include <thread>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "figures.hpp"
#include "output.hpp"
#include "progress.hpp"

extern char** environ;

namespace dualgrid::tools {
namespace {

// Starts `dualgrid run` for one seed with its output and log in `dir`.
pid_t StartRun(const ExperimentOptions& o, int seed, const std::filesystem::path& dir,
               bool figures) {
  std::filesystem::create_directories(dir);
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
  if (o.run.run.duration)
    args.insert(args.end(), {"--duration", std::to_string(*o.run.run.duration)});
  std::string modes;
  for (const auto& m : o.run.modes) modes += (modes.empty() ? "" : ",") + m;
  args.insert(args.end(), {"--modes", modes});
  if (!figures) args.push_back("--no-figures");
  if (!o.run.snapshots.empty()) {
    std::string times;
    for (double t : o.run.snapshots) times += (times.empty() ? "" : ",") + std::to_string(t);
    args.insert(args.end(), {"--snapshots", times});
  }
  if (o.run.write_detections) args.push_back("--write-detections");
  if (o.run.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.run.threads)});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string log = (dir / "log.txt").string();
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, o.executable.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + o.executable + ": " + std::strerror(rc));
  return pid;
}

std::string FirstLine(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

int RunExperiment(const ExperimentOptions& o) {
  if (o.seeds < 1) throw std::invalid_argument("--seeds must be >= 1");
  if (o.run.run.seed)
    throw std::invalid_argument(
        "experiment runs seeds --first-seed .. --first-seed + --seeds - 1; "
        "--seed is for single runs");
  ParseModes(o.run.modes);  // fail early on a bad mode
  scenario::ScenarioConfig config = LoadConfig(o.run.run);
  const auto& out = o.run.run.out;
  std::filesystem::create_directories(out / "figures");
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());

  // Run the seeds, `jobs` at a time; seed `first_seed` also draws its figures.
  Progress progress("experiment " + config.sim.name, o.seeds, !o.run.run.quiet);
  std::map<pid_t, int> running;
  std::vector<int> failed;
  int next = 0, done = 0;
  while (done < o.seeds) {
    while (next < o.seeds && static_cast<int>(running.size()) < jobs) {
      const int seed = o.first_seed + next++;
      const auto dir = out / "seeds" / ("seed_" + std::to_string(seed));
      running[StartRun(o, seed, dir, o.run.figures && seed == o.first_seed)] = seed;
    }
    int status = 0;
    const pid_t pid = wait(&status);
    if (pid < 0) throw std::runtime_error("lost track of the seed runs");
    const int seed = running.at(pid);
    running.erase(pid);
    ++done;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      failed.push_back(seed);
      std::cerr << "seed " << seed << " failed: "
                << FirstLine(out / "seeds" / ("seed_" + std::to_string(seed)) / "log.txt") << "\n";
    }
    progress.Update(done, std::to_string(done) + "/" + std::to_string(o.seeds) + " seeds");
  }
  progress.Finish();
  if (!failed.empty())
    throw std::runtime_error(std::to_string(failed.size()) + " of " + std::to_string(o.seeds) +
                             " seed runs failed (see " + (out / "seeds").string() + "/*/log.txt)");

  // Aggregate: per mode, the metrics of every seed; object ids mapped by vehicle name so that
  // per-object results line up across seeds.
  IdRegistry names;
  std::vector<eval::ModeRuns> runs;
  for (const auto& m : o.run.modes) runs.push_back({m, {}});
  double wall = 0.0;
  for (int k = 0; k < o.seeds; ++k) {
    const auto dir = out / "seeds" / ("seed_" + std::to_string(o.first_seed + k));
    nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "metrics.json"));
    wall += j.value("wall_s", 0.0);
    for (auto& r : runs) {
      eval::ScenarioMetrics m = j.at("modes").at(r.mode).get<eval::ScenarioMetrics>();
      for (auto& obj : m.objects)
        obj.id = names.Id(
            j.at("object_names").value(std::to_string(obj.id), "#" + std::to_string(obj.id)));
      r.seeds.push_back(std::move(m));
    }
  }
  const eval::ComparisonTable table = eval::MakeComparisonTable(config.sim.name, runs);
  OpenOutput(out / "table.md") << table.ToMarkdown();
  OpenOutput(out / "table.csv") << table.ToCsv();
  OpenOutput(out / "table.json") << table.ToJson().dump(2) << "\n";

  // Per-object tracked share over seeds (paper Fig. 6).
  std::map<int, std::vector<double>> rows;
  nlohmann::json per_object;
  for (std::size_t m = 0; m < runs.size(); ++m) {
    for (const auto& [id, s] : eval::PerObjectTrackedFraction(runs[m].seeds)) {
      rows.try_emplace(id, runs.size(), std::nan("")).first->second[m] = s.mean;
      per_object[names.Name(id)][runs[m].mode] = s;
    }
  }
  OpenOutput(out / "per_object.json") << per_object.dump(2) << "\n";
  TrackedShares shares;
  for (const auto& [id, r] : rows) shares.emplace_back(names.Name(id), r);
  if (o.run.figures)
    RenderTrackedShares(o.run.modes, shares,
                        config.sim.name + ": tracked share D per object, mean over " +
                            std::to_string(o.seeds) + " seeds",
                        out / "figures" / "tracked_share.png");
  // The first seed's pictures (grids, scene, weights) are the experiment's examples.
  const auto first = out / "seeds" / ("seed_" + std::to_string(o.first_seed)) / "figures";
  if (o.run.figures)
    for (const auto& e : std::filesystem::directory_iterator(first))
      if (e.path().filename() != "tracked_share.png")
        std::filesystem::copy_file(e.path(), out / "figures" / e.path().filename(),
                                   std::filesystem::copy_options::overwrite_existing);

  if (!o.run.run.quiet) {
    std::cout << table.ToMarkdown() << "\n"
              << o.seeds << " seeds (" << Fixed(wall, 0) << " s of runs); results in "
              << out.string() << "\n";
  }
  return 0;
}

}  // namespace dualgrid::tools
