#include <catch2/catch.hpp>

#include <malloc.h>

// clang says so through __has_feature, gcc through __SANITIZE_*__.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define DUALGRID_CLANG_SANITIZER 1
#endif
#endif
#ifndef DUALGRID_CLANG_SANITIZER
#define DUALGRID_CLANG_SANITIZER 0
#endif

#include <functional>
#include <stdexcept>
#include <string>

#include "dualgrid/filter/dynamic_grid.hpp"
#include "dualgrid/filter/params.hpp"

using dualgrid::filter::DynamicGrid;
using dualgrid::filter::FilterParams;
using dualgrid::filter::ParseWeightMode;
using dualgrid::filter::WeightMode;

TEST_CASE("default FilterParams are the paper's configuration and valid", "[filter][params]") {
  const FilterParams p;
  std::string error;
  CHECK(p.IsValid(&error));
  CHECK(p.CellsX() == 400);
  CHECK(p.CellsY() == 50);
  CHECK(p.num_particles == 10000);
  CHECK(p.mode == WeightMode::kDual);
}

TEST_CASE("IsValid names the offending field", "[filter][params]") {
  using Mutation = std::pair<std::string, std::function<void(FilterParams&)>>;
  const Mutation m = GENERATE(
      Mutation{"resolution", [](FilterParams& p) { p.resolution = 0.0; }},
      Mutation{"length_x", [](FilterParams& p) { p.length_x = -1.0; }},
      Mutation{"width_y", [](FilterParams& p) { p.width_y = 0.1; }},
      Mutation{"num_particles", [](FilterParams& p) { p.num_particles = 0; }},
      Mutation{"num_birth", [](FilterParams& p) { p.num_birth = -1; }},
      Mutation{"persistence", [](FilterParams& p) { p.persistence = 1.5; }},
      Mutation{"birth_probability", [](FilterParams& p) { p.birth_probability = -0.1; }},
      Mutation{"sigma_f", [](FilterParams& p) { p.sigma_f = 0.0; }},
      Mutation{"sigma_v", [](FilterParams& p) { p.sigma_v = std::nan(""); }},
      Mutation{"occupied_mass", [](FilterParams& p) { p.occupied_mass = 1.0; }},
      Mutation{"free_mass_no_return", [](FilterParams& p) { p.free_mass_no_return = 0.9; }},
      Mutation{"decay_eps", [](FilterParams& p) { p.decay_eps = 1.0; }},
      Mutation{"static_gain", [](FilterParams& p) { p.static_gain = -1.0; }});
  FilterParams p;
  m.second(p);
  std::string error;
  CHECK_FALSE(p.IsValid(&error));
  CHECK(error.find(m.first) != std::string::npos);
  CHECK_THROWS_AS(DynamicGrid(p, 1), std::invalid_argument);
}

TEST_CASE("a cell count that overflows int or exceeds kMaxCells names its key",
          "[filter][params]") {
  struct Case {
    double length_x, width_y, resolution;
    std::string key;
  };
  const Case cases[] = {
      {1e300, 40.0, 0.1, "length_x = 1e+300"},  // lround would overflow: no silent 1 cell
      {40.0, 1e300, 0.1, "width_y = 1e+300"},
      {40.0, 40.0, 1e-9, "length_x = 40"},             // 4e10 cells along x
      {40.0, 40.0, 5e-324, "length_x = 40"},           // inf cells
      {3e4, 3e4, 1.0, "length_x/width_y/resolution"},  // 9e8 cells in all
      {2e8, 1.0, 1.0, ""},                             // the bound itself: accepted
  };
  for (const Case& c : cases) {
    FilterParams p;
    p.length_x = c.length_x;
    p.width_y = c.width_y;
    p.resolution = c.resolution;
    std::string error;
    INFO(c.length_x << " " << c.width_y << " " << c.resolution << ": " << error);
    CHECK(p.IsValid(&error) == c.key.empty());
    if (!c.key.empty()) {
      CHECK(error.find(c.key) == 0);
      CHECK(error.find("at most 200000000 cells") != std::string::npos);
    }
  }
}

TEST_CASE("weight mode names round-trip", "[filter][params]") {
  const WeightMode m = GENERATE(WeightMode::kPosition, WeightMode::kVelocity, WeightMode::kDual);
  CHECK(ParseWeightMode(ToString(m)) == m);
  CHECK_FALSE(ParseWeightMode("Dual").has_value());
  CHECK_FALSE(ParseWeightMode("").has_value());
}

TEST_CASE("MemoryBytes matches what a DynamicGrid allocates by its first Update",
          "[filter][params]") {
  struct Size {
    double length, width;
    int particles, births;
  };
  const Size size = GENERATE(Size{100.0, 25.0, 10000, 1000}, Size{200.0, 50.0, 200000, 20000},
                             Size{60.0, 60.0, 1000000, 0});
  FilterParams p;
  p.length_x = size.length;
  p.width_y = size.width;
  p.num_particles = size.particles;
  p.num_birth = size.births;
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || DUALGRID_CLANG_SANITIZER
  WARN("not checked: a sanitizer's allocator bypasses glibc's malloc statistics");
  return;
#endif
  const std::size_t before = mallinfo2().uordblks + mallinfo2().hblkhd;
  DynamicGrid grid(p, 1);
  grid.Update({}, {}, {}, 0.05);  // allocates its own MeasurementGrid
  const std::size_t after = mallinfo2().uordblks + mallinfo2().hblkhd;
  const double used = static_cast<double>(after - before);
  INFO("estimate " << p.MemoryBytes() << " B, allocated " << used << " B");
  CHECK(p.MemoryBytes() >= 0.95 * used);
  CHECK(p.MemoryBytes() <= 1.05 * used);
}
