// Parameters of the radar-only dynamic grid (docs/algorithm.md maps each to the paper).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace dualgrid::filter {

/// Which particle weight drives resampling (paper Sec. III-C / IV).
enum class WeightMode {
  kPosition,  ///< eq. (7): w = f_d(d_p) (1 - eps) w_prev.
  kVelocity,  ///< eq. (8), blended form (see docs/algorithm.md).
  kDual,      ///< eq. (14): both weights kept, resampled on max(w_position, w_velocity).
};

/// "position", "velocity", "dual".
std::string_view ToString(WeightMode mode);
/// Inverse of ToString; std::nullopt for unknown names.
std::optional<WeightMode> ParseWeightMode(std::string_view name);

// Switches for the places where the paper is silent or where this filter departs from it. Each is
// documented beside the paper's equation in docs/algorithm.md ("Switches"); the `paper` preset sets
// every one to its literal reading.

/// Velocity of new-born particles (step 7; the paper gives no birth model).
enum class BirthVelocity {
  kDoppler,  ///< radial part from the detection's Doppler, tangential part uniform.
  kUniform,  ///< uniform in the disc |v| <= max_speed: no Doppler reaches position mode at all.
  /// Radial part from the detection's Doppler; tangential part from a robust least-squares fit
  /// of one velocity to the Doppler of every detection within doppler_fit_radius (all sensors)
  /// where the fit determines it better than the uniform draw, else uniform (docs/algorithm.md).
  kDopplerFit,
};
/// Eq. (7) in an observed cell where every hypothesis scores 0 (no detection near any of them).
enum class ZeroLikelihood {
  kKeepPrediction,  ///< the measurement cannot arbitrate: keep the predicted static/dynamic split.
  kLiteral,         ///< eq. (7) as printed: all weights 0, the occupied mass becomes unknown.
};
/// f_v of eq. (8).
enum class VelocityLikelihood {
  kVector,  ///< the paper: N(v_p; mu_v = (v_rx, v_ry), sigma_v^2 I) on the full velocity vector.
  kRadial,  ///< N(v_p . u; v_r, sigma_v^2): only the particle's line-of-sight component, the part
            ///< a Doppler measures (u: unit line of sight, v_r: compensated radial speed).
  /// kRadial times N(v_p . t; v_t, sigma_v^2 + s_t^2) along the detection's tangent t, where a
  /// robust fit of one velocity to the Doppler of the detections within doppler_fit_radius (all
  /// sensors) gives its tangential part v_t with standard deviation s_t (docs/algorithm.md).
  /// Where the lines of sight do not spread, s_t is large and this is kRadial.
  kRadialFit,
};
/// The joint normalisation of eqs. (9)-(12).
enum class Normalisation {
  kPerCell,  ///< Nuss random-finite-set form: Dempster on free/occupied, then the occupied mass
             ///< split by the hypotheses' likelihoods; particle weights sum to the dynamic mass.
  kLiteral,  ///< q_norm = P_free + P_static + sum_k w_k with the particles' own (accumulated,
             ///< unnormalised) weights, as printed; no unknown mass where it applies.
};

std::string_view ToString(BirthVelocity v);
std::string_view ToString(ZeroLikelihood v);
std::string_view ToString(VelocityLikelihood v);
std::string_view ToString(Normalisation v);
/// Inverses of ToString; std::nullopt for unknown names.
std::optional<BirthVelocity> ParseBirthVelocity(std::string_view name);
std::optional<ZeroLikelihood> ParseZeroLikelihood(std::string_view name);
std::optional<VelocityLikelihood> ParseVelocityLikelihood(std::string_view name);
std::optional<Normalisation> ParseNormalisation(std::string_view name);

/// All tuning of DynamicGrid. Defaults: the paper's configuration (200 m x 25 m at 0.5 m, 10,000
/// particles) and a nominal cycle of 0.05 s; per-cycle factors assume that cycle.
struct FilterParams {
  // Grid, axis-aligned with the filter's frame (the caller's; in dualgrid the grid frame,
  // docs/algorithm.md) and centred on EgoInput's position.
  double length_x = 200.0;  ///< Extent along the frame's x [m].
  double width_y = 25.0;    ///< Extent along the frame's y [m].
  double resolution = 0.5;  ///< Cell edge [m].

  // Particles.
  int num_particles = 10000;            ///< Persistent particles, constant after resampling.
  int num_birth = 1000;                 ///< New-born particles per cycle (10 %).
  double process_noise_position = 0.3;  ///< Position random walk [m/sqrt(s)].
  double process_noise_velocity = 1.5;  ///< Velocity random walk [m/s/sqrt(s)].
  double persistence = 0.99;            ///< p_S: particle weights times this per cycle.
  double birth_probability = 0.1;       ///< p_B: weight of the birth hypothesis vs persistence.
  double birth_max_tangential_speed = 40.0;  ///< Tangential birth speed ~ U(-v, v) [m/s].
  /// Fastest plausible object over ground [m/s] (180 km/h): no birth from a detection whose
  /// compensated radial speed exceeds it (clutter), and births never exceed it.
  double max_speed = 50.0;
  double birth_sigma_radial = 0.5;  ///< Radial birth speed noise around Doppler [m/s].
  // birth_velocity: doppler_fit and velocity_likelihood: radial_fit. The detections of one object
  // within this radius [m] (about a car's length across) share one velocity; their Doppler along
  // different lines of sight fits it.
  double doppler_fit_radius = 3.0;
  /// Noise floor of a detection's compensated radial speed in the fit [m/s]: the radars' range
  /// rate accuracy (0.10-0.12 m/s, docs/radar.md); the fit's own residual scale when larger.
  double doppler_fit_sigma = 0.1;
  /// Share of births that keep the uniform tangential draw where a fit exists (a defensive
  /// mixture: a fit biased by another object's detections must not remove the truth).
  double birth_fit_uniform_share = 0.25;

