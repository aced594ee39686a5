// The one table of numeric ranges for vehicles: the scenario's own vehicle types
// (ScenarioSpec::IsValid) and the vTypes, vehicles, trips and flows of the user's SUMO route and
// additional files (IndexSumoFiles) are checked against the same rows, before libsumo sees them
// (libsumo asserts on a NaN length). Also SUMO's vehicle classes (vClass).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dualgrid/core/validation.hpp"

namespace dualgrid::sim {

/// An accepted interval of one attribute, in SUMO's units (metres, seconds, m/s, m/s^2).
struct NumberRange {
  double lo = 0.0;
  double hi = 0.0;
  Interval ends = Interval::kClosed;
  const char* unit = "";  ///< "m", "m/s", ... ("" for a factor)

  bool Contains(double v) const;
  /// "in (0, 30] m".
  std::string Text() const;
};

/// The range of a SUMO <vType> attribute (or of a car-following model element's attribute) by its
/// SUMO name ("length", "maxSpeed", "accel", "sigma", ...); std::nullopt for attributes that are
/// not plain numbers or not checked (ids, colours, model names).
std::optional<NumberRange> VTypeAttributeRange(std::string_view attribute);

/// The range of a numeric attribute of <vehicle>, <trip>, <flow> and <stop> ("depart",
/// "departSpeed", "period", "probability", "duration", "endPos", ...); std::nullopt as above.
/// SUMO's words ("max", "random", ...) are not numbers: CheckSumoNumber leaves them to SUMO.
std::optional<NumberRange> VehicleAttributeRange(std::string_view attribute);

/// Why the text of a SUMO numeric attribute is refused, in words that fit after
/// `attribute="text"`: ": expected in (0, 30] m"; std::nullopt when it is accepted. Plain numbers
/// (including "nan", "inf", "1e999") must lie in `range`; a distribution "name(a, b, ...)" needs
/// finite arguments and a first argument (the mean) in `range`; other words (departSpeed="max")
/// are SUMO's to judge.
std::optional<std::string> SumoNumberProblem(std::string_view text, const NumberRange& range);

/// SUMO's vehicle classes (the "abstract vehicle class" table of SUMO's documentation, "Vehicle
/// Permissions", as SUMO 1.15 reads them), in the documentation's order.
const std::vector<std::string>& SumoVehicleClasses();
/// True for one of SumoVehicleClasses() or a deprecated synonym SUMO still reads
/// ("public_transport", ...).
bool IsSumoVehicleClass(std::string_view vclass);
/// "one of: ignoring, private, ..." for messages.
std::string SumoVehicleClassList();

}  // namespace dualgrid::sim
