// run_recorded: the filters of each mode on a recorded sequence (a RadarScenes sequence folder
// or a run folder recorded with --detections exact), as `dualgrid filter` runs them; the same
// result dict as run_scenario.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/recorded_source.hpp"
#include "dualgrid/outputs/output_guard.hpp"
#include "dualgrid/recorded/radarscenes.hpp"
#include "dualgrid/recorded/recorded_run.hpp"
#include "dualgrid/recorded/run_folder.hpp"
#include "run_results.hpp"
#include "run_setup.hpp"

namespace dualgrid::python {
namespace {

namespace fs = std::filesystem;

py::dict RunRecorded(const fs::path& path, std::optional<fs::path> sensors,
                     std::optional<fs::path> scenario_file,
                     const std::vector<std::string>& overrides, std::optional<Seed> seed,
                     const std::vector<std::string>& modes, double batch_window, int threads) {
  const RecordedSetup setup =
      LoadRecorded(path, sensors, scenario_file, overrides, seed, batch_window, "run_recorded");
  const cosim::CoSimOptions options = RunOptions(modes, threads, "run_recorded");
  cosim::CoSimulation cs(
      setup.config, options, [&](const scenario::ScenarioConfig&, cosim::IdRegistry&) {
        return std::make_unique<cosim::RecordedSource>(setup.input.sequence, setup.options);
      });
  ClusterColumns clusters;
  {
    py::gil_scoped_release release;
    cs.Start({}, {});
    cs.AddObserver(&clusters);
    while (cs.Step()) {
    }
    cs.Finish();
  }
  py::dict r = Results(cs, setup.config, clusters);
  r["input"] = RecordedInputInfo(setup.input);
  return r;
}

// The points of a recorded sequence as numpy columns, one row per detection, with its scan's
// time, sensor and ego state broadcast.
py::dict PointColumns(const cosim::RecordedSequence& seq) {
  const std::size_t n = seq.points.size();
  std::vector<std::int64_t> ts(n);
  std::vector<int> scan(n), sensor(n), label(n), track(n);
  std::vector<double> time(n), range(n), azimuth(n), rr(n), vr(n), rcs(n), x(n), y(n);
  for (std::size_t s = 0; s < seq.scans.size(); ++s) {
    const cosim::RecordedScan& sc = seq.scans[s];
    for (std::size_t i = sc.begin; i < sc.end; ++i) {
      const cosim::RecordedPoint& p = seq.points[i];
      ts[i] = sc.timestamp_us;
      time[i] = seq.Time(sc.timestamp_us);
      scan[i] = static_cast<int>(s);
      sensor[i] = sc.sensor;
      range[i] = p.range;
      azimuth[i] = p.azimuth;
      rr[i] = p.range_rate;
      vr[i] = p.radial_speed;
      rcs[i] = p.rcs;
      x[i] = p.position.x();
      y[i] = p.position.y();
      label[i] = p.label;
      track[i] = p.track;
    }
  }
  py::dict d;
  d["timestamp_us"] = ToArray(ts);
  d["time"] = ToArray(time);
  d["scan"] = ToArray(scan);
  d["sensor"] = ToArray(sensor);
  d["range"] = ToArray(range);
  d["azimuth"] = ToArray(azimuth);
  d["range_rate"] = ToArray(rr);
  d["radial_speed"] = ToArray(vr);
  d["rcs"] = ToArray(rcs);
  d["x"] = ToArray(x);
  d["y"] = ToArray(y);
  d["label"] = ToArray(label);
  d["track"] = ToArray(track);
  return d;
}

py::dict ScanColumns(const cosim::RecordedSequence& seq) {
  const std::size_t n = seq.scans.size();
  std::vector<std::int64_t> ts(n);
  std::vector<int> sensor(n), first(n), count(n);
  std::vector<double> time(n), ex(n), ey(n), eyaw(n), evx(n), evy(n), erate(n), lane(n);
  for (std::size_t s = 0; s < n; ++s) {
    const cosim::RecordedScan& sc = seq.scans[s];
    ts[s] = sc.timestamp_us;
    time[s] = seq.Time(sc.timestamp_us);
    sensor[s] = sc.sensor;
    first[s] = static_cast<int>(sc.begin);
    count[s] = static_cast<int>(sc.end - sc.begin);
    ex[s] = sc.ego_pose.position.x();
    ey[s] = sc.ego_pose.position.y();
    eyaw[s] = sc.ego_pose.yaw;
    evx[s] = sc.ego_velocity.x();
    evy[s] = sc.ego_velocity.y();
    erate[s] = sc.ego_yaw_rate;
    lane[s] = sc.lane_yaw;
  }
  py::dict d;
  d["timestamp_us"] = ToArray(ts);
  d["time"] = ToArray(time);
  d["sensor"] = ToArray(sensor);
  d["first_point"] = ToArray(first);
  d["points"] = ToArray(count);
  d["ego_x"] = ToArray(ex);
  d["ego_y"] = ToArray(ey);
  d["ego_yaw"] = ToArray(eyaw);
  d["ego_vx"] = ToArray(evx);
  d["ego_vy"] = ToArray(evy);
  d["ego_yaw_rate"] = ToArray(erate);
  d["lane_yaw"] = ToArray(lane);
  return d;
}

py::dict ReadRecorded(const fs::path& path, std::optional<fs::path> sensors) {
  const recorded::RecordedInput in = recorded::ReadRecordedInput(path, sensors);
  const cosim::RecordedSequence& seq = in.sequence;
  py::dict r;
  r["kind"] = in.radarscenes ? "radarscenes" : "run";
  r["name"] = seq.name;
  r["points"] = PointColumns(seq);
  r["scans"] = ScanColumns(seq);
  r["sensors"] = py::cast(seq.sensors);
  r["track_names"] = py::cast(seq.track_names);
  r["labels"] = seq.has_labels;
  r["ego_length"] = seq.ego_length;
  r["ego_width"] = seq.ego_width;
  r["time_origin_us"] = seq.time_origin_us;
  r["skipped_points"] = seq.skipped_points;
  return r;
}

// `dualgrid export`'s job: a run folder (recorded with --detections exact) as a RadarScenes
// dataset root. Returns the sequence folder written.
std::string ExportRadarScenes(const fs::path& run_dir, const fs::path& out,
                              const std::string& sequence, bool force, bool allow_incomplete) {
  outputs::SafeName(sequence, "export_radarscenes: sequence");
  outputs::InputSet inputs;
  inputs.Add(run_dir, "run folder");
  outputs::CheckOutputApart(out, inputs, "export_radarscenes: out");
  cosim::RecordedSequence seq = recorded::ReadRunFolder(run_dir);
  const std::string incomplete =
      outputs::CheckRunFinished(run_dir, allow_incomplete, "allow_incomplete=True");
  outputs::PrepareOutputFolder(
      out, {.force = force, .option = "export_radarscenes: out", .force_flag = "force=True"});
  if (!incomplete.empty()) outputs::MarkIncomplete(out, run_dir, incomplete);
  seq.name = sequence;
  // The rear axle (RadarScenes' car origin) 1 m ahead of the ego's rear end, as `dualgrid export`.
  const double rear_axle = std::max(0.0, 0.5 * seq.ego_length - 1.0);
  {
    py::gil_scoped_release nogil;
    recorded::WriteRadarScenes(seq, out, rear_axle);
    outputs::SealOutputFolder(out);
  }
  return (out / "data" / sequence).string();
}

}  // namespace

void BindRecorded(py::module_& m) {
  m.def("export_radarscenes", &ExportRadarScenes, py::arg("run_dir"), py::arg("out"),
        py::arg("sequence") = "sequence_1", py::arg("force") = false,
        py::arg("allow_incomplete") = false,
        R"doc(Writes a run folder (of `dualgrid run` or `sim` with --detections exact) as a
RadarScenes dataset root `out` (sensors.json, sequences.json, data/<sequence>/scenes.json and
radar_data.h5), as `dualgrid export` does; read_recorded() and run_recorded() read it back.
`out` must not exist or be empty, or, with force, hold an earlier dualgrid output (only its own
files are removed); it may not equal, contain or lie inside run_dir; sequence is one plain folder
name. A run that did not finish (no summary.json, or complete: false) is refused unless
allow_incomplete (the dataset is then marked by INCOMPLETE.txt). Returns the sequence folder.
ValueError for bad input (the file and field), RuntimeError naming the file and the system's
reason when a write fails.)doc");
  m.def("read_recorded", &ReadRecorded, py::arg("path"), py::arg("sensors") = py::none(),
        R"doc(Reads a recorded sequence without filtering it: a RadarScenes sequence folder
(scenes.json, radar_data.h5; sensors: its sensors.json, default the dataset root's) or a run
folder recorded with --detections exact, as `dualgrid filter` reads it (docs/recorded-data.md).

Returns a dict: kind ("radarscenes" or "run"), name, points (numpy columns, one row per
detection: timestamp_us, time [s since time_origin_us], scan (row of scans), sensor (index into
sensors), range [m], azimuth [rad, sensor frame], range_rate [m/s, uncompensated],
radial_speed [m/s, ego-motion compensated], rcs [dBsm], x, y [m, the sequence's world frame],
label (RadarScenes label_id, -1 none), track (index into track_names, -1 none)), scans (one row
per sensor scan: timestamp_us, time, sensor, first_point, points, ego_x, ego_y [m], ego_yaw
[rad], ego_vx, ego_vy [m/s], ego_yaw_rate [rad/s], lane_yaw [rad]: the ego's box centre),
sensors (SensorParams, mounted on the ego's box centre), track_names, labels (bool), ego_length,
ego_width [m], time_origin_us, skipped_points (detections with a NaN position or velocity, which
the reader drops). pandas.DataFrame(r["points"]) takes the columns. ValueError naming the file
and field for bad input.)doc");
  m.def("run_recorded", &RunRecorded, py::arg("path"), py::arg("sensors") = py::none(),
        py::arg("scenario") = py::none(), py::arg("overrides") = std::vector<std::string>{},
        py::arg("seed") = py::none(),
        py::arg("modes") = std::vector<std::string>{"position", "velocity", "dual"},
        py::arg("batch_window") = 0.001, py::arg("threads") = 0,
        R"doc(Runs the filters on recorded detections as `dualgrid filter` does and returns the
results; the same input, scenario and seed give the CLI's numbers (docs/recorded-data.md).

path: a RadarScenes sequence folder (scenes.json, radar_data.h5) or a dualgrid run folder
recorded with --detections exact. sensors: RadarScenes sensors.json (default: the dataset
root's, two folders up). scenario: a scenario file whose filter, grid and evaluation keys to use
(its step is the filter's reference cycle); overrides: "KEY=VALUE" for it. seed: the filters'
seed. modes: weight modes side by side. batch_window [s]: scans this close to a cycle's first
are filtered together. threads: OpenMP threads (results do not depend on it).

Returns run_scenario's dict (metrics per mode, with "points": the point-level precision, recall
and F1 when the data are labelled; objects: per track_id D and D_v; clusters) and "input" (kind,
sequence, scans, detections, skipped_detections, labels, tracks). Raises ValueError for bad
input: the message names the file and the field.)doc");
}

}  // namespace dualgrid::python
