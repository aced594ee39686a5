#include "dualgrid/viz/map_transform.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dualgrid::viz {

bool WorldRect::IsValid(std::string* error) const {
  auto fail = [&](const char* msg) {
    if (error) *error = msg;
    return false;
  };
  if (!min.allFinite()) return fail("min must be finite");
  if (!max.allFinite()) return fail("max must be finite");
  if (!(max.x() > min.x())) return fail("max.x must exceed min.x");
  if (!(max.y() > min.y())) return fail("max.y must exceed min.y");
  return true;
}

MapTransform::MapTransform(const WorldRect& world, int pixel_width, const Vector2& pixel_offset)
    : world_(world), pixel_width_(pixel_width), offset_(pixel_offset) {
  std::string error;
  if (!world.IsValid(&error)) throw std::invalid_argument("MapTransform: world." + error);
  if (pixel_width <= 0) throw std::invalid_argument("MapTransform: pixel_width must be positive");
  if (!pixel_offset.allFinite())
    throw std::invalid_argument("MapTransform: pixel_offset must be finite");
  scale_ = pixel_width / world.width();
  pixel_height_ = std::max(1, static_cast<int>(std::lround(world.height() * scale_)));
}

}  // namespace dualgrid::viz
