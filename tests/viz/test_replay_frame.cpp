// The replay video's frame (viz::ReplayRenderer): layout rules, cell colours where the cells are,
// cluster outlines in their role's colour, clear errors for bad input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "dualgrid/viz/replay_frame.hpp"

using namespace dualgrid;
using namespace dualgrid::viz;

namespace {

// A grid of `nx` x `ny` cells of 0.5 m, all free, centred on the ego.
GridRaster FreeRaster(int nx, int ny) {
  GridRaster r;
  r.cells_x = nx;
  r.cells_y = ny;
  r.resolution = 0.5;
  r.origin = Position(-0.25 * nx, -0.25 * ny);
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  r.free.assign(n, 1.0f);
  r.static_occ.assign(n, 0.0f);
  r.dynamic.assign(n, 0.0f);
  r.mean_vx.assign(n, 0.0f);
  r.mean_vy.assign(n, 0.0f);
  return r;
}

ReplayLayoutOptions Layout(const GridRaster& r, int panels) {
  ReplayLayoutOptions o;
  o.width = 1280;
  o.view = r.Extent();
  o.panels = panels;
  return o;
}

struct Px {
  int r, g, b;
};
Px PixelAt(const std::uint8_t* raster, int width, const Vector2& p) {
  const int x = static_cast<int>(p.x()), y = static_cast<int>(p.y());
  const std::uint8_t* q = raster + (static_cast<std::size_t>(y) * width + x) * 4;  // B G R A
  return {q[2], q[1], q[0]};
}

}  // namespace

TEST_CASE("replay frame: a square grid's panels sit side by side, a long one's are stacked",
          "[viz][replay]") {
  const GridRaster square = FreeRaster(80, 80);
  ReplayRenderer side(Layout(square, 3));
  CHECK(side.width() == 1280);
  CHECK(side.height() % 2 == 0);
  const Position p(1.0, 2.0);
  CHECK(side.ToPixel(1, p).x() > side.ToPixel(0, p).x() + 100);
  CHECK(side.ToPixel(1, p).y() == Approx(side.ToPixel(0, p).y()));

  const GridRaster road = FreeRaster(400, 50);  // 200 m x 25 m, the paper's highway grid
  ReplayRenderer stacked(Layout(road, 3));
  CHECK(stacked.ToPixel(1, p).x() == Approx(stacked.ToPixel(0, p).x()));
  CHECK(stacked.ToPixel(1, p).y() > stacked.ToPixel(0, p).y() + 50);
  CHECK(stacked.height() % 2 == 0);
}

TEST_CASE("replay frame: cells take their masses' colours at their place; clusters their role's",
          "[viz][replay]") {
  GridRaster r = FreeRaster(80, 80);
  // A 4 x 4 block of fully dynamic cells moving +y (green) around cell (60, 20), a static block
  // around (20, 60).
  for (int y = 18; y < 22; ++y)
    for (int x = 58; x < 62; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * 80 + x;
      r.free[k] = 0.0f;
      r.dynamic[k] = 1.0f;
      r.mean_vy[k] = 5.0f;
    }
  for (int y = 58; y < 62; ++y)
    for (int x = 18; x < 22; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * 80 + x;
      r.free[k] = 0.0f;
      r.static_occ[k] = 1.0f;
    }
  ReplayPicture pic;
  pic.heading = "test";
  pic.time = 1.5;
  pic.ego = {Position::Zero(), 0.0, 4.5, 1.8};
  ReplayPanel panel;
  panel.title = "dual";
  panel.raster = r;
  // A false cluster far from the blocks: its outline is magenta.
  panel.clusters.push_back(
      {Position(-12.0, 14.0), Position(-8.0, 16.0), Position(-10.0, 15.0), Velocity::Zero(), 2});
  pic.panels = {panel};
  ReplayRenderer renderer(Layout(r, 1));
  const std::uint8_t* raster = renderer.Render(pic);
  const auto cell_centre = [&](int x, int y) -> Position {
    return r.origin + Vector2((x + 0.5) * r.resolution, (y + 0.5) * r.resolution);
  };
  // Between the four centre cells: well inside each block.
  const Px dyn = PixelAt(raster, renderer.width(),
                         renderer.ToPixel(0, cell_centre(60, 20) - Vector2(0.25, 0.25)));
  // Fully dynamic: the pure hue of +y.
  const Rgba hue = HueColor(M_PI / 2);
  CHECK(dyn.r == Approx(255 * hue.r).margin(3));
  CHECK(dyn.g == Approx(255 * hue.g).margin(3));
  CHECK(dyn.b == Approx(255 * hue.b).margin(3));
  const Px stat = PixelAt(raster, renderer.width(),
                          renderer.ToPixel(0, cell_centre(20, 60) - Vector2(0.25, 0.25)));
  CHECK(stat.r + stat.g + stat.b < 60);
  const Px free = PixelAt(raster, renderer.width(), renderer.ToPixel(0, cell_centre(10, 10)));
  CHECK(free.r + free.g + free.b > 740);
  const Px ego = PixelAt(raster, renderer.width(), renderer.ToPixel(0, Position::Zero()));
  CHECK(ego.g > 150);
  CHECK(ego.r < 120);
  // The outline runs 2 px outside the cluster's box: sample the middle of its left edge.
  const Vector2 edge = renderer.ToPixel(0, Position(-12.0, 15.0)) - Vector2(2.0, 0.0);
  const Px outline = PixelAt(raster, renderer.width(), edge);
  CHECK(outline.r > 180);
  CHECK(outline.b > 150);
  CHECK(outline.g < 80);

  // SavePng: a PNG of the frame's size, RGB (the frame is opaque); its pixels are those of
  // viz's one PNG writer, which test_png_file checks against cairo's decoder.
  const std::filesystem::path png =
      std::filesystem::temp_directory_path() /
      ("dualgrid_replay_frame_" + std::to_string(::getpid()) + ".png");
  renderer.SavePng(png.string());
  std::ifstream in(png, std::ios::binary);
  std::vector<unsigned char> head(26);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  REQUIRE(in.gcount() == 26);
  in.close();
  std::filesystem::remove(png);
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  CHECK(std::equal(signature, signature + 8, head.begin()));
  const auto be32 = [&](int at) {
    return (head[at] << 24) | (head[at + 1] << 16) | (head[at + 2] << 8) | head[at + 3];
  };
  CHECK(std::string(head.begin() + 12, head.begin() + 16) == "IHDR");
  CHECK(be32(16) == renderer.width());
  CHECK(be32(20) == renderer.height());
  CHECK(head[24] == 8);  // bit depth
  CHECK(head[25] == 2);  // colour type: RGB
  CHECK_THROWS_WITH(renderer.SavePng("/nonexistent_dir_dualgrid/frame.png"),
                    Catch::Contains("cannot write"));
}

