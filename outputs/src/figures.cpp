#include "dualgrid/outputs/figures.hpp"

#include "pictures.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/run_folder.hpp"
#include "dualgrid/viz/birds_eye_view.hpp"
#include "dualgrid/viz/charts.hpp"
#include "dualgrid/viz/grid_panels.hpp"

namespace dualgrid::outputs {

std::optional<std::string> DrawFigure(const std::filesystem::path& path,
                                      const std::function<void()>& draw) {
  try {
    if (FaultInjected("figure:" + path.filename().string()))
      throw std::runtime_error("injected fault (DUALGRID_FAULT)");
    draw();
    return std::nullopt;
  } catch (const std::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    return "figure " + path.string() + " not drawn: " + what;
  }
}

void PublishWarning(const std::string& warning, std::vector<std::string>* warnings) {
  std::cerr << "dualgrid: warning: " << warning << "\n";
  if (warnings) warnings->push_back(warning);
}

bool TryFigure(const std::filesystem::path& path, const std::function<void()>& draw,
               std::vector<std::string>* warnings) {
  const std::optional<std::string> failure = DrawFigure(path, draw);
  if (failure) PublishWarning(*failure, warnings);
  return !failure;
}

namespace {

// The caption's sentence on the axes of a picture in the grid frame, relative to the ego.
std::string AxesNote(const GridFrame& g) {
  return "Axes: metres from the ego along the grid frame's axes (" +
         (g.identity()
              ? std::string("here world east and north")
              : "x axis at " + FormatFixed(RadToDeg(g.yaw()), 0) + " deg from world east") +
         ").";
}

// One arrow length for vehicles and detections: the two kinds of arrow compare directly.
constexpr double kArrowSeconds = 0.5;

}  // namespace

std::vector<std::string> DrawFigures(
    const std::filesystem::path& png_path, const std::vector<std::string>& formats,
    const std::function<void(const std::filesystem::path&)>& draw) {
  std::vector<std::string> failures;
  for (const std::string& format : formats) {
    std::filesystem::path path = png_path;
    path.replace_extension("." + format);
    if (auto failure = DrawFigure(path, [&] { draw(path); })) failures.push_back(*failure);
  }
  return failures;
}

bool TryFigures(const std::filesystem::path& png_path, const std::vector<std::string>& formats,
                const std::function<void(const std::filesystem::path&)>& draw,
                std::vector<std::string>* warnings) {
  const std::vector<std::string> failures = DrawFigures(png_path, formats, draw);
  for (const std::string& failure : failures) PublishWarning(failure, warnings);
  return failures.empty();
}

ReferenceWords WordsFor(const std::string& references) {
  if (references == "annotated")
    return {"annotated instance boxes (2 Hz annotations, interpolated)",
            "an instance's velocity (estimated from its annotations)",
            "object (annotated instance token)", "annotated"};
  if (references == "tracks")
    return {"track boxes estimated from their labelled points",
            "a track's velocity (estimated from its points)", "object (track id)",
            "track estimate"};
  return {};
}

ScenePicture MakeScene(const cosim::Pipeline& pipeline, double behind, double ahead,
                       double half_width, bool captions, const ReferenceWords& words) {
  const sim::Frame& f = pipeline.frame();
  const GridFrame& g = pipeline.grid_frame();
  // Drawn relative to the ego in the grid frame, like the grid figures: the axes read as metres
  // from the ego.
  const Position ego = g.ToGrid(f.ego.box.center);
  const auto rel = [&](const Position& p) { return Position(g.ToGrid(p) - ego); };
  const auto rel_box = [&](OrientedBox b) {
    b = g.ToGrid(b);
    b.center -= ego;
    return b;
  };
  ScenePicture s;
  s.world = {Position(-behind, -half_width), Position(ahead, half_width)};
  viz::BirdsEyeOptions& options = s.options;
  options.title = pipeline.config().sim.name + ", t = " + FormatFixed(f.time, 2) +
                  " s: radar view (" + std::to_string(pipeline.detections().size()) +
                  " detections)";
  options.x_label = "x from the ego [m]";
  options.y_label = "y [m]";
  options.caption =
      AxesNote(g) + " Arrows: motion over ground in " + FormatFixed(kArrowSeconds, 1) +
      " s; black: " + words.velocity +
      "; coloured: a detection's radial velocity, ego "
      "motion compensated (short where a vehicle moves across the line of sight). Colour: the "
      "radar (field of view outline, its detections). A label that finds no free place is left "
      "out; one set apart from its box has a leader line.";
  if (!captions) options.caption.clear();
  auto to_rel = [&](std::vector<Position> points) {
    for (Position& p : points) p = rel(p);
    return points;
  };
  if (const sim::SumoSimulation* sumo = pipeline.sumo())  // recorded data have no lanes
    for (const auto& lane : sumo->LaneShapes())
      s.lanes.emplace_back(to_rel(lane.points), lane.width);
  for (const auto& rail : pipeline.config().sim.guard_rails) s.rails.push_back(to_rel(rail.points));
  s.ego_box = rel_box(f.ego.box);
  for (const auto& p : pipeline.config().sim.parked) {
    viz::VehicleStyle style;
    style.fill = viz::colors::kGuardRail;
    style.label = p.id;
    style.legend = "parked";
    s.parked.emplace_back(rel_box(p.box), style);
  }
  const auto& radar = pipeline.radar();
  const auto poses = radar.SensorPoses(pipeline.ego_motion().pose);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto& p = radar.sensors()[i];
    s.fovs.push_back({rel(poses[i].position), g.YawToGrid(poses[i].yaw), 0.5 * p.fov, p.max_range,
                      static_cast<int>(i), p.name});
  }
  for (const auto& v : f.vehicles) {
    viz::VehicleStyle style;
    style.label = v.id;
    style.velocity = g.VectorToGrid(v.velocity);  // over ground, as the detections' arrows
    style.arrow_scale = kArrowSeconds;
    s.vehicles.emplace_back(rel_box(v.box), style);
  }
  s.ego_style.ego = true;  // no label: the green box at the axes' origin
  s.ego_style.velocity = g.VectorToGrid(f.ego.velocity);
  s.ego_style.arrow_scale = kArrowSeconds;
  for (const auto& d : pipeline.detections())
    s.detections.push_back(
        {rel(d.position_world), g.VectorToGrid(d.radial_velocity_world), d.sensor, d.is_clutter});
  s.detection_style.coloring = viz::DetectionColoring::kBySensor;
  s.detection_style.arrow_scale = kArrowSeconds;
  return s;
}

