#include "draw.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "dualgrid/core/types.hpp"
#include "dualgrid/viz/figure.hpp"
#include "png_file.hpp"

namespace dualgrid::viz::detail {

namespace {

cairo_surface_t* RecordingSurface(int width, int height) {
  const cairo_rectangle_t extents{0.0, 0.0, static_cast<double>(width),
                                  static_cast<double>(height)};
  return cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, &extents);
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The text record of a canvas hangs on its recording surface, so DrawText, which sees only a
// context, finds it through the context's target.
const cairo_user_data_key_t kTextRecordKey{};

TextRecord* RecordOf(cairo_t* cr) {
  return static_cast<TextRecord*>(
      cairo_surface_get_user_data(cairo_get_target(cr), &kTextRecordKey));
}

}  // namespace

void AttachTextRecord(cairo_surface_t* surface, TextRecord* record) {
  cairo_surface_set_user_data(surface, &kTextRecordKey, record, nullptr);
}

void TextRecord::Add(const std::string& text, double size) {
  min_size = std::min(min_size, size);
  ++count;
  strings.push_back(text);
}

void TextRecord::Merge(const TextRecord& other) {
  min_size = std::min(min_size, other.min_size);
  count += other.count;
  strings.insert(strings.end(), other.strings.begin(), other.strings.end());
}

Canvas::Canvas(int width, int height)
    : width_(width),
      height_(height),
      text_(std::make_unique<TextRecord>()),
      surface_(RecordingSurface(width, height)),
      cr_(cairo_create(surface_.get())) {
  if (width <= 0 || height <= 0 || cairo_surface_status(surface_.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("viz: cannot create a " + std::to_string(width) + "x" +
                             std::to_string(height) + " drawing");
  AttachTextRecord(surface_.get(), text_.get());
  cairo_set_source_rgb(cr(), 1.0, 1.0, 1.0);
  cairo_paint(cr());
}

void Canvas::SetRasterScale(double pixels_per_unit) {
  if (!(pixels_per_unit > 0.0 && pixels_per_unit <= 32.0))
    throw std::invalid_argument("viz: raster scale must be in (0, 32] pixels per unit");
  raster_scale_ = pixels_per_unit;
}

void Canvas::PaintCanvas(const Canvas& other, double x, double y) {
  cairo_save(cr());
  cairo_set_source_surface(cr(), other.surface(), x, y);
  cairo_paint(cr());
  cairo_restore(cr());
  text_->Merge(other.text_record());
}

void Canvas::Save(const std::string& path) const {
  cairo_surface_flush(surface_.get());
  const auto dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : Lower(path.substr(dot));
  SurfacePtr target;
  if (ext == ".png") {
    target.reset(cairo_image_surface_create(
        CAIRO_FORMAT_ARGB32, static_cast<int>(std::ceil(width_ * raster_scale_ - 1e-6)),
        static_cast<int>(std::ceil(height_ * raster_scale_ - 1e-6))));
  } else if (ext == ".svg") {
    target.reset(cairo_svg_surface_create(path.c_str(), width_, height_));
  } else if (ext == ".pdf") {
    target.reset(cairo_pdf_surface_create(path.c_str(), width_, height_));
    // No creation date: the same figure gives the same bytes (runs are compared by digests).
    if (cairo_surface_status(target.get()) == CAIRO_STATUS_SUCCESS)
      cairo_pdf_surface_set_metadata(target.get(), CAIRO_PDF_METADATA_CREATE_DATE, "");
  } else {
    throw std::invalid_argument("viz: cannot write '" + path +
                                "': expected a file name ending in .png, .svg or .pdf");
  }
  const auto fail = [&](cairo_status_t status) {
    throw std::runtime_error("viz: cannot write '" + path + "': " + cairo_status_to_string(status));
  };
  if (cairo_surface_status(target.get()) != CAIRO_STATUS_SUCCESS)
    fail(cairo_surface_status(target.get()));
  {
    ContextPtr cr(cairo_create(target.get()));
    // The recording is replayed at the raster scale: lines and text are drawn again at that
    // resolution, not enlarged.
    if (ext == ".png") cairo_scale(cr.get(), raster_scale_, raster_scale_);
    cairo_set_source_surface(cr.get(), surface_.get(), 0.0, 0.0);
    cairo_paint(cr.get());
    if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) fail(cairo_status(cr.get()));
  }
  if (ext == ".png") {
    cairo_surface_flush(target.get());
    // The words cairo's own writer used for a file it could not open or write.
    if (!WritePng(target.get(), path)) fail(CAIRO_STATUS_WRITE_ERROR);
  } else {
    // SVG and PDF surfaces write their file when finished; errors show in the surface status.
    cairo_surface_finish(target.get());
    if (cairo_surface_status(target.get()) != CAIRO_STATUS_SUCCESS)
      fail(cairo_surface_status(target.get()));
  }
  FigureAudit::Report({path, static_cast<double>(width_), static_cast<double>(height_),
                       ext == ".png" ? raster_scale_ : 1.0, text_->min_size, text_->count,
                       text_->strings});
}

Measure::Measure()
    : surface_(cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, nullptr)),
      cr_(cairo_create(surface_.get())) {}

void SetColor(cairo_t* cr, const Rgba& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

namespace {
void SelectFont(cairo_t* cr, double size, bool bold) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
}
}  // namespace

double TextWidth(cairo_t* cr, const std::string& text, double size, bool bold) {
  SelectFont(cr, size, bold);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  return ext.x_advance;
}

void DrawText(cairo_t* cr, const std::string& text, double x, double y, const TextStyle& style) {
  if (text.empty()) return;
  if (TextRecord* record = RecordOf(cr)) {
    // The size as it lands on the page: font size times the transformation's (area) scale.
    cairo_matrix_t m;
    cairo_get_matrix(cr, &m);
    record->Add(text, style.size * std::sqrt(std::abs(m.xx * m.yy - m.xy * m.yx)));
  }
  cairo_save(cr);
  SelectFont(cr, style.size, style.bold);
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  cairo_font_extents_t fext;
  cairo_font_extents(cr, &fext);
  double dx = 0.0, dy = 0.0;
  if (style.h == HAlign::kCenter) dx = -0.5 * ext.x_advance;
  if (style.h == HAlign::kRight) dx = -ext.x_advance;
  // Font ascent/descent (not the ink box) so labels of one row share a baseline.
  if (style.v == VAlign::kTop) dy = fext.ascent;
  if (style.v == VAlign::kMiddle) dy = 0.5 * (fext.ascent - fext.descent);
  if (style.v == VAlign::kBottom) dy = -fext.descent;
  cairo_translate(cr, x, y);
  cairo_rotate(cr, style.angle);
  cairo_move_to(cr, dx, dy);
  if (style.halo) {
    cairo_text_path(cr, text.c_str());
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_set_line_width(cr, 3.0 / 14.0 * style.size);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_stroke(cr);
    cairo_move_to(cr, dx, dy);
  }
  SetColor(cr, style.color);
  cairo_show_text(cr, text.c_str());
  cairo_restore(cr);
}

std::vector<double> NiceTicks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double raw = (hi - lo) / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm < 1.5 ? 1.0 : norm < 3.5 ? 2.0 : norm < 7.5 ? 5.0 : 10.0) * mag;
  const double eps = 1e-9 * step;
  for (double k = std::ceil((lo - eps) / step); k * step <= hi + eps; k += 1.0) {
    const double v = k * step;
    ticks.push_back(std::abs(v) < eps ? 0.0 : v);
  }
  return ticks;
}

