#include "dualgrid/outputs/run_folder.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/output_file.hpp"

namespace dualgrid::outputs {

namespace {

// The files OutputDigests covers, sorted: every regular file under `dir` except SUMO's own
// outputs (dated, and naming paths) and the additional files' copies (naming the run folder),
// which are SUMO's business, not dualgrid's results; summary.json, which holds the digests; the
// run marker; and the logs (*.log).
std::vector<std::filesystem::path> DigestedFiles(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (auto it = std::filesystem::recursive_directory_iterator(dir);
       it != std::filesystem::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it.depth() == 0 && it->is_directory() &&
        (name == "sumo_outputs" || name == "sumo_additional")) {
      it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file()) continue;
    if (name == "summary.json" || name == kRunMarker || it->path().extension() == ".log") continue;
    files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// FNV-1a 64 of the file's bytes, with the size and modification time it had before it was read.
FileDigest DigestFile(const std::filesystem::path& f, std::vector<char>& buf) {
  std::error_code ec;  // a file that cannot be read is digested as empty, as before
  FileDigest d{{}, std::filesystem::file_size(f, ec), std::filesystem::last_write_time(f, ec)};
  std::uint64_t h = 14695981039346656037ull;
  std::ifstream in(f, std::ios::binary);
  while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0)
    for (std::streamsize i = 0; i < in.gcount(); ++i)
      h = (h ^ static_cast<unsigned char>(buf[i])) * 1099511628211ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  d.hex = hex;
  return d;
}

}  // namespace

FileDigests FolderDigests(const std::filesystem::path& dir, const std::vector<std::string>& skip) {
  FileDigests digests;
  std::vector<char> buf(1 << 16);
  for (const auto& f : DigestedFiles(dir)) {
    const std::string name = std::filesystem::relative(f, dir).string();
    if (std::find(skip.begin(), skip.end(), name) == skip.end()) digests[name] = DigestFile(f, buf);
  }
  return digests;
}

nlohmann::json OutputDigests(const std::filesystem::path& dir, const FileDigests& earlier) {
  nlohmann::json digests = nlohmann::json::object();
  std::vector<char> buf(1 << 16);
  for (const auto& f : DigestedFiles(dir)) {
    const std::string name = std::filesystem::relative(f, dir).string();
    const auto known = earlier.find(name);
    std::error_code ec;
    if (known != earlier.end() && known->second.size == std::filesystem::file_size(f, ec) &&
        known->second.modified == std::filesystem::last_write_time(f, ec) && !ec)
      digests[name] = known->second.hex;
    else
      digests[name] = DigestFile(f, buf).hex;
  }
  return digests;
}

bool FaultInjected(const std::string& what) {
  const char* env = std::getenv("DUALGRID_FAULT");
  if (!env) return false;
  const std::string list = std::string(",") + env + ",";
  return list.find("," + what + ",") != std::string::npos;
}

void PrintAutoEgoNote(const cosim::Pipeline& pipeline, bool quiet) {
  const sim::ScenarioSpec& spec = pipeline.config().sim;
  if (!spec.ego_from_routes || spec.ego.id != sim::kAutoEgo || !pipeline.sumo()) return;
  const auto& choice = pipeline.simulation().auto_ego_choice();
  // A scene where no vehicle ever sees another is said even when quiet: its results are empty.
  if (choice && choice->with_traffic == 0)
    std::cerr << "dualgrid: warning: ego: auto chose '" << choice->id << "', but "
              << choice->Reason() << "\n";
  if (quiet) return;
  std::cerr << "dualgrid: ego: auto chose '" << pipeline.simulation().ego_id() << "' ("
            << (choice ? choice->Reason() : std::string()) << "; docs/scenarios.md)\n";
}

nlohmann::json EndRecord(const cosim::CoSimulation& cs, int stop_signal, std::string* status) {
  const sim::ScenarioSpec& spec = cs.config().sim;
  const bool started = cs.pipeline().started() && cs.steps() > 0;
  const sim::SumoSimulation* sumo = started ? cs.pipeline().sumo() : nullptr;
  const double last = started ? cs.pipeline().frame().time : 0.0;
  const double first = started ? last - (cs.steps() - 1) * spec.step_length : 0.0;
  // The ego leaving the network ends the scenario: the run is complete, `end` says how it ended.
  const bool ended = cs.finished() || (sumo && sumo->ego_left());
  nlohmann::json r = {{"complete", !stop_signal && ended},
                      {"ego", sumo ? sumo->ego_id() : spec.ego.id},
                      {"ego_departed_s", first},
                      {"ended_s", last},
                      {"begin_s", spec.begin},
                      {"begin_source", spec.begin_source}};
  if (!spec.network_source.empty()) r["network_source"] = spec.network_source;
  if (const auto& choice = sumo ? sumo->auto_ego_choice() : std::nullopt)
    r["ego_choice"] = {{"rule", "auto"},
                       {"reason", choice->Reason()},
                       {"seen_s", choice->seen_s},
                       {"in_run_s", choice->in_run_s},
                       {"depart_sumo_s", choice->depart_s},
                       {"candidates", choice->candidates},
                       {"with_traffic", choice->with_traffic}};
  // Where SUMO wrote the outputs that the user's additional files declare.
  r["sumo_outputs"] = nlohmann::json::array();
  if (sumo)
    for (const sim::RedirectedOutput& o : sumo->redirected_outputs())
      r["sumo_outputs"].push_back({{"file", o.file},
                                   {"element", o.element},
                                   {"attribute", o.attribute},
                                   {"original", o.original},
                                   {"path", o.path}});
  status->clear();
  if (stop_signal) {
    r["end"] = "signal";
    *status = "Incomplete run: stopped by signal " + std::to_string(stop_signal) +
              " at t = " + FormatFixed(last, 2) + " s of " + FormatFixed(spec.duration, 2) +
              " s (run time; SUMO time " + FormatFixed(spec.begin + last, 2) + " s)";
  } else if (sumo && sumo->ego_left()) {
    r["end"] = "ego_left";
    *status = "Shorter run than asked: the ego '" + sumo->ego_id() +
              "' left the network at t = " + FormatFixed(last, 2) + " s of " +
              FormatFixed(spec.duration, 2) + " s (run time; SUMO time " +
              FormatFixed(spec.begin + last, 2) +
              " s; its route ended there); the results cover its time in the network";
  } else {
    r["end"] = "duration";
  }
  return r;
}

}  // namespace dualgrid::outputs
