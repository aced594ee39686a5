// Python bindings of the filter: FilterParams (every field a property, units in the docstrings),
// the named presets and DynamicGrid with numpy inputs and outputs (docs/python.md).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "dualgrid/core/limits.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/filter/params.hpp"
#include "grid_holder.hpp"
#include "value_class.hpp"

namespace dualgrid::python {
namespace {

using filter::DynamicGrid;
using filter::FilterParams;

// Columns of DynamicGrid.update's table arguments, in array order (filter::Measurement and
// filter::SensorCoverage).
const std::vector<ColumnSpec> kMeasurementColumns = {{"x"},    {"y"},        {"v_rx"},
                                                     {"v_ry"}, {"sensor_x"}, {"sensor_y"}};
const std::vector<ColumnSpec> kCoverageColumns = {{"origin_x"}, {"origin_y"},  {"boresight"},
                                                  {"half_fov"}, {"min_range"}, {"max_range"}};

// Binds an enum field as a string property: the names of filter/params.hpp's ToString, parsed
// back with its Parse* function (ValueError listing the accepted names).
template <typename E>
void EnumField(py::class_<FilterParams>& cls, const FieldNames& names, const char* name,
               E FilterParams::*member, std::optional<E> (*parse)(std::string_view),
               std::vector<E> values, const std::string& doc) {
  std::string accepted;
  for (E v : values) accepted += (accepted.empty() ? "" : ", ") + std::string(filter::ToString(v));
  cls.def_property(
      name, [member](const FilterParams& p) { return std::string(filter::ToString(p.*member)); },
      [member, parse, name, accepted](FilterParams& p, const std::string& s) {
        const std::optional<E> v = parse(s);
        if (!v)
          throw py::value_error(std::string(name) + ": unknown value '" + s + "' (" + accepted +
                                ")");
        p.*member = *v;
      },
      (doc + " One of: " + accepted + ".").c_str());
  names->push_back(name);
}

void BindFilterParams(py::module_& m) {
  py::class_<FilterParams> cls(m, "FilterParams", R"doc(
All tuning of DynamicGrid (filter/include/dualgrid/filter/params.hpp; docs/algorithm.md maps each
field to the paper). Defaults: the paper's configuration (200 m x 25 m at 0.5 m, 10,000
particles) with the "dualgrid" switches; per-cycle factors assume a 0.05 s cycle.

FilterParams(**fields) starts from the defaults and sets the given fields. Setting a field does
not check it: is_valid() / validate() do (DynamicGrid's constructor calls validate()).
Enum-like fields are strings.)doc");
  auto names = std::make_shared<std::vector<std::string>>();
  // Grid.
  Field(cls, names, "length_x", &FilterParams::length_x,
        "Grid extent along x [m] (axis-aligned with the frame the inputs are given in).");
  Field(cls, names, "width_y", &FilterParams::width_y, "Grid extent along y [m].");
  Field(cls, names, "resolution", &FilterParams::resolution, "Cell edge [m].");
  // Particles.
  Field(cls, names, "num_particles", &FilterParams::num_particles,
        "Persistent particles, constant after resampling [count].");
  Field(cls, names, "num_birth", &FilterParams::num_birth, "New-born particles per cycle [count].");
  Field(cls, names, "process_noise_position", &FilterParams::process_noise_position,
        "Position random walk [m/sqrt(s)].");
  Field(cls, names, "process_noise_velocity", &FilterParams::process_noise_velocity,
        "Velocity random walk [m/s/sqrt(s)].");
  Field(cls, names, "persistence", &FilterParams::persistence,
        "p_S: particle weights are multiplied by this per cycle [probability].");
  Field(cls, names, "birth_probability", &FilterParams::birth_probability,
        "p_B: weight of the birth hypothesis against persistence [probability].");
  Field(cls, names, "birth_max_tangential_speed", &FilterParams::birth_max_tangential_speed,
        "Tangential birth speed ~ U(-v, v) [m/s].");
  Field(cls, names, "max_speed", &FilterParams::max_speed,
        "Fastest plausible object over ground [m/s]: no birth from a detection whose compensated "
        "radial speed exceeds it, and births never exceed it.");
  Field(cls, names, "birth_sigma_radial", &FilterParams::birth_sigma_radial,
        "Radial birth speed noise around the Doppler [m/s].");
  Field(cls, names, "doppler_fit_radius", &FilterParams::doppler_fit_radius,
        "doppler_fit / radial_fit: detections within this radius share one velocity [m].");
  Field(cls, names, "doppler_fit_sigma", &FilterParams::doppler_fit_sigma,
        "doppler_fit / radial_fit: noise floor of a detection's radial speed in the fit [m/s].");
  Field(cls, names, "birth_fit_uniform_share", &FilterParams::birth_fit_uniform_share,
        "birth_velocity 'doppler_fit': share of births kept uniform tangentially [probability].");
  // Measurement kernels.
  Field(cls, names, "sigma_f", &FilterParams::sigma_f, "Width of f_d, eq. (2) [m].");
  Field(cls, names, "sigma_static_distance", &FilterParams::sigma_static_distance,
        "Sigma_s distance std, eq. (4) [m].");
  Field(cls, names, "sigma_static_velocity", &FilterParams::sigma_static_velocity,
        "Sigma_s radial-velocity std, eq. (4) [m/s].");
  Field(cls, names, "sigma_v", &FilterParams::sigma_v, "Sigma_v of f_v, eq. (8) [m/s].");
  Field(cls, names, "cutoff_sigmas", &FilterParams::cutoff_sigmas,
        "Detections farther than this many sigma_f count as no detection [1].");
  Field(cls, names, "occupied_mass", &FilterParams::occupied_mass,
        "Peak occupied mass of one detection in the measurement grid [probability].");
  Field(cls, names, "free_mass", &FilterParams::free_mass,
        "Free mass along a ray in front of a detection, eq. (3) [probability].");
  Field(cls, names, "free_mass_no_return", &FilterParams::free_mass_no_return,
        "Free mass in a bearing bin without detection [probability].");
  Field(cls, names, "free_angle_bin", &FilterParams::free_angle_bin,
        "Bearing bin of the ray free space [rad].");
  Field(cls, names, "free_bin_dilation", &FilterParams::free_bin_dilation,
        "A detection shadows this many neighbouring bearing bins on each side [count].");
  // Temporal fusion.
  Field(cls, names, "free_decay", &FilterParams::free_decay,
        "Free mass kept per cycle [fraction].");
  Field(cls, names, "static_persistence", &FilterParams::static_persistence,
        "Static mass kept per cycle [fraction].");
  Field(cls, names, "static_gain", &FilterParams::static_gain,
        "eta: weight of this cycle's P_static (eq. 4) in q_norm [1].");
  Field(cls, names, "static_speed", &FilterParams::static_speed,
        "Particles slower than this vote static [m/s].");
  Field(cls, names, "decay_eps", &FilterParams::decay_eps, "eps of eqs. (7), (8) [1].");
  Field(cls, names, "cycle", &FilterParams::cycle,
        "Cycle the per-cycle factors refer to; other dt scale them (ForCycle) [s].");
  EnumField(
      cls, names, "mode", &FilterParams::mode, &filter::ParseWeightMode,
      {filter::WeightMode::kPosition, filter::WeightMode::kVelocity, filter::WeightMode::kDual},
      "Weight that drives resampling: eq. (7), eq. (8) or both (eq. 14).");
  EnumField(cls, names, "birth_velocity", &FilterParams::birth_velocity,
            &filter::ParseBirthVelocity,
            {filter::BirthVelocity::kDoppler, filter::BirthVelocity::kUniform,
             filter::BirthVelocity::kDopplerFit},
            "Velocity of new-born particles (switch; docs/algorithm.md).");
  EnumField(cls, names, "zero_likelihood", &FilterParams::zero_likelihood,
            &filter::ParseZeroLikelihood,
            {filter::ZeroLikelihood::kKeepPrediction, filter::ZeroLikelihood::kLiteral},
            "Eq. (7) in an observed cell where every hypothesis scores 0 (switch).");
  EnumField(cls, names, "velocity_likelihood", &FilterParams::velocity_likelihood,
            &filter::ParseVelocityLikelihood,
            {filter::VelocityLikelihood::kVector, filter::VelocityLikelihood::kRadial,
             filter::VelocityLikelihood::kRadialFit},
            "f_v of eq. (8): the full vector, only the line-of-sight component, or that and the "
            "tangential part of a fit to neighbouring Dopplers (switch).");
  EnumField(cls, names, "normalisation", &FilterParams::normalisation, &filter::ParseNormalisation,
            {filter::Normalisation::kPerCell, filter::Normalisation::kLiteral},
            "Joint normalisation of eqs. (9)-(12) (switch).");
  AddValueProtocol(cls, names, "FilterParams");

  cls.def_property_readonly("cells_x", &FilterParams::CellsX,
                            "Cells along x (length_x / resolution rounded, >= 1).");
  cls.def_property_readonly("cells_y", &FilterParams::CellsY,
                            "Cells along y (width_y / resolution rounded, >= 1).");
  cls.def("memory_bytes", &FilterParams::MemoryBytes,
          "Heap memory of one DynamicGrid with these parameters after its first update() [bytes] "
          "(within a few percent).");
  cls.def(
      "is_valid", [](const FilterParams& p) { return p.IsValid(nullptr); },
      "True when every field is usable.");
  cls.def(
      "validate",
      [](const FilterParams& p) {
        std::string error;
        if (!p.IsValid(&error)) throw py::value_error("FilterParams: " + error);
      },
      "Raises ValueError naming the first unusable field; returns None otherwise.");

  m.def(
      "preset",
      [](const std::string& name) {
        const std::optional<FilterParams> p = filter::Preset(name);
        if (!p)
          throw py::value_error("preset: unknown name '" + name + "' (" +
                                std::string(filter::PresetNames()) + ")");
        return *p;
      },
      py::arg("name"), R"doc(
Named parameter set: "paper" (every switch at its literal reading of the paper: birth_velocity
uniform, zero_likelihood literal, velocity_likelihood vector, normalisation literal), "dualgrid"
(the project's recommendation) or "default" (the struct defaults, currently equal to
"dualgrid"). Only the switches differ. ValueError for another name.)doc");
  m.def(
      "preset_names",
      []() {
        std::vector<std::string> out;
        std::string_view s = filter::PresetNames();
        while (!s.empty()) {
          const std::size_t comma = s.find(',');
          out.emplace_back(s.substr(0, comma));
          s = comma == std::string_view::npos ? std::string_view() : s.substr(comma + 1);
          while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
        }
        return out;
      },
      "Names preset() accepts.");
}

void Update(Grid& g, PoseArg ego_pose, Vector2Arg ego_velocity, TableArg detections,
            TableArg coverage, double dt) {
  // All conversion (and its errors) with the GIL held, before the grid changes.
  if (!std::isfinite(dt) || dt < 0.0)
    throw py::value_error("dt: expected a finite cycle length >= 0 [s], got " + std::to_string(dt));
  const filter::EgoInput ego{ReadPose(ego_pose, "ego_pose"),
                             ReadVector2(ego_velocity, "ego_velocity", "[m/s]")};
  const Table z = ReadTable(detections, "detections", kMeasurementColumns);
  std::vector<filter::Measurement> measurements(z.rows);
  for (std::size_t i = 0; i < z.rows; ++i)
    measurements[i] = {
        {z.at(i, 0), z.at(i, 1)}, {z.at(i, 2), z.at(i, 3)}, {z.at(i, 4), z.at(i, 5)}};
  const Table c = ReadTable(coverage, "coverage", kCoverageColumns);
  std::vector<filter::SensorCoverage> cov(c.rows);
  for (std::size_t i = 0; i < c.rows; ++i) {
    cov[i] = {{c.at(i, 0), c.at(i, 1)}, c.at(i, 2), c.at(i, 3), c.at(i, 4), c.at(i, 5)};
    // As the filter (MeasurementGrid::Build) and a sensor's fov (0, 2 pi]: at most a full circle.
    if (!(cov[i].half_fov >= 0.0 && cov[i].half_fov <= kPi) || cov[i].min_range < 0.0 ||
        cov[i].max_range < cov[i].min_range)
      throw py::value_error("coverage: row " + std::to_string(i) +
                            " (half_fov = " + FormatShort(cov[i].half_fov) +
                            ", min_range = " + FormatShort(cov[i].min_range) +
                            ", max_range = " + FormatShort(cov[i].max_range) +
                            ") needs 0 <= half_fov <= pi [rad] (a field of view of at most 360 "
                            "deg) and 0 <= min_range <= max_range [m]");
  }
  Locked(g, [&](DynamicGrid& grid) {
    ApplyThreadCount();
    grid.Update(ego, measurements, cov, dt);
  });
}

py::dict Masses(Grid& g) {
  const int nx = g.grid.cells_x(), ny = g.grid.cells_y();
  const std::size_t n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  py::array_t<float> free({ny, nx}), stat({ny, nx}), dyn({ny, nx}), unknown({ny, nx});
  py::array_t<bool> observed({ny, nx});
  float *pf = free.mutable_data(), *ps = stat.mutable_data(), *pd = dyn.mutable_data(),
        *pu = unknown.mutable_data();
  // numpy's bool is one byte holding 0 or 1: the bytes ExportMasses writes.
  auto* po = reinterpret_cast<std::uint8_t*>(observed.mutable_data());
  Locked(g, [&](const DynamicGrid& grid) {
    grid.ExportMasses({pf, n}, {ps, n}, {pd, n}, {po, n});
  });
  for (std::size_t i = 0; i < n; ++i) pu[i] = std::max(0.0f, 1.0f - pf[i] - ps[i] - pd[i]);
  py::dict d;
  d["free"] = free;
  d["static"] = stat;
  d["dynamic"] = dyn;
  d["unknown"] = unknown;
  d["observed"] = observed;
  return d;
}

// Mean velocity [m/s] (and covariance) of every cell via Cell(): (cells_y, cells_x, 2[, 2]).
py::array_t<double> VelocityMoments(Grid& g, bool covariance) {
  const int nx = g.grid.cells_x(), ny = g.grid.cells_y();
  py::array_t<double> out =
      covariance ? py::array_t<double>({ny, nx, 2, 2}) : py::array_t<double>({ny, nx, 2});
  double* p = out.mutable_data();
  Locked(g, [&](const DynamicGrid& grid) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        const filter::CellState s = grid.Cell({x, y});
        if (covariance) {
          // Row-major [[xx, xy], [yx, yy]].
          *p++ = s.velocity_cov(0, 0);
          *p++ = s.velocity_cov(0, 1);
          *p++ = s.velocity_cov(1, 0);
          *p++ = s.velocity_cov(1, 1);
        } else {
          *p++ = s.mean_velocity.x();
          *p++ = s.mean_velocity.y();
        }
      }
    }
  });
  return out;
}

