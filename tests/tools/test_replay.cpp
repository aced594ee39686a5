// The replay (issue 15, docs/replay.md): a run records its frames; the recording, decoded here
// independently from the documented format, agrees with the run's own outputs; `replay` turns it
// into an H.264 video whose frames show the run, and into the viewer page; bad input gets one-line
// errors with exit code 2.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "dualgrid/viz/replay_frame.hpp"

using namespace dualgrid::testing;
using nlohmann::json;

namespace {

// The decoded dense data of one frame, per mode (docs/replay.md, "Format").
struct Dense {
  std::vector<std::vector<std::int16_t>> vx, vy;
  std::vector<std::vector<std::uint16_t>> particles;
  std::vector<std::vector<std::uint8_t>> free, stat, dyn;
};

Dense Decode(const json& index, const std::string& bin, std::size_t i) {
  const json& f = index["frames"][i];
  const std::size_t n = index["cells_x"].get<std::size_t>() * index["cells_y"].get<std::size_t>();
  const std::size_t modes = index["modes"].size();
  std::size_t raw_size = 0;
  for (const json& m : f["modes"]) raw_size += 7 * n + 4 * m["np"].get<std::size_t>();
  const auto off = f["blob"][0].get<std::size_t>(), len = f["blob"][1].get<std::size_t>();
  REQUIRE(off + len <= bin.size());
  std::vector<std::uint8_t> raw(raw_size);
  uLongf size = raw_size;
  REQUIRE(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(bin.data() + off), len) ==
          Z_OK);
  REQUIRE(size == raw_size);
  Dense d;
  std::size_t at = 0;
  auto take = [&](auto& v, std::size_t count) {
    v.resize(count);
    std::memcpy(v.data(), raw.data() + at, count * sizeof(v[0]));
    at += count * sizeof(v[0]);
  };
  d.vx.resize(modes), d.vy.resize(modes), d.particles.resize(modes);
  d.free.resize(modes), d.stat.resize(modes), d.dyn.resize(modes);
  for (std::size_t m = 0; m < modes; ++m) {
    take(d.vx[m], n);
    take(d.vy[m], n);
  }
  for (std::size_t m = 0; m < modes; ++m)
    take(d.particles[m], 2 * f["modes"][m]["np"].get<std::size_t>());
  for (std::size_t m = 0; m < modes; ++m) {
    take(d.free[m], n);
    take(d.stat[m], n);
    take(d.dyn[m], n);
  }
  CHECK(at == raw_size);
  return d;
}

// A short highway run with a recording of ten frames per second (the default is two); made once
// for the test cases below.
const fs::path& RecordedRun() {
  static const fs::path dir = [] {
    const fs::path d = TempDir("replay", "run");
    const auto r = Run("run scenarios/highway.yaml --out " + (d / "run").string() +
                       " --duration 4 --figure-formats png --record-interval 0.1 -q");
    INFO(r.output);
    REQUIRE(r.code == 0);
    return d / "run";
  }();
  return dir;
}

// Reads a binary PPM (what ffmpeg writes with -c:v ppm).
struct Ppm {
  int width = 0, height = 0;
  std::string data;
  std::array<int, 3> At(double x, double y) const {
    const std::size_t k = (static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x)) * 3;
    return {static_cast<unsigned char>(data[k]), static_cast<unsigned char>(data[k + 1]),
            static_cast<unsigned char>(data[k + 2])};
  }
};
Ppm ReadPpm(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string magic;
  int maxval = 0;
  Ppm img;
  in >> magic >> img.width >> img.height >> maxval;
  in.get();
  REQUIRE(magic == "P6");
  REQUIRE(maxval == 255);
  img.data.resize(static_cast<std::size_t>(img.width) * img.height * 3);
  in.read(img.data.data(), static_cast<std::streamsize>(img.data.size()));
  REQUIRE(in);
  return img;
}

}  // namespace

