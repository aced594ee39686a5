// The robust velocity fit of step 4a (docs/algorithm.md, "The Doppler fit"): one velocity v with
// u_i . v = v_r,i for the detections i near a detection, by Tukey's biweight (iteratively
// reweighted least squares from ordinary least squares). Internal to the filter
// (MeasurementGrid::FitDetectionVelocities); public so that tests/filter can check it, bit for
// bit, against its definition.
#pragma once

#include <cstdint>

namespace dualgrid::filter::detail {

/// Neighbours per fit at most (the first ones in bucket order).
constexpr int kFitMaxNeighbours = 64;

/// Candidates looked at per detection at most (docs/algorithm.md, step 4a): bounds a fit's cost
/// when thousands of detections crowd its buckets, so that a cycle's cost stays linear in them.
constexpr int kMaxCandidates = 8 * kFitMaxNeighbours;

/// The detection buckets as the fit's gathering reads them: bucket (cx, cy) of nbx x nby holds
/// the points start[cy nbx + cx] to start[cy nbx + cx + 1] - 1 of x, y [m] (bucket order); the
/// buckets' edge is 1 / inv [m], bucket (0, 0) starts at (ox, oy) [m], and the edge buckets reach
/// out without end. Borrowed arrays.
struct BucketView {
  const double* x;
  const double* y;
  const std::int64_t* start;
  int nbx, nby;
  double inv, ox, oy;
};

/// A detection's neighbours at (px, py) [m] in bucket (bx, by) (the one it is placed in): the
/// bucket-order positions of the first kFitMaxNeighbours points within sqrt(radius2) [m] of it
/// among the first kMaxCandidates looked at, the buckets within `reach` of (bx, by) looked at row
/// by row (those wholly beyond the radius skipped). Into key (kFitMaxNeighbours entries); returns
/// their count.
int GatherNeighbours(const BucketView& v, double px, double py, int bx, int by, int reach,
                     double radius2, int* key);

/// The fit's result: the velocity [m/s], the scale sigma [m/s] and A = sum_i w_i u_i u_i^T at
/// the solution (its entries a00, a01, a11), and the inliers of the last reweighting.
struct DopplerFit {
  double vx = 0.0, vy = 0.0, scale = 0.0;
  double a00 = 0.0, a01 = 0.0, a11 = 0.0;
  int inliers = 0;
};

/// The largest m >= 0 with 1.4826 * m (rounded as double) <= floor: the fit's scale
/// max(floor, 1.4826 * median) is `floor` exactly when the median is <= this bound. floor >= 0,
/// finite.
double MadFloorBound(double floor);

/// The value of rank k (0-based) of a[0, n) in ascending order: what std::nth_element puts at
/// a + k, without changing a. `guess` [any value] only steers the work (a value near the result
/// makes it cheaper). Preconditions: 0 <= k < n <= kFitMaxNeighbours, no NaN, and equal values
/// are bitwise equal (no -0.0 beside +0.0; e.g. results of std::abs).
double SelectRank(const double* a, int n, int k, double guess);

/// Fits v to the n lines of sight (ux, uy) [unit vectors] and radial speeds y [m/s] (the
/// residuals' scale is 1.4826 x their median absolute deviation, at least floor [m/s];
/// floor_bound = MadFloorBound(floor)). False when fewer than 3 inliers remain or the weighted
/// lines of sight do not span the plane (f then holds partial values). 3 <= n <=
/// kFitMaxNeighbours. Same result, bit for bit, as the plain definition (tests/filter:
/// reference/doppler_fit.hpp), for any input including non-finite ones.
bool RobustDopplerFit(const double* ux, const double* uy, const double* y, int n, double floor,
                      double floor_bound, DopplerFit* f);

/// One neighbourhood's gathered arrays: RobustDopplerFit's inputs (3 <= n <= kFitMaxNeighbours).
struct FitInput {
  const double* ux;
  const double* uy;
  const double* y;
  int n;
};

/// RobustDopplerFit of two neighbourhoods at once, one per SIMD lane: ok[l] and f[l] are what
/// RobustDopplerFit(in[l], floor, floor_bound) gives, bit for bit (f[l] partial where ok[l] is
/// false). *first_guess [m/s, any value]: where the first pass's median selection starts
/// (SelectRank's guess: it only steers the work); set to the last first-pass median selected, a
/// good start for the next pair of a run (neighbouring detections, similar residuals).
void RobustDopplerFitPair(const FitInput in[2], double floor, double floor_bound, DopplerFit f[2],
                          bool ok[2], double* first_guess);

/// The last few fits of one thread's run of detections, each under its key: the neighbours it
/// gathered (their positions in the detection buckets, in gathering order). RobustDopplerFit is a
/// pure function of the gathered arrays, so a detection whose key equals an earlier one's (within
/// one build: the buckets fixed) takes that fit as it is, bit for bit. Owned by the caller's stack.
class FitMemo {
 public:
  static constexpr int kSlots = 16;  // fits remembered

