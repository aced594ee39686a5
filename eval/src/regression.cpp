#include "dualgrid/eval/regression.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dualgrid/core/text.hpp"

namespace dualgrid::eval {

namespace {

// Numbers in the verdict tables: 4 significant digits.
std::string Number(double v) { return FormatSignificant(v, 4); }

std::string Trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

std::string Shown(const MetricValue& v) {
  return Number(v.mean) + (v.half_width ? " ± " + Number(*v.half_width) : "") +
         " (n=" + std::to_string(v.n) + ")";
}

}  // namespace

const std::vector<std::string>& RegressionMetricNames() {
  static const std::vector<std::string> names = {"D",
                                                 "D_v",
                                                 "delta_x",
                                                 "delta_v",
                                                 "t_d",
                                                 "box_distance",
                                                 "false_clusters_per_scan",
                                                 "duplicate_clusters_per_scan",
                                                 "dynamic_cell_f1",
                                                 "objects_scored",
                                                 "objects_never_tracked",
                                                 "objects_never_in_coverage"};
  return names;
}

bool IsModeName(std::string_view m) { return m == "position" || m == "velocity" || m == "dual"; }

std::string MetricRef::ToString() const {
  return (case_name.empty() ? "" : case_name + ":") + mode + "." + metric;
}

MetricRef ParseMetricRef(const std::string& text) {
  std::string t = Trim(text);
  MetricRef r;
  if (const auto colon = t.find(':'); colon != std::string::npos) {
    r.case_name = Trim(t.substr(0, colon));
    t = Trim(t.substr(colon + 1));
    if (r.case_name.empty()) throw std::invalid_argument("'" + text + "': empty case name");
  }
  const auto dot = t.find('.');
  if (dot == std::string::npos)
    throw std::invalid_argument("'" + text + "': expected [case:]mode.metric, e.g. dual.D_v");
  r.mode = t.substr(0, dot);
  r.metric = t.substr(dot + 1);
  if (!IsModeName(r.mode))
    throw std::invalid_argument("'" + text + "': unknown mode '" + r.mode +
                                "' (expected position, velocity or dual)");
  const auto& names = RegressionMetricNames();
  if (std::find(names.begin(), names.end(), r.metric) == names.end()) {
    std::string all;
    for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
    throw std::invalid_argument("'" + text + "': unknown metric '" + r.metric +
                                "' (expected one of " + all + ")");
  }
  return r;
}

std::string Band::Describe() const {
  if (reference && tolerance) return Number(*reference) + " ± " + Number(*tolerance);
  // std::string first: "[" + a temporary trips GCC 12's -Wrestrict (a false positive).
  if (min && max) return std::string("[") + Number(*min) + ", " + Number(*max) + "]";
  if (min) return ">= " + Number(*min);
  if (max) return "<= " + Number(*max);
  return "any";
}

Ordering ParseOrdering(const std::string& text) {
  Ordering o;
  o.text = Trim(text);
  std::size_t at = std::string::npos, len = 0;
  for (const char* op : {">=", "<=", ">", "<"}) {
    const auto p = o.text.find(op);
    if (p != std::string::npos) {
      at = p;
      len = std::char_traits<char>::length(op);
      o.op = op;
      break;
    }
  }
  if (at == std::string::npos)
    throw std::invalid_argument(
        "'" + text +
        "': expected 'lhs OP rhs [+|- number]' with OP one of >=, <=, >, <, "
        "e.g. dual.D_v >= position.D_v - 2");
  o.lhs = ParseMetricRef(o.text.substr(0, at));
  std::string rhs = Trim(o.text.substr(at + len));
  // An offset: the last " + " or " - " followed by a number.
  for (const char sign : {'+', '-'}) {
    const auto p = rhs.rfind(std::string(" ") + sign + " ");
    if (p == std::string::npos) continue;
    const std::string num = Trim(rhs.substr(p + 3));
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(num, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != num.size() || !std::isfinite(v))
      throw std::invalid_argument("'" + text + "': offset '" + num + "' is not a number");
    o.offset = sign == '+' ? v : -v;
    rhs = Trim(rhs.substr(0, p));
    break;
  }
  o.rhs = ParseMetricRef(rhs);
  return o;
}

std::vector<Verdict> CheckCase(const std::string& case_name, const std::vector<Band>& bands,
                               const std::vector<Ordering>& orderings, const Measured& measured) {
  const auto find = [&](const MetricRef& r) -> std::optional<MetricValue> {
    const auto c = measured.find(r.case_name.empty() ? case_name : r.case_name);
    if (c == measured.end()) return std::nullopt;
    const auto v = c->second.find(r.mode + "." + r.metric);
    if (v == c->second.end()) return std::nullopt;
    return v->second;
  };
  std::vector<Verdict> out;
  for (const Band& b : bands) {
    Verdict v;
    v.case_name = case_name;
    v.check = b.metric.ToString();
    v.expected = b.Describe();
    const auto m = find(b.metric);
    if (!m) {
      v.measured = "—";
      v.why = "not measured (the case failed, or the metric is undefined in this run)";
    } else {
      v.measured = Shown(*m);
      v.pass =
          std::isfinite(m->mean) && (!b.min || m->mean >= *b.min) && (!b.max || m->mean <= *b.max);
      if (!v.pass && !std::isfinite(m->mean))
        v.why = "mean is not a finite number";
      else if (!v.pass)
        v.why = "mean " + Number(m->mean) + (b.min && m->mean < *b.min ? " below " : " above ") +
                Number(b.min && m->mean < *b.min ? *b.min : *b.max);
    }
    out.push_back(v);
  }
  for (const Ordering& o : orderings) {
    Verdict v;
    v.case_name = case_name;
    v.check = o.text;
    const auto l = find(o.lhs), r = find(o.rhs);
    if (!l || !r) {
      v.expected = o.op + " " + (r ? Number(r->mean + o.offset) : "—");
      v.measured = l ? Shown(*l) : "—";
      v.why = "not measured: " + (l ? o.rhs.ToString() : o.lhs.ToString());
    } else {
      const double rhs = r->mean + o.offset;
      v.expected = o.op + " " + Number(rhs);
      v.measured = Shown(*l);
      v.pass = o.op == ">="   ? l->mean >= rhs
               : o.op == "<=" ? l->mean <= rhs
               : o.op == ">"  ? l->mean > rhs
                              : l->mean < rhs;
      if (!v.pass)
        v.why = o.lhs.ToString() + " = " + Number(l->mean) + ", " + o.rhs.ToString() + " = " +
                Number(r->mean);
    }
    out.push_back(v);
  }
  return out;
}

double RecordFloor(const std::string& metric) {
  // Changes smaller than these are noise for a regression check; larger ones are worth a look.
  if (metric == "D" || metric == "D_v") return 2.0;  // percentage points
  if (metric == "delta_x" || metric == "delta_v" || metric == "box_distance") return 0.1;
  if (metric == "t_d") return 0.1;  // [s], two cycles
  if (metric == "dynamic_cell_f1") return 0.02;
  if (metric == "false_clusters_per_scan" || metric == "duplicate_clusters_per_scan") return 0.1;
  return 0.5;  // object counts
}

Band RecordBand(const MetricRef& metric, const MetricValue& value) {
  Band b;
  b.metric = metric;
  const double tol = std::max(3.0 * value.half_width.value_or(0.0), RecordFloor(metric.metric));
  // Rounded outwards to 3 significant decimals so the suite file reads cleanly.
  const auto round = [](double v) { return std::round(v * 1000.0) / 1000.0; };
  b.reference = round(value.mean);
  b.tolerance = std::ceil(tol * 1000.0) / 1000.0;
  b.min = *b.reference - *b.tolerance;
  b.max = *b.reference + *b.tolerance;
  return b;
}

}  // namespace dualgrid::eval
