#include "dualgrid/radar_model/multipath.hpp"

#include <cmath>

#include "dualgrid/core/validation.hpp"

namespace dualgrid::radar {

std::string_view ToString(Path p) {
  switch (p) {
    case Path::kType1:
      return "type1";
    case Path::kType2:
      return "type2";
    case Path::kDirect:
      break;
  }
  return "direct";
}

bool MultipathParams::IsValid(std::string* error) const {
  FieldCheck c;
  // Up to 60 dB: beyond that no ghost of any target is ever detected, so "off" says it better.
  c.InRange("rail_loss_db", rail_loss_db, 0.0, 60.0, Interval::kClosed, "dB");
  c.InRange("vehicle_loss_db", vehicle_loss_db, 0.0, 60.0, Interval::kClosed, "dB");
  c.Positive("vehicle_min_length", vehicle_min_length, "m");
  c.InRange("max_bounces", max_bounces, 2, 3);
  c.InRange("min_pd", min_pd, 0.0, 0.01, Interval::kRightOpen);
  return c.Done(error);
}

Velocity Mirror::ImageVelocity(const Position& p, const Velocity& v) const {
  const Vector2 r = p - point;
  const Vector2 n_dot = yaw_rate * Vector2(-normal.y(), normal.x());
  return v -
         2.0 * (((v - point_velocity).dot(normal) + r.dot(n_dot)) * normal + r.dot(normal) * n_dot);
}

}  // namespace dualgrid::radar
