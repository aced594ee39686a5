// The run folder as a whole (docs/output.md): made empty for a run, marked as dualgrid's, its
// files' digests and the record of how the run ended (both in summary.json, written last).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/outputs/output_guard.hpp"

namespace dualgrid::outputs {

/// One file's digest (OutputDigests) with the size and modification time it had when read.
struct FileDigest {
  std::string hex;  ///< 16 hex digits
  std::uintmax_t size = 0;
  std::filesystem::file_time_type modified;
};
/// By path relative to the folder digested.
using FileDigests = std::map<std::string, FileDigest>;

/// Test hook (docs/reliability.md): true when the environment variable DUALGRID_FAULT lists
/// `what` (comma-separated), e.g. DUALGRID_FAULT=figure:tracked_share.png,run-seed:2. Lets the
/// tests make one figure or one seed run fail on purpose; unset in normal use.
bool FaultInjected(const std::string& what);

/// Digests of every file under `dir` (relative path -> 16 hex digits, FNV-1a 64 over the bytes:
/// a change detector, not a cryptographic hash), except summary.json, which holds them, SUMO's
/// own sumo.log and the seed runs' logs (*.log). Everything else a run writes is a function of the
/// scenario and the seed alone (wall-clock times live only in summary.json), so equal digests
/// mean equal outputs, whatever the thread count.
/// `earlier`: digests taken before (FolderDigests), reused for every file whose size and
/// modification time are still those it had then (the run's files that were final early, digested
/// while the figures are drawn); any other file is read again.
nlohmann::json OutputDigests(const std::filesystem::path& dir, const FileDigests& earlier = {});

/// The digests OutputDigests would give for the files under `dir` now, each with the size and
/// modification time it had when read (relative path -> digest), leaving out the files named in
/// `skip` (paths relative to `dir`, e.g. files another thread is writing). Throws as
/// OutputDigests.
FileDigests FolderDigests(const std::filesystem::path& dir,
                          const std::vector<std::string>& skip = {});

/// After Start(), when `ego: {from_routes: auto}` chose the ego: prints to stderr the vehicle it
/// chose and why (unless `quiet`), and a warning when no vehicle ever had another in its grid
/// (always: nothing can then be scored). Prints nothing when the ego was named.
void PrintAutoEgoNote(const cosim::Pipeline& pipeline, bool quiet);

/// How a co-simulation ended, for summary.json and the one-line note: `complete` (no signal came
/// and SUMO reached the duration or the ego left the network: the scenario's own end), `end`
/// ("duration", "ego_left", "signal"), `ego` (its id: the scenario's, or the one `auto` chose),
/// `ego_departed_s` and `ended_s` (SUMO's time at the first and last frame [s]), `sumo_outputs`
/// (the outputs the additional files declare: file, element, attribute, original value, path
/// written). `status` receives the note ("" for a run that reached the duration): why it ended
/// otherwise, in one line.
nlohmann::json EndRecord(const cosim::CoSimulation& cs, int stop_signal, std::string* status);

}  // namespace dualgrid::outputs
