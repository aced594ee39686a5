// `dualgrid regress SUITE.yaml`: runs each case of a regression suite as an experiment, checks
// its bands and orderings, and reports (table, JSON, JUnit XML). docs/regression.md.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_checks.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/csv_writers.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/read_results.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/scenario/suite.hpp"
#include "exit_codes.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

namespace {

namespace fs = std::filesystem;

// Files whose digests make a case's determinism fingerprint: what it measured, not how long it
// took (summary.json) or where (config.json holds paths).
constexpr const char* kDigestFiles[] = {"clusters.csv", "objects.csv", "table.csv"};

// mode.metric -> value, from an experiment's table.json.
std::map<std::string, eval::MetricValue> ReadTable(const std::filesystem::path& table) {
  std::map<std::string, eval::MetricValue> out;
  for (const TableMetric& m : ReadTableJson(table))
    for (const auto& [mode, v] : m.modes) out[mode + "." + m.key] = v;
  return out;
}

// FNV-1a 64 over "file=digest;" of the fingerprint files of the first seed's run folder.
std::string CaseDigest(const std::filesystem::path& seed_dir) {
  const JsonFile summary = ReadJsonFile(seed_dir / "summary.json", "run summary");
  const JsonAt digests = summary.Root()["digests"];
  std::uint64_t h = 1469598103934665603ull;
  for (const char* f : kDigestFiles) {
    const std::string part =
        std::string(f) + "=" + (digests.Has(f) ? digests[f].Text() : std::string("missing")) + ";";
    for (unsigned char c : part) {
      h ^= c;
      h *= 1099511628211ull;
    }
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

struct CaseResult {
  std::string name;
  bool ran = false;   // the experiment finished with every seed
  std::string error;  // why not
  double wall_s = 0.0;
  std::string digest;         // "" when it did not run
  std::string digest_status;  // "same", "changed", "not recorded", "—"
};

}  // namespace

namespace {

// The suite as it will run: command-line overrides after each case's own, generated scenarios
// written into OUT/scenarios; every case's scenario loaded once, so that a bad one stops the suite
// before anything runs.
void PrepareCases(const RegressOptions& o, scenario::RegressionSuite* suite) {
  for (auto& c : suite->cases) {
    c.sets.insert(c.sets.end(), o.sets.begin(), o.sets.end());
    if (c.IsGenerator()) {
      TangentialOptions gen;
      gen.kind = "aspect";
      gen.quiet = true;
      gen.force = true;  // inside this command's own output folder
      std::vector<std::string> rest;
      try {
        for (const std::string& s : c.sets) {
          if (s.rfind("tangential.", 0) != 0) {
            rest.push_back(s);
            continue;
          }
          const std::size_t eq = s.find('=');
          SetGeneratorOption(&gen, s.substr(11, eq - 11), s.substr(eq + 1));
        }
        gen.out = fs::absolute(o.out / "scenarios" / (c.name + ".yaml"));
        fs::create_directories(gen.out.parent_path());
        RunTangential(gen);
      } catch (const std::invalid_argument& e) {
        throw scenario::ConfigError(o.suite.string() + ": case '" + c.name + "': " + e.what());
      }
      c.scenario = gen.out;
      c.sets = rest;
    }
    std::vector<scenario::Override> overrides;
    for (const std::string& s : c.sets) overrides.push_back(scenario::ParseOverride(s));
    try {
      scenario::LoadScenario(c.scenario, overrides);
    } catch (const scenario::ConfigError& e) {
      throw scenario::ConfigError(o.suite.string() + ": case '" + c.name +
                                  "' with --set: " + e.what());
    }
  }
}

// Runs case `c` as an experiment into OUT/<case>; its table goes into `measured`.
CaseResult RunCase(const RegressOptions& o, const scenario::RegressionCase& c,
                   eval::Measured* measured) {
  CaseResult r;
  r.name = c.name;
  const auto t0 = std::chrono::steady_clock::now();
  ExperimentOptions e;
  e.run.run.scenario = c.scenario;
  e.run.run.out = o.out / c.name;
  e.run.run.network_dir = o.network_dir;
  e.run.run.sets = c.sets;
  e.run.run.duration = c.duration;
  e.run.run.quiet = true;
  e.run.modes = c.modes;
  e.run.folder.figures = false;
  e.seeds = c.seeds;
  e.first_seed = c.first_seed;
  e.jobs = o.jobs;
  e.executable = o.executable;
  // experiment splits the cores (SplitCores: processes x threads <= cores) per case.
  try {
    const int code = RunExperiment(e);
    r.ran = code == kExitOk;
    if (!r.ran) r.error = "experiment exited " + std::to_string(code) + " (see its folder)";
  } catch (const std::exception& ex) {
    r.error = ex.what();
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (r.ran) {
    try {
      (*measured)[c.name] = ReadTable(e.run.run.out / "table.json");
      r.digest = CaseDigest(e.run.run.out / "seeds" / ("seed_" + std::to_string(c.first_seed)));
      r.digest_status = c.digest.empty()       ? "not recorded"
                        : c.digest == r.digest ? "same"
                                               : "changed";
    } catch (const std::exception& ex) {
      r.ran = false;
      r.error = ex.what();
    }
  }
  if (!r.ran) r.digest_status = "—";
  return r;
}

// Every case in order until a stop signal, with the progress lines.
std::vector<CaseResult> RunCases(const RegressOptions& o, const scenario::RegressionSuite& suite,
                                 eval::Measured* measured) {
  std::vector<CaseResult> results;
  for (std::size_t i = 0; i < suite.cases.size() && !StopSignal(); ++i) {
    const auto& c = suite.cases[i];
    if (!o.quiet)
      std::cerr << "regress: case " << i + 1 << "/" << suite.cases.size() << " " << c.name << " ("
                << c.seeds << " seeds, " << SplitCores(o.jobs, 0, c.seeds).Describe() << ")\n";
    CaseResult r = RunCase(o, c, measured);
    // A case that did not run is an error, said even under -q (which only silences progress).
    if (!r.ran)
      std::cerr << "dualgrid: error: regress: case " << c.name << " did not run: " << r.error
                << "\n";
    else if (!o.quiet)
      std::cerr << "regress: case " << c.name << " done in " << static_cast<int>(r.wall_s)
                << " s\n";
    results.push_back(r);
  }
  return results;
}

// The suite's outcome: every check's verdict and the counts the reports and the exit code use.
struct Outcome {
  std::vector<eval::Verdict> verdicts;
  std::vector<CaseResult> results;
  int failed_checks = 0, failed_runs = 0, changed = 0;
  bool digest_fail = false, stopped = false;
};

Outcome Judge(const RegressOptions& o, const scenario::RegressionSuite& suite,
              std::vector<CaseResult> results, const eval::Measured& measured, bool stopped) {
  Outcome out;
  for (const auto& c : suite.cases) {
    auto v = eval::CheckCase(c.name, c.bands, c.orderings, measured);
    out.verdicts.insert(out.verdicts.end(), v.begin(), v.end());
  }
  auto v = eval::CheckCase("suite", {}, suite.orderings, measured);
  out.verdicts.insert(out.verdicts.end(), v.begin(), v.end());
  out.failed_checks = static_cast<int>(std::count_if(out.verdicts.begin(), out.verdicts.end(),
                                                     [](const auto& v) { return !v.pass; }));
  out.failed_runs = static_cast<int>(
      std::count_if(results.begin(), results.end(), [](const auto& r) { return !r.ran; }));
  for (const auto& r : results) out.changed += r.digest_status == "changed";
  out.digest_fail = o.require_digests && out.changed > 0;
  out.stopped = stopped;
  out.results = std::move(results);
  return out;
}

// report.md (also printed on stdout).
std::string ReportMarkdown(const RegressOptions& o, const scenario::RegressionSuite& suite,
                           const Outcome& r) {
  std::ostringstream md;
  md << "### regression suite " << suite.name << " (" << o.suite.string() << ")\n\n"
     << "| case | check | expected | measured (mean ± 95 % CI) | verdict |\n"
     << "|---|---|---|---|---|\n";
  for (const auto& v : r.verdicts)
    md << "| " << v.case_name << " | " << v.check << " | " << v.expected << " | " << v.measured
       << " | " << (v.pass ? "pass" : "**FAIL**: " + v.why) << " |\n";
  md << "\n| case | run | digest of seed outputs |\n|---|---|---|\n";
  for (std::size_t i = 0; i < r.results.size(); ++i) {
    const auto& cr = r.results[i];
    const auto& c = suite.cases[i];
    std::string d = cr.digest_status;
    if (d == "changed") d = "**changed** (recorded " + c.digest + ", now " + cr.digest + ")";
    if (d == "same" || d == "not recorded") d += " " + cr.digest;
    md << "| " << cr.name << " | " << (cr.ran ? "ok" : "**failed**: " + cr.error) << " ("
       << static_cast<int>(cr.wall_s) << " s) | " << d << " |\n";
  }
  md << "\n"
     << r.verdicts.size() - r.failed_checks << " of " << r.verdicts.size() << " checks pass";
  if (r.failed_runs) md << "; " << r.failed_runs << " case(s) did not run";
  if (r.changed)
    md << "; " << r.changed << " digest(s) changed (the same seeds no longer give the same "
       << "outputs: expected after an intended change, refresh with --record)";
  if (r.stopped) md << "; stopped by a signal before every case ran";
  md << ".\n";
  return md.str();
}

// report.json.
nlohmann::json ReportJson(const RegressOptions& o, const scenario::RegressionSuite& suite,
                          const Outcome& r) {
  nlohmann::json j;
  j["suite"] = suite.name;
  j["file"] = o.suite.string();
  for (const auto& v : r.verdicts)
    j["checks"].push_back({{"case", v.case_name},
                           {"check", v.check},
                           {"expected", v.expected},
                           {"measured", v.measured},
                           {"pass", v.pass},
                           {"why", v.why}});
  for (std::size_t i = 0; i < r.results.size(); ++i)
    j["cases"].push_back({{"name", r.results[i].name},
                          {"ran", r.results[i].ran},
                          {"error", r.results[i].error},
                          {"wall_s", r.results[i].wall_s},
                          {"digest", r.results[i].digest},
                          {"recorded_digest", suite.cases[i].digest},
                          {"digest_status", r.results[i].digest_status}});
  j["failed_checks"] = r.failed_checks;
  j["failed_runs"] = r.failed_runs;
  j["changed_digests"] = r.changed;
  j["complete"] = !r.stopped && r.failed_runs == 0;
  return j;
}

// JUnit XML: one testsuite per case, a testcase per check and one for the digest.
std::string ReportJunit(const scenario::RegressionSuite& suite, const Outcome& r) {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"" << XmlEscape(suite.name)
    << "\" tests=\"" << r.verdicts.size() + r.results.size() << "\" failures=\""
    << r.failed_checks + (r.digest_fail ? r.changed : 0) << "\" errors=\"" << r.failed_runs
    << "\" skipped=\"" << (r.digest_fail ? 0 : r.changed) << "\">\n";
  for (std::size_t i = 0; i < suite.cases.size() + 1; ++i) {
    const std::string name = i < suite.cases.size() ? suite.cases[i].name : "suite";
    x << "  <testsuite name=\"" << XmlEscape(name) << "\">\n";
    if (i < r.results.size()) {
      const auto& cr = r.results[i];
      x << "    <testcase classname=\"" << XmlEscape(name) << "\" name=\"run and digest\" time=\""
        << cr.wall_s << "\">";
      if (!cr.ran)
        x << "<error message=\"" << XmlEscape(cr.error) << "\"/>";
      else if (cr.digest_status == "changed")
        x << (r.digest_fail ? "<failure message=\"" : "<skipped message=\"")
          << XmlEscape("digest changed: recorded " + suite.cases[i].digest + ", now " + cr.digest)
          << "\"/>";
      x << "</testcase>\n";
    }
    for (const auto& v : r.verdicts) {
      if (v.case_name != name) continue;
      x << "    <testcase classname=\"" << XmlEscape(name) << "\" name=\"" << XmlEscape(v.check)
        << "\">";
      if (!v.pass)
        x << "<failure message=\""
          << XmlEscape("expected " + v.expected + ", measured " + v.measured + ": " + v.why)
          << "\"/>";
      x << "</testcase>\n";
    }
    x << "  </testsuite>\n";
  }
  x << "</testsuites>\n";
  return x.str();
}

// --record: the suite as written with bands measured now and the new digests.
void RecordSuite(const RegressOptions& o, scenario::RegressionSuite rec, const Outcome& r,
                 const eval::Measured& measured) {
  for (std::size_t i = 0; i < rec.cases.size(); ++i) {
    auto& c = rec.cases[i];
    std::vector<eval::MetricRef> refs;
    for (const auto& b : c.bands) refs.push_back(b.metric);
    for (const auto& metric : c.record)
      for (const auto& mode : c.modes) refs.push_back({"", mode, metric});
    c.bands.clear();
    std::set<std::string> seen;
    for (const auto& ref : refs) {
      if (!seen.insert(ref.ToString()).second) continue;
      const auto& m = measured.at(c.name);
      const auto it = m.find(ref.mode + "." + ref.metric);
      if (it == m.end()) continue;  // undefined in this run: no band
      c.bands.push_back(eval::RecordBand(ref, it->second));
    }
    c.digest = r.results[i].digest;
  }
  const auto folder = std::filesystem::absolute(o.record).parent_path();
  WriteTextFile(o.record,
                "# Regression suite recorded by `dualgrid regress " + o.suite.string() +
                    " --record`: bands = mean ± max(3 × 95 % CI half-width, a per-metric "
                    "floor) (docs/regression.md);\n# orderings are copied unchanged: claims "
                    "written by hand.\n" +
                    scenario::SuiteToYaml(rec, folder));
  if (!o.quiet) std::cerr << "regress: recorded " << o.record.string() << "\n";
}

}  // namespace

int RunRegress(const RegressOptions& o) {
  // A baseline must describe the cases as written: bands measured under extra overrides would
  // belong to another configuration.
  if (!o.record.empty() && !o.sets.empty())
    throw std::invalid_argument(
        "--record with --set: a recorded baseline must be measured on the suite as written; put "
        "the overrides into the cases' `set` lists instead");
  scenario::RegressionSuite suite = scenario::LoadSuite(o.suite);
  const scenario::RegressionSuite as_written = suite;  // what --record writes back
  outputs::InputSet inputs;
  inputs.Add(o.suite, "suite");
  for (const scenario::RegressionCase& c : suite.cases) {
    SafeName(c.name, o.suite.string() + ": case name");  // its folder: --out/NAME
    if (!c.IsGenerator()) inputs.Add(c.scenario, "scenario of case '" + c.name + "'");
  }
  outputs::CheckOutputApart(o.out, inputs);
  PrepareOutputFolder(o.out, {.force = o.force});
  PrepareCases(o, &suite);
  eval::Measured measured;
  std::vector<CaseResult> results = RunCases(o, suite, &measured);
  const Outcome r = Judge(o, suite, std::move(results), measured, StopSignal() != 0);

  const std::string md = ReportMarkdown(o, suite, r);
  std::cout << md;
  WriteTextFile(o.out / "report.md", md);
  WriteTextFile(o.out / "report.json", ReportJson(o, suite, r).dump(2) + "\n");
  WriteTextFile(o.out / "junit.xml", ReportJunit(suite, r));
  SealOutputFolder(o.out);

  if (!o.record.empty() && !r.stopped) {
    if (r.failed_runs > 0) {
      std::cerr << "dualgrid: error: --record: not written, " << r.failed_runs
                << " case(s) did not run: a baseline needs every case\n";
      return kExitSomeSeedsFailed;
    }
    RecordSuite(o, as_written, r, measured);
  }
  if (r.stopped) return StopExitCode();
  if (r.failed_runs > 0) return kExitSomeSeedsFailed;
  if (r.failed_checks > 0 || r.digest_fail) return kExitRunFailed;  // 1: a check failed
  return kExitOk;
}

Command AddRegressCommand(CLI::App& app, const CliContext& ctx) {
  auto o = std::make_shared<RegressOptions>();
  o->network_dir = ctx.network_dir;
  o->executable = ctx.executable;
  auto* cmd = app.add_subcommand(
      "regress",
      "Run a regression suite (cases = scenario + overrides + seeds, with bands and orderings on "
      "the metrics) and report pass/fail; exit 0 all pass, 1 a check failed, 2 bad suite, 3 a "
      "case did not run (docs/regression.md)");
  cmd->add_option("suite", o->suite, "Suite file (e.g. tests/regression/suite.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* out = Opt(cmd, "--out,-o", &o->out,
                  "Folder for the case runs and the reports (the default folder is replaced as "
                  "with --force; a folder you name needs --force to be replaced)")
                  ->check(NonEmptyPath());
  cmd->add_option("--record", o->record,
                  "Also write the suite with bands recorded from this run (mean ± max(3 CI, "
                  "floor)) and the digests to this file")
      ->check(NonEmptyPath());
  cmd->add_flag("--require-digests", o->require_digests,
                "A changed digest (same seed, different outputs) fails the suite");
  cmd->add_option("--set", o->sets, "Override a scenario key in every case, KEY=VALUE")
      ->check(OverrideSpec());
  cmd->add_option("--jobs,-j", o->jobs,
                  "Seed runs at a time (default: one per core, each with one OpenMP thread)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));
  Opt(cmd, "--network-dir", &o->network_dir, "Folder of the built networks")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress output");
  AddForceFlag(cmd, &o->force);
  return {cmd, [o, out] {
            if (out->count() == 0) o->force = true;  // the default folder is dualgrid's own
            return RunRegress(*o);
          }};
}

}  // namespace dualgrid::tools
