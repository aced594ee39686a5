#include "dualgrid/outputs/output_guard.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/read_results.hpp"
#include "dualgrid/sim/sumo_simulation.hpp"

namespace dualgrid::outputs {

namespace fs = std::filesystem;

namespace {

// `p` absolute, symbolic links of its existing part resolved, without `.`, `..` or a trailing
// separator.
fs::path Resolved(const fs::path& p) {
  std::error_code ec;
  fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
  if (ec) r = fs::absolute(p).lexically_normal();
  fs::path clean;
  for (const fs::path& part : r)
    if (!part.empty() && part != ".") clean /= part;
  return clean;
}

bool LexicallyWithin(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i)
    if (i == inner.end() || *i != *o) return false;
  return true;
}

// True when `dir` or one of its existing ancestors is the same file-system object as `outer`
// (device and inode): sees the same folder reached through a bind mount or a hard-linked path.
bool IdentityWithin(const fs::path& inner, const fs::path& outer) {
  struct stat o {};
  if (::stat(outer.c_str(), &o) != 0) return false;
  for (fs::path p = inner;; p = p.parent_path()) {
    struct stat s {};
    if (::stat(p.c_str(), &s) == 0 && s.st_dev == o.st_dev && s.st_ino == o.st_ino) return true;
    if (p == p.parent_path()) return false;
  }
}

std::string Quoted(const fs::path& p) {
  std::string q = "'";
  q += p.string();
  q += '\'';
  return q;
}

std::string Hex(const std::string& s) {
  static const char* digits = "0123456789abcdef";
  std::string h;
  for (unsigned char c : s) {
    h += digits[c >> 4];
    h += digits[c & 15];
  }
  return h;
}

std::optional<std::string> Unhex(const std::string& h) {
  if (h.size() % 2 != 0) return std::nullopt;
  std::string s;
  for (std::size_t i = 0; i < h.size(); i += 2) {
    int v = 0;
    for (char c : h.substr(i, 2)) {
      const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
      if (d < 0) return std::nullopt;
      v = v * 16 + d;
    }
    s += static_cast<char>(v);
  }
  return s;
}

// What a marker lists: `kept` and `ours` entry names (ours: besides the names dualgrid writes)
// (plain names only; anything else in the file is ignored, so a damaged marker can only make
// --force remove less).
struct Marker {
  std::set<std::string> kept, ours;
  bool sealed = false;
};

Marker ReadMarker(const fs::path& out) {
  Marker m;
  std::string text;
  try {
    text = ReadInputText(out / kRunMarker, "dualgrid marker", 16u << 20);
  } catch (const std::invalid_argument&) {
    return m;  // unreadable: nothing listed
  }
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line == "sealed") m.sealed = true;
    const std::size_t space = line.find(' ');
    if (space == std::string::npos) continue;
    const std::string kind = line.substr(0, space);
    const auto name = Unhex(line.substr(space + 1));
    if (!name || (kind != "kept" && kind != "ours")) continue;
    try {
      SafeName(*name, "marker");
    } catch (const std::invalid_argument&) {
      continue;
    }
    (kind == "kept" ? m.kept : m.ours).insert(*name);
  }
  return m;
}

void WriteMarker(const fs::path& out, const Marker& m) {
  std::string text =
      "# This folder is written by dualgrid (docs/output.md). `--force` replaces the entries\n"
      "# listed as ours (hex-encoded names); every other entry is kept.\n";
  for (const std::string& n : m.kept) text += "kept " + Hex(n) + "\n";
  for (const std::string& n : m.ours) text += "ours " + Hex(n) + "\n";
  if (m.sealed) text += "sealed\n";
  WriteTextFile(out / kRunMarker, text);
}

std::string FirstEntry(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names.empty() ? std::string() : names.front();
}

