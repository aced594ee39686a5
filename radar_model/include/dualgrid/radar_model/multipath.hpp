// Specular multipath ("ghosts") off guard rails and the flat sides of large vehicles: the
// parameters, the path labels and the mirror geometry (docs/radar.md, "Multipath").
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "dualgrid/core/types.hpp"

namespace dualgrid::radar {

/// The way a detection's signal travelled, in the labels of the Radar Ghost Dataset (Kraus et al.,
/// IROS 2021): a type-1 ghost's last bounce is on the real object, a type-2 ghost's on the
/// reflector. Order (bounces) 2: one leg direct, one leg via the reflector; order 3 (type 2 only):
/// both legs via the reflector.
enum class Path : std::uint8_t {
  kDirect = 0,  ///< sensor -> object -> sensor (and clutter)
  kType1 = 1,   ///< order 2, arrives from the object's direction
  kType2 = 2,   ///< order 2 or 3, arrives from the mirror image's direction
};
/// "direct", "type1", "type2".
std::string_view ToString(Path p);

/// Switches and constants of the multipath model. Off by default: the paper's simulation had
/// none, and with it off every output is the same as before multipath existed.
struct MultipathParams {
  bool enabled = false;
  bool rails = true;     ///< guard-rail segments are mirrors
  bool vehicles = true;  ///< the long sides of boxes at least vehicle_min_length long are mirrors
  /// Power lost per bounce [dB] (20 log10 of 1 / |reflection coefficient|); docs/radar.md gives
  /// the reasoning behind the defaults.
  double rail_loss_db = 6.0;
  double vehicle_loss_db = 3.0;
  double vehicle_min_length = 8.0;  ///< [m] trucks and buses, not vans or cars
  /// 2: only the order-2 paths (type 1 and type 2); 3: also the order-3 type-2 mirror image.
  int max_bounces = 3;
  /// A ghost scatterer whose SNR alone gives a detection probability below this is dropped
  /// before its occlusion tests (a cost cut; 1/16 of that SNR is used, so that even 16 such
  /// scatterers merged in one resolution cell stay below it). 0 keeps every ghost scatterer.
  double min_pd = 1e-4;

  /// False with a message naming the offending field if a value is out of range.
  bool IsValid(std::string* error) const;
};

/// A plane mirror seen from above (a line), possibly moving rigidly: `point` on the line moves
/// with `point_velocity` and the line turns at `yaw_rate` (a truck's flank). Invariant: `normal`
/// is a unit vector.
struct Mirror {
  Position point = Position::Zero();           ///< a point of the line [m]
  Vector2 normal = Vector2::UnitY();           ///< unit normal
  Velocity point_velocity = Velocity::Zero();  ///< [m/s]
  double yaw_rate = 0.0;                       ///< [rad/s]

  /// Signed distance [m] of `p` from the line, positive on the side `normal` points to.
  double SignedDistance(const Position& p) const { return (p - point).dot(normal); }
  /// The mirror image p' = p - 2 ((p - q).n) n.
  Position Image(const Position& p) const { return p - 2.0 * SignedDistance(p) * normal; }
  /// Velocity [m/s] of the image of a point at `p` moving with `v`: the time derivative of
  /// Image(p), v' = v - 2 [((v - u).n + (p - q).n_dot) n + ((p - q).n) n_dot] with u the
  /// velocity of q and n_dot = yaw_rate x n; for a static mirror v' = v - 2 (v.n) n.
  Velocity ImageVelocity(const Position& p, const Velocity& v) const;
};

}  // namespace dualgrid::radar
