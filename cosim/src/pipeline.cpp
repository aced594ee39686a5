#include "dualgrid/cosim/pipeline.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "dualgrid/core/limits.hpp"

namespace dualgrid::cosim {

namespace {

bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
bool SameBits(const Vector2& a, const Vector2& b) {
  return SameBits(a.x(), b.x()) && SameBits(a.y(), b.y());
}

// Step 4's inputs equal bit for bit (so -0.0 differs from 0.0, and NaN can equal NaN: what Build
// sees, not what == says).
bool SameInputs(std::span<const filter::Measurement> m, std::span<const filter::SensorCoverage> c,
                std::span<const filter::Measurement> m2,
                std::span<const filter::SensorCoverage> c2) {
  if (m.size() != m2.size() || c.size() != c2.size()) return false;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (!SameBits(m[i].position, m2[i].position) ||
        !SameBits(m[i].radial_velocity, m2[i].radial_velocity) ||
        !SameBits(m[i].sensor_position, m2[i].sensor_position))
      return false;
  for (std::size_t i = 0; i < c.size(); ++i)
    if (!SameBits(c[i].origin, c2[i].origin) || !SameBits(c[i].boresight, c2[i].boresight) ||
        !SameBits(c[i].half_fov, c2[i].half_fov) || !SameBits(c[i].min_range, c2[i].min_range) ||
        !SameBits(c[i].max_range, c2[i].max_range))
      return false;
  return true;
}

}  // namespace

int IdRegistry::Id(const std::string& name) {
  auto [it, inserted] = ids_.try_emplace(name, static_cast<int>(names_.size()));
  if (inserted) names_.push_back(name);
  return it->second;
}

std::optional<int> IdRegistry::Find(const std::string& name) const {
  const auto it = ids_.find(name);
  return it == ids_.end() ? std::nullopt : std::optional<int>(it->second);
}

const std::string& IdRegistry::Name(int id) const {
  static const std::string kClutter = "clutter";
  if (id < 0 || id >= static_cast<int>(names_.size())) return kClutter;
  return names_[id];
}

void CheckFilterMemory(const scenario::ScenarioConfig& config, std::size_t modes) {
  const double need = static_cast<double>(modes) * config.filter.MemoryBytes();
  const double have = PhysicalMemoryBytes();
  if (have > 0 && need > kMaxMemoryShare * have) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "%s: key 'filter.num_particles' (%d) with num_birth %d and %d x %d cells: %zu "
                  "filter(s) would need %.1f GB, more than 80 %% of this machine's %.1f GB; lower "
                  "them or run fewer --modes",
                  config.file.string().c_str(), config.filter.num_particles,
                  config.filter.num_birth, config.filter.CellsX(), config.filter.CellsY(), modes,
                  need / 1e9, have / 1e9);
    throw std::invalid_argument(buf);
  }
}

Pipeline::Pipeline(const scenario::ScenarioConfig& config, std::vector<filter::WeightMode> modes)
    : config_(config), modes_(std::move(modes)) {
  CheckFilterMemory(config_, modes_.size());
  // The loader validated the sensors; a caller that built its configuration by hand learns of a
  // bad one here rather than at the ego's departure, when the radar is built.
  for (const radar::SensorParams& s : config_.radar.sensors) {
    std::string error;
    if (!s.IsValid(&error)) throw std::invalid_argument("sensor '" + s.name + "': " + error);
  }
  MakeFilters(true);
  source_ = std::make_unique<SumoSource>(config_, ids_);
}

Pipeline::Pipeline(const scenario::ScenarioConfig& config, std::vector<filter::WeightMode> modes,
                   const SourceFactory& make_source)
    : config_(config), modes_(std::move(modes)) {
  CheckFilterMemory(config_, modes_.size());
  MakeFilters(false);
  source_ = make_source(config_, ids_);
  if (!source_) throw std::logic_error("Pipeline: the source factory returned no source");
}

