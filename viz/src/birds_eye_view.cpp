#include "dualgrid/viz/birds_eye_view.hpp"

#include <algorithm>
#include <cmath>
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

bool BirdsEyeOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* msg) {
    if (error) *error = msg;
    return false;
  };
  if (pixel_width < 200 || pixel_width > 20000) return fail("pixel_width must be in [200, 20000]");
  if (!(font_size >= 6.0 && font_size <= 72.0)) return fail("font_size must be in [6, 72]");
  return true;
}

bool DetectionStyle::IsValid(std::string* error) const {
  auto fail = [&](const char* msg) {
    if (error) *error = msg;
    return false;
  };
  if (!(max_speed > 0.0) || !std::isfinite(max_speed)) return fail("max_speed must be positive");
  if (!(arrow_scale >= 0.0) || !std::isfinite(arrow_scale))
    return fail("arrow_scale must be non-negative");
  if (!(radius_px > 0.0 && radius_px <= 50.0)) return fail("radius_px must be in (0, 50]");
  return true;
}

namespace {
constexpr double kPad = 10.0;
// Right part of the legend band: scale bar and speed colour bar.
constexpr double kRightBlock = 300.0;
constexpr double kColorBarWidth = 160.0;
}  // namespace

struct BirdsEyeView::Impl {
  Impl(const WorldRect& world, const BirdsEyeOptions& opt)
      : options(opt),
        transform(world, opt.pixel_width),
        map(transform.pixel_width(), transform.pixel_height()) {
    cairo_set_line_join(map.cr(), CAIRO_LINE_JOIN_ROUND);
  }

  void AddLegend(const LegendItem& item) {
    for (const LegendItem& l : legend)
      if (l.label == item.label) return;
    legend.push_back(item);
  }
  double TitleHeight() const {
    return options.title.empty() ? 0.0 : std::round(options.font_size * 1.3 * 2.2);
  }
  double LegendHeight() const {
    const double fs = options.font_size;
    const double left = detail::LayoutLegendRow(
        map.cr(), legend, kPad, 0.0, options.pixel_width - kRightBlock - 2 * kPad, fs, false);
    const double right = fs * 1.6 + (speed_bar ? fs * 3.2 : 0.0);
    return std::round(std::max(left, right) + 2.0 * kPad);
  }
  void PathPolyline(const std::vector<Position>& line) const {
    cairo_t* cr = map.cr();
    cairo_new_path(cr);
    for (const Position& p : line) {
      const Vector2 px = transform.ToPixel(p);
      cairo_line_to(cr, px.x(), px.y());
    }
  }

  BirdsEyeOptions options;
  MapTransform transform;
  detail::Canvas map;
  std::vector<LegendItem> legend;
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
  return impl_->transform.ToPixel(world) + Vector2(0.0, impl_->TitleHeight());
}

int BirdsEyeView::image_width() const { return impl_->transform.pixel_width(); }

int BirdsEyeView::image_height() const {
  return static_cast<int>(impl_->TitleHeight()) + impl_->transform.pixel_height() +
         static_cast<int>(impl_->LegendHeight());
}

