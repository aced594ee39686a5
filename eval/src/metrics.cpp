#include "dualgrid/eval/metrics.hpp"

#include <cmath>
#include <set>
#include <stdexcept>

#include "dualgrid/core/validation.hpp"
#include "json_util.hpp"

namespace dualgrid::eval {

using detail::OptFromJson;
using detail::OptToJson;

bool TrackingMetricsParams::IsValid(std::string* error) const {
  FieldCheck c;
  c.Member("association.", association);
  c.AtLeast("window", window, 1);
  c.Expect(required >= 1 && required <= window, "required", std::to_string(required),
           "in [1, window = " + std::to_string(window) + "]");
  c.AtLeast("min_frames_in_grid", min_frames_in_grid, 1);
  c.Positive("velocity_tolerance", velocity_tolerance, "m/s");
  c.InRange("velocity_tolerance_fraction", velocity_tolerance_fraction, 0.0, 1.0);
  return c.Done(error);
}

TrackingMetricsAccumulator::TrackingMetricsAccumulator(const TrackingMetricsParams& params)
    : params_(params) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument("TrackingMetricsParams: " + error);
}

AssociationResult TrackingMetricsAccumulator::AddFrame(double time,
                                                       std::span<const Cluster> clusters,
                                                       std::span<const TruthObject> objects) {
  if (!std::isfinite(time) || (last_time_ && time <= *last_time_))
    throw std::invalid_argument("TrackingMetricsAccumulator::AddFrame: time " +
                                std::to_string(time) + " does not follow " +
                                (last_time_ ? std::to_string(*last_time_) : "the start"));
  {
    std::set<int> ids;
    for (const TruthObject& o : objects) {
      if (!ids.insert(o.id).second)
        throw std::invalid_argument("TrackingMetricsAccumulator::AddFrame: object id " +
                                    std::to_string(o.id) + " repeated at time " +
                                    std::to_string(time));
    }
  }
  AssociationResult a = Associate(clusters, objects, params_.association);
  last_time_ = time;
  ++frames_;
  clusters_ += static_cast<std::int64_t>(clusters.size());
  false_clusters_ += a.num_false;
  duplicate_clusters_ += a.num_duplicate;

  for (std::size_t k = 0; k < objects.size(); ++k) {
    const TruthObject& o = objects[k];
    const int c = a.cluster_of_object[k];
    const bool tracked = o.in_grid && c >= 0;
    // Objects enter the table when first in the grid or first detected in it; earlier frames
    // carry no information about the grid.
    auto it = objects_.find(o.id);
    if (it == objects_.end()) {
      if (!o.in_grid && !o.detected_in_grid) continue;
      it = objects_.emplace(o.id, ObjectState{}).first;
    }
    ObjectState& s = it->second;
    if (o.in_grid) {
      ++s.frames_in_grid;
      if (!s.first_in_grid_time) s.first_in_grid_time = time;
    }
    // Matched with the right velocity (D_v, and the t_d window whether or not in the grid).
    const bool matched_v =
        c >= 0 && (clusters[c].velocity - o.velocity).norm() <
                      std::max(params_.velocity_tolerance,
                               params_.velocity_tolerance_fraction * o.velocity.norm());
    if (tracked) {
      ++s.frames_tracked;
      const double dx = (clusters[c].position - o.box.center).norm();
      const double dv = (clusters[c].velocity - o.velocity).norm();
      if (matched_v) ++s.frames_tracked_v;
      s.position_error_sum += dx;
      s.velocity_error_sum += dv;
      position_error_sum_ += dx;
      velocity_error_sum_ += dv;
      // Distance to the box: the offset beyond the box's extent in its own frame.
      const Vector2 local = Rotation(o.box.yaw).transpose() * (clusters[c].position - o.box.center);
      const Vector2 outside(std::max(0.0, std::abs(local.x()) - 0.5 * o.box.length),
                            std::max(0.0, std::abs(local.y()) - 0.5 * o.box.width));
      box_distance_sum_ += outside.norm();
      ++matches_;
    }
    if (!s.clock_start_time && o.in_coverage && o.detected_in_grid) s.clock_start_time = time;
    if (s.clock_start_time && !s.track_onset_time) {
      if (static_cast<int>(s.window.size()) == params_.window) s.window.erase(s.window.begin());
      s.window.emplace_back(time, matched_v);
      int count = 0;
      std::optional<double> earliest;
      for (const auto& [t, tr] : s.window) {
        if (!tr) continue;
        ++count;
        if (!earliest) earliest = t;
      }
      if (count >= params_.required) {
        s.track_onset_time = earliest;
        s.window.clear();
        s.window.shrink_to_fit();
      }
    }
  }
  return a;
}

