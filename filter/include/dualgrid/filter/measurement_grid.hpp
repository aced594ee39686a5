// Step 4 of the cycle (paper eqs. 2-4) and step 4a (the Doppler fit): everything a filter cycle
// derives from the detections, the sensors' coverage and the grid's placement alone, independent
// of any filter's particles or weight mode. docs/algorithm.md, "One cycle".
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/filter/params.hpp"

namespace dualgrid::filter {

/// One radar detection, the paper's eq. (1) [x, y, v_rx, v_ry], in the caller's frame (the
/// filter's, docs/algorithm.md "Grid frame").
struct Measurement {
  Position position;
  /// Ego-motion-compensated radial speed over ground times the line-of-sight unit vector.
  Velocity radial_velocity;
  Position sensor_position;
};

/// Field of view of one sensor that scanned this cycle, in the caller's frame.
struct SensorCoverage {
  Position origin;
  double boresight = 0.0;  ///< [rad]
  double half_fov = 0.0;   ///< [rad], in [0, pi]
  double min_range = 0.0;  ///< [m]
  double max_range = 0.0;  ///< [m]
};

class DynamicGrid;
namespace detail {
struct Team;
/// One bound of a sensor's field of view or of a run of equal bin ranges (MeasurementGrid): the
/// global unit direction (gx, gy) at which the cells' computed bearing crosses it, gx / gy, and
/// the range [m] of the bins after it (kInf: no detection; NaN: outside the field of view). For
/// a finite range, the logical rows [mixed_lo, mixed_hi] that may meet the arc of that range
/// between this bound and the next (others see the run's cells all in front of the range or all
/// behind it), and the rows [free_lo, free_hi] that meet the sector inside that range.
struct ViewBound {
  double gx, gy, cot, br_after;
  int mixed_lo, mixed_hi, free_lo, free_hi;
};
}  // namespace detail

}  // namespace dualgrid::filter

namespace dualgrid::filter_ref {
class DynamicGrid;  // tests/filter/reference: the double cycle before issue 37
}  // namespace dualgrid::filter_ref

namespace dualgrid::filter {

/// The measurement grid of one cycle: per cell the nearest detection within the cutoff and its
/// squared distance (eq. 2's f_d), the field-of-view and ray free-space bits (eq. 3); per
/// detection its line of sight, its bucket, and (when the filter's birth_velocity or
/// velocity_likelihood needs it) the Doppler fit's tangential velocity and its standard deviation.
///
/// Sharing: the result depends only on the inputs of Build and on the geometry fields of the
/// FilterParams it was made with (resolution, length_x, width_y, cutoff_sigmas, sigma_f,
/// free_angle_bin, free_bin_dilation, doppler_fit_radius, doppler_fit_sigma and whether the fit
/// is needed), never on the weight mode or the particles. Filters that differ only in the other
/// fields (the co-simulation's position, velocity and dual modes) can therefore build it once per
/// cycle and each pass it to DynamicGrid::Update: same results, bit for bit, as each building its
/// own, at a third of step 4's cost for three modes (docs/performance.md).
///
/// Ownership: Build copies the detections; nothing refers to the caller's memory afterwards.
/// Memory: O(cells) bytes allocated by the constructor; the per-detection arrays grow to the
/// largest detection count seen and are then reused (no allocation in steady state).
class MeasurementGrid {
 public:
  /// Throws std::invalid_argument when !params.IsValid().
  explicit MeasurementGrid(const FilterParams& params);

  /// Builds the grid of one cycle for a filter grid centred on `centre` [m] (the position of the
  /// cycle's EgoInput, after any Reframe). Detections or sensors with non-finite values are
  /// skipped, as in DynamicGrid::Update. O(cells + detections x cutoff area); in one OpenMP
  /// parallel region (none when a region here would get one thread, OneThreadHere), results
  /// independent of the thread count. Throws std::invalid_argument for a
  /// centre that is not finite or beyond FilterParams::kMaxCentre, or an invalid SensorCoverage
  /// (as DynamicGrid::Update).
  void Build(const Position& centre, std::span<const Measurement> z,
             std::span<const SensorCoverage> coverage);

