// A run folder recorded with --detections exact, read as a recorded sequence.
#include "dualgrid/recorded/run_folder.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder_columns.hpp"

namespace dualgrid::recorded {

namespace {

// Bounds of the numbers of a run folder: coordinates and speeds [m, m/s, rad, rad/s] far beyond
// any road network, times [s] beyond any run.
constexpr double kMaxCoordinate = 1e7;
constexpr double kMaxTime = 1e9;

// A CSV file (plain or gzip) with a header row, read row by row through the checked reader:
// regular files only, at most kMaxStreamedInputBytes, lines of at most kMaxInputLineBytes.
class CsvReader {
 public:
  explicit CsvReader(const std::filesystem::path& path)
      : path_(path), in_(path, "run folder table") {
    if (!Next()) Fail("empty (no header row)");
    header_ = row_;
    line_ = 1;
  }

  /// The index of `column`; throws naming the file when it is missing.
  std::size_t Column(const std::string& column) const {
    for (std::size_t i = 0; i < header_.size(); ++i)
      if (header_[i] == column) return i;
    throw std::invalid_argument(path_.string() + ": column '" + column +
                                "' is missing (record the run with --detections exact)");
  }
  bool Next() {
    std::string line;
    if (!in_.ReadLine(&line)) return false;
    row_.clear();
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = line.find(',', start);
      row_.push_back(
          line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    ++line_;
    if (line_ > 1 && row_.size() != header_.size())
      Fail("row " + std::to_string(line_) + " has " + std::to_string(row_.size()) +
           " fields, the header " + std::to_string(header_.size()));
    return true;
  }
  const std::string& Text(std::size_t column) const { return row_[column]; }
  /// A finite number in [lo, hi] (the column's plausible range; the bound is named).
  double Number(std::size_t column, double lo = -kMaxCoordinate, double hi = kMaxCoordinate) const {
    const std::string& s = row_[column];
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(v))
      Fail("row " + std::to_string(line_) + ", column '" + header_[column] +
           "': expected a finite number, got '" + Shown(s) + "'");
    if (v < lo || v > hi)
      Fail("row " + std::to_string(line_) + ", column '" + header_[column] + "': " + Shown(s) +
           " is outside [" + FormatShort(lo) + ", " + FormatShort(hi) + "]");
    return v;
  }
  long Int(std::size_t column) const {
    const double v = Number(column);
    if (v != std::floor(v) || std::abs(v) > 1e9)
      Fail("row " + std::to_string(line_) + ", column '" + header_[column] +
           "': expected a whole number, got '" + Shown(row_[column]) + "'");
    return static_cast<long>(v);
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::invalid_argument(path_.string() + ": " + what);
  }
  int line() const { return line_; }

 private:
  // A field as a message shows it: at most 40 bytes.
  static std::string Shown(const std::string& s) {
    return s.size() > 40 ? s.substr(0, 40) + "..." : s;
  }

