// One frame of a replay video (docs/replay.md): the modes' grids side by side or stacked, with
// ground-truth boxes, cluster outlines with their estimated velocity arrows, optionally particles
// and detections per sensor, the time stamp and per-mode live metrics. Drawn into a raster the
// caller pipes to a video encoder; nothing here knows files or the recording format.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/viz/grid_panels.hpp"

namespace dualgrid::viz {

/// A cluster outline: the members' bounding box [m] and the cluster's mean velocity over ground
/// [m/s]; `role` 0 matched to an object, 1 duplicate, 2 false.
struct ReplayCluster {
  Position min = Position::Zero(), max = Position::Zero(), center = Position::Zero();
  Velocity velocity = Velocity::Zero();
  int role = 0;
};

struct ReplayDetection {
  Position position = Position::Zero();  ///< [m]
  int sensor = 0;                        ///< colour SensorColor(sensor)
};

/// One mode's panel. All positions relative to the ego, in the grid frame [m]; velocities over
/// ground [m/s].
struct ReplayPanel {
  std::string title;  ///< the mode
  std::string live;   ///< live metrics line drawn beside the title
  GridRaster raster;  ///< origin relative to the ego
  std::vector<OrientedBox> truth;
  std::vector<Velocity> truth_velocity;  ///< per truth box
  std::vector<ReplayCluster> clusters;
  std::vector<Position> particles;  ///< empty: not drawn
};

struct ReplayPicture {
  std::string heading;  ///< e.g. "highway · seed 1"
  double time = 0.0;    ///< [s]
  OrientedBox ego;      ///< centred at the origin
  std::vector<ReplayPanel> panels;
  std::vector<ReplayDetection> detections;  ///< drawn on every panel
  std::string banner;                       ///< e.g. "INCOMPLETE RUN", drawn in red when set
};

struct ReplayLayoutOptions {
  int width = 1920;  ///< [px], even (video encoders need even sizes)
  /// The view, relative to the ego [m]: usually the grid's extent at the first frame.
  WorldRect view;
  int panels = 3;
  double arrow_seconds = 0.5;  ///< an arrow is this many seconds of travel [s]
  /// Sensor names for the legend (pictures' detections index them); the legend wraps to as many
  /// rows as the width needs.
  std::vector<std::string> sensors;
  bool particles = false;  ///< pictures carry particles: a legend entry for them
  /// The legend's name of the reference boxes (ReplayPanel::truth): "ground truth" for SUMO,
  /// the figures' word for recorded data (GridFigureOptions::truth_label). Not empty.
  std::string truth_label = "ground truth";
  /// Throws std::invalid_argument naming the field.
  void Validate() const;
};

/// Renders frames of one fixed layout into a reused BGRA raster (cairo ARGB32, little-endian).
/// Not thread-safe; one per encoder.
class ReplayRenderer {
 public:
  explicit ReplayRenderer(const ReplayLayoutOptions& options);
  ~ReplayRenderer();
  ReplayRenderer(const ReplayRenderer&) = delete;
  ReplayRenderer& operator=(const ReplayRenderer&) = delete;

  int width() const;
  int height() const;  ///< even
  /// Where panel i's map lies in the frame [px] (for tests: a cell's pixel).
  Vector2 ToPixel(std::size_t panel, const Position& relative) const;
  /// Draws `picture` (its panel count must equal options.panels). Returns the raster: height
  /// rows of width * 4 bytes (B, G, R, A), valid until the next Render.
  const std::uint8_t* Render(const ReplayPicture& picture);
  /// Writes the last rendered frame as PNG (for tests and docs).
  void SavePng(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dualgrid::viz
