#include "dualgrid/outputs/recording.hpp"

#include <zlib.h>

#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/write_file.hpp"
#include "dualgrid/outputs/output_file.hpp"

namespace dualgrid::outputs::replay {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Centimetre rounding keeps index.json small without losing anything a picture shows.
double R(double v) { return std::round(v * 100.0) / 100.0; }
// Detections, most of the index: decimetres and 0.1 m/s (a radar's own accuracy is coarser).
double D(double v) { return std::round(v * 10.0) / 10.0; }

json BoxJson(const Box& b) {
  return json::array({b.id, R(b.x), R(b.y), std::round(b.yaw * 1e4) / 1e4, R(b.length), R(b.width),
                      R(b.vx), R(b.vy)});
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
  if (h.truth_label != Header{}.truth_label) j["truth_label"] = h.truth_label;
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

Writer::Writer(const fs::path& dir, Header header, OutputWorker& worker)
    : dir_(dir), header_(std::move(header)), worker_(worker) {
  fs::create_directories(dir_);
  // A stale index from an earlier run must not describe this run's frames.
  fs::remove(dir_ / "index.json");
  bin_.open(dir_ / "frames.bin", std::ios::binary | std::ios::trunc);
  if (!bin_)
    throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string() + ": " +
                             SystemReason());
}

Writer::~Writer() {
  while (!in_flight_.empty()) {
    try {
      WaitOldest();
    } catch (...) {  // NOLINT(bugprone-empty-catch): the owner gave up on this recording
    }
  }
}

void Writer::WaitOldest() {
  std::future<void> oldest = std::move(in_flight_.front());
  in_flight_.pop_front();
  oldest.get();
}

void Writer::Add(Frame frame) {
  if (in_flight_.size() >= kFramesInFlight) WaitOldest();
  ++added_;
  // std::function needs a copyable callable: the frame travels in a shared_ptr.
  auto owned = std::make_shared<const Frame>(std::move(frame));
  in_flight_.push_back(worker_.Post([this, owned] { Write(*owned); }));
}

void Writer::Write(const Frame& f) {
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
  if (!DeflateRle(raw_, packed_))
    throw std::runtime_error("replay: compressing frame t = " + FormatFixed(f.time, 2) +
                             " s failed");
  const std::size_t packed_size = packed_.size();
  bin_.write(reinterpret_cast<const char*>(packed_.data()),
             static_cast<std::streamsize>(packed_size));
  if (!bin_)
    throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string() + ": " +
                             SystemReason());

