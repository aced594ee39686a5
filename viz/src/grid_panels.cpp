#include "dualgrid/viz/grid_panels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include "draw.hpp"

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
  auto fail = [&](const std::string& msg) {
    if (error) *error = msg;
    return false;
  };
  if (cells_x <= 0) return fail("cells_x must be positive");
  if (cells_y <= 0) return fail("cells_y must be positive");
  if (!(resolution > 0.0) || !std::isfinite(resolution)) return fail("resolution must be positive");
  if (!origin.allFinite()) return fail("origin must be finite");
  const std::size_t n = static_cast<std::size_t>(cells_x) * static_cast<std::size_t>(cells_y);
  const std::pair<const char*, const std::vector<float>*> arrays[] = {
      {"free", &free},       {"static_occ", &static_occ}, {"dynamic", &dynamic},
      {"mean_vx", &mean_vx}, {"mean_vy", &mean_vy},
  };
  for (const auto& [name, values] : arrays) {
    if (values->size() != n)
      return fail(std::string(name) + " has " + std::to_string(values->size()) +
                  " values, expected cells_x * cells_y = " + std::to_string(n));
  }
  return true;
}

bool CellColorOptions::IsValid(std::string* error) const {
  if (!(dynamic_threshold >= 0.0 && dynamic_threshold <= 1.0)) {
    if (error) *error = "dynamic_threshold must be in [0, 1]";
    return false;
  }
  return true;
}

bool GridFigureOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& msg) {
    if (error) *error = msg;
    return false;
  };
  if (image_width < 500 || image_width > 20000) return fail("image_width must be in [500, 20000]");
  if (!(font_size >= 6.0 && font_size <= 40.0)) return fail("font_size must be in [6, 40]");
  if (columns < 0) return fail("columns must be >= 0 (0: automatic)");
  std::string sub;
  if (!cell.IsValid(&sub)) return fail("cell." + sub);
  return true;
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

struct Metrics {
  double left, right_col, fig_title, panel_title, tick_band, x_label, pad;
};

Metrics MetricsFor(const GridFigureOptions& o) {
  const double fs = o.font_size;
  return {std::round(fs * 4.6),
          std::round(fs * 15.0),
          o.title.empty() ? 0.0 : std::round(fs * 1.3 * 2.4),
          std::round(fs * 2.0),
          std::round(fs * 1.7),
          std::round(fs * 1.8),
          8.0};
}

// Height the legend column needs, from the same constants DrawLegendColumn uses.
double LegendColumnHeight(double fs, double wheel_r, int items) {
  return fs * 2.6 + 2.0 * wheel_r + fs * 2.6 + fs * 1.4 + items * fs * 1.6 + fs * 3.0;
}

double WheelRadius(double fs) { return std::round(fs * 3.6); }

void Validate(const std::vector<GridPanel>& panels, const GridFigureOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("RenderGridPanels: options." + error);
  if (panels.empty()) throw std::invalid_argument("RenderGridPanels: panels is empty");
  for (std::size_t i = 0; i < panels.size(); ++i) {
    if (!panels[i].raster.IsValid(&error))
      throw std::invalid_argument("RenderGridPanels: panels[" + std::to_string(i) + "].raster." +
                                  error);
  }
}