TEST_CASE("replay frame: bad layouts and pictures are refused naming the field", "[viz][replay]") {
  const GridRaster r = FreeRaster(20, 20);
  ReplayLayoutOptions odd = Layout(r, 1);
  odd.width = 1281;
  CHECK_THROWS_WITH(ReplayRenderer(odd), Catch::Contains("width"));
  ReplayLayoutOptions empty = Layout(r, 1);
  empty.view = {};
  CHECK_THROWS_WITH(ReplayRenderer(empty), Catch::Contains("view"));
  ReplayLayoutOptions unnamed = Layout(r, 1);
  unnamed.truth_label.clear();
  CHECK_THROWS_WITH(ReplayRenderer(unnamed), Catch::Contains("truth_label"));
  ReplayRenderer renderer(Layout(r, 2));
  ReplayPicture pic;
  pic.panels.resize(1);
  pic.panels[0].raster = r;
  CHECK_THROWS_WITH(renderer.Render(pic), Catch::Contains("panels, the layout has 2"));
  pic.panels.resize(2);
  pic.panels[1].raster = r;
  pic.panels[1].raster.dynamic.pop_back();
  CHECK_THROWS_WITH(renderer.Render(pic), Catch::Contains("panels[1].raster"));
}

TEST_CASE("replay frame: the legend names the reference boxes as the layout says",
          "[viz][replay]") {
  // A recorded run's references are not ground truth (outputs::WordsFor): the legend entry is the
  // layout's truth_label, and only the header strip above the panels changes with it.
  const GridRaster r = FreeRaster(40, 40);
  ReplayPicture pic;
  pic.heading = "recorded · seed 1";
  pic.panels.resize(1);
  pic.panels[0].raster = r;
  ReplayLayoutOptions sumo = Layout(r, 1), tracks = Layout(r, 1);
  tracks.truth_label = "track estimate";
  CHECK(sumo.truth_label == "ground truth");
  ReplayRenderer a(sumo), b(tracks);
  REQUIRE(a.height() == b.height());
  const std::size_t row = static_cast<std::size_t>(a.width()) * 4;
  const std::vector<std::uint8_t> fa(a.Render(pic), a.Render(pic) + row * a.height());
  const std::vector<std::uint8_t> fb(b.Render(pic), b.Render(pic) + row * b.height());
  // The header strip (and the panel's title) lie above the top edge of the panel's map.
  const WorldRect view = r.Extent();
  const auto header_rows =
      static_cast<std::size_t>(a.ToPixel(0, Position(view.min.x(), view.max.y())).y());
  REQUIRE(header_rows > 0);
  CHECK(!std::equal(fa.begin(), fa.begin() + row * header_rows, fb.begin()));
  CHECK(std::equal(fa.begin() + row * header_rows, fa.end(), fb.begin() + row * header_rows));
}
