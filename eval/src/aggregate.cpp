#include "dualgrid/eval/aggregate.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "dualgrid/core/text.hpp"

namespace dualgrid::eval {

double StudentT95(int df) {
  // t_{0.975, df} for df = 1..30 (NIST/SEMATECH e-Handbook, Sec. 1.3.6.7.2).
  static constexpr std::array<double, 30> kTable = {
      12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
      2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
      2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  if (df < 1) throw std::invalid_argument("StudentT95: df = " + std::to_string(df) + " < 1");
  return df <= 30 ? kTable[df - 1] : 1.96;
}

Summary Summarize(std::span<const double> samples) {
  Summary s;
  s.n = static_cast<int>(samples.size());
  if (s.n == 0) return s;
  double sum = 0.0;
  for (const double x : samples) {
    if (!std::isfinite(x)) throw std::invalid_argument("Summarize: non-finite sample");
    sum += x;
  }
  s.mean = sum / s.n;
  if (s.n < 2) return s;
  double ss = 0.0;
  for (const double x : samples) ss += (x - s.mean) * (x - s.mean);
  s.stddev = std::sqrt(ss / (s.n - 1));
  s.half_width = StudentT95(s.n - 1) * s.stddev / std::sqrt(static_cast<double>(s.n));
  return s;
}

namespace {

std::string NormaliseScenario(std::string_view name) {
  const auto slash = name.find_last_of('/');
  if (slash != std::string_view::npos) name.remove_prefix(slash + 1);
  const auto dot = name.find('.');
  if (dot != std::string_view::npos) name = name.substr(0, dot);
  std::string out;
  for (const char c : name) {
    out += (c == '-' || c == ' ') ? '_'
                                  : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

// CSV cells: 10 significant digits.
std::string FormatCsv(double v) { return FormatSignificant(v, 10); }

}  // namespace

std::vector<PaperValue> PaperReference(std::string_view scenario) {
  const std::string name = NormaliseScenario(scenario);
  const std::array<std::string, 3> modes = {"position", "velocity", "dual"};
  std::vector<PaperValue> out;
  auto row = [&](std::string_view metric, std::array<double, 3> values) {
    for (int m = 0; m < 3; ++m) out.push_back({std::string(metric), modes[m], values[m]});
  };
  if (name == "simple_road") {  // paper Table I
    row(kDeltaX, {1.20, 0.84, 0.53});
    row(kDeltaV, {0.55, 0.22, 0.39});
    row(kDetectionTime, {0.92, 0.29, 0.49});
    row(kTrackedFraction, {0.85, 0.89, 0.91});
  } else if (name == "highway") {  // paper Table II (no t_d)
    row(kDeltaX, {2.3, 3.3, 1.8});
    row(kDeltaV, {3.4, 3.3, 2.8});
    row(kTrackedFraction, {0.34, 0.40, 0.63});
  }
  return out;
}

ComparisonTable::ComparisonTable(std::string scenario, std::vector<std::string> modes)
    : scenario_(std::move(scenario)), modes_(std::move(modes)) {
  for (std::size_t i = 0; i < modes_.size(); ++i) {
    if (std::find(modes_.begin(), modes_.begin() + i, modes_[i]) != modes_.begin() + i)
      throw std::invalid_argument("ComparisonTable: mode '" + modes_[i] + "' repeated");
  }
}

void ComparisonTable::AddMetric(const MetricSpec& spec) {
  for (const MetricSpec& m : metrics_) {
    if (m.key == spec.key)
      throw std::invalid_argument("ComparisonTable::AddMetric: metric '" + spec.key +
                                  "' exists already");
  }
  metrics_.push_back(spec);
  ours_.emplace_back(modes_.size());
  paper_.emplace_back(modes_.size());
}

int ComparisonTable::MetricIndex(std::string_view metric) const {
  for (std::size_t i = 0; i < metrics_.size(); ++i) {
    if (metrics_[i].key == metric) return static_cast<int>(i);
  }
  return -1;
}

int ComparisonTable::ModeIndex(std::string_view mode) const {
  for (std::size_t i = 0; i < modes_.size(); ++i) {
    if (modes_[i] == mode) return static_cast<int>(i);
  }
  return -1;
}

void ComparisonTable::Set(std::string_view metric, std::string_view mode, const Summary& ours) {
  const int r = MetricIndex(metric), c = ModeIndex(mode);
  if (r < 0 || c < 0)
    throw std::invalid_argument("ComparisonTable::Set: unknown metric '" + std::string(metric) +
                                "' or mode '" + std::string(mode) + "'");
  ours_[r][c] = ours;
}

void ComparisonTable::SetPaper(std::string_view metric, std::string_view mode, double value) {
  const int r = MetricIndex(metric), c = ModeIndex(mode);
  if (r < 0 || c < 0)
    throw std::invalid_argument("ComparisonTable::SetPaper: unknown metric '" +
                                std::string(metric) + "' or mode '" + std::string(mode) + "'");
  paper_[r][c] = value;
}

void ComparisonTable::AttachPaperReference() {
  for (const PaperValue& p : PaperReference(scenario_)) {
    if (MetricIndex(p.metric) >= 0 && ModeIndex(p.mode) >= 0) SetPaper(p.metric, p.mode, p.value);
  }
}

std::optional<Summary> ComparisonTable::Ours(std::string_view metric, std::string_view mode) const {
  const int r = MetricIndex(metric), c = ModeIndex(mode);
  if (r < 0 || c < 0) return std::nullopt;
  return ours_[r][c];
}

std::optional<double> ComparisonTable::Paper(std::string_view metric, std::string_view mode) const {
  const int r = MetricIndex(metric), c = ModeIndex(mode);
  if (r < 0 || c < 0) return std::nullopt;
  return paper_[r][c];
}

std::string ComparisonTable::ToMarkdown() const {
  std::vector<bool> has_paper(modes_.size(), false);
  int max_n = 0;
  for (std::size_t r = 0; r < metrics_.size(); ++r) {
    for (std::size_t c = 0; c < modes_.size(); ++c) {
      if (paper_[r][c]) has_paper[c] = true;
      if (ours_[r][c]) max_n = std::max(max_n, ours_[r][c]->n);
    }
  }
  std::ostringstream os;
  os << "### " << scenario_ << "\n\n";
  if (!status_.empty()) os << "**" << status_ << "**\n\n";
  os << "| metric |";
  std::string rule = "|---|";
  for (std::size_t c = 0; c < modes_.size(); ++c) {
    os << ' ' << modes_[c] << " |";
    rule += "---:|";
    if (has_paper[c]) {
      os << ' ' << modes_[c] << " (paper) |";
      rule += "---:|";
    }
  }
  os << '\n' << rule << '\n';
  for (std::size_t r = 0; r < metrics_.size(); ++r) {
    const MetricSpec& m = metrics_[r];
    os << "| " << m.label << (m.unit.empty() ? "" : " [" + m.unit + "]") << " |";
    for (std::size_t c = 0; c < modes_.size(); ++c) {
      const std::optional<Summary>& s = ours_[r][c];
      if (!s || s->n == 0) {
        os << " — |";
      } else {
        const int decimals = m.count && s->n == 1 ? 0 : m.decimals;
        os << ' ' << FormatFixed(s->mean * m.display_scale, decimals);
        if (s->half_width) os << " ± " << FormatFixed(*s->half_width * m.display_scale, decimals);
        if (s->n < max_n) os << " (n=" << s->n << ')';
        os << " |";
      }
      if (has_paper[c]) {
        const std::optional<double>& p = paper_[r][c];
        os << ' ' << (p ? FormatFixed(*p * m.display_scale, m.decimals) : "—") << " |";
      }
    }
    os << '\n';
  }
  if (max_n > 1)
    os << "\nMean ± half-width of the 95 % confidence interval of the mean over " << max_n
       << " seeds (Student t).\n";
  else
    os << "\nOne seed: values of a single run, no confidence interval.\n";
  bool any_empty = false;
  for (const auto& row : ours_)
    for (const auto& cell : row) any_empty = any_empty || !cell || cell->n == 0;
  if (any_empty)
    os << "\n— : not defined in this run: Δx, Δv and the distance to the box need at least one "
          "tracked frame, t_d an object that was consistently tracked, D a scored object (one "
          "in the grid for at least `evaluation.min_frames_in_grid` frames).\n";
  for (const std::string& note : notes_) os << "\n" << note << "\n";
  return os.str();
}

std::string ComparisonTable::ToCsv() const {
  std::ostringstream os;
  os << "scenario,metric,unit,mode,n,mean,ci95_half_width,ci95_low,ci95_high,paper\n";
  for (std::size_t r = 0; r < metrics_.size(); ++r) {
    const MetricSpec& m = metrics_[r];
    for (std::size_t c = 0; c < modes_.size(); ++c) {
      const std::optional<Summary>& s = ours_[r][c];
      const double k = m.display_scale;
      os << scenario_ << ',' << m.key << ',' << m.unit << ',' << modes_[c] << ',' << (s ? s->n : 0)
         << ',';
      if (s && s->n > 0) os << FormatCsv(s->mean * k);
      os << ',';
      if (s && s->half_width) {
        os << FormatCsv(*s->half_width * k) << ',' << FormatCsv((s->mean - *s->half_width) * k)
           << ',' << FormatCsv((s->mean + *s->half_width) * k);
      } else {
        os << ",,";
      }
      os << ',';
      if (paper_[r][c]) os << FormatCsv(*paper_[r][c] * k);
      os << '\n';
    }
  }
  return os.str();
}

nlohmann::json ComparisonTable::ToJson() const {
  nlohmann::json metrics = nlohmann::json::array();
  for (std::size_t r = 0; r < metrics_.size(); ++r) {
    const MetricSpec& m = metrics_[r];
    nlohmann::json values = nlohmann::json::object();
    for (std::size_t c = 0; c < modes_.size(); ++c) {
      nlohmann::json v;
      const std::optional<Summary>& s = ours_[r][c];
      const double k = m.display_scale;
      v["n"] = s ? s->n : 0;
      v["mean"] = (s && s->n > 0) ? nlohmann::json(s->mean * k) : nlohmann::json(nullptr);
      v["ci95_half_width"] =
          (s && s->half_width) ? nlohmann::json(*s->half_width * k) : nlohmann::json(nullptr);
      v["paper"] = paper_[r][c] ? nlohmann::json(*paper_[r][c] * k) : nlohmann::json(nullptr);
      values[modes_[c]] = v;
    }
    metrics.push_back({{"key", m.key}, {"label", m.label}, {"unit", m.unit}, {"values", values}});
  }
  return {{"scenario", scenario_},
          {"modes", modes_},
          {"metrics", metrics},
          {"notes", notes_},
          {"status", status_}};
}

ComparisonTable MakeComparisonTable(std::string_view scenario, std::span<const ModeRuns> runs) {
  std::vector<std::string> modes;
  for (const ModeRuns& r : runs) modes.push_back(r.mode);
  ComparisonTable table{std::string(scenario), modes};
  using Getter = std::optional<double> (*)(const ScenarioMetrics&);
  struct Row {
    MetricSpec spec;
    Getter get;
  };
  std::vector<Row> rows = {
      {{std::string(kDeltaX), "Δx", "m", 1.0, 2},
       [](const ScenarioMetrics& m) { return m.position_error; }},
      {{std::string(kDeltaV), "Δv", "m/s", 1.0, 2},
       [](const ScenarioMetrics& m) { return m.velocity_error; }},
      {{std::string(kDetectionTime), "t_d", "s", 1.0, 2},
       [](const ScenarioMetrics& m) { return m.detection_time; }},
      {{std::string(kTrackedFraction), "D", "%", 100.0, 1},
       [](const ScenarioMetrics& m) { return m.tracked_fraction; }},
      {{std::string(kTrackedFractionV), "D_v (velocity right)", "%", 100.0, 1},
       [](const ScenarioMetrics& m) { return m.tracked_fraction_v; }},
      {{std::string(kBoxDistance), "Δx to box surface", "m", 1.0, 2},
       [](const ScenarioMetrics& m) { return m.box_distance; }},
      {{std::string(kFalseClusters), "false clusters / scan", "", 1.0, 2},
       [](const ScenarioMetrics& m) { return std::optional<double>(m.false_clusters_per_scan); }},
      {{std::string(kDuplicateClusters), "duplicate clusters / scan", "", 1.0, 2},
       [](const ScenarioMetrics& m) {
         return std::optional<double>(m.duplicate_clusters_per_scan);
       }},
      {{std::string(kScored), "objects scored", "", 1.0, 1, true},
       [](const ScenarioMetrics& m) {
         return std::optional<double>(static_cast<double>(m.objects_scored));
       }},
      {{std::string(kNeverTracked), "objects never tracked", "", 1.0, 1, true},
       [](const ScenarioMetrics& m) {
         return std::optional<double>(static_cast<double>(m.objects_never_tracked));
       }},
      {{std::string(kNeverObservable), "… of which never seen in the grid", "", 1.0, 1, true},
       [](const ScenarioMetrics& m) {
         return std::optional<double>(static_cast<double>(m.objects_never_observable));
       }},
  };
  bool any_cells = false;
  for (const ModeRuns& r : runs) {
    for (const ScenarioMetrics& m : r.seeds) any_cells = any_cells || m.cells.has_value();
  }
  if (any_cells) {
    rows.push_back(
        {{std::string(kDynamicF1), "dynamic-cell F1", "", 1.0, 3}, [](const ScenarioMetrics& m) {
           return m.cells ? m.cells->dynamic_f1 : std::optional<double>();
         }});
  }
  for (const Row& row : rows) {
    table.AddMetric(row.spec);
    for (const ModeRuns& r : runs) {
      std::vector<double> samples;
      for (const ScenarioMetrics& m : r.seeds) {
        if (const std::optional<double> v = row.get(m)) samples.push_back(*v);
      }
      table.Set(row.spec.key, r.mode, Summarize(samples));
    }
  }
  table.AttachPaperReference();
  return table;
}

std::map<int, Summary> PerObjectTrackedFraction(std::span<const ScenarioMetrics> seeds,
                                                bool velocity_aware) {
  std::map<int, std::vector<double>> samples;
  for (const ScenarioMetrics& m : seeds) {
    for (const ObjectMetrics& o : m.objects) {
      const std::optional<double>& d = velocity_aware ? o.tracked_fraction_v : o.tracked_fraction;
      if (o.scored && d) samples[o.id].push_back(*d);
    }
  }
  std::map<int, Summary> out;
  for (const auto& [id, v] : samples) out[id] = Summarize(v);
  return out;
}

void to_json(nlohmann::json& j, const Summary& s) {
  j = {{"n", s.n},
       {"mean", s.mean},
       {"stddev", s.stddev},
       {"ci95_half_width", s.half_width ? nlohmann::json(*s.half_width) : nlohmann::json(nullptr)}};
}

}  // namespace dualgrid::eval
