#include "dualgrid/viz/replay_frame.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cell_image.hpp"
#include "draw.hpp"
#include "png_file.hpp"

namespace dualgrid::viz {

using detail::DrawText;
using detail::HAlign;
using detail::SetColor;
using detail::TextStyle;
using detail::VAlign;

namespace {

const Rgba kMatched = ClusterRoleColor(0);
const Rgba kDuplicate = ClusterRoleColor(1);
const Rgba kFalse = ClusterRoleColor(2);
constexpr Rgba kOutside{0.93, 0.93, 0.93, 1.0};  // view area the grid does not cover

Rgba RoleColor(int role) { return ClusterRoleColor(role); }

void BoxPath(cairo_t* cr, const MapTransform& t, const OrientedBox& b) {
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double hl = 0.5 * b.length, hw = 0.5 * b.width;
  const double corners[4][2] = {{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}};
  for (int k = 0; k < 4; ++k) {
    const Position p = b.center + Vector2(c * corners[k][0] - s * corners[k][1],
                                          s * corners[k][0] + c * corners[k][1]);
    const Vector2 q = t.ToPixel(p);
    if (k == 0)
      cairo_move_to(cr, q.x(), q.y());
    else
      cairo_line_to(cr, q.x(), q.y());
  }
  cairo_close_path(cr);
}

// An arrow with a white halo, so it reads over any cell colour.
void HaloArrow(cairo_t* cr, const Vector2& a, const Vector2& b, const Rgba& color, double width) {
  if ((b - a).norm() < 1.0) return;
  const double head = 4.0 * width + 4.0;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
  detail::DrawArrow(cr, a.x(), a.y(), b.x(), b.y(), width + 2.5, head + 2.5);
  SetColor(cr, color);
  detail::DrawArrow(cr, a.x(), a.y(), b.x(), b.y(), width, head);
}

}  // namespace

void ReplayLayoutOptions::Validate() const {
  if (width < 320 || width > 7680 || width % 2 != 0)
    throw std::invalid_argument("width: expected an even number of pixels in [320, 7680], got " +
                                std::to_string(width));
  std::string error;
  if (!view.IsValid(&error)) throw std::invalid_argument("view: " + error);
  if (panels < 1 || panels > 8) throw std::invalid_argument("panels: expected 1 to 8");
  if (!(arrow_seconds > 0.0)) throw std::invalid_argument("arrow_seconds: expected > 0");
  if (truth_label.empty()) throw std::invalid_argument("truth_label: expected a name, got ''");
}

struct ReplayRenderer::Impl {
  ReplayLayoutOptions o;
  int width = 0, height = 0, columns = 1;
  double fs = 0.0;        // heading font [px]
  double fs_small = 0.0;  // titles, ticks, legend [px]
  double header_h = 0.0, legend_h = 0.0;
  std::vector<MapTransform> maps;
  detail::SurfacePtr frame;
  detail::SurfacePtr cells;  // one pixel per cell, reused
  int cells_x = 0, cells_y = 0;

