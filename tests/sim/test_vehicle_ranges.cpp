// The one table of vehicle ranges (sim/vehicle_ranges.hpp): every row refuses NaN, infinities,
// values beyond either end and absurd magnitudes, accepts its closed ends and the values just
// inside its open ones; the scenario's own vehicle types and the vTypes of users' SUMO files share
// the rows; SUMO's vehicle classes as SUMO 1.15 reads them.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dualgrid/core/text.hpp"
#include "dualgrid/sim/scenario.hpp"
#include "dualgrid/sim/sumo_files.hpp"
#include "dualgrid/sim/vehicle_ranges.hpp"

using namespace dualgrid;
using namespace dualgrid::sim;

namespace {

const std::vector<std::string> kVTypeAttributes = {"length",
                                                   "width",
                                                   "maxSpeed",
                                                   "accel",
                                                   "decel",
                                                   "height",
                                                   "minGap",
                                                   "minGapLat",
                                                   "maxSpeedLat",
                                                   "desiredMaxSpeed",
                                                   "emergencyDecel",
                                                   "apparentDecel",
                                                   "speedFactor",
                                                   "speedDev",
                                                   "sigma",
                                                   "tau",
                                                   "actionStepLength",
                                                   "mass"};
const std::vector<std::string> kVehicleAttributes = {
    "depart",      "begin",        "end",           "period",       "vehsPerHour",
    "probability", "number",       "departSpeed",   "arrivalSpeed", "departPos",
    "arrivalPos",  "departPosLat", "arrivalPosLat", "speedFactor",  "duration",
    "until",       "extension",    "startPos",      "endPos",       "posLat"};

bool OpenLo(const NumberRange& r) {
  return r.ends == Interval::kOpen || r.ends == Interval::kLeftOpen;
}
bool OpenHi(const NumberRange& r) {
  return r.ends == Interval::kOpen || r.ends == Interval::kRightOpen;
}

// A scenario that is valid as it stands (one route, the ego on it, the default car type).
ScenarioSpec MinimalSpec() {
  ScenarioSpec s;
  s.network.assign("simple_road");
  s.routes["r"].push_back(std::string("e"));
  s.ego.id.assign("ego");
  s.ego.route = s.routes.begin()->first;  // (a copy: GCC 12 warns on assign("r"))
  return s;
}

// The row's refusals and acceptances, as text the way a SUMO file writes it.
void CheckRow(const std::string& attribute, const NumberRange& r) {
  INFO(attribute << " " << r.Text());
  for (const char* bad : {"nan", "NaN", "inf", "-inf", "infinity", "1e999", "-1e999", ""})
    CHECK(SumoNumberProblem(bad, r));
  CHECK(SumoNumberProblem(FormatShort(r.hi + std::max(1.0, std::abs(r.hi))), r));
  CHECK(SumoNumberProblem(FormatShort(r.lo - std::max(1.0, std::abs(r.lo))), r));
  CHECK(SumoNumberProblem("1e300", r));
  CHECK(SumoNumberProblem("-1e300", r));
  // The ends: closed ones accepted, open ones refused with the value just inside accepted.
  CHECK(SumoNumberProblem(FormatShort(r.lo), r).has_value() == OpenLo(r));
  CHECK(SumoNumberProblem(FormatShort(r.hi), r).has_value() == OpenHi(r));
  const double inside_lo = OpenLo(r) ? std::nextafter(r.lo, r.hi) : r.lo;
  CHECK_FALSE(SumoNumberProblem(FormatShort(inside_lo), r));
  std::string padded(" ");
  padded.append(FormatShort(0.5 * (r.lo + r.hi))).append(" ");
  CHECK_FALSE(SumoNumberProblem(padded, r));
  // Distributions: finite arguments only; SUMO's words left to SUMO.
  CHECK(SumoNumberProblem("norm(nan,0.1)", r));
  CHECK(SumoNumberProblem("normc(1,inf,0,2)", r));
  CHECK_FALSE(SumoNumberProblem("normc(1,0.1,0.2,2)", r));
  CHECK_FALSE(SumoNumberProblem("max", r));
  // The message states the range in the row's unit.
  const auto message = SumoNumberProblem("nan", r);
  REQUIRE(message);
  CHECK(message->find(r.Text()) != std::string::npos);
}

}  // namespace

TEST_CASE("every vType row refuses NaN, inf and absurd values and accepts its ends", "[ranges]") {
  for (const std::string& a : kVTypeAttributes) {
    const auto r = VTypeAttributeRange(a);
    REQUIRE(r);
    CheckRow(a, *r);
  }
  CHECK_FALSE(VTypeAttributeRange("id"));
  CHECK_FALSE(VTypeAttributeRange("color"));
}

