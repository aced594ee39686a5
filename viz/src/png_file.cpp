#include "png_file.hpp"

#include <png.h>

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
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(width);
  png.height = static_cast<png_uint_32>(height);
  png.format = alpha ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  png.flags = PNG_IMAGE_FLAG_FAST;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) return false;
  const bool encoded = png_image_write_to_stdio(&png, file, 0, pixels.data(), 0, nullptr) != 0;
  png_image_free(&png);
  const bool flushed = std::fflush(file) == 0 && std::ferror(file) == 0;
  const bool closed = std::fclose(file) == 0;
  return encoded && flushed && closed;
}

}  // namespace dualgrid::viz::detail