  explicit Impl(const ReplayLayoutOptions& options) : o(options) {
    o.Validate();
    width = o.width;
    fs = width / 60.0;
    fs_small = width / 85.0;
    // Side by side when a panel is at most 2.5 times as wide as high (the figures' rule).
    columns = o.view.width() <= 2.5 * o.view.height() ? o.panels : 1;
    const int rows = (o.panels + columns - 1) / columns;
    const double left = 4.2 * fs_small, right = 1.2 * fs_small;
    const double column_w = (width - right) / columns;
    const int map_w = static_cast<int>(column_w - left);
    header_h = 2.4 * fs;
    frame.reset(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, 16));
    {
      detail::ContextPtr scratch(cairo_create(frame.get()));
      legend_h = (DrawLegend(scratch.get(), 0.0, false) + 0.6) * fs_small;
    }
    const double title_h = 1.9 * fs_small, ticks_h = 2.0 * fs_small;
    double y = header_h;
    for (int r = 0; r < rows; ++r) {
      double row_h = 0.0;
      for (int c = 0; c < columns && r * columns + c < o.panels; ++c) {
        maps.emplace_back(o.view, map_w, Vector2(c * column_w + left, y + title_h));
        row_h = std::max(row_h, title_h + maps.back().pixel_height() + ticks_h);
      }
      y += row_h;
    }
    height = static_cast<int>(std::ceil(y + legend_h));
    height += height % 2;
    frame.reset(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height));
    if (cairo_surface_status(frame.get()) != CAIRO_STATUS_SUCCESS)
      throw std::runtime_error("replay frame: cannot allocate " + std::to_string(width) + " x " +
                               std::to_string(height) + " px");
  }

  void PrepareCells(const GridRaster& r) {
    if (!cells || r.cells_x != cells_x || r.cells_y != cells_y) {
      cells.reset(cairo_image_surface_create(CAIRO_FORMAT_RGB24, r.cells_x, r.cells_y));
      // cairo's images end at 32767 px a side: a longer grid cannot be drawn cell by cell.
      if (cairo_surface_status(cells.get()) != CAIRO_STATUS_SUCCESS) {
        cells.reset();
        throw std::invalid_argument("replay frame: a grid of " + std::to_string(r.cells_x) + " x " +
                                    std::to_string(r.cells_y) +
                                    " cells is beyond cairo's 32767 px per side");
      }
      cells_x = r.cells_x;
      cells_y = r.cells_y;
    }
    // The grid figures' colours (CellColor), into the image reused across frames.
    detail::FillCellImage(cells.get(), r, {});
  }

  void DrawAxes(cairo_t* cr, const MapTransform& t) {
    const Vector2 tl = t.pixel_offset();
    const double w = t.pixel_width(), h = t.pixel_height();
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, tl.x() - 0.5, tl.y() - 0.5, w + 1.0, h + 1.0);
    cairo_stroke(cr);
    const TextStyle tick{.size = 0.8 * fs_small, .h = HAlign::kCenter, .v = VAlign::kTop};
    const WorldRect& v = t.world();
    const std::vector<double> xs = detail::NiceTicks(v.min.x(), v.max.x(), 10);
    const double step_x = xs.size() > 1 ? xs[1] - xs[0] : 1.0;
    for (double x : xs) {
      const double px = t.ToPixel({x, v.min.y()}).x();
      cairo_move_to(cr, px, tl.y() + h);
      cairo_line_to(cr, px, tl.y() + h + 0.3 * fs_small);
      cairo_stroke(cr);
      DrawText(cr, detail::FormatTick(x, step_x), px, tl.y() + h + 0.35 * fs_small, tick);
    }
    const std::vector<double> ys = detail::NiceTicks(
        v.min.y(), v.max.y(), std::max(2, static_cast<int>(h / (3.0 * fs_small))));
    const double step_y = ys.size() > 1 ? ys[1] - ys[0] : 1.0;
    for (double y : ys) {
      const double py = t.ToPixel({v.min.x(), y}).y();
      cairo_move_to(cr, tl.x(), py);
      cairo_line_to(cr, tl.x() - 0.3 * fs_small, py);
      cairo_stroke(cr);
      DrawText(cr, detail::FormatTick(y, step_y), tl.x() - 0.4 * fs_small, py,
               {.size = 0.8 * fs_small, .h = HAlign::kRight, .v = VAlign::kMiddle});
    }
  }

  void DrawPanel(cairo_t* cr, std::size_t i, const ReplayPanel& p, const ReplayPicture& pic) {
    const MapTransform& t = maps[i];
    const Vector2 tl = t.pixel_offset();
    const double w = t.pixel_width(), h = t.pixel_height();
    DrawText(cr, p.title, tl.x(), tl.y() - 0.45 * fs_small,
             {.size = fs_small, .bold = true, .v = VAlign::kBottom});
    DrawText(cr, p.live, tl.x() + detail::TextWidth(cr, p.title, fs_small, true) + fs_small,
             tl.y() - 0.45 * fs_small, {.size = 0.9 * fs_small, .v = VAlign::kBottom});
    cairo_save(cr);
    cairo_rectangle(cr, tl.x(), tl.y(), w, h);
    cairo_clip(cr);
    SetColor(cr, kOutside);
    cairo_paint(cr);
    // Cells: one pixel per cell scaled up without smoothing (cells are the grid's truth).
    const GridRaster& r = p.raster;
    PrepareCells(r);
    detail::PaintCellImage(cr, t, r, cells.get());

    cairo_set_source_rgba(cr, 0.1, 0.1, 0.1, 0.55);
    for (const Position& q : p.particles) {
      const Vector2 px = t.ToPixel(q);
      cairo_rectangle(cr, px.x() - 0.75, px.y() - 0.75, 1.5, 1.5);
    }
    cairo_fill(cr);

    const double dot = std::max(2.0, 0.18 * fs_small);
    for (const ReplayDetection& d : pic.detections) {
      const Vector2 px = t.ToPixel(d.position);
      cairo_new_sub_path(cr);
      cairo_arc(cr, px.x(), px.y(), dot, 0.0, 2.0 * kPi);
      SetColor(cr, SensorColor(d.sensor));
      cairo_fill_preserve(cr);
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_set_line_width(cr, 0.6);
      cairo_stroke(cr);
    }

    // Ego: the paper's green.
    BoxPath(cr, t, pic.ego);
    SetColor(cr, colors::kEgo);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_stroke(cr);

    for (std::size_t k = 0; k < p.truth.size(); ++k) {
      BoxPath(cr, t, p.truth[k]);
      cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
      cairo_set_line_width(cr, 4.0);
      cairo_stroke_preserve(cr);
      cairo_set_source_rgb(cr, 0, 0, 0);
      cairo_set_line_width(cr, 1.8);
      cairo_stroke(cr);
      const Vector2 a = t.ToPixel(p.truth[k].center);
      HaloArrow(cr, a, a + t.VectorToPixel(p.truth_velocity[k] * o.arrow_seconds), colors::kBlack,
                1.5);
    }
    for (const ReplayCluster& c : p.clusters) {
      const Vector2 a = t.ToPixel({c.min.x(), c.max.y()}), b = t.ToPixel({c.max.x(), c.min.y()});
      // A cluster of one cell still gets a visible outline.
      const double pad = 2.0;
      cairo_rectangle(cr, a.x() - pad, a.y() - pad, b.x() - a.x() + 2 * pad,
                      b.y() - a.y() + 2 * pad);
      cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
      cairo_set_line_width(cr, 4.5);
      cairo_stroke_preserve(cr);
      SetColor(cr, RoleColor(c.role));
      cairo_set_line_width(cr, 2.2);
      cairo_stroke(cr);
      const Vector2 m = t.ToPixel(c.center);
      HaloArrow(cr, m, m + t.VectorToPixel(c.velocity * o.arrow_seconds), RoleColor(c.role), 2.2);
    }
    cairo_restore(cr);
    DrawAxes(cr, t);
  }

  // One legend entry: a marker drawn by `marker` in a box of the font's height, then the label.
  template <typename F>
  double LegendEntry(cairo_t* cr, double x, double y, const std::string& label, F&& marker) {
    const double s = 0.9 * fs_small;
    cairo_save(cr);
    marker(x, y - 0.5 * s, s);
    cairo_restore(cr);
    DrawText(cr, label, x + 1.3 * s, y, {.size = 0.85 * fs_small, .v = VAlign::kMiddle});
    return 1.3 * s + detail::TextWidth(cr, label, 0.85 * fs_small) + 1.2 * fs_small;
  }

  // Draws the legend rows from y0 (or only measures them); returns their height in fs_small.
  double DrawLegend(cairo_t* cr, double y0, bool draw) {
    const double row_h = 1.6 * fs_small;
    const double x0 = 0.6 * fs_small;
    double x = x0, y = y0 + 0.5 * row_h;
    int rows = 1;
    // Places one entry, wrapping to a new row when it would run past the right edge.
    const auto entry = [&](const std::string& label, auto&& marker) {
      const double w = 1.3 * 0.9 * fs_small + detail::TextWidth(cr, label, 0.85 * fs_small);
      if (x > x0 && x + w > width - x0) {
        x = x0;
        y += row_h;
        ++rows;
      }
      if (draw)
        x += LegendEntry(cr, x, y, label, marker);
      else
        x += w + 1.2 * fs_small;
      return 0.0;
    };
    const auto swatch = [&](const Rgba& c) {
      return [&, c](double x0, double y0, double s) {
        cairo_rectangle(cr, x0, y0, s, s);
        SetColor(cr, c);
        cairo_fill_preserve(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, 1.0);
        cairo_stroke(cr);
      };
    };
    entry("free", swatch(colors::kWhite));
    entry("static", swatch(colors::kBlack));
    entry("unknown", swatch(colors::kUnknown));
    entry("dynamic: hue = direction", [&](double x0, double y0, double s) {
      for (int k = 0; k < 24; ++k) {
        const double a0 = 2 * kPi * k / 24, a1 = 2 * kPi * (k + 1) / 24;
        cairo_move_to(cr, x0 + 0.5 * s, y0 + 0.5 * s);
        // Screen y runs down: a direction angle a is drawn at -a.
        cairo_arc_negative(cr, x0 + 0.5 * s, y0 + 0.5 * s, 0.5 * s, -a0, -a1);
        cairo_close_path(cr);
        SetColor(cr, HueColor(0.5 * (a0 + a1)));
        cairo_fill(cr);
      }
    });
    entry("arrow: " + detail::FormatTick(o.arrow_seconds, 0.1) + " s of travel over ground",
          [&](double x0, double y0, double s) {
            cairo_set_source_rgb(cr, 0, 0, 0);
            detail::DrawArrow(cr, x0, y0 + 0.5 * s, x0 + s, y0 + 0.5 * s, 1.5, 0.5 * s);
          });
    for (std::size_t k = 0; k < o.sensors.size(); ++k)
      entry(o.sensors[k], [&](double x0, double y0, double s) {
        cairo_arc(cr, x0 + 0.5 * s, y0 + 0.5 * s, 0.3 * s, 0.0, 2.0 * kPi);
        SetColor(cr, SensorColor(static_cast<int>(k)));
        cairo_fill(cr);
      });
    if (o.particles)
      entry("particle", [&](double x0, double y0, double s) {
        cairo_set_source_rgba(cr, 0.1, 0.1, 0.1, 0.8);
        cairo_rectangle(cr, x0 + 0.4 * s, y0 + 0.4 * s, 0.2 * s, 0.2 * s);
        cairo_fill(cr);
      });
    entry("axes: metres from the ego, grid frame", [](double, double, double) {});
    return rows * row_h / fs_small;
  }

  void DrawHeader(cairo_t* cr, const ReplayPicture& pic) {
    const double y = 0.5 * header_h;
    DrawText(cr, pic.heading, 0.6 * fs_small, y, {.size = fs, .bold = true, .v = VAlign::kMiddle});
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "t = %.2f s", pic.time);
    double x = 0.6 * fs_small + detail::TextWidth(cr, pic.heading, fs, true) + 1.2 * fs;
    DrawText(cr, stamp, x, y, {.size = fs, .v = VAlign::kMiddle});
    x += detail::TextWidth(cr, "t = 000.00 s", fs) + 1.2 * fs;
    const auto outline = [&](const Rgba& c) {
      return [&, c](double x0, double y0, double s) {
        cairo_rectangle(cr, x0 + 1, y0 + 1, s - 2, s - 2);
        SetColor(cr, c);
        cairo_set_line_width(cr, 2.2);
        cairo_stroke(cr);
      };
    };
    x += LegendEntry(cr, x, y, o.truth_label, outline(colors::kBlack));
    x += LegendEntry(cr, x, y, "ego", outline(colors::kEgo));
    x += LegendEntry(cr, x, y, "cluster: matched", outline(kMatched));
    x += LegendEntry(cr, x, y, "duplicate", outline(kDuplicate));
    x += LegendEntry(cr, x, y, "false", outline(kFalse));
    if (!pic.banner.empty())
      DrawText(cr, pic.banner, width - 0.6 * fs_small, y,
               {.size = fs,
                .bold = true,
                .color = {0.85, 0.0, 0.0, 1.0},
                .h = HAlign::kRight,
                .v = VAlign::kMiddle});
  }
};

