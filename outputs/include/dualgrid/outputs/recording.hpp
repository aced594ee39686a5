// The replay recording of a run (RUN_DIR/replay/): what the replay video and the interactive viewer
// draw, so that neither reruns SUMO. Format (docs/replay.md):
//   replay/frames.bin   per recorded frame one zlib stream of the dense cell data, appended as
//                       the run goes;
//   replay/index.json   the header, the sparse per-frame data (truth boxes, detections, clusters,
//                       live metrics) and each frame's [offset, length] in frames.bin; written when
//                       the run ends, so a folder without it holds no usable recording.
// Coordinates: the grid frame (docs/frames.md), absolute [m]; pictures subtract the ego's
// position. Velocities: over ground, grid frame [m/s].
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dualgrid/outputs/output_worker.hpp"
#include "dualgrid/outputs/read_back.hpp"

namespace dualgrid::outputs::replay {

/// Current format version; the reader refuses others with a clear error.
inline constexpr int kFormatVersion = 2;

/// A box in the grid frame: centre [m], heading [rad], size [m], velocity over ground [m/s].
struct Box {
  int id = -1;
  double x = 0.0, y = 0.0, yaw = 0.0, length = 0.0, width = 0.0, vx = 0.0, vy = 0.0;
};

/// One detection: position [m] and its radial velocity over ground as a vector along the line of
/// sight [m/s] (paper eq. (1)), in the grid frame.
struct Detection {
  int sensor = 0;
  double x = 0.0, y = 0.0, vx = 0.0, vy = 0.0;
  bool clutter = false;
  /// Multipath: 0 direct (or clutter), 1 type-1 ghost, 2 type-2 ghost (radar::Path). Written as
  /// a 7th element only for ghosts, so recordings without multipath keep their format.
  int path = 0;
};

/// A cluster of dynamic particles (the scorer's, docs/metrics.md) and its association.
struct Cluster {
  double x = 0.0, y = 0.0, vx = 0.0, vy = 0.0;                ///< weighted mean [m], [m/s]
  double min_x = 0.0, min_y = 0.0, max_x = 0.0, max_y = 0.0;  ///< members' bounding box [m]
  int role = 0;              ///< 0 matched, 1 duplicate, 2 false (eval::ClusterRole)
  int object = -1;           ///< matched object id, -1 if none
  bool velocity_ok = false;  ///< matched with a velocity error within the D_v tolerance
};

/// This frame's scoring of one mode and the running totals since the start (pooled over
/// objects: tracked frames / in-grid frames; the run's D averages per object instead).
struct Live {
  int in_grid = 0, tracked = 0, tracked_v = 0, false_clusters = 0;
  long total_in_grid = 0, total_tracked = 0, total_tracked_v = 0;
};

/// The dense cell data of one mode: masses quantised to 1/255, mean cell velocity over ground
/// [cm/s] (0 where the cell holds no dynamic mass), and a subsample of the particles as offsets
/// from the grid's lower-left corner in units of Header::particle_unit [m].
struct ModeFrame {
  std::vector<std::uint8_t> free, static_occ, dynamic;
  std::vector<std::int16_t> vx_cm, vy_cm;
  std::vector<std::uint16_t> particles;  ///< x0, y0, x1, y1, ...
  std::vector<Cluster> clusters;
  Live live;
};

struct Frame {
  double time = 0.0;  ///< [s]
  /// The grid frame's turn from the world's at this frame [deg]: every position and velocity of
  /// the frame is in that grid frame (the grid that follows the road turns during a run).
  double yaw_deg = 0.0;
  Box ego;                                ///< the ego's box and velocity
  double origin_x = 0.0, origin_y = 0.0;  ///< lower-left corner of cell (0, 0) [m]
  std::vector<Box> truth;                 ///< other vehicles (ids as in objects.csv)
  std::vector<Detection> detections;
  std::vector<ModeFrame> modes;  ///< in Header::modes order
};

struct Header {
  std::string scenario;
  std::uint64_t seed = 0;
  std::vector<std::string> modes;
  std::vector<std::string> sensors;  ///< radar names, index = Detection::sensor
  int cells_x = 0, cells_y = 0;
  double resolution = 0.0;      ///< cell edge [m]
  double frame_yaw_deg = 0.0;   ///< grid frame's turn from the world's at the start [deg]
  double interval = 0.1;        ///< time between recorded frames [s]
  double particle_unit = 0.01;  ///< [m] per particle coordinate step
  int max_particles = 0;        ///< per mode and frame
  double dynamic_threshold = 0.6;
  std::vector<Box> parked;                                ///< static boxes, world frame
  std::vector<std::vector<std::array<double, 2>>> rails;  ///< guard-rail polylines, world frame
  nlohmann::json names;                                   ///< object id (as text) -> vehicle name
  nlohmann::json metrics;  ///< the run's metrics.json per mode, once finished
  bool complete = false;
  std::string status;  ///< why the run is incomplete, else empty
  /// sensors.multipath was on: detections may carry a path (index key `multipath`, written only
  /// when true).
  bool multipath = false;
  /// What the reference boxes (Frame::truth) are: the figures' legend word (outputs::WordsFor:
  /// "ground truth" for SUMO, "annotated" or "track estimate" for recorded data). Index key
  /// `truth_label`, written only when not "ground truth".
  std::string truth_label = "ground truth";
};

/// One frame's bytes as frames.bin holds them: `raw` deflated into one zlib stream (RFC 1950,
/// which any inflater reads: zlib's uncompress, the browser's DecompressionStream("deflate"),
/// Python's zlib.decompress) by dualgrid's own run-length encoder: the tokens of zlib's Z_RLE
/// strategy (literals and runs of one byte) with dynamic Huffman codes per block of 16,383
/// tokens (docs/replay.md, "Cost", says why). Replaces `packed`; false if `raw` is larger than
/// 4 GiB (then `packed` holds nothing usable).
bool DeflateRle(const std::vector<std::uint8_t>& raw, std::vector<std::uint8_t>& packed);

/// The particle unit for a grid of this extent: 1 cm up to 655 m, coarser beyond (uint16).
double ParticleUnit(double extent_x, double extent_y);

/// Writes a recording frame by frame. Add takes the frame over and returns at once: `worker`
/// packs, compresses (DeflateRle) and appends it while the run goes on, in the order added, so
/// the files are the same bytes as written in line. At most
/// kFramesInFlight frames wait or are being written (bounded memory): Add then waits for the
/// oldest. A failed write throws std::runtime_error naming the file, from the Add that waits for
/// that frame (the kFramesInFlight-th after it) or from Finish; the destructor waits for the
/// frames in flight and drops their errors. `worker` must outlive the writer.
class Writer {
 public:
  /// Frames handed to the worker and not yet waited for: enough to ride out a picture the worker
  /// draws in between, which takes several frames' worth of the run's time (docs/performance.md).
  static constexpr std::size_t kFramesInFlight = 8;

