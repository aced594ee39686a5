#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/eval/aggregate.hpp"

using dualgrid::eval::ComparisonTable;
using dualgrid::eval::MakeComparisonTable;
using dualgrid::eval::MetricSpec;
using dualgrid::eval::ModeRuns;
using dualgrid::eval::PaperReference;
using dualgrid::eval::PerObjectTrackedFraction;
using dualgrid::eval::ScenarioMetrics;
using dualgrid::eval::StudentT95;
using dualgrid::eval::Summarize;
using dualgrid::eval::Summary;

TEST_CASE("Student t 0.975 quantiles match textbook values", "[aggregate]") {
  CHECK(StudentT95(1) == Approx(12.706));
  CHECK(StudentT95(9) == Approx(2.262));  // n = 10 seeds
  CHECK(StudentT95(30) == Approx(2.042));
  CHECK(StudentT95(31) == Approx(1.96));
  CHECK(StudentT95(1000) == Approx(1.96));
  CHECK_THROWS_AS(StudentT95(0), std::invalid_argument);
  // Monotone decreasing towards the normal quantile.
  const int df = GENERATE(range(1, 30));
  CHECK(StudentT95(df) > StudentT95(df + 1));
  CHECK(StudentT95(df) > 1.96);
}

TEST_CASE("Summarize gives mean, sample sd and Student-t interval", "[aggregate]") {
  // 1..10: mean 5.5, sample variance 110/12 = 9.1667, sd 3.02765.
  std::vector<double> x;
  for (int i = 1; i <= 10; ++i) x.push_back(i);
  const Summary s = Summarize(x);
  CHECK(s.n == 10);
  CHECK(s.mean == Approx(5.5));
  CHECK(s.stddev == Approx(std::sqrt(110.0 / 12.0)));
  REQUIRE(s.half_width);
  CHECK(*s.half_width == Approx(2.262 * std::sqrt(110.0 / 12.0) / std::sqrt(10.0)));
  const Summary one = Summarize(std::vector<double>{3.0});
  CHECK(one.n == 1);
  CHECK(one.mean == 3.0);
  CHECK_FALSE(one.half_width);
  CHECK(Summarize({}).n == 0);
  CHECK_THROWS_AS(Summarize(std::vector<double>{1.0, NAN}), std::invalid_argument);
}

TEST_CASE("Paper reference numbers", "[aggregate]") {
  auto get = [](std::string_view scenario, std::string_view metric, std::string_view mode) {
    for (const auto& v : PaperReference(scenario))
      if (v.metric == metric && v.mode == mode) return std::optional<double>(v.value);
    return std::optional<double>();
  };
  CHECK(*get("simple_road", "delta_x", "dual") == 0.53);
  CHECK(*get("scenarios/simple_road.yaml", "t_d", "velocity") == 0.29);
  CHECK(*get("Simple-Road", "D", "position") == 0.85);
  CHECK(*get("highway", "D", "dual") == 0.63);
  CHECK(*get("highway", "delta_v", "position") == 3.4);
  CHECK_FALSE(get("highway", "t_d", "dual"));
  CHECK(PaperReference("simple_road").size() == 12);
  CHECK(PaperReference("highway").size() == 9);
  CHECK(PaperReference("roundabout").empty());
}

