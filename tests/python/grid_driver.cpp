// Reference run for tests/python/test_cpp_identical.py: steps a C++ DynamicGrid through a fixed
// synthetic scene (tests/filter/synthetic.hpp: exact detections on the faces of a moving and a
// parked box, the ego driving along x, two sensors) and writes every cycle's inputs and outputs
// to a binary file. The Python test feeds the same inputs (read back from the file, so both sides
// see identical doubles) to dualgrid.DynamicGrid and compares the outputs bit for bit.
//
// Usage: python_grid_driver OUT PRESET MODE NUM_PARTICLES CYCLES SEED
//   FilterParams = Preset(PRESET) with mode MODE, num_particles NUM_PARTICLES and
//   num_birth NUM_PARTICLES / 10 (the Python test builds the same).
//
// File (native byte order, written and read on the same machine):
//   char[8] "DGPYREF1"; int32 cycles, cells_x, cells_y, num_particles
//   per cycle: float64 ego[5] (x, y, yaw, vx, vy), float64 dt,
//              int64 N, float64[N][6] detections (x, y, v_rx, v_ry, sensor_x, sensor_y),
//              int64 M, float64[M][6] coverage (origin_x, origin_y, boresight, half_fov,
//              min_range, max_range),
//              float32[cells] free, static, dynamic; uint8[cells] observed (ExportMasses order),
//              float64[n] x, y; float32[n] vx, vy, w_position, w_velocity, weight (particles())
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "synthetic.hpp"

using namespace dualgrid;
using namespace dualgrid::filter;

namespace {

class Writer {
 public:
  explicit Writer(const std::string& path) : f_(std::fopen(path.c_str(), "wb")) {
    if (!f_) throw std::runtime_error("cannot open " + path + " for writing");
  }
  ~Writer() {
    if (f_) std::fclose(f_);
  }
  // Reports a failed final flush (the destructor cannot).
  void Close() {
    const int rc = std::fclose(f_);
    f_ = nullptr;
    if (rc != 0) throw std::runtime_error("close failed");
  }
  template <typename T>
  void Put(const T* data, std::size_t n) {
    if (n && std::fwrite(data, sizeof(T), n, f_) != n) throw std::runtime_error("write failed");
  }
  template <typename T>
  void Put(const T& v) {
    Put(&v, 1);
  }

 private:
  std::FILE* f_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s OUT PRESET MODE NUM_PARTICLES CYCLES SEED\n", argv[0]);
    return 2;
  }
  try {
    std::optional<FilterParams> fp = Preset(argv[2]);
    const std::optional<WeightMode> mode = ParseWeightMode(argv[3]);
    if (!fp || !mode) throw std::invalid_argument("unknown preset or mode");
    fp->mode = *mode;
    fp->num_particles = std::atoi(argv[4]);
    fp->num_birth = fp->num_particles / 10;
    const int cycles = std::atoi(argv[5]);
    DynamicGrid grid(*fp, std::strtoull(argv[6], nullptr, 10));

    Writer out(argv[1]);
    out.Put("DGPYREF1", 8);
    const std::int32_t header[4] = {cycles, grid.cells_x(), grid.cells_y(), fp->num_particles};
    out.Put(header, 4);
    const std::size_t cells = static_cast<std::size_t>(grid.cells_x()) * grid.cells_y();
    std::vector<float> free(cells), stat(cells), dyn(cells);
    std::vector<std::uint8_t> observed(cells);
    const double dt = 0.05;
    for (int k = 0; k < cycles; ++k) {
      const double t = k * dt;
      // Ego at 10 m/s along x; a car crossing ahead diagonally at (-4, 8) m/s; a parked box.
      const Pose2 ego{{10.0 * t, 0.0}, 0.0};
      const Velocity ego_v(10.0, 0.0);
      const OrientedBox mover{{25.0 - 4.0 * t, -8.0 + 8.0 * t}, std::atan2(8.0, -4.0), 4.5, 1.8};
      const Velocity mover_v(-4.0, 8.0);
      const OrientedBox parked{{40.0, 6.0}, 0.0, 4.5, 1.8};
      const SensorCoverage cov[2] = {testing::ForwardRadar(ego), testing::LeftRadar(ego)};
      std::vector<Measurement> z;
      for (const SensorCoverage& c : cov) {
        for (const Position& p : testing::NearFacePoints(mover, c.origin, 1.0, 0.5))
          z.push_back(testing::Detect(p, mover_v, c.origin));
        for (const Position& p : testing::NearFacePoints(parked, c.origin, 1.0, 0.5))
          z.push_back(testing::Detect(p, Velocity::Zero(), c.origin));
      }
      grid.Update({ego, ego_v}, z, cov, dt);

      const double ego_row[6] = {ego.position.x(), ego.position.y(), ego.yaw,
                                 ego_v.x(),        ego_v.y(),        dt};
      out.Put(ego_row, 6);
      out.Put(static_cast<std::int64_t>(z.size()));
      for (const Measurement& m : z) {
        const double row[6] = {m.position.x(),        m.position.y(),        m.radial_velocity.x(),
                               m.radial_velocity.y(), m.sensor_position.x(), m.sensor_position.y()};
        out.Put(row, 6);
      }
      out.Put(static_cast<std::int64_t>(2));
      for (const SensorCoverage& c : cov) {
        const double row[6] = {c.origin.x(), c.origin.y(), c.boresight,
                               c.half_fov,   c.min_range,  c.max_range};
        out.Put(row, 6);
      }
      grid.ExportMasses(free, stat, dyn, observed);
      out.Put(free.data(), cells);
      out.Put(stat.data(), cells);
      out.Put(dyn.data(), cells);
      out.Put(observed.data(), cells);
      const ParticleSet& p = grid.particles();
      out.Put(p.x.data(), p.size());
      out.Put(p.y.data(), p.size());
      out.Put(p.vx.data(), p.size());
      out.Put(p.vy.data(), p.size());
      out.Put(p.w_position.data(), p.size());
      out.Put(p.w_velocity.data(), p.size());
      out.Put(p.weight.data(), p.size());
    }
    out.Close();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "python_grid_driver: %s\n", e.what());
    return 1;
  }
  return 0;
}