  /// True when a filter with `params` may use this grid: the geometry fields listed above are
  /// equal. Any difference there makes DynamicGrid::Update throw.
  bool SharesGeometry(const FilterParams& params) const;
  /// Global index of logical cell (0, 0) of the last Build (DynamicGrid::origin_index).
  std::array<std::int64_t, 2> origin_index() const { return {origin_gx_, origin_gy_}; }
  /// The detections of the last Build (a copy).
  std::span<const Measurement> measurements() const { return z_; }
  /// Per cell of the last Build, in storage order (row Mod(origin_gy + ly, ny), column
  /// Mod(origin_gx + lx, nx)), the field-of-view and ray free-space bits of eq. (3): 1 in a
  /// sensor's field of view, 2 in front of its bin's closest detection, 4 in a bin without any.
  std::span<const std::uint8_t> view() const { return view_; }
  /// Number of Build calls so far (0: never built).
  std::uint64_t builds() const { return builds_; }

  /// Per cell of the last Build, in storage order (as view()): the index into measurements() of
  /// the detection nearest to the cell centre within cutoff_sigmas x sigma_f (the lowest index
  /// among equally near ones), or -1; and its squared distance [m^2] (inf where -1).
  std::span<const int> nearest() const { return near_det_; }
  std::span<const double> nearest_d2() const { return near_d2_; }

 private:
  friend class DynamicGrid;
  // test_float_bound.cpp's double reference cycle reads the same tables as DynamicGrid: it links
  // this class instead of keeping a copy of it.
  friend class ::dualgrid::filter_ref::DynamicGrid;

  // Build in two parts. Prepare (serial): checks the inputs (throws), places the grid and the
  // detections (PlaceDetections) and sizes every array the build writes. Fill: the tables, by
  // the team t (detail::Team's contract: every thread of it calls Fill; no allocation, no throw).
  // Fill ends without a barrier: the tables are complete for a reader only after the team's next
  // barrier (Build: its region's end). DynamicGrid::Update runs Fill in the cycle's own region.
  void Prepare(const Position& centre, std::span<const Measurement> z,
               std::span<const SensorCoverage> coverage);
  void Fill(const detail::Team& t, std::span<const SensorCoverage> coverage);
  // Per detection its bucket (or -1: not near the grid) and stamp origin; the bucket counts.
  void PlaceDetections();
  // The detection buckets' ranges and contents in bucket order (serial).
  void FillBuckets();
  // Nearest detection per cell centre of the bands [band_lo, band_hi) of storage rows
  // (kStampBands bands): resets the bands' cells of the last build, then stamps every
  // detection's cells in them in detection order (ties to the lower index whatever the bands
  // or thread).
  void StampBands(int band_lo, int band_hi);
  void Bins(std::span<const SensorCoverage> cov);               // the bins' ranges (serial)
  void FieldOfViewTables(std::span<const SensorCoverage> cov);  // per-sensor constants (serial)
  // bound_dir_ for the sensors' bins (FieldOfViewTables, serial): recomputed only when a
  // sensor's half_fov or bin count differs from the last build's.
  void BoundDirections(std::span<const SensorCoverage> cov);
  void ViewBounds(std::span<const SensorCoverage> cov);  // bound_* (FieldOfViewTables, serial)
  // The row ranges of one sensor's bounds vb[0, n) (ViewBounds), the sensor at y = oy [m].
  void BoundRows(double oy, detail::ViewBound* vb, std::int64_t n) const;
  void FieldOfViewRow(int ly, std::span<const SensorCoverage> cov);  // view_ of logical row ly
  // Per detection the unit line of sight and the signed radial speed into det_los_ (and, with
  // the fit, in bucket order into det_los_b_: after FillBuckets).
  void ComputeLinesOfSight();
  // Per detection the tangential velocity a robust fit to its neighbours' Doppler gives, and its
  // standard deviation (inf: no fit), by the team t; no barrier at the end.
  void FitDetectionVelocities(const detail::Team& t);
  // Detection bucket (clamped to the bucket grid) of a point. Inline: UpdateCells asks it for
  // every cell holding particles.
  std::pair<int, int> BucketOf(double px, double py) const;

