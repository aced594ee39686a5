// File output shared by the commands: CSV writers with documented columns (docs/output.md).
#pragma once

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/cosim/cosimulation.hpp"
#include "dualgrid/scenario/loader.hpp"
#include "dualgrid/sim/ground_truth.hpp"

namespace dualgrid::tools {

/// Loads the scenario and applies command-line overrides (seed, duration).
scenario::ScenarioConfig LoadConfig(const RunOptions& options);

/// Copies the scenario file into the run folder as scenario.yaml, with the overrides and the
/// resolved network noted, so a run can be repeated.
void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out);

/// A text output written as it goes: plain, or gzip-compressed when the path ends in ".gz".
/// Every write is checked when the file is closed: Close() throws std::runtime_error naming the
/// file and the system's reason (a full disk, a file-size limit), so a failed write is never
/// silent. Not copyable; the destructor closes without throwing (use Close() for the check).
class OutputFile {
 public:
  explicit OutputFile(const std::filesystem::path& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Appends to an in-memory buffer, written out in large blocks.
  std::string& buffer() { return buffer_; }
  /// Writes the buffer out when it is large (call once per step).
  void MaybeFlush();
  void Close();
  const std::filesystem::path& path() const { return path_; }

 private:
  void Flush();
  [[noreturn]] void Fail(const std::string& what);

  std::filesystem::path path_;
  std::string buffer_;
  std::FILE* file_ = nullptr;
  void* gz_ = nullptr;  // gzFile
};

/// ground_truth.csv: one row per vehicle (ego included) per step.
class GroundTruthWriter {
 public:
  explicit GroundTruthWriter(const std::filesystem::path& path);
  void Write(const sim::Frame& frame);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// grid.csv: where the grid lay, one row per step (world frame).
class GridPoseWriter {
 public:
  explicit GridPoseWriter(const std::filesystem::path& path);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// detections.csv (or detections.csv.gz): one row per radar detection per step. With
/// `multipath` (sensors.multipath on) four columns more name each detection's path: path
/// (direct, type1, type2, clutter), bounces, reflector and ghost_of (docs/output.md).
/// With `exact` (`--detections exact`) every number has 17 significant digits (it reads back as
/// the same double) and a last column `vclass` names the source vehicle's SUMO vClass: the input
/// of `dualgrid filter RUN_DIR` and `dualgrid export` (docs/recorded-data.md).
class DetectionWriter {
 public:
  explicit DetectionWriter(const std::filesystem::path& path, bool multipath = false,
                           bool exact = false);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  std::string Number(double v, int decimals) const;

  OutputFile out_;
  bool multipath_;
  bool exact_;
};

/// scans.csv (with `--detections exact`): one row per step and scanning sensor, every number
/// with 17 significant digits: the ego's state (box centre, heading, velocity, yaw rate, box,
/// its lane's direction) and the sensor's mount, field of view and ranges.
class ScanWriter {
 public:
  explicit ScanWriter(const std::filesystem::path& path);
  void Write(const cosim::Pipeline& pipeline);
  void Close() { out_.Close(); }

 private:
  OutputFile out_;
};

/// `--detections exact`: detections.csv with 17 digits, and scans.csv.
inline bool ExactDetections(const std::string& format) { return format == "exact"; }

/// The detection file for a `--detections` format ("csv", "csv.gz" or "exact"); empty for
/// "none".
std::optional<std::filesystem::path> DetectionPath(const std::filesystem::path& dir,
                                                   const std::string& format);

/// obstacles.csv: guard-rail vertices and parked boxes.
void WriteObstacles(const sim::ScenarioSpec& spec, const std::filesystem::path& path);

/// A new, empty temporary folder (under $TMPDIR or /tmp), removed with everything in it when
/// destroyed, unless destroyed while an exception is propagating: then it is kept for the
/// working files an error message may name (e.g. SUMO's log).
class TempDir {
 public:
  explicit TempDir(const std::string& purpose);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int exceptions_ = 0;
};

/// Marks a folder as dualgrid's own, written first into every output folder.
inline constexpr const char* kRunMarker = ".dualgrid-run";

/// Makes `out` an empty folder for a new run, so that no folder ever mixes two runs' files:
/// creates it if missing; keeps it if empty; empties it if it holds an earlier dualgrid output
/// (it has the marker kRunMarker, a summary.json or a config.json); otherwise throws
/// std::invalid_argument (a folder of other files is never cleared). The earlier completion
/// record goes first, so a run killed while clearing never looks finished. Then writes the
/// marker.
void PrepareOutputFolder(const std::filesystem::path& out);

/// Test hook (docs/reliability.md): true when the environment variable DUALGRID_FAULT lists
/// `what` (comma-separated), e.g. DUALGRID_FAULT=figure:tracked_share.png,run-seed:2. Lets the
/// tests make one figure or one seed run fail on purpose; unset in normal use.
bool FaultInjected(const std::string& what);

/// Digests of every file under `dir` (relative path -> 16 hex digits, FNV-1a 64 over the bytes:
/// a change detector, not a cryptographic hash), except summary.json, which holds them, SUMO's
/// own sumo.log and the seed runs' logs (*.log). Everything else a run writes is a function of the
/// scenario and the seed alone (wall-clock times live only in summary.json), so equal digests
/// mean equal outputs, whatever the thread count.
nlohmann::json OutputDigests(const std::filesystem::path& dir);

/// After Start(): names on stderr the vehicle that `ego: {from_routes: auto}` chose (nothing
/// when `quiet` or the ego was named).
void NoteAutoEgo(const cosim::Pipeline& pipeline, bool quiet);

/// How a co-simulation ended, for summary.json and the one-line note: `complete` (no signal came
/// and SUMO reached the duration or the ego left the network: the scenario's own end), `end`
/// ("duration", "ego_left", "signal"), `ego` (its id: the scenario's, or the one `auto` chose),
/// `ego_departed_s` and `ended_s` (SUMO's time at the first and last frame [s]), `sumo_outputs`
/// (the outputs the additional files declare: file, element, attribute, original value, path
/// written). `status` receives the note ("" for a run that reached the duration): why it ended
/// otherwise, in one line.
nlohmann::json EndRecord(const cosim::CoSimulation& cs, int stop_signal, std::string* status);

/// Writes a whole text file, checked: throws std::runtime_error naming the file and the reason.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);

}  // namespace dualgrid::tools
