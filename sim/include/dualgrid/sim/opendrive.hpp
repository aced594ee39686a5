// ASAM OpenDRIVE maps (.xodr) as a scenario's network: converted with SUMO's netconvert into a
// cache keyed by the file's digest, never beside the user's file (docs/scenarios.md, "OpenDRIVE
// maps").
#pragma once

#include <filesystem>
#include <string>

namespace dualgrid::sim {

/// Whether a scenario's `network` names an OpenDRIVE map (it ends in .xodr).
bool IsOpenDrive(const std::string& network);

/// Where converted maps are kept: $DUALGRID_CACHE_DIR/networks when set, else
/// $XDG_CACHE_HOME/dualgrid/networks, else $HOME/.cache/dualgrid/networks.
std::filesystem::path NetworkCacheDir();

/// The options dualgrid gives netconvert besides the input and output files: the map's own
/// coordinates kept, no U-turns at road ends (as the built networks).
inline constexpr const char* kOpenDriveOptions =
    "--offset.disable-normalization true --no-turnarounds true";

/// The SUMO network of the OpenDRIVE map `xodr`: NetworkCacheDir()/<stem>-<digest>.net.xml, where
/// the digest (FNV-1a 64) is over the file's bytes and kOpenDriveOptions. Made once with
/// `netconvert --opendrive-files` (its log beside it, .netconvert.log); a conversion written
/// under a temporary name and renamed when complete, so runs in parallel never read half a
/// network. Throws std::invalid_argument naming the file and netconvert's first error line when
/// netconvert rejects it (or the file cannot be read), std::runtime_error when the cache folder
/// cannot be written or netconvert cannot be started.
std::filesystem::path ConvertOpenDrive(const std::filesystem::path& xodr);

}  // namespace dualgrid::sim
