// Clustering and scoring on a grid of the caller's own (docs/python.md, "Scoring your own
// grid"): the cell classes of masses, the cell confusion against a truth raster, the particles
// the paper clusters, DBSCAN clusters and their association with truth boxes: the functions the
// co-simulation's scorer (cosim::ModeScorer) runs, on numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/eval/association.hpp"
#include "dualgrid/eval/cell_metrics.hpp"
#include "dualgrid/eval/clustering.hpp"
#include "grid_holder.hpp"
#include "run_results.hpp"

namespace dualgrid::python {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using ByteArray = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

std::string Shape(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

// (ny, nx, 3) masses from an array or masses()'s dict; ValueError naming the shape or NaN.
FloatArray ReadMasses(py::handle obj) {
  FloatArray a;
  if (py::isinstance<py::dict>(obj)) {
    const py::dict d = py::reinterpret_borrow<py::dict>(obj);
    for (const char* k : {"free", "static", "dynamic"})
      if (!d.contains(k))
        throw py::value_error(std::string("masses: the dict has no '") + k +
                              "' (expected DynamicGrid.masses()' keys or a (ny, nx, 3) array)");
    a = FloatArray::ensure(py::module_::import("numpy").attr("stack")(
        py::make_tuple(d["free"], d["static"], d["dynamic"]), py::arg("axis") = -1));
  } else {
    a = FloatArray::ensure(obj);
  }
  if (!a)
    throw py::value_error("masses: expected a (ny, nx, 3) float array, got " + ShortRepr(obj));
  if (a.ndim() != 3 || a.shape(2) != 3)
    throw py::value_error("masses: expected shape (ny, nx, 3) (free, static, dynamic), got " +
                          Shape(a));
  const float* p = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(p[i]))
      throw py::value_error("masses: value " + std::to_string(i) + " is not finite");
  return a;
}

ByteArray ReadClasses(py::handle obj, const char* arg, int classes) {
  ByteArray a = ByteArray::ensure(obj);
  if (!a) throw py::value_error(std::string(arg) + ": expected a 2-D uint8 array");
  if (a.ndim() != 2)
    throw py::value_error(std::string(arg) + ": expected shape (ny, nx), got " + Shape(a));
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (a.data()[i] >= classes)
      throw py::value_error(std::string(arg) + ": value " + std::to_string(a.data()[i]) +
                            " at index " + std::to_string(i) + " is not a class (0.." +
                            std::to_string(classes - 1) + ")");
  return a;
}

void CheckThreshold(double t) {
  if (!(t >= 0.5 && t < 1.0))
    throw py::value_error("threshold: expected a probability in [0.5, 1), got " +
                          std::to_string(t));
}

py::array ClassifyCellsPy(ArrayArg masses, double threshold) {
  CheckThreshold(threshold);
  const FloatArray a = ReadMasses(masses);
  const std::size_t n = static_cast<std::size_t>(a.shape(0) * a.shape(1));
  std::vector<float> f(n), s(n), d(n);
  for (std::size_t i = 0; i < n; ++i) {
    f[i] = a.data()[3 * i];
    s[i] = a.data()[3 * i + 1];
    d[i] = a.data()[3 * i + 2];
  }
  py::array_t<std::uint8_t> out({a.shape(0), a.shape(1)});
  eval::ClassifyCells(f, s, d, threshold, {out.mutable_data(), n});
  return out;
}

py::dict ScoreCells(ArrayArg predicted, ArrayArg truth, std::optional<ArrayArg> observed) {
  const ByteArray p = ReadClasses(predicted, "predicted", eval::kNumPredictedClasses);
  const ByteArray t = ReadClasses(truth, "truth", eval::kNumTruthClasses);
  if (Shape(p) != Shape(t))
    throw py::value_error("truth: shape " + Shape(t) + " differs from predicted's " + Shape(p));
  ByteArray o;
  if (observed) {
    o = ByteArray::ensure(observed->obj);
    if (!o || Shape(o) != Shape(p))
      throw py::value_error("observed: expected a bool array of predicted's shape " + Shape(p));
  }
  const auto n = static_cast<std::size_t>(p.size());
  eval::CellClassificationAccumulator acc;
  acc.AddFrame(
      {p.data(), n}, {t.data(), n},
      observed ? std::span<const std::uint8_t>(o.data(), n) : std::span<const std::uint8_t>());
  return FromJson(nlohmann::json(acc.Result())).cast<py::dict>();
}

py::dict DynamicParticlesPy(Grid& g, std::optional<ArrayArg> classes, double threshold) {
  CheckThreshold(threshold);
  std::vector<std::uint8_t> c;
  if (classes) {
    const ByteArray a = ReadClasses(classes->obj, "classes", eval::kNumPredictedClasses);
    if (a.ndim() != 2 || a.shape(0) != g.grid.cells_y() || a.shape(1) != g.grid.cells_x())
      throw py::value_error("classes: expected the grid's shape (" +
                            std::to_string(g.grid.cells_y()) + ", " +
                            std::to_string(g.grid.cells_x()) + "), got " + Shape(a));
    c.assign(a.data(), a.data() + a.size());
  }
  std::vector<eval::WeightedParticle> out;
  Locked(g, [&](const filter::DynamicGrid& grid) {
    if (grid.step() == 0) return;
    if (c.empty()) {
      const std::size_t n = static_cast<std::size_t>(grid.cells_x()) * grid.cells_y();
      std::vector<float> f(n), s(n), d(n);
      std::vector<std::uint8_t> observed(n);
      grid.ExportMasses(f, s, d, observed);
      c.resize(n);
      eval::ClassifyCells(f, s, d, threshold, c);
    }
    cosim::DynamicParticles(grid, c, std::nullopt, &out);
  });
  std::vector<double> x, y, vx, vy, w;
  for (const auto& p : out) {
    x.push_back(p.position.x());
    y.push_back(p.position.y());
    vx.push_back(p.velocity.x());
    vy.push_back(p.velocity.y());
    w.push_back(p.weight);
  }
  py::dict d;
  d["x"] = ToArray(x);
  d["y"] = ToArray(y);
  d["vx"] = ToArray(vx);
  d["vy"] = ToArray(vy);
  d["weight"] = ToArray(w);
  return d;
}

std::vector<eval::Cluster> ReadClusters(py::handle obj) {
  const Table t = ReadTable(obj, "clusters", {{"x"}, {"y"}, {"vx", 0.0}, {"vy", 0.0}});
  std::vector<eval::Cluster> c(t.rows);
  for (std::size_t i = 0; i < t.rows; ++i) {
    c[i].position = {t.at(i, 0), t.at(i, 1)};
    c[i].velocity = {t.at(i, 2), t.at(i, 3)};
  }
  return c;
}

py::dict ClusterColumnsOf(const std::vector<eval::Cluster>& clusters) {
  std::vector<double> x, y, vx, vy, w, x0, y0, x1, y1;
  std::vector<int> size;
  for (const eval::Cluster& c : clusters) {
    x.push_back(c.position.x());
    y.push_back(c.position.y());
    vx.push_back(c.velocity.x());
    vy.push_back(c.velocity.y());
    w.push_back(c.weight);
    size.push_back(c.size);
    x0.push_back(c.min.x());
    y0.push_back(c.min.y());
    x1.push_back(c.max.x());
    y1.push_back(c.max.y());
  }
  py::dict d;
  d["x"] = ToArray(x);
  d["y"] = ToArray(y);
  d["vx"] = ToArray(vx);
  d["vy"] = ToArray(vy);
  d["weight"] = ToArray(w);
  d["particles"] = ToArray(size);
  d["min_x"] = ToArray(x0);
  d["min_y"] = ToArray(y0);
  d["max_x"] = ToArray(x1);
  d["max_y"] = ToArray(y1);
  return d;
}

py::dict ClusterParticles(TableArg particles, double eps, int min_points, double min_mass) {
  eval::DbscanParams params;
  params.eps = eps;
  params.min_points = min_points;
  std::string error;
  if (!params.IsValid(&error)) throw py::value_error("cluster_particles: " + error);
  if (!(min_mass >= 0.0 && std::isfinite(min_mass)))
    throw py::value_error("cluster_particles: min_mass must be finite and >= 0");
  const Table t = ReadTable(particles, "particles", {{"x"}, {"y"}, {"vx"}, {"vy"}, {"weight"}});
  std::vector<eval::WeightedParticle> p(t.rows);
  for (std::size_t i = 0; i < t.rows; ++i)
    p[i] = {{t.at(i, 0), t.at(i, 1)}, {t.at(i, 2), t.at(i, 3)}, t.at(i, 4)};
  eval::ParticleClusterer clusterer(params, min_mass);
  return ClusterColumnsOf(clusterer.Run(p));
}

py::dict AssociatePy(TableArg clusters, TableArg objects, double box_margin, double center_gate) {
  const std::vector<eval::Cluster> c = ReadClusters(clusters);
  const Table t =
      ReadTable(objects, "objects",
                {{"x"}, {"y"}, {"yaw", 0.0}, {"length"}, {"width"}, {"vx", 0.0}, {"vy", 0.0}});
  std::vector<eval::TruthObject> o(t.rows);
  for (std::size_t i = 0; i < t.rows; ++i) {
    o[i].id = static_cast<int>(i);
    o[i].box = {{t.at(i, 0), t.at(i, 1)}, t.at(i, 2), t.at(i, 3), t.at(i, 4)};
    o[i].velocity = {t.at(i, 5), t.at(i, 6)};
  }
  const eval::AssociationResult a = eval::Associate(c, o, {box_margin, center_gate});
  std::vector<std::int8_t> role;
  for (eval::ClusterRole r : a.role) role.push_back(static_cast<std::int8_t>(r));
  py::dict d;
  d["object_of_cluster"] = ToArray(a.object_of_cluster);
  d["cluster_of_object"] = ToArray(a.cluster_of_object);
  d["role"] = ToArray(role);
  d["matched"] = a.num_matched;
  d["duplicate"] = a.num_duplicate;
  d["false"] = a.num_false;
  return d;
}

}  // namespace

