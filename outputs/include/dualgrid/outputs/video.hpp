// The replay video (docs/replay.md): recorded frames drawn by viz::ReplayRenderer and piped as raw
// BGRA frames into Debian's ffmpeg binary, which encodes H.264 (libx264) and the preview.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include <utility>
#include <vector>

#include "dualgrid/outputs/callbacks.hpp"
#include "dualgrid/outputs/recording.hpp"

namespace dualgrid::outputs {

/// How a recording is turned into the video and the viewer page (`dualgrid replay`'s options;
/// errors name the command-line option of a field).
struct ReplayOptions {
  std::filesystem::path out;       ///< video file (.mp4); default RUN_DIR/replay.mp4
  std::filesystem::path html_out;  ///< viewer page (.html); default RUN_DIR/replay.html
  std::vector<std::string> modes;  ///< subset of the recorded modes; empty: all
  bool particles = false;          ///< video: draw the recorded particles
  bool detections = true;          ///< video: draw the detections, coloured per sensor
  double from = 0.0, to = 0.0;     ///< time window [s]; to = 0: to the end
  double speed = 1.0;              ///< video playback speed (1 = real time), in [0.1, 20]
  int width = 1920;                ///< video width [px]
  std::string preview = "gif";     ///< "gif", "webm" or "none"
};

/// Thrown when Callbacks::stop stops a video: the unfinished file is removed.
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
/// std::runtime_error when ffmpeg is missing or fails (its log named), Stopped when
/// `callbacks.stop` asks. Reports progress per frame. Returns the video's path.
std::filesystem::path WriteVideo(const replay::Reader& reader, const ReplayOptions& options,
                                 const Callbacks& callbacks = {});

/// The frames of `reader` within [options.from, options.to] (to = 0: the end); throws
/// std::invalid_argument naming --from/--to when none is.
std::pair<std::size_t, std::size_t> FrameRange(const replay::Reader& reader,
                                               const ReplayOptions& options);

/// Indices into the recorded modes of options.modes (all when empty); throws
/// std::invalid_argument naming --modes for a mode that was not recorded.
std::vector<std::size_t> SelectModes(const replay::Header& header, const ReplayOptions& options);

}  // namespace dualgrid::outputs
