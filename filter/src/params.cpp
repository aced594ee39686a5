#include "dualgrid/filter/params.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

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
    {BirthVelocity::kDoppler, "doppler"}, {BirthVelocity::kUniform, "uniform"}};
constexpr std::pair<ZeroLikelihood, std::string_view> kZeroNames[] = {
    {ZeroLikelihood::kKeepPrediction, "keep_prediction"}, {ZeroLikelihood::kLiteral, "literal"}};
constexpr std::pair<VelocityLikelihood, std::string_view> kLikelihoodNames[] = {
    {VelocityLikelihood::kVector, "vector"}, {VelocityLikelihood::kRadial, "radial"}};
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

namespace {

bool Fail(std::string* error, const std::string& msg) {
  if (error) *error = msg;
  return false;
}

}  // namespace

double FilterParams::MemoryBytes() const {
  const double cells = static_cast<double>(CellsX()) * CellsY();
  return 93.0 * cells + 88.0 * num_particles + 44.0 * num_birth;
}

bool FilterParams::IsValid(std::string* error) const {
  const auto finite_pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  const auto prob = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 1.0; };
  if (!finite_pos(resolution)) return Fail(error, "resolution must be finite and > 0");
  if (!finite_pos(length_x) || length_x < resolution)
    return Fail(error, "length_x must be finite and >= resolution");
  if (!finite_pos(width_y) || width_y < resolution)
    return Fail(error, "width_y must be finite and >= resolution");
  if (static_cast<double>(CellsX()) * CellsY() > 2.0e8)
    return Fail(error, "length_x/width_y/resolution give more than 2e8 cells");
  if (num_particles < 1) return Fail(error, "num_particles must be >= 1");
  if (num_birth < 0) return Fail(error, "num_birth must be >= 0");
  if (!finite_nonneg(process_noise_position))
    return Fail(error, "process_noise_position must be finite and >= 0");
  if (!finite_nonneg(process_noise_velocity))
    return Fail(error, "process_noise_velocity must be finite and >= 0");
  if (!prob(persistence) || persistence == 0.0) return Fail(error, "persistence must be in (0, 1]");
  if (!prob(birth_probability)) return Fail(error, "birth_probability must be in [0, 1]");
  if (!finite_nonneg(birth_max_tangential_speed))
    return Fail(error, "birth_max_tangential_speed must be finite and >= 0");
  if (!finite_pos(max_speed)) return Fail(error, "max_speed must be finite and > 0");
  if (!finite_nonneg(birth_sigma_radial))
    return Fail(error, "birth_sigma_radial must be finite and >= 0");
  if (!finite_pos(sigma_f)) return Fail(error, "sigma_f must be finite and > 0");
  if (!finite_pos(sigma_static_distance))
    return Fail(error, "sigma_static_distance must be finite and > 0");
  if (!finite_pos(sigma_static_velocity))
    return Fail(error, "sigma_static_velocity must be finite and > 0");
  if (!finite_pos(sigma_v)) return Fail(error, "sigma_v must be finite and > 0");
  if (!finite_pos(cutoff_sigmas)) return Fail(error, "cutoff_sigmas must be finite and > 0");
  // Masses of 1 would allow total conflict (1 - K = 0) in the Dempster-Shafer fusion.
  if (!prob(occupied_mass) || occupied_mass >= 1.0)
    return Fail(error, "occupied_mass must be in [0, 1)");
  if (!prob(free_mass) || free_mass >= 1.0) return Fail(error, "free_mass must be in [0, 1)");
  if (!prob(free_mass_no_return) || free_mass_no_return > free_mass)
    return Fail(error, "free_mass_no_return must be in [0, free_mass]");
  if (!finite_pos(free_angle_bin) || free_angle_bin > 1.0)
    return Fail(error, "free_angle_bin must be in (0, 1] rad");
  if (free_bin_dilation < 0) return Fail(error, "free_bin_dilation must be >= 0");
  if (!prob(free_decay)) return Fail(error, "free_decay must be in [0, 1]");
  if (!prob(static_persistence)) return Fail(error, "static_persistence must be in [0, 1]");
  if (!finite_nonneg(static_gain)) return Fail(error, "static_gain must be finite and >= 0");
  if (!finite_nonneg(static_speed)) return Fail(error, "static_speed must be finite and >= 0");
  if (!prob(decay_eps) || decay_eps >= 1.0) return Fail(error, "decay_eps must be in [0, 1)");
  if (mode != WeightMode::kPosition && mode != WeightMode::kVelocity && mode != WeightMode::kDual)
    return Fail(error, "mode is not a WeightMode");
  if (ToString(birth_velocity) == "unknown") return Fail(error, "birth_velocity is not a value");
  if (ToString(zero_likelihood) == "unknown") return Fail(error, "zero_likelihood is not a value");
  if (ToString(velocity_likelihood) == "unknown")
    return Fail(error, "velocity_likelihood is not a value");
  if (ToString(normalisation) == "unknown") return Fail(error, "normalisation is not a value");
  return true;
}

}  // namespace dualgrid::filter
