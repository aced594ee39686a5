// A run folder recorded with --detections exact, read as a recorded sequence.
#include "dualgrid/recorded/run_folder.hpp"

#include <zlib.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/run_folder_columns.hpp"

namespace dualgrid::recorded {

namespace {

// A CSV file (plain or gzip: zlib reads both) with a header row, read row by row.
class CsvReader {
 public:
  explicit CsvReader(const std::filesystem::path& path) : path_(path) {
    file_ = gzopen(path.string().c_str(), "rb");
    if (!file_) throw std::invalid_argument(path.string() + ": cannot be read");
    if (!Next()) Fail("empty (no header row)");
    header_ = row_;
    line_ = 1;
  }
  ~CsvReader() {
    if (file_) gzclose(file_);
  }
  CsvReader(const CsvReader&) = delete;
  CsvReader& operator=(const CsvReader&) = delete;

  /// The index of `column`; throws naming the file when it is missing.
  std::size_t Column(const std::string& column) const {
    for (std::size_t i = 0; i < header_.size(); ++i)
      if (header_[i] == column) return i;
    throw std::invalid_argument(path_.string() + ": column '" + column +
                                "' is missing (record the run with --detections exact)");
  }
  bool Next() {
    std::string line;
    char buf[4096];
    for (;;) {
      if (!gzgets(file_, buf, sizeof buf)) {
        int err = 0;
        gzerror(file_, &err);
        if (err != Z_OK && err != Z_STREAM_END) Fail("read failed (truncated or damaged?)");
        if (line.empty()) return false;
        break;
      }
      line += buf;
      if (!line.empty() && line.back() == '\n') break;
    }
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
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
  double Number(std::size_t column) const {
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
           "': expected a finite number, got '" + s + "'");
    return v;
  }
  long Int(std::size_t column) const {
    const double v = Number(column);
    if (v != std::floor(v) || std::abs(v) > 1e9)
      Fail("row " + std::to_string(line_) + ", column '" + header_[column] +
           "': expected a whole number, got '" + row_[column] + "'");
    return static_cast<long>(v);
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::invalid_argument(path_.string() + ": " + what);
  }
  int line() const { return line_; }

 private:
  std::filesystem::path path_;
  gzFile file_ = nullptr;
  std::vector<std::string> header_, row_;
  int line_ = 0;
};

}  // namespace

RecordedSequence ReadRunFolder(const std::filesystem::path& run_dir) {
  std::filesystem::path dir = run_dir.lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();
  RecordedSequence seq;
  seq.name = std::filesystem::absolute(dir).filename().string();
  seq.has_labels = true;
  const std::filesystem::path scans_file = dir / "scans.csv";
  if (!std::filesystem::exists(scans_file))
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
    while (in.Next()) {
      const long step = in.Int(c_step), sensor = in.Int(c_sensor);
      if (sensor < 0 || sensor > 63)
        in.Fail("row " + std::to_string(in.line()) + ", column 'sensor': out of range");
      if (static_cast<std::size_t>(sensor) >= seq.sensors.size()) seq.sensors.resize(sensor + 1);
      radar::SensorParams& s = seq.sensors[sensor];
      s.name = in.Text(c_name);
      s.mount = {{in.Number(c_mx), in.Number(c_my)}, in.Number(c_myaw)};
      s.fov = in.Number(c_fov);
      s.min_range = in.Number(c_rmin);
      s.max_range = in.Number(c_rmax);
      RecordedScan scan;
      scan.timestamp_us = std::llround(in.Number(c_time) * 1e6);
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
  if (!std::filesystem::exists(det_file)) det_file = dir / "detections.csv.gz";
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

}  // namespace dualgrid::recorded
