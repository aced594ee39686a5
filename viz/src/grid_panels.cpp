#include "dualgrid/viz/grid_panels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "cell_image.hpp"
#include "draw.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::viz {

using detail::DrawText;
using detail::HAlign;
using detail::LegendItem;
using detail::Marker;
using detail::SetColor;
using detail::VAlign;

WorldRect GridRaster::Extent() const {
  return {origin, origin + Vector2(cells_x * resolution, cells_y * resolution)};
}

bool GridRaster::IsValid(std::string* error) const {
  FieldCheck c;
  c.AtLeast("cells_x", cells_x, 1);
  c.AtLeast("cells_y", cells_y, 1);
  c.Positive("resolution", resolution, "m");
  c.Expect(origin.allFinite(), "origin", FormatTuple({origin.x(), origin.y()}), "finite");
  const std::size_t n = static_cast<std::size_t>(std::max(cells_x, 0)) *
                        static_cast<std::size_t>(std::max(cells_y, 0));
  const std::pair<const char*, const std::vector<float>*> arrays[] = {
      {"free", &free},       {"static_occ", &static_occ}, {"dynamic", &dynamic},
      {"mean_vx", &mean_vx}, {"mean_vy", &mean_vy},
  };
  for (const auto& [name, values] : arrays) {
    c.Expect(values->size() == n, name, std::to_string(values->size()) + " values",
             "cells_x * cells_y = " + std::to_string(n) + " values");
  }
  return c.Done(error);
}

bool CellColorOptions::IsValid(std::string* error) const {
  return FieldCheck().InRange("dynamic_threshold", dynamic_threshold, 0.0, 1.0).Done(error);
}

bool GridFigureOptions::IsValid(std::string* error) const {
  FieldCheck c;
  c.InRange("image_width", image_width, 100, 5000);
  c.Expect(font_size == 0.0 || (font_size >= 2.0 && font_size <= 200.0), "font_size", font_size,
           "0 (automatic) or in [2, 200] pt");
  c.AtLeast("columns", columns, 0);
  c.InRange("png_scale", png_scale, 0.0, 32.0, Interval::kLeftOpen);
  c.Member("cell.", cell);
  return c.Done(error);
}

double GridFigureOptions::BaseFont() const {
  return font_size > 0.0 ? font_size : BaseFontSize(image_width);
}

Rgba CellColor(float free, float static_occ, float dynamic, float vx, float vy,
               const CellColorOptions& options) {
  double f = std::max(0.0f, free), s = std::max(0.0f, static_occ), d = std::max(0.0f, dynamic);
  if (!std::isfinite(f)) f = 0.0;
  if (!std::isfinite(s)) s = 0.0;
  if (!std::isfinite(d)) d = 0.0;
  // atan2(0, 0) = 0: a dynamic cell with no mean velocity shows as +x (red).
  const double angle = (std::isfinite(vx) && std::isfinite(vy)) ? std::atan2(vy, vx) : 0.0;
  const Rgba hue = HueColor(angle);
  if (options.coloring == CellColoring::kThreshold) {
    if (d > options.dynamic_threshold) return hue;
    d = 0.0;  // below threshold the dynamic mass reads as unknown
  }
  const double sum = f + s + d;
  if (sum > 1.0) {
    f /= sum;
    s /= sum;
    d /= sum;
  }
  const double u = std::max(0.0, 1.0 - f - s - d);
  // White and black weights: free contributes 1, static 0, unknown 0.5 per channel.
  const double base = f + u * colors::kUnknown.r;
  return {base + d * hue.r, base + d * hue.g, base + d * hue.b, 1.0};
}