bool IsOurs(const fs::path& entry, const Marker& m) {
  const std::string name = entry.filename().string();
  if (name == kRunMarker || m.kept.count(name)) return false;
  if (m.ours.count(name)) return true;
  std::error_code ec;
  // A nested dualgrid output (a seed's or a case's run folder) is ours as a whole.
  const bool nested = fs::is_directory(fs::symlink_status(entry, ec)) &&
                      fs::is_regular_file(fs::symlink_status(entry / kRunMarker, ec));
  return OwnEntryName(name) || nested;
}

// --force: removes summary.json first, then the entries that are ours; returns what is kept.
std::set<std::string> ClearOwnEntries(const fs::path& out, const std::string& option) {
  const Marker m = ReadMarker(out);
  std::error_code ec;
  fs::remove(out / "summary.json", ec);  // first: from here on the folder is not a finished output
  if (ec)
    throw std::runtime_error("cannot remove " + (out / "summary.json").string() + ": " +
                             ec.message());
  std::set<std::string> kept;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name == kRunMarker) continue;
    if (!IsOurs(e.path(), m)) {
      kept.insert(name);
      continue;
    }
    fs::remove_all(e.path(), ec);  // a symbolic link is removed, never what it points to
    if (ec)
      throw std::runtime_error(option + ": cannot remove the earlier output's " +
                               e.path().string() + ": " + ec.message());
  }
  return kept;
}

}  // namespace

void InputSet::Add(const fs::path& path, const std::string& what) {
  if (!path.empty()) inputs_.push_back({path, what});
}

void InputSet::AddScenario(const scenario::ScenarioConfig& config, const fs::path& network_dir) {
  const sim::ScenarioSpec& s = config.sim;
  Add(config.file, "scenario");
  if (!s.network.empty())
    Add(sim::IsNetworkPath(s.network) ? fs::path(s.network)
                                      : network_dir / (s.network + ".net.xml"),
        "SUMO network");
  Add(s.network_source, "OpenDRIVE map");
  for (const std::string& f : s.route_files) Add(f, "SUMO route file");
  for (const std::string& f : s.additional_files) Add(f, "SUMO additional file");
}

bool PathWithin(const fs::path& inner, const fs::path& outer) {
  const fs::path i = Resolved(inner), o = Resolved(outer);
  return LexicallyWithin(i, o) || IdentityWithin(i, o);
}

void CheckOutputApart(const fs::path& out, const InputSet& inputs, const std::string& option) {
  for (const InputSet::Input& in : inputs.inputs()) {
    const std::string both =
        option + " " + Quoted(out) + " and the " + in.what + " " + Quoted(in.path);
    if (PathWithin(out, in.path) && PathWithin(in.path, out))
      throw std::invalid_argument(both +
                                  " are the same place: an output never overwrites what "
                                  "the command reads; choose another folder");
    if (PathWithin(in.path, out))
      throw std::invalid_argument(both +
                                  ": the output would contain the input (and could "
                                  "remove it); choose a folder outside it");
    if (PathWithin(out, in.path))
      throw std::invalid_argument(both +
                                  ": the output would lie inside the input; choose a "
                                  "folder outside it");
  }
}

