#include "dualgrid/filter/params.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "dualgrid/core/text.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::filter {

std::string_view ToString(WeightMode mode) {
  switch (mode) {
    case WeightMode::kPosition:
      return "position";
    case WeightMode::kVelocity:
      return "velocity";
    case WeightMode::kDual:
      return "dual";
  }
  return "unknown";
}

std::optional<WeightMode> ParseWeightMode(std::string_view name) {
  for (WeightMode m : {WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual}) {
    if (ToString(m) == name) return m;
  }
  return std::nullopt;
}

namespace {

// One name table per switch: ToString and Parse read the same pairs.
template <typename E, std::size_t N>
std::string_view NameOf(const std::pair<E, std::string_view> (&table)[N], E v) {
  for (const auto& [e, name] : table)
    if (e == v) return name;
  return "unknown";
}
template <typename E, std::size_t N>
std::optional<E> ValueOf(const std::pair<E, std::string_view> (&table)[N], std::string_view name) {
  for (const auto& [e, n] : table)
    if (n == name) return e;
  return std::nullopt;
}
constexpr std::pair<BirthVelocity, std::string_view> kBirthNames[] = {
    {BirthVelocity::kDoppler, "doppler"},
    {BirthVelocity::kUniform, "uniform"},
    {BirthVelocity::kDopplerFit, "doppler_fit"}};
constexpr std::pair<ZeroLikelihood, std::string_view> kZeroNames[] = {
    {ZeroLikelihood::kKeepPrediction, "keep_prediction"}, {ZeroLikelihood::kLiteral, "literal"}};
constexpr std::pair<VelocityLikelihood, std::string_view> kLikelihoodNames[] = {
    {VelocityLikelihood::kVector, "vector"},
    {VelocityLikelihood::kRadial, "radial"},
    {VelocityLikelihood::kRadialFit, "radial_fit"}};
constexpr std::pair<Normalisation, std::string_view> kNormNames[] = {
    {Normalisation::kPerCell, "per_cell"}, {Normalisation::kLiteral, "literal"}};

}  // namespace

std::string_view ToString(BirthVelocity v) { return NameOf(kBirthNames, v); }
std::string_view ToString(ZeroLikelihood v) { return NameOf(kZeroNames, v); }
std::string_view ToString(VelocityLikelihood v) { return NameOf(kLikelihoodNames, v); }
std::string_view ToString(Normalisation v) { return NameOf(kNormNames, v); }
std::optional<BirthVelocity> ParseBirthVelocity(std::string_view n) {
  return ValueOf(kBirthNames, n);
}
std::optional<ZeroLikelihood> ParseZeroLikelihood(std::string_view n) {
  return ValueOf(kZeroNames, n);
}
std::optional<VelocityLikelihood> ParseVelocityLikelihood(std::string_view n) {
  return ValueOf(kLikelihoodNames, n);
}
std::optional<Normalisation> ParseNormalisation(std::string_view n) {
  return ValueOf(kNormNames, n);
}

std::optional<FilterParams> Preset(std::string_view name) {
  FilterParams p;
  if (name == "default" || name == "dualgrid") return p;
  if (name == "paper") {
    p.birth_velocity = BirthVelocity::kUniform;
    p.zero_likelihood = ZeroLikelihood::kLiteral;
    p.velocity_likelihood = VelocityLikelihood::kVector;
    p.normalisation = Normalisation::kLiteral;
    return p;
  }
  return std::nullopt;
}

std::string_view PresetNames() { return "default, dualgrid, paper"; }

int FilterParams::CellsX() const {
  return std::max(1, static_cast<int>(std::lround(length_x / resolution)));
}
int FilterParams::CellsY() const {
  return std::max(1, static_cast<int>(std::lround(width_y / resolution)));
}

double FilterParams::MemoryBytes() const {
  // Counted in double: also meaningful (huge) for sizes IsValid refuses, where int would overflow.
  const double cells = std::max(1.0, std::round(length_x / resolution)) *
                       std::max(1.0, std::round(width_y / resolution));
  return 94.0 * cells + 72.0 * num_particles + 36.0 * num_birth;
}

FilterParams ForCycle(const FilterParams& p, double dt) {
  FilterParams c = p;
  // The reference cycle keeps the factors bit for bit (no pow(x, 1.0) round trip).
  if (std::abs(dt - p.cycle) <= 1e-9 * p.cycle) return c;
  const double r = dt / p.cycle;
  c.persistence = std::pow(p.persistence, r);
  c.static_persistence = std::pow(p.static_persistence, r);
  c.free_decay = std::pow(p.free_decay, r);
  c.decay_eps = 1.0 - std::pow(1.0 - p.decay_eps, r);
  c.birth_probability = 1.0 - std::pow(1.0 - p.birth_probability, r);
  return c;
}