namespace {

constexpr Rgba kEgoOutline{0.05, 0.55, 0.05, 1.0};

// Everything is measured in u (one point at one column width) and the fonts: the figure looks
// the same at any width, only larger.
struct Metrics {
  double fs, sm, u, pad, gap, panel_title, tick, col_gap, wheel_r;
  std::vector<std::string> title_lines;
  double TitleHeight() const { return title_lines.size() * detail::LineHeight(1.05 * fs); }
};

Metrics MetricsFor(cairo_t* m, const GridFigureOptions& o) {
  Metrics k;
  k.fs = o.BaseFont();
  k.sm = 0.9 * k.fs;
  k.u = k.fs / 8.0;
  k.pad = 4.0 * k.u;
  k.gap = 2.0 * k.u;
  k.panel_title = detail::LineHeight(k.fs) + k.u;
  k.tick = 2.5 * k.u;
  k.col_gap = 4.0 * k.u;
  k.wheel_r = 13.0 * k.u;
  if (!o.title.empty())
    k.title_lines = detail::WrapText(m, o.title, 1.05 * k.fs, o.image_width - 2.0 * k.pad, true);
  return k;
}

detail::MapAxesStyle AxesStyle(const Metrics& k, bool label_x, bool label_y) {
  return {.font_size = k.sm,
          .tick_length = k.tick,
          .line_width = 0.6 * k.u,
          .label_x = label_x,
          .label_y = label_y};
}

void Validate(const std::vector<GridPanel>& panels, const GridFigureOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("RenderGridPanels: options." + error);
  if (panels.empty()) throw std::invalid_argument("RenderGridPanels: panels is empty");
  for (std::size_t i = 0; i < panels.size(); ++i) {
    if (!panels[i].raster.IsValid(&error))
      throw std::invalid_argument("RenderGridPanels: panels[" + std::to_string(i) + "].raster." +
                                  error);
    if (!panels[i].truth_velocities.empty() &&
        panels[i].truth_velocities.size() != panels[i].truth_boxes.size())
      throw std::invalid_argument("RenderGridPanels: panels[" + std::to_string(i) +
                                  "].truth_velocities: one per truth box, or none");
  }
  if (!(options.arrow_seconds > 0.0) || !std::isfinite(options.arrow_seconds))
    throw std::invalid_argument("RenderGridPanels: options.arrow_seconds must be positive");
}

std::vector<LegendItem> LegendItems(const std::vector<GridPanel>& panels,
                                    const GridFigureOptions& options) {
  std::vector<LegendItem> items = {
      {"free", colors::kWhite},
      {"static", colors::kBlack},
      {"unknown", colors::kUnknown},
  };
  const auto any = [&](auto member) {
    return std::any_of(panels.begin(), panels.end(),
                       [&](const GridPanel& p) { return !(p.*member).empty(); });
  };
  if (any(&GridPanel::truth_boxes))
    items.push_back({options.truth_label, colors::kBlack, Marker::kOutline});
  if (any(&GridPanel::ego_boxes)) items.push_back({"ego", kEgoOutline, Marker::kOutline});
  if (any(&GridPanel::particles)) items.push_back({"particle", colors::kBlack, Marker::kDot});
  if (any(&GridPanel::clusters)) {
    items.push_back({"cluster: matched", ClusterRoleColor(0), Marker::kOutline});
    items.push_back({"duplicate", ClusterRoleColor(1), Marker::kOutline});
    items.push_back({"false", ClusterRoleColor(2), Marker::kOutline});
  }
  if (any(&GridPanel::clusters) || any(&GridPanel::truth_velocities))
    items.push_back({"velocity over ground", colors::kBlack, Marker::kArrow});
  return items;
}

// The line under the legend items: how the cell colours combine.
std::string ColoringNote(const GridFigureOptions& options) {
  char buf[96];
  if (options.cell.coloring == CellColoring::kThreshold)
    std::snprintf(buf, sizeof buf, "wheel: direction of motion, shown if P(dyn) > %g",
                  options.cell.dynamic_threshold);
  else
    std::snprintf(buf, sizeof buf, "wheel: direction of motion; colours blended by mass");
  return buf;
}

// The legend band under the panels: the hue wheel (width and height) and the items right of it.
struct LegendBand {
  double wheel_w, wheel_h, items_x, items_w, items_h, height;
};

LegendBand BandFor(cairo_t* m, const Metrics& k, const std::vector<LegendItem>& items,
                   const GridFigureOptions& options) {
  const int image_width = options.image_width;
  LegendBand b;
  b.wheel_w = 2.0 * k.wheel_r + 2.0 * (detail::TextWidth(m, "\u2212x", k.sm) + 2.0 * k.u);
  b.wheel_h = 2.0 * k.wheel_r + 2.0 * detail::LineHeight(k.sm);
  b.items_x = k.pad + b.wheel_w + 6.0 * k.u;
  b.items_w = image_width - b.items_x - k.pad;
  b.items_h = detail::LayoutLegendRow(m, items, 0.0, 0.0, b.items_w, k.sm, false);
  b.height =
      std::max(b.wheel_h, b.items_h + detail::DrawParagraph(m, ColoringNote(options), 0.0, 0.0,
                                                            b.items_w, {.size = k.sm}, false));
  return b;
}

struct Placement {
  GridFigureLayout layout;
  int columns = 1;
  double legend_top = 0.0, caption_top = 0.0, x_label_y = 0.0;
};

Placement Place(cairo_t* m, const std::vector<GridPanel>& panels, const GridFigureOptions& options,
                const Metrics& k) {
  Placement p;
  p.layout.width = options.image_width;
  const int n = static_cast<int>(panels.size());
  int columns = std::min(options.columns, n);
  if (columns == 0) {
    const WorldRect e = panels.front().raster.Extent();
    const double aspect = (e.max.x() - e.min.x()) / std::max(1e-9, e.max.y() - e.min.y());
    columns = aspect <= 2.5 ? n : 1;
  }
  p.columns = columns;
  // Left margin: the y label and the y tick labels, measured on a first guess of the panel size.
  const auto map_width = [&](double left) {
    return std::max(
        10, static_cast<int>((options.image_width - left - k.pad - (columns - 1) * k.col_gap) /
                             columns));
  };
  const double label_band = options.y_label.empty() ? 0.0 : detail::LineHeight(k.fs) + k.u;
  double left = k.pad + label_band + 30.0 * k.u;
  for (int pass = 0; pass < 2; ++pass) {
    const MapTransform guess(panels.front().raster.Extent(), map_width(left));
    left = k.pad + label_band + detail::MapAxesLabelWidth(m, guess, AxesStyle(k, true, true));
  }
  const int map_w = map_width(left);
  double y = k.pad + k.TitleHeight() + (k.title_lines.empty() ? 0.0 : k.gap);
  const int rows = (n + columns - 1) / columns;
  for (int i = 0; i < n; ++i) {
    const int col = i % columns, row = i / columns;
    if (col == 0) y += k.panel_title;
    p.layout.panels.emplace_back(panels[i].raster.Extent(), map_w,
                                 Vector2(left + col * (map_w + k.col_gap), y));
    if (col == columns - 1 || i == n - 1) {
      double row_h = 0.0;
      for (int j = row * columns; j <= i; ++j)
        row_h = std::max(row_h, double(p.layout.panels[j].pixel_height()));
      // Inner rows share the bottom row's x labels: their tick marks only.
      y += row_h + (row == rows - 1 ? 0.0 : k.tick + k.gap);
    }
  }
  y += k.tick + 0.3 * k.sm + detail::LineHeight(k.sm);  // the bottom row's tick labels
  p.x_label_y = y + k.u;
  if (!options.x_label.empty()) y += k.u + detail::LineHeight(k.fs);
  p.legend_top = y + 3.0 * k.u;
  const LegendBand band = BandFor(m, k, LegendItems(panels, options), options);
  y = p.legend_top + band.height;
  p.caption_top = y + 3.0 * k.u;
  const double caption_h = detail::DrawParagraph(
      m, options.caption, k.pad, 0.0, options.image_width - 2.0 * k.pad, {.size = k.sm}, false);
  if (caption_h > 0.0) y = p.caption_top + caption_h;
  p.layout.height = static_cast<int>(std::ceil(y + k.pad));
  return p;
}

// One image pixel per cell, rows flipped so world +y is up; painted scaled with NEAREST filtering
// so cells stay crisp and adjacent cells leave no antialiasing seams.
detail::SurfacePtr RasterSurface(const GridRaster& g, const CellColorOptions& options) {
  detail::SurfacePtr img(cairo_image_surface_create(CAIRO_FORMAT_RGB24, g.cells_x, g.cells_y));
  if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("RenderGridPanels: cannot create the raster surface");
  detail::FillCellImage(img.get(), g, options);
  return img;
}

}  // namespace