  json j = {{"t", R(f.time * 10.0) / 10.0},
            {"yaw", f.yaw_deg},  // exact: positions far from the origin turn with it
            {"ego", BoxJson(f.ego)},
            {"origin", {R(f.origin_x), R(f.origin_y)}}};
  j["truth"] = json::array();
  for (const Box& b : f.truth) j["truth"].push_back(BoxJson(b));
  j["det"] = json::array();
  for (const Detection& d : f.detections) {
    json row = {d.sensor, D(d.x), D(d.y), D(d.vx), D(d.vy), d.clutter ? 1 : 0};
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

void Writer::Flush() {
  while (!in_flight_.empty()) WaitOldest();
}

void Writer::Finish(const Header& final_header) {
  Flush();
  bin_.close();
  if (!bin_)
    throw std::runtime_error("cannot write " + (dir_ / "frames.bin").string() + ": " +
                             SystemReason());
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

namespace {

// Bounds of a recording that the reader accepts: above any recording `run` writes, low enough
// that a damaged or hostile index cannot make the video or the viewer allocate without end.
constexpr std::int64_t kMaxCellsPerAxis = 1000000;
constexpr std::uint64_t kMaxFrameBytes = std::uint64_t{1} << 30;  // one frame, inflated
constexpr std::int64_t kMaxParticles = 1000000;                   // as --record-particles
constexpr std::size_t kMaxModes = 3, kMaxSensors = 64, kMaxFrames = 10000000;

Box BoxAt(const JsonAt& j) {
  const auto v = j.Tuple(8);
  return {static_cast<int>(v[0].Integer(-1, INT32_MAX)),
          v[1].Number(),
          v[2].Number(),
          v[3].Number(),
          v[4].Number(0.0, 1e6),
          v[5].Number(0.0, 1e6),
          v[6].Number(),
          v[7].Number()};
}

}  // namespace

Reader::Reader(const fs::path& run_dir) : dir_(run_dir / "replay") {
  const fs::path index_path = dir_ / "index.json";
  if (!fs::is_directory(run_dir))
    throw std::invalid_argument(run_dir.string() + ": no such run folder");
  if (!fs::exists(index_path))
    throw std::invalid_argument(
        index_path.string() +
        ": missing (the run was made with --no-record or --no-figures, or did not finish; "
        "rerun `dualgrid run` without them)");
  index_file_ =
      std::make_unique<JsonFile>(ReadJsonFile(index_path, "replay index", kMaxStreamedInputBytes));
  const JsonAt root = index_file_->Root();
  const std::string where = index_path.string();
  if (!root.raw().is_object()) root.Fail("an object (a dualgrid replay index)");
  if (root["format"].raw() != "dualgrid-replay") root["format"].Fail("\"dualgrid-replay\"");
  if (root["version"].raw() != kFormatVersion)
    root["version"].Fail(std::to_string(kFormatVersion) + " (recorded by another release)");
  Header& h = header_;
  h.scenario = root["scenario"].Text();
  h.seed = root["seed"].Unsigned();
  for (const JsonAt& m : root["modes"].Items(kMaxModes)) h.modes.push_back(m.Text());
  if (h.modes.empty()) root["modes"].Fail("at least one mode");
  for (const JsonAt& s : root["sensors"].Items(kMaxSensors)) h.sensors.push_back(s.Text());
  h.cells_x = static_cast<int>(root["cells_x"].Integer(1, kMaxCellsPerAxis));
  h.cells_y = static_cast<int>(root["cells_y"].Integer(1, kMaxCellsPerAxis));
  h.resolution = root["resolution"].Number(1e-3, 1e3);
  h.frame_yaw_deg = root["frame_yaw_deg"].Number();
  h.interval = root["interval"].Number(1e-4, 1e4);
  h.particle_unit = root["particle_unit"].Number(1e-4, 1e3);
  h.max_particles = static_cast<int>(root["max_particles"].Integer(0, kMaxParticles));
  h.dynamic_threshold = root["dynamic_threshold"].Number(0.0, 1.0);
  if (!root["names"].raw().is_object()) root["names"].Fail("an object");
  h.names = root["names"].raw();
  if (!root["metrics"].raw().is_object()) root["metrics"].Fail("an object");
  h.metrics = root["metrics"].raw();
  h.complete = root["complete"].Flag();
  h.status = root["status"].Text();
  if (root.Has("multipath")) h.multipath = root["multipath"].Flag();
  if (root.Has("truth_label")) h.truth_label = root["truth_label"].Text();
  if (h.truth_label.empty()) root["truth_label"].Fail("a name");
  // What one frame inflates to must be allocatable: the video and the viewer hold one.
  const std::uint64_t cells = static_cast<std::uint64_t>(h.cells_x) * h.cells_y;
  if ((cells * 7 + 4 * static_cast<std::uint64_t>(h.max_particles)) * h.modes.size() >
      kMaxFrameBytes)
    throw std::invalid_argument(
        where + ": keys 'cells_x', 'cells_y', 'max_particles': a frame of " +
        std::to_string(h.cells_x) + " x " + std::to_string(h.cells_y) + " cells and " +
        std::to_string(h.max_particles) + " particles per mode, expected at most 1 GiB per frame");
  for (const JsonAt& b : root["parked"].Items()) h.parked.push_back(BoxAt(b));
  for (const JsonAt& r : root["rails"].Items()) {
    h.rails.emplace_back();
    for (const JsonAt& p : r.Items()) {
      const auto xy = p.Tuple(2);
      h.rails.back().push_back({xy[0].Number(), xy[1].Number()});
    }
  }
  const JsonAt frames = root["frames"];
  const auto list = frames.Items(kMaxFrames);
  if (list.empty())
    frames.Fail("a non-empty list (a run records its first frame after --record-interval)");
  // Each frame's blob must lie in frames.bin and its particle counts within the header's, so that
  // a damaged index fails here with its key named, not later in the middle of a video.
  const fs::path bin = dir_ / "frames.bin";
  std::error_code ec;
  const fs::file_status bin_status = fs::status(bin, ec);
  if (fs::exists(bin_status) && !fs::is_regular_file(bin_status))
    throw std::invalid_argument(
        bin.string() + ": the recording's frames are not a regular file (" +
        (fs::is_directory(bin_status) ? "a directory" : "a device or pipe") +
        "), expected the frames.bin a run writes");
  std::error_code size_ec;
  const std::uint64_t bin_size =
      fs::is_regular_file(bin_status) ? fs::file_size(bin, size_ec) : 0;  // 0: missing
  if (size_ec)
    throw std::invalid_argument(bin.string() + ": cannot read its size: " + size_ec.message());
  for (const JsonAt& f : list) {
    times_.push_back(f["t"].Number());
    f["yaw"].Number();
    const auto blob = f["blob"].Tuple(2);
    const std::uint64_t offset = blob[0].Unsigned(), length = blob[1].Unsigned();
    if (length > bin_size || offset > bin_size - length)
      throw std::invalid_argument(bin.string() + ": shorter than " + where + "'s " +
                                  f["blob"].key() + " says (" +
                                  (fs::exists(bin_status) ? "truncated copy?" : "missing") + ")");
    blobs_.push_back({offset, length});
    const auto modes = f["modes"].Tuple(h.modes.size());
    for (const JsonAt& m : modes) m["np"].Integer(0, h.max_particles);
  }
}

Reader::~Reader() = default;

const nlohmann::json& Reader::index() const { return index_file_->doc(); }

std::vector<std::uint8_t> Reader::Compressed(std::size_t i) const {
  const auto [offset, length] = blobs_.at(i);
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
  const JsonAt j = index_file_->Root()["frames"].Item(i);
  const Header& h = header_;
  const std::size_t n = static_cast<std::size_t>(h.cells_x) * h.cells_y;
  const std::string where = j.file() + ": " + j.key();
  Frame f;
  f.time = j["t"].Number();
  f.yaw_deg = j["yaw"].Number();
  f.ego = BoxAt(j["ego"]);
  const auto origin = j["origin"].Tuple(2);
  f.origin_x = origin[0].Number();
  f.origin_y = origin[1].Number();
  for (const JsonAt& b : j["truth"].Items()) f.truth.push_back(BoxAt(b));
  const auto sensors = static_cast<std::int64_t>(h.sensors.size());
  for (const JsonAt& d : j["det"].Items()) {
    if (!d.raw().is_array() || (d.raw().size() != 6 && d.raw().size() != 7))
      d.Fail("a detection [sensor, x, y, vx, vy, clutter] or [..., path]");
    const auto v = d.Items();
    f.detections.push_back(
        {static_cast<int>(v[0].Integer(0, std::max<std::int64_t>(sensors - 1, 0))), v[1].Number(),
         v[2].Number(), v[3].Number(), v[4].Number(), v[5].Integer(0, 1) != 0,
         v.size() > 6 ? static_cast<int>(v[6].Integer(0, 2)) : 0});
  }
  const auto modes = j["modes"].Tuple(h.modes.size());
  f.modes.resize(h.modes.size());
  std::size_t raw_size = 0;
  std::vector<std::size_t> np(modes.size());
  for (std::size_t m = 0; m < modes.size(); ++m) {
    ModeFrame& mf = f.modes[m];
    for (const JsonAt& c : modes[m]["cl"].Items()) {
      const auto v = c.Tuple(11);
      mf.clusters.push_back(
          {v[0].Number(), v[1].Number(), v[2].Number(), v[3].Number(), v[4].Number(), v[5].Number(),
           v[6].Number(), v[7].Number(), static_cast<int>(v[8].Integer(0, 2)),
           static_cast<int>(v[9].Integer(-1, INT32_MAX)), v[10].Integer(0, 1) != 0});
    }
    const auto l = modes[m]["live"].Tuple(7);
    mf.live = {static_cast<int>(l[0].Integer(0, INT32_MAX)),
               static_cast<int>(l[1].Integer(0, INT32_MAX)),
               static_cast<int>(l[2].Integer(0, INT32_MAX)),
               static_cast<int>(l[3].Integer(0, INT32_MAX)),
               l[4].Integer(0, INT64_MAX),
               l[5].Integer(0, INT64_MAX),
               l[6].Integer(0, INT64_MAX)};
    np[m] = static_cast<std::size_t>(modes[m]["np"].Integer(0, h.max_particles));
    raw_size += n * 7 + 4 * np[m];
  }
  const std::vector<std::uint8_t> packed = Compressed(i);
  std::vector<std::uint8_t> raw(raw_size);
  uLongf size = raw_size;
  if (uncompress(raw.data(), &size, packed.data(), packed.size()) != Z_OK || size != raw_size)
    throw std::invalid_argument((dir_ / "frames.bin").string() + ": frame " + std::to_string(i) +
                                " (index.json's " + j.key() +
                                ".blob) is damaged: expected a zlib stream of " +
                                std::to_string(raw_size) + " bytes");
  std::size_t at = 0;
  for (ModeFrame& mf : f.modes) {
    Take(raw, at, n, mf.vx_cm, where);
    Take(raw, at, n, mf.vy_cm, where);
  }
  for (std::size_t m = 0; m < f.modes.size(); ++m)
    Take(raw, at, 2 * np[m], f.modes[m].particles, where);
  for (ModeFrame& mf : f.modes) {
    Take(raw, at, n, mf.free, where);
    Take(raw, at, n, mf.static_occ, where);
    Take(raw, at, n, mf.dynamic, where);
  }
  return f;
}

}  // namespace dualgrid::outputs::replay
