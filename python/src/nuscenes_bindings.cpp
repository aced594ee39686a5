// read_nuscenes and read_radarscenes: the recorded-data readers for notebooks, without the
// filter (docs/python.md, "Recorded data as arrays"). Each returns a dict of 1-D numpy columns
// per table (pandas.DataFrame(r["points"]) makes a frame of it) in the world frame, SI units.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/radarscenes.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

// points: one row per detection with its scan's time and sensor; scans: one row per scan with
// the ego's state and its points' range [begin, end).
void SequenceColumns(const recorded::RecordedSequence& seq, py::dict* out) {
  std::vector<double> x, y, range, azimuth, range_rate, radial, rcs, time;
  std::vector<std::int64_t> timestamp, sensor, scan, label;
  std::vector<std::string> track;
  std::vector<double> s_time, ex, ey, eyaw, evx, evy, ewz;
  std::vector<std::int64_t> s_ts, s_sensor, s_begin, s_end;
  for (std::size_t k = 0; k < seq.scans.size(); ++k) {
    const recorded::RecordedScan& s = seq.scans[k];
    s_ts.push_back(s.timestamp_us);
    s_time.push_back(seq.Time(s.timestamp_us));
    s_sensor.push_back(s.sensor);
    ex.push_back(s.ego_pose.position.x());
    ey.push_back(s.ego_pose.position.y());
    eyaw.push_back(s.ego_pose.yaw);
    evx.push_back(s.ego_velocity.x());
    evy.push_back(s.ego_velocity.y());
    ewz.push_back(s.ego_yaw_rate);
    s_begin.push_back(static_cast<std::int64_t>(s.begin));
    s_end.push_back(static_cast<std::int64_t>(s.end));
    for (std::size_t i = s.begin; i < s.end; ++i) {
      const recorded::RecordedPoint& p = seq.points[i];
      x.push_back(p.position.x());
      y.push_back(p.position.y());
      range.push_back(p.range);
      azimuth.push_back(p.azimuth);
      range_rate.push_back(p.range_rate);
      radial.push_back(p.radial_speed);
      rcs.push_back(p.rcs);
      time.push_back(seq.Time(s.timestamp_us));
      timestamp.push_back(s.timestamp_us);
      sensor.push_back(s.sensor);
      scan.push_back(static_cast<std::int64_t>(k));
      label.push_back(p.label);
      track.push_back(p.track >= 0 ? seq.track_names[p.track] : std::string());
    }
  }
  py::dict points;
  points["x"] = ToArray(x);
  points["y"] = ToArray(y);
  points["range"] = ToArray(range);
  points["azimuth"] = ToArray(azimuth);
  points["range_rate"] = ToArray(range_rate);
  points["radial_speed"] = ToArray(radial);
  points["rcs"] = ToArray(rcs);
  points["time"] = ToArray(time);
  points["timestamp"] = ToArray(timestamp);
  points["sensor"] = ToArray(sensor);
  points["scan"] = ToArray(scan);
  points["label"] = ToArray(label);
  points["track"] = track;
  py::dict scans;
  scans["timestamp"] = ToArray(s_ts);
  scans["time"] = ToArray(s_time);
  scans["sensor"] = ToArray(s_sensor);
  scans["ego_x"] = ToArray(ex);
  scans["ego_y"] = ToArray(ey);
  scans["ego_yaw"] = ToArray(eyaw);
  scans["ego_vx"] = ToArray(evx);
  scans["ego_vy"] = ToArray(evy);
  scans["ego_yaw_rate"] = ToArray(ewz);
  scans["begin"] = ToArray(s_begin);
  scans["end"] = ToArray(s_end);
  py::list sensors;
  for (const radar::SensorParams& s : seq.sensors) {
    py::dict d;
    d["name"] = s.name;
    d["x"] = s.mount.position.x();
    d["y"] = s.mount.position.y();
    d["yaw"] = s.mount.yaw;
    d["fov"] = s.fov;
    d["min_range"] = s.min_range;
    d["max_range"] = s.max_range;
    sensors.append(d);
  }
  (*out)["name"] = seq.name;
  (*out)["points"] = points;
  (*out)["scans"] = scans;
  (*out)["sensors"] = sensors;
  (*out)["ego_length"] = seq.ego_length;
  (*out)["ego_width"] = seq.ego_width;
  (*out)["time_origin_us"] = seq.time_origin_us;
}