  /// The fit remembered under key[0, n) (true: found; *ok and *f then hold its outcome).
  /// 0 <= n <= kFitMaxNeighbours.
  bool Find(const int* key, int n, bool* ok, DopplerFit* f) const;
  /// Remembers a fit under key[0, n), in place of the oldest one when all slots are taken.
  void Add(const int* key, int n, bool ok, const DopplerFit& f);

 private:
  struct Entry {
    int n;
    int key[kFitMaxNeighbours];
    bool ok;
    DopplerFit f;
  };
  Entry slot_[kSlots];
  int size_ = 0, next_ = 0;  // slots in use; the slot the next Add takes
};

/// The fits of one run of up to kRun detections (run-local indices 0 .. kRun - 1), two at a time:
/// each neighbourhood is looked up in a FitMemo first; a new one is queued (one equal to a queued
/// one waits for it) and fitted by RobustDopplerFitPair when a second joins it. Results bit for
/// bit those of RobustDopplerFit on each neighbourhood. About 12 kB: for the caller's stack.
class RunFits {
 public:
  static constexpr int kRun = 32;
  /// A neighbourhood: its key (FitMemo), and the arrays Submit fills from it.
  struct Gathered {
    double ux[kFitMaxNeighbours], uy[kFitMaxNeighbours], y[kFitMaxNeighbours];
    int key[kFitMaxNeighbours];
  };

  RunFits(double floor, double floor_bound) : floor_(floor), floor_bound_(floor_bound) {}
  /// Where the next neighbourhood's key is gathered before Submit.
  Gathered& Next() { return queue_[queued_]; }
  /// Detection i's neighbourhood: the first n entries of Next().key, whose ux, uy and y are
  /// by_key[3 key], [3 key + 1], [3 key + 2] (read only for a fit not found in the memo or the
  /// queue). n < 3: no fit. Each i once.
  void Submit(int i, int n, const double* by_key);
  /// Fits what is still queued; then Result holds every submitted detection's fit.
  void Finish();
  /// Detection i's fit after Finish (false: no fit; *f then unspecified).
  bool Result(int i, DopplerFit* f) const {
    *f = fit_[i];
    return ok_[i];
  }

 private:
  void FitQueued();  // the queue's one or two fits, their results and their waiters'

  double floor_, floor_bound_;
  double first_guess_ = floor_bound_;  // RobustDopplerFitPair's, carried from pair to pair
  FitMemo memo_;
  Gathered queue_[2];
  int queued_ = 0, queued_n_[2] = {0, 0}, queued_i_[2] = {0, 0};
  int waiters_ = 0, waiter_i_[kRun], waiter_of_[kRun];  // detections waiting for a queued fit
  bool ok_[kRun] = {};
  DopplerFit fit_[kRun];
};

}  // namespace dualgrid::filter::detail
