// World-to-pixel mapping for maps: equal-aspect scale, y up in the world, y down in the image.
#pragma once

#include <string>

#include "dualgrid/core/types.hpp"

namespace dualgrid::viz {

/// Axis-aligned world rectangle [m].
struct WorldRect {
  Position min = Position::Zero();
  Position max = Position::Zero();

  double width() const { return max.x() - min.x(); }
  double height() const { return max.y() - min.y(); }
  /// False (error names the field) unless finite with max > min on both axes.
  bool IsValid(std::string* error) const;
};

/// Maps the world rectangle onto a `pixel_width` wide image area whose top-left pixel corner is at
/// `pixel_offset`; the height follows from the common scale [px/m] (equal aspect).
/// Pixel coordinates are continuous: pixel (i, j) covers [i, i+1) x [j, j+1).
class MapTransform {
 public:
  /// Throws std::invalid_argument for an invalid rectangle or a non-positive width.
  MapTransform(const WorldRect& world, int pixel_width, const Vector2& pixel_offset = {0.0, 0.0});

  const WorldRect& world() const { return world_; }
  /// Pixels per metre, the same on both axes.
  double scale() const { return scale_; }
  int pixel_width() const { return pixel_width_; }
  /// round(world height * scale), at least 1.
  int pixel_height() const { return pixel_height_; }
  const Vector2& pixel_offset() const { return offset_; }

  /// World point to pixel coordinates: world.min.x maps to offset.x, world.max.y to offset.y.
  Vector2 ToPixel(const Position& world) const {
    return {offset_.x() + (world.x() - world_.min.x()) * scale_,
            offset_.y() + (world_.max.y() - world.y()) * scale_};
  }
  /// Inverse of ToPixel.
  Position ToWorld(const Vector2& pixel) const {
    return {world_.min.x() + (pixel.x() - offset_.x()) / scale_,
            world_.max.y() - (pixel.y() - offset_.y()) / scale_};
  }
  /// A world vector (velocity arrow, offset) in pixels: scaled, y flipped.
  Vector2 VectorToPixel(const Vector2& v) const { return {v.x() * scale_, -v.y() * scale_}; }

 private:
  WorldRect world_;
  int pixel_width_;
  int pixel_height_;
  double scale_;
  Vector2 offset_;
};

}  // namespace dualgrid::viz
