#include "dualgrid/outputs/capture.hpp"

#include "dualgrid/core/text.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace dualgrid::outputs::replay {

namespace {

Box ToBox(int id, const OrientedBox& b, const Velocity& v) {
  return {id, b.center.x(), b.center.y(), b.yaw, b.length, b.width, v.x(), v.y()};
}

// Velocity in cm/s, rounded to 0.2 m/s: finer steps only add noise that zlib cannot compress
// (measured on the highway: 0.1 m/s steps made the velocity arrays 2.7x smaller than cm/s, 0.2
// m/s another ~10 %; a colour hue or a read-out does not show the difference).
std::int16_t Centimetres(float v) {
  const double steps = std::round(static_cast<double>(v) * 5.0);
  return static_cast<std::int16_t>(std::clamp(steps * 20.0, -32760.0, 32760.0));
}

// A mass in 1/255 steps, rounded to 2 per cent first: 51 levels compress the mass arrays ~20 %
// better than whole per cents (docs/replay.md, "Cost"), and a picture's grey levels or a
// read-out of two decimals lose nothing a reader compares.
std::uint8_t Quantise(float mass) {
  // Non-negative, so adding 0.5 and truncating rounds (std::lround was 2 % of a recorded run).
  const int steps = static_cast<int>(std::clamp(mass, 0.0f, 1.0f) * 50.0f + 0.5f);
  return static_cast<std::uint8_t>(static_cast<int>(steps * 5.1f + 0.5f));
}

// Below this quantised dynamic mass (0.05) a cell's mean velocity is not recorded: its colour
// does not show it, and its few particles' mean is noise.
constexpr std::uint8_t kVelocityMinDynamic = 13;

}  // namespace

bool LiveCounter::VelocityOk(const cosim::ModeScorer& scorer,
                             const std::vector<eval::TruthObject>& objects, std::size_t c) const {
  const int o = scorer.association().object_of_cluster[c];
  if (o < 0) return false;
  const eval::TruthObject& obj = objects[static_cast<std::size_t>(o)];
  // The D_v rule (eval/metrics.hpp): absolute tolerance or a fraction of the object's speed.
  const double tolerance = std::max(params_.velocity_tolerance,
                                    params_.velocity_tolerance_fraction * obj.velocity.norm());
  return (scorer.clusters()[c].velocity - obj.velocity).norm() < tolerance;
}

Live LiveCounter::Count(const cosim::ModeScorer& scorer,
                        const std::vector<eval::TruthObject>& objects) {
  Live l;
  const eval::AssociationResult& a = scorer.association();
  for (std::size_t o = 0; o < objects.size(); ++o) {
    if (!objects[o].in_grid) continue;
    ++l.in_grid;
    const int c = a.cluster_of_object[o];
    if (c < 0) continue;
    ++l.tracked;
    if (VelocityOk(scorer, objects, static_cast<std::size_t>(c))) ++l.tracked_v;
  }
  l.false_clusters = a.num_false;
  in_grid_ += l.in_grid;
  tracked_ += l.tracked;
  tracked_v_ += l.tracked_v;
  l.total_in_grid = in_grid_;
  l.total_tracked = tracked_;
  l.total_tracked_v = tracked_v_;
  return l;
}

Header MakeHeader(const cosim::Pipeline& pipeline, const std::vector<std::string>& modes,
                  double interval, int max_particles) {
  const scenario::ScenarioConfig& c = pipeline.config();
  const filter::DynamicGrid& grid = pipeline.grid(0);
  const GridFrame& g = pipeline.grid_frame();
  Header h;
  h.scenario = c.sim.name;
  h.seed = c.sim.seed;
  h.modes = modes;
  for (const auto& s : pipeline.radar().sensors()) h.sensors.push_back(s.name);
  h.cells_x = grid.cells_x();
  h.cells_y = grid.cells_y();
  h.resolution = grid.resolution();
  h.frame_yaw_deg = RadToDeg(g.yaw());
  h.interval = interval;
  h.particle_unit = ParticleUnit(h.cells_x * h.resolution, h.cells_y * h.resolution);
  h.max_particles = max_particles;
  h.dynamic_threshold = c.evaluation.dynamic_threshold;
  h.multipath = c.radar.options.multipath.enabled;
  // The static world in the world frame: each frame turns it into its own grid frame.
  for (std::size_t i = 0; i < c.sim.parked.size(); ++i)
    h.parked.push_back(ToBox(-1, c.sim.parked[i].box, Velocity::Zero()));
  for (const auto& rail : c.sim.guard_rails) {
    h.rails.emplace_back();
    for (const Position& p : rail.points) h.rails.back().push_back({p.x(), p.y()});
  }
  return h;
}

