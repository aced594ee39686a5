#include "dualgrid/viz/birds_eye_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "draw.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::viz {

using detail::DrawText;
using detail::HAlign;
using detail::LegendItem;
using detail::Marker;
using detail::SetColor;
using detail::VAlign;

bool BirdsEyeOptions::IsValid(std::string* error) const {
  FieldCheck c;
  c.InRange("pixel_width", pixel_width, 100, 20000);
  c.Expect(font_size == 0.0 || (font_size >= 2.0 && font_size <= 200.0), "font_size", font_size,
           "0 (automatic) or in [2, 200] pt");
  c.InRange("png_scale", png_scale, 0.0, 32.0, Interval::kLeftOpen);
  return c.Done(error);
}

double BirdsEyeOptions::BaseFont() const {
  return font_size > 0.0 ? font_size : BaseFontSize(pixel_width);
}

bool DetectionStyle::IsValid(std::string* error) const {
  FieldCheck c;
  c.Positive("max_speed", max_speed, "m/s");
  c.NonNegative("arrow_scale", arrow_scale, "s");
  c.InRange("radius_px", radius_px, 0.0, 50.0, Interval::kLeftOpen);
  return c.Done(error);
}

namespace {

// Sizes in u: one point at one column width (base font 8 pt); the picture looks the same at any
// width, only larger.
struct Sizes {
  double fs, sm, u, pad, gap;
  explicit Sizes(const BirdsEyeOptions& o)
      : fs(o.BaseFont()), sm(0.9 * fs), u(fs / 8.0), pad(4.0 * u), gap(2.0 * u) {}
  detail::MapAxesStyle Axes() const {
    return {.font_size = sm, .tick_length = 2.5 * u, .line_width = 0.6 * u};
  }
};

// Margins around the map: left (y ticks and label) and right (half the last x tick label).
struct Margins {
  double left = 0.0, right = 0.0;
};

Margins MarginsFor(const WorldRect& world, const BirdsEyeOptions& o, const Sizes& z) {
  if (!o.axes) return {};
  detail::Measure m;
  Margins g{z.pad + (o.y_label.empty() ? 0.0 : detail::LineHeight(z.fs) + z.u) + 20.0 * z.u,
            z.pad + 6.0 * z.u};
  for (int pass = 0; pass < 2; ++pass) {
    const int w = std::max(10, static_cast<int>(o.pixel_width - g.left - g.right));
    g.left = z.pad + (o.y_label.empty() ? 0.0 : detail::LineHeight(z.fs) + z.u) +
             detail::MapAxesLabelWidth(m.cr(), MapTransform(world, w), z.Axes());
  }
  return g;
}

int MapWidth(const BirdsEyeOptions& o, const Margins& g) {
  return std::max(10, static_cast<int>(o.pixel_width - g.left - g.right));
}

// Width of the right part of the legend band (scale bar without axes, speed colour bar).
double RightBlock(const BirdsEyeOptions& o, bool speed_bar) {
  return (!o.axes || speed_bar) ? 0.42 * o.pixel_width : 0.0;
}

}  // namespace

struct BirdsEyeView::Impl {
  Impl(const WorldRect& world, const BirdsEyeOptions& opt)
      : options(opt),
        z(opt),
        margins(MarginsFor(world, opt, z)),
        transform(world, MapWidth(opt, margins)),
        map(transform.pixel_width(), transform.pixel_height()) {
    cairo_set_line_join(map.cr(), CAIRO_LINE_JOIN_ROUND);
    if (!opt.title.empty())
      title_lines = detail::WrapText(measure.cr(), opt.title, 1.05 * z.fs,
                                     opt.pixel_width - 2.0 * z.pad, true);
  }