void DrawScene(const ScenePicture& s, const std::filesystem::path& path) {
  viz::BirdsEyeView view(s.world, s.options);
  for (const auto& [points, width] : s.lanes) view.DrawLane(points, width);
  for (const auto& rail : s.rails) view.DrawGuardRail(rail);
  view.KeepLabelsOff(s.ego_box);  // drawn last, on top; no label may cover it
  for (const auto& [box, style] : s.parked) view.DrawVehicle(box, style);
  for (const viz::SensorFov& fov : s.fovs) view.DrawSensorFov(fov);
  for (const auto& [box, style] : s.vehicles) view.DrawVehicle(box, style);
  view.DrawVehicle(s.ego_box, s.ego_style);
  view.DrawDetections(s.detections, s.detection_style);
  view.Save(path.string());
}

void RenderScene(const cosim::Pipeline& pipeline, const std::filesystem::path& path, double behind,
                 double ahead, double half_width, bool captions, const ReferenceWords& words) {
  DrawScene(MakeScene(pipeline, behind, ahead, half_width, captions, words), path);
}

namespace {

viz::GridRaster ToRaster(const cosim::GridSnapshot& s) {
  return {s.cells_x,    s.cells_y, s.resolution, s.origin, s.free,
          s.static_occ, s.dynamic, s.mean_vx,    s.mean_vy};
}

}  // namespace