std::string FormatTick(double value, double step) {
  const int decimals =
      step > 0.0 ? std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 6) : 0;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  std::string s = buf;
  if (s.rfind("-", 0) == 0) {
    // Avoid "-0" and use a real minus sign for readability.
    bool all_zero = s.find_first_not_of("-0.") == std::string::npos;
    s = all_zero ? s.substr(1) : "\u2212" + s.substr(1);
  }
  return s;
}

double NiceScaleLength(double px_per_m, double max_px) {
  const double max_m = max_px / px_per_m;
  const double mag = std::pow(10.0, std::floor(std::log10(max_m)));
  for (double f : {5.0, 2.0, 1.0}) {
    if (f * mag <= max_m) return f * mag;
  }
  return mag;
}

double DrawScaleBar(cairo_t* cr, double x, double y, double px_per_m, double max_px,
                    double font_size) {
  const double len_m = NiceScaleLength(px_per_m, max_px);
  const double len_px = len_m * px_per_m;
  const double u = font_size / 14.0;  // sizes were designed at font size 14
  const double h = 6.0 * u;
  cairo_save(cr);
  // Two halves, black and white, in a black frame: classic map scale bar.
  cairo_set_line_width(cr, u);
  cairo_rectangle(cr, x, y - h, 0.5 * len_px, h);
  SetColor(cr, colors::kBlack);
  cairo_fill(cr);
  cairo_rectangle(cr, x + 0.5 * u, y - h + 0.5 * u, len_px - u, h - u);
  cairo_stroke(cr);
  cairo_restore(cr);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g m", len_m);
  TextStyle ts{.size = font_size, .h = HAlign::kLeft, .v = VAlign::kMiddle};
  const double label_x = x + len_px + 6.0 * u;
  DrawText(cr, buf, label_x, y - 0.5 * h, ts);
  return len_px + 6.0 * u + TextWidth(cr, buf, font_size);
}

namespace {
// Legend geometry at font size 14; everything scales with the font size.
double MarkerWidth(double font_size) { return 22.0 / 14.0 * font_size; }
double MarkerGap(double font_size) { return 6.0 / 14.0 * font_size; }
double ItemGap(double font_size) { return 18.0 / 14.0 * font_size; }
}  // namespace

double LegendItemWidth(cairo_t* cr, const LegendItem& item, double font_size) {
  return MarkerWidth(font_size) + MarkerGap(font_size) + TextWidth(cr, item.label, font_size);
}