py::dict AnnotationColumns(const recorded::NuScenesScene& n, std::int64_t origin) {
  std::vector<std::string> instance, category;
  std::vector<std::int64_t> ts, pts, moving;
  std::vector<double> time, x, y, yaw, length, width, vx, vy;
  for (const recorded::NuScenesAnnotation& a : n.annotations) {
    instance.push_back(a.instance);
    category.push_back(a.category);
    ts.push_back(a.timestamp_us);
    time.push_back(static_cast<double>(a.timestamp_us - origin) / 1e6);
    x.push_back(a.center.x());
    y.push_back(a.center.y());
    yaw.push_back(a.yaw);
    length.push_back(a.length);
    width.push_back(a.width);
    vx.push_back(a.velocity.x());
    vy.push_back(a.velocity.y());
    pts.push_back(a.num_radar_pts);
    moving.push_back(a.moving ? 1 : 0);
  }
  py::dict d;
  d["instance"] = instance;
  d["category"] = category;
  d["timestamp"] = ToArray(ts);
  d["time"] = ToArray(time);
  d["x"] = ToArray(x);
  d["y"] = ToArray(y);
  d["yaw"] = ToArray(yaw);
  d["length"] = ToArray(length);
  d["width"] = ToArray(width);
  d["vx"] = ToArray(vx);
  d["vy"] = ToArray(vy);
  d["num_radar_pts"] = ToArray(pts);
  d["moving"] = ToArray(moving);
  return d;
}

std::vector<int> States(const std::optional<std::vector<int>>& v) {
  return v ? *v : std::vector<int>();
}

py::dict ReadNuScenes(const fs::path& root, const std::string& scene, const std::string& version,
                      const std::optional<std::vector<int>>& invalid_states,
                      const std::optional<std::vector<int>>& dynprop_states,
                      const std::optional<std::vector<int>>& ambig_states) {
  recorded::NuScenesOptions o;
  o.scene = scene;
  o.version = version;
  o.invalid_states = States(invalid_states);
  o.dynprop_states = States(dynprop_states);
  o.ambig_states = States(ambig_states);
  recorded::NuScenesScene n;
  {
    py::gil_scoped_release release;
    n = recorded::ReadNuScenes(root, o);
  }
  py::dict r;
  SequenceColumns(n.sequence, &r);
  r["channels"] = n.channels;
  r["scene_token"] = n.scene_token;
  r["annotations"] = AnnotationColumns(n, n.sequence.time_origin_us);
  r["filtered_points"] = n.filtered_points;
  r["empty_clouds"] = n.empty_clouds;
  r["skipped_instances"] = n.skipped_instances;
  r["ego_velocity_estimated"] = n.ego_velocity_estimated;
  return r;
}

py::dict ReadRadarScenesArrays(const fs::path& sequence, std::optional<fs::path> sensors) {
  recorded::RecordedSequence seq;
  {
    py::gil_scoped_release release;
    seq = recorded::ReadRadarScenes(sequence, sensors);
  }
  py::dict r;
  SequenceColumns(seq, &r);
  r["skipped_points"] = seq.skipped_points;
  return r;
}

}  // namespace

void BindNuScenes(py::module_& m) {
  m.def("read_nuscenes", &ReadNuScenes, py::arg("root"), py::arg("scene"),
        py::arg("version") = "v1.0-mini", py::arg("invalid_states") = std::vector<int>{0},
        py::arg("dynprop_states") = py::none(), py::arg("ambig_states") = std::vector<int>{3},
        "Reads one scene of a nuScenes-layout dataset as `dualgrid filter ROOT --scene` does "
        "(docs/recorded-data.md): a dict with 'points' (world x, y [m], range [m], azimuth "
        "[rad], range_rate and radial_speed [m/s], rcs, time [s], timestamp [us], sensor, scan, "
        "label, track), 'scans' (per sample_data: the ego's box centre, heading, velocity), "
        "'sensors', 'channels' and 'annotations' (per key frame and vehicle instance: box, the "
        "devkit's velocity, num_radar_pts, moving). Each table is a dict of 1-D columns: "
        "pandas.DataFrame(r['points']). The state filters keep the listed values (None: all); "
        "the defaults are the devkit's. Bad input raises ValueError naming the file and field.");
  m.def("read_radarscenes", &ReadRadarScenesArrays, py::arg("sequence"),
        py::arg("sensors") = py::none(),
        "Reads a RadarScenes sequence folder as `dualgrid filter` does: a dict with 'points', "
        "'scans' and 'sensors' as read_nuscenes returns them (label: RadarScenes' label_id, "
        "track: track_id).");
}

}  // namespace dualgrid::python
