// SUMO additional files (vTypes, traffic-light programs, stops, detectors, rerouters, polygons,
// ...) handed to SUMO as they are, except that nothing is ever written beside the user's files:
// the outputs they declare are moved into the run folder (docs/scenarios.md, "Bring your own SUMO
// scenario", lists the attributes).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace dualgrid::sim {

/// An output that an additional file declares, moved into the run folder.
struct RedirectedOutput {
  std::string file;       ///< the additional file that declares it
  std::string element;    ///< e.g. "e1Detector", "edgeData", "timedEvent"
  std::string attribute;  ///< "file", "output" or "dest"
  std::string original;   ///< the value as written
  std::string path;       ///< where SUMO writes it instead (inside the run folder)
};

struct PreparedAdditionalFiles {
  std::vector<std::string> files;         ///< what SUMO loads, in the order given
  std::vector<RedirectedOutput> outputs;  ///< in document order
};

/// For each of `files` that declares an output (SUMO's output attributes: detectors' and
/// meanData's `file`, calibrators' `output`, timed events' `dest`) or names another file by a
/// relative path (`include href`, `imgFile`, ...): a copy in `work_dir/sumo_additional/` whose
/// outputs point into `work_dir/sumo_outputs/` and whose relative paths are made absolute (SUMO
/// reads them relative to the file naming them); every other file as it is. Outputs of the same
/// path share one redirected file, as SUMO shares one device; the null device ("NUL",
/// "/dev/null") stays. Included files are prepared the same way (at most 8 levels deep). Each
/// file is read once. Throws std::invalid_argument naming a file that cannot be read or is not
/// well-formed XML, std::runtime_error when a copy cannot be written.
PreparedAdditionalFiles PrepareAdditionalFiles(const std::vector<std::string>& files,
                                               const std::filesystem::path& work_dir);

}  // namespace dualgrid::sim