void Pipeline::MakeFilters(bool cycle_is_step) {
  for (filter::WeightMode m : modes_) {
    filter::FilterParams p = config_.FilterFor(m);
    if (!cycle_is_step) p.cycle = config_.filter.cycle;
    // The same seed for every mode: birth and prediction noise are identical across modes until
    // their particle sets differ, so the comparison isolates the weights.
    filters_.push_back(std::make_unique<filter::DynamicGrid>(p, config_.sim.seed));
  }
  // Step 4 depends on the detections and the grid's geometry only: built once per step for every
  // mode (MeasurementGrid, docs/performance.md).
  measurement_.reset();
  if (!filters_.empty()) {
    // A copy: PrepareAhead makes its grid while the filters run.
    measurement_params_ = filters_[0]->params();
    measurement_ = std::make_unique<filter::MeasurementGrid>(measurement_params_);
  }
}

void Pipeline::Start(const std::filesystem::path& network_dir,
                     const std::filesystem::path& work_dir) {
  if (source_->started()) throw std::logic_error("Pipeline::Start called twice");
  source_->Start({network_dir, work_dir});
}

void Pipeline::Finish() { source_->Finish(); }

const sim::SumoSimulation& Pipeline::simulation() const {
  if (!source_->sumo()) throw std::logic_error("Pipeline::simulation: this run has no SUMO");
  return *source_->sumo();
}

void Pipeline::UpdateFilter(std::size_t i) {
  // The grid is centred on ego + offset (filter.ahead / filter.left); the filter reads only the
  // position of EgoInput's pose, to place the grid.
  const radar::EgoMotion& ego_motion = current_.ego;
  const Pose2 pose = grid_frame_.ToGrid(ego_motion.pose);
  const Position centre = pose.position + centre_offset_;
  filter::DynamicGrid& grid = *filters_[i];
  if (realign_angle_ != 0.0) grid.Reframe(realign_angle_, centre);
  const filter::EgoInput ego{{centre, pose.yaw}, grid_frame_.VectorToGrid(ego_motion.velocity)};
  if (measurement_->SharesGeometry(grid.params())) {
    // Only this cycle's slot: a filter behind the others (after an error) draws its own, never
    // reading the slot that DrawNoise(true) may be writing.
    const filter::PredictionNoise& noise = noise_[grid.step() % 2];
    const bool shared = grid.step() == noise_cycle_ &&
                        noise.Holds(config_.sim.seed, grid.step(), grid.params().num_particles);
    grid.Update(ego, *measurement_, dt_, shared ? &noise : nullptr);  // built in Advance
  } else {
    grid.Update(ego, measurements_, coverage_, dt_);
  }
}

void Pipeline::DrawNoise(bool ahead) {
  if (filters_.empty()) return;
  // Every filter has the seed config_.sim.seed (MakeFilters) and they advance in lockstep. Ahead
  // reads no filter (they may be updating): the cycle after the one set without `ahead`.
  if (!ahead) noise_cycle_ = filters_[0]->step();
  const std::uint64_t cycle = noise_cycle_ + (ahead ? 1 : 0);
  const std::int64_t n = filters_[0]->params().num_particles;
  filter::PredictionNoise& slot = noise_[cycle % 2];
  if (!slot.Holds(config_.sim.seed, cycle, n)) slot.Draw(config_.sim.seed, cycle, n);
}

void Pipeline::FixFrame(const sim::Frame& f) {
  // GridYawAlong: a road along a world axis keeps an exactly world-aligned grid (SUMO's headings
  // carry ~1e-6 deg of rounding). The grid that follows the road starts along the ego's lane,
  // the one that stays fixed along its heading.
  using Frame = scenario::GridPlacement::Frame;
  const Frame frame = config_.grid.frame;
  grid_frame_ = GridFrame(frame == Frame::kWorld     ? 0.0
                          : frame == Frame::kHeading ? GridYawAlong(current_.ego.pose.yaw)
                                                     : GridYawAlong(f.ego.lane_yaw));
  centre_offset_ = config_.grid.CentreOffset(config_.filter.length_x, config_.filter.width_y);
}

bool Pipeline::ReadStep(DetectionSource& source, IdRegistry& ids, StepData* step) {
  if (!source.Advance(ids)) return false;
  source.Scan(ids, &step->detections, &step->scanned);
  step->frame = source.frame();
  step->ego = source.ego();
  step->labels = source.labels();
  step->reached_end = source.reached_end();
  return true;
}

bool Pipeline::NextStep() {
  using Read = Ahead::Read;
  switch (std::exchange(ahead_.read, Read::kNothing)) {
    case Read::kStep:
      std::swap(current_, ahead_.step);
      return true;
    case Read::kEnd:
      return false;
    case Read::kError:
      std::rethrow_exception(std::exchange(ahead_.error, nullptr));
    case Read::kNothing:
      break;
  }
  return ReadStep(*source_, ids_, &current_);
}