ScenarioMetrics TrackingMetricsAccumulator::Result() const {
  ScenarioMetrics m;
  m.frames = frames_;
  m.matches = matches_;
  if (matches_ > 0) {
    m.position_error = position_error_sum_ / static_cast<double>(matches_);
    m.velocity_error = velocity_error_sum_ / static_cast<double>(matches_);
    m.box_distance = box_distance_sum_ / static_cast<double>(matches_);
  }
  if (frames_ > 0) {
    m.clusters_per_scan = static_cast<double>(clusters_) / frames_;
    m.false_clusters_per_scan = static_cast<double>(false_clusters_) / frames_;
    m.duplicate_clusters_per_scan = static_cast<double>(duplicate_clusters_) / frames_;
  }
  double d_sum = 0.0, dv_sum = 0.0, td_sum = 0.0;
  for (const auto& [id, s] : objects_) {
    ObjectMetrics o;
    o.id = id;
    o.frames_in_grid = s.frames_in_grid;
    o.frames_tracked = s.frames_tracked;
    o.frames_tracked_v = s.frames_tracked_v;
    o.scored = s.frames_in_grid >= params_.min_frames_in_grid;
    o.first_in_grid_time = s.first_in_grid_time;
    o.clock_start_time = s.clock_start_time;
    o.track_onset_time = s.track_onset_time;
    if (s.frames_in_grid > 0) {
      o.tracked_fraction = static_cast<double>(s.frames_tracked) / s.frames_in_grid;
      o.tracked_fraction_v = static_cast<double>(s.frames_tracked_v) / s.frames_in_grid;
    }
    if (s.track_onset_time) o.detection_time = *s.track_onset_time - *s.clock_start_time;
    if (s.frames_tracked > 0) {
      o.position_error = s.position_error_sum / s.frames_tracked;
      o.velocity_error = s.velocity_error_sum / s.frames_tracked;
    }
    if (o.scored) {
      ++m.objects_scored;
      d_sum += *o.tracked_fraction;
      dv_sum += *o.tracked_fraction_v;
      if (o.detection_time) {
        ++m.objects_detected;
        td_sum += *o.detection_time;
      } else {
        ++m.objects_never_tracked;
        if (!o.clock_start_time) ++m.objects_never_observable;
      }
    }
    m.objects.push_back(o);
  }
  if (m.objects_scored > 0) {
    m.tracked_fraction = d_sum / m.objects_scored;
    m.tracked_fraction_v = dv_sum / m.objects_scored;
  }
  if (m.objects_detected > 0) m.detection_time = td_sum / m.objects_detected;
  return m;
}

void to_json(nlohmann::json& j, const TrackingMetricsParams& p) {
  j = {{"association", p.association},
       {"required", p.required},
       {"window", p.window},
       {"min_frames_in_grid", p.min_frames_in_grid},
       {"velocity_tolerance", p.velocity_tolerance},
       {"velocity_tolerance_fraction", p.velocity_tolerance_fraction}};
}

void to_json(nlohmann::json& j, const ObjectMetrics& m) {
  j = nlohmann::json{{"id", m.id},
                     {"frames_in_grid", m.frames_in_grid},
                     {"frames_tracked", m.frames_tracked},
                     {"frames_tracked_v", m.frames_tracked_v},
                     {"scored", m.scored},
                     {"first_in_grid_time", OptToJson(m.first_in_grid_time)},
                     {"clock_start_time", OptToJson(m.clock_start_time)},
                     {"track_onset_time", OptToJson(m.track_onset_time)},
                     {"tracked_fraction", OptToJson(m.tracked_fraction)},
                     {"tracked_fraction_v", OptToJson(m.tracked_fraction_v)},
                     {"detection_time", OptToJson(m.detection_time)},
                     {"position_error", OptToJson(m.position_error)},
                     {"velocity_error", OptToJson(m.velocity_error)}};
}

