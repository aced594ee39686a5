// The replay writer (outputs/recording.hpp) compresses and appends frames on the run's output
// worker while the run goes on: the frames read back in the order added and equal to what was
// added, the same bytes with the worker on its own thread or in line, and a failed write still
// reaches the caller (from a later Add or from Finish), naming the file.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "dualgrid/outputs/recording.hpp"

namespace fs = std::filesystem;
using namespace dualgrid::outputs::replay;
using dualgrid::outputs::OutputWorker;

namespace {

constexpr int kCellsX = 40, kCellsY = 30;

Header TestHeader() {
  Header h;
  h.scenario = "writer_test";
  h.modes = {"position", "dual"};
  h.sensors = {"front"};
  h.cells_x = kCellsX;
  h.cells_y = kCellsY;
  h.resolution = 0.5;
  h.max_particles = 1000;
  return h;
}

// Frame k: every value a function of (k, mode, cell), scrambled so that zlib cannot shrink it
// much (a frame of ~14 kB then passes the file stream's buffer on every write).
Frame TestFrame(int k) {
  Frame f;
  f.time = 0.5 * (k + 1);
  f.ego = {-1, 10.0 + k, 2.0, 0.0, 4.5, 1.8, 20.0, 0.0};
  f.truth.push_back({7, 30.0 + k, 1.5, 0.1, 4.0, 1.8, 25.0, 0.5});
  f.detections.push_back({0, 12.3 + k, 0.4, 1.5, -0.2, false, 0});
  std::uint32_t state = 2654435761u * static_cast<std::uint32_t>(k + 1);
  const auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  const std::size_t n = static_cast<std::size_t>(kCellsX) * kCellsY;
  for (int m = 0; m < 2; ++m) {
    ModeFrame mf;
    for (std::size_t c = 0; c < n; ++c) {
      mf.free.push_back(static_cast<std::uint8_t>(next()));
      mf.static_occ.push_back(static_cast<std::uint8_t>(next()));
      mf.dynamic.push_back(static_cast<std::uint8_t>(next()));
      mf.vx_cm.push_back(static_cast<std::int16_t>(next() % 4000) - 2000);
      mf.vy_cm.push_back(static_cast<std::int16_t>(next() % 4000) - 2000);
    }
    for (int p = 0; p < 200; ++p) mf.particles.push_back(static_cast<std::uint16_t>(next() % 2000));
    mf.live.in_grid = k + m;
    f.modes.push_back(mf);
  }
  return f;
}

fs::path FreshDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("dualgrid_writer_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

std::string Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_CASE("the replay writer's frames read back in order, equal to those added", "[replay]") {
  const bool threaded = GENERATE(true, false);
  const fs::path run = FreshDir(threaded ? "order_thread" : "order_inline");
  // More frames than may be in flight: Add waits for the oldest on the way.
  constexpr int kFrames = 2 * static_cast<int>(Writer::kFramesInFlight) + 3;
  {
    OutputWorker worker(threaded, 2);
    Writer w(run / "replay", TestHeader(), worker);
    for (int k = 0; k < kFrames; ++k) {
      w.Add(TestFrame(k));
      CHECK(w.frames() == static_cast<std::size_t>(k + 1));
    }
    Header done = TestHeader();
    done.complete = true;
    w.Finish(done);
  }
  const Reader r(run);
  REQUIRE(r.size() == kFrames);
  CHECK(r.header().complete);
  for (int k = 0; k < kFrames; ++k) {
    const Frame want = TestFrame(k);
    const Frame got = r.Load(static_cast<std::size_t>(k));
    CHECK(got.time == Approx(want.time));
    CHECK(got.ego.x == Approx(want.ego.x));
    REQUIRE(got.modes.size() == want.modes.size());
    for (std::size_t m = 0; m < want.modes.size(); ++m) {
      CHECK(got.modes[m].free == want.modes[m].free);
      CHECK(got.modes[m].dynamic == want.modes[m].dynamic);
      CHECK(got.modes[m].vx_cm == want.modes[m].vx_cm);
      CHECK(got.modes[m].particles == want.modes[m].particles);
      CHECK(got.modes[m].live.in_grid == want.modes[m].live.in_grid);
    }
  }
  fs::remove_all(run);
}

TEST_CASE("the replay writer writes the same bytes on the worker's thread as in line", "[replay]") {
  const fs::path a = FreshDir("bytes_thread"), b = FreshDir("bytes_inline");
  for (const bool threaded : {true, false}) {
    OutputWorker worker(threaded);
    Writer w((threaded ? a : b) / "replay", TestHeader(), worker);
    for (int k = 0; k < 11; ++k) w.Add(TestFrame(k));
    w.Finish(TestHeader());
  }
  CHECK(Bytes(a / "replay" / "frames.bin") == Bytes(b / "replay" / "frames.bin"));
  CHECK(Bytes(a / "replay" / "index.json") == Bytes(b / "replay" / "index.json"));
  CHECK_FALSE(Bytes(a / "replay" / "frames.bin").empty());
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST_CASE("a failed write of the recording reaches the caller, naming frames.bin", "[replay]") {
  REQUIRE(fs::exists("/dev/full"));  // Linux: every write to it fails with ENOSPC
  const fs::path run = FreshDir("full");
  fs::create_directories(run / "replay");
  fs::create_symlink("/dev/full", run / "replay" / "frames.bin");
  std::string error;
  try {
    OutputWorker worker(true);
    Writer w(run / "replay", TestHeader(), worker);
    for (int k = 0; k < 3; ++k) w.Add(TestFrame(k));
    w.Finish(TestHeader());
  } catch (const std::runtime_error& e) {
    error = e.what();
  }
  CHECK(error.find("frames.bin") != std::string::npos);
  CHECK_FALSE(fs::exists(run / "replay" / "index.json"));
  fs::remove_all(run);
}

TEST_CASE("a failed frame's error comes from the Add that waits for it", "[replay]") {
  REQUIRE(fs::exists("/dev/full"));
  const bool threaded = GENERATE(true, false);
  const fs::path run = FreshDir(threaded ? "late_thread" : "late_inline");
  fs::create_directories(run / "replay");
  fs::create_symlink("/dev/full", run / "replay" / "frames.bin");
  OutputWorker worker(threaded);
  Writer w(run / "replay", TestHeader(), worker);
  // Frame 0 fails; Add waits for it once kFramesInFlight frames are in flight, on either thread.
  std::size_t added = 0;
  std::string error;
  try {
    for (; added < 3 * Writer::kFramesInFlight; ++added) w.Add(TestFrame(static_cast<int>(added)));
  } catch (const std::runtime_error& e) {
    error = e.what();
  }
  CHECK(added == Writer::kFramesInFlight);
  CHECK(error.find("frames.bin") != std::string::npos);
  fs::remove_all(run);
}
