// The nuScenes reader's parts (docs/recorded-data.md, "nuScenes"): PCD v0.7 binary files written
// and read back at every type and size, their header errors, and the interpolation of annotated
// boxes between key frames.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "dualgrid/recorded/pcd.hpp"
#include "nuscenes_annotations.hpp"

using namespace dualgrid;
using namespace dualgrid::recorded;
namespace fs = std::filesystem;

namespace {

fs::path TempFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dualgrid_test_nuscenes_parts";
  fs::create_directories(dir);
  return dir / name;
}

std::string ReadAll(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void WriteAll(const fs::path& f, const std::string& s) {
  std::ofstream out(f, std::ios::binary);
  out << s;
}

PcdCloud EveryType() {
  PcdCloud c;
  c.fields = {{"f4", 'F', 4}, {"f8", 'F', 8}, {"i1", 'I', 1}, {"i2", 'I', 2},
              {"i4", 'I', 4}, {"i8", 'I', 8}, {"u1", 'U', 1}, {"u8", 'U', 8}};
  c.columns = {{0.1, -3.5}, {0.1, 1e300},      {-128, 127}, {-32768, 1234},
               {-7, 2e9},   {-(1LL << 40), 5}, {0, 255},    {0, 9e15}};
  return c;
}

}  // namespace

TEST_CASE("PCD: every type and size reads back as written") {
  const fs::path f = TempFile("types.pcd");
  WritePcd(f, EveryType());
  const PcdCloud r = ReadPcd(f);
  REQUIRE(r.size() == 2);
  REQUIRE(r.fields.size() == 8);
  CHECK(r.Column("f4")->at(0) == static_cast<double>(0.1f));  // rounded through float32
  CHECK(r.Column("f8")->at(0) == 0.1);                        // exact
  CHECK(r.Column("f8")->at(1) == 1e300);
  CHECK(r.Column("i1")->at(0) == -128);
  CHECK(r.Column("i2")->at(1) == 1234);
  CHECK(r.Column("i4")->at(1) == 2e9);
  CHECK(r.Column("i8")->at(0) == -(1LL << 40));
  CHECK(r.Column("u1")->at(1) == 255);
  CHECK(r.Column("u8")->at(1) == 9e15);
  CHECK(r.Column("missing") == nullptr);
}

TEST_CASE("PCD: NaN travels; trailing bytes are allowed, missing ones are not") {
  PcdCloud c;
  c.fields = {{"x", 'F', 4}};
  c.columns = {{std::numeric_limits<double>::quiet_NaN(), 2.0}};
  const fs::path f = TempFile("nan.pcd");
  WritePcd(f, c);
  const PcdCloud r = ReadPcd(f);
  CHECK(std::isnan(r.columns[0][0]));
  CHECK(r.columns[0][1] == 2.0);
  std::string bytes = ReadAll(f);
  WriteAll(f, bytes + "extra");
  CHECK(ReadPcd(f).size() == 2);
  WriteAll(f, bytes.substr(0, bytes.size() - 3));  // the newline and 2 of the last 4 bytes
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("fewer than its POINTS"));
}

TEST_CASE("PCD: header errors name the key") {
  const fs::path f = TempFile("bad.pcd");
  const std::string good = ReadAll([&] {
    WritePcd(f, EveryType());
    return f;
  }());
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    WriteAll(f, s);
  };
  with("DATA binary", "DATA ascii");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("header key 'DATA'"));
  with("HEIGHT 1", "HEIGHT 2");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("header key 'HEIGHT'"));
  with("POINTS 2", "POINTS 3");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("header key 'POINTS'"));
  with("COUNT 1 1", "COUNT 2 1");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("header key 'COUNT'"));
  with("SIZE 4 8", "SIZE 3 8");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("field 'f4' has type F"));
  WriteAll(f, "not a pcd file\n");
  CHECK_THROWS_WITH(ReadPcd(f), Catch::Contains("header key 'DATA' is missing"));
}

TEST_CASE("Annotations: linear in position and velocity, the short way round in yaw") {
  nuscenes::Instance in;
  in.token = "car";
  in.category = "vehicle.car";
  NuScenesAnnotation a, b;
  a.timestamp_us = 1'000'000;
  a.center = {0.0, 0.0};
  a.yaw = kPi - 0.1;
  a.velocity = {10.0, 0.0};
  a.length = 4.0;
  a.width = 2.0;
  b = a;
  b.timestamp_us = 1'500'000;
  b.center = {5.0, 1.0};
  b.yaw = -kPi + 0.1;  // 0.2 rad further, across the +-pi seam
  b.velocity = {10.0, 4.0};
  b.length = 5.0;
  in.keys = {a, b};
  const auto mid = nuscenes::Interpolate(in, 1'250'000);
  REQUIRE(mid);
  CHECK(mid->box.center.x() == Approx(2.5));
  CHECK(mid->box.center.y() == Approx(0.5));
  CHECK(std::abs(WrapAngle(mid->box.yaw - kPi)) < 1e-12);  // through pi, not through 0
  CHECK(mid->velocity.y() == Approx(2.0));
  CHECK(mid->box.length == 5.0);  // the later annotation's size
  CHECK(mid->id == "car");
  CHECK_FALSE(nuscenes::Interpolate(in, 999'999));  // outside the annotated span
  CHECK_FALSE(nuscenes::Interpolate(in, 1'500'001));
  // A key without the devkit's velocity (NaN) takes the segment's.
  in.keys[0].velocity = Velocity::Constant(std::numeric_limits<double>::quiet_NaN());
  const auto start = nuscenes::Interpolate(in, 1'000'000);
  REQUIRE(start);
  CHECK(start->velocity.x() == Approx(10.0));  // (5 - 0) / 0.5 s
  CHECK(start->velocity.y() == Approx(2.0));
}