  // Measurement kernels (all scaled to peak 1, see docs/algorithm.md).
  double sigma_f = 0.6;                ///< f_d width, eq. (2) [m].
  double sigma_static_distance = 0.6;  ///< Sigma_s distance std, eq. (4) [m].
  double sigma_static_velocity = 0.5;  ///< Sigma_s radial-velocity std, eq. (4) [m/s].
  double sigma_v = 1.0;                ///< Sigma_v of f_v, eq. (8) [m/s] (isotropic).
  double cutoff_sigmas = 3.0;  ///< Detections farther than this many sigma_f are "no detection".
  double occupied_mass = 0.9;  ///< Peak occupied mass of one detection in the measurement grid.
  double free_mass = 0.7;      ///< Free mass along a ray in front of a detection, eq. (3).
  double free_mass_no_return = 0.3;   ///< Free mass in a bearing bin with no detection.
  double free_angle_bin = 0.0174533;  ///< Bearing bin for ray free space [rad] (1 deg).
  int free_bin_dilation = 1;  ///< A detection shadows this many neighbouring bins each side.

  // Temporal fusion and joint normalisation.
  double free_decay = 0.9;           ///< Free mass kept per cycle.
  double static_persistence = 0.98;  ///< Static mass kept per cycle.
  double static_gain = 0.3;          ///< eta: weight of this cycle's P_static (eq. 4) in q_norm.
  double static_speed = 1.0;         ///< Particles slower than this [m/s] vote static (v = 0).

  // Particle weights.
  double decay_eps = 0.05;  ///< eps of eqs. (7), (8).
  /// The cycle [s] that every per-cycle factor above refers to (persistence, birth_probability,
  /// free_decay, static_persistence, decay_eps). A cycle of another length dt scales them
  /// (ForCycle; docs/algorithm.md, "Asynchronous sensors"). The co-simulation sets it to its
  /// step length (ScenarioConfig::FilterFor), so its cycles take the factors as given.
  double cycle = 0.05;
  WeightMode mode = WeightMode::kDual;

  // Departures from the paper (docs/algorithm.md, "Switches"). Defaults: the `dualgrid` preset,
  // the best setting of the ablation in docs/results.md; Preset("paper") gives the literal ones.
  // birth_velocity and velocity_likelihood: the Doppler fit (docs/algorithm.md; its effect is
  // measured in docs/results.md, section 9).
  BirthVelocity birth_velocity = BirthVelocity::kDopplerFit;
  ZeroLikelihood zero_likelihood = ZeroLikelihood::kKeepPrediction;
  VelocityLikelihood velocity_likelihood = VelocityLikelihood::kRadialFit;
  Normalisation normalisation = Normalisation::kPerCell;

  /// The most cells a grid may have (IsValid), per side and in all: 2e8 cells take about 19 GB
  /// (MemoryBytes).
  static constexpr double kMaxCells = 2.0e8;
  /// The largest |x| or |y| [m] of a grid centre (the ego position given to an update): 1e9 m,
  /// 25 times the Earth's circumference, keeps every global cell index and cell centre exact in
  /// 64-bit integers and doubles; beyond it DynamicGrid::Update and MeasurementGrid::Build throw.
  static constexpr double kMaxCentre = 1.0e9;
  /// Number of cells along x / y (rounded to the nearest whole cell, at least 1); valid
  /// parameters only (IsValid bounds the count before it is rounded to int).
  int CellsX() const;
  int CellsY() const;
  /// Heap memory of one DynamicGrid with these parameters after its first Update [bytes], from
  /// its layout: per cell 94 bytes (81 of the grid: four double masses, free-space bits, cell
  /// ranges, birth list, 8 sort histograms; 13 of its own MeasurementGrid: free-space bits,
  /// nearest detection and distance), per persistent particle 68 (the particle and its sorted
  /// copy, 28 each in float, 32-bit cell index, resampling sum), per new-born particle 36; the
  /// double copies particles() and weighted_particles() make on demand (36 each) are not included.
  /// A grid fed a shared MeasurementGrid never allocates its own (13 bytes per cell less). Within a
  /// few percent of the measured allocation (tests/filter/test_params.cpp); detection buffers
  /// (which grow with the detections per cycle) are not included. Lets a caller refuse a
  /// configuration before allocating it.
  double MemoryBytes() const;

  /// True when every field is usable; otherwise names the offending field in *error.
  bool IsValid(std::string* error) const;
};

/// `p` with its per-cycle factors for a filter cycle of `dt` [s] (>= 0), with r = dt / p.cycle:
/// persistence^r, static_persistence^r, free_decay^r, (1 - decay_eps)^r kept (decay_eps =
/// 1 - (1 - eps)^r) and a birth probability 1 - (1 - p_B)^r: the survival (or no-birth)
/// probability of r reference cycles. When dt equals p.cycle within 1e-9 relative, `p` is
/// returned unchanged, bit for bit (the co-simulation's synchronous cycles). Other fields as given.
FilterParams ForCycle(const FilterParams& p, double dt);

/// Named parameter sets. "paper": every switch at its literal reading of the paper (the paper's
/// experiment as written); "dualgrid": the setting this project recommends (docs/results.md);
/// "default": the struct defaults. Only the switches differ; sizes and kernels are the defaults.
/// std::nullopt for an unknown name.
std::optional<FilterParams> Preset(std::string_view name);
/// Names accepted by Preset, for error messages: "default, dualgrid, paper".
std::string_view PresetNames();

}  // namespace dualgrid::filter