  FilterParams params_;
  bool with_fit_ = false;
  int nx_, ny_;
  std::int64_t num_cells_;
  std::int64_t origin_gx_ = 0, origin_gy_ = 0;
  std::uint64_t builds_ = 0;
  std::vector<Measurement> z_;

  // Per cell (storage order: circular in both axes, as DynamicGrid's layers).
  std::vector<std::uint8_t> view_;  // field-of-view / ray free-space bits (grid_internal.hpp)
  std::vector<int> near_det_;       // nearest detection index or -1
  std::vector<double> near_d2_;     // its squared distance to the cell centre [m^2]
  // Bands of storage rows the stamping runs in: band b holds rows [b ny / kStampBands,
  // (b + 1) ny / kStampBands).
  static constexpr int kStampBands = 8;
  // Per storage row, the storage columns [lo, hi] the last build's stamps covered (lo > hi:
  // none); the next build resets near_det_ and near_d2_ there.
  std::vector<std::array<int, 2>> stamp_span_;

  // Detection bucket index (logical coordinates, bucket edge >= cutoff + one cell).
  int bucket_cells_ = 1, nbx_ = 1, nby_ = 1;
  double bucket_inv_ = 1.0;  // 1 / bucket edge [1/m], with bucket_cells_ (BucketOf)
  std::vector<std::int64_t> bucket_count_, bucket_start_;
  std::vector<int> bucket_items_;
  std::vector<double> det_x_, det_y_;     // detection positions in bucket order [m]
  std::vector<std::int64_t> det_bucket_;  // bucket per detection or -1 (not near the grid)
  // Per detection with a bucket: logical cell (lx, ly) and the storage row of its stamp's first
  // row max(0, ly - rc).
  std::vector<std::array<int, 3>> det_stamp_;

  // Per-sensor bearing bins for the ray free space.
  std::vector<double> bin_range_;
  std::vector<std::int64_t> bin_offset_;
  std::vector<double> sensor_trig_;  // per sensor: cos, sin of the boresight, tan(half_fov), inner
  std::vector<int> bin_run_end_;     // per bin: last bin (sensor-local) of its run of equal ranges
  // Per sensor of a half_fov below pi/2 (a narrow one), the unit directions in the sensor frame
  // (x along the boresight) at which the computed bearing (FastAtan2) crosses its bins' bounds
  // -half_fov + b free_angle_bin, b = 0 .. bins: bins + 1 entries from bound_dir_offset_[k]
  // (none for a wide sensor). They depend on half_fov and the bin width alone: bound_key_ holds
  // each sensor's half_fov and bin count they were computed for.
  std::vector<std::array<double, 2>> bound_dir_;
  std::vector<std::int64_t> bound_dir_offset_;
  std::vector<std::pair<double, std::int64_t>> bound_key_;
  // A narrow sensor's view bounds of this build (detail::ViewBound), per sensor
  // [bound_offset_[k], bound_offset_[k + 1]), in ascending bearing: the field of view's start,
  // the edges between its runs of equal bin ranges, its end.
  std::vector<std::int64_t> bound_offset_;
  std::vector<detail::ViewBound> bound_;

  std::vector<double> det_los_;                 // per detection: unit line of sight, v_r . u
  std::vector<double> det_los_b_;               // det_los_ in bucket order (the fit's gathering)
  std::vector<double> det_fit_t_, det_fit_sd_;  // per detection: the fit [m/s] (4a)
};

inline std::pair<int, int> MeasurementGrid::BucketOf(double px, double py) const {
  // Same formula for detections and queries.
  const double x0 = static_cast<double>(origin_gx_) * params_.resolution;
  const double y0 = static_cast<double>(origin_gy_) * params_.resolution;
  const double fx = std::clamp(std::floor((px - x0) * bucket_inv_), 0.0, nbx_ - 1.0);
  const double fy = std::clamp(std::floor((py - y0) * bucket_inv_), 0.0, nby_ - 1.0);
  return {static_cast<int>(fx), static_cast<int>(fy)};
}

}  // namespace dualgrid::filter
