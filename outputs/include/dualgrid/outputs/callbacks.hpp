// What a caller passes into long work of this library (a run, a video): a way to stop it and a
// way to hear how far it got. Every member may be empty (never stop, report nothing).
#pragma once

#include <functional>
#include <string>

namespace dualgrid::outputs {

struct Callbacks {
  /// Polled between steps (frames of a video): non-zero asks the work to stop there, and is
  /// recorded as the reason (the command line passes the signal number that arrived).
  std::function<int()> stop;
  /// A task of `total` units begins (`task` names it in one line, e.g. "run highway seed 1").
  std::function<void(const std::string& task, int total)> begin;
  /// `done` units of the current task are finished; `detail` says more (e.g. "t=12.5 s").
  std::function<void(int done, const std::string& detail)> progress;
  /// The current task ended (finished or stopped).
  std::function<void()> end;

  int StopRequested() const { return stop ? stop() : 0; }
  void Begin(const std::string& task, int total) const {
    if (begin) begin(task, total);
  }
  void Progress(int done, const std::string& detail) const {
    if (progress) progress(done, detail);
  }
  void End() const {
    if (end) end();
  }
};

}  // namespace dualgrid::outputs
