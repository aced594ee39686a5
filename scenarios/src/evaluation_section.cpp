#include "dualgrid/core/validation.hpp"
#include "sections.hpp"

namespace dualgrid::scenario {
namespace detail {

void ReadEvaluation(MapReader& root, EvaluationConfig* e) {
  auto r = root.Map("evaluation");
  if (!r) return;
  r->Read("dynamic_threshold", &e->dynamic_threshold);
  r->Read("dbscan_eps", &e->dbscan.eps);
  r->Read("dbscan_min_points", &e->dbscan.min_points);
  r->Read("min_cluster_mass", &e->min_cluster_mass);
  r->Read("gate_box_margin", &e->tracking.association.box_margin);
  r->Read("gate_center", &e->tracking.association.center_gate);
  r->Read("consistent_required", &e->tracking.required);
  r->Read("consistent_window", &e->tracking.window);
  r->Read("min_frames_in_grid", &e->tracking.min_frames_in_grid);
  r->Read("velocity_tolerance", &e->tracking.velocity_tolerance);
  r->Read("velocity_tolerance_fraction", &e->tracking.velocity_tolerance_fraction);
  r->Read("focus_object", &e->focus_object);
  r->Read("snapshot_times", &e->snapshot_times);
  r->Finish();
  std::string error;
  // The validators' names of the keys above that differ from them.
  static const KeyAlias kKeys[] = {{"association.box_margin", "gate_box_margin"},
                                   {"association.center_gate", "gate_center"},
                                   {"required", "consistent_required"},
                                   {"window", "consistent_window"}};
  if (!e->IsValid(&error)) Invalid(root.file(), "evaluation", error, kKeys);
}

}  // namespace detail

bool EvaluationConfig::IsValid(std::string* error) const {
  FieldCheck c;
  c.InRange("dynamic_threshold", dynamic_threshold, 0.0, 1.0, Interval::kOpen);
  c.Expect(min_cluster_mass >= 0.0, "min_cluster_mass", min_cluster_mass, ">= 0");
  c.Member("dbscan_", dbscan);
  c.Member("", tracking);
  return c.Done(error);
}
}  // namespace dualgrid::scenario