// One image pixel per cell, rows flipped so world +y is up; painted scaled with NEAREST filtering
// so cells stay crisp and adjacent cells leave no antialiasing seams.
detail::SurfacePtr RasterSurface(const GridRaster& g, const CellColorOptions& options) {
  detail::SurfacePtr img(cairo_image_surface_create(CAIRO_FORMAT_RGB24, g.cells_x, g.cells_y));
  if (cairo_surface_status(img.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("RenderGridPanels: cannot create the raster surface");
  cairo_surface_flush(img.get());
  unsigned char* data = cairo_image_surface_get_data(img.get());
  const int stride = cairo_image_surface_get_stride(img.get());
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
  cairo_surface_mark_dirty(img.get());
  return img;
}

void PathBox(cairo_t* cr, const MapTransform& t, const OrientedBox& box) {
  cairo_new_path(cr);
  for (const Position& c : box.Corners()) {
    const Vector2 p = t.ToPixel(c);
    cairo_line_to(cr, p.x(), p.y());
  }
  cairo_close_path(cr);
}

void StrokeHaloed(cairo_t* cr, const MapTransform& t, const OrientedBox& box, const Rgba& color) {
  // White halo under the outline keeps it visible on black (static) and on any hue.
  PathBox(cr, t, box);
  SetColor(cr, colors::kWhite);
  cairo_set_line_width(cr, 4.0);
  cairo_stroke(cr);
  PathBox(cr, t, box);
  SetColor(cr, color);
  cairo_set_line_width(cr, 2.0);
  cairo_stroke(cr);
}

constexpr Rgba kEgoOutline{0.05, 0.55, 0.05, 1.0};

void DrawPanel(cairo_t* cr, const GridPanel& panel, const MapTransform& t,
               const GridFigureOptions& options, const Metrics& m) {
  const double fs = options.font_size;
  const double x0 = t.pixel_offset().x(), y0 = t.pixel_offset().y();
  const double w = t.pixel_width(), h = t.pixel_height();
  const GridRaster& g = panel.raster;

  // Title, with the mode's colour as a swatch when the title names a mode.
  double title_x = x0;
  if (const auto mode = ModeFromName(panel.title)) {
    cairo_rectangle(cr, x0, y0 - m.panel_title * 0.5 - fs * 0.4, fs * 0.8, fs * 0.8);
    SetColor(cr, ModeColor(*mode));
    cairo_fill(cr);
    title_x += fs * 1.2;
  }
  DrawText(cr, panel.title, title_x, y0 - m.panel_title * 0.5,
           {.size = fs * 1.1, .bold = true, .v = VAlign::kMiddle});

  cairo_save(cr);
  cairo_rectangle(cr, x0, y0, w, h);
  cairo_clip(cr);
  SetColor(cr, colors::kUnknown);
  cairo_paint(cr);
  {
    detail::SurfacePtr img = RasterSurface(g, options.cell);
    cairo_save(cr);
    const Vector2 top_left = t.ToPixel(g.origin + Vector2(0.0, g.cells_y * g.resolution));
    cairo_translate(cr, top_left.x(), top_left.y());
    cairo_scale(cr, t.scale() * g.resolution, t.scale() * g.resolution);
    cairo_set_source_surface(cr, img.get(), 0.0, 0.0);
    cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
    cairo_rectangle(cr, 0.0, 0.0, g.cells_x, g.cells_y);
    cairo_fill(cr);
    cairo_restore(cr);
  }
  if (!panel.particles.empty()) {
    SetColor(cr, WithAlpha(colors::kBlack, 0.5));
    for (const Position& p : panel.particles) {
      const Vector2 q = t.ToPixel(p);
      cairo_rectangle(cr, q.x() - 0.9, q.y() - 0.9, 1.8, 1.8);
    }
    cairo_fill(cr);
  }
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
  for (const OrientedBox& b : panel.ego_boxes) StrokeHaloed(cr, t, b, kEgoOutline);
  for (const OrientedBox& b : panel.truth_boxes) StrokeHaloed(cr, t, b, colors::kBlack);
  cairo_restore(cr);

  // Frame and ticks (world metres).
  cairo_save(cr);
  SetColor(cr, colors::kBlack);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, x0 - 0.5, y0 - 0.5, w + 1.0, h + 1.0);
  cairo_stroke(cr);
  const WorldRect& wr = t.world();
  const std::vector<double> xt =
      detail::NiceTicks(wr.min.x(), wr.max.x(), std::max(2, int(w / 90)));
  const std::vector<double> yt =
      detail::NiceTicks(wr.min.y(), wr.max.y(), std::max(2, int(h / 45)));
  const detail::TextStyle tick_x{.size = fs * 0.8, .h = HAlign::kCenter, .v = VAlign::kTop};
  const detail::TextStyle tick_y{.size = fs * 0.8, .h = HAlign::kRight, .v = VAlign::kMiddle};
  for (double v : xt) {
    const double px = t.ToPixel({v, wr.min.y()}).x();
    cairo_move_to(cr, px, y0 + h);
    cairo_line_to(cr, px, y0 + h + 5.0);
    cairo_stroke(cr);
    DrawText(cr, detail::FormatTick(v, xt.size() > 1 ? xt[1] - xt[0] : 1.0), px, y0 + h + 6.0,
             tick_x);
  }
  for (double v : yt) {
    const double py = t.ToPixel({wr.min.x(), v}).y();
    cairo_move_to(cr, x0 - 5.0, py);
    cairo_line_to(cr, x0, py);
    cairo_stroke(cr);
    DrawText(cr, detail::FormatTick(v, yt.size() > 1 ? yt[1] - yt[0] : 1.0), x0 - 7.0, py, tick_y);
  }
  cairo_restore(cr);
  DrawText(cr, options.y_label, x0 - m.left + fs * 0.9, y0 + 0.5 * h,
           {.size = fs * 0.9, .h = HAlign::kCenter, .v = VAlign::kMiddle, .angle = -0.5 * kPi});
}

void DrawLegendColumn(cairo_t* cr, double x, double y, const GridFigureOptions& options,
                      const std::vector<LegendItem>& items, double px_per_m) {
  const double fs = options.font_size;
  const double r = WheelRadius(fs);
  DrawText(cr, "dynamic: direction", x, y, {.size = fs * 0.9, .bold = true, .v = VAlign::kTop});
  DrawText(cr, "of motion", x, y + fs * 1.2, {.size = fs * 0.9, .bold = true, .v = VAlign::kTop});
  const double cx = x + fs * 1.8 + r, cy = y + fs * 2.6 + fs * 1.3 + r;
  // Hue wheel (a ring) in world orientation (+x right, +y up), one pixel at a time: sector
  // paths would leave antialiasing seams between sectors.
  {
    const int n = static_cast<int>(2.0 * r) + 2;
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
            std::clamp(r - d + 0.5, 0.0, 1.0) * std::clamp(d - 0.45 * r + 0.5, 0.0, 1.0);
        const Rgba c = HueColor(std::atan2(dy, dx));
        const auto ch = [a](double v) {
          return static_cast<std::uint32_t>(std::lround(v * a * 255.0));
        };
        row[i] = (ch(1.0) << 24) | (ch(c.r) << 16) | (ch(c.g) << 8) | ch(c.b);
      }
    }
    cairo_surface_mark_dirty(ring.get());
    cairo_set_source_surface(cr, ring.get(), cx - 0.5 * n, cy - 0.5 * n);
    cairo_paint(cr);
  }
  cairo_new_path(cr);
  cairo_arc(cr, cx, cy, r, 0.0, 2.0 * kPi);
  SetColor(cr, colors::kBlack);
  cairo_set_line_width(cr, 1.0);
  cairo_stroke(cr);
  const detail::TextStyle lab{.size = fs * 0.85, .h = HAlign::kCenter, .v = VAlign::kMiddle};
  DrawText(cr, "+x", cx + r + fs * 1.0, cy, lab);
  DrawText(cr, "\u2212x", cx - r - fs * 1.0, cy, lab);
  DrawText(cr, "+y", cx, cy - r - fs * 0.7, lab);
  DrawText(cr, "\u2212y", cx, cy + r + fs * 0.7, lab);
  double yy = cy + r + fs * 1.3 + fs * 0.2;
  char buf[96];
  if (options.cell.coloring == CellColoring::kThreshold)
    std::snprintf(buf, sizeof buf, "shown if P(dyn) > %g", options.cell.dynamic_threshold);
  else
    std::snprintf(buf, sizeof buf, "colours blended by mass");
  DrawText(cr, buf, x, yy + fs * 0.7, {.size = fs * 0.8, .v = VAlign::kMiddle});
  yy += fs * 1.4 + fs * 0.8;
  for (const LegendItem& item : items) {
    detail::DrawLegendItem(cr, item, x, yy, fs * 0.9);
    yy += fs * 1.6;
  }
  detail::DrawScaleBar(cr, x, yy + fs * 0.6, px_per_m, 120.0, fs * 0.9);
}

