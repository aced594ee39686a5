// Python bindings of the radar model: SensorParams and the default rig, ModelOptions, EgoMotion,
// Scene (targets as a table, guard rails as polylines) and RadarModel, whose scans come back as a
// dict of numpy columns that pandas.DataFrame takes directly (docs/python.md).
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/radar_model/radar_model.hpp"
#include "dualgrid/radar_model/scene.hpp"
#include "dualgrid/radar_model/sensor_params.hpp"
#include "value_class.hpp"

namespace dualgrid::python {
namespace {

using radar::Detection;
using radar::EgoMotion;
using radar::ModelOptions;
using radar::RadarModel;
using radar::Scene;
using radar::SensorParams;

// Columns of a target table, in array order; the optional ones default as in radar::Target.
const std::vector<ColumnSpec> kTargetColumns = {
    {"id"},    {"x"},       {"y"},       {"yaw", 0.0},      {"length"},
    {"width"}, {"vx", 0.0}, {"vy", 0.0}, {"yaw_rate", 0.0}, {"rcs_dbsm", 10.0}};

radar::Accuracy ParseAccuracy(const std::string& s) {
  if (s == "data_sheet") return radar::Accuracy::kDataSheet;
  if (s == "clean") return radar::Accuracy::kClean;
  throw py::value_error("accuracy: unknown value '" + s + "' (data_sheet, clean)");
}

int ReadId(double v, const std::string& where) {
  if (v != std::floor(v) || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max())
    throw py::value_error(where + ": id must be an integer in the int32 range, got " +
                          std::to_string(v));
  return static_cast<int>(v);
}

// Targets and polylines from Python (see the Scene docstring); ids unique across both.
Scene ReadScene(py::handle targets, py::handle polylines) {
  Scene scene;
  std::set<int> ids;
  const Table t = ReadTable(targets, "targets", kTargetColumns);
  for (std::size_t i = 0; i < t.rows; ++i) {
    const std::string where = "targets: row " + std::to_string(i);
    radar::Target g;
    g.id = ReadId(t.at(i, 0), where);
    g.box = OrientedBox{{t.at(i, 1), t.at(i, 2)}, t.at(i, 3), t.at(i, 4), t.at(i, 5)};
    g.velocity = {t.at(i, 6), t.at(i, 7)};
    g.yaw_rate = t.at(i, 8);
    g.rcs_dbsm = t.at(i, 9);
    if (!(g.box.length > 0.0) || !(g.box.width > 0.0))
      throw py::value_error(where + ": length and width must be > 0 [m]");
    if (!ids.insert(g.id).second)
      throw py::value_error(where + ": id " + std::to_string(g.id) +
                            " is used twice (ids must be unique across targets and polylines)");
    scene.targets.push_back(g);
  }
  if (polylines.is_none()) return scene;
  if (!py::isinstance<py::sequence>(polylines) || py::isinstance<py::str>(polylines))
    throw py::value_error(
        "polylines: expected a list of dicts {id, points, rcs_dbsm_per_metre}, "
        "got " +
        ShortRepr(polylines));
  const auto seq = py::reinterpret_borrow<py::sequence>(polylines);
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const std::string where = "polylines[" + std::to_string(i) + "]";
    py::object item = seq[i];
    if (!py::isinstance<py::dict>(item))
      throw py::value_error(where + ": expected a dict {id, points, rcs_dbsm_per_metre}, got " +
                            ShortRepr(item));
    const auto d = py::reinterpret_borrow<py::dict>(item);
    for (auto kv : d) {
      const std::string key = py::str(kv.first).cast<std::string>();
      if (key != "id" && key != "points" && key != "rcs_dbsm_per_metre")
        throw py::value_error(where + ": unknown key '" + key +
                              "' (expected id, points, rcs_dbsm_per_metre)");
    }
    if (!d.contains("id") || !d.contains("points"))
      throw py::value_error(where + ": needs the keys 'id' and 'points'");
    radar::Polyline line;
    line.id = ReadId(ReadFixed(d["id"], (where + "['id']").c_str(), 1, "an integer")[0], where);
    const Table pts = ReadTable(d["points"], (where + "['points']").c_str(), {{"x"}, {"y"}});
    if (pts.rows < 2)
      throw py::value_error(where + "['points']: expected an array (P, 2) [m] with P >= 2, got " +
                            std::to_string(pts.rows) + " point(s)");
    for (std::size_t k = 0; k < pts.rows; ++k) line.points.emplace_back(pts.at(k, 0), pts.at(k, 1));
    if (d.contains("rcs_dbsm_per_metre"))
      line.rcs_dbsm_per_metre =
          ReadFixed(d["rcs_dbsm_per_metre"], (where + "['rcs_dbsm_per_metre']").c_str(), 1,
                    "a number [dBsm/m]")[0];
    if (!ids.insert(line.id).second)
      throw py::value_error(where + ": id " + std::to_string(line.id) +
                            " is used twice (ids must be unique across targets and polylines)");
    scene.polylines.push_back(std::move(line));
  }
  return scene;
}

// scan()'s scene argument: a Scene or a dict {"targets": ..., "polylines": ...}.
Scene ToScene(py::handle obj) {
  if (py::isinstance<Scene>(obj)) return obj.cast<Scene>();
  if (py::isinstance<py::dict>(obj)) {
    const auto d = py::reinterpret_borrow<py::dict>(obj);
    for (auto kv : d) {
      const std::string key = py::str(kv.first).cast<std::string>();
      if (key != "targets" && key != "polylines")
        throw py::value_error("scene: unknown key '" + key + "' (expected targets, polylines)");
    }
    const py::object targets = d.contains("targets") ? py::object(d["targets"]) : py::none();
    const py::object polylines = d.contains("polylines") ? py::object(d["polylines"]) : py::none();
    return ReadScene(targets, polylines);
  }
  throw py::value_error(
      "scene: expected a Scene or a dict {'targets': ..., 'polylines': ...}, got " +
      ShortRepr(obj));
}

// scan()'s ego argument: an EgoMotion or a dict of its fields.
EgoMotion ToEgo(py::handle obj, const FieldNames& names) {
  if (py::isinstance<EgoMotion>(obj)) return obj.cast<EgoMotion>();
  if (py::isinstance<py::dict>(obj)) {
    EgoMotion e;
    try {
      SetFields(e, py::reinterpret_borrow<py::dict>(obj), names, "EgoMotion");
    } catch (py::error_already_set& err) {  // raised by a property setter
      throw py::value_error(std::string("ego: ") + err.what());
    } catch (py::builtin_exception& err) {  // unknown field
      throw py::value_error(std::string("ego: ") + err.what());
    }
    return e;
  }
  throw py::value_error(
      "ego: expected an EgoMotion or a dict {pose, velocity, yaw_rate, length, width}, got " +
      ShortRepr(obj));
}

// Detections as a dict of equally long numpy columns (pandas.DataFrame(d) takes it as is).
py::dict DetectionsDict(const std::vector<Detection>& dets) {
  const std::size_t n = dets.size();
  std::vector<std::int32_t> sensor(n), source(n), path(n), bounces(n), reflector(n), ghost_of(n);
  std::vector<bool> clutter(n);
  std::vector<double> range(n), azimuth(n), range_rate(n), snr(n), x(n), y(n), xe(n), ye(n), vr(n),
      vrx(n), vry(n), sx(n), sy(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Detection& d = dets[i];
    sensor[i] = d.sensor;
    range[i] = d.range;
    azimuth[i] = d.azimuth;
    range_rate[i] = d.range_rate;
    snr[i] = d.snr_db;
    x[i] = d.position_world.x();
    y[i] = d.position_world.y();
    xe[i] = d.position_ego.x();
    ye[i] = d.position_ego.y();
    vr[i] = d.radial_speed_compensated;
    vrx[i] = d.radial_velocity_world.x();
    vry[i] = d.radial_velocity_world.y();
    sx[i] = d.sensor_position_world.x();
    sy[i] = d.sensor_position_world.y();
    source[i] = d.source_id;
    clutter[i] = d.is_clutter;
    path[i] = static_cast<std::int32_t>(d.path);
    bounces[i] = d.bounces;
    reflector[i] = d.reflector_id;
    ghost_of[i] = d.ghost_of;
  }
  py::array_t<bool> is_clutter(static_cast<py::ssize_t>(n));
  for (std::size_t i = 0; i < n; ++i) is_clutter.mutable_data()[i] = clutter[i];
  py::dict out;
  out["sensor"] = ToArray(sensor);
  out["range"] = ToArray(range);
  out["azimuth"] = ToArray(azimuth);
  out["range_rate"] = ToArray(range_rate);
  out["snr_db"] = ToArray(snr);
  out["x"] = ToArray(x);
  out["y"] = ToArray(y);
  out["x_ego"] = ToArray(xe);
  out["y_ego"] = ToArray(ye);
  out["radial_speed_compensated"] = ToArray(vr);
  out["v_rx"] = ToArray(vrx);
  out["v_ry"] = ToArray(vry);
  out["sensor_x"] = ToArray(sx);
  out["sensor_y"] = ToArray(sy);
  out["source_id"] = ToArray(source);
  out["is_clutter"] = is_clutter;
  out["path"] = ToArray(path);
  out["bounces"] = ToArray(bounces);
  out["reflector_id"] = ToArray(reflector);
  out["ghost_of"] = ToArray(ghost_of);
  return out;
}

// RadarModel plus its seed (the C++ class does not expose it; repr and docs show it).
struct Radar {
  Radar(std::vector<SensorParams> sensors, ModelOptions options, std::uint64_t seed)
      : model(std::move(sensors), options, seed), seed(seed) {}
  RadarModel model;
  std::uint64_t seed;
};

void CheckTime(double time, double step_length) {
  if (!std::isfinite(time)) throw py::value_error("time: must be finite [s]");
  if (!std::isfinite(step_length) || !(step_length > 0.0))
    throw py::value_error("step_length: must be finite and > 0 [s], got " +
                          std::to_string(step_length));
}

void CheckSensorIndex(const Radar& r, int sensor) {
  if (sensor < 0 || sensor >= static_cast<int>(r.model.sensors().size()))
    throw py::index_error("sensor: no sensor " + std::to_string(sensor) + " (the model has " +
                          std::to_string(r.model.sensors().size()) + ")");
}

void BindSensorParams(py::module_& m) {
  py::class_<SensorParams> cls(m, "SensorParams", R"doc(
One radar sensor (radar_model/include/dualgrid/radar_model/sensor_params.hpp; docs/radar.md cites
every value). Angles in radians. The defaults describe a corner short-range radar mounted at the
ego origin facing forward. SensorParams(**fields) starts from them; is_valid() / validate() check.
List fields (off_boresight*) are returned as copies: assign a whole new list to change them.)doc");
  auto names = std::make_shared<std::vector<std::string>>();
  Field(cls, names, "name", &SensorParams::name, "Sensor name (non-empty).");
  cls.def_property(
      "mount",
      [](const SensorParams& p) {
        return py::make_tuple(p.mount.position.x(), p.mount.position.y(), p.mount.yaw);
      },
      [](SensorParams& p, PoseArg v) { p.mount = ReadPose(v, "mount"); },
      "Mounting pose in the ego frame (x forward, y left, origin at the ego box centre): "
      "(x, y, yaw) [m, m, rad].");
  names->push_back("mount");
  Field(cls, names, "fov", &SensorParams::fov,
        "Full azimuth field of view centred on the boresight [rad].");
  Field(cls, names, "min_range", &SensorParams::min_range, "[m]");
  Field(cls, names, "max_range", &SensorParams::max_range, "[m]");
  Field(cls, names, "min_range_rate", &SensorParams::min_range_rate,
        "Range-rate window, lower end [m/s] (negative = approaching).");
  Field(cls, names, "max_range_rate", &SensorParams::max_range_rate,
        "Range-rate window, upper end [m/s].");
  Field(cls, names, "range_resolution", &SensorParams::range_resolution, "[m]");
  Field(cls, names, "azimuth_resolution", &SensorParams::azimuth_resolution, "At boresight [rad].");
  Field(cls, names, "range_rate_resolution", &SensorParams::range_rate_resolution, "[m/s]");
  Field(cls, names, "range_accuracy", &SensorParams::range_accuracy,
        "1-sigma floor at high SNR [m].");
  Field(cls, names, "azimuth_accuracy", &SensorParams::azimuth_accuracy,
        "1-sigma floor at high SNR, at boresight [rad].");
  Field(cls, names, "range_rate_accuracy", &SensorParams::range_rate_accuracy,
        "1-sigma floor at high SNR [m/s].");
  Field(cls, names, "off_boresight", &SensorParams::off_boresight,
        "Off-boresight profile angles |azimuth| [rad], increasing (list of float).");
  Field(cls, names, "off_boresight_resolution", &SensorParams::off_boresight_resolution,
        "Azimuth resolution factor at each off_boresight angle [1].");
  Field(cls, names, "off_boresight_accuracy", &SensorParams::off_boresight_accuracy,
        "Azimuth accuracy factor at each off_boresight angle [1].");
  Field(cls, names, "reference_range", &SensorParams::reference_range,
        "Range at which the reference target is detected with reference_pd [m].");
  Field(cls, names, "reference_rcs_dbsm", &SensorParams::reference_rcs_dbsm,
        "RCS of the reference target [dBsm].");
  Field(cls, names, "reference_pd", &SensorParams::reference_pd,
        "Detection probability of the reference target [probability].");
  Field(cls, names, "false_alarm_rate", &SensorParams::false_alarm_rate,
        "False-alarm probability per resolution cell [probability].");
  Field(cls, names, "update_period", &SensorParams::update_period, "Scan period [s].");
  AddValueProtocol(cls, names, "SensorParams");
  cls.def(
      "is_valid", [](const SensorParams& p) { return p.IsValid(nullptr); },
      "True when every field is in range.");
  cls.def(
      "validate",
      [](const SensorParams& p) {
        std::string error;
        if (!p.IsValid(&error)) throw py::value_error("SensorParams '" + p.name + "': " + error);
      },
      "Raises ValueError naming the offending field; returns None otherwise.");
  cls.def("azimuth_resolution_at", &SensorParams::AzimuthResolutionAt, py::arg("azimuth"),
          "Azimuth resolution [rad] at sensor-frame azimuth [rad] (off-boresight profile).");
  cls.def("azimuth_accuracy_at", &SensorParams::AzimuthAccuracyAt, py::arg("azimuth"),
          "Azimuth accuracy floor [rad] at sensor-frame azimuth [rad].");

  m.def(
      "default_rig",
      [](double length, double width, const std::string& accuracy) {
        return radar::DefaultRig(length, width, ParseAccuracy(accuracy));
      },
      py::arg("ego_length"), py::arg("ego_width"), py::arg("accuracy") = "data_sheet", R"doc(
The paper's rig for an ego box of ego_length x ego_width [m]: four corner short-range radars
"front_left", "front_right", "rear_left", "rear_right" (facing +-45 / +-135 deg, at
x = +-0.3 ego_length, y = +-0.5 ego_width) and the long-range "front" radar at the front bumper
centre. accuracy: "data_sheet" (default) or "clean" (idealised floors). A list of SensorParams;
ValueError on non-positive dimensions.)doc");
  m.def(
      "default_short_range_radar",
      [](const std::string& accuracy) {
        return radar::DefaultShortRangeRadar(ParseAccuracy(accuracy));
      },
      py::arg("accuracy") = "data_sheet",
      "Corner short-range radar defaults, named 'short_range', mounted at the ego origin.");
  m.def(
      "default_long_range_radar",
      [](const std::string& accuracy) {
        return radar::DefaultLongRangeRadar(ParseAccuracy(accuracy));
      },
      py::arg("accuracy") = "data_sheet",
      "Front long-range radar defaults, named 'long_range', mounted at the ego origin.");
}

FieldNames BindEgoAndOptions(py::module_& m) {
  using radar::MultipathParams;
  py::class_<MultipathParams> mp(m, "MultipathParams", R"doc(
The radar model's multipath ghosts (radar_model/.../multipath.hpp, docs/radar.md "Multipath"):
guard rails and the long flanks of trucks as plane mirrors. Off by default (enabled=False).
MultipathParams(enabled=True) for the defaults; ModelOptions(multipath=...).)doc");
  auto mp_names = std::make_shared<std::vector<std::string>>();
  Field(mp, mp_names, "enabled", &MultipathParams::enabled, "Ghosts on (False: none).");
  Field(mp, mp_names, "rails", &MultipathParams::rails, "Guard-rail segments are mirrors.");
  Field(mp, mp_names, "vehicles", &MultipathParams::vehicles,
        "The long sides of boxes at least vehicle_min_length long are mirrors.");
  Field(mp, mp_names, "rail_loss_db", &MultipathParams::rail_loss_db,
        "Power lost per bounce off a rail [dB].");
  Field(mp, mp_names, "vehicle_loss_db", &MultipathParams::vehicle_loss_db,
        "Power lost per bounce off a vehicle [dB].");
  Field(mp, mp_names, "vehicle_min_length", &MultipathParams::vehicle_min_length,
        "Shortest box whose flanks are mirrors [m] (trucks and buses).");
  Field(mp, mp_names, "max_bounces", &MultipathParams::max_bounces,
        "2: the order-2 paths only; 3: also the order-3 mirror image.");
  Field(mp, mp_names, "min_pd", &MultipathParams::min_pd,
        "Ghost scatterers whose detection probability alone is below this are dropped [-].");
  mp.def(
      "is_valid", [](const MultipathParams& p) { return p.IsValid(nullptr); },
      "True when every field is usable.");
  mp.def(
      "validate",
      [](const MultipathParams& p) {
        std::string error;
        if (!p.IsValid(&error)) throw py::value_error("MultipathParams: " + error);
      },
      "Raises ValueError naming the first unusable field.");
  AddValueProtocol(mp, mp_names, "MultipathParams");

  py::class_<ModelOptions> opt(m, "ModelOptions",
                               "Switches of the radar model's effects: ModelOptions(noise=True, "
                               "false_alarms=True, occlusion=True, multipath=MultipathParams()).");
  auto opt_names = std::make_shared<std::vector<std::string>>();
  Field(opt, opt_names, "noise", &ModelOptions::noise,
        "Measurement noise on range, azimuth, range rate.");
  Field(opt, opt_names, "false_alarms", &ModelOptions::false_alarms, "Clutter detections.");
  Field(opt, opt_names, "occlusion", &ModelOptions::occlusion,
        "Nearer boxes and rails hide scatterers behind them.");
  opt.def_property(
      "multipath", [](ModelOptions& o) -> MultipathParams& { return o.multipath; },
      [](ModelOptions& o, MultipathArg v) {
        // A MultipathParams, or its to_dict() (what pickling and to_dict() give back).
        py::object p = py::isinstance<py::dict>(v.obj)
                           ? py::module_::import("dualgrid._dualgrid")
                                 .attr("MultipathParams")(**v.obj.cast<py::dict>())
                           : v.obj;
        if (!py::isinstance<MultipathParams>(p))
          throw py::type_error(
              "multipath: expected a MultipathParams or a dict of its fields, got " +
              ShortRepr(v.obj));
        o.multipath = p.cast<MultipathParams>();
      },
      py::return_value_policy::reference_internal,
      "Multipath ghosts (MultipathParams, or a dict of its fields; off unless "
      "multipath.enabled): options.multipath.enabled = True switches them on in place.");
  opt_names->push_back("multipath");
  AddValueProtocol(opt, opt_names, "ModelOptions");

  py::class_<EgoMotion> ego(m, "EgoMotion", R"doc(
Ego state in the world frame for a radar scan: EgoMotion(pose=(x, y, yaw), velocity=(vx, vy),
yaw_rate=0, length=0, width=0). Velocity is that of the ego box centre (pose position). length x
width [m] is the ego's own body, hiding what lies behind it from its sensors (0: no body).)doc");
  auto ego_names = std::make_shared<std::vector<std::string>>();
  ego.def_property(
      "pose",
      [](const EgoMotion& e) {
        return py::make_tuple(e.pose.position.x(), e.pose.position.y(), e.pose.yaw);
      },
      [](EgoMotion& e, PoseArg v) { e.pose = ReadPose(v, "pose"); },
      "(x, y, yaw) [m, m, rad] of the ego box centre, world frame.");
  ego_names->push_back("pose");
  ego.def_property(
      "velocity", [](const EgoMotion& e) { return py::make_tuple(e.velocity.x(), e.velocity.y()); },
      [](EgoMotion& e, Vector2Arg v) { e.velocity = ReadVector2(v, "velocity", "[m/s]"); },
      "(vx, vy) [m/s] of the box centre over ground, world frame.");
  ego_names->push_back("velocity");
  Field(ego, ego_names, "yaw_rate", &EgoMotion::yaw_rate, "[rad/s]");
  Field(ego, ego_names, "length", &EgoMotion::length, "Ego body length [m] (0: no body).");
  Field(ego, ego_names, "width", &EgoMotion::width, "Ego body width [m] (0: no body).");
  AddValueProtocol(ego, ego_names, "EgoMotion");
  return ego_names;
}

void BindScene(py::module_& m) {
  py::class_<Scene> cls(m, "Scene", R"doc(
Everything around the ego, world frame (radar_model/include/dualgrid/radar_model/scene.hpp).

targets: vehicles and parked boxes, one row each, columns
  [id, x, y, yaw, length, width, vx, vy, yaw_rate, rcs_dbsm]
  (integer id; box centre [m]; heading of the length axis [rad]; box size [m]; centre velocity
  over ground [m/s]; yaw rate [rad/s]; whole-vehicle RCS [dBsm]), as a float array (K, 10) in that
  order, a dict of columns / DataFrame / structured array by name, or a list of dicts. By name,
  yaw, vx, vy, yaw_rate default to 0 and rcs_dbsm to 10.
polylines: guard rails, a list of dicts {"id": int, "points": (P, 2) array [m] with P >= 2,
  "rcs_dbsm_per_metre": float [dBsm/m], default -5}.
Ids must be unique across targets and polylines (they become the detections' source_id). The ego
must not be part of the scene. ValueError names the argument and row of bad input.)doc");
  cls.def(py::init([](TableArg targets, PolylinesArg polylines) {
            return ReadScene(targets, polylines);
          }),
          py::arg("targets") = py::none(), py::arg("polylines") = py::none());
  cls.def_property_readonly(
      "targets",
      [](const Scene& s) {
        const std::size_t n = s.targets.size();
        std::vector<std::int32_t> id(n);
        std::vector<std::vector<double>> col(9, std::vector<double>(n));
        for (std::size_t i = 0; i < n; ++i) {
          const radar::Target& t = s.targets[i];
          id[i] = t.id;
          const double v[9] = {t.box.center.x(), t.box.center.y(), t.box.yaw,
                               t.box.length,     t.box.width,      t.velocity.x(),
                               t.velocity.y(),   t.yaw_rate,       t.rcs_dbsm};
          for (int c = 0; c < 9; ++c) col[c][i] = v[c];
        }
        py::dict d;
        d["id"] = ToArray(id);
        for (int c = 0; c < 9; ++c) d[py::str(kTargetColumns[c + 1].name)] = ToArray(col[c]);
        return d;
      },
      "The targets as a dict of columns (a copy).");
  cls.def_property_readonly(
      "polylines",
      [](const Scene& s) {
        py::list out;
        for (const radar::Polyline& p : s.polylines) {
          py::array_t<double> pts({static_cast<py::ssize_t>(p.points.size()), py::ssize_t{2}});
          for (std::size_t k = 0; k < p.points.size(); ++k) {
            pts.mutable_at(k, 0) = p.points[k].x();
            pts.mutable_at(k, 1) = p.points[k].y();
          }
          py::dict d;
          d["id"] = p.id;
          d["points"] = pts;
          d["rcs_dbsm_per_metre"] = p.rcs_dbsm_per_metre;
          out.append(d);
        }
        return out;
      },
      "The polylines as a list of dicts (copies).");
  cls.def("__repr__", [](const Scene& s) {
    return "Scene(" + std::to_string(s.targets.size()) + " targets, " +
           std::to_string(s.polylines.size()) + " polylines)";
  });
}

void BindRadarModel(py::module_& m, const FieldNames& ego_names) {
  py::class_<Radar> cls(m, "RadarModel", R"doc(
The radar model (radar_model/include/dualgrid/radar_model/radar_model.hpp): scatterers on boxes
and guard rails, occlusion, resolution-cell merging, SNR-driven detection and noise, false alarms,
ego-motion compensation. RadarModel(sensors, options=ModelOptions(), seed=0); ValueError naming
the sensor and field if one is invalid. Scans are deterministic in (seed, step) whatever the
thread count; they release the GIL.

Detections come back as a dict of equally long numpy columns (pandas.DataFrame(d) takes it):
  sensor (int32, index into sensors), range [m], azimuth [rad, sensor frame], range_rate [m/s,
  measured, relative to the moving sensor], snr_db [dB, noise-free SNR of the resolution cell],
  x, y [m, world], x_ego, y_ego [m, ego frame], radial_speed_compensated [m/s, over ground],
  v_rx, v_ry [m/s, radial_speed_compensated times the world line of sight: paper eq. (1)],
  sensor_x, sensor_y [m, world], source_id (int32, target / polyline id, -1 for clutter and
  ghosts), is_clutter (bool), and the multipath labels (ModelOptions.multipath): path (int32, 0
  direct, 1 type 1, 2 type 2), bounces (1 direct, 2 or 3), reflector_id (the mirror's id, -1
  direct), ghost_of (the real object's id, -1 direct).
detections_to_measurements() turns it into DynamicGrid.update()'s (N, 6) array.)doc");
  cls.def(py::init([](std::vector<SensorParams> sensors, const ModelOptions& options, Seed seed) {
            return std::make_unique<Radar>(std::move(sensors), options, seed.value);
          }),
          py::arg("sensors"), py::arg("options") = ModelOptions(), py::arg("seed") = 0);
  cls.def_property_readonly(
      "sensors", [](const Radar& r) { return r.model.sensors(); }, "The sensors (copies).");
  cls.def_property_readonly(
      "options", [](const Radar& r) { return r.model.options(); }, "The options (a copy).");
  cls.def_property_readonly(
      "seed", [](const Radar& r) { return r.seed; }, "Seed of the random streams.");
  cls.def("__len__", [](const Radar& r) { return r.model.sensors().size(); });
  cls.def(
      "sensor_pose",
      [](const Radar& r, int sensor, PoseArg ego_pose) {
        CheckSensorIndex(r, sensor);
        const Pose2 p = r.model.SensorPose(sensor, ReadPose(ego_pose, "ego_pose"));
        return py::make_tuple(p.position.x(), p.position.y(), p.yaw);
      },
      py::arg("sensor"), py::arg("ego_pose"),
      "World pose (x, y, yaw) [m, m, rad] of sensor `sensor` for ego pose (x, y, yaw).");
  cls.def(
      "sensors_due",
      [](const Radar& r, double time, double step_length) {
        CheckTime(time, step_length);
        return r.model.SensorsDue(time, step_length);
      },
      py::arg("time"), py::arg("step_length"),
      "Indices of the sensors that fire at the step ending at `time` [s] of length "
      "`step_length` [s] (each fires when a multiple of its update_period falls in the step).");
  cls.def(
      "coverage",
      [](const Radar& r, PoseArg ego_pose, std::optional<std::vector<int>> sensors) {
        const Pose2 pose = ReadPose(ego_pose, "ego_pose");
        std::vector<int> which = sensors ? *sensors : std::vector<int>();
        if (!sensors)
          for (int i = 0; i < static_cast<int>(r.model.sensors().size()); ++i) which.push_back(i);
        py::array_t<double> out({static_cast<py::ssize_t>(which.size()), py::ssize_t{6}});
        for (std::size_t k = 0; k < which.size(); ++k) {
          CheckSensorIndex(r, which[k]);
          const SensorParams& p = r.model.sensors()[which[k]];
          const Pose2 s = r.model.SensorPose(which[k], pose);
          const double row[6] = {s.position.x(), s.position.y(), s.yaw,
                                 0.5 * p.fov,    p.min_range,    p.max_range};
          for (int c = 0; c < 6; ++c) out.mutable_at(k, c) = row[c];
        }
        return out;
      },
      py::arg("ego_pose"), py::arg("sensors") = py::none(), R"doc(
DynamicGrid.update()'s coverage argument for ego pose (x, y, yaw): a float array (M, 6)
[origin_x, origin_y, boresight, half_fov, min_range, max_range] ([m, m, rad, rad, m, m], world
frame), one row per sensor index in `sensors` (default: all; pass sensors_due(...) for a cycle).)doc");
  const auto scan_doc = R"doc(
Detections of all sensors due at the step ending at `time` [s] (step length `step_length` [s]),
ordered by sensor, resolution cell, then clutter. `step` (integer >= 0) addresses the random
streams. ego: an EgoMotion or a dict of its fields; scene: a Scene or a dict {targets, polylines}.
Returns the dict of columns described in the class docstring.)doc";
  cls.def(
      "scan",
      [ego_names](const Radar& r, EgoArg ego, SceneArg scene, std::uint64_t step, double time,
                  double step_length) {
        CheckTime(time, step_length);
        const EgoMotion e = ToEgo(ego, ego_names);
        const Scene s = ToScene(scene);
        std::vector<Detection> dets;
        {
          py::gil_scoped_release nogil;
          ApplyThreadCount();
          dets = r.model.Scan(e, s, step, time, step_length);
        }
        return DetectionsDict(dets);
      },
      py::arg("ego"), py::arg("scene"), py::arg("step"), py::arg("time"),
      py::arg("step_length") = 0.05, scan_doc);
  cls.def(
      "scan_sensor",
      [ego_names](const Radar& r, int sensor, EgoArg ego, SceneArg scene, std::uint64_t step) {
        CheckSensorIndex(r, sensor);
        const EgoMotion e = ToEgo(ego, ego_names);
        const Scene s = ToScene(scene);
        std::vector<Detection> dets;
        {
          py::gil_scoped_release nogil;
          ApplyThreadCount();
          dets = r.model.ScanSensor(sensor, e, s, step);
        }
        return DetectionsDict(dets);
      },
      py::arg("sensor"), py::arg("ego"), py::arg("scene"), py::arg("step"),
      "Detections of sensor `sensor` alone, regardless of its update period (same columns as "
      "scan()). IndexError for an unknown sensor.");
  cls.def("__repr__", [](const Radar& r) {
    std::string s = "RadarModel([";
    for (std::size_t i = 0; i < r.model.sensors().size(); ++i)
      s += (i ? ", " : "") + std::string("'") + r.model.sensors()[i].name + "'";
    return s + "], seed=" + std::to_string(r.seed) + ")";
  });
}

}  // namespace

void BindRadar(py::module_& m) {
  BindSensorParams(m);
  const FieldNames ego_names = BindEgoAndOptions(m);
  BindScene(m);
  BindRadarModel(m, ego_names);
}

}  // namespace dualgrid::python
