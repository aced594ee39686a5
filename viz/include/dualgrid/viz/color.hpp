// Colours shared by every figure, so a filter mode or a sensor looks the same everywhere.
#pragma once

#include <optional>
#include <string_view>

namespace dualgrid::viz {

/// Colour with components in [0, 1].
struct Rgba {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
  double a = 1.0;
};

namespace colors {
inline constexpr Rgba kWhite{1.0, 1.0, 1.0, 1.0};
inline constexpr Rgba kBlack{0.0, 0.0, 0.0, 1.0};
/// Grid cells whose state is unknown (no mass on free/static/dynamic).
inline constexpr Rgba kUnknown{0.5, 0.5, 0.5, 1.0};
inline constexpr Rgba kLane{0.78, 0.78, 0.78, 1.0};
inline constexpr Rgba kLaneEdge{0.55, 0.55, 0.55, 1.0};
inline constexpr Rgba kGuardRail{0.25, 0.25, 0.28, 1.0};
inline constexpr Rgba kVehicle{0.55, 0.70, 0.88, 1.0};
/// The paper draws the ego vehicle green.
inline constexpr Rgba kEgo{0.30, 0.78, 0.30, 1.0};
inline constexpr Rgba kText{0.1, 0.1, 0.1, 1.0};
inline constexpr Rgba kGridLine{0.88, 0.88, 0.88, 1.0};
}  // namespace colors

/// The three particle-weighting modes compared in the paper.
enum class Mode { kPosition, kVelocity, kDual };

/// Lower-case name: "position", "velocity", "dual".
std::string_view ModeName(Mode mode);
/// Inverse of ModeName (case-insensitive); nullopt for any other name.
std::optional<Mode> ModeFromName(std::string_view name);
/// Position blue, velocity orange, dual green.
Rgba ModeColor(Mode mode);

/// Sensor `index` (0-based) colour; cycles after 8 and avoids the three mode colours.
Rgba SensorColor(int index);
/// Outline colour of a cluster by its association role (0 matched, 1 duplicate, 2 false):
/// blue-violet, orange, magenta: no direction hue is one of them, so outlines stand out from the
/// cells (a highway's are mostly red, +x).
Rgba ClusterRoleColor(int role);
/// General categorical colour for series `index`: the mode colours first, then the sensor ones.
Rgba CategoryColor(int index);

/// Fully saturated HSV colour whose hue is the direction `angle` [rad] (CCW from +x):
/// 0 (+x) red, 2pi/3 green, -2pi/3 blue.
Rgba HueColor(double angle);
/// Sequential (viridis-like) colour map, t clamped to [0, 1]: dark purple to yellow.
Rgba SequentialColor(double t);
/// (1 - t) * a + t * b, component-wise including alpha.
Rgba Mix(const Rgba& a, const Rgba& b, double t);
/// Same colour with alpha replaced.
Rgba WithAlpha(const Rgba& c, double alpha);

}  // namespace dualgrid::viz