namespace detail {

void FillCellImage(cairo_surface_t* img, const GridRaster& g, const CellColorOptions& options) {
  cairo_surface_flush(img);
  unsigned char* data = cairo_image_surface_get_data(img);
  const int stride = cairo_image_surface_get_stride(img);
  auto to8 = [](double c) {
    return static_cast<std::uint32_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
  };
  for (int y = 0; y < g.cells_y; ++y) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + (g.cells_y - 1 - y) * stride);
    for (int x = 0; x < g.cells_x; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * g.cells_x + x;
      const Rgba c =
          CellColor(g.free[i], g.static_occ[i], g.dynamic[i], g.mean_vx[i], g.mean_vy[i], options);
      row[x] = 0xFF000000u | (to8(c.r) << 16) | (to8(c.g) << 8) | to8(c.b);
    }
  }
  cairo_surface_mark_dirty(img);
}

void PaintCellImage(cairo_t* cr, const MapTransform& t, const GridRaster& g, cairo_surface_t* img) {
  cairo_save(cr);
  const Vector2 top_left = t.ToPixel(g.origin + Vector2(0.0, g.cells_y * g.resolution));
  cairo_translate(cr, top_left.x(), top_left.y());
  cairo_scale(cr, t.scale() * g.resolution, t.scale() * g.resolution);
  cairo_set_source_surface(cr, img, 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_rectangle(cr, 0.0, 0.0, g.cells_x, g.cells_y);
  cairo_fill(cr);
  cairo_restore(cr);
}

}  // namespace detail
namespace {

void PathBox(cairo_t* cr, const MapTransform& t, const OrientedBox& box) {
  cairo_new_path(cr);
  for (const Position& c : box.Corners()) {
    const Vector2 p = t.ToPixel(c);
    cairo_line_to(cr, p.x(), p.y());
  }
  cairo_close_path(cr);
}

void StrokeHaloed(cairo_t* cr, const MapTransform& t, const OrientedBox& box, const Rgba& color,
                  double u) {
  // White halo under the outline keeps it visible on black (static) and on any hue; both thin,
  // so that a car (2 pt wide at one column) still shows its cells.
  PathBox(cr, t, box);
  SetColor(cr, colors::kWhite);
  cairo_set_line_width(cr, 1.3 * u);
  cairo_stroke(cr);
  PathBox(cr, t, box);
  SetColor(cr, color);
  cairo_set_line_width(cr, 0.6 * u);
  cairo_stroke(cr);
}

void DrawPanel(cairo_t* cr, const GridPanel& panel, const MapTransform& t,
               const GridFigureOptions& options, const Metrics& k, bool label_x, bool label_y,
               double left_room, double right_room) {
  const double x0 = t.pixel_offset().x(), y0 = t.pixel_offset().y();
  const double w = t.pixel_width(), h = t.pixel_height();
  const GridRaster& g = panel.raster;

  // Title, with the mode's colour as a swatch when the title names a mode.
  const double title_y = y0 - 0.5 * k.panel_title;
  double title_x = x0;
  if (const auto mode = ModeFromName(panel.title)) {
    cairo_rectangle(cr, x0, title_y - 0.4 * k.fs, 0.8 * k.fs, 0.8 * k.fs);
    SetColor(cr, ModeColor(*mode));
    cairo_fill(cr);
    title_x += 1.2 * k.fs;
  }
  DrawText(cr, panel.title, title_x, title_y, {.size = k.fs, .bold = true, .v = VAlign::kMiddle});

  cairo_save(cr);
  cairo_rectangle(cr, x0, y0, w, h);
  cairo_clip(cr);
  SetColor(cr, colors::kUnknown);
  cairo_paint(cr);
  {
    detail::SurfacePtr img = RasterSurface(g, options.cell);
    detail::PaintCellImage(cr, t, g, img.get());
  }
  if (!panel.particles.empty()) {
    SetColor(cr, WithAlpha(colors::kBlack, 0.5));
    const double d = 0.5 * k.u;
    for (const Position& p : panel.particles) {
      const Vector2 q = t.ToPixel(p);
      cairo_rectangle(cr, q.x() - 0.5 * d, q.y() - 0.5 * d, d, d);
    }
    cairo_fill(cr);
  }
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
  for (const OrientedBox& b : panel.ego_boxes) StrokeHaloed(cr, t, b, kEgoOutline, k.u);
  for (const OrientedBox& b : panel.truth_boxes) StrokeHaloed(cr, t, b, colors::kBlack, k.u);
  // Velocity arrows over ground, on a white halo so they read over any cell colour.
  const auto arrow = [&](const Position& from, const Velocity& v, const Rgba& color) {
    const Vector2 a = t.ToPixel(from), b = a + t.VectorToPixel(v * options.arrow_seconds);
    if ((b - a).norm() < 0.5 * k.u) return;
    SetColor(cr, colors::kWhite);
    detail::DrawArrow(cr, a.x(), a.y(), b.x(), b.y(), 1.1 * k.u, 3.0 * k.u);
    SetColor(cr, color);
    detail::DrawArrow(cr, a.x(), a.y(), b.x(), b.y(), 0.5 * k.u, 2.4 * k.u);
  };
  for (std::size_t i = 0; i < panel.truth_velocities.size(); ++i)
    arrow(panel.truth_boxes[i].center, panel.truth_velocities[i], colors::kBlack);
  for (const GridCluster& c : panel.clusters) {
    const Vector2 a = t.ToPixel({c.min.x(), c.max.y()}), b = t.ToPixel({c.max.x(), c.min.y()});
    // A little outside the members' box, so that a one-cell cluster still shows an outline.
    const double pad = 0.6 * k.u;
    for (const auto& [color, width] :
         {std::pair{colors::kWhite, 1.3 * k.u}, std::pair{ClusterRoleColor(c.role), 0.6 * k.u}}) {
      cairo_rectangle(cr, a.x() - pad, a.y() - pad, b.x() - a.x() + 2 * pad,
                      b.y() - a.y() + 2 * pad);
      SetColor(cr, color);
      cairo_set_line_width(cr, width);
      cairo_stroke(cr);
    }
    arrow(c.center, c.velocity, ClusterRoleColor(c.role));
  }
  cairo_restore(cr);
  detail::MapAxesStyle axes = AxesStyle(k, label_x, label_y);
  axes.label_left_room = left_room;
  axes.label_right_room = right_room;
  detail::DrawMapAxes(cr, t, axes);
}

// Hue wheel (a ring) in world orientation (+x right, +y up), drawn pixel by pixel at the PNG's
// resolution: sector paths would leave antialiasing seams between sectors.
void DrawHueWheel(cairo_t* cr, double cx, double cy, double r, double png_scale, double u) {
  const double s = std::max(1.0, png_scale);
  const int n = static_cast<int>(std::ceil(2.0 * r * s)) + 2;
  const double rr = r * s;
  detail::SurfacePtr ring(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, n, n));
  cairo_surface_flush(ring.get());
  unsigned char* data = cairo_image_surface_get_data(ring.get());
  const int stride = cairo_image_surface_get_stride(ring.get());
  for (int j = 0; j < n; ++j) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + j * stride);
    for (int i = 0; i < n; ++i) {
      const double dx = i + 0.5 - 0.5 * n, dy = 0.5 * n - (j + 0.5);
      const double d = std::hypot(dx, dy);
      // Coverage of a 1-px-wide soft edge on both rims, premultiplied into the colour.
      const double a =
          std::clamp(rr - d + 0.5, 0.0, 1.0) * std::clamp(d - 0.45 * rr + 0.5, 0.0, 1.0);
      const Rgba c = HueColor(std::atan2(dy, dx));
      const auto ch = [a](double v) {
        return static_cast<std::uint32_t>(std::lround(v * a * 255.0));
      };
      row[i] = (ch(1.0) << 24) | (ch(c.r) << 16) | (ch(c.g) << 8) | ch(c.b);
    }
  }
  cairo_surface_mark_dirty(ring.get());
  cairo_save(cr);
  cairo_translate(cr, cx - 0.5 * n / s, cy - 0.5 * n / s);
  cairo_scale(cr, 1.0 / s, 1.0 / s);
  cairo_set_source_surface(cr, ring.get(), 0.0, 0.0);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_new_path(cr);
  cairo_arc(cr, cx, cy, r, 0.0, 2.0 * kPi);
  SetColor(cr, colors::kBlack);
  cairo_set_line_width(cr, 0.5 * u);
  cairo_stroke(cr);
}