std::vector<LegendItem> LegendItems(const std::vector<GridPanel>& panels) {
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
    items.push_back({"ground truth", colors::kBlack, Marker::kOutline});
  if (any(&GridPanel::ego_boxes)) items.push_back({"ego", kEgoOutline, Marker::kOutline});
  if (any(&GridPanel::particles)) items.push_back({"particle", colors::kBlack, Marker::kDot});
  return items;
}

}  // namespace

GridFigureLayout LayoutGridPanels(const std::vector<GridPanel>& panels,
                                  const GridFigureOptions& options) {
  Validate(panels, options);
  const Metrics m = MetricsFor(options);
  GridFigureLayout layout;
  layout.width = options.image_width;
  const int n = static_cast<int>(panels.size());
  int columns = std::min(options.columns, n);
  if (columns == 0) {
    const WorldRect e = panels.front().raster.Extent();
    const double aspect = (e.max.x() - e.min.x()) / std::max(1e-9, e.max.y() - e.min.y());
    columns = aspect <= 2.5 ? n : 1;
  }
  // Side by side, each panel keeps a left margin for its y ticks.
  const double all_w = options.image_width - m.left - m.right_col;
  const int map_w = static_cast<int>((all_w - (columns - 1) * m.left) / columns);
  double y = m.pad + m.fig_title;
  for (int i = 0; i < n; ++i) {
    const int col = i % columns;
    if (col == 0) y += m.panel_title;
    layout.panels.emplace_back(panels[i].raster.Extent(), map_w,
                               Vector2(m.left + col * (map_w + m.left), y));
    if (col == columns - 1 || i == n - 1)
      y += layout.panels.back().pixel_height() + m.tick_band +
           (i == n - 1 ? 0.0 : m.x_label * (columns > 1 ? 1.0 : 0.0));
  }
  y += m.x_label + m.pad;
  const double fs = options.font_size;
  const double legend_h = m.pad + m.fig_title + m.panel_title +
                          LegendColumnHeight(fs, WheelRadius(fs), LegendItems(panels).size()) +
                          m.pad;
  layout.height = static_cast<int>(std::ceil(std::max(y, legend_h)));
  return layout;
}

