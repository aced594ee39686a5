// Counter-based random numbers (Random123 Philox4x32-10).
//
// A stream is addressed by (seed, purpose, step, index): the same address always yields the same
// numbers, whatever thread draws them and in whatever order, which keeps OpenMP loops
// reproducible. Draws within one stream advance an internal block counter.
#pragma once

#include <cmath>
#include <cstdint>

#include <Random123/philox.h>

namespace dualgrid {

/// Distinguishes independent uses of the same (seed, step, index) address.
enum class RngPurpose : std::uint32_t {
  kRadarScatter = 1,
  kRadarClutter = 2,
  kRadarGhost = 3,  ///< resolution cells holding multipath ghosts only
  kFilterPredict = 10,
  kFilterBirth = 11,
  kFilterResample = 12,
  kFilterInit = 13,
  kSimulation = 20,
  kTest = 99,
};

class CounterRng {
 public:
  CounterRng(std::uint64_t seed, RngPurpose purpose, std::uint64_t step, std::uint32_t index)
      : key_{{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}},
        ctr_{{static_cast<std::uint32_t>(step), static_cast<std::uint32_t>(step >> 32), index,
              static_cast<std::uint32_t>(purpose) << 24}} {}

  /// Uniform 32-bit integer.
  std::uint32_t NextU32() {
    if (used_ == 4) Refill();
    return block_[used_++];
  }
  /// Uniform in [0, 1).
  double Uniform() {
    const std::uint64_t hi = NextU32() >> 5, lo = NextU32() >> 6;  // 53 random bits
    return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
  }
  /// Uniform in (0, 1]: safe for logarithms.
  double UniformOpen() { return 1.0 - Uniform(); }
  /// Uniform in [a, b).
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  /// Standard normal via Box-Muller (both outputs used).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(UniformOpen()));
    const double t = 2.0 * 3.14159265358979323846 * Uniform();
    spare_ = r * std::sin(t);
    has_spare_ = true;
    return r * std::cos(t);
  }
  double Normal(double mean, double sigma) { return mean + sigma * Normal(); }
  /// Poisson-distributed count (Knuth for small means, normal approximation above 60).
  std::uint32_t Poisson(double mean) {
    if (mean <= 0.0) return 0;
    if (mean > 60.0) {
      const double x = std::round(Normal(mean, std::sqrt(mean)));
      return x < 0.0 ? 0u : static_cast<std::uint32_t>(x);
    }
    const double limit = std::exp(-mean);
    double p = Uniform();
    std::uint32_t k = 0;
    while (p > limit) {
      p *= Uniform();
      ++k;
    }
    return k;
  }

 private:
  void Refill() {
    block_ = philox4x32(ctr_, key_);
    ++ctr_.v[3];  // low 24 bits: block counter within this stream
    used_ = 0;
  }

  r123array2x32 key_;
  r123array4x32 ctr_;
  r123array4x32 block_{};
  int used_ = 4;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace dualgrid