GridPicture MakeGridFigure(const std::vector<std::string>& modes,
                           const std::vector<cosim::GridSnapshot>& snapshots,
                           const std::vector<cosim::ModeScorer>& scorers, const GridFrame& g,
                           const sim::Frame& frame, double time, bool captions,
                           const ReferenceWords& words) {
  GridPicture picture;
  // Axes in metres from the ego, along the grid's axes: readers compare positions with the ego,
  // not with the network's (often UTM-sized) coordinates.
  const Position ego = g.ToGrid(frame.ego.box.center);
  const auto from_ego = [&](OrientedBox b) {
    b.center -= ego;
    return b;
  };
  std::vector<viz::GridPanel>& panels = picture.panels;
  for (std::size_t i = 0; i < modes.size(); ++i) {
    viz::GridPanel panel;
    panel.title = modes[i];
    panel.raster = ToRaster(snapshots[i]);
    panel.raster.origin -= ego;
    for (const auto& v : frame.vehicles) {
      panel.truth_boxes.push_back(from_ego(g.ToGrid(v.box)));
      panel.truth_velocities.push_back(g.VectorToGrid(v.velocity));
    }
    panel.ego_boxes.push_back(from_ego(g.ToGrid(frame.ego.box)));
    // The scorer's clusters of this step (grid frame) with their roles: what the mode tracks and
    // at which estimated velocity.
    const cosim::ModeScorer& sc = scorers[i];
    for (std::size_t c = 0; c < sc.clusters().size(); ++c) {
      const eval::Cluster& cl = sc.clusters()[c];
      panel.clusters.push_back({cl.min - ego, cl.max - ego, cl.position - ego, cl.velocity,
                                static_cast<int>(sc.association().role[c])});
    }
    panels.push_back(std::move(panel));
  }
  viz::GridFigureOptions& options = picture.options;
  options.x_label = "x from the ego [m]";  // the grid frame's axes (its angle is in the caption)
  options.y_label = "y [m]";
  options.title = "Dynamic grids at t = " + FormatFixed(time, 2) + " s";
  options.truth_label = words.legend;
  options.caption =
      "Cells: white free, black static, grey unknown; dynamic mass in the hue of its direction "
      "of motion over ground (the cell's mean particle velocity, grid frame: wheel), colours "
      "blended by the cell's masses. Black outlines: " +
      words.boxes +
      "; green: "
      "the ego. Coloured outlines: the mode's clusters of dynamic particles (blue-violet "
      "matched to a vehicle, orange duplicate, magenta false) with their estimated velocity; "
      "black arrows: " +
      words.velocity + ". Arrows: motion over ground in " + FormatFixed(options.arrow_seconds, 1) +
      " s. " + AxesNote(g);
  if (!captions) options.caption.clear();
  return picture;
}

void RenderGridFigure(const std::vector<std::string>& modes,
                      const std::vector<cosim::GridSnapshot>& snapshots,
                      const std::vector<cosim::ModeScorer>& scorers, const GridFrame& g,
                      const sim::Frame& frame, double time, const std::filesystem::path& path,
                      bool captions, const ReferenceWords& words) {
  const GridPicture picture =
      MakeGridFigure(modes, snapshots, scorers, g, frame, time, captions, words);
  viz::RenderGridPanels(picture.panels, path.string(), picture.options);
}

TrackedShares RunTrackedShares(const std::vector<eval::ScenarioMetrics>& metrics,
                               const cosim::IdRegistry& ids, bool velocity_aware) {
  std::map<int, std::vector<double>> per_object;  // by id: order of first appearance
  for (std::size_t m = 0; m < metrics.size(); ++m) {
    for (const auto& o : metrics[m].objects) {
      if (!o.scored) continue;
      auto& row = per_object.try_emplace(o.id, metrics.size(), std::nan("")).first->second;
      row[m] = (velocity_aware ? o.tracked_fraction_v : o.tracked_fraction).value_or(0.0);
    }
  }
  TrackedShares out;
  for (const auto& [id, row] : per_object) out.emplace_back(ids.Name(id), row);
  return out;
}

void RenderTrackedShares(const std::vector<std::string>& modes, const TrackedShares& shares,
                         const std::string& title, const std::string& y_label,
                         const std::filesystem::path& path, const TrackedShares& errors,
                         bool captions, const ReferenceWords& words) {
  viz::BarChart chart;  // with nothing scored (a very short run) the chart says "no data"
  chart.title = title;
  chart.x_label = words.object;
  chart.y_label = y_label;
  chart.percent = true;
  // One column wide whatever the number of objects: a wider chart would need larger fonts
  // (readability at one column) and show no more. Names turn, then thin out; value labels only
  // where they fit their bars.
  const bool velocity_aware = y_label.find("D_v") != std::string::npos;
  chart.caption =
      std::string("Bar colour: the filter's weight mode. ") +
      (velocity_aware ? "D_v: share of an object's frames in the grid in which a cluster with the "
                        "right velocity sits on it. "
                      : "D: share of an object's frames in the grid in which a cluster sits on "
                        "it. ") +
      (errors.empty() ? "One run: no confidence interval."
                      : "Bars: mean over the seeds; whiskers: 95 % confidence interval of the "
                        "mean (Student t), none where fewer than two seeds scored the object.");
  if (!captions) chart.caption.clear();
  for (const auto& [name, row] : shares) chart.categories.push_back(name);
  for (std::size_t m = 0; m < modes.size(); ++m) {
    viz::BarSeries s;
    s.name = modes[m];
    for (const auto& [name, row] : shares) s.values.push_back(row[m]);
    for (const auto& [name, row] : errors) s.errors.push_back(row[m]);
    chart.series.push_back(std::move(s));
  }
  viz::RenderBarChart(chart, path.string());
}