void BindEval(py::module_& m) {
  m.def("classify_cells", &ClassifyCellsPy, py::arg("masses"), py::arg("threshold") = 0.6,
        R"doc(Cell classes of masses as the scorer computes them: 2 dynamic when P(dynamic) >
threshold, else 1 static when P(static) > threshold, else 0 free when P(free) > threshold, else
3 unknown (CELL_CLASSES). masses: a (ny, nx, 3) array (free, static, dynamic: StepGrid.masses) or
DynamicGrid.masses()'s dict; finite. threshold in [0.5, 1) [probability]. Returns (ny, nx) uint8.)doc");
  m.def("score_cells", &ScoreCells, py::arg("predicted"), py::arg("truth"),
        py::arg("observed") = py::none(),
        R"doc(The cell confusion of one grid: predicted classes (0..3, classify_cells) against
truth classes (0 free, 1 static, 2 dynamic; StepGrid.truth_classes), counting the observed cells
only when `observed` (bool, same shape) is given. Returns metrics.json's "cells" entry
(confusion_truth_by_predicted, precision, recall, F1 per class, accuracy).)doc");
  m.def("dynamic_particles", &DynamicParticlesPy, py::arg("grid"), py::arg("classes") = py::none(),
        py::arg("threshold") = 0.6,
        R"doc(The particles the paper clusters (Sec. V) of a DynamicGrid of yours: its weighted
particles (after the weight update, before resampling, weight = the cell's dynamic mass share)
in the cells classified dynamic, by `classes` ((cells_y, cells_x) uint8) or else by
classify_cells(grid.masses(), threshold). Grid frame. Returns a dict of columns x, y [m], vx, vy
[m/s], weight, for cluster_particles(). Empty before the first update.)doc");
  m.def("cluster_particles", &ClusterParticles, py::arg("particles"), py::arg("eps") = 1.0,
        py::arg("min_points") = 3, py::arg("min_mass") = 1.8,
        R"doc(DBSCAN clusters of weighted particles as the scorer forms them: particles a table
with columns x, y [m], vx, vy [m/s], weight (dynamic_particles()' dict, a DataFrame, ...);
eps [m] the neighbourhood radius, min_points the core count, min_mass the lightest cluster kept
(summed weight). The defaults are the scenarios' evaluation.dbscan and min_cluster_mass. Returns
columns x, y, vx, vy (weighted means), weight, particles, min_x, min_y, max_x, max_y.)doc");
  m.def("associate", &AssociatePy, py::arg("clusters"), py::arg("objects"),
        py::arg("box_margin") = 1.0, py::arg("center_gate") = 2.5,
        R"doc(The paper's cluster-to-object association (eval::Associate): clusters with x, y
[m] (and vx, vy) against objects with x, y [m], yaw [rad], length, width [m] (and vx, vy), in one
frame; box_margin and center_gate [m] as the scenarios' evaluation.tracking. Returns
object_of_cluster and cluster_of_object (indices, -1 none), role per cluster (ROLE_NAMES) and
the matched, duplicate and false counts.)doc");
}

}  // namespace dualgrid::python
