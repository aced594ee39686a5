// `dualgrid replay RUN_DIR`: the video and/or the interactive viewer of a recorded run, from its
// replay/ folder (docs/replay.md), without SUMO.
#include <csignal>
#include <iostream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "dualgrid/outputs/recording.hpp"
#include "dualgrid/outputs/video.hpp"
#include "dualgrid/outputs/viewer.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace dualgrid::tools {

int RunReplay(const ReplayCommandOptions& options) {
  // ffmpeg may stop reading (it failed): the write then reports it instead of killing us.
  std::signal(SIGPIPE, SIG_IGN);
  const replay::Reader reader(options.run_dir);
  const replay::Header& h = reader.header();
  if (!h.complete && !options.quiet)
    std::cerr << "dualgrid: note: the recorded run did not finish (" << h.status
              << "); its replay is marked incomplete\n";
  const bool video = options.video || !options.html;
  if (options.html) {
    const auto path = WriteViewer(reader, options.replay);
    if (!options.quiet) std::cout << "viewer: " << path.string() << "\n";
  }
  if (video) {
    try {
      const auto path = WriteVideo(reader, options.replay, TerminalCallbacks(options.quiet));
      if (!options.quiet) std::cout << "video: " << path.string() << "\n";
    } catch (const Stopped&) {
      std::cerr << "dualgrid: replay stopped by signal " << StopSignal()
                << "; the unfinished video was removed\n";
      return StopExitCode();
    }
  }
  return 0;
}

Command AddReplayCommand(CLI::App& app, const CliContext&) {
  auto o = std::make_shared<ReplayCommandOptions>();
  auto* cmd = app.add_subcommand(
      "replay",
      "Video (MP4 + GIF preview) and/or interactive HTML viewer of a recorded run, without "
      "rerunning SUMO (docs/replay.md)");
  cmd->add_option("run_dir", o->run_dir, "Run folder written by `dualgrid run`")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--video", o->video, "Write the video (the default unless --html is given)");
  cmd->add_flag("--html", o->html, "Write the self-contained interactive viewer");
  cmd->add_option("--out,-o", o->replay.out, "Video file (default RUN_DIR/replay.mp4)")
      ->check(NonEmptyPath());
  cmd->add_option("--html-out", o->replay.html_out, "Viewer file (default RUN_DIR/replay.html)")
      ->check(NonEmptyPath());
  cmd->add_option("--modes", o->replay.modes,
                  "Video: modes to show, comma-separated (default: all recorded)")
      ->delimiter(',');
  cmd->add_flag("--particles", o->replay.particles, "Video: draw the recorded particles");
  cmd->add_flag_callback(
      "--no-detections", [o] { o->replay.detections = false; }, "Video: leave the detections out");
  Opt(cmd, "--from", &o->replay.from, "First time [s]")->check(Number(0.0, kMaxDuration, false));
  Opt(cmd, "--to", &o->replay.to, "Last time [s] (0: the end)")
      ->check(Number(0.0, kMaxDuration, false));
  Opt(cmd, "--speed", &o->replay.speed, "Video playback speed (1: real time)")
      ->check(Number(0.1, 20.0, false));
  Opt(cmd, "--width", &o->replay.width, "Video width [px] (even)")->check(WholeNumber(320, 7680));
  Opt(cmd, "--preview", &o->replay.preview, "Short preview beside the video: gif, webm or none")
      ->check(CLI::IsMember({"gif", "webm", "none"}));
  cmd->add_flag("--quiet,-q", o->quiet, "No progress output");
  return {cmd, [o, cmd] {
            // The viewer has its own controls for these: given with --html alone they would be
            // ignored.
            if (o->html && !o->video)
              for (const char* name : {"--out", "--modes", "--particles", "--no-detections",
                                       "--speed", "--width", "--preview"})
                if (cmd->count(name) > 0)
                  throw std::invalid_argument(std::string(name) +
                                              " is a video option; add --video, or leave it out "
                                              "(the viewer has its own controls)");
            return RunReplay(*o);
          }};
}

}  // namespace dualgrid::tools
