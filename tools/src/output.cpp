#include "output.hpp"

#include <stdlib.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace dualgrid::tools {

scenario::ScenarioConfig LoadConfig(const RunOptions& options) {
  std::vector<scenario::Override> overrides;
  for (const std::string& text : options.sets) overrides.push_back(scenario::ParseOverride(text));
  scenario::ScenarioConfig config = scenario::LoadScenario(options.scenario, overrides);
  config.overrides = options.sets;
  for (const std::string& w : config.sim.warnings) std::cerr << "dualgrid: warning: " << w << "\n";
  if (options.seed) config.sim.seed = *options.seed;
  if (options.duration) config.sim.duration = *options.duration;
  if (options.begin) {
    config.sim.begin = *options.begin;
    config.sim.begin_source = "command line";
  }
  // The overrides go through the same validation as the file.
  std::string error;
  if (!config.sim.IsValid(&error))
    throw std::invalid_argument(config.file.string() +
                                " with the command-line overrides: " + error);
  return config;
}

void CopyScenario(const scenario::ScenarioConfig& config, const std::filesystem::path& out) {
  std::ifstream in(config.file);
  std::ostringstream copy;
  copy << "# Copy of " << config.file.string() << " as used for this run; command-line overrides:\n"
       << "#   seed: " << config.sim.seed << ", duration: " << config.sim.duration
       << " s, begin: " << config.sim.begin << " s (SUMO time; " << config.sim.begin_source
       << ")\n";
  for (const std::string& set : config.overrides) copy << "#   --set " << set << "\n";
  copy << "# network as resolved: " << config.sim.network << "\n" << in.rdbuf();
  WriteTextFile(out / "scenario.yaml", copy.str());
}

namespace {
constexpr std::size_t kFlushBytes = 1 << 20;

std::string Reason() { return errno ? std::strerror(errno) : "unknown error"; }
}  // namespace

OutputFile::OutputFile(const std::filesystem::path& path) : path_(path) {
  errno = 0;
  if (path.extension() == ".gz") {
    gz_ = gzopen(path.c_str(), "wb6");
    if (!gz_) Fail("cannot create");
  } else {
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) Fail("cannot create");
  }
  buffer_.reserve(kFlushBytes + (kFlushBytes >> 2));
}

OutputFile::~OutputFile() {
  if (file_) std::fclose(file_);
  if (gz_) gzclose(static_cast<gzFile>(gz_));
}

void OutputFile::Fail(const std::string& what) {
  throw std::runtime_error(what + " " + path_.string() + ": " + Reason());
}

void OutputFile::MaybeFlush() {
  if (buffer_.size() >= kFlushBytes) Flush();
}

void OutputFile::Flush() {
  if (buffer_.empty()) return;
  errno = 0;
  if (file_) {
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      Fail("cannot write");
  } else if (gz_) {
    if (gzwrite(static_cast<gzFile>(gz_), buffer_.data(), static_cast<unsigned>(buffer_.size())) !=
        static_cast<int>(buffer_.size()))
      Fail("cannot write");
  }
  buffer_.clear();
}

void OutputFile::Close() {
  Flush();
  errno = 0;
  if (file_) {
    const bool ok = std::fflush(file_) == 0 && std::ferror(file_) == 0;
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (!ok || rc != 0) Fail("cannot write");
  }
  if (gz_) {
    const int rc = gzclose(static_cast<gzFile>(gz_));
    gz_ = nullptr;
    if (rc != Z_OK) Fail("cannot write");
  }
}

TempDir::TempDir(const std::string& purpose) : exceptions_(std::uncaught_exceptions()) {
  std::string pattern =
      (std::filesystem::temp_directory_path() / ("dualgrid_" + purpose + "_XXXXXX")).string();
  if (!mkdtemp(pattern.data()))
    throw std::runtime_error("cannot create a temporary folder " + pattern + ": " + Reason());
  path_ = pattern;
}