bool Pipeline::Advance() {
  if (!source_->started()) throw std::logic_error("Pipeline::Advance before Start");
  // Whatever happens below, a grid read ahead is for this step or never (PrepareAhead).
  const bool ahead_ready = std::exchange(ahead_.ready, false);
  if (!NextStep()) {
    current_.reached_end = source_->reached_end();
    return false;
  }
  ++advances_;
  const sim::Frame& f = current_.frame;
  // The first filter cycle (the ego may depart late) predicts over one step.
  dt_ = !first_step_ ? f.time - last_time_ : source_->first_dt();
  realign_angle_ = 0.0;
  if (first_step_) {
    FixFrame(f);
  } else if (const auto yaw = TurnedYaw(f)) {
    // The road has turned: the grid turns with it (the filters follow in UpdateFilter).
    realign_angle_ = WrapAngle(*yaw - grid_frame_.yaw());
    grid_frame_ = GridFrame(*yaw);
    ++realignments_;
  }
  first_step_ = false;
  last_time_ = f.time;

  if (filters_.empty()) return true;
  // The grid frame has already turned (above).
  const Position centre = FilterInputs(current_, radar(), grid_frame_, &measurements_, &coverage_);
  // The grid read ahead is taken only for the very same inputs, bit for bit: Build is a function
  // of them (and of the geometry, the same), so the filters see what Build would give here.
  if (ahead_ready && ahead_.advances == advances_ && SameBits(centre, ahead_.centre) &&
      SameInputs(measurements_, coverage_, ahead_.measurements, ahead_.coverage)) {
    std::swap(measurement_, ahead_.grid);
    ++ahead_hits_;
  } else {
    measurement_->Build(centre, measurements_, coverage_);
  }
  return true;
}

std::optional<double> Pipeline::TurnedYaw(const sim::Frame& f) const {
  if (config_.grid.frame != scenario::GridPlacement::Frame::kFollow) return std::nullopt;
  return RealignedYaw(grid_frame_.yaw(), f.ego.lane_yaw, DegToRad(config_.grid.realign_deg));
}

Position Pipeline::FilterInputs(const StepData& step, const radar::RadarModel& radar,
                                const GridFrame& g, std::vector<filter::Measurement>* measurements,
                                std::vector<filter::SensorCoverage>* coverage) const {
  measurements->clear();
  // Nothing but the ego can be inside the ego's own footprint: returns there (clutter drawn down
  // to the sensors' minimum range) would feed particles that ride along with the ego.
  const BoxTest ego_box(step.frame.ego.box);
  // The filter works in the grid frame.
  for (const radar::Detection& d : step.detections) {
    if (ego_box.Contains(d.position_world)) continue;
    measurements->push_back({g.ToGrid(d.position_world), g.VectorToGrid(d.radial_velocity_world),
                             g.ToGrid(d.sensor_position_world)});
  }
  coverage->clear();
  const Pose2& ego = step.ego.pose;
  for (int s : step.scanned) {
    const radar::SensorParams& p = radar.sensors()[s];
    const Pose2 pose = radar.SensorPose(s, ego);
    coverage->push_back(
        {g.ToGrid(pose.position), g.YawToGrid(pose.yaw), 0.5 * p.fov, p.min_range, p.max_range});
  }
  // Every filter's centre (UpdateFilter).
  return g.ToGrid(ego).position + centre_offset_;
}

void Pipeline::ReadAhead() noexcept {
  if (filters_.empty() || advances_ == 0 || !source_->can_run_ahead()) return;
  if (ahead_.read != Ahead::Read::kNothing) return;  // one step ahead at most
  ahead_.ready = false;
  try {
    if (!ReadStep(*source_, ids_, &ahead_.step)) {
      ahead_.read = Ahead::Read::kEnd;
      return;
    }
    ahead_.read = Ahead::Read::kStep;
    ahead_.advances = advances_ + 1;
    ++ahead_.read_steps;
  } catch (...) {
    // The run's own error, for the next Advance() to throw: what reading this step there throws.
    ahead_.error = std::current_exception();
    ahead_.read = Ahead::Read::kError;
  }
}