  Writer(const std::filesystem::path& dir, Header header, OutputWorker& worker);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  void Add(Frame frame);
  /// Waits for every frame in flight; rethrows the first failure.
  void Flush();
  /// Waits for the last frame, then writes index.json (header with `complete`, `status`,
  /// `metrics` and `names` as given now).
  void Finish(const Header& final_header);
  /// Frames added so far.
  std::size_t frames() const { return added_; }

 private:
  /// Packs, compresses and appends one frame and its index entry (on the worker).
  void Write(const Frame& frame);
  /// Waits for the oldest frame in flight; rethrows its error.
  void WaitOldest();

  std::filesystem::path dir_;
  Header header_;
  OutputWorker& worker_;
  std::ofstream bin_;
  std::uint64_t offset_ = 0;
  std::size_t added_ = 0;
  /// Each frame's index entry, already serialised: a JSON tree of a long run's detections would
  /// take ~6x the memory of its text.
  std::vector<std::string> index_;
  /// Only the worker's jobs touch the members above (from bin_ on) while frames are in flight.
  std::vector<std::uint8_t> raw_, packed_;
  std::deque<std::future<void>> in_flight_;  // oldest first
};

/// A finished recording, read back through the checked reader (read_back.hpp). The constructor
/// checks the header and every frame's index entry against the bounds a recording can have;
/// Load checks the rest of a frame (its detections, clusters and zlib data). Both throw
/// std::invalid_argument naming the file, the key and what was expected (missing, not a
/// recording, other version, truncated, damaged, out of bounds).
class Reader {
 public:
  explicit Reader(const std::filesystem::path& run_dir);
  ~Reader();
  const Header& header() const { return header_; }
  std::size_t size() const { return times_.size(); }
  double time(std::size_t i) const { return times_[i]; }
  Frame Load(std::size_t i) const;
  /// The index as written (for the viewer) and the raw compressed bytes of frame i.
  const nlohmann::json& index() const;
  std::vector<std::uint8_t> Compressed(std::size_t i) const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::unique_ptr<JsonFile> index_file_;
  Header header_;
  std::vector<double> times_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> blobs_;  ///< [offset, length] [bytes]
};

}  // namespace dualgrid::outputs::replay