  void AddLegend(const LegendItem& item) {
    for (const LegendItem& l : legend)
      if (l.label == item.label) return;
    legend.push_back(item);
  }
  double TitleHeight() const {
    return title_lines.empty()
               ? 0.0
               : z.pad + title_lines.size() * detail::LineHeight(1.05 * z.fs) + z.gap;
  }
  double AxesHeight() const {
    if (!options.axes) return 0.0;
    return z.Axes().tick_length + 0.3 * z.sm + detail::LineHeight(z.sm) +
           (options.x_label.empty() ? 0.0 : z.u + detail::LineHeight(z.fs));
  }
  double LegendWidth() const {
    return options.pixel_width - RightBlock(options, speed_bar) - 2.0 * z.pad;
  }
  double LegendHeight() const {
    const double left =
        detail::LayoutLegendRow(measure.cr(), legend, 0.0, 0.0, LegendWidth(), z.sm, false);
    double right = 0.0;
    if (!options.axes) right = 1.6 * z.sm;
    if (speed_bar) right += 3.2 * z.sm;
    return std::max(left, right);
  }
  double CaptionHeight() const {
    return detail::DrawParagraph(measure.cr(), options.caption, 0.0, 0.0,
                                 options.pixel_width - 2.0 * z.pad, {.size = z.sm}, false);
  }
  Vector2 MapOffset() const { return {margins.left, TitleHeight()}; }
  void PathPolyline(const std::vector<Position>& line) const {
    cairo_t* cr = map.cr();
    cairo_new_path(cr);
    for (const Position& p : line) {
      const Vector2 px = transform.ToPixel(p);
      cairo_line_to(cr, px.x(), px.y());
    }
  }

  BirdsEyeOptions options;
  Sizes z;
  Margins margins;
  MapTransform transform;
  detail::Canvas map;
  detail::Measure measure;
  std::vector<std::string> title_lines;
  std::vector<LegendItem> legend;
  // Labels placed so far (x0, y0, x1, y1 in map units): a label goes above its box, else below,
  // where it overlaps none of them.
  struct Box {
    double x0, y0, x1, y1;
    bool Overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  };
  std::vector<Box> labels;  // and the ego's box
  int labels_left_out = 0;
  bool InView(const Vector2& p) const {
    return p.x() >= 0.0 && p.y() >= 0.0 && p.x() <= transform.pixel_width() &&
           p.y() <= transform.pixel_height();
  }
  bool speed_bar = false;
  double max_speed = 0.0;
};

BirdsEyeView::BirdsEyeView(const WorldRect& world, const BirdsEyeOptions& options) {
  std::string error;
  if (!world.IsValid(&error)) throw std::invalid_argument("BirdsEyeView: world." + error);
  if (!options.IsValid(&error)) throw std::invalid_argument("BirdsEyeView: options." + error);
  impl_ = std::make_unique<Impl>(world, options);
}

BirdsEyeView::~BirdsEyeView() = default;

const MapTransform& BirdsEyeView::transform() const { return impl_->transform; }

Vector2 BirdsEyeView::ToImagePixel(const Position& world) const {
  return impl_->transform.ToPixel(world) + impl_->MapOffset();
}

int BirdsEyeView::image_width() const { return impl_->options.pixel_width; }

int BirdsEyeView::image_height() const {
  const Impl& im = *impl_;
  const double caption = im.CaptionHeight();
  const double h = im.TitleHeight() + im.transform.pixel_height() + im.AxesHeight() + im.z.pad +
                   im.LegendHeight() + (caption > 0.0 ? im.z.gap + caption : 0.0) + im.z.pad;
  return static_cast<int>(std::ceil(h));
}

void BirdsEyeView::DrawLane(const std::vector<Position>& centre_line, double width) {
  if (!(width > 0.0) || !std::isfinite(width))
    throw std::invalid_argument("BirdsEyeView::DrawLane: width must be positive");
  if (centre_line.size() < 2) return;
  cairo_t* cr = impl_->map.cr();
  const double w = width * impl_->transform.scale(), u = impl_->z.u;
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  // A slightly wider dark band under the light one leaves a thin edge line between lanes.
  impl_->PathPolyline(centre_line);
  SetColor(cr, colors::kLaneEdge);
  cairo_set_line_width(cr, w + 0.4 * u);
  cairo_stroke(cr);
  impl_->PathPolyline(centre_line);
  SetColor(cr, colors::kLane);
  cairo_set_line_width(cr, std::max(0.3 * u, w - 0.4 * u));
  cairo_stroke(cr);
  cairo_restore(cr);
  impl_->AddLegend({"lane", colors::kLane, Marker::kSwatch, colors::kLaneEdge});
}