void BirdsEyeView::DrawLane(const std::vector<Position>& centre_line, double width) {
  if (!(width > 0.0) || !std::isfinite(width))
    throw std::invalid_argument("BirdsEyeView::DrawLane: width must be positive");
  if (centre_line.size() < 2) return;
  cairo_t* cr = impl_->map.cr();
  const double w = width * impl_->transform.scale();
  cairo_save(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  // A slightly wider dark band under the light one leaves a thin edge line between lanes.
  impl_->PathPolyline(centre_line);
  SetColor(cr, colors::kLaneEdge);
  cairo_set_line_width(cr, w + 1.5);
  cairo_stroke(cr);
  impl_->PathPolyline(centre_line);
  SetColor(cr, colors::kLane);
  cairo_set_line_width(cr, std::max(1.0, w - 1.5));
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
  cairo_set_line_width(cr, std::max(2.0, width * impl_->transform.scale()));
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_stroke(cr);
  cairo_restore(cr);
  impl_->AddLegend({"guard rail", colors::kGuardRail, Marker::kLine});
}

void BirdsEyeView::DrawVehicle(const OrientedBox& box, const VehicleStyle& style) {
  cairo_t* cr = impl_->map.cr();
  const MapTransform& t = impl_->transform;
  const Rgba fill = style.ego ? colors::kEgo : style.fill;
  cairo_save(cr);
  cairo_new_path(cr);
  double top = 1e300;
  for (const Position& c : box.Corners()) {
    const Vector2 p = t.ToPixel(c);
    cairo_line_to(cr, p.x(), p.y());
    top = std::min(top, p.y());
  }
  cairo_close_path(cr);
  SetColor(cr, fill);
  cairo_fill_preserve(cr);
  SetColor(cr, style.ego ? colors::kBlack : Mix(fill, colors::kBlack, 0.55));
  cairo_set_line_width(cr, style.ego ? 2.5 : 1.5);
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
    detail::DrawArrow(cr, c.x(), c.y(), e.x(), e.y(), 1.8, 8.0);
    char buf[64];
    std::snprintf(buf, sizeof buf, "velocity (%g s)", style.arrow_scale);
    impl_->AddLegend({buf, colors::kBlack, Marker::kArrow});
  }
  cairo_restore(cr);
  if (!style.label.empty()) {
    DrawText(cr, style.label, t.ToPixel(box.center).x(), top - 3.0,
             {.size = impl_->options.font_size * 0.85,
              .bold = style.ego,
              .h = HAlign::kCenter,
              .v = VAlign::kBottom,
              .halo = true});
  }
  if (style.ego)
    impl_->AddLegend({"ego", colors::kEgo});
  else
    impl_->AddLegend({"vehicle", colors::kVehicle, Marker::kSwatch,
                      Mix(colors::kVehicle, colors::kBlack, 0.55)});
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
  SetColor(cr, WithAlpha(c, 0.12));
  cairo_fill_preserve(cr);
  SetColor(cr, WithAlpha(c, 0.6));
  cairo_set_line_width(cr, 1.2);
  cairo_stroke(cr);
  cairo_restore(cr);
  const std::string name =
      fov.name.empty() ? "sensor " + std::to_string(fov.sensor_index) : fov.name;
  impl_->AddLegend({name, c, Marker::kWedge});
}

void BirdsEyeView::DrawDetections(const std::vector<DetectionMark>& detections,
                                  const DetectionStyle& style) {
  std::string error;
  if (!style.IsValid(&error))
    throw std::invalid_argument("BirdsEyeView::DrawDetections: style." + error);
  cairo_t* cr = impl_->map.cr();
  const MapTransform& t = impl_->transform;
  const bool by_speed = style.coloring == DetectionColoring::kBySpeed;
  bool any_clutter = false, any_target = false, any_arrow = false;
  cairo_save(cr);
  // Arrows first so the dots stay visible on top.
  if (style.arrow_scale > 0.0) {
    for (const DetectionMark& d : detections) {
      const Vector2 v = d.radial_velocity * style.arrow_scale;
      if (v.norm() * t.scale() < 2.0) continue;
      const Rgba c = by_speed ? SequentialColor(d.radial_velocity.norm() / style.max_speed)
                              : SensorColor(d.sensor_index);
      const Vector2 p = t.ToPixel(d.position), e = p + t.VectorToPixel(v);
      SetColor(cr, WithAlpha(c, 0.85));
      detail::DrawArrow(cr, p.x(), p.y(), e.x(), e.y(), 1.2, 6.0);
      any_arrow = true;
    }
  }
  for (const DetectionMark& d : detections) {
    const Rgba c = by_speed ? SequentialColor(d.radial_velocity.norm() / style.max_speed)
                            : SensorColor(d.sensor_index);
    const Vector2 p = t.ToPixel(d.position);
    if (d.clutter) {
      SetColor(cr, c);
      detail::DrawCross(cr, p.x(), p.y(), style.radius_px * 1.2, 1.6);
      any_clutter = true;
    } else {
      cairo_new_path(cr);
      cairo_arc(cr, p.x(), p.y(), style.radius_px, 0.0, 2.0 * kPi);
      SetColor(cr, c);
      cairo_fill_preserve(cr);
      SetColor(cr, WithAlpha(colors::kBlack, 0.6));
      cairo_set_line_width(cr, 0.6);
      cairo_stroke(cr);
      any_target = true;
    }
  }
  cairo_restore(cr);
  const Rgba legend_color = by_speed ? SequentialColor(0.5) : Rgba{0.35, 0.35, 0.35, 1.0};
  if (any_target) impl_->AddLegend({"detection", legend_color, Marker::kDot});
  if (any_clutter) impl_->AddLegend({"clutter", legend_color, Marker::kCross});
  if (any_arrow) {
    char buf[64];
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
           {.size = impl_->options.font_size, .v = VAlign::kMiddle, .halo = true});
}