void Pipeline::PrepareAhead() noexcept {
  if (filters_.empty() || advances_ == 0 || ahead_.given_up) return;
  if (!source_->can_run_ahead()) {
    ReadTwinAhead();
    return;
  }
  ReadAhead();
  if (ahead_.read != Ahead::Read::kStep || ahead_.ready) return;  // nothing to build, or built
  try {
    BuildAhead(radar());
  } catch (...) {
    // Only the grid failed: Advance builds it itself and meets any error there.
    ahead_.ready = false;
  }
}

void Pipeline::ReadTwinAhead() noexcept {
  ahead_.ready = false;
  try {
    if (!ahead_.source) {
      ahead_.source = source_->Twin();
      if (!ahead_.source) {
        ahead_.given_up = true;
        return;
      }
    }
    // The twin reads the step after the last Advance() (it catches up if a call was skipped).
    while (ahead_.advances <= advances_) {
      if (!ReadStep(*ahead_.source, ahead_.ids, &ahead_.step)) {
        ahead_.given_up = true;  // the sequence ends: nothing left to read ahead
        return;
      }
      ++ahead_.advances;
    }
    BuildAhead(ahead_.source->radar());
  } catch (...) {
    // Only speculation failed: Advance builds the step's grid itself and reports any error of
    // the data at its own step. The twin's state is unknown now, so it is not used again.
    ahead_.given_up = true;
    ahead_.source.reset();
  }
}

void Pipeline::BuildAhead(const radar::RadarModel& radar) {
  if (!ahead_.grid) ahead_.grid = std::make_unique<filter::MeasurementGrid>(measurement_params_);
  const std::optional<double> yaw = TurnedYaw(ahead_.step.frame);
  const GridFrame g = yaw ? GridFrame(*yaw) : grid_frame_;
  ahead_.centre = FilterInputs(ahead_.step, radar, g, &ahead_.measurements, &ahead_.coverage);
  ahead_.grid->Build(ahead_.centre, ahead_.measurements, ahead_.coverage);
  ahead_.ready = true;
  ++ahead_.prepared;
}

OrientedBox Pipeline::GridFootprint() const {
  const double length = config_.filter.length_x, width = config_.filter.width_y;
  Position centre = grid_frame_.ToGrid(current_.ego.pose.position) + centre_offset_;
  if (!filters_.empty() && filters_[0]->initialized()) {
    const filter::DynamicGrid& g = *filters_[0];
    const auto [gx, gy] = g.origin_index();
    centre = {(static_cast<double>(gx) + 0.5 * g.cells_x()) * g.resolution(),
              (static_cast<double>(gy) + 0.5 * g.cells_y()) * g.resolution()};
  }
  return {grid_frame_.ToWorld(centre), grid_frame_.yaw(), length, width};
}

std::vector<eval::TruthObject> Pipeline::TruthObjects(const filter::DynamicGrid& grid) const {
  std::vector<eval::TruthObject> out;
  const auto poses = radar().SensorPoses(current_.ego.pose);
  // Sources of this step's detections inside the grid: the t_d clock starts at a vehicle's first.
  std::vector<int> detected;
  const GridFrame& g = grid_frame_;
  for (const radar::Detection& d : current_.detections)
    if (grid.CellOf(g.ToGrid(d.position_world))) detected.push_back(d.source_id);
  std::sort(detected.begin(), detected.end());
  for (const sim::VehicleState& v : frame().vehicles) {
    eval::TruthObject o;
    // Registered by BuildScene this step: a look-up (this runs inside the modes' tasks).
    o.id = *ids_.Find(v.id);
    o.detected_in_grid = std::binary_search(detected.begin(), detected.end(), o.id);
    o.box = g.ToGrid(v.box);
    o.velocity = g.VectorToGrid(v.velocity);
    o.in_grid = grid.CellOf(o.box.center).has_value();
    for (std::size_t s = 0; s < poses.size() && !o.in_coverage; ++s) {
      const radar::SensorParams& p = radar().sensors()[s];
      const Position local = poses[s].ToLocal(v.box.center);
      const double r = local.norm();
      o.in_coverage = r >= p.min_range && r <= p.max_range &&
                      std::abs(std::atan2(local.y(), local.x())) <= 0.5 * p.fov;
    }
    out.push_back(o);
  }
  return out;
}

}  // namespace dualgrid::cosim