void BirdsEyeView::DrawGuardRail(const std::vector<Position>& polyline, double width) {
  if (polyline.size() < 2) return;
  cairo_t* cr = impl_->map.cr();
  cairo_save(cr);
  impl_->PathPolyline(polyline);
  SetColor(cr, colors::kGuardRail);
  cairo_set_line_width(cr, std::max(0.8 * impl_->z.u, width * impl_->transform.scale()));
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(cr);
  cairo_restore(cr);
  impl_->AddLegend({"guard rail", colors::kGuardRail, Marker::kLine});
}

void BirdsEyeView::DrawVehicle(const OrientedBox& box, const VehicleStyle& style) {
  cairo_t* cr = impl_->map.cr();
  const MapTransform& t = impl_->transform;
  const double u = impl_->z.u;
  const Rgba fill = style.ego ? colors::kEgo : style.fill;
  double top = 1e300, bottom = -1e300, left = 1e300, right = -1e300;
  for (const Position& c : box.Corners()) {
    const Vector2 p = t.ToPixel(c);
    top = std::min(top, p.y());
    bottom = std::max(bottom, p.y());
    left = std::min(left, p.x());
    right = std::max(right, p.x());
  }
  // A box outside the map draws nothing and adds no legend entry.
  if (right < 0.0 || bottom < 0.0 || left > t.pixel_width() || top > t.pixel_height()) return;
  cairo_save(cr);
  cairo_new_path(cr);
  for (const Position& c : box.Corners()) {
    const Vector2 p = t.ToPixel(c);
    cairo_line_to(cr, p.x(), p.y());
  }
  cairo_close_path(cr);
  SetColor(cr, fill);
  cairo_fill_preserve(cr);
  SetColor(cr, style.ego ? colors::kBlack : Mix(fill, colors::kBlack, 0.55));
  cairo_set_line_width(cr, (style.ego ? 0.9 : 0.5) * u);
  cairo_stroke(cr);
  // Heading mark: a darker triangle in the front quarter of the box.
  const Vector2 f = UnitVector(box.yaw), l = UnitVector(box.yaw + 0.5 * kPi);
  const Position apex = box.center + f * (0.45 * box.length);
  const Position base = box.center + f * (0.2 * box.length);
  const Vector2 a = t.ToPixel(apex), b1 = t.ToPixel(base + l * (0.3 * box.width)),
                b2 = t.ToPixel(base - l * (0.3 * box.width));
  cairo_move_to(cr, a.x(), a.y());
  cairo_line_to(cr, b1.x(), b1.y());
  cairo_line_to(cr, b2.x(), b2.y());
  cairo_close_path(cr);
  SetColor(cr, WithAlpha(Mix(fill, colors::kBlack, 0.6), 0.6));
  cairo_fill(cr);
  if (style.velocity && style.arrow_scale > 0.0) {
    const Vector2 c = t.ToPixel(box.center);
    const Vector2 e = c + t.VectorToPixel(*style.velocity * style.arrow_scale);
    SetColor(cr, colors::kBlack);
    detail::DrawArrow(cr, c.x(), c.y(), e.x(), e.y(), 0.7 * u, 3.2 * u);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s (%g s)",
                  style.velocity_legend.empty() ? "velocity" : style.velocity_legend.c_str(),
                  style.arrow_scale);
    impl_->AddLegend({buf, colors::kBlack, Marker::kArrow});
  }
  cairo_restore(cr);
  // The ego's box is kept clear of the labels drawn after it.
  if (style.ego) impl_->labels.push_back({left, top, right, bottom});
  if (!style.label.empty()) {
    const double sm = impl_->z.sm;
    const double w = detail::TextWidth(cr, style.label, sm, style.ego), h = detail::LineHeight(sm);
    // Centred over the box, but inside the map (a label cut by the edge is unreadable).
    const double cx0 = std::clamp(t.ToPixel(box.center).x(), 0.5 * w,
                                  std::max(0.5 * w, t.pixel_width() - 0.5 * w));
    // Free: inside the map and clear of the labels placed so far and of the ego.
    const auto free = [&](const Impl::Box& b) {
      return b.y0 >= 0.0 && b.y1 <= t.pixel_height() && b.x0 >= 0.0 &&
             b.x1 <= t.pixel_width() + 1e-9 &&
             std::none_of(impl_->labels.begin(), impl_->labels.end(),
                          [&](const Impl::Box& o) { return o.Overlaps(b); });
    };
    // Candidates, nearest first: above, below, then stepped further out (a leader line joins a
    // label to its box), then beside. A label with no free place is left out rather than drawn
    // over another.
    std::optional<Impl::Box> at;
    for (int k = 0; k < 8 && !at; ++k) {
      for (const double shift : {0.0, -0.6 * w - u, 0.6 * w + u}) {
        if (k < 2 && shift != 0.0) continue;
        const double cx = cx0 + shift;
        const double gap = 0.8 * u + k * (h + 0.3 * u);
        const Impl::Box above{cx - 0.5 * w, top - gap - h, cx + 0.5 * w, top - gap};
        const Impl::Box below{cx - 0.5 * w, bottom + gap, cx + 0.5 * w, bottom + gap + h};
        if (free(above))
          at = above;
        else if (free(below))
          at = below;
        if (at) break;
      }
    }
    if (at) {
      impl_->labels.push_back(*at);
      const double cx = 0.5 * (at->x0 + at->x1);
      const bool is_above = at->y1 <= top;
      const double edge = is_above ? top : bottom;
      const double near = is_above ? at->y1 : at->y0;
      if (std::abs(near - edge) > 1.5 * u || std::abs(cx - t.ToPixel(box.center).x()) > 0.5 * w) {
        cairo_save(cr);
        SetColor(cr, WithAlpha(colors::kBlack, 0.6));
        cairo_set_line_width(cr, 0.35 * u);
        cairo_move_to(cr, cx, near);
        cairo_line_to(cr, std::clamp(cx, left, right), edge);
        cairo_stroke(cr);
        cairo_restore(cr);
      }
      DrawText(cr, style.label, cx, at->y1 - 0.2 * h,
               {.size = sm,
                .bold = style.ego,
                .h = HAlign::kCenter,
                .v = VAlign::kBottom,
                .halo = true});
    } else {
      ++impl_->labels_left_out;
    }
  }
  const std::string legend = !style.legend.empty() ? style.legend : style.ego ? "ego" : "vehicle";
  impl_->AddLegend({legend, fill, Marker::kSwatch, Mix(fill, colors::kBlack, 0.55)});
}

