// The --set KEY=LIST grammar of `dualgrid sweep`.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "dualgrid/scenario/sweep_spec.hpp"

using dualgrid::scenario::ParseSweepAxis;
using dualgrid::scenario::SweepSettings;

TEST_CASE("sweep lists and ranges expand in order, exactly printed", "[sweep]") {
  auto a = ParseSweepAxis("tangential.angle=0:15:90");
  CHECK(a.key == "tangential.angle");
  CHECK(a.values == std::vector<std::string>{"0", "15", "30", "45", "60", "75", "90"});
  CHECK(a.numeric);
  // Decimal steps print as written, not as 0.30000000000000004.
  CHECK(ParseSweepAxis("k=0.1:0.1:0.3").values == std::vector<std::string>{"0.1", "0.2", "0.3"});
  // Mixed items; non-numeric values make the axis non-numeric.
  a = ParseSweepAxis("filter.preset=paper,dualgrid");
  CHECK_FALSE(a.numeric);
  CHECK(ParseSweepAxis("k=1,5:5:15,100").values ==
        std::vector<std::string>{"1", "5", "10", "15", "100"});
  // The last value of a range is included despite rounding (0:0.1:1 has 11 values).
  CHECK(ParseSweepAxis("k=0:0.1:1").values.size() == 11);
  const auto s = SweepSettings({ParseSweepAxis("a=1,2"), ParseSweepAxis("b=x,y,z")});
  REQUIRE(s.size() == 6);
  CHECK(s.front() == std::vector<std::string>{"1", "x"});
  CHECK(s[1] == std::vector<std::string>{"1", "y"});
  CHECK(s.back() == std::vector<std::string>{"2", "z"});
}

TEST_CASE("bad sweep lists name what is wrong", "[sweep]") {
  const auto why = [](const std::string& text) {
    try {
      ParseSweepAxis(text);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK(why("k").find("KEY=LIST") != std::string::npos);
  CHECK(why("=1,2").find("KEY=LIST") != std::string::npos);
  CHECK(why("k=1,,2").find("empty value") != std::string::npos);
  CHECK(why("k=3:1:1").find("empty (first > last)") != std::string::npos);
  CHECK(why("k=0:-1:3").find("step > 0") != std::string::npos);
  CHECK(why("k=0:1").find("three numbers") != std::string::npos);
  CHECK(why("k=0:1:5000").find("1,000") != std::string::npos);
  CHECK(why("k=1,2,1").find("twice") != std::string::npos);
}