bool FilterParams::IsValid(std::string* error) const {
  FieldCheck c;
  c.Positive("resolution", resolution, "m");
  c.Expect(std::isfinite(length_x) && length_x >= resolution, "length_x", length_x,
           "finite and >= resolution = " + FormatShort(resolution) + " m");
  c.Expect(std::isfinite(width_y) && width_y >= resolution, "width_y", width_y,
           "finite and >= resolution = " + FormatShort(resolution) + " m");
  if (c.ok()) {
    // Counted in double before CellsX/CellsY round to int (1e300 / 0.1 would overflow it); each
    // side names its key, the product all three.
    const double nx = std::round(length_x / resolution), ny = std::round(width_y / resolution);
    const std::string per_cell = " / resolution = " + FormatShort(resolution) + " m: ";
    c.Expect(nx <= kMaxCells, "length_x", length_x,
             "at most " + FormatShort(kMaxCells) + " cells along x (length_x" + per_cell +
                 FormatShort(nx) + " cells)");
    c.Expect(ny <= kMaxCells, "width_y", width_y,
             "at most " + FormatShort(kMaxCells) + " cells along y (width_y" + per_cell +
                 FormatShort(ny) + " cells)");
    c.Expect(nx * ny <= kMaxCells, "length_x/width_y/resolution",
             FormatShort(length_x) + "/" + FormatShort(width_y) + "/" + FormatShort(resolution) +
                 " m (" + FormatShort(nx * ny) + " cells)",
             "at most " + FormatShort(kMaxCells) + " cells (about " +
                 FormatShort(kMaxCells * 94.0 / 1e9) + " GB)");
  }
  c.AtLeast("num_particles", num_particles, 1);
  c.AtLeast("num_birth", num_birth, 0);
  c.NonNegative("process_noise_position", process_noise_position);
  c.NonNegative("process_noise_velocity", process_noise_velocity);
  c.InRange("persistence", persistence, 0.0, 1.0, Interval::kLeftOpen);
  c.InRange("birth_probability", birth_probability, 0.0, 1.0);
  c.NonNegative("birth_max_tangential_speed", birth_max_tangential_speed, "m/s");
  c.Positive("max_speed", max_speed, "m/s");
  c.NonNegative("birth_sigma_radial", birth_sigma_radial, "m/s");
  c.Positive("doppler_fit_radius", doppler_fit_radius, "m");
  c.Positive("doppler_fit_sigma", doppler_fit_sigma, "m/s");
  c.InRange("birth_fit_uniform_share", birth_fit_uniform_share, 0.0, 1.0);
  c.Positive("sigma_f", sigma_f, "m");
  c.Positive("sigma_static_distance", sigma_static_distance, "m");
  c.Positive("sigma_static_velocity", sigma_static_velocity, "m/s");
  c.Positive("sigma_v", sigma_v, "m/s");
  c.Positive("cutoff_sigmas", cutoff_sigmas);
  // Masses of 1 would allow total conflict (1 - K = 0) in the Dempster-Shafer fusion.
  c.InRange("occupied_mass", occupied_mass, 0.0, 1.0, Interval::kRightOpen);
  c.InRange("free_mass", free_mass, 0.0, 1.0, Interval::kRightOpen);
  c.Expect(free_mass_no_return >= 0.0 && free_mass_no_return <= free_mass, "free_mass_no_return",
           free_mass_no_return, "in [0, free_mass = " + FormatShort(free_mass) + "]");
  c.InRange("free_angle_bin", free_angle_bin, 0.0, 1.0, Interval::kLeftOpen, "rad");
  c.AtLeast("free_bin_dilation", free_bin_dilation, 0);
  c.InRange("free_decay", free_decay, 0.0, 1.0);
  c.InRange("static_persistence", static_persistence, 0.0, 1.0);
  c.NonNegative("static_gain", static_gain);
  c.NonNegative("static_speed", static_speed, "m/s");
  c.InRange("decay_eps", decay_eps, 0.0, 1.0, Interval::kRightOpen);
  c.Expect(std::isfinite(cycle) && cycle > 0.0, "cycle", cycle, "finite and > 0 s");
  const auto check_enum = [&](std::string_view field, auto value, std::string_view name,
                              std::string_view expected) {
    c.Expect(name != "unknown", field, std::to_string(static_cast<int>(value)), expected);
  };
  check_enum("mode", mode, ToString(mode), "position, velocity or dual");
  check_enum("birth_velocity", birth_velocity, ToString(birth_velocity),
             "doppler, uniform or doppler_fit");
  check_enum("zero_likelihood", zero_likelihood, ToString(zero_likelihood),
             "keep_prediction or literal");
  check_enum("velocity_likelihood", velocity_likelihood, ToString(velocity_likelihood),
             "vector, radial or radial_fit");
  check_enum("normalisation", normalisation, ToString(normalisation), "per_cell or literal");
  return c.Done(error);
}

}  // namespace dualgrid::filter