TEST_CASE("a run's recording agrees with its ground truth, clusters and per-object counts",
          "[cli][replay]") {
  const fs::path run = RecordedRun();
  const json index = json::parse(Slurp(run / "replay" / "index.json"));
  const std::string bin = Slurp(run / "replay" / "frames.bin");
  CHECK(index["format"] == "dualgrid-replay");
  CHECK(index["version"] == 2);
  CHECK(index["complete"] == true);
  const double interval = index["interval"].get<double>();
  CHECK(interval == Approx(0.1));
  // 4 s at one frame per 0.1 s.
  REQUIRE(index["frames"].size() == 40);
  const std::size_t modes = index["modes"].size();
  REQUIRE(modes == 3);
  // Each frame is in its own grid frame; its turn is grid.csv's at that time.
  std::map<std::string, double> grid_yaw;
  for (const auto& row : ReadCsv(run / "grid.csv"))
    grid_yaw[row.at("time")] = std::stod(row.at("yaw_deg"));

  // Ground truth: every recorded box is the vehicle's ground_truth.csv row at that time, turned
  // into the grid frame.
  std::map<std::pair<std::string, std::string>, std::map<std::string, std::string>> truth;
  for (const auto& row : ReadCsv(run / "ground_truth.csv"))
    truth[{row.at("time"), row.at("id")}] = row;
  std::map<std::pair<std::string, std::string>, int> clusters;  // (time, mode) -> count
  for (const auto& row : ReadCsv(run / "clusters.csv"))
    ++clusters[{row.at("time"), row.at("mode")}];
  int boxes_checked = 0;
  std::size_t clusters_checked = 0;
  for (std::size_t i = 0; i < index["frames"].size(); ++i) {
    const json& f = index["frames"][i];
    CHECK(f["t"].get<double>() == Approx((i + 1) * interval));
    char stamp[16];
    std::snprintf(stamp, sizeof stamp, "%.3f", f["t"].get<double>());
    CHECK(f["yaw"].get<double>() == grid_yaw.at(stamp));
    const double yaw = f["yaw"].get<double>() * M_PI / 180.0;
    for (const json& b : f["truth"]) {
      const std::string name = index["names"][std::to_string(b[0].get<int>())];
      const auto& row = truth.at({stamp, name});
      const double x = std::stod(row.at("x")), y = std::stod(row.at("y"));
      CHECK(b[1].get<double>() == Approx(std::cos(yaw) * x + std::sin(yaw) * y).margin(0.01));
      CHECK(b[2].get<double>() == Approx(-std::sin(yaw) * x + std::cos(yaw) * y).margin(0.01));
      ++boxes_checked;
    }
    for (std::size_t m = 0; m < modes; ++m) {
      CHECK(f["modes"][m]["cl"].size() ==
            static_cast<std::size_t>(clusters[{stamp, index["modes"][m].get<std::string>()}]));
      clusters_checked += f["modes"][m]["cl"].size();
    }
    // Dense data: masses of a cell sum to at most one; each is rounded to 2 per cent (the three
    // then sum to at most 103 %) and then to 1/255 (each byte at most 0.5 above steps x 5.1): at
    // most 103 x 2.55 + 1.5 = 264; every byte decodes to a whole number of 2 % steps (value /
    // 255 rounded to two decimals, docs/replay.md). Velocities are whole 0.2 m/s steps, none
    // where the recording says there is too little dynamic mass.
    const Dense d = Decode(index, bin, i);
    const auto two_percent = [](std::uint8_t b) {
      const long percent = std::lround(b / 2.55);
      return percent % 2 == 0 && std::abs(b - percent * 2.55) <= 0.51;
    };
    for (std::size_t m = 0; m < modes; ++m) {
      CHECK(d.particles[m].size() <= 2 * index["max_particles"].get<std::size_t>());
      for (std::size_t k = 0; k < d.free[m].size(); ++k) {
        REQUIRE(d.free[m][k] + d.stat[m][k] + d.dyn[m][k] <= 264);
        REQUIRE(
            (two_percent(d.free[m][k]) && two_percent(d.stat[m][k]) && two_percent(d.dyn[m][k])));
        REQUIRE((d.vx[m][k] % 20 == 0 && d.vy[m][k] % 20 == 0));
        if (d.dyn[m][k] < 13) REQUIRE((d.vx[m][k] == 0 && d.vy[m][k] == 0));
      }
    }
  }
  CHECK(boxes_checked > 40);
  CHECK(clusters_checked > 40);

  // The live totals of the last frame count every step (not only recorded ones): they are the
  // sums of objects.csv's per-object frame counts.
  const json& last = index["frames"].back();
  for (std::size_t m = 0; m < modes; ++m) {
    long in_grid = 0, tracked = 0, tracked_v = 0;
    for (const auto& row : ReadCsv(run / "objects.csv")) {
      if (row.at("mode") != index["modes"][m].get<std::string>()) continue;
      in_grid += std::stol(row.at("frames_in_grid"));
      tracked += std::stol(row.at("frames_tracked"));
      tracked_v += std::stol(row.at("frames_tracked_v"));
    }
    const json& live = last["modes"][m]["live"];
    INFO("mode " << index["modes"][m]);
    CHECK(live[4].get<long>() == in_grid);
    CHECK(live[5].get<long>() == tracked);
    CHECK(live[6].get<long>() == tracked_v);
    CHECK(in_grid > 0);
  }
}

