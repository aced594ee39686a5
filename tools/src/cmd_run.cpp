// `dualgrid run`: one SUMO run, one radar stream, three filters side by side, scored per step.
#include <omp.h>

#include <chrono>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dualgrid/eval/aggregate.hpp"
#include "figures.hpp"
#include "output.hpp"
#include "pipeline.hpp"
#include "progress.hpp"
#include "scoring.hpp"

namespace dualgrid::tools {

std::vector<filter::WeightMode> ParseModes(const std::vector<std::string>& names) {
  std::vector<filter::WeightMode> modes;
  for (const std::string& n : names) {
    const auto m = filter::ParseWeightMode(n);
    if (!m)
      throw std::invalid_argument("unknown mode '" + n + "' (expected position, velocity, dual)");
    if (std::find(modes.begin(), modes.end(), *m) != modes.end())
      throw std::invalid_argument("mode '" + n + "' given twice");
    modes.push_back(*m);
  }
  if (modes.empty()) throw std::invalid_argument("--modes needs at least one mode");
  return modes;
}

namespace {

// Everything the run actually used, so any result can be rerun or compared.
nlohmann::json ConfigJson(const scenario::ScenarioConfig& c, const FilterRunOptions& o) {
  nlohmann::json j = scenario::ConfigToJson(c);
  j["modes"] = o.modes;
  return j;
}

}  // namespace

int RunFilters(const FilterRunOptions& options) {
  if (options.threads > 0) omp_set_num_threads(options.threads);
  const std::vector<filter::WeightMode> modes = ParseModes(options.modes);
  std::vector<std::string> mode_names;
  for (auto m : modes) mode_names.emplace_back(filter::ToString(m));
  scenario::ScenarioConfig config = LoadConfig(options.run);
  const auto& out = options.run.out;
  std::filesystem::create_directories(out / "figures");
  CopyScenario(config, out);
  OpenOutput(out / "config.json") << ConfigJson(config, options).dump(2) << "\n";

  const auto wall_start = std::chrono::steady_clock::now();
  Pipeline pipeline(config, options.run.network_dir, out, modes);
  GroundTruthWriter truth(out / "ground_truth.csv");
  std::unique_ptr<DetectionWriter> detections;
  if (options.write_detections)
    detections = std::make_unique<DetectionWriter>(out / "detections.csv");

  std::vector<ModeScorer> scorers(modes.size(), ModeScorer(config.evaluation));
  // Every cluster of every cycle with its role: the tracks as the evaluation saw them.
  std::ofstream clusters = OpenOutput(out / "clusters.csv");
  clusters << "step,time,mode,x,y,vx,vy,weight,particles,role,object,x_ego,y_ego\n";
  std::vector<double> snapshot_times = options.snapshots;
  // The scenario's picture times are defaults: those past a shortened run are dropped; times
  // asked for on the command line must lie in the run (checked below).
  if (snapshot_times.empty())
    for (double t : config.evaluation.snapshot_times)
      if (t > 0.0 && t <= config.sim.duration) snapshot_times.push_back(t);
  if (snapshot_times.empty())
    for (double f : {0.25, 0.5, 0.75}) snapshot_times.push_back(f * config.sim.duration);
  std::sort(snapshot_times.begin(), snapshot_times.end());
  snapshot_times.erase(std::unique(snapshot_times.begin(), snapshot_times.end()),
                       snapshot_times.end());
  for (double t : snapshot_times)
    if (!(t > 0.0 && t <= config.sim.duration))
      throw std::invalid_argument("snapshot time " + Fixed(t, 2) + " s is outside the run (0, " +
                                  Fixed(config.sim.duration, 2) + "] s");
  std::size_t next_snapshot = 0;

  // Weight traces (paper Fig. 4) of the dual filter, or of the last mode if dual is not run.
  const std::size_t trace_mode =
      std::find(modes.begin(), modes.end(), filter::WeightMode::kDual) != modes.end()
          ? std::find(modes.begin(), modes.end(), filter::WeightMode::kDual) - modes.begin()
          : modes.size() - 1;
  std::map<std::string, WeightTrace> traces;
  std::map<std::string, int> frames_in_grid;

  Progress progress("run " + config.sim.name + " seed " + std::to_string(config.sim.seed),
                    config.sim.StepCount(), !options.run.quiet);
  int steps = 0;
  std::size_t total_detections = 0;
  while (pipeline.Step()) {
    const sim::Frame& f = pipeline.frame();
    truth.Write(f);
    if (detections) detections->Write(pipeline);
    total_detections += pipeline.detections().size();
    std::vector<GridSnapshot> snaps;
    // All filters share one grid geometry (centred on the same ego), so the ground truth per cell
    // and per object is computed once for the first and holds for every mode.
    std::vector<std::uint8_t> truth_classes;
    const std::vector<eval::TruthObject> objects = pipeline.TruthObjects(pipeline.grid(0));
    for (std::size_t m = 0; m < modes.size(); ++m) {
      const auto& grid = pipeline.grid(m);
      snaps.push_back(TakeSnapshot(grid));
      if (m == 0) truth_classes = TruthClasses(snaps[0], f, config.sim);
      scorers[m].AddFrame(f.time, grid, snaps[m], objects, truth_classes, f.ego.box);
      const auto& a = scorers[m].association();
      for (std::size_t c = 0; c < scorers[m].clusters().size(); ++c) {
        const eval::Cluster& cl = scorers[m].clusters()[c];
        const Position local = f.EgoPose().ToLocal(cl.position);
        static const char* kRole[] = {"matched", "duplicate", "false"};
        clusters << f.step << ',' << Fixed(f.time, 3) << ',' << mode_names[m] << ','
                 << Fixed(cl.position.x(), 3) << ',' << Fixed(cl.position.y(), 3) << ','
                 << Fixed(cl.velocity.x(), 3) << ',' << Fixed(cl.velocity.y(), 3) << ','
                 << cl.weight << ',' << cl.size << ',' << kRole[static_cast<int>(a.role[c])] << ','
                 << (a.object_of_cluster[c] >= 0
                         ? pipeline.ids().Name(objects[a.object_of_cluster[c]].id)
                         : std::string())
                 << ',' << Fixed(local.x(), 2) << ',' << Fixed(local.y(), 2) << '\n';
      }
    }
    // Weight masses of the particles inside each vehicle's box, for the focus-object figure.
    {
      const auto& p = pipeline.grid(trace_mode).particles();
      for (const auto& v : f.vehicles) {
        if (!pipeline.grid(trace_mode).CellOf(v.box.center)) continue;
        ++frames_in_grid[v.id];
        double wp = 0, wv = 0, w = 0, wp_good = 0, wv_good = 0;
        const OrientedBox grown{v.box.center, v.box.yaw, v.box.length + 1.0, v.box.width + 1.0};
        for (std::size_t i = 0; i < p.size(); ++i) {
          if (!grown.Contains(Position(p.x[i], p.y[i]))) continue;
          wp += p.w_position[i];
          wv += p.w_velocity[i];
          w += p.weight[i];
          if ((Velocity(p.vx[i], p.vy[i]) - v.velocity).norm() < WeightTrace::kGoodVelocity) {
            wp_good += p.w_position[i];
            wv_good += p.w_velocity[i];
          }
        }
        int n = 0, tangential = 0;
        const int vehicle_id = pipeline.ids().Id(v.id);
        for (const auto& d : pipeline.detections())
          if (d.source_id == vehicle_id) {
            tangential += std::abs(d.radial_speed_compensated) < 0.5 * v.velocity.norm();
            ++n;
          }
        auto& t = traces[v.id];
        t.time.push_back(f.time);
        t.w_position.push_back(wp);
        t.w_velocity.push_back(wv);
        t.weight.push_back(w);
        t.position_share.push_back(wp > 0 ? wp_good / wp : std::nan(""));
        t.velocity_share.push_back(wv > 0 ? wv_good / wv : std::nan(""));
        t.tangential_share.push_back(n > 0 ? static_cast<double>(tangential) / n : std::nan(""));
      }
    }
    // Several requested times may fall into one step: one picture for all of them.
    bool picture = false;
    while (next_snapshot < snapshot_times.size() &&
           f.time + 1e-9 >= snapshot_times[next_snapshot]) {
      picture = true;
      ++next_snapshot;
    }
    if (options.figures && picture) {
      const std::string stamp = Fixed(f.time, 2);
      RenderGridFigure(mode_names, snaps, f, f.time, out / "figures" / ("grid_t" + stamp + ".png"));
      RenderScene(pipeline, out / "figures" / ("scene_t" + stamp + ".png"), 60, 140, 22);
      // The particles behind each picture, for closer looks.
      for (std::size_t m = 0; m < modes.size(); ++m) {
        std::ofstream pc =
            OpenOutput(out / "figures" / ("particles_" + mode_names[m] + "_t" + stamp + ".csv"));
        pc << "x,y,vx,vy,w_position,w_velocity,weight,p_dynamic\n";
        const auto& ps = pipeline.grid(m).particles();
        for (std::size_t i = 0; i < ps.size(); ++i) {
          const auto cell = pipeline.grid(m).CellOf(Position(ps.x[i], ps.y[i]));
          const double pd =
              cell
                  ? snaps[m].dynamic[static_cast<std::size_t>(cell->y) * snaps[m].cells_x + cell->x]
                  : 0.0;
          pc << Fixed(ps.x[i], 3) << ',' << Fixed(ps.y[i], 3) << ',' << Fixed(ps.vx[i], 3) << ','
             << Fixed(ps.vy[i], 3) << ',' << ps.w_position[i] << ',' << ps.w_velocity[i] << ','
             << ps.weight[i] << ',' << Fixed(pd, 3) << '\n';
        }
      }
    }
    ++steps;
    progress.Update(steps, "t=" + Fixed(f.time, 1) + " s");
  }
  progress.Finish();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  // Results.
  std::vector<eval::ScenarioMetrics> metrics;
  std::vector<eval::ModeRuns> runs;
  nlohmann::json mj;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    metrics.push_back(scorers[m].Result());
    runs.push_back({mode_names[m], {metrics.back()}});
    mj["modes"][mode_names[m]] = metrics.back();
  }
  mj["scenario"] = config.sim.name;
  mj["seed"] = config.sim.seed;
  mj["steps"] = steps;
  mj["wall_s"] = wall;
  mj["detections_per_step"] = steps ? static_cast<double>(total_detections) / steps : 0.0;
  for (const auto& [id, n] : frames_in_grid)
    (void)n, mj["object_names"][std::to_string(pipeline.ids().Id(id))] = id;
  OpenOutput(out / "metrics.json") << mj.dump(2) << "\n";

