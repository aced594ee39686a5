#include "cli_checks.hpp"
#include "dualgrid/core/text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace dualgrid::tools {
namespace {

std::string Shown(double v) { return FormatSignificant(v, 6); }

}  // namespace

CLI::Validator WholeNumber(long long lo, long long hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& s) -> std::string {
        const std::string expected = "expected a whole number in " + range + ", got '" + s + "'";
        if (s.empty() || !(std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '-'))
          return expected;
        errno = 0;
        char* end = nullptr;
        const long long v = std::strtoll(s.c_str(), &end, 10);
        if (errno != 0 || *end != '\0' || v < lo || v > hi) return expected;
        return "";
      },
      "INT in " + range);
}

CLI::Validator NonEmptyPath() {
  return CLI::Validator(
      [](std::string& s) -> std::string { return s.empty() ? "expected a path, got ''" : ""; },
      "PATH");
}

CLI::Validator OverrideSpec() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const std::size_t eq = s.find('=');
        return eq == std::string::npos || eq == 0
                   ? "expected KEY=VALUE (e.g. filter.preset=paper), got '" + s + "'"
                   : "";
      },
      "KEY=VALUE");
}

CLI::Validator Number(double lo, double hi, bool lo_open) {
  const std::string range = (lo_open ? "(" : "[") + Shown(lo) + ", " + Shown(hi) + "]";
  return CLI::Validator(
      [lo, hi, lo_open, range](std::string& s) -> std::string {
        const std::string expected = "expected a number in " + range + ", got '" + s + "'";
        if (s.empty()) return expected;
        errno = 0;
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (errno != 0 || *end != '\0' || !std::isfinite(v)) return expected;
        if ((lo_open ? !(v > lo) : !(v >= lo)) || !(v <= hi)) return expected;
        return "";
      },
      "NUMBER in " + range);
}

}  // namespace dualgrid::tools
