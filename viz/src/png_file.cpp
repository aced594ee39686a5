#include "png_file.hpp"

#include <png.h>
#include <zlib.h>

#include <cassert>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace dualgrid::viz::detail {

namespace {

// One premultiplied ARGB32 pixel (native endian) as straight R, G, B (, A) bytes: each colour
// divided by alpha, rounded to nearest (the rule cairo's PNG writer applies); a transparent
// pixel becomes all zeros.
void Unpremultiply(std::uint32_t pixel, std::uint8_t* out, bool alpha) {
  const std::uint32_t a = pixel >> 24;
  for (int c = 0; c < 3; ++c) {
    const std::uint32_t v = (pixel >> (16 - 8 * c)) & 0xFFu;
    out[c] = static_cast<std::uint8_t>(a == 255 ? v : a == 0 ? 0 : (v * 255 + a / 2) / a);
  }
  if (alpha) out[3] = static_cast<std::uint8_t>(a);
}

std::uint32_t Pixel(const unsigned char* row, int x) {
  std::uint32_t pixel;
  std::memcpy(&pixel, row + 4 * static_cast<std::size_t>(x), 4);
  return pixel;
}

bool Opaque(const unsigned char* data, int width, int height, int stride) {
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (Pixel(data + static_cast<std::size_t>(y) * stride, x) >> 24 != 255) return false;
  return true;
}

// libpng reports errors by longjmp: no C++ object with a destructor may live in this frame.
// Writes 8-bit RGB(A) rows without row filters at zlib level 1 (libpng's simplified API offers
// level 3 at most: twice the time for 5 % smaller figures), with the sRGB chunk that API wrote.
bool Encode(std::FILE* file, const std::uint8_t* pixels, int width, int height, bool alpha) {
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, nullptr, [](png_structp p, png_const_charp) { png_longjmp(p, 1); },
      [](png_structp, png_const_charp) {});  // silent: a failure is the caller's false
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               alpha ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);  // NO_FILTERS (0) means "all" here
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_DEFAULT_STRATEGY);
  png_write_info(png, info);
  const std::size_t row_bytes = static_cast<std::size_t>(width) * (alpha ? 4 : 3);
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(pixels + static_cast<std::size_t>(y) * row_bytes));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

bool WritePng(cairo_surface_t* image, const std::string& path) {
  assert(cairo_image_surface_get_format(image) == CAIRO_FORMAT_ARGB32);
  const int width = cairo_image_surface_get_width(image);
  const int height = cairo_image_surface_get_height(image);
  const int stride = cairo_image_surface_get_stride(image);
  const unsigned char* data = cairo_image_surface_get_data(image);
  if (!data || width <= 0 || height <= 0) return false;
  // As cairo's writer: an opaque image is written without its alpha channel.
  const bool alpha = !Opaque(data, width, height, stride);
  const std::size_t channels = alpha ? 4 : 3;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height * channels);
  for (int y = 0; y < height; ++y) {
    const unsigned char* row = data + static_cast<std::size_t>(y) * stride;
    std::uint8_t* out = pixels.data() + static_cast<std::size_t>(y) * width * channels;
    for (int x = 0; x < width; ++x) Unpremultiply(Pixel(row, x), out + channels * x, alpha);
  }
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return false;
  const bool encoded = Encode(file, pixels.data(), width, height, alpha);
  const bool flushed = encoded && std::fflush(file) == 0 && std::ferror(file) == 0;
  const bool closed = std::fclose(file) == 0;
  return encoded && flushed && closed;
}

}  // namespace dualgrid::viz::detail
