// Bird's-eye map of the scene: lanes, guard rails, vehicles, radar fields of view and detections,
// laid out in points at a column width (dualgrid/viz/figure.hpp), with axes in metres.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/figure.hpp"
#include "dualgrid/viz/map_transform.hpp"

namespace dualgrid::viz {

struct BirdsEyeOptions {
  /// Image width [pt] (PNG: times png_scale), axis margin included; the map height follows from
  /// the world rectangle (equal aspect).
  int pixel_width = static_cast<int>(kSingleColumn);
  /// Drawn in a band above the map when not empty (wrapped).
  std::string title;
  /// Base font size [pt] (axis labels; titles 1.05x, ticks, legend, labels and caption 0.9x);
  /// 0: BaseFontSize(pixel_width), readable at one column.
  double font_size = 0.0;
  /// Metre ticks left of and under the map, labelled with the world coordinates (a caller that
  /// draws relative to the ego passes relative coordinates); without axes a scale bar.
  bool axes = true;
  std::string x_label = "x [m]", y_label = "y [m]";
  /// Wrapped under the legend when not empty: frames of the arrows, meaning of the colours.
  std::string caption;
  double png_scale = kPngScale;  ///< PNG pixels per point
  bool IsValid(std::string* error) const;
  /// font_size, or the automatic one.
  double BaseFont() const;
};

/// How vehicles are drawn.
struct VehicleStyle {
  Rgba fill = colors::kVehicle;
  /// Drawn next to the box when not empty (e.g. the SUMO id or "obj 3").
  std::string label;
  /// Ego: green fill, thicker outline, own legend entry.
  bool ego = false;
  /// Legend entry of the box in its fill colour; empty: "vehicle" (or "ego").
  std::string legend;
  /// Optional ground-truth velocity [m/s] drawn as an arrow of length v * arrow_scale [s]; its
  /// legend entry says "velocity" unless `velocity_legend` says otherwise (a caption says in which
  /// frame).
  std::optional<Velocity> velocity;
  double arrow_scale = 0.5;
  std::string velocity_legend;
};

/// Opacity of a field of view's fill; its outline is opaque, so overlapping wedges stay readable.
inline constexpr double kSensorFovTint = 0.05;

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
  /// Arrow = radial_velocity * arrow_scale [s] (the same scale as the vehicles' arrows keeps the
  /// two comparable); 0 disables arrows.
  double arrow_scale = 0.5;
  /// Clutter is a small cross without an arrow unless set: its Doppler is noise, and its long
  /// random arrows would dominate the picture.
  bool clutter_arrows = false;
  /// Dot radius [pt at one column width; scaled with the figure].
  double radius_px = 1.1;
  bool IsValid(std::string* error) const;
};

/// Immediate-mode map canvas: each Draw call paints onto the map at once (later calls on top);
/// the title band, axes, legend band (with entries collected from the calls) and caption are
/// added by Save. Image layout, top to bottom: title band (if any), map with its axes, legend
/// band, caption.
class BirdsEyeView {
 public:
  /// Throws std::invalid_argument (naming the field) for a bad rectangle or options.
  BirdsEyeView(const WorldRect& world, const BirdsEyeOptions& options = {});
  ~BirdsEyeView();
  BirdsEyeView(const BirdsEyeView&) = delete;
  BirdsEyeView& operator=(const BirdsEyeView&) = delete;

  /// Map-area transform (pixel offset 0: map coordinates).
  const MapTransform& transform() const;
  /// World point to coordinates of the saved image [pt] (the map is shifted by the title band and
  /// the axis margin; PNG pixels: times png_scale).
  Vector2 ToImagePixel(const Position& world) const;
  int image_width() const;
  /// Height of the image Save would write now [pt] (depends on the legend entries so far).
  int image_height() const;

  /// A lane centre line with its width [m]: light grey band with a darker edge.
  void DrawLane(const std::vector<Position>& centre_line, double width);
  /// A guard rail (or any barrier) polyline, dark, `width` [m] (at least 2 px).
  void DrawGuardRail(const std::vector<Position>& polyline, double width = 0.3);
  /// A vehicle's box, heading mark, velocity arrow and label. Labels never overlap each other
  /// or the ego's box (KeepLabelsOff): each goes above or below its box, stepped further out
  /// with a leader line when that is taken; a label with no free place is left out (counted).
  /// The ego's box, when drawn, is kept clear of later labels.
  void DrawVehicle(const OrientedBox& box, const VehicleStyle& style = {});
  /// Keeps the labels drawn from now on off `box` (e.g. the ego's, drawn last on top).
  void KeepLabelsOff(const OrientedBox& box);
  /// The pixel boxes [x0, y0, x1, y1] of the labels placed so far (and the boxes kept clear),
  /// and how many labels found no free place.
  std::vector<std::array<double, 4>> label_boxes() const;
  int labels_left_out() const;
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
