// The figures' PNG writer (viz/src/png_file.hpp, private to viz): its files decode with cairo to
// the same pixels, in the same pixel format, as the files cairo_surface_write_to_png writes of
// the same surface, for opaque drawings and for every premultiplied colour and alpha.
#include <cairo.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <zlib.h>

#include "png_file.hpp"

namespace fs = std::filesystem;
using dualgrid::viz::detail::WritePng;

namespace {

fs::path TempDir() {
  const fs::path dir = fs::temp_directory_path() / "dualgrid_test_png_file";
  fs::create_directories(dir);
  return dir;
}

struct Surface {
  cairo_surface_t* s;
  explicit Surface(cairo_surface_t* surface) : s(surface) {
    REQUIRE(cairo_surface_status(s) == CAIRO_STATUS_SUCCESS);
  }
  Surface(const Surface&) = delete;
  Surface& operator=(const Surface&) = delete;
  ~Surface() { cairo_surface_destroy(s); }
};

// Decodes both files with cairo and requires the same size, format and pixel bytes.
void RequireSamePixels(const fs::path& a, const fs::path& b, cairo_format_t format) {
  const Surface da(cairo_image_surface_create_from_png(a.c_str()));
  const Surface db(cairo_image_surface_create_from_png(b.c_str()));
  CHECK(cairo_image_surface_get_format(da.s) == format);
  REQUIRE(cairo_image_surface_get_format(db.s) == cairo_image_surface_get_format(da.s));
  const int h = cairo_image_surface_get_height(da.s);
  const int stride = cairo_image_surface_get_stride(da.s);
  REQUIRE(cairo_image_surface_get_width(db.s) == cairo_image_surface_get_width(da.s));
  REQUIRE(cairo_image_surface_get_height(db.s) == h);
  REQUIRE(cairo_image_surface_get_stride(db.s) == stride);
  CHECK(std::memcmp(cairo_image_surface_get_data(da.s), cairo_image_surface_get_data(db.s),
                    static_cast<std::size_t>(stride) * h) == 0);
}

// Writes `image` both ways and compares what they decode to.
void CheckAgainstCairo(cairo_surface_t* image, const std::string& name, cairo_format_t format) {
  cairo_surface_flush(image);
  const fs::path ours = TempDir() / (name + "_ours.png");
  const fs::path theirs = TempDir() / (name + "_cairo.png");
  REQUIRE(WritePng(image, ours.string()));
  REQUIRE(cairo_surface_write_to_png(image, theirs.c_str()) == CAIRO_STATUS_SUCCESS);
  RequireSamePixels(ours, theirs, format);
}

}  // namespace

TEST_CASE("an opaque drawing's PNG decodes to cairo's pixels, without alpha", "[viz][png]") {
  const Surface image(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 301, 207));
  cairo_t* cr = cairo_create(image.s);
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  // Antialiased edges and translucent paint over the opaque background: many colours, alpha 255.
  cairo_set_source_rgba(cr, 0.8, 0.2, 0.1, 0.6);
  cairo_arc(cr, 120.3, 90.7, 70.2, 0.0, 2.0 * M_PI);
  cairo_fill(cr);
  cairo_set_source_rgba(cr, 0.1, 0.3, 0.9, 0.35);
  cairo_set_line_width(cr, 7.3);
  cairo_move_to(cr, 10.2, 190.4);
  cairo_line_to(cr, 290.9, 15.1);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 23.0);
  cairo_move_to(cr, 30.0, 60.0);
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_show_text(cr, "dualgrid 0.5 m/s");
  REQUIRE(cairo_status(cr) == CAIRO_STATUS_SUCCESS);
  cairo_destroy(cr);
  CheckAgainstCairo(image.s, "opaque", CAIRO_FORMAT_RGB24);
}

TEST_CASE("every premultiplied colour and alpha decodes to cairo's pixels", "[viz][png]") {
  // Row a holds alpha a; column c the colour c * a / 255 in red, its mirror in green and the
  // middle in blue: every alpha (0 transparent to 255 opaque) with every colour it allows.
  const Surface image(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 256, 256));
  cairo_surface_flush(image.s);
  unsigned char* data = cairo_image_surface_get_data(image.s);
  const int stride = cairo_image_surface_get_stride(image.s);
  for (std::uint32_t a = 0; a < 256; ++a) {
    for (std::uint32_t c = 0; c < 256; ++c) {
      const std::uint32_t r = c * a / 255, g = (255 - c) * a / 255, b = a / 2;
      const std::uint32_t pixel = a << 24 | r << 16 | g << 8 | b;
      std::memcpy(data + a * stride + 4 * c, &pixel, 4);
    }
  }
  cairo_surface_mark_dirty(image.s);
  CheckAgainstCairo(image.s, "alpha", CAIRO_FORMAT_ARGB32);
}

TEST_CASE("a PNG that cannot be written is reported", "[viz][png]") {
  const Surface image(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 8, 8));
  CHECK_FALSE(WritePng(image.s, "/nonexistent_dir_dualgrid/x.png"));
  if (fs::exists("/dev/full")) CHECK_FALSE(WritePng(image.s, "/dev/full"));  // ENOSPC
}

TEST_CASE("the PNG holds IHDR, sRGB, IDAT and IEND, its rows unfiltered", "[viz][png]") {
  const Surface image(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 64, 40));
  cairo_t* cr = cairo_create(image.s);
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, 0.2, 0.5, 0.7);
  cairo_arc(cr, 30.0, 20.0, 15.0, 0.0, 2.0 * M_PI);
  cairo_fill(cr);
  cairo_destroy(cr);
  cairo_surface_flush(image.s);
  const fs::path path = TempDir() / "chunks.png";
  REQUIRE(WritePng(image.s, path.string()));
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> file((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  std::vector<std::string> chunks;
  std::vector<unsigned char> idat;
  for (std::size_t at = 8; at + 12 <= file.size();) {
    const std::size_t n = static_cast<std::size_t>(file[at]) << 24 | file[at + 1] << 16 |
                          file[at + 2] << 8 | file[at + 3];
    const std::string type(file.begin() + static_cast<long>(at) + 4,
                           file.begin() + static_cast<long>(at) + 8);
    if (type == "IDAT")
      idat.insert(idat.end(), file.begin() + static_cast<long>(at) + 8,
                  file.begin() + static_cast<long>(at + 8 + n));
    if (chunks.empty() || chunks.back() != type) chunks.push_back(type);
    at += 12 + n;
  }
  CHECK(chunks == std::vector<std::string>{"IHDR", "sRGB", "IDAT", "IEND"});
  // Opaque: RGB rows of 1 + 64 * 3 bytes, each starting with its filter type (0: none).
  std::vector<unsigned char> raw(40 * (1 + 64 * 3));
  uLongf size = raw.size();
  REQUIRE(uncompress(raw.data(), &size, idat.data(), idat.size()) == Z_OK);
  REQUIRE(size == raw.size());
  for (std::size_t row = 0; row < 40; ++row) CHECK(raw[row * (1 + 64 * 3)] == 0);
}