void DrawLegendBand(cairo_t* cr, const std::vector<GridPanel>& panels,
                    const GridFigureOptions& options, const Metrics& k, double top) {
  const std::vector<LegendItem> items = LegendItems(panels, options);
  const LegendBand band = BandFor(cr, k, items, options);
  const double cx = k.pad + 0.5 * band.wheel_w, cy = top + 0.5 * band.wheel_h;
  DrawHueWheel(cr, cx, cy, k.wheel_r, options.png_scale, k.u);
  const detail::TextStyle lab{.size = k.sm, .h = HAlign::kCenter, .v = VAlign::kMiddle};
  const double side = k.wheel_r + 0.5 * detail::TextWidth(cr, "\u2212x", k.sm) + 1.5 * k.u;
  DrawText(cr, "+x", cx + side, cy, lab);
  DrawText(cr, "\u2212x", cx - side, cy, lab);
  DrawText(cr, "+y", cx, cy - k.wheel_r - 0.5 * detail::LineHeight(k.sm), lab);
  DrawText(cr, "\u2212y", cx, cy + k.wheel_r + 0.5 * detail::LineHeight(k.sm), lab);
  detail::LayoutLegendRow(cr, items, band.items_x, top, band.items_w, k.sm, true);
  detail::DrawParagraph(cr, ColoringNote(options), band.items_x, top + band.items_h, band.items_w,
                        {.size = k.sm});
}

}  // namespace