TEST_CASE("the recording is the same whatever the thread count", "[cli][replay]") {
  const fs::path d = TempDir("replay", "threads");
  for (const char* t : {"1", "2", "4"}) {
    const auto r =
        Run(std::string("run scenarios/highway.yaml --duration 2 --figure-formats png -q") +
            " --threads " + t + " --out " + (d / t).string());
    INFO(r.output);
    REQUIRE(r.code == 0);
  }
  // The frames are taken inside the step's region, each mode's part by either thread.
  for (const char* t : {"2", "4"}) {
    INFO(t << " threads");
    CHECK(Slurp(d / "1" / "replay" / "frames.bin") == Slurp(d / t / "replay" / "frames.bin"));
    CHECK(Slurp(d / "1" / "replay" / "index.json") == Slurp(d / t / "replay" / "index.json"));
  }
  // The defaults (docs/replay.md, "The recording"): two frames per second, 500 particles.
  const json index = json::parse(Slurp(d / "1" / "replay" / "index.json"));
  CHECK(index["interval"].get<double>() == Approx(0.5));
  CHECK(index["max_particles"] == 500);
  CHECK(index["frames"].size() == 4);
}

TEST_CASE("replay: an H.264 video whose frames show the run, a preview and the viewer page",
          "[cli][replay][video]") {
  const fs::path run = RecordedRun();
  const auto r = Run("replay " + run.string() + " --html --video --width 1280 -q");
  INFO(r.output);
  REQUIRE(r.code == 0);
  REQUIRE(fs::exists(run / "replay.mp4"));
  REQUIRE(fs::exists(run / "replay_preview.gif"));
  REQUIRE(fs::exists(run / "replay.html"));
  CHECK_FALSE(fs::exists(run / "replay.mp4.part"));
  const json index = json::parse(Slurp(run / "replay" / "index.json"));

  const auto probe = Shell(
      "ffprobe -v error -select_streams v -count_frames -show_entries "
      "stream=codec_name,width,nb_read_frames -of csv=p=0 " +
      (run / "replay.mp4").string());
  INFO(probe.output);
  REQUIRE(probe.code == 0);
  CHECK(probe.output.rfind("h264,1280,", 0) == 0);
  CHECK(probe.output.find("," + std::to_string(index["frames"].size())) != std::string::npos);

  // Frame 20 decoded: the ego (filled green) sits where the layout puts the ego, and a cell the
  // recording holds as surely free, with free neighbours and nothing drawn over it, is white.
  const fs::path ppm = run / "frame20.ppm";
  const auto x = Shell("ffmpeg -v error -y -i " + (run / "replay.mp4").string() +
                       " -vf 'select=eq(n\\,20)' -frames:v 1 -c:v ppm " + ppm.string());
  INFO(x.output);
  REQUIRE(x.code == 0);
  const Ppm img = ReadPpm(ppm);
  const json& f = index["frames"][20];
  const double ego_x = f["ego"][1], ego_y = f["ego"][2];
  const json& f0 = index["frames"][0];
  dualgrid::viz::ReplayLayoutOptions layout;
  layout.width = 1280;
  const double res = index["resolution"];
  const int nx = index["cells_x"], ny = index["cells_y"];
  const dualgrid::Position lo(f0["origin"][0].get<double>() - f0["ego"][1].get<double>(),
                              f0["origin"][1].get<double>() - f0["ego"][2].get<double>());
  layout.view = {lo, lo + dualgrid::Vector2(nx * res, ny * res)};
  layout.panels = 3;
  for (const auto& s : index["sensors"]) layout.sensors.push_back(s);
  const dualgrid::viz::ReplayRenderer renderer(layout);
  REQUIRE(img.width == renderer.width());
  REQUIRE(img.height == renderer.height());
  const auto ego_px =
      img.At(renderer.ToPixel(2, {0.0, 0.0}).x(), renderer.ToPixel(2, {0.0, 0.0}).y());
  // Green dominates (H.264 shifts colours a little, most of all in small areas).
  CHECK(ego_px[1] > ego_px[0] + 50);
  CHECK(ego_px[1] > ego_px[2] + 50);

  const Dense d = Decode(index, Slurp(run / "replay" / "frames.bin"), 20);
  const double ox = f["origin"][0], oy = f["origin"][1];
  // Cells of mostly free mass in a uniform neighbourhood: grey level 255 (free + unknown / 2).
  int whites = 0;
  for (int cy = 3; cy < ny - 3 && whites < 5; cy += 3) {
    for (int cx = 3; cx < nx - 3 && whites < 5; cx += 7) {
      const std::size_t k = static_cast<std::size_t>(cy) * nx + cx;
      bool clear = d.free[2][k] >= 200 && d.dyn[2][k] == 0 && d.stat[2][k] == 0;
      for (int dy = -2; dy <= 2 && clear; ++dy)
        for (int dx = -2; dx <= 2 && clear; ++dx) {
          const std::size_t j = static_cast<std::size_t>(cy + dy) * nx + cx + dx;
          clear =
              std::abs(d.free[2][j] - d.free[2][k]) <= 5 && d.dyn[2][j] == 0 && d.stat[2][j] == 0;
        }
      const dualgrid::Position centre(ox + (cx + 0.5) * res - ego_x, oy + (cy + 0.5) * res - ego_y);
      // Nothing drawn within 3 m (boxes, arrows, detection dots).
      for (const json& b : f["truth"])
        clear = clear && std::hypot(b[1].get<double>() - ego_x - centre.x(),
                                    b[2].get<double>() - ego_y - centre.y()) > 12.0;
      for (const json& det : f["det"])
        clear = clear && std::hypot(det[1].get<double>() - ego_x - centre.x(),
                                    det[2].get<double>() - ego_y - centre.y()) > 3.0;
      clear = clear && centre.norm() > 6.0;
      if (!clear) continue;
      const auto px = img.At(renderer.ToPixel(2, centre).x(), renderer.ToPixel(2, centre).y());
      INFO("cell (" << cx << ", " << cy << ")");
      const double expected = d.free[2][k] + 0.5 * (255.0 - d.free[2][k]);
      CHECK(px[0] == Approx(expected).margin(20));
      CHECK(px[1] == Approx(expected).margin(20));
      CHECK(px[2] == Approx(expected).margin(20));
      ++whites;
    }
  }
  CHECK(whites >= 1);

  // The viewer page holds the data (no placeholder left) and every recorded frame: the base64
  // list after the index ("frames":["...","...",...]).
  const std::string html = Slurp(run / "replay.html");
  CHECK(html.find("/*DUALGRID_DATA*/") == std::string::npos);
  CHECK(html.find("\"format\":\"dualgrid-replay\"") != std::string::npos);
  const std::size_t list = html.find("\"frames\":[\"");
  REQUIRE(list != std::string::npos);
  const std::size_t end = html.find("\"]", list);
  REQUIRE(end != std::string::npos);
  const std::string b64 = html.substr(list, end - list);
  CHECK(static_cast<std::size_t>(std::count(b64.begin(), b64.end(), ',')) + 1 ==
        index["frames"].size());
}