// The first n particles of a set (copied under the lock, then into numpy with the GIL).
py::dict ParticlesDict(Grid& g, bool weighted) {
  filter::ParticleSet copy;
  Locked(g, [&](const DynamicGrid& grid) {
    const filter::ParticleSet& src = weighted ? grid.weighted_particles() : grid.particles();
    const std::size_t n = weighted ? grid.num_weighted_particles() : src.size();
    copy.x.assign(src.x.begin(), src.x.begin() + n);
    copy.y.assign(src.y.begin(), src.y.begin() + n);
    copy.vx.assign(src.vx.begin(), src.vx.begin() + n);
    copy.vy.assign(src.vy.begin(), src.vy.begin() + n);
    copy.w_position.assign(src.w_position.begin(), src.w_position.begin() + n);
    copy.w_velocity.assign(src.w_velocity.begin(), src.w_velocity.begin() + n);
    copy.weight.assign(src.weight.begin(), src.weight.begin() + n);
  });
  py::dict d;
  d["x"] = ToArray(copy.x);
  d["y"] = ToArray(copy.y);
  d["vx"] = ToArray(copy.vx);
  d["vy"] = ToArray(copy.vy);
  d["w_position"] = ToArray(copy.w_position);
  d["w_velocity"] = ToArray(copy.w_velocity);
  d["weight"] = ToArray(copy.weight);
  return d;
}