ReplayRenderer::ReplayRenderer(const ReplayLayoutOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
ReplayRenderer::~ReplayRenderer() = default;
int ReplayRenderer::width() const { return impl_->width; }
int ReplayRenderer::height() const { return impl_->height; }

Vector2 ReplayRenderer::ToPixel(std::size_t panel, const Position& relative) const {
  return impl_->maps.at(panel).ToPixel(relative);
}

const std::uint8_t* ReplayRenderer::Render(const ReplayPicture& picture) {
  Impl& m = *impl_;
  if (picture.panels.size() != static_cast<std::size_t>(m.o.panels))
    throw std::invalid_argument("replay frame: " + std::to_string(picture.panels.size()) +
                                " panels, the layout has " + std::to_string(m.o.panels));
  for (std::size_t i = 0; i < picture.panels.size(); ++i) {
    std::string error;
    if (!picture.panels[i].raster.IsValid(&error))
      throw std::invalid_argument("replay frame: panels[" + std::to_string(i) +
                                  "].raster: " + error);
    if (picture.panels[i].truth_velocity.size() != picture.panels[i].truth.size())
      throw std::invalid_argument("replay frame: panels[" + std::to_string(i) +
                                  "].truth_velocity: one per truth box expected");
  }
  detail::ContextPtr ctx(cairo_create(m.frame.get()));
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  m.DrawHeader(cr, picture);
  for (std::size_t i = 0; i < picture.panels.size(); ++i)
    m.DrawPanel(cr, i, picture.panels[i], picture);
  m.DrawLegend(cr, m.height - m.legend_h, true);
  ctx.reset();
  cairo_surface_flush(m.frame.get());
  return cairo_image_surface_get_data(m.frame.get());
}

void ReplayRenderer::SavePng(const std::string& path) const {
  if (!detail::WritePng(impl_->frame.get(), path)) throw std::runtime_error("cannot write " + path);
}

}  // namespace dualgrid::viz
