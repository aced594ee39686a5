// Regression checks on aggregated metrics (`dualgrid regress`, docs/regression.md): bands on a
// metric of a mode, and orderings between modes or cases. Inputs are the measured means and 95 %
// confidence half-widths of an experiment's table; nothing here runs anything.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dualgrid::eval {

/// Metric keys of an experiment's table.csv / table.json that checks may name.
const std::vector<std::string>& RegressionMetricNames();
/// True for "position", "velocity", "dual".
bool IsModeName(std::string_view mode);

/// "[case:]mode.metric". An empty case_name means the case the check belongs to.
struct MetricRef {
  std::string case_name;
  std::string mode;
  std::string metric;
  std::string ToString() const;
};
/// Parses "[case:]mode.metric"; throws std::invalid_argument naming what is wrong (unknown mode or
/// metric, missing parts).
MetricRef ParseMetricRef(const std::string& text);

/// A band on one metric: min <= mean <= max (either side may be open). `reference` and
/// `tolerance` are kept when the band was given as reference +- tolerance, for the report.
struct Band {
  MetricRef metric;
  std::optional<double> min, max;
  std::optional<double> reference, tolerance;
  std::string Describe() const;  ///< "[1.2, 3.4]", ">= 80", "1.5 ± 0.3"
};

/// "lhs OP rhs [+|- offset]", OP one of >=, <=, >, <. Holds when mean(lhs) OP mean(rhs) + offset.
struct Ordering {
  MetricRef lhs, rhs;
  std::string op;
  double offset = 0.0;
  std::string text;  ///< as written
};
/// Throws std::invalid_argument naming what is wrong.
Ordering ParseOrdering(const std::string& text);

struct MetricValue {
  double mean = 0.0;
  std::optional<double> half_width;  ///< 95 % CI half-width; empty for one seed
  int n = 0;
};
/// case -> "mode.metric" -> value.
using Measured = std::map<std::string, std::map<std::string, MetricValue>>;

struct Verdict {
  std::string case_name;
  std::string check;     ///< "dual.D_v in [80, 95]" or the ordering's text
  std::string expected;  ///< the band or the ordering's right-hand side value
  std::string measured;  ///< "85.2 ± 1.3"
  bool pass = false;
  std::string why;  ///< for a failure (or a missing value)
};

/// Checks `bands` and `orderings` of case `case_name` against `measured`. A check whose metric
/// was not measured (a case that failed, a metric undefined in the run: e.g. t_d with no tracked
/// object) fails with the reason.
std::vector<Verdict> CheckCase(const std::string& case_name, const std::vector<Band>& bands,
                               const std::vector<Ordering>& orderings, const Measured& measured);

/// The band a `--record` run writes for a measured value: mean +- max(3 x CI half-width, floor),
/// floor = RecordFloor(metric) (the smallest change worth flagging; with one seed the floor alone).
Band RecordBand(const MetricRef& metric, const MetricValue& value);
double RecordFloor(const std::string& metric);

}  // namespace dualgrid::eval
