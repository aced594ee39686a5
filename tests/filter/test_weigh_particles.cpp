// WeighParticles (dualgrid/filter/weigh_particles.hpp) against its version before Nearest's two
// running minima (reference/weigh_particles.cpp), bit for bit: the stored weights and the cell's
// sums.
// Random cells with detections exactly at the cutoff, ties (two detections at one position),
// particles on the grid's edge (coordinates near 0), cells larger than a vector and tails.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "dualgrid/filter/weigh_particles.hpp"
#include "reference/weigh_particles.hpp"

namespace {

using dualgrid::filter::WeightMode;
using dualgrid::filter::detail::CellParticles;
using dualgrid::filter::detail::CellSums;
using dualgrid::filter::detail::WeighInputs;

// One cell's particles (at [lo, hi) of arrays with room before and after) and the detections of
// its 3 x 3 buckets (three ranges of bucket-order arrays with detections outside them as well).
struct Scene {
  std::vector<float> x, y, vx, vy, weight, w_position, w_velocity;
  std::int64_t lo = 0, hi = 0;
  std::vector<float> det_x, det_y;
  std::vector<int> det_item;
  std::int64_t cand[3][2] = {};
  std::vector<float> u0, u1, u2, fit_k, fit_t, vr_x, vr_y;  // per detection index j
};

constexpr float kSigmaF = 0.6f;
constexpr float kCutoff = 3.0f * kSigmaF;

// A detection near the particles: uniform around them, exactly at the cutoff (or one float step
// either side) from a particle, along an axis or a diagonal or outward from a side of their
// bounding box, or on an earlier one's position (a tie of distances, broken by the lower index).
void PlaceDetection(std::mt19937& rng, const Scene& s, float& dx, float& dy) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::uniform_int_distribution<std::int64_t> pick(s.lo, s.hi - 1);
  const int kind = static_cast<int>(u(rng) * 5.0f);
  if (kind == 4 && !s.det_x.empty()) {
    const std::size_t k = std::uniform_int_distribution<std::size_t>(0, s.det_x.size() - 1)(rng);
    dx = s.det_x[k];
    dy = s.det_y[k];
    return;
  }
  const float inf = std::numeric_limits<float>::infinity();
  const int nudge = static_cast<int>(u(rng) * 3.0f) - 1;  // -1, 0 or +1 float steps
  if (kind == 3) {
    // Outward from the particle on one side of the bounding box, at the cutoff along the axis.
    const int side = static_cast<int>(u(rng) * 4.0f);
    const auto first = s.x.begin() + s.lo, last = s.x.begin() + s.hi;
    const auto yfirst = s.y.begin() + s.lo, ylast = s.y.begin() + s.hi;
    const std::int64_t p = s.lo + (side == 0   ? std::max_element(first, last) - first
                                   : side == 1 ? std::min_element(first, last) - first
                                   : side == 2 ? std::max_element(yfirst, ylast) - yfirst
                                               : std::min_element(yfirst, ylast) - yfirst);
    const float sign = side % 2 == 0 ? 1.0f : -1.0f;
    dx = side < 2 ? s.x[p] + sign * kCutoff : s.x[p];
    dy = side < 2 ? s.y[p] : s.y[p] + sign * kCutoff;
    float& moved = side < 2 ? dx : dy;
    if (nudge != 0) moved = std::nextafter(moved, nudge > 0 ? inf : -inf);
    return;
  }
  const std::int64_t p = pick(rng);
  const float px = s.x[p], py = s.y[p];
  if (kind == 0) {
    dx = px + (u(rng) - 0.5f) * 4.0f * kCutoff;
    dy = py + (u(rng) - 0.5f) * 4.0f * kCutoff;
    return;
  }
  // At the cutoff from a particle along an axis or a diagonal, then nudged.
  const float a = 6.2831853f * std::floor(u(rng) * 8.0f) / 8.0f;
  dx = px + kCutoff * std::cos(a);
  dy = py + kCutoff * std::sin(a);
  if (nudge != 0) dx = std::nextafter(dx, nudge > 0 ? inf : -inf);
}

// A random cell of n particles around (cx, cy) [m, grid-local] with nd candidate detections.
Scene MakeScene(std::mt19937& rng, std::int64_t n, float cx, float cy, int nd) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Scene s;
  const std::int64_t pad = 3;
  s.lo = pad;
  s.hi = pad + n;
  for (auto* v : {&s.x, &s.y, &s.vx, &s.vy, &s.weight, &s.w_position, &s.w_velocity})
    v->assign(static_cast<std::size_t>(n + 2 * pad), 0.0f);
  for (std::int64_t i = 0; i < n + 2 * pad; ++i) {
    s.x[i] = std::max(0.0f, cx + 0.5f * u(rng));  // one 0.5 m cell; 0 on the grid's edge
    s.y[i] = std::max(0.0f, cy + 0.5f * u(rng));
    s.vx[i] = (u(rng) - 0.5f) * (u(rng) < 0.3f ? 0.2f : 60.0f);  // some below static_speed
    s.vy[i] = (u(rng) - 0.5f) * 20.0f;
    s.weight[i] = u(rng) * 0.01f;
    s.w_position[i] = u(rng);
    s.w_velocity[i] = u(rng);
  }
  // Bucket order: a few detections before, between and after the three candidate ranges.
  const int before = 2, gap = 1;
  std::vector<int> items(static_cast<std::size_t>(nd + before + 3 * gap));
  std::iota(items.begin(), items.end(), 0);
  std::shuffle(items.begin(), items.end(), rng);
  const int total = static_cast<int>(items.size());
  for (int k = 0; k < total; ++k) {
    float dx, dy;
    PlaceDetection(rng, s, dx, dy);
    s.det_x.push_back(dx);
    s.det_y.push_back(dy);
    s.det_item.push_back(items[static_cast<std::size_t>(k)]);
  }
  const int a = std::uniform_int_distribution<int>(0, nd)(rng);
  const int b = std::uniform_int_distribution<int>(a, nd)(rng);
  const int starts[3] = {before, before + a + gap, before + b + 2 * gap};
  const int ends[3] = {before + a, before + b + gap, before + nd + 2 * gap};
  for (int r = 0; r < 3; ++r) {
    s.cand[r][0] = starts[r];
    s.cand[r][1] = ends[r];
  }
  for (int j = 0; j < total; ++j) {
    const float ang = 6.2831853f * u(rng);
    s.u0.push_back(std::cos(ang));
    s.u1.push_back(std::sin(ang));
    s.u2.push_back((u(rng) - 0.5f) * 40.0f);
    s.fit_k.push_back(u(rng) < 0.5f ? 0.0f : u(rng));
    s.fit_t.push_back((u(rng) - 0.5f) * 10.0f);
    s.vr_x.push_back((u(rng) - 0.5f) * 40.0f);
    s.vr_y.push_back((u(rng) - 0.5f) * 40.0f);
  }
  return s;
}