Frame CaptureStep(const cosim::Pipeline& pipeline, const std::vector<eval::TruthObject>& objects,
                  std::size_t modes) {
  const GridFrame& g = pipeline.grid_frame();
  const sim::Frame& sf = pipeline.frame();
  Frame f;
  f.time = sf.time;
  f.yaw_deg = RadToDeg(g.yaw());
  f.ego = ToBox(-1, g.ToGrid(sf.ego.box), g.VectorToGrid(sf.ego.velocity));
  for (const eval::TruthObject& o : objects) f.truth.push_back(ToBox(o.id, o.box, o.velocity));
  for (const radar::Detection& d : pipeline.detections()) {
    const Position p = g.ToGrid(d.position_world);
    const Velocity v = g.VectorToGrid(d.radial_velocity_world);
    f.detections.push_back(
        {d.sensor, p.x(), p.y(), v.x(), v.y(), d.is_clutter, static_cast<int>(d.path)});
  }
  f.modes.resize(modes);
  return f;
}

namespace {

// Mode m's cells: masses quantised, mean velocities where the cell is dynamic enough.
void CaptureCells(const cosim::GridSnapshot& s, ModeFrame& mf) {
  const std::size_t n = s.free.size();
  assert(s.mean_vx.size() == n);
  mf.free.resize(n);
  mf.static_occ.resize(n);
  mf.dynamic.resize(n);
  mf.vx_cm.resize(n);
  mf.vy_cm.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    mf.free[k] = Quantise(s.free[k]);
    mf.static_occ[k] = Quantise(s.static_occ[k]);
    mf.dynamic[k] = Quantise(s.dynamic[k]);
    const bool moving = mf.dynamic[k] >= kVelocityMinDynamic;
    mf.vx_cm[k] = moving ? Centimetres(s.mean_vx[k]) : 0;
    mf.vy_cm[k] = moving ? Centimetres(s.mean_vy[k]) : 0;
  }
}

}  // namespace

void CaptureMode(const cosim::Pipeline& pipeline, std::size_t m,
                 const cosim::GridSnapshot& snapshot, const cosim::ModeScorer& scorer,
                 const LiveCounter& counter, const Live& live,
                 const std::vector<eval::TruthObject>& objects, const Header& header, Frame* f) {
  // Every mode's grid lies on the same cells (one ego, one origin), so each mode's own origin is
  // the frame's; mode 0 writes it.
  const double origin_x = snapshot.origin.x(), origin_y = snapshot.origin.y();
  if (m == 0) f->origin_x = origin_x, f->origin_y = origin_y;
  ModeFrame& mf = f->modes[m];
  CaptureCells(snapshot, mf);
  // An even subsample of the persistent particles (their order is the filter's, which is
  // deterministic), as offsets from the grid's corner.
  const filter::ParticleSet& ps = pipeline.grid(m).particles();
  const std::size_t total = ps.size();
  const std::size_t want =
      std::min<std::size_t>(total, static_cast<std::size_t>(header.max_particles));
  const double extent_x = header.cells_x * header.resolution;
  const double extent_y = header.cells_y * header.resolution;
  mf.particles.reserve(2 * want);
  for (std::size_t j = 0; j < want; ++j) {
    const std::size_t i = j * total / want;
    const double dx = ps.x[i] - origin_x, dy = ps.y[i] - origin_y;
    if (!(dx >= 0.0 && dy >= 0.0 && dx < extent_x && dy < extent_y)) continue;
    mf.particles.push_back(static_cast<std::uint16_t>(dx / header.particle_unit));
    mf.particles.push_back(static_cast<std::uint16_t>(dy / header.particle_unit));
  }
  const auto& a = scorer.association();
  for (std::size_t c = 0; c < scorer.clusters().size(); ++c) {
    const eval::Cluster& cl = scorer.clusters()[c];
    const int o = a.object_of_cluster[c];
    mf.clusters.push_back({cl.position.x(), cl.position.y(), cl.velocity.x(), cl.velocity.y(),
                           cl.min.x(), cl.min.y(), cl.max.x(), cl.max.y(),
                           static_cast<int>(a.role[c]),
                           o >= 0 ? objects[static_cast<std::size_t>(o)].id : -1,
                           counter.VelocityOk(scorer, objects, c)});
  }
  mf.live = live;
}

}  // namespace dualgrid::outputs::replay
