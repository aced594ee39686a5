// Sweeps over scenario keys: the `--set KEY=LIST` grammar of `dualgrid sweep` (docs/stress.md).
// LIST is comma-separated items, each a value ("0.5", "paper") or an inclusive numeric range
// "first:step:last".
#pragma once

#include <string>
#include <vector>

namespace dualgrid::scenario {

struct SweepAxis {
  std::string key;
  std::vector<std::string> values;  ///< in order, as text (numbers from ranges exactly printed)
  bool numeric = true;              ///< every value parses as a finite number
};

/// A finite number spelled out in full by `text` (no trailing characters); false otherwise.
bool ParseNumber(const std::string& text, double* out);

/// Parses "KEY=LIST". Throws std::invalid_argument naming the text and what is wrong: no '=' or
/// key, an empty item, a range with step <= 0, first > last, more than 1,000 values, a
/// non-numeric range bound, or a value given twice.
SweepAxis ParseSweepAxis(const std::string& text);

/// The cartesian product of the axes' values (the first axis varies slowest).
std::vector<std::vector<std::string>> SweepSettings(const std::vector<SweepAxis>& axes);

}  // namespace dualgrid::scenario
