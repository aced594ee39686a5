// Progress reporting for long runs: a redrawn bar on a terminal, a line every few seconds
// otherwise (logs, CI). Silent for runs shorter than a couple of seconds.
#pragma once

#include <chrono>
#include <string>

#include "dualgrid/outputs/callbacks.hpp"

namespace dualgrid::tools {

class Progress {
 public:
  Progress(std::string label, int total, bool enabled = true);
  /// Reports `done` of `total` steps; `detail` is appended (e.g. simulated time, counts).
  void Update(int done, const std::string& detail = "");
  /// Ends the line (terminal) and prints the elapsed time if anything was shown.
  void Finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::string label_;
  int total_;
  bool enabled_;
  bool tty_;
  bool shown_ = false;
  Clock::time_point start_;
  Clock::time_point last_;
};

/// The command line's callbacks for the outputs library: stop at SIGINT/SIGTERM (signals.hpp),
/// progress as a Progress bar on stderr (none when `quiet`).
outputs::Callbacks TerminalCallbacks(bool quiet);

}  // namespace dualgrid::tools
