#include "dualgrid/viz/map_transform.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/validation.hpp"
namespace dualgrid::viz {

bool WorldRect::IsValid(std::string* error) const {
  FieldCheck c;
  c.Expect(min.allFinite(), "min", FormatTuple({min.x(), min.y()}), "finite");
  c.Expect(max.allFinite(), "max", FormatTuple({max.x(), max.y()}), "finite");
  c.Expect(max.x() > min.x(), "max.x", max.x(), "> min.x = " + FormatShort(min.x()));
  c.Expect(max.y() > min.y(), "max.y", max.y(), "> min.y = " + FormatShort(min.y()));
  return c.Done(error);
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
