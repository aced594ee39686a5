// The run's pictures split in two: what they show, taken on the thread that steps the
// simulation (Make*: no cairo), and their drawing and encoding (Draw*, viz::RenderGridPanels: on
// any thread, e.g. the run's output worker). Private to the outputs library.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dualgrid/outputs/figures.hpp"
#include "dualgrid/viz/birds_eye_view.hpp"
#include "dualgrid/viz/grid_panels.hpp"

namespace dualgrid::outputs {

/// TryFigure without its printing: the warning naming `path` if the figure was not drawn.
std::optional<std::string> DrawFigure(const std::filesystem::path& path,
                                      const std::function<void()>& draw);
/// TryFigures without its printing: one warning per format not drawn, in the formats' order.
std::vector<std::string> DrawFigures(const std::filesystem::path& png_path,
                                     const std::vector<std::string>& formats,
                                     const std::function<void(const std::filesystem::path&)>& draw);
/// What TryFigure does with a warning: prints it to stderr and appends it to `warnings` (if any).
void PublishWarning(const std::string& warning, std::vector<std::string>* warnings);

/// What the bird's-eye picture of one step shows, taken from the pipeline and the simulation
/// (MakeScene, on the thread that steps them) and drawn later (DrawScene, with cairo, on any
/// thread): the viz calls' arguments, in the grid frame relative to the ego [m, m/s].
struct ScenePicture {
  viz::WorldRect world;
  viz::BirdsEyeOptions options;
  std::vector<std::pair<std::vector<Position>, double>> lanes;  ///< centre line, width [m]
  std::vector<std::vector<Position>> rails;
  OrientedBox ego_box;
  /// Parked boxes, then the radars' fields of view, then the vehicles, then the ego (drawn in
  /// this order, so later ones lie on top).
  std::vector<std::pair<OrientedBox, viz::VehicleStyle>> parked;
  std::vector<viz::SensorFov> fovs;
  std::vector<std::pair<OrientedBox, viz::VehicleStyle>> vehicles;
  viz::VehicleStyle ego_style;
  std::vector<viz::DetectionMark> detections;
  viz::DetectionStyle detection_style;
};

/// RenderScene's picture without drawing it (the arguments as RenderScene's).
ScenePicture MakeScene(const cosim::Pipeline& pipeline, double behind, double ahead,
                       double half_width, bool captions = true, const ReferenceWords& words = {});
/// Draws `scene` and writes it to `path` (.png, .svg or .pdf).
void DrawScene(const ScenePicture& scene, const std::filesystem::path& path);
/// Draws `scene` and writes it to `path` (.png, .svg or .pdf).
void DrawScene(const ScenePicture& scene, const std::filesystem::path& path);

/// The paper's Fig. 7 as viz input: one grid panel per mode (owning copies of the cells), in the
/// grid frame relative to the ego, with the captions' words; drawn by viz::RenderGridPanels.
struct GridPicture {
  std::vector<viz::GridPanel> panels;
  viz::GridFigureOptions options;
};
/// `scorers` hold each mode's clusters of this step (drawn with their roles and estimated
/// velocities beside the true velocities).
GridPicture MakeGridFigure(const std::vector<std::string>& modes,
                           const std::vector<cosim::GridSnapshot>& snapshots,
                           const std::vector<cosim::ModeScorer>& scorers,
                           const GridFrame& grid_frame, const sim::Frame& frame, double time,
                           bool captions = true, const ReferenceWords& words = {});

}  // namespace dualgrid::outputs