std::vector<std::array<double, 4>> BirdsEyeView::label_boxes() const {
  std::vector<std::array<double, 4>> out;
  for (const auto& b : impl_->labels) out.push_back({b.x0, b.y0, b.x1, b.y1});
  return out;
}

int BirdsEyeView::labels_left_out() const { return impl_->labels_left_out; }

void BirdsEyeView::KeepLabelsOff(const OrientedBox& box) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const Position& c : box.Corners()) {
    const Vector2 p = impl_->transform.ToPixel(c);
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  impl_->labels.push_back({x0, y0, x1, y1});
}

void BirdsEyeView::DrawSensorFov(const SensorFov& fov) {
  if (!fov.origin.allFinite() || !std::isfinite(fov.boresight))
    throw std::invalid_argument("BirdsEyeView::DrawSensorFov: origin and boresight must be finite");
  if (!(fov.half_fov > 0.0 && fov.half_fov <= kPi))
    throw std::invalid_argument("BirdsEyeView::DrawSensorFov: half_fov must be in (0, pi]");
  if (!(fov.max_range > 0.0) || !std::isfinite(fov.max_range))
    throw std::invalid_argument("BirdsEyeView::DrawSensorFov: max_range must be positive");
  cairo_t* cr = impl_->map.cr();
  const MapTransform& t = impl_->transform;
  const Vector2 o = t.ToPixel(fov.origin);
  const double r = fov.max_range * t.scale();
  const Rgba c = SensorColor(fov.sensor_index);
  cairo_save(cr);
  cairo_new_path(cr);
  if (fov.half_fov >= kPi) {
    cairo_arc(cr, o.x(), o.y(), r, 0.0, 2.0 * kPi);
  } else {
    // Image y points down, so a world angle a is the screen angle -a.
    cairo_move_to(cr, o.x(), o.y());
    cairo_arc(cr, o.x(), o.y(), r, -(fov.boresight + fov.half_fov),
              -(fov.boresight - fov.half_fov));
    cairo_close_path(cr);
  }
  // A faint tint and an opaque outline: overlapping wedges stay readable by their outlines.
  SetColor(cr, WithAlpha(c, kSensorFovTint));
  cairo_fill_preserve(cr);
  SetColor(cr, c);
  cairo_set_line_width(cr, 0.6 * impl_->z.u);
  cairo_stroke(cr);
  cairo_restore(cr);
  const std::string name =
      fov.name.empty() ? "sensor " + std::to_string(fov.sensor_index) : fov.name;
  impl_->AddLegend({name, c, Marker::kSensor});
}

