#include "dualgrid/sim/vehicle_ranges.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>

#include "dualgrid/sim/scenario.hpp"

namespace dualgrid::sim {
namespace {

using Table = std::map<std::string, NumberRange, std::less<>>;

constexpr double kMaxSumoTime = kMaxBegin + kMaxDuration;  // [s, SUMO time]
constexpr double kMaxPosition = 1e6;  // [m] along a lane: longer than any road of one net

// vType attributes, car-following parameters included (they may also sit in a nested
// <carFollowing-...> element). The first rows are the scenario's own vehicle_types keys.
const Table& VTypeTable() {
  static const Table kTable = {
      {"length", {0.0, 30.0, Interval::kLeftOpen, "m"}},
      {"width", {0.0, 4.0, Interval::kLeftOpen, "m"}},
      {"maxSpeed", {0.0, kMaxTrafficSpeed, Interval::kLeftOpen, "m/s"}},
      {"accel", {0.0, 50.0, Interval::kLeftOpen, "m/s^2"}},
      {"decel", {0.0, 50.0, Interval::kLeftOpen, "m/s^2"}},
      {"height", {0.0, 10.0, Interval::kLeftOpen, "m"}},
      {"minGap", {0.0, 100.0, Interval::kClosed, "m"}},
      {"minGapLat", {0.0, 100.0, Interval::kClosed, "m"}},
      {"maxSpeedLat", {0.0, kMaxTrafficSpeed, Interval::kLeftOpen, "m/s"}},
      {"desiredMaxSpeed", {0.0, kMaxTrafficSpeed, Interval::kLeftOpen, "m/s"}},
      {"emergencyDecel", {0.0, 100.0, Interval::kLeftOpen, "m/s^2"}},
      {"apparentDecel", {0.0, 100.0, Interval::kLeftOpen, "m/s^2"}},
      {"speedFactor", {0.0, 10.0, Interval::kLeftOpen, ""}},
      {"speedDev", {0.0, 10.0, Interval::kClosed, ""}},
      {"sigma", {0.0, 1.0, Interval::kClosed, ""}},
      {"tau", {0.0, 60.0, Interval::kLeftOpen, "s"}},
      {"actionStepLength", {0.0, 60.0, Interval::kLeftOpen, "s"}},
      {"mass", {0.0, 1e6, Interval::kLeftOpen, "kg"}},
  };
  return kTable;
}

const Table& VehicleTable() {
  static const Table kTable = {
      {"depart", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"begin", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"end", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"period", {0.0, kMaxSumoTime, Interval::kLeftOpen, "s"}},
      {"vehsPerHour", {0.0, 1e5, Interval::kLeftOpen, "vehicles/h"}},
      {"probability", {0.0, 1.0, Interval::kClosed, "per s"}},
      {"number", {0.0, 1e7, Interval::kClosed, "vehicles"}},
      {"departSpeed", {kMinTrafficSpeed, kMaxTrafficSpeed, Interval::kClosed, "m/s"}},
      {"arrivalSpeed", {kMinTrafficSpeed, kMaxTrafficSpeed, Interval::kClosed, "m/s"}},
      {"departPos", {-kMaxPosition, kMaxPosition, Interval::kClosed, "m"}},
      {"arrivalPos", {-kMaxPosition, kMaxPosition, Interval::kClosed, "m"}},
      {"departPosLat", {-100.0, 100.0, Interval::kClosed, "m"}},
      {"arrivalPosLat", {-100.0, 100.0, Interval::kClosed, "m"}},
      {"speedFactor", {0.0, 10.0, Interval::kLeftOpen, ""}},
      // <stop> (inside a vehicle, trip, flow or route)
      {"duration", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"until", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"extension", {0.0, kMaxSumoTime, Interval::kClosed, "s"}},
      {"startPos", {-kMaxPosition, kMaxPosition, Interval::kClosed, "m"}},
      {"endPos", {-kMaxPosition, kMaxPosition, Interval::kClosed, "m"}},
      {"posLat", {-100.0, 100.0, Interval::kClosed, "m"}},
  };
  return kTable;
}

std::optional<NumberRange> Find(const Table& table, std::string_view attribute) {
  const auto it = table.find(attribute);
  return it == table.end() ? std::nullopt : std::optional<NumberRange>(it->second);
}

std::string_view Trimmed(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// The whole of `text` as a number (strtod's forms, "nan" and "inf" included; out-of-range
// magnitudes become +-inf); std::nullopt when it is not one number.
std::optional<double> WholeNumber(std::string_view text) {
  const std::string s(Trimmed(text));
  if (s.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0') return std::nullopt;
  return v;
}

// SUMO's distribution form "name(a,b,...)": its arguments, or std::nullopt for another form.
std::optional<std::vector<std::string_view>> DistributionArguments(std::string_view text) {
  text = Trimmed(text);
  const auto open = text.find('(');
  if (open == std::string_view::npos || open == 0 || text.back() != ')') return std::nullopt;
  std::vector<std::string_view> args;
  std::string_view rest = text.substr(open + 1, text.size() - open - 2);
  for (std::size_t comma; (comma = rest.find(',')) != std::string_view::npos;
       rest.remove_prefix(comma + 1))
    args.push_back(rest.substr(0, comma));
  args.push_back(rest);
  return args;
}

}  // namespace

bool NumberRange::Contains(double v) const { return InInterval(v, lo, hi, ends); }

std::string NumberRange::Text() const {
  std::string out = IntervalText(lo, hi, ends);
  if (*unit != '\0') out.append(" ").append(unit);
  return out;
}

std::optional<NumberRange> VTypeAttributeRange(std::string_view attribute) {
  return Find(VTypeTable(), attribute);
}

std::optional<NumberRange> VehicleAttributeRange(std::string_view attribute) {
  return Find(VehicleTable(), attribute);
}

std::optional<std::string> SumoNumberProblem(std::string_view text, const NumberRange& range) {
  if (const auto v = WholeNumber(text)) {
    if (range.Contains(*v)) return std::nullopt;
    return "expected " + range.Text();
  }
  if (const auto args = DistributionArguments(text)) {
    for (std::string_view a : *args) {
      const auto v = WholeNumber(a);
      if (!v || !std::isfinite(*v))
        return "expected a distribution whose arguments are finite numbers";
    }
    return std::nullopt;
  }
  if (Trimmed(text).empty()) return "expected a number " + range.Text();
  return std::nullopt;  // SUMO's words ("max", "random", "triggered", "1:00:00"): SUMO judges
}

const std::vector<std::string>& SumoVehicleClasses() {
  static const std::vector<std::string> kClasses = {
      "ignoring",  "private",       "emergency", "authority", "army",     "vip",      "pedestrian",
      "passenger", "hov",           "taxi",      "bus",       "coach",    "delivery", "truck",
      "trailer",   "motorcycle",    "moped",     "bicycle",   "evehicle", "tram",     "rail_urban",
      "rail",      "rail_electric", "rail_fast", "ship",      "custom1",  "custom2"};
  return kClasses;
}

bool IsSumoVehicleClass(std::string_view vclass) {
  static const char* kDeprecated[] = {"public_emergency", "public_authority", "public_army",
                                      "public_transport", "transport",        "lightrail",
                                      "cityrail",         "rail_slow"};
  const auto& all = SumoVehicleClasses();
  return std::find(all.begin(), all.end(), vclass) != all.end() ||
         std::find(std::begin(kDeprecated), std::end(kDeprecated), vclass) != std::end(kDeprecated);
}

std::string SumoVehicleClassList() {
  std::string out = "one of: ";
  for (const std::string& c : SumoVehicleClasses())
    out += (c == SumoVehicleClasses().front() ? "" : ", ") + c;
  return out;
}

}  // namespace dualgrid::sim
