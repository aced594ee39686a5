#include "dualgrid/outputs/csv_writers.hpp"

#include <algorithm>
#include <charconv>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "dualgrid/core/text.hpp"
#include "dualgrid/recorded/run_folder_columns.hpp"

namespace dualgrid::outputs {

namespace {

// One CSV row at a time appended to a file's buffer, the numbers as printf writes them but
// without a std::string or a stream per number (the run writes ~600 numbers per step).
class CsvRow {
 public:
  explicit CsvRow(std::string& out) : out_(out) {}
  CsvRow& Int(long long v) { return Chars(std::to_chars(buf_, buf_ + sizeof buf_, v)); }
  /// printf's "%.<decimals>f" (FormatFixed): std::to_chars writes the same digits.
  CsvRow& Fixed(double v, int decimals) {
    const auto r = std::to_chars(buf_, buf_ + sizeof buf_, v, std::chars_format::fixed, decimals);
    return r.ec == std::errc() ? Chars(r) : Text(FormatFixed(v, decimals));  // beyond ~1e60
  }
  /// printf's "%.<digits>g", as a stream with precision(digits) writes a double.
  CsvRow& Significant(double v, int digits) {
    const auto r = std::to_chars(buf_, buf_ + sizeof buf_, v, std::chars_format::general, digits);
    return r.ec == std::errc() ? Chars(r) : Text(FormatSignificant(v, digits));
  }
  CsvRow& Text(std::string_view text) {
    Comma();
    out_ += text;
    return *this;
  }
  void End() {
    out_ += '\n';
    first_ = true;
  }

 private:
  void Comma() {
    if (!first_) out_ += ',';
    first_ = false;
  }
  CsvRow& Chars(const std::to_chars_result& r) {
    Comma();
    out_.append(buf_, r.ptr);
    return *this;
  }

  std::string& out_;
  char buf_[96];
  bool first_ = true;
};

}  // namespace

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
  CsvRow row(out_.buffer());
  auto vehicle = [&](const sim::VehicleState& v, bool is_ego) {
    const Position p = ego.ToLocal(v.box.center);
    const Velocity vr = ego.RotateToLocal(v.velocity);
    row.Int(f.step).Fixed(f.time, 3).Text(v.id).Text(v.type).Int(is_ego ? 1 : 0);
    row.Fixed(v.box.center.x(), 4).Fixed(v.box.center.y(), 4).Fixed(v.box.yaw, 6);
    row.Fixed(v.velocity.x(), 4).Fixed(v.velocity.y(), 4).Fixed(v.speed, 4);
    row.Fixed(v.lateral_speed, 4).Fixed(v.yaw_rate, 6).Fixed(v.box.length, 3);
    row.Fixed(v.box.width, 3).Text(v.lane).Fixed(p.x(), 4).Fixed(p.y(), 4).Fixed(vr.x(), 4);
    row.Fixed(vr.y(), 4).Fixed(v.rcs_dbsm, 1).End();
  };
  vehicle(f.ego, true);
  for (const auto& v : f.vehicles) vehicle(v, false);
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
  out_.buffer() += recorded::JoinColumns(recorded::kDetectionColumns);
  // The path columns only with multipath on.
  if (multipath_) (out_.buffer() += ',') += recorded::JoinColumns(recorded::kMultipathColumns);
  if (exact_) (out_.buffer() += ',') += recorded::kVClassColumn;
  out_.buffer() += "\n";
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
  out_.buffer() += recorded::JoinColumns(recorded::kScanColumns) + "\n";
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

ClusterWriter::ClusterWriter(const std::filesystem::path& path) : out_(path) {
  out_.buffer() += "step,time,mode,x,y,vx,vy,weight,particles,role,object,x_ego,y_ego\n";
}

void ClusterWriter::Rows(std::string& out, const sim::Frame& f, const GridFrame& g,
                         const std::string& mode, const cosim::ModeScorer& scorer,
                         const std::vector<eval::TruthObject>& objects,
                         const cosim::IdRegistry& ids) {
  static const char* kRole[] = {"matched", "duplicate", "false"};
  const auto& a = scorer.association();
  CsvRow row(out);
  for (std::size_t c = 0; c < scorer.clusters().size(); ++c) {
    const eval::Cluster& cl = scorer.clusters()[c];
    const Position pos = g.ToWorld(cl.position);
    const Velocity vel = g.VectorToWorld(cl.velocity);
    const Position local = f.EgoPose().ToLocal(pos);
    row.Int(f.step).Fixed(f.time, 3).Text(mode).Fixed(pos.x(), 3).Fixed(pos.y(), 3);
    row.Fixed(vel.x(), 3).Fixed(vel.y(), 3).Significant(cl.weight, 10).Int(cl.size);
    row.Text(kRole[static_cast<int>(a.role[c])]);
    row.Text(a.object_of_cluster[c] >= 0 ? ids.Name(objects[a.object_of_cluster[c]].id) : "");
    row.Fixed(local.x(), 2).Fixed(local.y(), 2).End();
  }
}

void ClusterWriter::Append(const std::string& rows) {
  out_.buffer() += rows;
  out_.MaybeFlush();
}

void WriteParticles(const cosim::Pipeline& pipeline, std::size_t m,
                    const cosim::GridSnapshot& snapshot, const std::filesystem::path& path) {
  OutputFile pc(path);
  pc.buffer() += "x,y,vx,vy,w_position,w_velocity,weight,p_dynamic\n";
  const auto& grid = pipeline.grid(m);
  const auto& ps = grid.particles();
  const GridFrame& g = pipeline.grid_frame();
  std::ostringstream os;
  os.precision(10);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const auto cell = grid.CellOf(Position(ps.x[i], ps.y[i]));
    const double pd =
        cell ? snapshot.dynamic[static_cast<std::size_t>(cell->y) * snapshot.cells_x + cell->x]
             : 0.0;
    // Written in the world frame, like every other file of the run.
    const Position pos = g.ToWorld(Position(ps.x[i], ps.y[i]));
    const Velocity vel = g.VectorToWorld(Velocity(ps.vx[i], ps.vy[i]));
    os << FormatFixed(pos.x(), 3) << ',' << FormatFixed(pos.y(), 3) << ','
       << FormatFixed(vel.x(), 3) << ',' << FormatFixed(vel.y(), 3) << ',' << ps.w_position[i]
       << ',' << ps.w_velocity[i] << ',' << ps.weight[i] << ',' << FormatFixed(pd, 3) << '\n';
  }
  pc.buffer() += os.str();
  pc.Close();
}