TEST_CASE("replay: bad input gets one line and exit code 2", "[cli][replay]") {
  const fs::path run = RecordedRun();
  const fs::path d = TempDir("replay", "errors");
  auto one_line_2 = [](const Result& r, const std::string& needle) {
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(CountLines(r.output) == 1);
    CHECK(r.output.find(needle) != std::string::npos);
  };
  // A run without a recording.
  const auto plain = Run("run scenarios/highway.yaml --duration 1 --no-figures -q --out " +
                         (d / "plain").string());
  REQUIRE(plain.code == 0);
  CHECK_FALSE(fs::exists(d / "plain" / "replay"));
  one_line_2(Run("replay " + (d / "plain").string()), "index.json");
  one_line_2(Run("replay " + run.string() + " --from 50"), "--from/--to");
  one_line_2(Run("replay " + run.string() + " --modes dual,sideways"), "sideways");
  one_line_2(Run("replay " + run.string() + " --out " + (d / "x.avi").string()), ".mp4");
  one_line_2(Run("run scenarios/highway.yaml --duration 1 --video --no-record --out " +
                 (d / "novideo").string()),
             "--no-record");
  // A recording of another version, and one whose frames were cut short.
  fs::copy(run, d / "copy", fs::copy_options::recursive);
  json index = json::parse(Slurp(d / "copy" / "replay" / "index.json"));
  index["version"] = 99;
  std::ofstream(d / "copy" / "replay" / "index.json") << index.dump();
  one_line_2(Run("replay " + (d / "copy").string()), "'version'");
  index["version"] = 2;
  std::ofstream(d / "copy" / "replay" / "index.json") << index.dump();
  json bad = index;
  bad["cells_x"] = "400";
  std::ofstream(d / "copy" / "replay" / "index.json") << bad.dump();
  one_line_2(Run("replay " + (d / "copy").string()), "'cells_x'");
  bad = index;
  bad["frames"][3]["blob"] = json::array({0, 1ull << 62});
  std::ofstream(d / "copy" / "replay" / "index.json") << bad.dump();
  one_line_2(Run("replay " + (d / "copy").string() + " --html"), "frames[3].blob");
  bad = index;
  bad["frames"] = json::array();
  std::ofstream(d / "copy" / "replay" / "index.json") << bad.dump();
  one_line_2(Run("replay " + (d / "copy").string()), "'frames'");
  // A malformed detection: the viewer page is refused as the video is (the page was written).
  // (The copied run may hold a page an earlier test case wrote.)
  fs::remove(d / "copy" / "replay.html");
  bad = index;
  bad["frames"][5]["det"] = json::array({json::array({0, 1.0, 2.0})});
  std::ofstream(d / "copy" / "replay" / "index.json") << bad.dump();
  one_line_2(Run("replay " + (d / "copy").string() + " --html"), "'frames[5].det[0]'");
  CHECK_FALSE(fs::exists(d / "copy" / "replay.html"));
  std::ofstream(d / "copy" / "replay" / "index.json") << index.dump();
  // Flipped bytes in a frame's zlib data: refused by --html too, naming the frame.
  {
    std::string frames = Slurp(d / "copy" / "replay" / "frames.bin");
    const std::size_t at = index["frames"][7]["blob"][0].get<std::size_t>() + 40;
    frames[at] = static_cast<char>(frames[at] ^ 0xff);
    frames[at + 9] = static_cast<char>(frames[at + 9] ^ 0x5a);
    std::ofstream(d / "copy" / "replay" / "frames.bin", std::ios::binary) << frames;
  }
  one_line_2(Run("replay " + (d / "copy").string() + " --html"), "frames[7].blob");
  fs::resize_file(d / "copy" / "replay" / "frames.bin", 1000);
  one_line_2(Run("replay " + (d / "copy").string()), "frames.bin");
  // Options the viewer would ignore, and a video into a folder that does not exist.
  one_line_2(Run("replay " + run.string() + " --html --width 640"), "--width");
  one_line_2(Run("replay " + run.string() + " --out " + (d / "nowhere" / "x.mp4").string()),
             "--out");
}

