#include "recording.hpp"

#include <zlib.h>

#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <stdexcept>

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
    throw std::runtime_error("replay: compressing frame t = " + Fixed(f.time, 2) + " s failed");
  bin_.write(reinterpret_cast<const char*>(packed_.data()),
             static_cast<std::streamsize>(packed_size));
  if (!bin_) throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string());

  json j = {{"t", R(f.time * 10.0) / 10.0},
            {"ego", BoxJson(f.ego)},
            {"origin", {R(f.origin_x), R(f.origin_y)}}};
  j["truth"] = json::array();
  for (const Box& b : f.truth) j["truth"].push_back(BoxJson(b));
  j["det"] = json::array();
  for (const Detection& d : f.detections)
    j["det"].push_back({d.sensor, R(d.x), R(d.y), R(d.vx), R(d.vy), d.clutter ? 1 : 0});
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
  try {
    if (index_.value("format", "") != "dualgrid-replay")
      throw std::invalid_argument(where + ": key 'format': expected \"dualgrid-replay\"");
    if (index_.at("version").get<int>() != kFormatVersion)
      throw std::invalid_argument(where + ": key 'version': expected " +
                                  std::to_string(kFormatVersion) + ", found " +
                                  index_.at("version").dump() + " (recorded by another release)");
    Header& h = header_;
    h.scenario = index_.at("scenario").get<std::string>();
    h.seed = index_.at("seed").get<std::uint64_t>();
    h.modes = index_.at("modes").get<std::vector<std::string>>();
    h.sensors = index_.at("sensors").get<std::vector<std::string>>();
    h.cells_x = index_.at("cells_x").get<int>();
    h.cells_y = index_.at("cells_y").get<int>();
    h.resolution = index_.at("resolution").get<double>();
    h.frame_yaw_deg = index_.at("frame_yaw_deg").get<double>();
    h.interval = index_.at("interval").get<double>();
    h.particle_unit = index_.at("particle_unit").get<double>();
    h.max_particles = index_.at("max_particles").get<int>();
    h.dynamic_threshold = index_.at("dynamic_threshold").get<double>();
    h.names = index_.at("names");
    h.metrics = index_.at("metrics");
    h.complete = index_.at("complete").get<bool>();
    h.status = index_.at("status").get<std::string>();
    for (const json& b : index_.at("parked")) h.parked.push_back(BoxFrom(b));
    for (const json& r : index_.at("rails")) {
      h.rails.emplace_back();
      for (const json& p : r)
        h.rails.back().push_back({p.at(0).get<double>(), p.at(1).get<double>()});
    }
    if (h.cells_x <= 0 || h.cells_y <= 0 || !(h.resolution > 0.0) || h.modes.empty())
      throw std::invalid_argument(where +
                                  ": keys 'cells_x', 'cells_y', 'resolution', 'modes': "
                                  "expected a non-empty grid and at least one mode");
    for (const json& f : index_.at("frames")) times_.push_back(f.at("t").get<double>());
  } catch (const json::exception& e) {
    throw std::invalid_argument(where + ": " + e.what());
  }
  const auto bin_size = fs::exists(dir_ / "frames.bin") ? fs::file_size(dir_ / "frames.bin") : 0;
  if (!times_.empty()) {
    const json& last = index_["frames"].back()["blob"];
    if (last.at(0).get<std::uint64_t>() + last.at(1).get<std::uint64_t>() > bin_size)
      throw std::invalid_argument((dir_ / "frames.bin").string() +
                                  ": shorter than index.json says (truncated copy?)");
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
  if (!in) throw std::runtime_error("cannot read " + (dir_ / "frames.bin").string());
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
  f.ego = BoxFrom(j.at("ego"));
  f.origin_x = j.at("origin").at(0).get<double>();
  f.origin_y = j.at("origin").at(1).get<double>();
  for (const json& b : j.at("truth")) f.truth.push_back(BoxFrom(b));
  for (const json& d : j.at("det"))
    f.detections.push_back({d.at(0).get<int>(), d.at(1).get<double>(), d.at(2).get<double>(),
                            d.at(3).get<double>(), d.at(4).get<double>(), d.at(5).get<int>() != 0});
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