void CheckIndex(const DynamicGrid& grid, int ix, int iy) {
  if (ix < 0 || iy < 0 || ix >= grid.cells_x() || iy >= grid.cells_y())
    throw py::index_error("cell (" + std::to_string(ix) + ", " + std::to_string(iy) +
                          ") outside the grid of " + std::to_string(grid.cells_x()) + " x " +
                          std::to_string(grid.cells_y()) + " cells");
}

// ValueError when one grid of `params` would need more than the share of this machine's memory
// the command line allows (kMaxMemoryShare), before anything is allocated: the kernel's
// out-of-memory killer would otherwise end the interpreter.
void CheckGridMemory(const FilterParams& params) {
  const double need = params.MemoryBytes(), have = PhysicalMemoryBytes();
  if (have <= 0 || need <= kMaxMemoryShare * have) return;
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "DynamicGrid: FilterParams num_particles = %d, num_birth = %d and %d x %d cells "
                "would need %.1f GB, more than %.0f %% of this machine's %.1f GB",
                params.num_particles, params.num_birth, params.CellsX(), params.CellsY(),
                need / 1e9, 100.0 * kMaxMemoryShare, have / 1e9);
  throw py::value_error(buf);
}

void BindDynamicGrid(py::module_& m) {
  py::class_<Grid> cls(m, "DynamicGrid", R"doc(
Radar-only dynamic occupancy grid with position, velocity and dual particle weights
(filter/include/dualgrid/filter/dynamic_grid.hpp). All positions and velocities are in one
Cartesian frame of your choice (the "grid frame", e.g. the world frame): the grid is axis-aligned
in it and centred on the ego position given to update(). Cell (ix, iy): ix along +x, iy along +y;
2-D arrays are indexed [iy, ix].

Results are deterministic in (params, seed, inputs) whatever the thread count. Every method
returns copies (no views into the grid). Calls from several Python threads on one grid are
serialised; update() releases the GIL.)doc");
  cls.def(py::init([](const FilterParams& params, Seed seed) {
            std::string error;
            if (!params.IsValid(&error)) throw py::value_error("FilterParams: " + error);
            CheckGridMemory(params);
            return std::make_unique<Grid>(params, seed.value);
          }),
          py::arg("params") = FilterParams(), py::arg("seed") = 0,
          "ValueError when params is not valid (see FilterParams.validate()).");
  cls.def("update", &Update, py::arg("ego_pose"),
          py::arg("ego_velocity") = py::make_tuple(0.0, 0.0), py::arg("detections") = py::none(),
          py::arg("coverage") = py::none(), py::kw_only(), py::arg("dt"), R"doc(
One filter cycle; the first call initialises the grid around the ego.

ego_pose: (x, y, yaw) [m, m, rad]; the grid is centred on (x, y) (yaw is not used by the filter).
ego_velocity: (vx, vy) [m/s].
detections: the paper's eq. (1) measurement plus the sensor position, one row per detection:
  a float array (N, 6) with columns [x, y, v_rx, v_ry, sensor_x, sensor_y]
  (position [m]; ego-motion-compensated radial speed over ground times the line-of-sight unit
  vector [m/s]; position of the detecting sensor [m]), or a dict of columns / DataFrame /
  structured array with those names (so RadarModel.scan()'s result can be passed as is), or a
  list of dicts. None: no detection.
coverage: the fields of view of the sensors that scanned this cycle, a float array (M, 6) with
  columns [origin_x, origin_y, boresight, half_fov, min_range, max_range] ([m, m, rad, rad, m, m];
  RadarModel.coverage() builds it) or the same as named columns. None: nothing observed.
dt: time since the previous cycle [s], >= 0 (keyword only).
ValueError (naming the argument) for a bad shape, a missing column or a non-finite value.)doc");
  cls.def(
      "reframe",
      [](Grid& g, double angle, Vector2Arg ego_position) {
        const Vector2 ego = ReadVector2(ego_position, "ego_position", "[m]");
        if (!std::isfinite(angle))
          throw py::value_error("angle: expected a finite angle [rad], got " +
                                std::to_string(angle));
        Locked(g, [&](DynamicGrid& grid) {
          ApplyThreadCount();
          grid.Reframe(angle, ego);
        });
      },
      py::arg("angle"), py::arg("ego_position"), R"doc(
Turns your frame by `angle` [rad] (counter-clockwise, about its origin) between two updates, for
a grid that follows the ego's heading: the particles are turned exactly, the grid re-centred on
`ego_position` (x, y) [m] given in the turned frame (as the next update() will give it), and each
new cell takes the masses of the old cell under its centre. Give every later input in the turned
frame. No-op before the first update. (DynamicGrid::Reframe; docs/algorithm.md, "Grid frame".))doc");
  cls.def("masses", &Masses, R"doc(
Cell masses after the last update as (cells_y, cells_x) arrays: "free", "static", "dynamic"
(float32 [probability], DynamicGrid::ExportMasses), "unknown" (float32, 1 - free - static -
dynamic clipped at 0) and "observed" (bool: inside a sensor's field of view this cycle).)doc");
  cls.def(
      "mean_velocities", [](Grid& g) { return VelocityMoments(g, false); },
      "Weighted mean velocity [m/s] of each cell's moving particles after the weight update, "
      "(cells_y, cells_x, 2) float64 [..., (vx, vy)]; 0 where a cell has none.");
  cls.def(
      "velocity_covariances", [](Grid& g) { return VelocityMoments(g, true); },
      "Weighted velocity covariance [(m/s)^2] of each cell's moving particles, "
      "(cells_y, cells_x, 2, 2) float64; 0 where a cell has none.");
  cls.def(
      "cell",
      [](Grid& g, int ix, int iy) {
        CheckIndex(g.grid, ix, iy);
        const filter::CellState s = Locked(g, [&](const DynamicGrid& grid) {
          return grid.Cell({ix, iy});
        });
        py::dict d;
        d["free"] = s.free;
        d["static"] = s.static_occ;
        d["dynamic"] = s.dynamic;
        d["unknown"] = s.unknown;
        d["mean_velocity"] = py::make_tuple(s.mean_velocity.x(), s.mean_velocity.y());
        d["velocity_cov"] =
            py::make_tuple(py::make_tuple(s.velocity_cov(0, 0), s.velocity_cov(0, 1)),
                           py::make_tuple(s.velocity_cov(1, 0), s.velocity_cov(1, 1)));
        d["observed"] = s.observed;
        return d;
      },
      py::arg("ix"), py::arg("iy"),
      "One cell's state (double precision): free, static, dynamic, unknown [probability], "
      "mean_velocity (vx, vy) [m/s], velocity_cov [(m/s)^2], observed. IndexError outside.");
  cls.def(
      "particles", [](Grid& g) { return ParticlesDict(g, false); }, R"doc(
Particles after the last resampling (num_particles of them), a dict of 1-D arrays: x, y [m]
(float64), vx, vy [m/s], w_position, w_velocity, weight [dynamic mass] (float32). After
resampling all `weight`s are equal (total dynamic mass / count).)doc");
  cls.def(
      "weighted_particles", [](Grid& g) { return ParticlesDict(g, true); }, R"doc(
Persistent particles after the last weight update, before birth and resampling, sorted by cell
(num_weighted_particles() of them), same keys as particles(): `weight` is the mode's weight
normalised so that each cell's weights sum to its dynamic mass. The set the paper clusters.)doc");
  cls.def(
      "num_weighted_particles",
      [](Grid& g) {
        return Locked(g, [](const DynamicGrid& grid) { return grid.num_weighted_particles(); });
      },
      "Number of entries weighted_particles() returns.");
  cls.def(
      "cell_center",
      [](Grid& g, int ix, int iy) -> std::optional<std::pair<double, double>> {
        CheckIndex(g.grid, ix, iy);
        const std::optional<Position> c =
            Locked(g, [&](const DynamicGrid& grid) -> std::optional<Position> {
              if (!grid.initialized()) return std::nullopt;
              return grid.CellCenter({ix, iy});
            });
        if (!c) return std::nullopt;
        return std::make_pair(c->x(), c->y());
      },
      py::arg("ix"), py::arg("iy"),
      "Centre (x, y) [m] of cell (ix, iy); IndexError outside the grid, None before the first "
      "update (the grid has no position yet).");
  cls.def(
      "cell_of",
      [](Grid& g, double x, double y) {
        return Locked(g, [&](const DynamicGrid& grid) -> std::optional<std::pair<int, int>> {
          const auto c = grid.CellOf({x, y});
          if (!c) return std::nullopt;
          return std::make_pair(c->x, c->y);
        });
      },
      py::arg("x"), py::arg("y"),
      "Cell (ix, iy) holding point (x, y) [m]; None outside the grid or before the first update.");
  cls.def_property_readonly(
      "extent",
      [](Grid& g) -> py::object {
        const auto o = Locked(g, [](const DynamicGrid& grid) {
          return grid.initialized() ? std::optional(grid.origin_index()) : std::nullopt;
        });
        if (!o) return py::none();
        const double r = g.grid.resolution();
        return py::make_tuple(
            static_cast<double>((*o)[0]) * r, static_cast<double>((*o)[0] + g.grid.cells_x()) * r,
            static_cast<double>((*o)[1]) * r, static_cast<double>((*o)[1] + g.grid.cells_y()) * r);
      },
      "(x_min, x_max, y_min, y_max) [m] of the grid's outer edges (matplotlib's imshow extent "
      "with origin='lower'); None before the first update.");
  cls.def_property_readonly(
      "cells_x", [](Grid& g) { return g.grid.cells_x(); }, "Cells along x.");
  cls.def_property_readonly(
      "cells_y", [](Grid& g) { return g.grid.cells_y(); }, "Cells along y.");
  cls.def_property_readonly(
      "resolution", [](Grid& g) { return g.grid.resolution(); }, "Cell edge [m].");
  cls.def_property_readonly(
      "step", [](Grid& g) { return Locked(g, [](const DynamicGrid& d) { return d.step(); }); },
      "Number of completed update() calls.");
  cls.def_property_readonly(
      "initialized",
      [](Grid& g) { return Locked(g, [](const DynamicGrid& d) { return d.initialized(); }); },
      "True after the first update().");
  cls.def_property_readonly(
      "params", [](Grid& g) { return g.grid.params(); }, "A copy of the grid's FilterParams.");
  cls.def(
      "check_invariants",
      [](Grid& g) { return Locked(g, [](const DynamicGrid& d) { return d.CheckInvariants(); }); },
      "Description of the first violated invariant (finite masses in [0, 1] summing to <= 1, "
      "num_particles finite particles with weights >= 0 and no mass created), None if all hold.");
  cls.def("__repr__", [](Grid& g) {
    return "DynamicGrid(" + std::to_string(g.grid.cells_x()) + " x " +
           std::to_string(g.grid.cells_y()) + " cells of " + std::to_string(g.grid.resolution()) +
           " m, " + std::to_string(g.grid.params().num_particles) + " particles, mode " +
           std::string(filter::ToString(g.grid.params().mode)) + ")";
  });
}

}  // namespace

void BindFilter(py::module_& m) {
  BindFilterParams(m);
  BindDynamicGrid(m);
}

}  // namespace dualgrid::python