WeighInputs Inputs(const Scene& s, int variant) {
  WeighInputs in;
  in.inv_2sf2 = 0.5f / (kSigmaF * kSigmaF);
  in.cutoff2 = kCutoff * kCutoff;
  in.inv_2v2 = 0.5f / (1.5f * 1.5f);
  in.keep = 0.99f;
  in.slow2 = 0.3f * 0.3f;
  in.mode = variant % 3 == 0   ? WeightMode::kDual
            : variant % 3 == 1 ? WeightMode::kPosition
                               : WeightMode::kVelocity;
  in.radial = variant % 2 == 0;
  in.radial_fit = variant % 4 == 0;
  in.det_x = s.det_x.data();
  in.det_y = s.det_y.data();
  in.det_item = s.det_item.data();
  in.u0 = s.u0.data();
  in.u1 = s.u1.data();
  in.u2 = s.u2.data();
  in.fit_k = s.fit_k.data();
  in.fit_t = s.fit_t.data();
  in.vr_x = s.vr_x.data();
  in.vr_y = s.vr_y.data();
  return in;
}

CellParticles Cell(Scene& s, bool observed) {
  CellParticles c{s.x.data(),
                  s.y.data(),
                  s.vx.data(),
                  s.vy.data(),
                  s.weight.data(),
                  s.w_position.data(),
                  s.w_velocity.data(),
                  s.lo,
                  s.hi,
                  {{0, 0}, {0, 0}, {0, 0}},
                  observed,
                  0.8f,
                  1.0f};
  for (int r = 0; r < 3; ++r)
    for (int e = 0; e < 2; ++e) c.cand[r][e] = s.cand[r][e];
  return c;
}

bool SameBits(const CellSums& a, const CellSums& b) {
  const double va[6] = {a.slow_mass, a.fast_mass, a.sum_pos, a.sum_vel, a.sum_mode, a.a_dyn};
  const double vb[6] = {b.slow_mass, b.fast_mass, b.sum_pos, b.sum_vel, b.sum_mode, b.a_dyn};
  for (int k = 0; k < 6; ++k)
    if (std::bit_cast<std::uint64_t>(va[k]) != std::bit_cast<std::uint64_t>(vb[k])) return false;
  return true;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::bit_cast<std::uint32_t>(a[i]) != std::bit_cast<std::uint32_t>(b[i])) return false;
  return true;
}

// Runs the reference and WeighParticles on copies of the scene; true if the stored weights and
// the sums have the same bits.
bool SameAsReference(const Scene& scene, int variant, bool observed) {
  Scene ref = scene, s = scene;
  const CellSums want =
      dualgrid::filter_ref::WeighParticles(Inputs(ref, variant), Cell(ref, observed));
  const CellSums got =
      dualgrid::filter::detail::WeighParticles(Inputs(s, variant), Cell(s, observed));
  return SameBits(got, want) && SameBits(s.weight, ref.weight) &&
         SameBits(s.w_position, ref.w_position) && SameBits(s.w_velocity, ref.w_velocity);
}

}  // namespace

TEST_CASE("WeighParticles: Nearest's two running minima change no bit", "[filter][weigh]") {
  std::mt19937 rng(20261127);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int cells = 0, bad = 0;
  for (const std::int64_t n : {1, 3, 4, 5, 7, 8, 9, 16, 17, 40}) {
    for (int trial = 0; trial < 60; ++trial) {
      // Half the cells on the grid's low edge (coordinates from 0), half inside.
      const float cx = trial % 2 == 0 ? 0.0f : 1.0f + 80.0f * u(rng);
      const float cy = trial % 4 < 2 ? 80.0f * u(rng) : 0.0f;
      const int nd = static_cast<int>(u(rng) * 40.0f);
      const Scene s = MakeScene(rng, n, cx, cy, nd);
      bad += SameAsReference(s, trial, trial % 3 != 0) ? 0 : 1;
      ++cells;
    }
  }
  INFO(bad << " of " << cells << " cells differ");
  CHECK(bad == 0);
}

TEST_CASE("WeighParticles: many candidates, one, and none", "[filter][weigh]") {
  std::mt19937 rng(37);
  for (const int nd : {0, 1, 600}) {
    const Scene s = MakeScene(rng, 13, 20.0f, 30.0f, nd);
    for (int variant = 0; variant < 4; ++variant) CHECK(SameAsReference(s, variant, true));
  }
}
