// Private cairo helpers shared by the figure kinds: surfaces, text, ticks, legends, scale bars.
#pragma once

#include <cairo.h>

#include <memory>
#include <string>
#include <vector>

#include "dualgrid/viz/color.hpp"

namespace dualgrid::viz::detail {

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

/// A drawing of width x height units (pixels in PNG, points in SVG and PDF) with a context,
/// cleared to white. Drawn into a cairo recording surface, so one drawing is written as a raster
/// or as vectors (text as text, lines as paths; embedded images such as grid cells stay rasters).
class Canvas {
 public:
  Canvas(int width, int height);
  cairo_t* cr() const { return cr_.get(); }
  cairo_surface_t* surface() const { return surface_.get(); }
  int width() const { return width_; }
  int height() const { return height_; }
  /// Writes the drawing; the format follows the extension: .png (raster), .svg or .pdf (vector,
  /// through cairo's own surfaces). Throws std::invalid_argument for another extension and
  /// std::runtime_error naming the path and cairo's reason when writing fails.
  void Save(const std::string& path) const;

 private:
  int width_, height_;
  SurfacePtr surface_;
  ContextPtr cr_;
};

void SetColor(cairo_t* cr, const Rgba& c);

enum class HAlign { kLeft, kCenter, kRight };
enum class VAlign { kTop, kMiddle, kBaseline, kBottom };

struct TextStyle {
  double size = 14.0;
  bool bold = false;
  Rgba color = colors::kText;
  HAlign h = HAlign::kLeft;
  VAlign v = VAlign::kBaseline;
  double angle = 0.0;  ///< [rad], clockwise on screen (cairo); -pi/2 for a vertical axis label
  bool halo = false;   ///< white outline behind the glyphs for text over busy maps
};

/// Toy-API text in DejaVu Sans (fontconfig substitutes a sans font if it is missing).
void DrawText(cairo_t* cr, const std::string& text, double x, double y, const TextStyle& style);
double TextWidth(cairo_t* cr, const std::string& text, double size, bool bold = false);

/// Tick positions at a 1-2-5 step covering [lo, hi] with about `target` ticks.
std::vector<double> NiceTicks(double lo, double hi, int target);
/// Formats a tick value with just enough decimals for `step`.
std::string FormatTick(double value, double step);
/// 1-2-5 length [m] whose pixel length is at most `max_px` at `px_per_m`.
double NiceScaleLength(double px_per_m, double max_px);
/// Draws a scale bar with its left end at (x, y) (bar baseline); returns the width used [px].
double DrawScaleBar(cairo_t* cr, double x, double y, double px_per_m, double max_px,
                    double font_size);

enum class Marker { kSwatch, kOutline, kLine, kDashedLine, kDot, kCross, kArrow, kWedge };

struct LegendItem {
  std::string label;
  Rgba color;
  Marker marker = Marker::kSwatch;
  Rgba outline = colors::kBlack;  ///< kSwatch border; kSwatch with alpha 0 outline = no border
};

/// Width [px] of one legend entry (marker, gap, label).
double LegendItemWidth(cairo_t* cr, const LegendItem& item, double font_size);
/// Draws one entry whose marker starts at x, vertically centred on y.
void DrawLegendItem(cairo_t* cr, const LegendItem& item, double x, double y, double font_size);
/// Lays entries out in rows from (x, y) within max_width; returns the rows' total height.
/// With draw = false it only measures.
double LayoutLegendRow(cairo_t* cr, const std::vector<LegendItem>& items, double x, double y,
                       double max_width, double font_size, bool draw);

/// Arrow from (x0, y0) to (x1, y1) in pixels with a filled head of `head` px; current colour.
void DrawArrow(cairo_t* cr, double x0, double y0, double x1, double y1, double line_width,
               double head);
void DrawCross(cairo_t* cr, double x, double y, double half, double line_width);

}  // namespace dualgrid::viz::detail