TempDir::~TempDir() {
  if (std::uncaught_exceptions() > exceptions_) return;
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

nlohmann::json OutputDigests(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (auto it = std::filesystem::recursive_directory_iterator(dir);
       it != std::filesystem::recursive_directory_iterator(); ++it) {
    // SUMO's own outputs (dated, and naming paths) and the additional files' copies (naming the
    // run folder) are SUMO's business, not dualgrid's results.
    const std::string name = it->path().filename().string();
    if (it.depth() == 0 && it->is_directory() &&
        (name == "sumo_outputs" || name == "sumo_additional")) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file()) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  nlohmann::json digests = nlohmann::json::object();
  std::vector<char> buf(1 << 16);
  for (const auto& f : files) {
    const std::string name = f.filename().string();
    if (name == "summary.json" || name == kRunMarker || f.extension() == ".log") continue;
    std::uint64_t h = 14695981039346656037ull;
    std::ifstream in(f, std::ios::binary);
    while (in.read(buf.data(), static_cast<std::streamsize>(buf.size())) || in.gcount() > 0)
      for (std::streamsize i = 0; i < in.gcount(); ++i)
        h = (h ^ static_cast<unsigned char>(buf[i])) * 1099511628211ull;
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    digests[std::filesystem::relative(f, dir).string()] = hex;
  }
  return digests;
}

void PrepareOutputFolder(const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out))
    throw std::invalid_argument("--out: " + out.string() + " exists and is not a folder");
  if (fs::exists(out, ec) && !fs::is_empty(out)) {
    if (!fs::exists(out / kRunMarker) && !fs::exists(out / "summary.json") &&
        !fs::exists(out / "config.json")) {
      const std::string first = fs::directory_iterator(out)->path().filename().string();
      throw std::invalid_argument("--out: " + out.string() +
                                  " holds files that are not a dualgrid run (e.g. '" + first +
                                  "'); give a new or empty folder");
    }
    fs::remove(out / "summary.json", ec);  // first: from here on the folder is not a finished run
    if (ec)
      throw std::runtime_error("cannot remove the earlier " + (out / "summary.json").string() +
                               ": " + ec.message());
    for (const auto& e : fs::directory_iterator(out)) {
      fs::remove_all(e.path(), ec);
      if (ec)
        throw std::runtime_error("cannot clear the earlier run's " + e.path().string() + ": " +
                                 ec.message());
    }
  }
  fs::create_directories(out);
  WriteTextFile(out / kRunMarker,
                "This folder is written by dualgrid; a new run with this --out empties it.\n");
}

bool FaultInjected(const std::string& what) {
  const char* env = std::getenv("DUALGRID_FAULT");
  if (!env) return false;
  const std::string list = std::string(",") + env + ",";
  return list.find("," + what + ",") != std::string::npos;
}

void WriteTextFile(const std::filesystem::path& path, const std::string& text) {
  OutputFile out(path);
  out.buffer() = text;
  out.Close();
}

std::optional<std::filesystem::path> DetectionPath(const std::filesystem::path& dir,
                                                   const std::string& format) {
  if (format == "csv" || format == "exact") return dir / "detections.csv";
  if (format == "csv.gz") return dir / "detections.csv.gz";
  if (format == "none") return std::nullopt;
  throw std::invalid_argument("--detections: expected none, csv, csv.gz or exact, got '" + format +
                              "'");
}

GroundTruthWriter::GroundTruthWriter(const std::filesystem::path& path) : out_(path) {
  out_.buffer() +=
      "step,time,id,type,is_ego,x,y,yaw,vx,vy,speed,lateral_speed,yaw_rate,length,width,lane,"
      "x_ego,y_ego,vx_ego,vy_ego,rcs_dbsm\n";
}

