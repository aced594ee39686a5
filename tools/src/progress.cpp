#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <memory>

#include "signals.hpp"

namespace dualgrid::tools {

Progress::Progress(std::string label, int total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled),
      tty_(isatty(fileno(stderr)) != 0),
      start_(Clock::now()),
      last_(start_) {}

void Progress::Update(int done, const std::string& detail) {
  if (!enabled_) return;
  const auto now = Clock::now();
  const double since_start = std::chrono::duration<double>(now - start_).count();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  // Stay quiet for the first two seconds; then redraw 4x/s on a terminal, every 5 s in logs.
  if (since_start < 2.0 || since_last < (tty_ ? 0.25 : 5.0)) return;
  last_ = now;
  shown_ = true;
  const double frac = static_cast<double>(done) / total_;
  const double eta = frac > 0 ? since_start * (1.0 - frac) / frac : 0.0;
  if (tty_) {
    const int width = 30, filled = static_cast<int>(frac * width);
    std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%% %s, %.0f s left  ", label_.c_str(), filled,
                 "##############################", width - filled, "", 100.0 * frac, detail.c_str(),
                 eta);
  } else {
    std::fprintf(stderr, "%s: %3.0f%% %s, %.0f s elapsed, %.0f s left\n", label_.c_str(),
                 100.0 * frac, detail.c_str(), since_start, eta);
  }
  std::fflush(stderr);
}

void Progress::Finish() {
  if (!enabled_ || !shown_) return;
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  if (tty_) std::fprintf(stderr, "\r%*s\r", 100, "");
  std::fprintf(stderr, "%s: done in %.1f s\n", label_.c_str(), elapsed);
}

outputs::Callbacks TerminalCallbacks(bool quiet) {
  auto progress = std::make_shared<std::unique_ptr<Progress>>();
  outputs::Callbacks c;
  c.stop = [] { return StopSignal(); };
  c.begin = [progress, quiet](const std::string& task, int total) {
    *progress = std::make_unique<Progress>(task, total, !quiet);
  };
  c.progress = [progress](int done, const std::string& detail) {
    if (*progress) (*progress)->Update(done, detail);
  };
  c.end = [progress] {
    if (*progress) (*progress)->Finish();
    progress->reset();
  };
  return c;
}

}  // namespace dualgrid::tools