TEST_CASE("a run shorter than the record interval still records its last step", "[cli][replay]") {
  const fs::path d = TempDir("replay", "short");
  const auto r = Run("run scenarios/highway.yaml --duration 0.05 --figure-formats png -q --out " +
                     (d / "run").string());
  INFO(r.output);
  REQUIRE(r.code == 0);
  const json index = json::parse(Slurp(d / "run" / "replay" / "index.json"));
  REQUIRE(index["frames"].size() == 1);
  CHECK(index["frames"][0]["t"].get<double>() == Approx(0.05));
}

TEST_CASE("a failing ffmpeg costs the video, never the run's results", "[cli][replay][video]") {
  const fs::path run = RecordedRun();
  const fs::path d = TempDir("replay", "bad_ffmpeg");
  // An ffmpeg that fails at once, first on PATH.
  std::ofstream(d / "ffmpeg") << "#!/bin/sh\necho 'no encoder here' >&2\nexit 1\n";
  fs::permissions(d / "ffmpeg", fs::perms::owner_all);
  const std::string env = "PATH=" + d.string() + ":$PATH ";
  const auto r =
      Shell(env + DUALGRID_EXE + " replay " + run.string() + " -q --out " + (d / "v.mp4").string());
  INFO(r.output);
  CHECK(r.code == 1);
  CHECK(r.output.find("no encoder here") != std::string::npos);
  CHECK_FALSE(fs::exists(d / "v.mp4"));
  CHECK_FALSE(fs::exists(d / "v.mp4.part"));
  const auto v = Shell(env + DUALGRID_EXE +
                       " run scenarios/highway.yaml --duration 1 --figure-formats png -q --video "
                       "--out " +
                       (d / "run").string());
  INFO(v.output);
  CHECK(v.code == 0);
  const json summary = json::parse(Slurp(d / "run" / "summary.json"));
  CHECK(summary["complete"] == true);
  REQUIRE(summary["warnings"].size() == 1);
  CHECK(summary["warnings"][0].get<std::string>().find("replay not written") != std::string::npos);
  CHECK(fs::exists(d / "run" / "metrics.json"));
  CHECK(fs::exists(d / "run" / "replay" / "index.json"));
}
