#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "dualgrid/core/random.hpp"
#include "dualgrid/eval/clustering.hpp"

using dualgrid::CounterRng;
using dualgrid::Position;
using dualgrid::RngPurpose;
using dualgrid::Velocity;
using dualgrid::eval::Cluster;
using dualgrid::eval::DbscanParams;
using dualgrid::eval::kNoise;
using dualgrid::eval::ParticleClusterer;
using dualgrid::eval::WeightedParticle;

TEST_CASE("Clusters carry weighted means, size and bounding box", "[clustering]") {
  const std::vector<WeightedParticle> particles = {
      {{0.0, 0.0}, {10.0, 0.0}, 1.0},
      {{0.5, 0.0}, {12.0, 0.0}, 3.0},
      {{0.5, 0.5}, {10.0, 2.0}, 0.0},
      {{50.0, 50.0}, {0.0, 0.0}, 5.0},  // isolated: noise, must not leak into any mean
      {{20.0, 0.0}, {-5.0, 1.0}, 2.0},
      {{20.0, 0.5}, {-5.0, 1.0}, 2.0},
      {{20.5, 0.0}, {-7.0, 1.0}, 4.0},
  };
  ParticleClusterer clusterer;
  const std::vector<Cluster> clusters = clusterer.Run(particles);
  REQUIRE(clusters.size() == 2);
  CHECK(clusterer.labels()[3] == kNoise);
  const Cluster& a = clusters[0];
  CHECK(a.size == 3);
  CHECK(a.weight == Approx(4.0));
  // (1*(0,0) + 3*(0.5,0) + 0*(0.5,0.5)) / 4
  CHECK(a.position.x() == Approx(0.375));
  CHECK(a.position.y() == Approx(0.0).margin(1e-12));
  CHECK(a.velocity.x() == Approx((10.0 + 36.0) / 4.0));
  CHECK(a.velocity.y() == Approx(0.0).margin(1e-12));
  CHECK(a.min == Position(0.0, 0.0));
  CHECK(a.max == Position(0.5, 0.5));
  const Cluster& b = clusters[1];
  CHECK(b.size == 3);
  CHECK(b.position.x() == Approx((40.0 + 40.0 + 82.0) / 8.0));
  CHECK(b.position.y() == Approx(1.0 / 8.0));
  CHECK(b.velocity.x() == Approx((-10.0 - 10.0 - 28.0) / 8.0));
  CHECK(b.velocity.y() == Approx(1.0));
}

TEST_CASE("Weighted mean of a cluster lies within its bounding box", "[clustering]") {
  const std::uint64_t seed = GENERATE(range(1, 11));
  CounterRng rng(seed, RngPurpose::kTest, 0, 0);
  std::vector<WeightedParticle> particles(200);
  for (auto& p : particles) {
    p.position = Position(rng.Normal(0.0, 1.0), rng.Normal(0.0, 0.5));
    p.velocity = Velocity(rng.Normal(20.0, 1.0), rng.Normal(0.0, 1.0));
    p.weight = rng.Uniform();
  }
  ParticleClusterer clusterer;
  const auto clusters = clusterer.Run(particles);
  int members = 0;
  for (const Cluster& c : clusters) {
    members += c.size;
    CHECK((c.position.array() >= c.min.array() - 1e-12).all());
    CHECK((c.position.array() <= c.max.array() + 1e-12).all());
  }
  int labelled = 0;
  for (const int l : clusterer.labels()) labelled += l != kNoise;
  CHECK(members == labelled);
}

TEST_CASE("Zero total weight falls back to the plain mean", "[clustering]") {
  const std::vector<WeightedParticle> particles = {
      {{0.0, 0.0}, {1.0, 0.0}, 0.0}, {{1.0, 0.0}, {3.0, 0.0}, 0.0}, {{0.5, 0.6}, {2.0, 3.0}, 0.0}};
  ParticleClusterer clusterer;
  const auto clusters = clusterer.Run(particles);
  REQUIRE(clusters.size() == 1);
  CHECK(clusters[0].position.x() == Approx(0.5));
  CHECK(clusters[0].position.y() == Approx(0.2));
  CHECK(clusters[0].velocity.x() == Approx(2.0));
  CHECK(clusters[0].velocity.y() == Approx(1.0));
}

TEST_CASE("Negative or non-finite weights are rejected", "[clustering]") {
  ParticleClusterer clusterer;
  const double bad = GENERATE(-1.0, std::numeric_limits<double>::quiet_NaN());
  const std::vector<WeightedParticle> particles = {{{0.0, 0.0}, {0.0, 0.0}, bad}};
  CHECK_THROWS_AS(clusterer.Run(particles), std::invalid_argument);
}

