#include "chart_frame.hpp"

#include <algorithm>
#include <cmath>

#include "dualgrid/core/types.hpp"

namespace dualgrid::viz::detail {

namespace {
constexpr double kSin45 = 0.70710678118654752;

// Width of the legend in one row, as LayoutLegendRow lays it out (its item gap is 18/14 of the
// font size).
double LegendRowWidth(cairo_t* m, const std::vector<LegendItem>& items, double size) {
  double total = 0.0;
  for (const LegendItem& item : items) total += LegendItemWidth(m, item, size) + size * 18.0 / 14.0;
  return items.empty() ? 0.0 : total - size * 18.0 / 14.0;
}
}  // namespace

int ChartFrame::CanvasWidth() const { return static_cast<int>(std::ceil(layout.width - 1e-9)); }
int ChartFrame::CanvasHeight() const { return static_cast<int>(std::ceil(layout.height - 1e-9)); }

double WidestLabel(cairo_t* m, const std::vector<std::string>& labels, double size) {
  double w = 0.0;
  for (const std::string& l : labels) w = std::max(w, TextWidth(m, l, size));
  return w;
}

ChartFrame LayoutChartFrame(cairo_t* m, const ChartText& text, int width, int height,
                            double y_tick_width, const std::function<double(double)>& x_tick_height,
                            const std::function<double()>& headroom) {
  ChartFrame f;
  f.u = width / kSingleColumn;
  f.base = BaseFontSize(width);
  f.small = SmallFontSize(width);
  f.title_size = 1.05 * f.base;
  f.pad = 5.0 * f.u;
  f.tick_length = 3.0 * f.u;
  f.label_gap = 1.5 * f.u;
  const double gap = 2.0 * f.u;
  PlotArea& a = f.layout.plot;
  // `height` holds a one-line title, one legend row and one line of tick labels: more lines make
  // the image taller, the plot keeps its height.
  const double nominal_top = f.pad + LineHeight(f.title_size) + gap + 1.6 * f.small + gap;
  const double nominal_bottom =
      f.tick_length + f.label_gap + LineHeight(f.small) + f.u + LineHeight(f.base) + f.pad;
  a.height = std::max(30.0 * f.u, height - nominal_top - nominal_bottom);
  // A y label longer than the plot is high wraps into more (turned) lines.
  if (!text.y_label.empty()) f.y_label_lines = WrapText(m, text.y_label, f.base, a.height);
  a.left = f.pad + f.y_label_lines.size() * LineHeight(f.base) +
           (f.y_label_lines.empty() ? 0.0 : f.u) + y_tick_width + f.label_gap + f.tick_length;
  // Room on the right for half of the last x tick label.
  a.width = width - a.left - f.pad - 5.0 * f.u;

  const double title_h =
      text.title.empty() ? 0.0
                         : WrapText(m, text.title, f.title_size, width - 2.0 * f.pad, true).size() *
                               LineHeight(f.title_size);
  const double legend_h = LayoutLegendRow(m, text.legend, 0.0, 0.0, a.width, f.small, false);
  f.title_top = f.pad;
  f.legend_top = f.pad + title_h + (title_h > 0.0 ? gap : 0.0);
  const double row_w = LegendRowWidth(m, text.legend, f.small);
  f.legend_x = row_w <= a.width ? a.left + a.width - row_w : a.left;
  const double x_ticks_h = x_tick_height(a.width);
  a.top = f.legend_top + legend_h + (legend_h > 0.0 ? gap : 0.0) + headroom();

  const double x_label_h = text.x_label.empty() ? 0.0 : f.u + LineHeight(f.base);
  f.x_ticks_top = a.top + a.height + f.tick_length + f.label_gap;
  f.x_label_top = f.x_ticks_top + x_ticks_h + f.u;
  const double body_end = f.x_ticks_top + x_ticks_h + x_label_h;
  f.caption_top = body_end + 2.0 * gap;
  const double caption_h =
      DrawParagraph(m, text.caption, f.pad, 0.0, width - 2.0 * f.pad, {.size = f.small}, false);
  f.layout.width = width;
  // Whole points: the canvas (and the PNG, times its scale) has exactly this size.
  f.layout.height = std::ceil((caption_h > 0.0 ? f.caption_top + caption_h : body_end) + f.pad);
  return f;
}

CategoryLabels FitCategoryLabels(cairo_t* m, const std::vector<std::string>& names,
                                 double plot_width, double size) {
  CategoryLabels fit;
  if (names.empty()) return fit;
  const double slot = plot_width / names.size();
  const double widest = WidestLabel(m, names, size);
  if (widest + 0.5 * size <= slot) {
    fit.height = LineHeight(size);
    return fit;
  }
  fit.rotated = true;
  // Turned 45 degrees, neighbouring names are slot * sin 45 apart across their lines.
  fit.stride = std::max(1, static_cast<int>(std::ceil(LineHeight(size) / (slot * kSin45))));
  fit.height = kSin45 * (widest + size) + 0.35 * size;
  return fit;
}

void DrawCategoryLabels(cairo_t* cr, const ChartFrame& f, const CategoryLabels& fit,
                        const std::vector<std::string>& names) {
  const PlotArea& a = f.layout.plot;
  const double slot = a.width / std::max<std::size_t>(1, names.size());
  for (std::size_t c = 0; c < names.size(); c += fit.stride) {
    const double x = a.left + slot * (c + 0.5);
    if (fit.rotated)
      DrawText(cr, names[c], x, f.x_ticks_top + 0.35 * f.small,
               {.size = f.small, .h = HAlign::kRight, .v = VAlign::kMiddle, .angle = -0.25 * kPi});
    else
      DrawText(cr, names[c], x, f.x_ticks_top,
               {.size = f.small, .h = HAlign::kCenter, .v = VAlign::kTop});
  }
}

void HorizontalTick(cairo_t* cr, const ChartFrame& f, double py, const std::string& label) {
  const PlotArea& a = f.layout.plot;
  cairo_save(cr);
  SetColor(cr, colors::kGridLine);
  cairo_set_line_width(cr, 0.4 * f.u);
  cairo_move_to(cr, a.left, py);
  cairo_line_to(cr, a.left + a.width, py);
  cairo_stroke(cr);
  SetColor(cr, kChartAxis);
  cairo_set_line_width(cr, 0.6 * f.u);
  cairo_move_to(cr, a.left - f.tick_length, py);
  cairo_line_to(cr, a.left, py);
  cairo_stroke(cr);
  cairo_restore(cr);
  DrawText(cr, label, a.left - f.tick_length - f.label_gap, py,
           {.size = f.small, .h = HAlign::kRight, .v = VAlign::kMiddle});
}

void VerticalTick(cairo_t* cr, const ChartFrame& f, double px, const std::string& label) {
  const PlotArea& a = f.layout.plot;
  cairo_save(cr);
  SetColor(cr, kChartAxis);
  cairo_set_line_width(cr, 0.6 * f.u);
  cairo_move_to(cr, px, a.top + a.height);
  cairo_line_to(cr, px, a.top + a.height + f.tick_length);
  cairo_stroke(cr);
  cairo_restore(cr);
  DrawText(cr, label, px, f.x_ticks_top,
           {.size = f.small, .h = HAlign::kCenter, .v = VAlign::kTop});
}

void DrawNoData(cairo_t* cr, const ChartFrame& f) {
  const PlotArea& a = f.layout.plot;
  DrawText(
      cr, "no data", a.left + 0.5 * a.width, a.top + 0.5 * a.height,
      {.size = f.base, .color = {0.4, 0.4, 0.4, 1.0}, .h = HAlign::kCenter, .v = VAlign::kMiddle});
}

void DrawChartFrame(cairo_t* cr, const ChartFrame& f, const ChartText& text) {
  const PlotArea& a = f.layout.plot;
  const double width = f.layout.width;
  cairo_save(cr);
  SetColor(cr, kChartAxis);
  cairo_set_line_width(cr, 0.6 * f.u);
  cairo_rectangle(cr, a.left, a.top, a.width, a.height);
  cairo_stroke(cr);
  cairo_restore(cr);
  const std::vector<std::string> title =
      text.title.empty() ? std::vector<std::string>{}
                         : WrapText(cr, text.title, f.title_size, width - 2.0 * f.pad, true);
  for (std::size_t i = 0; i < title.size(); ++i)
    DrawText(cr, title[i], 0.5 * width, f.title_top + i * LineHeight(f.title_size),
             {.size = f.title_size, .bold = true, .h = HAlign::kCenter, .v = VAlign::kTop});
  LayoutLegendRow(cr, text.legend, f.legend_x, f.legend_top, a.width, f.small, true);
  DrawText(cr, text.x_label, a.left + 0.5 * a.width, f.x_label_top,
           {.size = f.base, .h = HAlign::kCenter, .v = VAlign::kTop});
  for (std::size_t i = 0; i < f.y_label_lines.size(); ++i)
    DrawText(cr, f.y_label_lines[i], f.pad + (i + 0.5) * LineHeight(f.base), a.top + 0.5 * a.height,
             {.size = f.base, .h = HAlign::kCenter, .v = VAlign::kMiddle, .angle = -0.5 * kPi});
  DrawParagraph(cr, text.caption, f.pad, f.caption_top, width - 2.0 * f.pad, {.size = f.small});
}

}  // namespace dualgrid::viz::detail
