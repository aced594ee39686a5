// Where a command may write (docs/reliability.md, "Output folders"): an output folder never
// equals, contains or lies inside anything the command reads; a name from the user or from a
// file never leaves the output folder; and a folder is emptied only when this invocation created
// it, or with --force, and then only of dualgrid's own entries. Every command that writes a
// folder or a file goes through this header, the Python module included.
//
//   outputs::InputSet in;
//   in.Add(scenario_path, "scenario");
//   in.AddScenario(config, network_dir);
//   outputs::CheckOutputApart(out, in);             // throws std::invalid_argument (exit 2)
//   outputs::PrepareOutputFolder(out, {.force = force});
//   ... write ...
//   outputs::SealOutputFolder(out);                 // lists what this run wrote
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "dualgrid/scenario/loader.hpp"

namespace dualgrid::outputs {

/// Marks a folder as dualgrid's own; written first into every output folder. It lists, as hex
/// names one per line, the entries that were there before the run and were kept (`kept`), and,
/// once the command finished writing, the entries it wrote (`ours`).
inline constexpr const char* kRunMarker = ".dualgrid-run";

/// Everything a command reads, gathered as it parses and loads: the paths as given, each with
/// a word saying what it is ("scenario", "run folder", "SUMO route file").
class InputSet {
 public:
  struct Input {
    std::filesystem::path path;
    std::string what;
  };

  /// Adds `path` (a file or a folder; need not exist). Empty paths are ignored.
  void Add(const std::filesystem::path& path, const std::string& what);
  /// Adds what a loaded scenario reads: its file, the network (a built one is looked up in
  /// `network_dir`), the map it was converted from, its SUMO route and additional files.
  void AddScenario(const scenario::ScenarioConfig& config,
                   const std::filesystem::path& network_dir);
  const std::vector<Input>& inputs() const { return inputs_; }

 private:
  std::vector<Input> inputs_;
};

/// Throws std::invalid_argument naming both paths when `out` (the option `option`, e.g.
/// "--out") equals an input, contains one, or lies inside one. Paths are compared after
/// resolving symbolic links, `.`, `..` and relative parts (weakly_canonical), and existing
/// folders are also compared by identity (device and inode), which sees bind mounts.
void CheckOutputApart(const std::filesystem::path& out, const InputSet& inputs,
                      const std::string& option = "--out");

/// True when `inner` equals `outer` or lies inside it, both resolved as CheckOutputApart does.
bool PathWithin(const std::filesystem::path& inner, const std::filesystem::path& outer);

/// `name` when it is one plain file or folder name that stays inside the folder it is joined
/// to: not empty, not `.` or `..`, no `/`, no NUL or other control character, at most 255
/// bytes. Otherwise throws std::invalid_argument "`what`: '...' ...: expected ...". `what`
/// names where it came from ("--sequence", "scenes.json: sensor name").
std::string SafeName(const std::string& name, const std::string& what);

/// How PrepareOutputFolder treats a folder that holds files already.
struct OutputFolderOptions {
  /// Replace an earlier dualgrid output in the folder: remove its own entries (those its marker
  /// lists as `ours`, else the names dualgrid writes: OwnEntryName), keep every other entry.
  bool force = false;
  std::string option = "--out";        ///< the option named in errors ("--out", "out")
  std::string force_flag = "--force";  ///< how errors tell to force ("--force", "force=True")
};

/// Makes `out` ready for a new output: creates it if missing (with its parents); uses it as it
/// is if it is an empty folder; otherwise throws std::invalid_argument (exit 2) unless
/// `options.force` and the folder holds dualgrid's marker. With force, the earlier summary.json
/// goes first (a run killed while clearing never looks finished), then dualgrid's own entries;
/// foreign entries stay and are listed as `kept` in the new marker. The marker is written
/// before anything else of the new output.
void PrepareOutputFolder(const std::filesystem::path& out, const OutputFolderOptions& options = {});

/// Rewrites the marker of `out` listing every entry not `kept` as `ours`: called when a command
/// has written everything but its completion record, so that a later --force removes exactly
/// what it wrote.
void SealOutputFolder(const std::filesystem::path& out);

/// The file that marks an export of a run that did not finish, at the dataset's root.
inline constexpr const char* kIncompleteMark = "INCOMPLETE.txt";

/// Before exporting `run_dir`: "" when its summary.json says complete; otherwise why not ("no
/// summary.json", "summary.json says complete: false", its status), which throws
/// std::invalid_argument naming `run_dir` unless `allow_incomplete` (`option` names the flag).
std::string CheckRunFinished(const std::filesystem::path& run_dir, bool allow_incomplete,
                             const std::string& option = "--allow-incomplete");

/// Writes `out`/kIncompleteMark saying why `run_dir` did not finish (CheckRunFinished's reason).
void MarkIncomplete(const std::filesystem::path& out, const std::filesystem::path& run_dir,
                    const std::string& why);

/// True for the names dualgrid writes at the top of an output folder (docs/output.md), used by
/// --force on a folder whose marker lists nothing (an output that did not finish, or one of an
/// earlier version): the run, experiment, regression, sweep and export files, `*.log`.
bool OwnEntryName(const std::string& name);

}  // namespace dualgrid::outputs
