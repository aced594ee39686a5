// Regression checks: parsing of metric references and orderings, bands, the record rule.
#include <catch2/catch.hpp>

#include <stdexcept>

#include "dualgrid/eval/regression.hpp"

using namespace dualgrid::eval;

TEST_CASE("metric references and orderings parse, and bad ones name the problem",
          "[eval][regression]") {
  const MetricRef r = ParseMetricRef(" highway:dual.D_v ");
  CHECK(r.case_name == "highway");
  CHECK(r.mode == "dual");
  CHECK(r.metric == "D_v");
  CHECK(r.ToString() == "highway:dual.D_v");
  const Ordering o = ParseOrdering("dual.D_v >= position.D_v - 2.5");
  CHECK(o.op == ">=");
  CHECK(o.offset == -2.5);
  CHECK(o.rhs.mode == "position");
  CHECK(ParseOrdering("velocity.delta_v < dual.delta_v").offset == 0.0);
  CHECK(ParseOrdering("a:dual.D > b:dual.D + 1").offset == 1.0);
  const auto message = [](auto f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(message([] { ParseMetricRef("dual.Dv"); }).find("unknown metric 'Dv'") !=
        std::string::npos);
  CHECK(message([] { ParseMetricRef("both.D"); }).find("unknown mode 'both'") != std::string::npos);
  CHECK(message([] { ParseMetricRef("D"); }).find("expected [case:]mode.metric") !=
        std::string::npos);
  CHECK(message([] { ParseOrdering("dual.D = position.D"); }).find("OP") != std::string::npos);
  CHECK(message([] { ParseOrdering("dual.D >= position.D - x"); }).find("offset") !=
        std::string::npos);
}

TEST_CASE("bands and orderings pass and fail on the measured means", "[eval][regression]") {
  Measured m;
  m["a"]["dual.D_v"] = {80.0, 2.0, 5};
  m["a"]["position.D_v"] = {70.0, 3.0, 5};
  m["b"]["dual.D_v"] = {60.0, std::nullopt, 1};
  Band in{{"", "dual", "D_v"}, 75.0, 85.0, {}, {}};
  Band below{{"", "position", "D_v"}, 72.0, {}, {}, {}};
  Band missing{{"", "velocity", "D_v"}, 0.0, {}, {}, {}};
  const auto v =
      CheckCase("a", {in, below, missing},
                {ParseOrdering("dual.D_v >= position.D_v + 5"),
                 ParseOrdering("dual.D_v < b:dual.D_v"), ParseOrdering("dual.D_v > c:dual.D_v")},
                m);
  REQUIRE(v.size() == 6);
  CHECK(v[0].pass);
  CHECK_FALSE(v[1].pass);
  CHECK(v[1].why.find("below 72") != std::string::npos);
  CHECK_FALSE(v[2].pass);  // not measured is a failure, with the reason
  CHECK(v[2].why.find("not measured") != std::string::npos);
  CHECK(v[3].pass);        // 80 >= 70 + 5
  CHECK_FALSE(v[4].pass);  // 80 < 60 is false
  CHECK_FALSE(v[5].pass);  // case c unknown
}

TEST_CASE("recorded bands are mean +- max(3 CI, floor) and contain the measurement",
          "[eval][regression]") {
  const Band wide = RecordBand({"", "dual", "D"}, {90.0, 1.5, 5});
  CHECK(*wide.tolerance == Approx(4.5));
  const Band floor = RecordBand({"", "dual", "D"}, {90.0, 0.1, 5});
  CHECK(*floor.tolerance == Approx(RecordFloor("D")));
  const Band one_seed = RecordBand({"", "dual", "delta_v"}, {1.234567, std::nullopt, 1});
  CHECK(*one_seed.tolerance == Approx(RecordFloor("delta_v")));
  // Property: over sampled values the recorded band always contains the mean it was made from.
  for (int k = 0; k < 200; ++k) {
    const double mean = -50.0 + 0.731 * k, hw = 0.013 * (k % 17);
    const Band b = RecordBand({"", "position", "t_d"}, {mean, hw, 3});
    Measured m;
    m["x"]["position.t_d"] = {mean, hw, 3};
    INFO("mean " << mean << " band " << b.Describe());
    CHECK(CheckCase("x", {b}, {}, m).front().pass);
  }
}