GridFigureLayout LayoutGridPanels(const std::vector<GridPanel>& panels,
                                  const GridFigureOptions& options) {
  Validate(panels, options);
  detail::Measure m;
  return Place(m.cr(), panels, options, MetricsFor(m.cr(), options)).layout;
}

void RenderGridPanels(const std::vector<GridPanel>& panels, const std::string& path,
                      const GridFigureOptions& options) {
  Validate(panels, options);
  detail::Measure m;
  const Metrics k = MetricsFor(m.cr(), options);
  const Placement p = Place(m.cr(), panels, options, k);
  const GridFigureLayout& layout = p.layout;
  detail::Canvas canvas(layout.width, layout.height);
  canvas.SetRasterScale(options.png_scale);
  cairo_t* cr = canvas.cr();
  for (std::size_t i = 0; i < k.title_lines.size(); ++i)
    DrawText(cr, k.title_lines[i], 0.5 * layout.width, k.pad + i * detail::LineHeight(1.05 * k.fs),
             {.size = 1.05 * k.fs, .bold = true, .h = HAlign::kCenter, .v = VAlign::kTop});
  const double last_y = layout.panels.back().pixel_offset().y();
  for (std::size_t i = 0; i < panels.size(); ++i) {
    const MapTransform& t = layout.panels[i];
    const int col = static_cast<int>(i) % p.columns;
    // Shared axes: x labels under the bottom row, y labels left of the first column; x labels
    // stay clear of the neighbouring panels' and of the image's edge.
    const double left_room = col == 0 ? t.pixel_offset().x() - k.pad : 0.5 * k.col_gap;
    const double right_room = col == p.columns - 1 || i + 1 == panels.size()
                                  ? layout.width - k.pad - t.pixel_offset().x() - t.pixel_width()
                                  : 0.5 * k.col_gap;
    DrawPanel(cr, panels[i], t, options, k, t.pixel_offset().y() == last_y, col == 0, left_room,
              right_room);
  }
  for (const MapTransform& t : layout.panels) {
    if (t.pixel_offset().y() != last_y) continue;
    DrawText(cr, options.x_label, t.pixel_offset().x() + 0.5 * t.pixel_width(), p.x_label_y,
             {.size = k.fs, .h = HAlign::kCenter, .v = VAlign::kTop});
  }
  if (!options.y_label.empty()) {
    // Centred on the panels' column, left of the tick labels.
    const MapTransform& first = layout.panels.front();
    const double top = first.pixel_offset().y();
    const double bottom =
        layout.panels.back().pixel_offset().y() + layout.panels.back().pixel_height();
    DrawText(cr, options.y_label, k.pad + 0.5 * detail::LineHeight(k.fs), 0.5 * (top + bottom),
             {.size = k.fs, .h = HAlign::kCenter, .v = VAlign::kMiddle, .angle = -0.5 * kPi});
  }
  DrawLegendBand(cr, panels, options, k, p.legend_top);
  detail::DrawParagraph(cr, options.caption, k.pad, p.caption_top, layout.width - 2.0 * k.pad,
                        {.size = k.sm});
  canvas.Save(path);
}

}  // namespace dualgrid::viz
