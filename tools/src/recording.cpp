#include "recording.hpp"

#include <zlib.h>

#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "output.hpp"

namespace dualgrid::tools::replay {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Centimetre rounding keeps index.json small without losing anything a picture shows.
double R(double v) { return std::round(v * 100.0) / 100.0; }

json BoxJson(const Box& b) {
  return json::array({b.id, R(b.x), R(b.y), std::round(b.yaw * 1e4) / 1e4, R(b.length), R(b.width),
                      R(b.vx), R(b.vy)});
}
Box BoxFrom(const json& j) {
  return {j.at(0).get<int>(),    j.at(1).get<double>(), j.at(2).get<double>(),
          j.at(3).get<double>(), j.at(4).get<double>(), j.at(5).get<double>(),
          j.at(6).get<double>(), j.at(7).get<double>()};
}

template <typename T>
void Append(std::vector<std::uint8_t>& out, const std::vector<T>& v) {
  const std::size_t n = v.size() * sizeof(T);
  const std::size_t at = out.size();
  out.resize(at + n);
  if (n) std::memcpy(out.data() + at, v.data(), n);
}

template <typename T>
void Take(const std::vector<std::uint8_t>& in, std::size_t& at, std::size_t count,
          std::vector<T>& v, const std::string& where) {
  const std::size_t n = count * sizeof(T);
  if (at + n > in.size())
    throw std::invalid_argument(where + ": frame data shorter than its index says");
  v.resize(count);
  if (n) std::memcpy(v.data(), in.data() + at, n);
  at += n;
}

json HeaderJson(const Header& h) {
  json j = {{"format", "dualgrid-replay"},
            {"version", kFormatVersion},
            {"scenario", h.scenario},
            {"seed", h.seed},
            {"modes", h.modes},
            {"sensors", h.sensors},
            {"cells_x", h.cells_x},
            {"cells_y", h.cells_y},
            {"resolution", h.resolution},
            {"frame_yaw_deg", h.frame_yaw_deg},
            {"interval", h.interval},
            {"particle_unit", h.particle_unit},
            {"max_particles", h.max_particles},
            {"dynamic_threshold", h.dynamic_threshold},
            {"names", h.names.is_null() ? json::object() : h.names},
            {"metrics", h.metrics.is_null() ? json::object() : h.metrics},
            {"complete", h.complete},
            {"status", h.status}};
  if (h.multipath) j["multipath"] = true;
  j["parked"] = json::array();
  for (const Box& b : h.parked) j["parked"].push_back(BoxJson(b));
  j["rails"] = json::array();
  for (const auto& rail : h.rails) {
    json r = json::array();
    for (const auto& p : rail) r.push_back({R(p[0]), R(p[1])});
    j["rails"].push_back(r);
  }
  return j;
}

}  // namespace

double ParticleUnit(double extent_x, double extent_y) {
  const double extent = std::max(extent_x, extent_y);
  return std::max(0.01, extent / 65000.0);
}

Writer::Writer(const fs::path& dir, Header header) : dir_(dir), header_(std::move(header)) {
  fs::create_directories(dir_);
  // A stale index from an earlier run must not describe this run's frames.
  fs::remove(dir_ / "index.json");
  bin_.open(dir_ / "frames.bin", std::ios::binary | std::ios::trunc);
  if (!bin_) throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string());
}

