// dualgrid: SUMO traffic -> radar detections -> dynamic occupancy grid, scored against truth.
#include <unistd.h>

#include <csignal>

#include <iostream>

#include <CLI/CLI.hpp>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"
#include "exit_codes.hpp"
#include "signals.hpp"

namespace {

using namespace dualgrid::tools;

constexpr const char* kExitCodes =
    "Exit codes: 0 done; 1 the run failed (SUMO error, an output not written); 2 bad input "
    "(command line, scenario or network file; nothing simulated); 3 experiment: some seed runs "
    "failed (the others are aggregated), regress: a case did not run; regress: 1 a check failed; "
    "130/143 stopped by SIGINT/SIGTERM (results of the "
    "simulated part written, marked incomplete). Details: docs/cli.md.";

// An option whose default is shown in --help.
template <typename T>
CLI::Option* Opt(CLI::App* cmd, const std::string& name, T* value, const std::string& help) {
  return cmd->add_option(name, *value, help)->capture_default_str();
}

void AddRunOptions(CLI::App* cmd, RunOptions* o, const std::string& out_help, bool with_seed) {
  cmd->add_option("scenario", o->scenario, "Scenario file (e.g. scenarios/highway.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", o->out, out_help)->required()->check(NonEmptyPath());
  if (with_seed)
    cmd->add_option("--seed", o->seed, "Random seed (default: the scenario's `seed`)")
        ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  cmd->add_option("--duration", o->duration,
                  "Simulated time [s] (default: the scenario's `duration`)")
      ->check(Number(0.0, kMaxDuration, true));
  Opt(cmd, "--network-dir", &o->network_dir,
      "Folder of the built networks named in scenarios (`network: highway`)")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--quiet,-q", o->quiet, "No progress or summary output");
  cmd->add_option("--set", o->sets,
                  "Override a scenario key, KEY=VALUE (repeatable): e.g. --set filter.preset=paper "
                  "--set filter.num_particles=3000; a number in KEY indexes a list "
                  "(traffic.vehicles.0.speed=20). Validated like the file")
      ->check(OverrideSpec());
}

CLI::Validator DetectionFormat() { return CLI::IsMember({"none", "csv", "csv.gz"}); }

void AddFilterOptions(CLI::App* cmd, FilterRunOptions* o, bool* no_figures) {
  cmd->add_option("--modes", o->modes,
                  "Weight modes to run side by side, comma-separated (default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"position", "velocity", "dual"}));
  cmd->add_option("--snapshots", o->snapshots,
                  "Times [s] of the grid pictures, comma-separated (default: the scenario's "
                  "`evaluation.snapshot_times`, else 1/4, 1/2, 3/4 of the run)")
      ->delimiter(',')
      ->check(Number(0.0, kMaxDuration, true));
  cmd->add_flag("--no-figures", *no_figures, "Skip the pictures (metrics and tables only)");
  cmd->add_option("--figure-formats", o->figure_formats,
                  "Formats of every figure, comma-separated: png (raster), svg, pdf (vectors) "
                  "(default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"png", "svg", "pdf"}));
  cmd->add_flag_callback(
      "--write-detections", [o] { o->detections = "csv"; }, "Same as --detections csv");
  Opt(cmd, "--detections", &o->detections,
      "Write the radar detections: none, csv, or csv.gz (gzip, about 3.5x smaller)")
      ->check(DetectionFormat());
  cmd->add_flag("--write-particles", o->write_particles,
                "Write every particle beside each grid picture (figures/particles_*.csv, several "
                "MB each)");
  cmd->add_flag("--check-invariants", o->check_invariants,
                "Check the filters' invariants every step and sample the resident memory (soak "
                "tests; docs/reliability.md)");
  cmd->add_option("--threads", o->threads,
                  "OpenMP threads per run (default 0: all cores; at most " +
                      std::to_string(kMaxThreadsPerCore) + " per core)")
      ->check(WholeNumber(0, kMaxThreadsPerCore * Cores()));
}

std::string SelfPath(const char* argv0) {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, n) : std::string(argv0);
}

std::string OneLine(std::string s) {
  for (char& c : s)
    if (c == '\n') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// The subcommand being parsed when the error happened, for the "see --help" hint.
std::string HelpHint(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands())
    return "dualgrid " + sub->get_name() + " --help";
  return "dualgrid --help";
}

}  // namespace

// OpenMP threads that spin while they wait (libgomp's default: ~3 ms) steal the time slices of
// the threads doing the work when another process is busy on the cores: measured with two other
// CPU-bound processes on 2 cores, a paper-size filter cycle took 14 ms on 2 threads instead of
// 2.5 ms with passive waiting (docs/performance.md). Purely passive waiting (a futex sleep at
// every barrier) costs ~30 us per barrier on a quiet machine, though; a spin of ~3 us
// (GOMP_SPINCOUNT=300) before sleeping keeps most of the quiet speed and the robustness under
// load. libgomp reads these variables when it is loaded, before main, so the program re-executes
// itself once with them set, unless the user chose a policy or spin count. Returns only if no
// re-exec happened.
static void UseShortOpenMpSpinning(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", "PASSIVE", 1) != 0 || setenv("GOMP_SPINCOUNT", "300", 1) != 0)
    return;
  execv("/proc/self/exe", argv);
  // exec failed (no /proc): run on with the default policy; the variables still reach children.
}

int main(int argc, char** argv) {
  UseShortOpenMpSpinning(argv);
  // Past a file-size limit (ulimit -f) a write should fail and be reported naming the file, not
  // kill the process with SIGXFSZ and leave a half-written run behind silently.
  std::signal(SIGXFSZ, SIG_IGN);
  InstallStopHandlers();
  CLI::App app{
      "dualgrid: radar-only dynamic occupancy grid with dual particle weights, "
      "co-simulated with SUMO.\nScenarios are YAML files (see scenarios/ and "
      "docs/scenarios.md)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "dualgrid 0.1.0");
  app.footer(kExitCodes);
  const auto network_dir = dualgrid::sim::DefaultNetworkDir();

  SimOptions sim_options;
  sim_options.run.network_dir = network_dir;
  auto* sim = app.add_subcommand(
      "sim", "Run SUMO and the radar model; write ground truth and detections (CSV)");
  AddRunOptions(sim, &sim_options.run, "Output folder", true);
  Opt(sim, "--detections", &sim_options.detections,
      "Write the radar detections: none, csv, or csv.gz (gzip, about 3.5x smaller)")
      ->check(DetectionFormat());

  SnapshotOptions snap;
  snap.run.network_dir = network_dir;
  auto* snapshot = app.add_subcommand(
      "snapshot",
      "Bird's-eye picture (PNG) of a scenario at one time: road, vehicles, radar "
      "fields of view, detections with radial-velocity arrows");
  AddRunOptions(snapshot, &snap.run, "PNG file to write (must end in .png)", true);
  snapshot->add_option("--time,-t", snap.time, "Scenario time [s]")
      ->required()
      ->check(Number(0.0, kMaxDuration, true));
  Opt(snapshot, "--behind", &snap.behind, "View behind the ego [m]")
      ->check(Number(0.0, 2000.0, true));
  Opt(snapshot, "--ahead", &snap.ahead, "View ahead of the ego [m]")
      ->check(Number(0.0, 2000.0, true));
  Opt(snapshot, "--half-width", &snap.half_width, "View to each side of the ego [m]")
      ->check(Number(0.0, 1000.0, true));

  FilterRunOptions run_options;
  bool run_no_figures = false;
  run_options.run.network_dir = network_dir;
  auto* run = app.add_subcommand(
      "run",
      "Run SUMO, the radar and the grid filters (one per weight mode, same detections) "
      "and score them against the ground truth");
  AddRunOptions(run, &run_options.run, "Run folder (metrics, tables, figures, config)", true);
  AddFilterOptions(run, &run_options, &run_no_figures);
  bool run_no_record = false;
  run->add_flag("--no-record", run_no_record,
                "Do not record the replay frames (RUN_DIR/replay/; off anyway with --no-figures)");
  Opt(run, "--record-interval", &run_options.record_interval,
      "Time between recorded replay frames [s], rounded to whole steps")
      ->check(Number(0.001, 60.0, true));
  Opt(run, "--record-particles", &run_options.record_particles,
      "Particles recorded per mode and frame (an even subsample; 0: none)")
      ->check(WholeNumber(0, 1000000));
  run->add_flag("--video", run_options.video,
                "Also write the replay video (replay.mp4 and a GIF preview; needs ffmpeg) as "
                "`dualgrid replay` would");
  run->add_flag(
      "--viewer", run_options.viewer,
      "Also write the interactive viewer (replay.html) as `dualgrid replay --html` would");

  ReplayOptions rep;
  auto* replay = app.add_subcommand(
      "replay",
      "Video (MP4 + GIF preview) and/or interactive HTML viewer of a recorded run, without "
      "rerunning SUMO (docs/replay.md)");
  replay->add_option("run_dir", rep.run_dir, "Run folder written by `dualgrid run`")
      ->required()
      ->check(CLI::ExistingDirectory);
  replay->add_flag("--video", rep.video, "Write the video (the default unless --html is given)");
  replay->add_flag("--html", rep.html, "Write the self-contained interactive viewer");
  replay->add_option("--out,-o", rep.out, "Video file (default RUN_DIR/replay.mp4)")
      ->check(NonEmptyPath());
  replay->add_option("--html-out", rep.html_out, "Viewer file (default RUN_DIR/replay.html)")
      ->check(NonEmptyPath());
  replay
      ->add_option("--modes", rep.modes,
                   "Video: modes to show, comma-separated (default: all recorded)")
      ->delimiter(',');
  replay->add_flag("--particles", rep.particles, "Video: draw the recorded particles");
  replay->add_flag_callback(
      "--no-detections", [&rep] { rep.detections = false; }, "Video: leave the detections out");
  Opt(replay, "--from", &rep.from, "First time [s]")->check(Number(0.0, kMaxDuration, false));
  Opt(replay, "--to", &rep.to, "Last time [s] (0: the end)")
      ->check(Number(0.0, kMaxDuration, false));
  Opt(replay, "--speed", &rep.speed, "Video playback speed (1: real time)")
      ->check(Number(0.1, 20.0, false));
  Opt(replay, "--width", &rep.width, "Video width [px] (even)")->check(WholeNumber(320, 7680));
  Opt(replay, "--preview", &rep.preview, "Short preview beside the video: gif, webm or none")
      ->check(CLI::IsMember({"gif", "webm", "none"}));
  replay->add_flag("--quiet,-q", rep.quiet, "No progress output");

  ExperimentOptions exp;
  bool exp_no_figures = false;
  exp.run.run.network_dir = network_dir;
  auto* experiment = app.add_subcommand(
      "experiment",
      "`run` over seeds first-seed .. first-seed + seeds - 1 (separate processes) and aggregate "
      "the tables with 95 % confidence intervals");
  AddRunOptions(experiment, &exp.run.run, "Experiment folder", false);
  AddFilterOptions(experiment, &exp.run, &exp_no_figures);
  Opt(experiment, "--seeds", &exp.seeds, "Number of seeds")->check(WholeNumber(1, kMaxSeeds));
  Opt(experiment, "--first-seed", &exp.first_seed, "First seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  experiment
      ->add_option("--jobs,-j", exp.jobs,
                   "Seed runs at a time (default: one per core, each with one OpenMP thread)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));

  TangentialOptions tan;
  auto* tangential =
      app.add_subcommand("tangential",
                         "Write a tangential-motion stress scenario (traffic crossing ahead of the "
                         "ego, or driving alongside it), to run with `dualgrid run`");
  Opt(tangential, "--kind", &tan.kind,
      "crossing (ahead, across the front radar), parallel (alongside, across the corner "
      "radars), or aspect (any --angle to any --sensor's line of sight; docs/stress.md)")
      ->check(CLI::IsMember({"crossing", "parallel", "aspect"}));
  Opt(tangential, "--sensor", &tan.sensor,
      "aspect: the radar whose line of sight the angle refers to")
      ->check(CLI::IsMember({"front", "front_left", "front_right", "rear_left", "rear_right"}));
  Opt(tangential, "--angle", &tan.angle,
      "aspect: angle between the targets' velocity over ground and the line of sight [deg] "
      "(0 receding, 90 across, 180 approaching)")
      ->check(Number(0.0, 180.0, false));
  Opt(tangential, "--range", &tan.range,
      "aspect: distance sensor -> target centre when on the sensor's boresight [m]")
      ->check(Number(1.0, 200.0, false));
  Opt(tangential, "--target", &tan.target, "aspect: car, truck or cyclist")
      ->check(CLI::IsMember({"car", "truck", "cyclist"}));
  Opt(tangential, "--interval", &tan.interval, "aspect: seconds between the targets")
      ->check(Number(1.0, 60.0, false));
  tangential
      ->add_option("--grid-width", tan.grid_width,
                   "aspect: the grid's width (filter.width_y) [m] (default: the paper's 25, "
                   "widened when a target would not be scored in it)")
      ->check(Number(5.0, 400.0, false));
  Opt(tangential, "--count", &tan.count, "Number of stress vehicles")->check(WholeNumber(1, 12));
  Opt(tangential, "--ego-speed", &tan.ego_speed, "Ego speed [m/s] (0, a parked ego: aspect only)")
      ->check(Number(0.0, 40.0, false));
  tangential
      ->add_option("--speed", tan.speed,
                   "Stress vehicles' speed over ground [m/s] (default: crossing 15; parallel "
                   "ego speed + 0.3, so they stay alongside)")
      ->check(Number(0.0, 40.0, true));
  Opt(tangential, "--first-distance", &tan.first_distance,
      "crossing: distance ahead of the ego of the first crossing [m]")
      ->check(Number(10.0, 600.0, false));
  tangential
      ->add_option("--spacing", tan.spacing,
                   "crossing: distance between crossings (default 20 m); parallel: distance "
                   "between vehicles of one lane (default 40 m) [m]")
      ->check(Number(0.0, 600.0, true));
  Opt(tangential, "--seed", &tan.seed, "Scenario seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  tangential->add_option("--out,-o", tan.out, "Scenario file to write (.yaml)")
      ->required()
      ->check(NonEmptyPath());
  tangential->add_flag("--quiet,-q", tan.quiet, "No summary");

  RegressOptions reg;
  reg.network_dir = network_dir;
  auto* regress = app.add_subcommand(
      "regress",
      "Run a regression suite (cases = scenario + overrides + seeds, with bands and orderings on "
      "the metrics) and report pass/fail; exit 0 all pass, 1 a check failed, 2 bad suite, 3 a "
      "case did not run (docs/regression.md)");
  regress->add_option("suite", reg.suite, "Suite file (e.g. tests/regression/suite.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  Opt(regress, "--out,-o", &reg.out, "Folder for the case runs and the reports")
      ->check(NonEmptyPath());
  regress
      ->add_option("--record", reg.record,
                   "Also write the suite with bands recorded from this run (mean ± max(3 CI, "
                   "floor)) and the digests to this file")
      ->check(NonEmptyPath());
  regress->add_flag("--require-digests", reg.require_digests,
                    "A changed digest (same seed, different outputs) fails the suite");
  regress->add_option("--set", reg.sets, "Override a scenario key in every case, KEY=VALUE")
      ->check(OverrideSpec());
  regress
      ->add_option("--jobs,-j", reg.jobs,
                   "Seed runs at a time (default: one per core, each with one OpenMP thread)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));
  Opt(regress, "--network-dir", &reg.network_dir, "Folder of the built networks")
      ->check(CLI::ExistingDirectory);
  regress->add_flag("--quiet,-q", reg.quiet, "No progress output");

  SweepOptions sw;
  sw.network_dir = network_dir;
  auto* sweep = app.add_subcommand(
      "sweep",
      "Run a scenario (or the tangential generator) over a grid of key values and seeds: "
      "locally, or as a run list / Slurm job array (docs/stress.md)");
  sweep
      ->add_option("scenario", sw.scenario,
                   "Scenario file, or 'tangential' to sweep the stress-case generator "
                   "(keys tangential.angle, tangential.sensor, ...)")
      ->required();
  sweep->add_option("--out,-o", sw.out, "Sweep folder (resumable: finished runs are kept)")
      ->required()
      ->check(NonEmptyPath());
  sweep
      ->add_option("--set", sw.sets,
                   "KEY=LIST to sweep (repeatable): values a,b,c and/or ranges first:step:last, "
                   "e.g. filter.sigma_v=0.5,1,2 or tangential.angle=0:15:90")
      ->required();
  Opt(sweep, "--seeds", &sw.seeds, "Seeds per setting")->check(WholeNumber(1, kMaxSeeds));
  Opt(sweep, "--first-seed", &sw.first_seed, "First seed")
      ->check(WholeNumber(0, static_cast<long long>(kMaxSeed)));
  sweep->add_option("--modes", sw.modes, "Weight modes (default: all three)")
      ->delimiter(',')
      ->check(CLI::IsMember({"position", "velocity", "dual"}));
  sweep->add_option("--duration", sw.duration, "Simulated time per run [s]")
      ->check(Number(0.0, kMaxDuration, true));
  sweep->add_option("--jobs,-j", sw.jobs, "Runs at a time (default: one per core, 1 thread each)")
      ->check(WholeNumber(1, kMaxThreadsPerCore * Cores()));
  sweep
      ->add_option("--emit", sw.emit,
                   "Do not run: 'list' writes runs.txt (one shell command per run, e.g. for GNU "
                   "parallel), 'slurm' also slurm.sh (a job array); then `dualgrid collect`")
      ->check(CLI::IsMember({"list", "slurm"}));
  Opt(sweep, "--network-dir", &sw.network_dir, "Folder of the built networks")
      ->check(CLI::ExistingDirectory);
  sweep->add_flag("--quiet,-q", sw.quiet, "No progress output");

  CollectOptions col;
  auto* collect = app.add_subcommand(
      "collect", "Merge the finished runs of a sweep folder into tables and figures");
  collect->add_option("dir", col.dir, "Sweep folder")->required()->check(CLI::ExistingDirectory);
  collect->add_flag("--quiet,-q", col.quiet, "No summary output");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << " (see " << HelpHint(app) << ")\n";
    return kExitBadInput;
  }
  try {
    if (sim->parsed()) return RunSim(sim_options);
    if (sweep->parsed()) {
      sw.executable = SelfPath(argv[0]);
      return RunSweep(sw);
    }
    if (collect->parsed()) return RunCollect(col);
    if (regress->parsed()) {
      reg.executable = SelfPath(argv[0]);
      return RunRegress(reg);
    }
    if (tangential->parsed()) {
      // The aspect options imply --kind aspect; with another kind they would be ignored.
      bool aspect_options = false;
      for (const char* name :
           {"--sensor", "--angle", "--range", "--target", "--interval", "--grid-width"})
        aspect_options = aspect_options || tangential->count(name) > 0;
      if (aspect_options && tangential->count("--kind") == 0) tan.kind = "aspect";
      if (aspect_options && tan.kind != "aspect")
        throw std::invalid_argument(
            "--sensor, --angle, --range, --target, --interval and "
            "--grid-width are options of --kind aspect, not " +
            tan.kind);
      return RunTangential(tan);
    }
    if (snapshot->parsed()) return RunSnapshot(snap);
    if (replay->parsed()) {
      // The viewer has its own controls for these: given with --html alone they would be ignored.
      if (rep.html && !rep.video)
        for (const char* name : {"--out", "--modes", "--particles", "--no-detections", "--speed",
                                 "--width", "--preview"})
          if (replay->count(name) > 0)
            throw std::invalid_argument(std::string(name) +
                                        " is a video option; add --video, or leave it out (the "
                                        "viewer has its own controls)");
      return RunReplay(rep);
    }
    if (run->parsed()) {
      run_options.figures = !run_no_figures;
      run_options.record = run_options.figures && !run_no_record;
      if ((run_options.video || run_options.viewer) && !run_options.record)
        throw std::invalid_argument(
            "--video and --viewer need the recording: drop --no-record / --no-figures");
      return RunFilters(run_options);
    }
    if (experiment->parsed()) {
      exp.run.figures = !exp_no_figures;
      exp.executable = SelfPath(argv[0]);
      // Parallel runs share the cores: one OpenMP thread each unless told otherwise.
      const int jobs = exp.jobs > 0 ? exp.jobs : Cores();
      if (exp.run.threads == 0 && jobs > 1) exp.run.threads = 1;
      return RunExperiment(exp);
    }
  } catch (const dualgrid::scenario::ConfigError& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "dualgrid: error: " << OneLine(e.what()) << "\n";
    return kExitRunFailed;
  }
  return kExitOk;
}
