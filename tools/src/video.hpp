// The replay video (docs/replay.md): recorded frames drawn by viz::ReplayRenderer and piped as raw
// BGRA frames into Debian's ffmpeg binary, which encodes H.264 (libx264) and the preview.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "recording.hpp"

namespace dualgrid::tools {

/// Thrown when SIGINT/SIGTERM stops a video: the unfinished file is removed; RunReplay exits with
/// StopExitCode().
struct Stopped : std::runtime_error {
  Stopped() : std::runtime_error("stopped by a signal") {}
};

/// `path` (the value of `option`) ends in `extension` and its folder exists; else
/// std::invalid_argument naming the option. Returns `path`.
const std::filesystem::path& CheckOutputFile(const std::filesystem::path& path,
                                             const std::string& option,
                                             const std::string& extension);

/// `ffmpeg` on PATH, or nullopt.
std::optional<std::filesystem::path> FindFfmpeg();

/// Writes options.out (default RUN_DIR/replay.mp4) and the preview beside it
/// (replay_preview.gif/.webm). Files appear under their names only when complete (written as
/// *.part, then renamed). Throws std::invalid_argument for bad options (naming the option) and
/// std::runtime_error when ffmpeg is missing or fails (its log named). Returns the video's path.
std::filesystem::path WriteVideo(const replay::Reader& reader, const ReplayOptions& options);

/// The frames of `reader` within [options.from, options.to] (to = 0: the end); throws
/// std::invalid_argument naming --from/--to when none is.
std::pair<std::size_t, std::size_t> FrameRange(const replay::Reader& reader,
                                               const ReplayOptions& options);

/// Indices into the recorded modes of options.modes (all when empty); throws
/// std::invalid_argument naming --modes for a mode that was not recorded.
std::vector<std::size_t> SelectModes(const replay::Header& header, const ReplayOptions& options);

}  // namespace dualgrid::tools