  {
    std::ofstream objects = OpenOutput(out / "objects.csv");
    objects << "mode,id,name,frames_in_grid,frames_tracked,scored,D,t_d,delta_x,delta_v\n";
    for (std::size_t m = 0; m < modes.size(); ++m) {
      for (const auto& o : metrics[m].objects) {
        auto opt = [](const std::optional<double>& v) { return v ? Fixed(*v, 4) : std::string(); };
        objects << mode_names[m] << ',' << o.id << ',' << pipeline.ids().Name(o.id) << ','
                << o.frames_in_grid << ',' << o.frames_tracked << ',' << (o.scored ? 1 : 0) << ','
                << opt(o.tracked_fraction) << ',' << opt(o.detection_time) << ','
                << opt(o.position_error) << ',' << opt(o.velocity_error) << '\n';
      }
    }
  }
  const eval::ComparisonTable table = eval::MakeComparisonTable(config.sim.name, runs);
  OpenOutput(out / "table.md") << table.ToMarkdown();
  OpenOutput(out / "table.csv") << table.ToCsv();
  OpenOutput(out / "table.json") << table.ToJson().dump(2) << "\n";

  // Focus object: the scenario's choice, else the vehicle longest in the grid.
  std::string focus = config.evaluation.focus_object;
  if (focus.empty() || !traces.count(focus)) {
    int best = -1;
    for (const auto& [id, n] : frames_in_grid)
      if (n > best) best = n, focus = id;
  }
  if (traces.count(focus)) {
    const WeightTrace& t = traces.at(focus);
    std::ofstream w = OpenOutput(out / "weights.csv");
    w << "time,object,w_position,w_velocity,w_resample,position_share,velocity_share,"
         "tangential_share\n";
    for (std::size_t i = 0; i < t.time.size(); ++i)
      w << Fixed(t.time[i], 3) << ',' << focus << ',' << t.w_position[i] << ',' << t.w_velocity[i]
        << ',' << t.weight[i] << ',' << t.position_share[i] << ',' << t.velocity_share[i] << ','
        << t.tangential_share[i] << '\n';
    if (options.figures)
      RenderWeightTrace(t, focus, mode_names[trace_mode], out / "figures" / "weights.png");
  }
  if (options.figures)
    RenderTrackedShares(mode_names, RunTrackedShares(metrics, pipeline.ids()),
                        config.sim.name + ": tracked share D per object (seed " +
                            std::to_string(config.sim.seed) + ")",
                        out / "figures" / "tracked_share.png");

  if (!options.run.quiet) {
    std::cout << table.ToMarkdown() << "\n"
              << config.sim.name << ": " << steps << " steps in " << Fixed(wall, 1)
              << " s; results in " << out.string() << "\n";
  }
  return 0;
}

}  // namespace dualgrid::tools
