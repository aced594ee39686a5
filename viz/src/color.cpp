#include "dualgrid/viz/color.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>

#include "dualgrid/core/types.hpp"

namespace dualgrid::viz {
namespace {

// Tableau-10 colours: familiar, distinguishable, print well.
constexpr Rgba kModeColors[] = {
    {0.122, 0.467, 0.706, 1.0},  // position: blue
    {1.000, 0.498, 0.055, 1.0},  // velocity: orange
    {0.173, 0.627, 0.173, 1.0},  // dual: green
};
constexpr Rgba kSensorColors[] = {
    {0.580, 0.404, 0.741, 1.0},  // purple
    {0.839, 0.153, 0.157, 1.0},  // red
    {0.090, 0.745, 0.812, 1.0},  // cyan
    {0.549, 0.337, 0.294, 1.0},  // brown
    {0.890, 0.467, 0.761, 1.0},  // pink
    {0.737, 0.741, 0.133, 1.0},  // olive
    {0.498, 0.498, 0.498, 1.0},  // grey
    {0.000, 0.000, 0.545, 1.0},  // dark blue
};

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

}  // namespace

std::string_view ModeName(Mode mode) {
  switch (mode) {
    case Mode::kPosition:
      return "position";
    case Mode::kVelocity:
      return "velocity";
    case Mode::kDual:
      return "dual";
  }
  return "unknown";
}

std::optional<Mode> ModeFromName(std::string_view name) {
  for (Mode m : {Mode::kPosition, Mode::kVelocity, Mode::kDual}) {
    if (EqualsIgnoreCase(name, ModeName(m))) return m;
  }
  return std::nullopt;
}

Rgba ModeColor(Mode mode) { return kModeColors[static_cast<int>(mode)]; }

Rgba ClusterRoleColor(int role) {
  if (role == 0) return {0.20, 0.25, 1.00, 1.0};
  if (role == 1) return {1.00, 0.55, 0.00, 1.0};
  return {0.95, 0.00, 0.85, 1.0};
}

Rgba SensorColor(int index) {
  constexpr int n = static_cast<int>(std::size(kSensorColors));
  return kSensorColors[((index % n) + n) % n];
}

Rgba CategoryColor(int index) {
  constexpr int m = static_cast<int>(std::size(kModeColors));
  const int i = std::max(index, 0);
  return i < m ? kModeColors[i] : SensorColor(i - m);
}

Rgba HueColor(double angle) {
  // HSV with S = V = 1: hue in [0, 6) sextants.
  double h = std::fmod(angle, 2.0 * kPi);
  if (h < 0.0) h += 2.0 * kPi;
  h = h / (2.0 * kPi) * 6.0;
  const int sector = std::min(static_cast<int>(h), 5);
  const double f = h - sector;
  const double q = 1.0 - f, t = f;
  switch (sector) {
    case 0:
      return {1.0, t, 0.0, 1.0};
    case 1:
      return {q, 1.0, 0.0, 1.0};
    case 2:
      return {0.0, 1.0, t, 1.0};
    case 3:
      return {0.0, q, 1.0, 1.0};
    case 4:
      return {t, 0.0, 1.0, 1.0};
    default:
      return {1.0, 0.0, q, 1.0};
  }
}

Rgba SequentialColor(double t) {
  // Viridis sampled at 9 points, linearly interpolated: perceptually ordered, colour-blind safe.
  static constexpr std::array<std::array<double, 3>, 9> kStops = {{
      {0.267, 0.005, 0.329},
      {0.283, 0.141, 0.458},
      {0.254, 0.265, 0.530},
      {0.207, 0.372, 0.553},
      {0.164, 0.471, 0.558},
      {0.128, 0.567, 0.551},
      {0.135, 0.659, 0.518},
      {0.478, 0.821, 0.318},
      {0.993, 0.906, 0.144},
  }};
  if (!(t >= 0.0)) t = 0.0;  // also catches NaN
  t = std::min(t, 1.0);
  const double s = t * (kStops.size() - 1);
  const int i = std::min(static_cast<int>(s), static_cast<int>(kStops.size()) - 2);
  const double f = s - i;
  return {kStops[i][0] + f * (kStops[i + 1][0] - kStops[i][0]),
          kStops[i][1] + f * (kStops[i + 1][1] - kStops[i][1]),
          kStops[i][2] + f * (kStops[i + 1][2] - kStops[i][2]), 1.0};
}

Rgba Mix(const Rgba& a, const Rgba& b, double t) {
  return {a.r + t * (b.r - a.r), a.g + t * (b.g - a.g), a.b + t * (b.b - a.b),
          a.a + t * (b.a - a.a)};
}

Rgba WithAlpha(const Rgba& c, double alpha) { return {c.r, c.g, c.b, alpha}; }

}  // namespace dualgrid::viz