  std::filesystem::path path_;
  InputStream in_;
  std::vector<std::string> header_, row_;
  int line_ = 0;
};

RecordedSequence ReadRun(const std::filesystem::path& run_dir) {
  std::filesystem::path dir = run_dir.lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();
  CheckInputFolder(dir, "run folder");
  RecordedSequence seq;
  seq.name = std::filesystem::absolute(dir).filename().string();
  seq.has_labels = true;
  const std::filesystem::path scans_file = dir / "scans.csv";
  if (!InputExists(scans_file))
    throw std::invalid_argument(scans_file.string() +
                                ": missing: `filter` and `export` read a run recorded with "
                                "--detections exact (docs/recorded-data.md)");
  std::map<std::pair<long, long>, std::size_t> scan_of;  // (step, sensor) -> scan
  {
    CsvReader in(scans_file);
    const auto col = [&in](ScanColumn c) { return in.Column(std::string(kScanColumns[c])); };
    const std::size_t c_step = col(kScanStep), c_time = col(kScanTime), c_sensor = col(kScanSensor),
                      c_name = col(kScanSensorName), c_x = col(kScanEgoX), c_y = col(kScanEgoY),
                      c_yaw = col(kScanEgoYaw), c_vx = col(kScanEgoVx), c_vy = col(kScanEgoVy),
                      c_wz = col(kScanEgoYawRate), c_len = col(kScanEgoLength),
                      c_wid = col(kScanEgoWidth), c_lane = col(kScanLaneYaw),
                      c_mx = col(kScanMountX), c_my = col(kScanMountY), c_myaw = col(kScanMountYaw),
                      c_fov = col(kScanFov), c_rmin = col(kScanMinRange),
                      c_rmax = col(kScanMaxRange);
    std::int64_t last_t = -1;
    std::map<long, std::string> name_of;  // sensor -> its name in the first row
    while (in.Next()) {
      const long step = in.Int(c_step), sensor = in.Int(c_sensor);
      if (sensor < 0 || sensor > 63)
        in.Fail("row " + std::to_string(in.line()) + ", column 'sensor': out of range");
      if (static_cast<std::size_t>(sensor) >= seq.sensors.size()) seq.sensors.resize(sensor + 1);
      radar::SensorParams& s = seq.sensors[sensor];
      if (const auto [it, first] = name_of.try_emplace(sensor, in.Text(c_name));
          !first && it->second != in.Text(c_name))
        in.Fail("row " + std::to_string(in.line()) + ", column 'sensor_name': sensor " +
                std::to_string(sensor) + " was named '" + it->second +
                "' before (one name per sensor)");
      s.name = in.Text(c_name);
      s.mount = {{in.Number(c_mx), in.Number(c_my)}, in.Number(c_myaw)};
      s.fov = in.Number(c_fov);
      s.min_range = in.Number(c_rmin);
      s.max_range = in.Number(c_rmax);
      RecordedScan scan;
      scan.timestamp_us = std::llround(in.Number(c_time, 0.0, kMaxTime) * 1e6);
      if (scan.timestamp_us < last_t)
        in.Fail("row " + std::to_string(in.line()) + ", column 'time': not increasing");
      last_t = scan.timestamp_us;
      scan.sensor = static_cast<int>(sensor);
      scan.ego_pose = {{in.Number(c_x), in.Number(c_y)}, in.Number(c_yaw)};
      scan.ego_velocity = {in.Number(c_vx), in.Number(c_vy)};
      scan.ego_yaw_rate = in.Number(c_wz);
      scan.lane_yaw = in.Number(c_lane);
      seq.ego_length = in.Number(c_len);
      seq.ego_width = in.Number(c_wid);
      if (const std::string e = EgoSizeError(seq.ego_length, seq.ego_width); !e.empty())
        in.Fail("row " + std::to_string(in.line()) + ", ego " + e);
      if (!scan_of.try_emplace({step, sensor}, seq.scans.size()).second)
        in.Fail("row " + std::to_string(in.line()) + ": step " + std::to_string(step) +
                " and sensor " + std::to_string(sensor) + " given twice");
      seq.scans.push_back(scan);
    }
  }
  if (seq.scans.empty())
    throw std::invalid_argument(scans_file.string() + ": no scans (an empty run)");
  for (std::size_t k = 0; k < seq.sensors.size(); ++k) {
    std::string error;
    if (!seq.sensors[k].IsValid(&error))
      throw std::invalid_argument(scans_file.string() + ": sensor " + std::to_string(k) + ": " +
                                  error);
  }

  std::filesystem::path det_file = dir / "detections.csv";
  if (!InputExists(det_file)) det_file = dir / "detections.csv.gz";
  CsvReader in(det_file);
  const auto col = [&in](DetectionColumn c) {
    return in.Column(std::string(kDetectionColumns[c]));
  };
  const std::size_t c_step = col(kDetStep), c_sensor = col(kDetSensor), c_range = col(kDetRange),
                    c_az = col(kDetAzimuth), c_rr = col(kDetRangeRate), c_x = col(kDetX),
                    c_y = col(kDetY), c_vr = col(kDetRadialSpeed), c_source = col(kDetSource),
                    c_vclass = in.Column(std::string(kVClassColumn));
  std::map<std::string, int> track_index;
  std::size_t current = 0;  // scans are filled in order
  for (auto& s : seq.scans) s.begin = s.end = 0;
  bool any = false;
  while (in.Next()) {
    const auto it = scan_of.find({in.Int(c_step), in.Int(c_sensor)});
    if (it == scan_of.end())
      in.Fail("row " + std::to_string(in.line()) + ": step and sensor have no row in scans.csv");
    if (any && it->second < current)
      in.Fail("row " + std::to_string(in.line()) + ": out of order (scans.csv's order expected)");
    for (std::size_t k = any ? current + 1 : 0; k <= it->second; ++k)
      seq.scans[k].begin = seq.scans[k].end = seq.points.size();
    current = it->second;
    any = true;
    RecordedPoint p;
    p.range = in.Number(c_range);
    p.azimuth = in.Number(c_az);
    p.range_rate = in.Number(c_rr);
    p.radial_speed = in.Number(c_vr);
    p.position = {in.Number(c_x), in.Number(c_y)};
    const std::string& vclass = in.Text(c_vclass);
    if (vclass.empty()) {
      p.label = kStaticLabel;  // clutter, ghosts, guard rails and parked boxes
    } else {
      p.label = LabelOfVClass(vclass);
      const std::string& name = in.Text(c_source);
      const auto [t, inserted] =
          track_index.try_emplace(name, static_cast<int>(seq.track_names.size()));
      if (inserted) seq.track_names.push_back(name);
      p.track = t->second;
    }
    seq.points.push_back(p);
    seq.scans[current].end = seq.points.size();
  }
  for (std::size_t k = any ? current + 1 : 0; k < seq.scans.size(); ++k)
    seq.scans[k].begin = seq.scans[k].end = seq.points.size();
  const std::int64_t t0 = seq.scans.front().timestamp_us;
  seq.time_origin_us = t0 - t0 % 1000000;
  return seq;
}

}  // namespace

RecordedSequence ReadRunFolder(const std::filesystem::path& run_dir) {
  return NamingInputOnFailure(run_dir, "run folder", [&] { return ReadRun(run_dir); });
}

std::vector<NuScenesKeyFrame> ReadKeyFrames(const std::filesystem::path& run_dir,
                                            const RecordedSequence& seq, double period) {
  std::map<std::string, std::string> category;  // track -> category
  for (const RecordedPoint& p : seq.points)
    if (p.track >= 0) category.try_emplace(seq.track_names[p.track], CategoryOfLabel(p.label));
  std::filesystem::path file = run_dir / "ground_truth.csv";
  if (!InputExists(file)) file = run_dir / "ground_truth.csv.gz";
  CsvReader in(file);
  const std::size_t c_step = in.Column("step"), c_time = in.Column("time"), c_id = in.Column("id"),
                    c_ego = in.Column("is_ego"), c_x = in.Column("x"), c_y = in.Column("y"),
                    c_yaw = in.Column("yaw"), c_vx = in.Column("vx"), c_vy = in.Column("vy"),
                    c_len = in.Column("length"), c_wid = in.Column("width");
  std::vector<NuScenesKeyFrame> out;
  long last_step = -1;
  while (in.Next()) {
    const double t = in.Number(c_time, 0.0, kMaxTime);
    const double k = t / period;
    if (std::abs(k - std::round(k)) > 1e-6) continue;
    const long step = in.Int(c_step);
    if (step != last_step) {
      out.push_back({std::llround(t * 1e6), {}});
      last_step = step;
    }
    if (in.Int(c_ego) != 0) continue;
    ReferenceObject v;
    v.id = in.Text(c_id);
    const auto c = category.find(v.id);
    v.type = c != category.end() ? c->second : "vehicle.car";
    v.box = {
        {in.Number(c_x), in.Number(c_y)}, in.Number(c_yaw), in.Number(c_len), in.Number(c_wid)};
    if (const std::string e = EgoSizeError(v.box.length, v.box.width); !e.empty())
      in.Fail("row " + std::to_string(in.line()) + ", vehicle '" + v.id + "' " + e);
    v.velocity = {in.Number(c_vx), in.Number(c_vy)};
    out.back().vehicles.push_back(std::move(v));
  }
  return out;
}

}  // namespace dualgrid::recorded
