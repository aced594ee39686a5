// Writing a cairo image surface as a PNG file through libpng, without row filters at zlib level
// 1, instead of cairo_surface_write_to_png's libpng defaults (docs/output.md, "PNG encoding",
// says what it costs and saves).
#pragma once

#include <cairo.h>

#include <string>

namespace dualgrid::viz::detail {

/// Writes `image` (a CAIRO_FORMAT_ARGB32 image surface, flushed; not modified) to `path` as an
/// 8-bit PNG, RGB when every pixel is opaque and RGBA otherwise, its colours un-premultiplied:
/// what cairo_surface_write_to_png writes, so the file decodes
/// (cairo_image_surface_create_from_png, any PNG reader) to the same pixels in the same format as
/// cairo's file; only the compression differs (no row filters, zlib level 1) and one ancillary
/// chunk (sRGB where cairo writes bKGD, white). Returns false when the file
/// cannot be opened, encoded, written or closed (a partial file may remain, as with cairo's
/// writer).
bool WritePng(cairo_surface_t* image, const std::string& path);

}  // namespace dualgrid::viz::detail
