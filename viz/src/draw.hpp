// Private cairo helpers shared by the figure kinds: surfaces, text, ticks, legends, scale bars.
#pragma once

#include <cairo.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/map_transform.hpp"

namespace dualgrid::viz::detail {

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

/// Texts drawn on a canvas through DrawText: how many, and the smallest size in the canvas's
/// units (the font size times the scale of the current transformation).
struct TextRecord {
  double min_size = std::numeric_limits<double>::infinity();
  int count = 0;
  std::vector<std::string> strings;  ///< every text, in drawing order
  void Add(const std::string& text, double size);
  void Merge(const TextRecord& other);
};

/// Makes DrawText record into `record` the texts drawn on `surface` (a canvas does this for its
/// own surface; a raster of one's own, e.g. a video frame, can use it to check its fonts). The
/// record must outlive the drawing; nullptr detaches.
void AttachTextRecord(cairo_surface_t* surface, TextRecord* record);

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
  /// Reports the figure to FigureAudit (dualgrid/viz/figure.hpp).
  void Save(const std::string& path) const;

  /// PNG pixels per unit (1 unless set; figures use kPngScale: points at 300 dpi). SVG and PDF
  /// stay in units (points). Throws std::invalid_argument unless in (0, 32].
  void SetRasterScale(double pixels_per_unit);
  double raster_scale() const { return raster_scale_; }
  /// Texts drawn on this canvas so far (DrawText records them by the context's target surface).
  const TextRecord& text_record() const { return *text_; }
  /// Paints `other` with its top-left corner at (x, y) and takes over its text record.
  void PaintCanvas(const Canvas& other, double x, double y);

 private:
  int width_, height_;
  double raster_scale_ = 1.0;
  std::unique_ptr<TextRecord> text_;  // before the surface: the surface's user data points here
  SurfacePtr surface_;
  ContextPtr cr_;
};

/// A scratch context for measuring text before a canvas (whose size depends on it) exists.
class Measure {
 public:
  Measure();
  cairo_t* cr() const { return cr_.get(); }

 private:
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

/// kSensor: a radar's legend entry, an opaque wedge outline with a detection dot in its colour.
enum class Marker { kSwatch, kOutline, kLine, kDashedLine, kDot, kCross, kArrow, kWedge, kSensor };

struct LegendItem {
  std::string label;
  Rgba color;
  Marker marker = Marker::kSwatch;
  Rgba outline = colors::kBlack;  ///< kSwatch border; kSwatch with alpha 0 outline = no border
};

/// Legend markers scale with the font size (22 x 12 units at size 14).
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

/// `text` split at spaces into lines at most `max_width` wide at `size` (a longer word has a line
/// of its own, broken after '_', '.', '=', '/' or ',' if it has them; a "%" stays with the word
/// before it); "\n" forces a break.
std::vector<std::string> WrapText(cairo_t* cr, const std::string& text, double size,
                                  double max_width, bool bold = false);
/// Line advance of wrapped text: 1.25 x size.
double LineHeight(double size);
/// Draws `text` wrapped to max_width with its first line's top at y (style.v is ignored, style.h
/// aligns each line at x); with draw = false only measures. Returns the height used.
double DrawParagraph(cairo_t* cr, const std::string& text, double x, double y, double max_width,
                     const TextStyle& style, bool draw = true);

/// Frame and metre ticks around a map area (t's pixel offset and size): ticks on the left and
/// bottom edges; labels at `font_size` when the flags say so (shared axes of stacked or side by
/// side panels label only the outer ones). Returns the height the bottom labels take below the
/// frame.
struct MapAxesStyle {
  double font_size = 14.0;
  double tick_length = 5.0;
  double line_width = 1.0;
  bool label_x = true;
  bool label_y = true;
  /// How far an x label may reach left of the frame's left edge and right of its right edge
  /// (neighbouring panels, the image's edge); a label that would reach further is left out.
  double label_left_room = std::numeric_limits<double>::infinity();
  double label_right_room = std::numeric_limits<double>::infinity();
};
double DrawMapAxes(cairo_t* cr, const MapTransform& t, const MapAxesStyle& style);
/// Width the y tick labels of DrawMapAxes take left of the frame (tick, gap and widest label).
double MapAxesLabelWidth(cairo_t* cr, const MapTransform& t, const MapAxesStyle& style);

}  // namespace dualgrid::viz::detail
