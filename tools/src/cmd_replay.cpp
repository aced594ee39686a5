// `dualgrid replay RUN_DIR`: the video and/or the interactive viewer of a recorded run, from its
// replay/ folder (docs/replay.md), without SUMO.
#include <csignal>
#include <iostream>

#include "commands.hpp"
#include "output.hpp"
#include "recording.hpp"
#include "signals.hpp"
#include "video.hpp"
#include "viewer.hpp"

namespace dualgrid::tools {

int RunReplay(const ReplayOptions& options) {
  // ffmpeg may stop reading (it failed): the write then reports it instead of killing us.
  std::signal(SIGPIPE, SIG_IGN);
  const replay::Reader reader(options.run_dir);
  const replay::Header& h = reader.header();
  if (!h.complete && !options.quiet)
    std::cerr << "dualgrid: note: the recorded run did not finish (" << h.status
              << "); its replay is marked incomplete\n";
  const bool video = options.video || !options.html;
  if (options.html) {
    const auto path = WriteViewer(reader, options);
    if (!options.quiet) std::cout << "viewer: " << path.string() << "\n";
  }
  if (video) {
    try {
      const auto path = WriteVideo(reader, options);
      if (!options.quiet) std::cout << "video: " << path.string() << "\n";
    } catch (const Stopped&) {
      std::cerr << "dualgrid: replay stopped by signal " << StopSignal()
                << "; the unfinished video was removed\n";
      return StopExitCode();
    }
  }
  return 0;
}

}  // namespace dualgrid::tools