void BirdsEyeView::DrawDetections(const std::vector<DetectionMark>& detections,
                                  const DetectionStyle& style) {
  std::string error;
  if (!style.IsValid(&error))
    throw std::invalid_argument("BirdsEyeView::DrawDetections: style." + error);
  cairo_t* cr = impl_->map.cr();
  const MapTransform& t = impl_->transform;
  const double u = impl_->z.u;
  const bool by_speed = style.coloring == DetectionColoring::kBySpeed;
  const auto color_of = [&](const DetectionMark& d) {
    return by_speed ? SequentialColor(d.radial_velocity.norm() / style.max_speed)
                    : SensorColor(d.sensor_index);
  };
  bool any_clutter = false, any_target = false, any_arrow = false;
  cairo_save(cr);
  // Arrows first so the dots stay visible on top.
  if (style.arrow_scale > 0.0) {
    for (const DetectionMark& d : detections) {
      if (d.clutter && !style.clutter_arrows) continue;
      if (!impl_->InView(t.ToPixel(d.position))) continue;
      const Vector2 v = d.radial_velocity * style.arrow_scale;
      if (v.norm() * t.scale() < 1.0 * u) continue;
      const Vector2 p = t.ToPixel(d.position), e = p + t.VectorToPixel(v);
      SetColor(cr, WithAlpha(color_of(d), 0.9));
      detail::DrawArrow(cr, p.x(), p.y(), e.x(), e.y(), 0.5 * u, 2.4 * u);
      any_arrow = true;
    }
  }
  const double radius = style.radius_px * u;
  for (const DetectionMark& d : detections) {
    const Vector2 p = t.ToPixel(d.position);
    if (!impl_->InView(p)) continue;  // outside: no legend entry for it either
    SetColor(cr, color_of(d));
    if (d.clutter) {
      detail::DrawCross(cr, p.x(), p.y(), radius, 0.5 * u);
      any_clutter = true;
    } else {
      cairo_new_path(cr);
      cairo_arc(cr, p.x(), p.y(), radius, 0.0, 2.0 * kPi);
      cairo_fill_preserve(cr);
      SetColor(cr, WithAlpha(colors::kBlack, 0.6));
      cairo_set_line_width(cr, 0.25 * u);
      cairo_stroke(cr);
      any_target = true;
    }
  }
  cairo_restore(cr);
  const Rgba legend_color = by_speed ? SequentialColor(0.5) : Rgba{0.35, 0.35, 0.35, 1.0};
  if (any_target) impl_->AddLegend({"detection", legend_color, Marker::kDot});
  if (any_clutter)
    impl_->AddLegend({std::string("clutter") + (style.clutter_arrows ? "" : ", no arrow"),
                      legend_color, Marker::kCross});
  if (any_arrow) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "radial velocity (%g s)", style.arrow_scale);
    impl_->AddLegend({buf, legend_color, Marker::kArrow});
  }
  if (by_speed) {
    impl_->speed_bar = true;
    impl_->max_speed = std::max(impl_->max_speed, style.max_speed);
  }
}

void BirdsEyeView::DrawLabel(const Position& at, const std::string& text) {
  const Vector2 p = impl_->transform.ToPixel(at);
  DrawText(impl_->map.cr(), text, p.x(), p.y(),
           {.size = impl_->z.sm, .v = VAlign::kMiddle, .halo = true});
}

