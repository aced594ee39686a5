// Aggregation over seeds and the paper-style comparison table (metric rows x mode columns).
#pragma once

#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/eval/metrics.hpp"

namespace dualgrid::eval {

/// Two-sided 95 % critical value of Student's t distribution (the 0.975 quantile) for `df`
/// degrees of freedom: tabulated for df 1..30 (NIST/SEMATECH e-Handbook of Statistical Methods,
/// Sec. 1.3.6.7.2, "Critical values of the Student's t distribution"), 1.96 (normal) beyond.
/// Throws std::invalid_argument for df < 1.
double StudentT95(int df);

/// Mean and 95 % confidence interval of the mean over independent samples (seeds).
struct Summary {
  int n = 0;
  double mean = 0.0;                 ///< 0 when n == 0
  double stddev = 0.0;               ///< sample standard deviation (n - 1); 0 when n < 2
  std::optional<double> half_width;  ///< t_{0.975, n-1} * stddev / sqrt(n); empty when n < 2
};

/// Throws std::invalid_argument on a non-finite sample.
Summary Summarize(std::span<const double> samples);

/// Standard metric keys of the comparison table.
inline constexpr std::string_view kDeltaX = "delta_x";
inline constexpr std::string_view kDeltaV = "delta_v";
inline constexpr std::string_view kBoxDistance = "box_distance";
inline constexpr std::string_view kDetectionTime = "t_d";
inline constexpr std::string_view kTrackedFraction = "D";
inline constexpr std::string_view kTrackedFractionV = "D_v";
inline constexpr std::string_view kFalseClusters = "false_clusters_per_scan";
inline constexpr std::string_view kDuplicateClusters = "duplicate_clusters_per_scan";
inline constexpr std::string_view kScored = "objects_scored";
inline constexpr std::string_view kNeverTracked = "objects_never_tracked";
inline constexpr std::string_view kNeverObservable = "objects_never_in_coverage";
inline constexpr std::string_view kDynamicF1 = "dynamic_cell_f1";

/// One number of the paper's Tables I and II, in our units (D as a fraction in [0, 1]).
struct PaperValue {
  std::string metric;  ///< one of the keys above
  std::string mode;    ///< "position", "velocity" or "dual"
  double value = 0.0;
};

/// The paper's numbers for "simple_road" or "highway" (names are normalised: directory and
/// extension dropped, lower case, '-' and ' ' read as '_', so "scenarios/highway.yaml" works).
/// Empty for any other scenario. The highway table has no t_d.
std::vector<PaperValue> PaperReference(std::string_view scenario);

struct MetricSpec {
  std::string key;             ///< stable identifier (CSV / JSON)
  std::string label;           ///< shown in Markdown
  std::string unit;            ///< display unit
  double display_scale = 1.0;  ///< stored values are multiplied by this for display (D: 100 -> %)
  int decimals = 2;
  /// A count (objects scored): Markdown shows one seed's value as a whole number, a mean over
  /// seeds with `decimals`.
  bool count = false;
};

/// Metric rows x mode columns; each cell holds our summary over seeds and optionally the paper's
/// value. All three outputs are in display units (value x display_scale, unit as given).
class ComparisonTable {
 public:
  ComparisonTable(std::string scenario, std::vector<std::string> modes);

  /// Throws std::invalid_argument if the key exists already.
  void AddMetric(const MetricSpec& spec);
  /// Stored values are in metric units (D as fraction). Throw std::invalid_argument for an
  /// unknown metric or mode.
  void Set(std::string_view metric, std::string_view mode, const Summary& ours);
  void SetPaper(std::string_view metric, std::string_view mode, double value);
  /// Sets every PaperReference(scenario()) value whose metric and mode are in the table.
  void AttachPaperReference();
  /// A sentence printed under the Markdown table and listed in the JSON ("notes"), e.g. why a
  /// cell is empty.
  void AddNote(std::string note) { notes_.push_back(std::move(note)); }
  /// A status line printed in bold right under the heading (e.g. an incomplete run) and stored
  /// in the JSON as "status"; empty: none.
  void SetStatus(std::string status) { status_ = std::move(status); }
  const std::vector<std::string>& notes() const { return notes_; }

  std::optional<Summary> Ours(std::string_view metric, std::string_view mode) const;
  std::optional<double> Paper(std::string_view metric, std::string_view mode) const;

  const std::string& scenario() const { return scenario_; }
  const std::vector<std::string>& modes() const { return modes_; }
  const std::vector<MetricSpec>& metrics() const { return metrics_; }

  /// A heading, a table with "mode" and "mode (paper)" columns (the latter only for modes with
  /// paper numbers), cells "mean ± half-width" ("—" when empty; "(n=k)" when fewer seeds than
  /// the table's largest n contributed), a note on the interval (none for a single seed), what
  /// "—" means, and the notes.
  std::string ToMarkdown() const;
  /// Long format, one row per (metric, mode):
  /// scenario,metric,unit,mode,n,mean,ci95_half_width,ci95_low,ci95_high,paper (empty = none).
  std::string ToCsv() const;
  nlohmann::json ToJson() const;

 private:
  int MetricIndex(std::string_view metric) const;
  int ModeIndex(std::string_view mode) const;

  std::string scenario_;
  std::vector<std::string> modes_;
  std::vector<MetricSpec> metrics_;
  std::vector<std::vector<std::optional<Summary>>> ours_;  // [metric][mode]
  std::vector<std::vector<std::optional<double>>> paper_;
  std::vector<std::string> notes_;
  std::string status_;
};

/// The runs (one ScenarioMetrics per seed) of one filter mode.
struct ModeRuns {
  std::string mode;
  std::vector<ScenarioMetrics> seeds;
};

/// The standard table: Delta x [m], Delta v [m/s], t_d [s], D [%], D_v [%], false and duplicate
/// clusters per scan, objects scored, objects never tracked (scored, never consistently tracked)
/// and of those never in any radar's coverage, and the dynamic-cell F1 when any run has cell
/// metrics. Each cell summarises the seeds where the metric is defined (Summary::n says how many).
/// Paper numbers are attached when the scenario is known. Columns follow the order of `runs`.
ComparisonTable MakeComparisonTable(std::string_view scenario, std::span<const ModeRuns> runs);

/// Per object id: D summarised over the seeds in which that object was scored (for the paper's
/// Fig. 6). Meaningful when object ids denote the same vehicle in every seed. `velocity_aware`:
/// D_v instead of D.
std::map<int, Summary> PerObjectTrackedFraction(std::span<const ScenarioMetrics> seeds,
                                                bool velocity_aware = false);

void to_json(nlohmann::json& j, const Summary& s);

}  // namespace dualgrid::eval