void Writer::Add(const Frame& f) {
  const std::size_t n = static_cast<std::size_t>(header_.cells_x) * header_.cells_y;
  raw_.clear();
  for (const ModeFrame& m : f.modes) {
    assert(m.vx_cm.size() == n && m.vy_cm.size() == n);
    Append(raw_, m.vx_cm);
    Append(raw_, m.vy_cm);
  }
  for (const ModeFrame& m : f.modes) Append(raw_, m.particles);
  for (const ModeFrame& m : f.modes) {
    assert(m.free.size() == n && m.static_occ.size() == n && m.dynamic.size() == n);
    Append(raw_, m.free);
    Append(raw_, m.static_occ);
    Append(raw_, m.dynamic);
  }
  (void)n;
  uLongf packed_size = compressBound(raw_.size());
  packed_.resize(packed_size);
  // Level 1: the cell data is mostly runs of equal bytes; higher levels cost time for ~10 %.
  if (compress2(packed_.data(), &packed_size, raw_.data(), raw_.size(), 1) != Z_OK)
    throw std::runtime_error("replay: compressing frame t = " + FormatFixed(f.time, 2) +
                             " s failed");
  bin_.write(reinterpret_cast<const char*>(packed_.data()),
             static_cast<std::streamsize>(packed_size));
  if (!bin_) throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string());

  json j = {{"t", R(f.time * 10.0) / 10.0},
            {"yaw", f.yaw_deg},  // exact: positions far from the origin turn with it
            {"ego", BoxJson(f.ego)},
            {"origin", {R(f.origin_x), R(f.origin_y)}}};
  j["truth"] = json::array();
  for (const Box& b : f.truth) j["truth"].push_back(BoxJson(b));
  j["det"] = json::array();
  for (const Detection& d : f.detections) {
    json row = {d.sensor, R(d.x), R(d.y), R(d.vx), R(d.vy), d.clutter ? 1 : 0};
    if (d.path != 0) row.push_back(d.path);  // ghosts only (docs/replay.md)
    j["det"].push_back(std::move(row));
  }
  j["modes"] = json::array();
  for (const ModeFrame& m : f.modes) {
    json cl = json::array();
    for (const Cluster& c : m.clusters)
      cl.push_back({R(c.x), R(c.y), R(c.vx), R(c.vy), R(c.min_x), R(c.min_y), R(c.max_x),
                    R(c.max_y), c.role, c.object, c.velocity_ok ? 1 : 0});
    const Live& l = m.live;
    j["modes"].push_back({{"np", m.particles.size() / 2},
                          {"cl", cl},
                          {"live",
                           {l.in_grid, l.tracked, l.tracked_v, l.false_clusters, l.total_in_grid,
                            l.total_tracked, l.total_tracked_v}}});
  }
  j["blob"] = {offset_, static_cast<std::uint64_t>(packed_size)};
  offset_ += packed_size;
  index_.push_back(j.dump());
}

void Writer::Finish(const Header& final_header) {
  bin_.close();
  if (!bin_) throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string());
  json j = HeaderJson(final_header);
  j["frames"] = json::array();
  std::string text = j.dump();
  // Splice the serialised frames into the empty "frames" array (the header's last key: nlohmann
  // orders keys alphabetically, so find the array by its key).
  const std::string key = "\"frames\":[]";
  const std::size_t at = text.find(key);
  assert(at != std::string::npos);
  std::string frames = "\"frames\":[";
  for (std::size_t i = 0; i < index_.size(); ++i) {
    if (i) frames += ',';
    frames += index_[i];
  }
  frames += ']';
  text.replace(at, key.size(), frames);
  index_.clear();
  WriteTextFile(dir_ / "index.json", text + "\n");
}

