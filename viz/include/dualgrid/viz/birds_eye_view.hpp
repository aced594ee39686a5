// Bird's-eye map of the scene: lanes, guard rails, vehicles, radar fields of view and detections.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/map_transform.hpp"

namespace dualgrid::viz {

struct BirdsEyeOptions {
  /// Image width [px]; the map height follows from the world rectangle (equal aspect).
  int pixel_width = 1600;
  /// Drawn in a band above the map when not empty.
  std::string title;
  /// Font size [px] of title (x1.3), legend and labels.
  double font_size = 14.0;
  bool IsValid(std::string* error) const;
};

/// How vehicles are drawn.
struct VehicleStyle {
  Rgba fill = colors::kVehicle;
  /// Drawn next to the box when not empty (e.g. the SUMO id or "obj 3").
  std::string label;
  /// Ego: green fill, thicker outline, own legend entry.
  bool ego = false;
  /// Optional ground-truth velocity [m/s] drawn as an arrow of length v * arrow_scale [s].
  std::optional<Velocity> velocity;
  double arrow_scale = 0.5;
};

/// A radar field of view: a wedge from `origin` around `boresight` (world frame).
struct SensorFov {
  Position origin = Position::Zero();
  double boresight = 0.0;  ///< [rad], world frame
  double half_fov = 0.0;   ///< [rad], in (0, pi]
  double max_range = 0.0;  ///< [m]
  int sensor_index = 0;    ///< picks SensorColor(sensor_index)
  std::string name;        ///< legend label, e.g. "front LRR"; "sensor <i>" when empty
};

/// One radar detection in the world frame.
struct DetectionMark {
  Position position = Position::Zero();
  /// Ego-motion compensated radial velocity vector [m/s] in the world frame (along the line of
  /// sight); its norm is |compensated radial speed|.
  Velocity radial_velocity = Velocity::Zero();
  int sensor_index = 0;
  /// Clutter (false alarm) is drawn as a cross instead of a dot.
  bool clutter = false;
};

enum class DetectionColoring {
  kBySensor,  ///< SensorColor(sensor_index)
  kBySpeed,   ///< SequentialColor(|radial_velocity| / max_speed) with a colour bar
};

struct DetectionStyle {
  DetectionColoring coloring = DetectionColoring::kBySensor;
  /// Speed mapped to the top of the colour map [m/s] (kBySpeed).
  double max_speed = 40.0;
  /// Arrow = radial_velocity * arrow_scale [s]; 0 disables arrows.
  double arrow_scale = 0.2;
  /// Dot radius [px].
  double radius_px = 2.5;
  bool IsValid(std::string* error) const;
};

/// Immediate-mode map canvas: each Draw call paints onto the map at once (later calls on top);
/// the title band, legend band (with entries collected from the calls) and scale bar are added by
/// Save. Image layout, top to bottom: title band (if any), map, legend band.
class BirdsEyeView {
 public:
  /// Throws std::invalid_argument (naming the field) for a bad rectangle or options.
  BirdsEyeView(const WorldRect& world, const BirdsEyeOptions& options = {});
  ~BirdsEyeView();
  BirdsEyeView(const BirdsEyeView&) = delete;
  BirdsEyeView& operator=(const BirdsEyeView&) = delete;

  /// Map-area transform (pixel offset 0: map coordinates).
  const MapTransform& transform() const;
  /// World point to pixel coordinates of the saved image (the map is shifted by the title band).
  Vector2 ToImagePixel(const Position& world) const;
  int image_width() const;
  /// Height of the image Save would write now (depends on the legend entries so far).
  int image_height() const;

  /// A lane centre line with its width [m]: light grey band with a darker edge.
  void DrawLane(const std::vector<Position>& centre_line, double width);
  /// A guard rail (or any barrier) polyline, dark, `width` [m] (at least 2 px).
  void DrawGuardRail(const std::vector<Position>& polyline, double width = 0.3);
  void DrawVehicle(const OrientedBox& box, const VehicleStyle& style = {});
  void DrawSensorFov(const SensorFov& fov);
  void DrawDetections(const std::vector<DetectionMark>& detections,
                      const DetectionStyle& style = {});
  /// Free text at a world position (e.g. a time stamp), left-aligned, with a white halo.
  void DrawLabel(const Position& at, const std::string& text);

  /// Writes the picture as PNG, SVG or PDF by the path's extension (.png, .svg, .pdf; vectors
  /// through cairo's own surfaces). Throws std::invalid_argument for another extension and
  /// std::runtime_error on a failed write.
  void Save(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dualgrid::viz