TEST_CASE("Comparison table renders ours beside the paper's", "[aggregate]") {
  std::vector<ModeRuns> runs = {{"position", {}}, {"velocity", {}}, {"dual", {}}};
  for (int seed = 0; seed < 3; ++seed) {
    for (std::size_t m = 0; m < runs.size(); ++m) {
      ScenarioMetrics s;
      s.position_error = 1.0 + 0.1 * seed + static_cast<double>(m);
      s.velocity_error = 0.5;
      s.tracked_fraction = 0.9;
      s.false_clusters_per_scan = 0.25;
      if (m != 1) s.detection_time = 0.4;  // velocity mode: never consistently tracked
      dualgrid::eval::ObjectMetrics o;
      o.id = 3;
      o.scored = true;
      o.tracked_fraction = 0.5 + 0.1 * seed;
      s.objects.push_back(o);
      runs[m].seeds.push_back(s);
    }
  }
  const ComparisonTable t = MakeComparisonTable("scenarios/highway.yaml", runs);
  const Summary dx = *t.Ours("delta_x", "dual");
  CHECK(dx.n == 3);
  CHECK(dx.mean == Approx(3.1));
  CHECK(*dx.half_width == Approx(4.303 * 0.1 / std::sqrt(3.0)));
  CHECK(t.Ours("t_d", "velocity")->n == 0);
  CHECK(*t.Paper("delta_x", "dual") == 1.8);
  CHECK_FALSE(t.Paper("t_d", "dual"));
  CHECK_FALSE(t.Ours("dynamic_cell_f1", "dual"));  // no run had cell metrics

  const std::string md = t.ToMarkdown();
  CHECK(md.find("over 3 seeds (Student t)") != std::string::npos);
  // t_d is empty for velocity: the table says what a blank means.
  CHECK(md.find("— : not defined in this run") != std::string::npos);
  CHECK(md.find("| dual | dual (paper) |") != std::string::npos);
  CHECK(md.find("| D [%] | 90.0 ± 0.0 | 34.0 |") != std::string::npos);
  CHECK(md.find("| t_d [s] | 0.40 ± 0.00 | — | — | — |") != std::string::npos);
  CHECK(md.find("3.10 ± 0.25 | 1.80 |") != std::string::npos);

  const std::string csv = t.ToCsv();
  CHECK(csv.rfind("scenario,metric,unit,mode,n,mean,ci95_half_width,ci95_low,ci95_high,paper\n",
                  0) == 0);
  CHECK(csv.find("scenarios/highway.yaml,D,%,dual,3,90,0,90,90,63\n") != std::string::npos);
  CHECK(csv.find("scenarios/highway.yaml,t_d,s,velocity,0,,,,,\n") != std::string::npos);

  const nlohmann::json j = t.ToJson();
  CHECK(j.at("modes").size() == 3);
  CHECK(j.at("metrics").at(0).at("key") == "delta_x");
  CHECK(j.at("metrics").at(0).at("values").at("dual").at("paper") == 1.8);
  CHECK(j.at("metrics").at(3).at("values").at("dual").at("mean").get<double>() == Approx(90.0));

  std::vector<ScenarioMetrics> dual_seeds = runs[2].seeds;
  const auto per_object = PerObjectTrackedFraction(dual_seeds);
  REQUIRE(per_object.count(3) == 1);
  CHECK(per_object.at(3).n == 3);
  CHECK(per_object.at(3).mean == Approx(0.6));
}

TEST_CASE("A single run claims no confidence interval; notes are printed", "[aggregate]") {
  ScenarioMetrics m;
  m.tracked_fraction = 0.5;
  m.tracked_fraction_v = 0.25;
  m.position_error = 1.0;
  m.velocity_error = 1.0;
  m.box_distance = 0.0;
  m.detection_time = 0.2;
  m.objects_scored = 2;
  m.objects_never_tracked = 1;
  m.objects_never_observable = 1;
  const std::vector<ModeRuns> runs = {{"dual", {m}}};
  ComparisonTable t = MakeComparisonTable("x", runs);
  t.AddNote("Not scored: cross_1 (17 frames).");
  const std::string md = t.ToMarkdown();
  CHECK(md.find("confidence interval of the mean over") == std::string::npos);
  CHECK(md.find("One seed") != std::string::npos);
  CHECK(md.find("— : not defined") == std::string::npos);  // nothing is blank
  CHECK(md.find("Not scored: cross_1 (17 frames).") != std::string::npos);
  // Counts of one run are whole numbers.
  CHECK(md.find("| objects scored | 2 |") != std::string::npos);
  CHECK(md.find("| objects never tracked | 1 |") != std::string::npos);
  CHECK(md.find("| … of which never seen in the grid | 1 |") != std::string::npos);
  CHECK(t.ToJson().at("notes").size() == 1);
  // A mean over seeds keeps its decimal.
  ScenarioMetrics m3 = m;
  m3.objects_scored = 3;
  const std::vector<ModeRuns> two = {{"dual", {m, m3}}};
  CHECK(MakeComparisonTable("x", two).ToMarkdown().find("| objects scored | 2.5 ±") !=
        std::string::npos);
}

TEST_CASE("Comparison table misuse", "[aggregate]") {
  ComparisonTable t("x", {"a", "b"});
  t.AddMetric(MetricSpec{"m", "M", "m"});
  CHECK_THROWS_AS(t.AddMetric(MetricSpec{"m", "M2", "m"}), std::invalid_argument);
  CHECK_THROWS_AS(t.Set("nope", "a", Summary{}), std::invalid_argument);
  CHECK_THROWS_AS(t.SetPaper("m", "c", 1.0), std::invalid_argument);
  CHECK_THROWS_AS(ComparisonTable("x", {"a", "a"}), std::invalid_argument);
}