void WriteObjects(const std::vector<std::string>& modes,
                  const std::vector<eval::ScenarioMetrics>& metrics, const cosim::IdRegistry& ids,
                  const std::filesystem::path& path,
                  const std::map<std::string, std::string>* categories) {
  std::ostringstream os;
  os << "mode,id,name,frames_in_grid,frames_tracked,frames_tracked_v,scored,D,D_v,t_d,delta_x,"
        "delta_v"
     << (categories ? ",category\n" : "\n");
  auto opt = [](const std::optional<double>& v) { return v ? FormatFixed(*v, 4) : std::string(); };
  auto category = [&](const std::string& name) {
    if (!categories) return std::string();
    const auto it = categories->find(name);
    return "," + (it != categories->end() ? it->second : std::string());
  };
  for (std::size_t m = 0; m < modes.size(); ++m)
    for (const auto& o : metrics[m].objects)
      os << modes[m] << ',' << o.id << ',' << ids.Name(o.id) << ',' << o.frames_in_grid << ','
         << o.frames_tracked << ',' << o.frames_tracked_v << ',' << (o.scored ? 1 : 0) << ','
         << opt(o.tracked_fraction) << ',' << opt(o.tracked_fraction_v) << ','
         << opt(o.detection_time) << ',' << opt(o.position_error) << ',' << opt(o.velocity_error)
         << category(ids.Name(o.id)) << '\n';
  WriteTextFile(path, os.str());
}

void WriteWeights(const WeightTrace& t, const std::string& object,
                  const std::filesystem::path& path) {
  std::ostringstream os;
  os.precision(10);
  os << "time,object,w_position,w_velocity,w_resample,position_share,velocity_share,"
        "tangential_share\n";
  for (std::size_t i = 0; i < t.time.size(); ++i)
    os << FormatFixed(t.time[i], 3) << ',' << object << ',' << t.w_position[i] << ','
       << t.w_velocity[i] << ',' << t.weight[i] << ',' << t.position_share[i] << ','
       << t.velocity_share[i] << ',' << t.tangential_share[i] << '\n';
  WriteTextFile(path, os.str());
}

void WriteTables(const eval::ComparisonTable& table, const std::filesystem::path& dir) {
  WriteTextFile(dir / "table.md", table.ToMarkdown());
  WriteTextFile(dir / "table.csv", table.ToCsv());
  WriteTextFile(dir / "table.json", table.ToJson().dump(2) + "\n");
}

}  // namespace dualgrid::outputs
