#include "run_results.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>

#include "convert.hpp"

namespace dualgrid::python {

void ClusterColumns::OnStep(const cosim::StepView& v) {
  static const char* kRole[] = {"matched", "duplicate", "false"};
  const GridFrame& g = v.pipeline.grid_frame();
  for (std::size_t m = 0; m < v.scorers.size(); ++m) {
    const auto& a = v.scorers[m].association();
    const auto& clusters = v.scorers[m].clusters();
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      const Position p = g.ToWorld(clusters[c].position);
      const Velocity u = g.VectorToWorld(clusters[c].velocity);
      step.push_back(v.frame.step);
      time.push_back(v.frame.time);
      mode.push_back(v.mode_names[m]);
      x.push_back(p.x());
      y.push_back(p.y());
      vx.push_back(u.x());
      vy.push_back(u.y());
      weight.push_back(clusters[c].weight);
      particles.push_back(clusters[c].size);
      role.push_back(kRole[static_cast<int>(a.role[c])]);
      const int o = a.object_of_cluster[c];
      object.push_back(o >= 0 ? v.pipeline.ids().Name(v.objects[o].id) : std::string());
    }
  }
}
py::dict ClusterColumns::Columns() const {
  py::dict d;
  d["step"] = ToArray(step);
  d["time"] = ToArray(time);
  d["mode"] = py::cast(mode);
  d["x"] = ToArray(x);
  d["y"] = ToArray(y);
  d["vx"] = ToArray(vx);
  d["vy"] = ToArray(vy);
  d["weight"] = ToArray(weight);
  d["particles"] = ToArray(particles);
  d["role"] = py::cast(role);
  d["object"] = py::cast(object);
  return d;
}

py::object FromJson(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// objects.csv's rows as columns: every key of eval::ObjectMetrics, plus mode and name.
namespace {

py::dict ObjectColumns(const std::vector<std::string>& modes,
                       const std::vector<eval::ScenarioMetrics>& metrics,
                       const cosim::IdRegistry& ids) {
  std::vector<nlohmann::json> rows;
  for (std::size_t m = 0; m < metrics.size(); ++m)
    for (const eval::ObjectMetrics& o : metrics[m].objects) {
      nlohmann::json row = o;
      row["mode"] = modes[m];
      row["name"] = ids.Name(o.id);
      rows.push_back(std::move(row));
    }
  std::vector<std::string> keys;
  for (const auto& row : rows)
    for (const auto& [k, value] : row.items())
      if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
  nlohmann::json columns = nlohmann::json::object();
  for (const auto& k : keys) {
    columns[k] = nlohmann::json::array();
    for (const auto& row : rows) columns[k].push_back(row.contains(k) ? row[k] : nullptr);
  }
  py::dict d;
  for (const auto& [k, value] : FromJson(columns).cast<py::dict>()) d[k] = value;
  return d;
}

}  // namespace

py::dict Results(const cosim::CoSimulation& cs, const scenario::ScenarioConfig& config,
                 const ClusterColumns& clusters) {
  const std::vector<eval::ScenarioMetrics> metrics = cs.Metrics();
  nlohmann::json mj = nlohmann::json::object();
  for (std::size_t m = 0; m < metrics.size(); ++m) mj[cs.mode_names()[m]] = metrics[m];
  nlohmann::json names = nlohmann::json::object();
  if (!metrics.empty())
    for (const auto& o : metrics.front().objects)
      names[std::to_string(o.id)] = cs.pipeline().ids().Name(o.id);

  py::dict r;
  r["scenario"] = config.sim.name;
  r["seed"] = config.sim.seed;
  r["steps"] = cs.steps();
  r["simulated_s"] = cs.simulated();
  r["requested_s"] = config.sim.duration;
  r["complete"] = cs.finished();
  r["detections_per_step"] =
      cs.steps() ? static_cast<double>(cs.total_detections()) / cs.steps() : 0.0;
  r["metrics"] = FromJson(mj);
  r["object_names"] = FromJson(names);
  r["objects"] = ObjectColumns(cs.mode_names(), metrics, cs.pipeline().ids());
  r["clusters"] = clusters.Columns();
  return r;
}

}  // namespace dualgrid::python
