#include "dualgrid/scenario/sweep_spec.hpp"
#include "dualgrid/core/text.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

namespace dualgrid::scenario {
namespace {

constexpr std::size_t kMaxValues = 1000;

// Text of a value already rounded to 12 significant digits: "90", "0.3", "1e-05".
std::string Text(double v) { return FormatSignificant(v, 12); }

}  // namespace

bool ParseNumber(const std::string& s, double* out) {
  if (s.empty()) return false;
  std::size_t used = 0;
  try {
    *out = std::stod(s, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == s.size() && std::isfinite(*out);
}

SweepAxis ParseSweepAxis(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument("--set " + text + ": " + why);
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) fail("expected KEY=LIST, e.g. filter.sigma_v=0.5,1,2");
  SweepAxis axis;
  axis.key = text.substr(0, eq);
  const std::string list = text.substr(eq + 1);
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = list.find(',', start);
    const std::string item =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) fail("an empty value in the list");
    const std::size_t c1 = item.find(':');
    if (c1 != std::string::npos) {
      const std::size_t c2 = item.find(':', c1 + 1);
      double first, step, last;
      if (c2 == std::string::npos || !ParseNumber(item.substr(0, c1), &first) ||
          !ParseNumber(item.substr(c1 + 1, c2 - c1 - 1), &step) ||
          !ParseNumber(item.substr(c2 + 1), &last))
        fail("range '" + item + "' is not first:step:last with three numbers");
      if (!(step > 0.0)) fail("range '" + item + "' needs a step > 0");
      if (first > last) fail("range '" + item + "' is empty (first > last)");
      const double count = std::floor((last - first) / step + 1e-9) + 1.0;
      if (count > kMaxValues) fail("range '" + item + "' gives more than 1,000 values");
      for (int k = 0; k < static_cast<int>(count); ++k) {
        // first + k * step, rounded to 12 significant digits so 0.1 steps print as 0.3, not
        // 0.30000000000000004.
        double v = first + k * step;
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.12g", v);
        v = std::stod(buf);
        axis.values.push_back(Text(v));
      }
    } else {
      axis.values.push_back(item);
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (axis.values.size() > kMaxValues) fail("more than 1,000 values");
  std::set<std::string> seen;
  for (const auto& v : axis.values) {
    if (!seen.insert(v).second) fail("the value '" + v + "' is given twice");
    double d;
    axis.numeric = axis.numeric && ParseNumber(v, &d);
  }
  return axis;
}

std::vector<std::vector<std::string>> SweepSettings(const std::vector<SweepAxis>& axes) {
  std::vector<std::vector<std::string>> out = {{}};
  for (const SweepAxis& a : axes) {
    std::vector<std::vector<std::string>> next;
    for (const auto& prefix : out)
      for (const auto& v : a.values) {
        auto s = prefix;
        s.push_back(v);
        next.push_back(std::move(s));
      }
    out = std::move(next);
  }
  return out;
}

}  // namespace dualgrid::scenario
