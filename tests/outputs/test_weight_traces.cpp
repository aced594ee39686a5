// The weight traces' sums over the vehicles' boxes (outputs/weight_traces.hpp): one pass over the
// particles gives each box the bits a pass per box gives (the sums in the particles' order), for
// overlapping boxes, turned boxes, boxes sharing x buckets and particles on their edges.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "dualgrid/outputs/weight_traces.hpp"

using dualgrid::BoxTest;
using dualgrid::OrientedBox;
using dualgrid::Position;
using dualgrid::Velocity;
using dualgrid::filter::ParticleSet;
using dualgrid::outputs::BoxWeights;
using dualgrid::outputs::SumBoxWeights;
using dualgrid::outputs::WeightTrace;

namespace {

// The reference: one pass over every particle per box, the box test alone.
void SumPerBox(const ParticleSet& p, std::vector<BoxWeights>& boxes) {
  for (BoxWeights& b : boxes) {
    const BoxTest test(b.box);
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (!test.Contains(Position(p.x[i], p.y[i]))) continue;
      b.wp += p.w_position[i];
      b.wv += p.w_velocity[i];
      b.w += p.weight[i];
      if ((Velocity(p.vx[i], p.vy[i]) - b.velocity).norm() < WeightTrace::kGoodVelocity) {
        b.wp_good += p.w_position[i];
        b.wv_good += p.w_velocity[i];
      }
    }
  }
}

}  // namespace

TEST_CASE("the boxes' weight sums of one pass equal a pass per box, bit for bit", "[outputs]") {
  std::mt19937_64 rng(GENERATE(1u, 2u, 3u));
  std::uniform_real_distribution<double> x(-60.0, 140.0), y(-12.0, 12.0), v(-30.0, 30.0),
      w(0.0, 1e-3), yaw(-3.2, 3.2), len(3.0, 18.0);
  ParticleSet p;
  p.resize(20000);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.x[i] = x(rng);
    p.y[i] = y(rng);
    p.vx[i] = static_cast<float>(v(rng));
    p.vy[i] = static_cast<float>(0.2 * v(rng));
    p.w_position[i] = static_cast<float>(w(rng));
    p.w_velocity[i] = static_cast<float>(w(rng));
    p.weight[i] = static_cast<float>(w(rng));
  }
  std::vector<BoxWeights> boxes;
  for (int k = 0; k < 25; ++k) {
    const double cx = x(rng), cy = y(rng);
    boxes.push_back({OrientedBox{Position(cx, cy), yaw(rng), len(rng), 2.8},
                     Velocity(p.vx[static_cast<std::size_t>(k)], 0.0)});
    // Its twin, shifted by less than a bucket: the two share particles and buckets.
    boxes.push_back(
        {OrientedBox{Position(cx + 1.3, cy - 0.4), 0.1, 5.5, 2.8}, Velocity(20.0, 0.0)});
  }
  // Particles exactly on a box's corner and edge (Contains keeps them).
  const auto corners = boxes[0].box.Corners();
  p.x[0] = corners[0].x();
  p.y[0] = corners[0].y();
  p.x[1] = boxes[3].box.center.x();
  p.y[1] = boxes[3].box.center.y();
  std::vector<BoxWeights> one_pass = boxes, per_box = boxes;
  SumBoxWeights(p, one_pass);
  SumPerBox(p, per_box);
  int with_particles = 0;
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    INFO("box " << k);
    CHECK(one_pass[k].wp == per_box[k].wp);
    CHECK(one_pass[k].wv == per_box[k].wv);
    CHECK(one_pass[k].w == per_box[k].w);
    CHECK(one_pass[k].wp_good == per_box[k].wp_good);
    CHECK(one_pass[k].wv_good == per_box[k].wv_good);
    with_particles += per_box[k].w > 0.0;
  }
  CHECK(with_particles > 40);  // the boxes hold particles: the comparison means something
}

TEST_CASE("no boxes, no particles", "[outputs]") {
  std::vector<BoxWeights> none;
  ParticleSet p;
  p.resize(3);
  SumBoxWeights(p, none);
  CHECK(none.empty());
  std::vector<BoxWeights> one = {{OrientedBox{Position(0, 0), 0.0, 4.0, 2.0}, Velocity(0, 0)}};
  SumBoxWeights(ParticleSet{}, one);
  CHECK(one[0].w == 0.0);
}