TEST_CASE("The first bad particle is named; weights in [0, max] and finite velocities pass",
          "[clustering]") {
  // TakeParticles checks without a branch per particle and walks a bad set again for the
  // message: the index must be the first bad one, a weight fault must win over a velocity fault
  // of the same particle, and the boundary values must pass.
  constexpr double kMax = std::numeric_limits<double>::max();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<WeightedParticle> good;
  for (int i = 0; i < 7; ++i) good.push_back({Position(0.3 * i, 0), Velocity(1, 0), 1.0});
  good[1].weight = 0.0;
  good[2].weight = -0.0;
  good[3].weight = kMax;
  good[4].velocity = Velocity(kMax, -kMax);
  ParticleClusterer clusterer;
  CHECK_NOTHROW(clusterer.Run(good));
  const int first = GENERATE(0, 3, 6);
  const auto message = [&](const std::vector<WeightedParticle>& particles) -> std::string {
    try {
      clusterer.Run(particles);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no throw";
  };
  for (const double w : {-1.0, -kMax, kInf, kNaN}) {
    auto bad = good;
    bad[first].weight = w;
    bad[first].velocity = Velocity(kNaN, 0);  // the weight is reported first
    if (first + 1 < 7) bad[first + 1].velocity = Velocity(0, kInf);
    INFO("weight " << w << " at " << first);
    const std::string m = message(bad);
    CHECK(m.find("particle " + std::to_string(first) + " has weight") != std::string::npos);
  }
  for (const Velocity& v : {Velocity(kNaN, 0), Velocity(0, -kInf), Velocity(kInf, kInf)}) {
    auto bad = good;
    bad[first].velocity = v;
    if (first + 1 < 7) bad[first + 1].weight = -1.0;
    INFO("velocity " << v.transpose() << " at " << first);
    const std::string m = message(bad);
    CHECK(m.find("particle " + std::to_string(first) + " has a non-finite velocity") !=
          std::string::npos);
  }
}

TEST_CASE("ParticleClusterer drops clusters below the minimum mass", "[eval][clustering]") {
  // Two blobs of 5 particles 10 m apart, weights 0.1 and 1.0 each: masses 0.5 and 5.0.
  std::vector<WeightedParticle> particles;
  for (int i = 0; i < 5; ++i) particles.push_back({Position(0.1 * i, 0), Velocity(1, 0), 0.1});
  for (int i = 0; i < 5; ++i) particles.push_back({Position(10 + 0.1 * i, 0), Velocity(2, 0), 1.0});
  ParticleClusterer all(DbscanParams{}, 0.0), heavy(DbscanParams{}, 1.0);
  CHECK(all.Run(particles).size() == 2);
  const auto kept = heavy.Run(particles);
  REQUIRE(kept.size() == 1);
  CHECK(kept[0].weight == Approx(5.0));
  CHECK(kept[0].velocity.x() == Approx(2.0));
  CHECK(heavy.labels()[0] == kNoise);
  CHECK(heavy.labels()[9] == 0);
  CHECK_THROWS_AS(ParticleClusterer(DbscanParams{}, -1.0), std::invalid_argument);
}

TEST_CASE("Cluster sums equal a particle-by-particle reference bit for bit", "[clustering]") {
  // Three blobs whose particles come interleaved (runs of one) or blob by blob (long runs), and
  // one blob of zero weights (plain means): every field as the reference sums it, in input order.
  const bool interleaved = GENERATE(false, true);
  std::vector<WeightedParticle> particles;
  for (int i = 0; i < 90; ++i) {
    const int blob = interleaved ? i % 3 : i / 30;
    const double u = 0.013 * i, w = blob == 2 ? 0.0 : 0.1 + 0.37 * ((i * 7) % 11);
    particles.push_back({Position(10.0 * blob + std::sin(u), std::cos(3.0 * u)),
                         Velocity(1.0 + u, -2.0 * blob + 0.1 * u), w});
  }
  ParticleClusterer clusterer;
  const std::vector<Cluster> clusters = clusterer.Run(particles);
  REQUIRE(clusters.size() == 3);
  const std::span<const int> labels = clusterer.labels();
  for (int c = 0; c < 3; ++c) {
    Cluster ref;
    ref.min = Position::Constant(std::numeric_limits<double>::infinity());
    ref.max = -ref.min;
    Position plain_p = Position::Zero();
    Velocity plain_v = Velocity::Zero();
    for (std::size_t i = 0; i < particles.size(); ++i) {
      if (labels[i] != c) continue;
      const WeightedParticle& p = particles[i];
      ref.position += p.weight * p.position;
      ref.velocity += p.weight * p.velocity;
      ref.weight += p.weight;
      ++ref.size;
      ref.min = ref.min.cwiseMin(p.position);
      ref.max = ref.max.cwiseMax(p.position);
      plain_p += p.position;
      plain_v += p.velocity;
    }
    if (ref.weight > 0.0) {
      ref.position /= ref.weight;
      ref.velocity /= ref.weight;
    } else {
      ref.position = plain_p / ref.size;
      ref.velocity = plain_v / ref.size;
    }
    CHECK(ref.size == 30);
    CHECK(clusters[c].position == ref.position);
    CHECK(clusters[c].velocity == ref.velocity);
    CHECK(clusters[c].weight == ref.weight);
    CHECK(clusters[c].size == ref.size);
    CHECK(clusters[c].min == ref.min);
    CHECK(clusters[c].max == ref.max);
  }
}