std::string SafeName(const std::string& name, const std::string& what) {
  std::string why;
  if (name.empty())
    why = "is empty";
  else if (name == "." || name == "..")
    why = "names a folder itself";
  else if (name.size() > 255)
    why = "is longer than 255 bytes";
  else if (name.find('/') != std::string::npos)
    why = "holds a '/'";
  else if (std::any_of(name.begin(), name.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
    why = "holds a control character (NUL, newline, ...)";
  if (why.empty()) return name;
  std::string shown;
  for (char c : name.substr(0, 80))
    shown += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  throw std::invalid_argument(what + ": '" + shown + "' " + why +
                              ": expected one plain name that stays inside the output folder "
                              "(no '/', '.', '..', control characters)");
}

void PrepareOutputFolder(const fs::path& out, const OutputFolderOptions& o) {
  std::error_code ec;
  const fs::file_status st = fs::status(out, ec);
  if (fs::exists(st) && !fs::is_directory(st))
    throw std::invalid_argument(o.option + ": " + out.string() + " exists and is not a folder");
  Marker marker;
  if (fs::exists(st) && !fs::is_empty(out)) {
    const std::string first = FirstEntry(out);
    const bool marked = fs::is_regular_file(fs::symlink_status(out / kRunMarker, ec));
    if (!o.force && marked)
      throw std::invalid_argument(
          o.option + ": " + out.string() + " holds an earlier dualgrid output" +
          (ReadMarker(out).sealed ? "" : " (one that did not finish)") + "; add " + o.force_flag +
          " to replace it (only dualgrid's own files are removed) or choose a new folder");
    if (!o.force)
      throw std::invalid_argument(
          o.option + ": " + out.string() + " is not empty (e.g. '" + first +
          "'); dualgrid never empties a folder it did not create: choose a new or empty folder");
    if (!marked)
      throw std::invalid_argument(o.option + ": " + out.string() +
                                  " holds files that are not a dualgrid output (no " + kRunMarker +
                                  "; e.g. '" + first + "'); " + o.force_flag +
                                  " replaces only dualgrid's own: choose a new folder");
    marker.kept = ClearOwnEntries(out, o.option);
  }
  if (!fs::exists(st) && fs::is_symlink(fs::symlink_status(out, ec)))
    throw std::invalid_argument(o.option + ": " + out.string() +
                                " is a symbolic link to a missing folder; give a real folder");
  fs::create_directories(out, ec);
  if (ec)  // a parent that is a file, a folder without write permission: nothing written yet
    throw std::invalid_argument(o.option + ": cannot create the folder " + out.string() + ": " +
                                ec.message());
  WriteMarker(out, marker);
}

void SealOutputFolder(const fs::path& out) {
  Marker m = ReadMarker(out);
  m.ours.clear();
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name != kRunMarker && !m.kept.count(name)) m.ours.insert(name);
  }
  m.ours.insert("summary.json");  // written after the seal
  m.sealed = true;
  WriteMarker(out, m);
}

std::string CheckRunFinished(const fs::path& run_dir, bool allow_incomplete,
                             const std::string& option) {
  const RunState state = ReadRunState(run_dir);
  if (state.complete) return "";
  const std::string why = state.why == "not run"      ? "no summary.json"
                          : state.why == "incomplete" ? "summary.json says complete: false"
                                                      : state.why;
  if (!allow_incomplete)
    throw std::invalid_argument(run_dir.string() + " is not a finished run (" + why +
                                "): its export would look complete; finish the run, or add " +
                                option + " (the dataset is then marked by " + kIncompleteMark +
                                ")");
  return why;
}

void MarkIncomplete(const fs::path& out, const fs::path& run_dir, const std::string& why) {
  WriteTextFile(out / kIncompleteMark, "Exported from a run that did not finish (" + why +
                                           "): " + fs::absolute(run_dir).string() + "\n");
}

bool OwnEntryName(const std::string& name) {
  static const std::set<std::string> kNames = {
      // run and sim (docs/output.md, "Run folder")
      "scenario.yaml", "config.json", "routes.rou.xml", "ground_truth.csv", "grid.csv",
      "sumo_additional", "sumo_outputs", "detections.csv", "detections.csv.gz", "clusters.csv",
      "metrics.json", "objects.csv", "table.md", "table.csv", "table.json", "weights.csv",
      "figures", "replay", "replay.mp4", "replay_preview.gif", "replay.html", "scans.csv",
      "obstacles.csv", "summary.json",
      // experiment, regress, sweep
      "seeds", "per_object.json", "report.md", "report.json", "junit.xml", "plan.json", "runs.txt",
      "slurm.sh", "slurm", "scenarios", "runs", "tidy.csv", "aggregate.csv", "sweep.json",
      // export (RadarScenes, nuScenes)
      "sensors.json", "sequences.json", "data", "dualgrid_scenario.yaml", "samples", "sweeps",
      "INCOMPLETE.txt"};
  return kNames.count(name) > 0 || (name.size() > 4 && name.ends_with(".log"));
}

}  // namespace dualgrid::outputs
