// WeighParticles (dualgrid/filter/weigh_particles.hpp) against its version before Nearest's two
// running minima (reference/weigh_particles.cpp), bit for bit: the stored weights and the cell's
// sums.
// Random cells with detections exactly at the cutoff, ties (two detections at one position),
// particles on the grid's edge (coordinates near 0), cells larger than a vector and tails.
// CandidateIndex against a brute-force scan: every detection within the cutoff of a particle is
// among its cell's candidates.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <set>
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
                  {},
                  3,
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

namespace {

// Squared distance [m^2] as WeighParticles computes it (float, the same operations).
float Distance2(float dx, float dy, float px, float py) {
  const float ex = dx - px, ey = dy - py;
  return ex * ex + ey * ey;
}

struct IndexCase {
  int nx, ny;
  double r, cutoff;
};

// Detections around (and some beyond) an nx x ny grid: uniform, clustered, exactly at the
// cutoff from a particle (one float step either side), on cell edges. Returns the index's misses
// (a detection within the cutoff of a particle but not among its cell's candidates) and counts
// the candidates and the detections within the cutoff.
int Misses(const IndexCase& g, std::mt19937& rng, long& candidates, long& within) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double w = g.nx * g.r, h = g.ny * g.r, x0 = 1000.0 * g.r, y0 = -300.0 * g.r;
  const float inv_r = static_cast<float>(1.0 / g.r);
  const float cutoff2 = static_cast<float>(g.cutoff * g.cutoff);
  // Particles: uniform over the grid and on cell edges, in the sort's cells.
  std::vector<float> px, py;
  for (int i = 0; i < 400; ++i) {
    float x = static_cast<float>(u(rng) * w), y = static_cast<float>(u(rng) * h);
    if (i % 4 == 1) x = static_cast<float>(std::floor(u(rng) * g.nx) * g.r);
    if (i % 4 == 2) y = std::nextafter(static_cast<float>(std::ceil(u(rng) * g.ny) * g.r), 0.0f);
    const float fx = std::floor(x * inv_r), fy = std::floor(y * inv_r);
    if (!(fx >= 0.0f && fy >= 0.0f && fx < g.nx && fy < g.ny)) continue;  // off the grid
    px.push_back(x);
    py.push_back(y);
  }
  std::vector<double> dx, dy;
  for (int k = 0; k < 300; ++k) {
    double x = (u(rng) * 1.2 - 0.1) * w, y = (u(rng) * 1.2 - 0.1) * h;
    if (k % 3 == 1) {  // at the cutoff from a particle, along an axis or a diagonal
      const std::size_t i = std::uniform_int_distribution<std::size_t>(0, px.size() - 1)(rng);
      const double ang = 0.7853981633974483 * std::floor(u(rng) * 8.0);
      x = px[i] + g.cutoff * std::cos(ang);
      y = py[i] + g.cutoff * std::sin(ang);
      const int nudge = static_cast<int>(u(rng) * 3.0) - 1;
      float fx = static_cast<float>(x);
      if (nudge != 0) fx = std::nextafter(fx, nudge * 1e30f);
      x = fx;
    }
    if (k % 7 == 3) x = std::floor(u(rng) * g.nx) * g.r;  // on a cell edge
    dx.push_back(x0 + x);
    dy.push_back(y0 + y);
  }
  const std::int64_t n = static_cast<std::int64_t>(dx.size());
  std::vector<int> item(dx.size());
  std::iota(item.begin(), item.end(), 100);
  std::shuffle(item.begin(), item.end(), rng);
  dualgrid::filter::detail::CandidateIndex index;
  index.Configure(g.nx, g.ny, g.r, g.cutoff, dx.size());
  std::vector<float> cx(dx.size()), cy(dx.size());
  index.Fill(dx.data(), dy.data(), item.data(), n, x0, y0, cx.data(), cy.data());
  // Candidate order is a permutation of the input with its positions.
  std::vector<int> seen(index.items(), index.items() + n);
  std::sort(seen.begin(), seen.end());
  for (std::int64_t k = 0; k < n; ++k) REQUIRE(seen[k] == 100 + k);
  for (std::int64_t k = 0; k < n; ++k) {
    const int j = index.items()[k] - 100;
    const auto at = std::find(item.begin(), item.end(), index.items()[k]) - item.begin();
    REQUIRE(j >= 0);
    REQUIRE(cx[k] == static_cast<float>(dx[at] - x0));
    REQUIRE(cy[k] == static_cast<float>(dy[at] - y0));
  }
  int misses = 0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    std::int64_t cand[dualgrid::filter::detail::kMaxRanges][2];
    const int ranges = index.Ranges(static_cast<int>(std::floor(px[i] * inv_r)),
                                    static_cast<int>(std::floor(py[i] * inv_r)), cand);
    REQUIRE(ranges >= 0);
    REQUIRE(ranges <= dualgrid::filter::detail::kMaxRanges);
    std::set<int> mine;
    for (int r = 0; r < ranges; ++r) {
      REQUIRE(0 <= cand[r][0]);
      REQUIRE(cand[r][0] < cand[r][1]);  // non-empty
      REQUIRE(cand[r][1] <= n);
      for (std::int64_t k = cand[r][0]; k < cand[r][1]; ++k) mine.insert(index.items()[k]);
    }
    candidates += static_cast<long>(mine.size());
    for (std::int64_t k = 0; k < n; ++k) {
      if (!(Distance2(cx[k], cy[k], px[i], py[i]) < cutoff2)) continue;
      ++within;
      misses += mine.count(index.items()[k]) ? 0 : 1;
    }
  }
  return misses;
}

}  // namespace

TEST_CASE("CandidateIndex: every detection within the cutoff is a candidate", "[filter][weigh]") {
  std::mt19937 rng(2611);
  // The highway's grid, finer cells than the cutoff (larger buckets), a cutoff under one cell.
  for (const IndexCase g : {IndexCase{400, 50, 0.5, 1.8}, IndexCase{60, 90, 0.1, 1.8},
                            IndexCase{30, 20, 1.0, 0.4}, IndexCase{1, 7, 0.5, 1.8}}) {
    long candidates = 0, within = 0;
    int misses = 0;
    for (int trial = 0; trial < 5; ++trial) misses += Misses(g, rng, candidates, within);
    INFO(g.nx << " x " << g.ny << " cells of " << g.r << " m, cutoff " << g.cutoff << ": " << within
              << " pairs within the cutoff, " << candidates << " candidates");
    CHECK(within > 0);
    CHECK(misses == 0);
    // The buckets prune: fewer candidates than all detections for every particle (300 each).
    if (g.nx * g.r > 8.0 * g.cutoff) CHECK(candidates < 2000L * 300L / 4);
  }
}

TEST_CASE("CandidateIndex: a grid or cutoff out of range is refused", "[filter][weigh]") {
  dualgrid::filter::detail::CandidateIndex index;
  CHECK_THROWS_AS(index.Configure(0, 5, 0.5, 1.8, 10), std::invalid_argument);
  CHECK_THROWS_AS(index.Configure(5, 5, 0.0, 1.8, 10), std::invalid_argument);
  CHECK_THROWS_AS(index.Configure(5, 5, 0.5, std::nan(""), 10), std::invalid_argument);
  CHECK_NOTHROW(index.Configure(5, 5, 0.5, 1.8, 0));
}