void BirdsEyeView::Save(const std::string& path) const {
  const Impl& im = *impl_;
  const Sizes& z = im.z;
  const double fs = z.fs, sm = z.sm, u = z.u;
  const Vector2 off = im.MapOffset();
  const double map_w = im.transform.pixel_width(), map_h = im.transform.pixel_height();
  detail::Canvas out(image_width(), image_height());
  out.SetRasterScale(im.options.png_scale);
  cairo_t* cr = out.cr();
  out.PaintCanvas(im.map, off.x(), off.y());
  for (std::size_t i = 0; i < im.title_lines.size(); ++i)
    DrawText(cr, im.title_lines[i], 0.5 * out.width(), z.pad + i * detail::LineHeight(1.05 * fs),
             {.size = 1.05 * fs, .bold = true, .h = HAlign::kCenter, .v = VAlign::kTop});
  if (im.options.axes) {
    MapTransform placed(im.transform.world(), im.transform.pixel_width(), off);
    detail::MapAxesStyle axes = z.Axes();
    axes.label_left_room = off.x();
    axes.label_right_room = im.margins.right;
    detail::DrawMapAxes(cr, placed, axes);
    DrawText(cr, im.options.x_label, off.x() + 0.5 * map_w,
             off.y() + map_h + im.AxesHeight() - detail::LineHeight(fs),
             {.size = fs, .h = HAlign::kCenter, .v = VAlign::kTop});
    DrawText(cr, im.options.y_label, z.pad + 0.5 * detail::LineHeight(fs), off.y() + 0.5 * map_h,
             {.size = fs, .h = HAlign::kCenter, .v = VAlign::kMiddle, .angle = -0.5 * kPi});
  } else {
    // A thin frame separates the map from the bands.
    cairo_rectangle(cr, 0.25 * u, off.y() + 0.25 * u, out.width() - 0.5 * u, map_h - 0.5 * u);
    SetColor(cr, {0.6, 0.6, 0.6, 1.0});
    cairo_set_line_width(cr, 0.5 * u);
    cairo_stroke(cr);
  }
  const double band_y = off.y() + map_h + im.AxesHeight() + z.pad;
  detail::LayoutLegendRow(cr, im.legend, z.pad, band_y, im.LegendWidth(), sm, true);
  const double right_x = out.width() - RightBlock(im.options, im.speed_bar) + z.pad;
  double right_y = band_y;
  if (!im.options.axes) {
    detail::DrawScaleBar(cr, right_x, band_y + 1.1 * sm, im.transform.scale(),
                         0.5 * RightBlock(im.options, im.speed_bar), sm);
    right_y += 1.6 * sm;
  }
  if (im.speed_bar) {
    // Horizontal colour bar for |compensated radial speed|.
    const double bar_w = 0.45 * RightBlock(im.options, true);
    const double y = right_y + 0.5 * u, h = 0.8 * sm;
    const int steps = 64;
    for (int i = 0; i < steps; ++i) {
      SetColor(cr, SequentialColor((i + 0.5) / steps));
      cairo_rectangle(cr, right_x + bar_w * i / steps, y, bar_w / steps + 0.05 * u, h);
      cairo_fill(cr);
    }
    cairo_rectangle(cr, right_x, y, bar_w, h);
    SetColor(cr, colors::kBlack);
    cairo_set_line_width(cr, 0.4 * u);
    cairo_stroke(cr);
    const detail::TextStyle tick{.size = sm, .h = HAlign::kCenter, .v = VAlign::kTop};
    char buf[32];
    DrawText(cr, "0", right_x, y + h + 0.3 * u, tick);
    std::snprintf(buf, sizeof buf, "%g", im.max_speed);
    DrawText(cr, buf, right_x + bar_w, y + h + 0.3 * u, tick);
    DrawText(cr, "|v_r| [m/s]", right_x + bar_w + 2.0 * u, y + 0.5 * h,
             {.size = sm, .v = VAlign::kMiddle});
  }
  detail::DrawParagraph(cr, im.options.caption, z.pad, band_y + im.LegendHeight() + z.gap,
                        out.width() - 2.0 * z.pad, {.size = sm});
  out.Save(path);
}

}  // namespace dualgrid::viz