void GroundTruthWriter::Write(const sim::Frame& f) {
  const Pose2 ego = f.EgoPose();
  std::ostringstream os;
  os.precision(10);
  auto row = [&](const sim::VehicleState& v, bool is_ego) {
    const Position p = ego.ToLocal(v.box.center);
    const Velocity vr = ego.RotateToLocal(v.velocity);
    os << f.step << ',' << FormatFixed(f.time, 3) << ',' << v.id << ',' << v.type << ','
       << (is_ego ? 1 : 0) << ',' << FormatFixed(v.box.center.x(), 4) << ','
       << FormatFixed(v.box.center.y(), 4) << ',' << FormatFixed(v.box.yaw, 6) << ','
       << FormatFixed(v.velocity.x(), 4) << ',' << FormatFixed(v.velocity.y(), 4) << ','
       << FormatFixed(v.speed, 4) << ',' << FormatFixed(v.lateral_speed, 4) << ','
       << FormatFixed(v.yaw_rate, 6) << ',' << FormatFixed(v.box.length, 3) << ','
       << FormatFixed(v.box.width, 3) << ',' << v.lane << ',' << FormatFixed(p.x(), 4) << ','
       << FormatFixed(p.y(), 4) << ',' << FormatFixed(vr.x(), 4) << ',' << FormatFixed(vr.y(), 4)
       << ',' << FormatFixed(v.rcs_dbsm, 1) << '\n';
  };
  row(f.ego, true);
  for (const auto& v : f.vehicles) row(v, false);
  out_.buffer() += os.str();
  out_.MaybeFlush();
}

GridPoseWriter::GridPoseWriter(const std::filesystem::path& path) : out_(path) {
  out_.buffer() += "step,time,x,y,yaw_deg,length,width,realigned\n";
}

void GridPoseWriter::Write(const cosim::Pipeline& p) {
  const OrientedBox g = p.GridFootprint();
  const sim::Frame& f = p.frame();
  out_.buffer() += std::to_string(f.step) + ',' + FormatFixed(f.time, 3) + ',' +
                   FormatFixed(g.center.x(), 4) + ',' + FormatFixed(g.center.y(), 4) + ',' +
                   FormatSignificant(RadToDeg(g.yaw), 10) + ',' + FormatSignificant(g.length, 10) +
                   ',' + FormatSignificant(g.width, 10) + ',' + (p.grid_realigned() ? "1" : "0") +
                   '\n';
  out_.MaybeFlush();
}

DetectionWriter::DetectionWriter(const std::filesystem::path& path, bool multipath, bool exact)
    : out_(path), multipath_(multipath), exact_(exact) {
  out_.buffer() +=
      "step,time,sensor,sensor_name,range,azimuth,range_rate,snr_db,x_ego,y_ego,x,y,"
      "radial_speed,vrx,vry,sensor_x,sensor_y,source,is_clutter";
  // Only with multipath on: without it the file is the same as before multipath existed.
  if (multipath_) out_.buffer() += ",path,bounces,reflector,ghost_of";
  out_.buffer() += exact_ ? ",vclass\n" : "\n";
}

std::string DetectionWriter::Number(double v, int decimals) const {
  return exact_ ? FormatSignificant(v, 17) : FormatFixed(v, decimals);
}

