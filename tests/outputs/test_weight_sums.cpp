// The weight traces' sums (outputs/weight_traces.hpp, SumWeightsInBoxes): one pass over the
// particles with boxes looked up by x strip gives the same bits as the plain loop over every
// particle for each box, for overlapping, turned, long, tiny and empty boxes.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "dualgrid/outputs/weight_traces.hpp"

using namespace dualgrid;
using outputs::BoxWeights;

namespace {

// The definition: every particle against every box, in ascending particle order.
BoxWeights Reference(const filter::ParticleSet& p, const OrientedBox& box, const Velocity& v) {
  BoxWeights b;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!box.Contains(Position(p.x[i], p.y[i]))) continue;
    b.position += p.w_position[i];
    b.velocity += p.w_velocity[i];
    b.weight += p.weight[i];
    if ((Velocity(p.vx[i], p.vy[i]) - v).norm() < outputs::WeightTrace::kGoodVelocity) {
      b.position_good += p.w_position[i];
      b.velocity_good += p.w_velocity[i];
    }
  }
  return b;
}

}  // namespace

TEST_CASE("weight sums over boxes equal one plain pass per box, bit for bit", "[outputs]") {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto u = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  std::vector<OrientedBox> boxes;
  std::vector<Velocity> velocities;
  for (int k = 0; k < 14; ++k) {  // cars and trucks along a 300 m road, some overlapping
    boxes.push_back(
        {Position(u(-150.0, 150.0), u(-8.0, 8.0)), u(-0.4, 0.4), u(4.0, 18.0), u(2.0, 3.5)});
    velocities.push_back(Velocity(u(-30.0, 30.0), u(-2.0, 2.0)));
  }
  boxes.push_back({Position(10.0, 1.0), 1.3, 5.0, 2.5});   // turned across the road
  boxes.push_back({boxes[0].center, 0.2, 3.0, 1.0});       // inside another box
  boxes.push_back({Position(0.3, 0.2), 0.0, 1e-3, 1e-3});  // tiny: a particle or none
  boxes.push_back({Position(900.0, 0.0), 0.0, 5.0, 2.0});  // far from every particle
  for (int k = 0; k < 4; ++k) velocities.push_back(Velocity(u(-30.0, 30.0), 0.0));
  filter::ParticleSet p;
  for (int i = 0; i < 20000; ++i) {
    // Most particles near a box (as the filter's dynamic particles are), the rest anywhere.
    const OrientedBox& near =
        boxes[static_cast<std::size_t>(i) % (boxes.size() - 1)];  // not the far one
    const bool anywhere = i % 5 == 0;
    p.x.push_back(anywhere ? u(-160.0, 160.0) : near.center.x() + u(-10.0, 10.0));
    p.y.push_back(anywhere ? u(-12.0, 12.0) : near.center.y() + u(-3.0, 3.0));
    p.vx.push_back(static_cast<float>(u(-35.0, 35.0)));
    p.vy.push_back(static_cast<float>(u(-3.0, 3.0)));
    p.w_position.push_back(static_cast<float>(u(0.0, 1e-3)));
    p.w_velocity.push_back(static_cast<float>(u(0.0, 1e-3)));
    p.weight.push_back(static_cast<float>(u(0.0, 1e-3)));
  }
  p.x.push_back(0.3);  // on the tiny box's centre
  p.y.push_back(0.2);
  for (auto* column : {&p.vx, &p.vy, &p.w_position, &p.w_velocity, &p.weight})
    column->push_back(0.5f);
  const std::vector<BoxWeights> sums = outputs::SumWeightsInBoxes(p, boxes, velocities);
  REQUIRE(sums.size() == boxes.size());
  int with_particles = 0, with_good = 0;
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    INFO("box " << k);
    const BoxWeights want = Reference(p, boxes[k], velocities[k]);
    CHECK(sums[k].position == want.position);  // exact: the same additions in the same order
    CHECK(sums[k].velocity == want.velocity);
    CHECK(sums[k].weight == want.weight);
    CHECK(sums[k].position_good == want.position_good);
    CHECK(sums[k].velocity_good == want.velocity_good);
    with_particles += want.weight > 0;
    with_good += want.position_good > 0;
  }
  // The case tests something: most boxes hold particles, some of them good ones, one none.
  CHECK(with_particles >= 15);
  CHECK(with_good >= 5);
  CHECK(sums.back().weight == 0.0);
  CHECK(sums[boxes.size() - 2].weight == 0.5f);  // the tiny box holds its one particle
  CHECK(outputs::SumWeightsInBoxes(p, {}, {}).empty());
}
