// The interactive replay viewer (docs/replay.md): one self-contained HTML file, the page of
// viz/viewer/viewer.html with the recording inlined (index.json as JSON, each frame's zlib stream
// as base64, inflated in the browser by its own DecompressionStream). No network at view time.
#pragma once

#include <filesystem>

#include "dualgrid/outputs/recording.hpp"
#include "dualgrid/outputs/video.hpp"

namespace dualgrid::outputs {

/// Writes options.html_out (default RUN_DIR/replay.html) with the frames within --from/--to.
/// Throws std::runtime_error naming the file when it cannot be written. Returns its path.
std::filesystem::path WriteViewer(const replay::Reader& reader, const ReplayOptions& options);

}  // namespace dualgrid::outputs