void DetectionWriter::Write(const cosim::Pipeline& p) {
  const auto& f = p.frame();
  std::ostringstream os;
  os.precision(10);
  for (const auto& d : p.detections()) {
    os << f.step << ',' << Number(f.time, 3) << ',' << d.sensor << ','
       << p.radar().sensors()[d.sensor].name << ',' << Number(d.range, 4) << ','
       << Number(d.azimuth, 6) << ',' << Number(d.range_rate, 4) << ',' << Number(d.snr_db, 2)
       << ',' << Number(d.position_ego.x(), 4) << ',' << Number(d.position_ego.y(), 4) << ','
       << Number(d.position_world.x(), 4) << ',' << Number(d.position_world.y(), 4) << ','
       << Number(d.radial_speed_compensated, 4) << ',' << Number(d.radial_velocity_world.x(), 4)
       << ',' << Number(d.radial_velocity_world.y(), 4) << ','
       << Number(d.sensor_position_world.x(), 4) << ',' << Number(d.sensor_position_world.y(), 4)
       << ',' << p.ids().Name(d.source_id) << ',' << (d.is_clutter ? 1 : 0);
    if (multipath_) {
      const bool ghost = d.path != radar::Path::kDirect;
      os << ',' << (d.is_clutter ? "clutter" : radar::ToString(d.path)) << ',' << d.bounces << ','
         << (ghost ? p.ids().Name(d.reflector_id) : "") << ','
         << (ghost ? p.ids().Name(d.ghost_of) : "");
    }
    if (exact_) {
      // The source vehicle's vClass (its type's, for the scenario's own types; "unknown" for
      // types of the user's route files); empty for clutter, ghosts and static obstacles.
      std::string vclass;
      const std::string& name = p.ids().Name(d.source_id);
      const auto v = std::lower_bound(
          f.vehicles.begin(), f.vehicles.end(), name,
          [](const sim::VehicleState& a, const std::string& id) { return a.id < id; });
      if (d.source_id >= 0 && v != f.vehicles.end() && v->id == name) {
        const auto t = p.config().sim.vehicle_types.find(v->type);
        vclass = t != p.config().sim.vehicle_types.end() ? t->second.vclass : "unknown";
      }
      os << ',' << vclass;
    }
    os << '\n';
  }
  out_.buffer() += os.str();
  out_.MaybeFlush();
}

ScanWriter::ScanWriter(const std::filesystem::path& path) : out_(path) {
  out_.buffer() +=
      "step,time,sensor,sensor_name,ego_x,ego_y,ego_yaw,ego_vx,ego_vy,ego_yaw_rate,ego_length,"
      "ego_width,lane_yaw,mount_x,mount_y,mount_yaw,fov,min_range,max_range\n";
}

void ScanWriter::Write(const cosim::Pipeline& p) {
  const sim::Frame& f = p.frame();
  const radar::EgoMotion& e = p.ego_motion();
  auto n = [](double v) { return FormatSignificant(v, 17); };
  std::string& b = out_.buffer();
  for (int s : p.scanned()) {
    const radar::SensorParams& r = p.radar().sensors()[s];
    b += std::to_string(f.step) + ',' + n(f.time) + ',' + std::to_string(s) + ',' + r.name + ',' +
         n(e.pose.position.x()) + ',' + n(e.pose.position.y()) + ',' + n(e.pose.yaw) + ',' +
         n(e.velocity.x()) + ',' + n(e.velocity.y()) + ',' + n(e.yaw_rate) + ',' + n(e.length) +
         ',' + n(e.width) + ',' + n(f.ego.lane_yaw) + ',' + n(r.mount.position.x()) + ',' +
         n(r.mount.position.y()) + ',' + n(r.mount.yaw) + ',' + n(r.fov) + ',' + n(r.min_range) +
         ',' + n(r.max_range) + '\n';
  }
  out_.MaybeFlush();
}

void WriteObstacles(const sim::ScenarioSpec& spec, const std::filesystem::path& path) {
  std::ostringstream out;
  out << "id,kind,vertex,x,y,yaw,length,width\n";
  for (const auto& g : spec.guard_rails)
    for (std::size_t i = 0; i < g.points.size(); ++i)
      out << g.id << ",guard_rail," << i << ',' << g.points[i].x() << ',' << g.points[i].y()
          << ",,,\n";
  for (const auto& p : spec.parked)
    out << p.id << ",parked,0," << p.box.center.x() << ',' << p.box.center.y() << ',' << p.box.yaw
        << ',' << p.box.length << ',' << p.box.width << '\n';
  WriteTextFile(path, out.str());
}

void NoteAutoEgo(const cosim::Pipeline& pipeline, bool quiet) {
  const sim::ScenarioSpec& spec = pipeline.config().sim;
  if (!spec.ego_from_routes || spec.ego.id != sim::kAutoEgo || !pipeline.sumo()) return;
  const auto& choice = pipeline.simulation().auto_ego_choice();
  // A scene where no vehicle ever sees another is said even under -q: its results are empty.
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

}  // namespace dualgrid::tools