void BirdsEyeView::Save(const std::string& path) const {
  const Impl& im = *impl_;
  const double fs = im.options.font_size;
  const double title_h = im.TitleHeight();
  const int map_h = im.transform.pixel_height();
  detail::Canvas out(image_width(), image_height());
  cairo_t* cr = out.cr();
  cairo_set_source_surface(cr, im.map.surface(), 0.0, title_h);
  cairo_paint(cr);
  // Thin frame around the map separates it from the bands.
  cairo_rectangle(cr, 0.5, title_h + 0.5, out.width() - 1.0, map_h - 1.0);
  SetColor(cr, {0.6, 0.6, 0.6, 1.0});
  cairo_set_line_width(cr, 1.0);
  cairo_stroke(cr);
  if (title_h > 0.0)
    DrawText(cr, im.options.title, 0.5 * out.width(), 0.5 * title_h,
             {.size = fs * 1.3, .bold = true, .h = HAlign::kCenter, .v = VAlign::kMiddle});
  const double band_y = title_h + map_h + kPad;
  detail::LayoutLegendRow(cr, im.legend, kPad, band_y, out.width() - kRightBlock - 2 * kPad, fs,
                          true);
  const double right_x = out.width() - kRightBlock + kPad;
  detail::DrawScaleBar(cr, right_x, band_y + fs * 1.1, im.transform.scale(), kRightBlock * 0.55,
                       fs);
  if (im.speed_bar) {
    // Horizontal colour bar for |compensated radial speed|.
    const double y = band_y + fs * 1.6 + 4.0, h = fs * 0.8;
    for (int i = 0; i < static_cast<int>(kColorBarWidth); ++i) {
      SetColor(cr, SequentialColor((i + 0.5) / kColorBarWidth));
      cairo_rectangle(cr, right_x + i, y, 1.0, h);
      cairo_fill(cr);
    }
    cairo_rectangle(cr, right_x + 0.5, y + 0.5, kColorBarWidth - 1.0, h - 1.0);
    SetColor(cr, colors::kBlack);
    cairo_stroke(cr);
    const detail::TextStyle tick{.size = fs * 0.8, .h = HAlign::kCenter, .v = VAlign::kTop};
    char buf[32];
    DrawText(cr, "0", right_x, y + h + 1.0, tick);
    std::snprintf(buf, sizeof buf, "%g", im.max_speed);
    DrawText(cr, buf, right_x + kColorBarWidth, y + h + 1.0, tick);
    DrawText(cr, "|v_r| [m/s]", right_x + kColorBarWidth + 8.0, y + 0.5 * h,
             {.size = fs, .v = VAlign::kMiddle});
  }
  out.Save(path);
}

}  // namespace dualgrid::viz