void RenderWeightTrace(const WeightTrace& trace, const std::string& object, const std::string& mode,
                       filter::VelocityLikelihood likelihood, const std::filesystem::path& path,
                       bool captions) {
  viz::LineChart chart;
  // Not titled as the paper's Fig. 4: it plots another quantity (the caption compares them).
  chart.title = "Weight shares on " + object + " (" + mode + " filter)";
  chart.y_label =
      "share within " + FormatFixed(WeightTrace::kGoodVelocity, 0) + " m/s [fraction of weight]";
  chart.y_min = 0.0;
  chart.y_max = 1.0;
  // Not the paper's Fig. 4 quantity (one particle's weights): readers compare the two, so the
  // caption says what is plotted and why w_velocity sits above w_position by default.
  chart.caption =
      "Share of each weight on " + object + " held by its particles within " +
      FormatFixed(WeightTrace::kGoodVelocity, 0) +
      " m/s of its true velocity. w_position scores positions only; w_velocity also scores the "
      "Doppler. ";
  // The explanation depends on the run's f_v (eq. (8)): say which one this run used.
  if (likelihood == filter::VelocityLikelihood::kRadialFit)
    chart.caption +=
        "This run uses the radial likelihood with the Doppler fit's tangential term (the "
        "dualgrid preset, the default): a particle with the true velocity matches the radial "
        "speed and, where neighbouring Dopplers fix it, the tangential part, so w_velocity's "
        "share sits at or above w_position's. The paper's Fig. 4 (w_velocity drops while the "
        "Doppler is below the speed) is eq. (8) in its vector form (filter.preset=paper).";
  else if (likelihood == filter::VelocityLikelihood::kRadial)
    chart.caption +=
        "This run uses the radial likelihood (velocity_likelihood=radial): a particle "
        "with the true velocity always matches the radial speed, even across the line of "
        "sight, so w_velocity's share sits at or above w_position's. The paper's Fig. 4 "
        "(w_velocity drops while the Doppler is below the speed) is eq. (8) in its vector form "
        "(filter.preset=paper), where that share falls near 0.";
  else
    chart.caption +=
        "This run uses eq. (8) in its vector form (the paper preset): it compares the whole "
        "velocity with the radial one, so where the Doppler is below the speed w_velocity "
        "favours the wrong particles and its share falls, as in the paper's Fig. 4; the "
        "default radial likelihood keeps it at or above w_position's.";
  for (const bool v : {false, true}) {
    viz::LineSeries s;
    s.name = v ? "w_velocity" : "w_position";
    s.x = trace.time;
    s.y = v ? trace.velocity_share : trace.position_share;
    s.color = viz::ModeColor(v ? viz::Mode::kVelocity : viz::Mode::kPosition);
    chart.series.push_back(std::move(s));
  }
  // Shade where most detections see less than half of the object's speed (tangential motion).
  std::optional<double> start;
  for (std::size_t i = 0; i <= trace.time.size(); ++i) {
    const bool low = i < trace.time.size() && trace.tangential_share[i] > 0.5;
    if (low && !start) start = trace.time[i];
    if (!low && start) {
      chart.spans.push_back({*start, trace.time[i - 1], "Doppler < speed / 2"});
      start.reset();
    }
  }
  if (!chart.spans.empty())
    chart.caption += " Shaded: most of the object's detections see less than half its speed.";
  if (!captions) chart.caption.clear();
  viz::RenderLineChart(chart, path.string());
}

}  // namespace dualgrid::outputs
