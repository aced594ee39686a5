#include "nuscenes_annotations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dualgrid::recorded::nuscenes {

namespace {

// The devkit's box_velocity: the centred difference between the previous and next annotation
// (one-sided at the ends); NaN when the two lie more than 1.5 s apart (3 s when centred).
void DevkitVelocities(std::vector<NuScenesAnnotation>* keys) {
  const std::size_t n = keys->size();
  std::vector<Velocity> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i > 0 ? i - 1 : i, b = i + 1 < n ? i + 1 : i;
    const double dt = static_cast<double>((*keys)[b].timestamp_us - (*keys)[a].timestamp_us) / 1e6;
    const double max_dt = (i > 0 && i + 1 < n) ? 3.0 : 1.5;
    v[i] = (dt > 0.0 && dt <= max_dt)
               ? Velocity(((*keys)[b].center - (*keys)[a].center) / dt)
               : Velocity::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  for (std::size_t i = 0; i < n; ++i) (*keys)[i].velocity = v[i];
}

NuScenesAnnotation ReadAnnotation(Tables& tables, const Json& r, std::int64_t timestamp) {
  const Table& t = tables.Get("sample_annotation");
  NuScenesAnnotation a;
  a.timestamp_us = timestamp;
  const std::vector<double> c = Numbers(t, r, "translation", 3);
  const std::vector<double> size = Numbers(t, r, "size", 3);  // width, length, height
  a.center = {c[0], c[1]};
  a.yaw = QuaternionYaw(Numbers(t, r, "rotation", 4));
  a.width = size[0];
  a.length = size[1];
  if (!(a.width > 0.0 && a.length > 0.0))
    throw std::invalid_argument(Where(t, r, "size") + "width and length must be > 0");
  const auto pts = r.find("num_radar_pts");
  a.num_radar_pts = pts != r.end() && pts->is_number_integer() ? pts->get<int>() : 0;
  return a;
}

}  // namespace

SceneInstances ReadInstances(Tables& tables, const std::map<std::string, std::int64_t>& sample_time,
                             const NuScenesOptions& options) {
  const Table& anns = tables.Get("sample_annotation");
  std::map<std::string, Instance> by_token;
  std::map<std::string, std::string> category_of;  // category token -> name
  for (const Json& r : *anns.records) {
    const auto s = sample_time.find(Str(anns, r, "sample_token"));
    if (s == sample_time.end()) continue;  // another scene's
    const std::string inst = Str(anns, r, "instance_token");
    const Json& ir = tables.Record("instance", inst, Where(anns, r, "instance_token"));
    const Table& it = tables.Get("instance");
    const std::string cat_token = Str(it, ir, "category_token");
    auto cat = category_of.find(cat_token);
    if (cat == category_of.end()) {
      const Json& cr = tables.Record("category", cat_token, Where(it, ir, "category_token"));
      cat = category_of.emplace(cat_token, Str(tables.Get("category"), cr, "name")).first;
    }
    if (LabelOfCategory(cat->second) < 0) continue;  // not a vehicle
    Instance& in = by_token[inst];
    in.token = inst;
    in.category = cat->second;
    in.label = LabelOfCategory(cat->second);
    NuScenesAnnotation a = ReadAnnotation(tables, r, s->second);
    a.instance = inst;
    a.category = cat->second;
    in.keys.push_back(a);
  }
  SceneInstances out;
  for (auto& [token, in] : by_token) {
    std::sort(in.keys.begin(), in.keys.end(),
              [](const auto& a, const auto& b) { return a.timestamp_us < b.timestamp_us; });
    for (std::size_t i = 1; i < in.keys.size(); ++i)
      if (in.keys[i].timestamp_us == in.keys[i - 1].timestamp_us)
        throw std::invalid_argument(anns.file.string() + ": instance '" + token +
                                    "', field 'sample_token': two annotations in one sample");
    if (static_cast<int>(in.keys.size()) < options.min_annotations) {
      ++out.skipped;
      continue;
    }
    DevkitVelocities(&in.keys);
    for (const NuScenesAnnotation& a : in.keys)
      if (std::isfinite(a.velocity.x()) && a.velocity.norm() >= options.moving_speed)
        in.moving = true;
    for (NuScenesAnnotation& a : in.keys) a.moving = in.moving;
    out.instances.push_back(std::move(in));
  }
  return out;
}

std::optional<ReferenceObject> Interpolate(const Instance& instance, std::int64_t t) {
  const auto& k = instance.keys;
  if (k.empty() || t < k.front().timestamp_us || t > k.back().timestamp_us) return std::nullopt;
  std::size_t j = 1;
  while (j < k.size() && k[j].timestamp_us < t) ++j;
  if (j >= k.size()) j = k.size() - 1;
  const NuScenesAnnotation& a = k[j - 1];
  const NuScenesAnnotation& b = k.size() > 1 ? k[j] : k[0];
  const double span = static_cast<double>(b.timestamp_us - a.timestamp_us);
  const double f = span > 0.0 ? static_cast<double>(t - a.timestamp_us) / span : 0.0;
  // A key without the devkit's velocity takes the segment's own.
  const Velocity segment =
      span > 0.0 ? Velocity((b.center - a.center) / (span / 1e6)) : Velocity::Zero();
  const Velocity va = std::isfinite(a.velocity.x()) ? a.velocity : segment;
  const Velocity vb = std::isfinite(b.velocity.x()) ? b.velocity : segment;
  ReferenceObject v;
  v.id = instance.token;
  v.type = instance.category;
  v.box.center = a.center + f * (b.center - a.center);
  v.box.yaw = WrapAngle(a.yaw + f * WrapAngle(b.yaw - a.yaw));
  v.box.length = b.length;
  v.box.width = b.width;
  v.velocity = va + f * (vb - va);
  return v;
}

}  // namespace dualgrid::recorded::nuscenes