Reader::Reader(const fs::path& run_dir) : dir_(run_dir / "replay") {
  const fs::path index_path = dir_ / "index.json";
  if (!fs::exists(run_dir)) throw std::invalid_argument(run_dir.string() + ": no such run folder");
  if (!fs::exists(index_path))
    throw std::invalid_argument(
        index_path.string() +
        ": missing (the run was made with --no-record or --no-figures, or did not finish; "
        "rerun `dualgrid run` without them)");
  std::ifstream in(index_path);
  try {
    index_ = json::parse(in);
  } catch (const json::exception& e) {
    throw std::invalid_argument(index_path.string() + ": not JSON (" + e.what() + ")");
  }
  const std::string where = index_path.string();
  // Every key read through Get names itself in the error (one line, exit code 2).
  const auto get = [&](const json& j, const std::string& key, auto* out, const std::string& what) {
    try {
      *out = j.at(key).get<std::remove_pointer_t<decltype(out)>>();
    } catch (const json::exception&) {
      throw std::invalid_argument(where + ": key '" + key + "': expected " + what);
    }
  };
  Header& h = header_;
  std::string format;
  get(index_, "format", &format, "\"dualgrid-replay\"");
  if (format != "dualgrid-replay")
    throw std::invalid_argument(where + ": key 'format': expected \"dualgrid-replay\"");
  const json version = index_.value("version", json());
  if (!version.is_number_integer() || version.get<int>() != kFormatVersion)
    throw std::invalid_argument(where + ": key 'version': expected " +
                                std::to_string(kFormatVersion) + ", found " + version.dump() +
                                " (recorded by another release)");
  get(index_, "scenario", &h.scenario, "a text");
  get(index_, "seed", &h.seed, "a whole number");
  get(index_, "modes", &h.modes, "a list of mode names");
  get(index_, "sensors", &h.sensors, "a list of sensor names");
  get(index_, "cells_x", &h.cells_x, "a whole number");
  get(index_, "cells_y", &h.cells_y, "a whole number");
  get(index_, "resolution", &h.resolution, "a number [m]");
  get(index_, "frame_yaw_deg", &h.frame_yaw_deg, "a number [deg]");
  get(index_, "interval", &h.interval, "a number [s]");
  get(index_, "particle_unit", &h.particle_unit, "a number [m]");
  get(index_, "max_particles", &h.max_particles, "a whole number");
  get(index_, "dynamic_threshold", &h.dynamic_threshold, "a number");
  get(index_, "names", &h.names, "an object");
  get(index_, "metrics", &h.metrics, "an object");
  get(index_, "complete", &h.complete, "true or false");
  get(index_, "status", &h.status, "a text");
  if (index_.contains("multipath")) get(index_, "multipath", &h.multipath, "true or false");
  // The filter's own bound on cells (FilterParams) keeps the arrays allocatable.
  if (h.cells_x <= 0 || h.cells_y <= 0 || static_cast<double>(h.cells_x) * h.cells_y > 2e8)
    throw std::invalid_argument(where +
                                ": keys 'cells_x', 'cells_y': expected a grid of 1 to "
                                "2e8 cells");
  for (const auto& [key, value] : {std::pair<const char*, double>{"resolution", h.resolution},
                                   {"interval", h.interval},
                                   {"particle_unit", h.particle_unit}})
    if (!(value > 0.0) || !std::isfinite(value))
      throw std::invalid_argument(where + ": key '" + key + "': expected a positive number");
  if (h.modes.empty())
    throw std::invalid_argument(where + ": key 'modes': expected at least one mode");
  if (h.max_particles < 0)
    throw std::invalid_argument(where + ": key 'max_particles': expected >= 0");
  try {
    for (const json& b : index_.at("parked")) h.parked.push_back(BoxFrom(b));
    for (const json& r : index_.at("rails")) {
      h.rails.emplace_back();
      for (const json& p : r)
        h.rails.back().push_back({p.at(0).get<double>(), p.at(1).get<double>()});
    }
  } catch (const json::exception&) {
    throw std::invalid_argument(where + ": keys 'parked', 'rails': expected boxes and polylines");
  }
  const json& frames = index_.value("frames", json());
  if (!frames.is_array() || frames.empty())
    throw std::invalid_argument(where +
                                ": key 'frames': expected a non-empty list (a run "
                                "records its first frame after --record-interval)");
  // Each frame's blob must lie in frames.bin and its sizes be the header's, so that a damaged
  // index fails here with its key named, not later in the middle of a video.
  const std::uint64_t bin_size =
      fs::exists(dir_ / "frames.bin") ? fs::file_size(dir_ / "frames.bin") : 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::string key = "frames[" + std::to_string(i) + "]";
    const json& f = frames[i];
    double t = 0.0, yaw = 0.0;
    get(f, "t", &t, "a time [s] (in " + key + ")");
    get(f, "yaw", &yaw, "the grid frame's turn [deg] (in " + key + ")");
    if (!std::isfinite(t) || !std::isfinite(yaw))
      throw std::invalid_argument(where + ": key '" + key + "': expected a finite 't' and 'yaw'");
    times_.push_back(t);
    const json blob = f.value("blob", json());
    if (!blob.is_array() || blob.size() != 2 || !blob[0].is_number_unsigned() ||
        !blob[1].is_number_unsigned())
      throw std::invalid_argument(where + ": key '" + key + ".blob': expected [offset, length]");
    const auto offset = blob[0].get<std::uint64_t>(), length = blob[1].get<std::uint64_t>();
    if (length > bin_size || offset > bin_size - length)
      throw std::invalid_argument((dir_ / "frames.bin").string() + ": shorter than " + where +
                                  "'s " + key + ".blob says (truncated copy?)");
    const json modes = f.value("modes", json());
    if (!modes.is_array() || modes.size() != h.modes.size())
      throw std::invalid_argument(where + ": key '" + key + ".modes': expected " +
                                  std::to_string(h.modes.size()) + " entries");
    for (const json& m : modes) {
      const json np = m.value("np", json());
      if (!np.is_number_unsigned() ||
          np.get<std::uint64_t>() > static_cast<std::uint64_t>(h.max_particles))
        throw std::invalid_argument(where + ": key '" + key +
                                    ".modes[].np': expected 0 to max_particles");
    }
  }
}