void RenderGridPanels(const std::vector<GridPanel>& panels, const std::string& path,
                      const GridFigureOptions& options) {
  const GridFigureLayout layout = LayoutGridPanels(panels, options);
  const Metrics m = MetricsFor(options);
  const double fs = options.font_size;
  detail::Canvas canvas(layout.width, layout.height);
  cairo_t* cr = canvas.cr();
  if (!options.title.empty())
    DrawText(cr, options.title, 0.5 * layout.width, m.pad + 0.5 * m.fig_title,
             {.size = fs * 1.3, .bold = true, .h = HAlign::kCenter, .v = VAlign::kMiddle});
  for (std::size_t i = 0; i < panels.size(); ++i)
    DrawPanel(cr, panels[i], layout.panels[i], options, m);
  // The x label under each panel of the last row (the bottom panel when stacked).
  const double last_y = layout.panels.back().pixel_offset().y();
  for (const MapTransform& t : layout.panels) {
    if (t.pixel_offset().y() != last_y) continue;
    DrawText(cr, options.x_label, t.pixel_offset().x() + 0.5 * t.pixel_width(),
             t.pixel_offset().y() + t.pixel_height() + m.tick_band + 0.5 * m.x_label,
             {.size = fs * 0.9, .h = HAlign::kCenter, .v = VAlign::kMiddle});
  }
  // The legend column right of the rightmost panel.
  const MapTransform* right = &layout.panels.front();
  for (const MapTransform& t : layout.panels)
    if (t.pixel_offset().x() > right->pixel_offset().x()) right = &t;
  const MapTransform& first = *right;
  DrawLegendColumn(cr, first.pixel_offset().x() + first.pixel_width() + fs * 1.5,
                   first.pixel_offset().y(), options, LegendItems(panels), first.scale());
  canvas.Save(path);
}

}  // namespace dualgrid::viz
