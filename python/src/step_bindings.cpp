// Step and StepGrid: one co-simulation step for Python (step_data.hpp). Every array is a
// read-only numpy view onto the step's own copy (no copy per access); the arrays keep that copy
// alive, so they stay valid after later steps and after the simulation is gone.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>

#include "convert.hpp"
#include "step_data.hpp"

namespace dualgrid::python {
namespace {

using Owner = std::shared_ptr<const StepData>;

struct PyStep {
  Owner d;
};
struct PyStepGrid {
  Owner d;
  std::size_t m;
  const GridData& g() const { return d->grids[m]; }
};

// A read-only array of `shape` over `data`, which `owner` keeps alive.
template <typename T>
py::array View(const Owner& owner, const T* data, std::vector<py::ssize_t> shape) {
  auto* keep = new Owner(owner);
  py::capsule base(keep, [](void* p) { delete static_cast<Owner*>(p); });
  py::array a = py::array_t<T>(shape, data, base);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array ClustersOf(const Owner& d, std::size_t m) {
  const auto& c = d->grids[m].clusters;
  return View(d, c.data(), {static_cast<py::ssize_t>(c.size())});
}

py::dict ScoresOf(const Owner& d, std::size_t m) {
  const GridData& g = d->grids[m];
  int in_grid = 0;
  for (const TruthRow& t : d->truth) in_grid += t.in_grid;
  py::dict s;
  s["matched"] = g.matched;
  s["duplicate"] = g.duplicate;
  s["false"] = g.false_clusters;
  s["objects"] = d->truth.size();
  s["objects_in_grid"] = in_grid;
  s["objects_matched"] = g.objects_matched;
  s["cells"] = View(d, &g.confusion[0][0], {3, 4});
  return s;
}

void BindStepGrid(py::module_& m) {
  py::class_<PyStepGrid> cls(m, "StepGrid", R"doc(
One weight mode's grid after a step, in the grid frame (docs/python.md, "Step by step"): 2-D
arrays indexed [iy, ix] with ix along the grid frame's +x, cell (0, 0) at the lower-left corner.
The grid frame is the world turned by `yaw` [rad] about the world origin (docs/frames.md);
to_world() maps grid-frame points to the world. All arrays are read-only views of the step's copy.)doc");
  cls.def_property_readonly(
      "mode", [](const PyStepGrid& s) { return s.d->modes[s.m]; },
      "Weight mode: position, velocity or dual.");
  cls.def_property_readonly(
      "masses",
      [](const PyStepGrid& s) {
        return View(s.d, s.g().masses.data(), {s.g().cells_y, s.g().cells_x, 3});
      },
      "(cells_y, cells_x, 3) float32 [probability]: free, static, dynamic mass of each cell.");
  cls.def_property_readonly(
      "velocity",
      [](const PyStepGrid& s) -> std::optional<py::array> {
        if (s.g().velocity.empty()) return std::nullopt;
        return View(s.d, s.g().velocity.data(), {s.g().cells_y, s.g().cells_x, 2});
      },
      "(cells_y, cells_x, 2) float32 [m/s], grid frame: mean velocity of each cell's moving "
      "particles (0 without); None when the simulation was made with velocities=False.");
  cls.def_property_readonly(
      "classes",
      [](const PyStepGrid& s) {
        return View(s.d, s.g().classes.data(), {s.g().cells_y, s.g().cells_x});
      },
      "(cells_y, cells_x) uint8: predicted class at the scenario's evaluation.dynamic_threshold: "
      "0 free, 1 static, 2 dynamic, 3 unknown (CELL_CLASSES).");
  cls.def_property_readonly(
      "truth_classes",
      [](const PyStepGrid& s) {
        return View(s.d, s.d->truth_classes.data(), {s.g().cells_y, s.g().cells_x});
      },
      "(cells_y, cells_x) uint8: ground-truth class (0 free, 1 static, 2 dynamic).");
  cls.def_property_readonly(
      "observed",
      [](const PyStepGrid& s) {
        return View(s.d, reinterpret_cast<const bool*>(s.g().observed.data()),
                    {s.g().cells_y, s.g().cells_x});
      },
      "(cells_y, cells_x) bool: in some radar's field of view this step.");
  cls.def_property_readonly(
      "x", [](const PyStepGrid& s) { return View(s.d, s.g().x.data(), {s.g().cells_x}); },
      "(cells_x,) float64 [m]: cell-centre x, grid frame.");
  cls.def_property_readonly(
      "y", [](const PyStepGrid& s) { return View(s.d, s.g().y.data(), {s.g().cells_y}); },
      "(cells_y,) float64 [m]: cell-centre y, grid frame.");
  cls.def_property_readonly(
      "extent",
      [](const PyStepGrid& s) {
        const GridData& g = s.g();
        const double r = g.resolution;
        return py::make_tuple(g.origin_ix * r, (g.origin_ix + g.cells_x) * r, g.origin_iy * r,
                              (g.origin_iy + g.cells_y) * r);
      },
      "(x_min, x_max, y_min, y_max) [m] of the outer cell edges, grid frame: "
      "plt.imshow(a, origin='lower', extent=g.extent).");
  cls.def_property_readonly(
      "resolution", [](const PyStepGrid& s) { return s.g().resolution; }, "Cell edge [m].");
  cls.def_property_readonly(
      "frame", [](const PyStepGrid&) { return "grid"; },
      "The frame of the arrays and x, y: always 'grid'.");
  cls.def_property_readonly(
      "yaw", [](const PyStepGrid& s) { return s.d->grid_yaw; },
      "World heading of the grid frame's +x axis [rad].");
  cls.def(
      "to_world",
      [](const PyStepGrid& s, py::array_t<double> x, py::array_t<double> y) {
        if (x.request().size != y.request().size)
          throw py::value_error("to_world: x and y must have the same size, got " +
                                std::to_string(x.size()) + " and " + std::to_string(y.size()));
        const double c = std::cos(s.d->grid_yaw), n = std::sin(s.d->grid_yaw);
        const bool id = s.d->grid_yaw == 0.0;  // GridFrame's identity: bit for bit
        py::array_t<double> wx(x.request().shape), wy(x.request().shape);
        const double *px = x.data(), *py_ = y.data();
        double *ox = wx.mutable_data(), *oy = wy.mutable_data();
        for (py::ssize_t i = 0; i < x.size(); ++i) {
          ox[i] = id ? px[i] : c * px[i] - n * py_[i];
          oy[i] = id ? py_[i] : n * px[i] + c * py_[i];
        }
        return py::make_tuple(wx, wy);
      },
      py::arg("x"), py::arg("y"),
      "Grid-frame points [m] (arrays of one shape) -> (x, y) world [m], new arrays.");
  cls.def_property_readonly(
      "clusters", [](const PyStepGrid& s) { return ClustersOf(s.d, s.m); },
      "This step's clusters of the mode (Step.clusters[mode]).");
  cls.def_property_readonly(
      "scores", [](const PyStepGrid& s) { return ScoresOf(s.d, s.m); },
      "This step's scores of the mode (Step.scores[mode]).");
  cls.def("__repr__", [](const PyStepGrid& s) {
    return "<StepGrid " + s.d->modes[s.m] + " " + std::to_string(s.g().cells_y) + "x" +
           std::to_string(s.g().cells_x) + " cells of " + std::to_string(s.g().resolution) +
           " m, step " + std::to_string(s.d->step) + ">";
  });
}

void BindStepClass(py::module_& m) {
  py::class_<PyStep> cls(m, "Step", R"doc(
One step of a CoSimulation or RecordedSimulation (docs/python.md, "Step by step"): the ego,
the detections, the ground truth (world frame) and per weight mode the grid (grid frame),
the clusters (world frame) and this step's scores. Arrays are read-only views of the step's own
copy, valid for as long as you keep them.)doc");
  cls.def_property_readonly(
      "step", [](const PyStep& s) { return s.d->step; }, "Step number (clusters.csv's step).");
  cls.def_property_readonly(
      "time", [](const PyStep& s) { return s.d->time; },
      "Simulated time at the end of the step [s].");
  cls.def_property_readonly(
      "ego_pose",
      [](const PyStep& s) { return std::make_tuple(s.d->ego_x, s.d->ego_y, s.d->ego_yaw); },
      "(x, y, yaw) [m, m, rad] of the ego's box centre, world frame.");
  cls.def_property_readonly(
      "ego_velocity", [](const PyStep& s) { return std::make_tuple(s.d->ego_vx, s.d->ego_vy); },
      "(vx, vy) [m/s], world frame.");
  cls.def_property_readonly(
      "grid_yaw", [](const PyStep& s) { return s.d->grid_yaw; },
      "World heading of the grid frame's +x axis [rad].");
  cls.def_property_readonly(
      "modes", [](const PyStep& s) { return s.d->modes; },
      "The weight modes, in the simulation's order.");
  cls.def_property_readonly(
      "detections",
      [](const PyStep& s) {
        return View(s.d, s.d->detections.data(),
                    {static_cast<py::ssize_t>(s.d->detections.size())});
      },
      "Structured array, one row per detection of the sensors due this step (DETECTION_FIELDS; "
      "world frame unless named _ego): pandas.DataFrame(step.detections) takes it.");
  cls.def_property_readonly(
      "truth",
      [](const PyStep& s) {
        return View(s.d, s.d->truth.data(), {static_cast<py::ssize_t>(s.d->truth.size())});
      },
      "Structured array of the ground-truth objects as scored (world frame): id, x, y [m], yaw "
      "[rad], length, width [m], vx, vy [m/s], in_grid, in_coverage, detected_in_grid.");
  cls.def_property_readonly(
      "names",
      [](const PyStep& s) {
        py::dict d;
        for (const auto& [id, name] : s.d->names) d[py::int_(id)] = name;
        return d;
      },
      "{object id: name} of the truth objects (SUMO vehicle id or recorded track).");
  cls.def_property_readonly(
      "grids",
      [](const PyStep& s) {
        py::dict d;
        for (std::size_t m = 0; m < s.d->modes.size(); ++m)
          d[py::str(s.d->modes[m])] = PyStepGrid{s.d, m};
        return d;
      },
      "{mode: StepGrid}.");
  cls.def_property_readonly(
      "clusters",
      [](const PyStep& s) {
        py::dict d;
        for (std::size_t m = 0; m < s.d->modes.size(); ++m)
          d[py::str(s.d->modes[m])] = ClustersOf(s.d, m);
        return d;
      },
      "{mode: structured array}: x, y [m], vx, vy [m/s] (world frame), weight [dynamic mass], "
      "particles, role (0 matched, 1 duplicate, 2 false: ROLE_NAMES), object (matched truth "
      "id, -1 none).");
  cls.def_property_readonly(
      "scores",
      [](const PyStep& s) {
        py::dict d;
        for (std::size_t m = 0; m < s.d->modes.size(); ++m)
          d[py::str(s.d->modes[m])] = ScoresOf(s.d, m);
        return d;
      },
      "{mode: dict}: this step's matched, duplicate and false clusters, objects, "
      "objects_in_grid, objects_matched, and cells: the (3, 4) int64 confusion matrix "
      "[truth free/static/dynamic][predicted free/static/dynamic/unknown] of the observed cells.");
  cls.def("__repr__", [](const PyStep& s) {
    return "<Step " + std::to_string(s.d->step) + " t=" + std::to_string(s.d->time) + " s, " +
           std::to_string(s.d->detections.size()) + " detections, " +
           std::to_string(s.d->truth.size()) + " objects>";
  });
}

}  // namespace

py::object WrapStep(std::shared_ptr<const StepData> d) { return py::cast(PyStep{std::move(d)}); }

void BindStep(py::module_& m) {
  PYBIND11_NUMPY_DTYPE(DetectionRow, sensor, range, azimuth, range_rate, snr_db, x, y, x_ego, y_ego,
                       radial_speed_compensated, v_rx, v_ry, sensor_x, sensor_y, source_id,
                       is_clutter, label);
  PYBIND11_NUMPY_DTYPE(TruthRow, id, x, y, yaw, length, width, vx, vy, in_grid, in_coverage,
                       detected_in_grid);
  PYBIND11_NUMPY_DTYPE(ClusterRow, x, y, vx, vy, weight, particles, role, object);
  BindStepGrid(m);
  BindStepClass(m);
  m.attr("ROLE_NAMES") = py::make_tuple("matched", "duplicate", "false");
  m.attr("CELL_CLASSES") = py::make_tuple("free", "static", "dynamic", "unknown");
}

}  // namespace dualgrid::python