std::vector<std::uint8_t> Reader::Compressed(std::size_t i) const {
  const json& blob = index_["frames"].at(i).at("blob");
  const auto offset = blob.at(0).get<std::uint64_t>();
  const auto length = blob.at(1).get<std::uint64_t>();
  std::ifstream in(dir_ / "frames.bin", std::ios::binary);
  in.seekg(static_cast<std::streamoff>(offset));
  std::vector<std::uint8_t> bytes(length);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(length));
  // The constructor checked the blob against the file's size: a failure now is a changed file.
  if (!in)
    throw std::invalid_argument("cannot read " + (dir_ / "frames.bin").string() +
                                " (changed since it was opened?)");
  return bytes;
}

Frame Reader::Load(std::size_t i) const {
  try {
    return LoadFrame(i);
  } catch (const json::exception& e) {
    throw std::invalid_argument((dir_ / "index.json").string() + ": frames[" + std::to_string(i) +
                                "]: " + e.what());
  }
}

Frame Reader::LoadFrame(std::size_t i) const {
  const std::string where = (dir_ / "index.json").string() + ": frames[" + std::to_string(i) + "]";
  const json& j = index_["frames"].at(i);
  const Header& h = header_;
  const std::size_t n = static_cast<std::size_t>(h.cells_x) * h.cells_y;
  Frame f;
  f.time = j.at("t").get<double>();
  f.yaw_deg = j.at("yaw").get<double>();
  f.ego = BoxFrom(j.at("ego"));
  f.origin_x = j.at("origin").at(0).get<double>();
  f.origin_y = j.at("origin").at(1).get<double>();
  for (const json& b : j.at("truth")) f.truth.push_back(BoxFrom(b));
  for (const json& d : j.at("det"))
    f.detections.push_back({d.at(0).get<int>(), d.at(1).get<double>(), d.at(2).get<double>(),
                            d.at(3).get<double>(), d.at(4).get<double>(), d.at(5).get<int>() != 0,
                            d.size() > 6 ? d.at(6).get<int>() : 0});
  const json& modes = j.at("modes");
  if (modes.size() != h.modes.size())
    throw std::invalid_argument(where + ": wrong number of modes");
  f.modes.resize(h.modes.size());
  std::size_t raw_size = 0;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    ModeFrame& mf = f.modes[m];
    for (const json& c : modes[m].at("cl"))
      mf.clusters.push_back({c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<double>(),
                             c.at(3).get<double>(), c.at(4).get<double>(), c.at(5).get<double>(),
                             c.at(6).get<double>(), c.at(7).get<double>(), c.at(8).get<int>(),
                             c.at(9).get<int>(), c.at(10).get<int>() != 0});
    const json& l = modes[m].at("live");
    mf.live = {l.at(0).get<int>(),  l.at(1).get<int>(),  l.at(2).get<int>(), l.at(3).get<int>(),
               l.at(4).get<long>(), l.at(5).get<long>(), l.at(6).get<long>()};
    raw_size += n * 7 + 4 * modes[m].at("np").get<std::size_t>();
  }
  const std::vector<std::uint8_t> packed = Compressed(i);
  std::vector<std::uint8_t> raw(raw_size);
  uLongf size = raw_size;
  if (uncompress(raw.data(), &size, packed.data(), packed.size()) != Z_OK || size != raw_size)
    throw std::invalid_argument(where + ": frame data damaged (zlib)");
  std::size_t at = 0;
  for (ModeFrame& mf : f.modes) {
    Take(raw, at, n, mf.vx_cm, where);
    Take(raw, at, n, mf.vy_cm, where);
  }
  for (std::size_t m = 0; m < f.modes.size(); ++m)
    Take(raw, at, 2 * modes[m].at("np").get<std::size_t>(), f.modes[m].particles, where);
  for (ModeFrame& mf : f.modes) {
    Take(raw, at, n, mf.free, where);
    Take(raw, at, n, mf.static_occ, where);
    Take(raw, at, n, mf.dynamic, where);
  }
  return f;
}

}  // namespace dualgrid::tools::replay
