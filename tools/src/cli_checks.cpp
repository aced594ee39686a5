#include "cli_checks.hpp"
#include "dualgrid/core/text.hpp"

#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <thread>

namespace dualgrid::tools {
namespace {

std::string Shown(double v) { return FormatSignificant(v, 6); }

}  // namespace

int Cores() {
  // The CPUs this process may run on (taskset, a Slurm allocation's cpuset), not the machine's.
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
  return std::max(1u, std::thread::hardware_concurrency());
}

CoreSplit SplitCores(int jobs, int threads, int tasks) {
  CoreSplit s;
  s.cores = Cores();
  s.jobs = jobs > 0 ? jobs : std::max(1, std::min(s.cores, tasks));
  s.threads = threads > 0 ? threads : std::max(1, s.cores / s.jobs);
  return s;
}

std::string CoreSplit::Describe() const {
  std::string out = std::to_string(jobs) + (jobs == 1 ? " process" : " processes") +
                    " at a time x " + std::to_string(threads) +
                    (threads == 1 ? " thread" : " threads") + " on " + std::to_string(cores) +
                    (cores == 1 ? " core" : " cores");
  if (jobs * threads > cores) out += " (oversubscribed as asked: expect slowdowns)";
  return out;
}

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