void from_json(const nlohmann::json& j, ObjectMetrics& m) {
  j.at("id").get_to(m.id);
  j.at("frames_in_grid").get_to(m.frames_in_grid);
  j.at("frames_tracked").get_to(m.frames_tracked);
  m.frames_tracked_v = j.value("frames_tracked_v", 0);
  j.at("scored").get_to(m.scored);
  m.first_in_grid_time = OptFromJson(j, "first_in_grid_time");
  m.clock_start_time = OptFromJson(j, "clock_start_time");
  m.track_onset_time = OptFromJson(j, "track_onset_time");
  m.tracked_fraction = OptFromJson(j, "tracked_fraction");
  m.tracked_fraction_v = OptFromJson(j, "tracked_fraction_v");
  m.detection_time = OptFromJson(j, "detection_time");
  m.position_error = OptFromJson(j, "position_error");
  m.velocity_error = OptFromJson(j, "velocity_error");
}

void to_json(nlohmann::json& j, const ScenarioMetrics& m) {
  j = nlohmann::json{{"frames", m.frames},
                     {"matches", m.matches},
                     {"box_distance", OptToJson(m.box_distance)},
                     {"position_error", OptToJson(m.position_error)},
                     {"velocity_error", OptToJson(m.velocity_error)},
                     {"detection_time", OptToJson(m.detection_time)},
                     {"tracked_fraction", OptToJson(m.tracked_fraction)},
                     {"tracked_fraction_v", OptToJson(m.tracked_fraction_v)},
                     {"objects_scored", m.objects_scored},
                     {"objects_detected", m.objects_detected},
                     {"objects_never_tracked", m.objects_never_tracked},
                     {"objects_never_observable", m.objects_never_observable},
                     {"clusters_per_scan", m.clusters_per_scan},
                     {"false_clusters_per_scan", m.false_clusters_per_scan},
                     {"duplicate_clusters_per_scan", m.duplicate_clusters_per_scan},
                     {"cells", m.cells ? nlohmann::json(*m.cells) : nlohmann::json(nullptr)},
                     {"objects", m.objects}};
  if (m.points) j["points"] = *m.points;  // recorded data only: co-simulation files unchanged
}

void from_json(const nlohmann::json& j, ScenarioMetrics& m) {
  j.at("frames").get_to(m.frames);
  j.at("matches").get_to(m.matches);
  m.box_distance = OptFromJson(j, "box_distance");
  m.position_error = OptFromJson(j, "position_error");
  m.velocity_error = OptFromJson(j, "velocity_error");
  m.detection_time = OptFromJson(j, "detection_time");
  m.tracked_fraction = OptFromJson(j, "tracked_fraction");
  m.tracked_fraction_v = OptFromJson(j, "tracked_fraction_v");
  j.at("objects_scored").get_to(m.objects_scored);
  j.at("objects_detected").get_to(m.objects_detected);
  j.at("objects_never_tracked").get_to(m.objects_never_tracked);
  j.at("objects_never_observable").get_to(m.objects_never_observable);
  j.at("clusters_per_scan").get_to(m.clusters_per_scan);
  j.at("false_clusters_per_scan").get_to(m.false_clusters_per_scan);
  j.at("duplicate_clusters_per_scan").get_to(m.duplicate_clusters_per_scan);
  const auto cells = j.find("cells");
  if (cells != j.end() && !cells->is_null())
    m.cells = cells->get<CellMetrics>();
  else
    m.cells.reset();
  const auto points = j.find("points");
  if (points != j.end() && !points->is_null())
    m.points = points->get<PointMetrics>();
  else
    m.points.reset();
  j.at("objects").get_to(m.objects);
}

}  // namespace dualgrid::eval
