#include "figures.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>

#include "dualgrid/viz/birds_eye_view.hpp"
#include "dualgrid/viz/charts.hpp"
#include "dualgrid/viz/grid_panels.hpp"
#include "output.hpp"

namespace dualgrid::tools {

bool TryFigure(const std::filesystem::path& path, const std::function<void()>& draw,
               std::vector<std::string>* warnings) {
  try {
    if (FaultInjected("figure:" + path.filename().string()))
      throw std::runtime_error("injected fault (DUALGRID_FAULT)");
    draw();
    return true;
  } catch (const std::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    const std::string warning = "figure " + path.string() + " not drawn: " + what;
    std::cerr << "dualgrid: warning: " << warning << "\n";
    if (warnings) warnings->push_back(warning);
    return false;
  }
}

namespace {

// " (grid frame: x along 152 deg)" when the picture is turned from the world, else "".
std::string FrameNote(const GridFrame& g) {
  if (g.identity()) return "";
  return "  (grid frame: x axis at " + Fixed(RadToDeg(g.yaw()), 0) + " deg from world east)";
}

}  // namespace

bool TryFigures(const std::filesystem::path& png_path, const std::vector<std::string>& formats,
                const std::function<void(const std::filesystem::path&)>& draw,
                std::vector<std::string>* warnings) {
  bool all = true;
  for (const std::string& format : formats) {
    std::filesystem::path path = png_path;
    path.replace_extension("." + format);
    all = TryFigure(
              path, [&] { draw(path); }, warnings) &&
          all;
  }
  return all;
}

void RenderScene(const Pipeline& pipeline, const std::filesystem::path& path, double behind,
                 double ahead, double half_width) {
  const sim::Frame& f = pipeline.frame();
  const GridFrame& g = pipeline.grid_frame();
  const Position c = g.ToGrid(f.ego.box.center);
  viz::BirdsEyeOptions options;
  options.title = pipeline.config().sim.name + "  t = " + Fixed(f.time, 2) + " s  (" +
                  std::to_string(pipeline.detections().size()) + " detections)" + FrameNote(g);
  viz::BirdsEyeView view({c + Position(-behind, -half_width), c + Position(ahead, half_width)},
                         options);
  auto to_grid = [&](std::vector<Position> points) {
    for (Position& p : points) p = g.ToGrid(p);
    return points;
  };
  for (const auto& lane : pipeline.simulation().LaneShapes())
    view.DrawLane(to_grid(lane.points), lane.width);
  for (const auto& rail : pipeline.config().sim.guard_rails)
    view.DrawGuardRail(to_grid(rail.points));
  for (const auto& p : pipeline.config().sim.parked) {
    viz::VehicleStyle style;
    style.fill = viz::colors::kGuardRail;
    style.label = p.id;
    view.DrawVehicle(g.ToGrid(p.box), style);
  }
  const auto& radar = pipeline.radar();
  const auto poses = radar.SensorPoses(pipeline.ego_motion().pose);
  for (std::size_t s = 0; s < poses.size(); ++s) {
    const auto& p = radar.sensors()[s];
    view.DrawSensorFov({g.ToGrid(poses[s].position), g.YawToGrid(poses[s].yaw), 0.5 * p.fov,
                        p.max_range, static_cast<int>(s), p.name});
  }
  for (const auto& v : f.vehicles) {
    viz::VehicleStyle style;
    style.label = v.id;
    // Relative motion reads better at speed.
    style.velocity = g.VectorToGrid(v.velocity - f.ego.velocity);
    view.DrawVehicle(g.ToGrid(v.box), style);
  }
  viz::VehicleStyle ego_style;
  ego_style.ego = true;
  ego_style.label = "ego";
  view.DrawVehicle(g.ToGrid(f.ego.box), ego_style);
  std::vector<viz::DetectionMark> marks;
  for (const auto& d : pipeline.detections())
    marks.push_back({g.ToGrid(d.position_world), g.VectorToGrid(d.radial_velocity_world), d.sensor,
                     d.is_clutter});
  viz::DetectionStyle style;
  style.coloring = viz::DetectionColoring::kBySpeed;
  view.DrawDetections(marks, style);
  view.Save(path.string());
}

namespace {

viz::GridRaster ToRaster(const GridSnapshot& s) {
  return {s.cells_x,    s.cells_y, s.resolution, s.origin, s.free,
          s.static_occ, s.dynamic, s.mean_vx,    s.mean_vy};
}

}  // namespace

void RenderGridFigure(const std::vector<std::string>& modes,
                      const std::vector<GridSnapshot>& snapshots, const GridFrame& g,
                      const sim::Frame& frame, double time, const std::filesystem::path& path) {
  // Axes in metres from the ego, along the grid's axes: readers compare positions with the ego,
  // not with the network's (often UTM-sized) coordinates.
  const Position ego = g.ToGrid(frame.ego.box.center);
  const auto from_ego = [&](OrientedBox b) {
    b.center -= ego;
    return b;
  };
  std::vector<viz::GridPanel> panels;
  for (std::size_t i = 0; i < modes.size(); ++i) {
    viz::GridPanel panel;
    panel.title = modes[i];
    panel.raster = ToRaster(snapshots[i]);
    panel.raster.origin -= ego;
    for (const auto& v : frame.vehicles) panel.truth_boxes.push_back(from_ego(g.ToGrid(v.box)));
    panel.ego_boxes.push_back(from_ego(g.ToGrid(frame.ego.box)));
    panels.push_back(std::move(panel));
  }
  viz::GridFigureOptions options;
  options.x_label = "x from the ego [m]";  // the grid frame's axes (its angle is in the title)
  options.y_label = "y [m]";
  options.title = "Dynamic grid at t = " + Fixed(time, 2) +
                  " s: hue = direction of motion, white free, black static, grey unknown" +
                  FrameNote(g);
  viz::RenderGridPanels(panels, path.string(), options);
}

TrackedShares RunTrackedShares(const std::vector<eval::ScenarioMetrics>& metrics,
                               const IdRegistry& ids, bool velocity_aware) {
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
                         const std::filesystem::path& path, const TrackedShares& errors) {
  viz::BarChart chart;  // with nothing scored (a very short run) the chart says "no data"
  chart.title = title;
  chart.x_label = "object";
  chart.y_label = y_label;
  chart.percent = true;
  chart.value_labels = shares.size() <= 12;
  // 60 px per bar up to a 4000 px wide image; beyond that the bars narrow (to 1 px) and the
  // object names are thinned out.
  chart.width = std::clamp(60 * static_cast<int>(shares.size() * modes.size()) + 200, 1000, 4000);
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
                       const std::filesystem::path& path) {
  viz::LineChart chart;
  chart.title = "Weights on " + object + " (" + mode + " filter): share held by particles within " +
                Fixed(WeightTrace::kGoodVelocity, 0) + " m/s of its true velocity";
  chart.y_label = "share of the weight";
  chart.y_min = 0.0;
  chart.y_max = 1.0;
  chart.series.push_back(
      {"w_position", trace.time, trace.position_share, viz::ModeColor(viz::Mode::kPosition)});
  chart.series.push_back(
      {"w_velocity", trace.time, trace.velocity_share, viz::ModeColor(viz::Mode::kVelocity)});
  // Shade where most detections see less than half of the object's speed (tangential motion).
  std::optional<double> start;
  for (std::size_t i = 0; i <= trace.time.size(); ++i) {
    const bool low = i < trace.time.size() && trace.tangential_share[i] > 0.5;
    if (low && !start) start = trace.time[i];
    if (!low && start) {
      chart.spans.push_back({*start, trace.time[i - 1], "most Doppler < 50 % of speed"});
      start.reset();
    }
  }
  viz::RenderLineChart(chart, path.string());
}

}  // namespace dualgrid::tools