void DrawArrow(cairo_t* cr, double x0, double y0, double x1, double y1, double line_width,
               double head) {
  const double dx = x1 - x0, dy = y1 - y0;
  const double len = std::hypot(dx, dy);
  if (len < 1e-9) return;
  const double ux = dx / len, uy = dy / len;
  head = std::min(head, 0.6 * len);
  cairo_save(cr);
  cairo_set_line_width(cr, line_width);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1 - ux * head * 0.8, y1 - uy * head * 0.8);
  cairo_stroke(cr);
  cairo_move_to(cr, x1, y1);
  cairo_line_to(cr, x1 - ux * head - uy * head * 0.45, y1 - uy * head + ux * head * 0.45);
  cairo_line_to(cr, x1 - ux * head + uy * head * 0.45, y1 - uy * head - ux * head * 0.45);
  cairo_close_path(cr);
  cairo_fill(cr);
  cairo_restore(cr);
}

void DrawCross(cairo_t* cr, double x, double y, double half, double line_width) {
  cairo_save(cr);
  cairo_set_line_width(cr, line_width);
  cairo_move_to(cr, x - half, y - half);
  cairo_line_to(cr, x + half, y + half);
  cairo_move_to(cr, x - half, y + half);
  cairo_line_to(cr, x + half, y - half);
  cairo_stroke(cr);
  cairo_restore(cr);
}

void DrawLegendItem(cairo_t* cr, const LegendItem& item, double x, double y, double font_size) {
  cairo_save(cr);
  const double u = font_size / 14.0;  // sizes below were designed at font size 14
  const double w = MarkerWidth(font_size), h = std::min(12.0 * u, font_size);
  switch (item.marker) {
    case Marker::kSwatch:
      cairo_rectangle(cr, x + 0.5 * u, y - 0.5 * h + 0.5 * u, w - u, h - u);
      SetColor(cr, item.color);
      cairo_fill_preserve(cr);
      SetColor(cr, item.outline);
      cairo_set_line_width(cr, u);
      cairo_stroke(cr);
      break;
    case Marker::kOutline:
      cairo_rectangle(cr, x + 1.5 * u, y - 0.5 * h + u, w - 3.0 * u, h - 2.0 * u);
      SetColor(cr, item.color);
      cairo_set_line_width(cr, 2.0 * u);
      cairo_stroke(cr);
      break;
    case Marker::kLine:
    case Marker::kDashedLine: {
      SetColor(cr, item.color);
      cairo_set_line_width(cr, 3.0 * u);
      if (item.marker == Marker::kDashedLine) {
        const double dash[] = {5.0 * u, 3.0 * u};
        cairo_set_dash(cr, dash, 2, 0.0);
      }
      cairo_move_to(cr, x, y);
      cairo_line_to(cr, x + w, y);
      cairo_stroke(cr);
      break;
    }
    case Marker::kDot:
      SetColor(cr, item.color);
      cairo_arc(cr, x + 0.5 * w, y, 3.5 * u, 0.0, 2.0 * kPi);
      cairo_fill(cr);
      break;
    case Marker::kCross:
      SetColor(cr, item.color);
      DrawCross(cr, x + 0.5 * w, y, 4.0 * u, 1.8 * u);
      break;
    case Marker::kArrow:
      SetColor(cr, item.color);
      DrawArrow(cr, x, y, x + w, y, 1.5 * u, 7.0 * u);
      break;
    case Marker::kWedge:
    case Marker::kSensor:
      cairo_move_to(cr, x + 2.0 * u, y);
      cairo_arc(cr, x + 2.0 * u, y, w - 2.0 * u, -0.45, 0.45);
      cairo_close_path(cr);
      if (item.marker == Marker::kWedge) {
        SetColor(cr, WithAlpha(item.color, 0.3));
        cairo_fill_preserve(cr);
      }
      SetColor(cr, item.color);
      cairo_set_line_width(cr, (item.marker == Marker::kSensor ? 2.0 : 1.2) * u);
      cairo_stroke(cr);
      if (item.marker == Marker::kSensor) {  // the colour of its detections, opaque
        cairo_arc(cr, x + 0.62 * w, y, 3.0 * u, 0.0, 2.0 * kPi);
        cairo_fill(cr);
      }
      break;
  }
  cairo_restore(cr);
  DrawText(cr, item.label, x + w + MarkerGap(font_size), y,
           {.size = font_size, .h = HAlign::kLeft, .v = VAlign::kMiddle});
}

double LayoutLegendRow(cairo_t* cr, const std::vector<LegendItem>& items, double x, double y,
                       double max_width, double font_size, bool draw) {
  if (items.empty()) return 0.0;
  const double row_h = font_size * 1.6;
  double cx = x, cy = y + 0.5 * row_h;
  int rows = 1;
  for (const LegendItem& item : items) {
    const double w = LegendItemWidth(cr, item, font_size);
    if (cx > x && cx + w > x + max_width) {
      cx = x;
      cy += row_h;
      ++rows;
    }
    if (draw) DrawLegendItem(cr, item, cx, cy, font_size);
    cx += w + ItemGap(font_size);
  }
  return rows * row_h;
}

}  // namespace dualgrid::viz::detail