TEST_CASE("every vehicle, trip and flow row refuses NaN, inf and absurd values", "[ranges]") {
  for (const std::string& a : kVehicleAttributes) {
    const auto r = VehicleAttributeRange(a);
    REQUIRE(r);
    CheckRow(a, *r);
  }
  CHECK_FALSE(VehicleAttributeRange("departLane"));
}

TEST_CASE("the scenario's vehicle types use the rows of the users' vTypes", "[ranges]") {
  struct Key {
    const char* scenario_key;
    const char* sumo_attribute;
    double VehicleTypeSpec::*member;
  };
  const Key keys[] = {{"length", "length", &VehicleTypeSpec::length},
                      {"width", "width", &VehicleTypeSpec::width},
                      {"max_speed", "maxSpeed", &VehicleTypeSpec::max_speed},
                      {"accel", "accel", &VehicleTypeSpec::accel},
                      {"decel", "decel", &VehicleTypeSpec::decel}};
  for (const Key& k : keys) {
    const NumberRange r = *VTypeAttributeRange(k.sumo_attribute);
    INFO(k.scenario_key);
    for (double v : {r.hi, 0.5 * (r.lo + r.hi), r.hi * 1.01, r.lo, std::nan(""), HUGE_VAL}) {
      ScenarioSpec s = MinimalSpec();
      s.vehicle_types["car"].*k.member = v;
      std::string error;
      const bool file_accepts = !SumoNumberProblem(FormatShort(v), r);
      CHECK(s.IsValid(&error) == file_accepts);
      if (!file_accepts)
        CHECK(error.find(std::string("vehicle_types.car.") + k.scenario_key) != std::string::npos);
    }
  }
}

TEST_CASE("vClass: SUMO's classes and deprecated synonyms accepted, others refused", "[ranges]") {
  CHECK(SumoVehicleClasses().size() == 27);
  for (const std::string& c : SumoVehicleClasses()) CHECK(IsSumoVehicleClass(c));
  CHECK(IsSumoVehicleClass("public_transport"));
  for (const char* bad : {"spaceship", "", "Passenger", "passenger bus", "container", "drone"})
    CHECK_FALSE(IsSumoVehicleClass(bad));
  ScenarioSpec s = MinimalSpec();
  s.vehicle_types["car"].vclass = "spaceship";
  std::string error;
  CHECK_FALSE(s.IsValid(&error));
  CHECK(error.find("vehicle_types.car.vclass = 'spaceship'") != std::string::npos);
  CHECK(error.find("rail_fast") != std::string::npos);
}

TEST_CASE("users' SUMO files: a bad number names file, line, element, attribute and range",
          "[ranges]") {
  const auto dir = std::filesystem::temp_directory_path() / "dualgrid_test_vehicle_ranges";
  std::filesystem::create_directories(dir);
  const auto file = (dir / "t.rou.xml").string();
  struct Case {
    std::string element, expected;
  };
  const std::vector<Case> cases = {
      {"<vType id=\"a\" length=\"nan\"/>",
       ":2: <vType id=\"a\"> length=\"nan\": expected in (0, 30] m"},
      {"<vType id=\"a\"><carFollowing-Krauss sigma=\"-0.5\"/></vType>",
       "<carFollowing-Krauss> sigma=\"-0.5\": expected in [0, 1]"},
      {"<vehicle id=\"v\" depart=\"inf\"/>", "<vehicle id=\"v\"> depart=\"inf\""},
      {"<trip id=\"t\" depart=\"0\" departSpeed=\"1e300\"/>",
       "<trip id=\"t\"> departSpeed=\"1e300\""},
      {"<flow id=\"f\" begin=\"0\" end=\"10\" period=\"0\"/>", "<flow id=\"f\"> period=\"0\""},
      {"<vType id=\"a\" vClass=\"spaceship\"/>",
       "vClass=\"spaceship\": expected a SUMO vehicle class"},
  };
  for (const Case& c : cases) {
    std::ofstream(file) << "<routes>\n  " << c.element << "\n</routes>\n";
    RouteFileIndex index;
    INFO(c.element);
    try {
      IndexSumoFiles({file}, "SUMO route file", &index);
      FAIL("accepted");
    } catch (const std::invalid_argument& e) {
      CHECK(std::string(e.what()).find(file + ":") == 0);
      CHECK(std::string(e.what()).find(c.expected) != std::string::npos);
    }
  }
  // SUMO's words and good numbers pass.
  std::ofstream(file) << "<routes>\n  <vType id=\"a\" length=\"4.5\" sigma=\"0\" "
                         "speedFactor=\"normc(1,0.1,0.2,2)\"/>\n  <vehicle id=\"v\" type=\"a\" "
                         "depart=\"triggered\" departSpeed=\"max\" departPos=\"random\"/>\n"
                         "</routes>\n";
  RouteFileIndex index;
  CHECK_NOTHROW(IndexSumoFiles({file}, "SUMO route file", &index));
  std::filesystem::remove_all(dir);
}
