// Named quantities and 2-D frame helpers shared by all dualgrid libraries.
//
// Conventions (see docs/frames.md): metres, seconds, m/s, radians. Angles are counter-clockwise
// from the +x axis of the frame they are expressed in. The world frame is SUMO's network frame
// (x east, y north). The ego frame has its origin at the ego box centre, x forward, y left.
#pragma once

#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace dualgrid {

/// Position [m].
using Position = Eigen::Vector2d;
/// Velocity [m/s].
using Velocity = Eigen::Vector2d;
/// Generic 2-D vector (offset [m], direction, ...).
using Vector2 = Eigen::Vector2d;
/// 2x2 rotation or covariance matrix.
using Matrix2 = Eigen::Matrix2d;

constexpr double kPi = std::numbers::pi;

/// Wraps an angle [rad] to (-pi, pi].
inline double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

inline double DegToRad(double deg) { return deg * kPi / 180.0; }
inline double RadToDeg(double rad) { return rad * 180.0 / kPi; }

/// Rotation matrix by yaw [rad].
inline Matrix2 Rotation(double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  Matrix2 r;
  r << c, -s, s, c;
  return r;
}

/// Unit vector at angle [rad].
inline Vector2 UnitVector(double angle) { return {std::cos(angle), std::sin(angle)}; }

/// A rigid 2-D pose: position [m] of the frame origin and yaw [rad] of its x axis, both expressed
/// in the parent frame.
struct Pose2 {
  Position position = Position::Zero();
  double yaw = 0.0;

  /// Maps a point given in this frame to the parent frame.
  Position ToParent(const Position& local) const { return position + Rotation(yaw) * local; }
  /// Maps a point given in the parent frame to this frame.
  Position ToLocal(const Position& parent) const {
    return Rotation(yaw).transpose() * (parent - position);
  }
  /// Rotates a free vector (velocity, direction) from this frame to the parent frame.
  Vector2 RotateToParent(const Vector2& v) const { return Rotation(yaw) * v; }
  /// Rotates a free vector from the parent frame to this frame.
  Vector2 RotateToLocal(const Vector2& v) const { return Rotation(yaw).transpose() * v; }
  /// Composition: `child` given in this frame, result in the parent frame.
  Pose2 Compose(const Pose2& child) const {
    return {ToParent(child.position), WrapAngle(yaw + child.yaw)};
  }
};

/// An oriented rectangle: centre [m], yaw [rad] of its length axis, length and width [m].
struct OrientedBox {
  Position center = Position::Zero();
  double yaw = 0.0;
  double length = 0.0;
  double width = 0.0;

  /// Corners counter-clockwise starting at front-left: FL, RL, RR, FR.
  std::array<Position, 4> Corners() const {
    const Vector2 f = UnitVector(yaw) * (0.5 * length);
    const Vector2 l = UnitVector(yaw + 0.5 * kPi) * (0.5 * width);
    return {center + f + l, center - f + l, center - f - l, center + f - l};
  }
  /// True if `p` lies inside or on the box. For many points, BoxTest computes the rotation once.
  bool Contains(const Position& p) const;
};

/// The box inside test with the rotation computed once (a sincos per call showed in profiles);
/// OrientedBox::Contains uses it, so both answer the same bit for bit.
class BoxTest {
 public:
  explicit BoxTest(const OrientedBox& b)
      : center_(b.center),
        rt_(Rotation(b.yaw).transpose()),
        hl_(0.5 * b.length),
        hw_(0.5 * b.width) {}
  bool Contains(const Position& p) const {
    const Vector2 d = rt_ * (p - center_);
    return std::abs(d.x()) <= hl_ && std::abs(d.y()) <= hw_;
  }

 private:
  Position center_;
  Matrix2 rt_;
  double hl_, hw_;
};

// One test for both: BoxTest's arithmetic is the definition, so they agree bit for bit.
inline bool OrientedBox::Contains(const Position& p) const { return BoxTest(*this).Contains(p); }

/// Velocity [m/s] of a point `p` of a rigid body moving with centre velocity `v` and yaw rate
/// `omega` [rad/s] about `center`: v + omega x (p - center).
inline Velocity RigidPointVelocity(const Velocity& v, double omega, const Position& center,
                                   const Position& p) {
  const Vector2 r = p - center;
  return v + omega * Vector2(-r.y(), r.x());
}

}  // namespace dualgrid
