#include "dualgrid/viz/charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "draw.hpp"
#include "dualgrid/core/types.hpp"

namespace dualgrid::viz {

using detail::DrawText;
using detail::HAlign;
using detail::LegendItem;
using detail::Marker;
using detail::SetColor;
using detail::TextStyle;
using detail::VAlign;

namespace {
constexpr double kFont = 14.0;
constexpr Rgba kAxis{0.2, 0.2, 0.2, 1.0};

bool Fail(std::string* error, const std::string& msg) {
  if (error) *error = msg;
  return false;
}

bool ValidSize(int width, int height, std::string* error) {
  if (width < 300 || width > 10000) return Fail(error, "width must be in [300, 10000]");
  if (height < 200 || height > 10000) return Fail(error, "height must be in [200, 10000]");
  return true;
}

Rgba SeriesColor(const std::string& name, const std::optional<Rgba>& color, int index) {
  if (color) return *color;
  if (const auto mode = ModeFromName(name)) return ModeColor(*mode);
  return CategoryColor(index);
}

// Title on top, legend right-aligned under it (wrapping to the left edge if it is too wide).
void DrawHeader(cairo_t* cr, const std::string& title, const std::vector<LegendItem>& legend,
                const PlotArea& area, int width) {
  DrawText(cr, title, 0.5 * width, 22.0,
           {.size = kFont * 1.3, .bold = true, .h = HAlign::kCenter, .v = VAlign::kMiddle});
  double total = 0.0;
  for (const LegendItem& item : legend) total += detail::LegendItemWidth(cr, item, kFont) + 18.0;
  total -= 18.0;
  const double x = total <= area.width ? area.left + area.width - total : area.left;
  detail::LayoutLegendRow(cr, legend, x, 38.0, area.width, kFont, true);
}

void DrawAxisLabels(cairo_t* cr, const PlotArea& a, const std::string& x_label,
                    const std::string& y_label) {
  DrawText(cr, x_label, a.left + 0.5 * a.width, a.top + a.height + 44.0,
           {.size = kFont, .h = HAlign::kCenter, .v = VAlign::kMiddle});
  DrawText(cr, y_label, 18.0, a.top + 0.5 * a.height,
           {.size = kFont, .h = HAlign::kCenter, .v = VAlign::kMiddle, .angle = -0.5 * kPi});
}

void DrawFrame(cairo_t* cr, const PlotArea& a) {
  cairo_save(cr);
  SetColor(cr, kAxis);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, std::round(a.left) - 0.5, std::round(a.top) - 0.5, std::round(a.width) + 1.0,
                  std::round(a.height) + 1.0);
  cairo_stroke(cr);
  cairo_restore(cr);
}

void HorizontalGridLine(cairo_t* cr, const PlotArea& a, double py) {
  cairo_save(cr);
  SetColor(cr, colors::kGridLine);
  cairo_set_line_width(cr, 1.0);
  cairo_move_to(cr, a.left, std::round(py) + 0.5);
  cairo_line_to(cr, a.left + a.width, std::round(py) + 0.5);
  cairo_stroke(cr);
  SetColor(cr, kAxis);
  cairo_move_to(cr, a.left - 5.0, std::round(py) + 0.5);
  cairo_line_to(cr, a.left, std::round(py) + 0.5);
  cairo_stroke(cr);
  cairo_restore(cr);
}

// Linear axis [lo, hi] widened to whole ticks, with the ticks.
struct LinearAxis {
  double lo, hi;
  std::vector<double> ticks;
};

LinearAxis NiceAxis(double lo, double hi, bool fixed_lo, bool fixed_hi, int target) {
  if (!(hi > lo)) {
    if (fixed_hi && !fixed_lo) lo = hi;
    hi = lo;
    const double pad = std::max(1.0, std::abs(lo) * 0.1);
    lo -= pad;
    hi += pad;
  }
  std::vector<double> t = detail::NiceTicks(lo, hi, target);
  const double step = t.size() > 1 ? t[1] - t[0] : (hi - lo);
  if (!fixed_lo) lo = std::floor(lo / step + 1e-9) * step;
  if (!fixed_hi) hi = std::ceil(hi / step - 1e-9) * step;
  return {lo, hi, detail::NiceTicks(lo, hi, target)};
}

// A chart with nothing to show still renders: its frame with a note, so a figure of an empty or
// degenerate run is a picture that says so rather than an error.
void DrawNoData(cairo_t* cr, const PlotArea& a, const std::string& what) {
  DrawText(
      cr, what, a.left + 0.5 * a.width, a.top + 0.5 * a.height,
      {.size = kFont, .color = {0.4, 0.4, 0.4, 1.0}, .h = HAlign::kCenter, .v = VAlign::kMiddle});
}

}  // namespace

PlotArea ChartPlotArea(int width, int height) {
  return {84.0, 78.0, width - 84.0 - 28.0, height - 78.0 - 66.0};
}

bool BarChart::IsValid(std::string* error) const {
  if (!ValidSize(width, height, error)) return false;
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (series[i].values.size() != categories.size())
      return Fail(error, "series[" + std::to_string(i) + "].values has " +
                             std::to_string(series[i].values.size()) + " values, expected " +
                             std::to_string(categories.size()) + " (one per category)");
    for (double v : series[i].values)
      if (std::isinf(v)) return Fail(error, "series[" + std::to_string(i) + "].values has inf");
    if (!series[i].errors.empty() && series[i].errors.size() != categories.size())
      return Fail(error, "series[" + std::to_string(i) + "].errors has " +
                             std::to_string(series[i].errors.size()) + " values, expected 0 or " +
                             std::to_string(categories.size()));
    for (double e : series[i].errors)
      if (!std::isnan(e) && !(e >= 0.0 && std::isfinite(e)))
        return Fail(error, "series[" + std::to_string(i) + "].errors must be finite and >= 0");
  }
  if (!std::isfinite(y_min)) return Fail(error, "y_min must be finite");
  if (!std::isnan(y_max) && !(y_max > y_min)) return Fail(error, "y_max must exceed y_min");
  return true;
}

bool LineChart::IsValid(std::string* error) const {
  if (!ValidSize(width, height, error)) return false;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const LineSeries& s = series[i];
    if (s.x.size() != s.y.size())
      return Fail(error, "series[" + std::to_string(i) + "].y has " + std::to_string(s.y.size()) +
                             " values, expected " + std::to_string(s.x.size()) + " (size of x)");
    if (!(s.line_width > 0.0 && s.line_width <= 20.0))
      return Fail(error, "series[" + std::to_string(i) + "].line_width must be in (0, 20]");
  }
  if (log_y && !std::isnan(y_min) && !(y_min > 0.0))
    return Fail(error, "y_min must be positive with log_y");
  if (!std::isnan(x_min) && !std::isnan(x_max) && !(x_max > x_min))
    return Fail(error, "x_max must exceed x_min");
  if (!std::isnan(y_min) && !std::isnan(y_max) && !(y_max > y_min))
    return Fail(error, "y_max must exceed y_min");
  return true;
}

void RenderBarChart(const BarChart& chart, const std::string& path) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderBarChart: " + error);
  const PlotArea a = ChartPlotArea(chart.width, chart.height);
  detail::Canvas canvas(chart.width, chart.height);
  cairo_t* cr = canvas.cr();

  double data_max = chart.y_min;
  for (const BarSeries& s : chart.series)
    for (std::size_t c = 0; c < s.values.size(); ++c) {
      const double e = c < s.errors.size() && std::isfinite(s.errors[c]) ? s.errors[c] : 0.0;
      if (std::isfinite(s.values[c])) data_max = std::max(data_max, s.values[c] + e);
    }
  double y_hi = chart.y_max;
  if (std::isnan(y_hi)) y_hi = chart.percent ? std::max(1.0, data_max) : data_max * 1.08;
  const LinearAxis axis = NiceAxis(chart.y_min, y_hi, true, !std::isnan(chart.y_max), 5);
  const auto to_py = [&](double v) {
    v = std::clamp(v, axis.lo, axis.hi);
    return a.top + a.height * (axis.hi - v) / (axis.hi - axis.lo);
  };
  const double step = axis.ticks.size() > 1 ? axis.ticks[1] - axis.ticks[0] : 1.0;
  for (double t : axis.ticks) {
    HorizontalGridLine(cr, a, to_py(t));
    const std::string label = chart.percent ? detail::FormatTick(100.0 * t, 100.0 * step) + "%"
                                            : detail::FormatTick(t, step);
    DrawText(cr, label, a.left - 8.0, to_py(t),
             {.size = kFont * 0.9, .h = HAlign::kRight, .v = VAlign::kMiddle});
  }

  const int nc = static_cast<int>(chart.categories.size());
  const int ns = static_cast<int>(chart.series.size());
  if (nc == 0 || ns == 0) {
    DrawFrame(cr, a);
    DrawNoData(cr, a, "no data");
    DrawAxisLabels(cr, a, chart.x_label, chart.y_label);
    DrawHeader(cr, chart.title, {}, a, chart.width);
    canvas.Save(path);
    return;
  }
  const double slot = a.width / nc;
  const double bar_w = 0.8 * slot / ns;
  const double base = to_py(std::max(axis.lo, 0.0));
  std::vector<LegendItem> legend;
  for (int s = 0; s < ns; ++s) {
    const BarSeries& series = chart.series[s];
    const Rgba color = SeriesColor(series.name, series.color, s);
    legend.push_back({series.name, color, Marker::kSwatch, Mix(color, colors::kBlack, 0.4)});
    for (int c = 0; c < nc; ++c) {
      const double v = series.values[c];
      if (std::isnan(v)) continue;
      const double x = a.left + slot * (c + 0.1) + bar_w * s;
      const double top = to_py(v);
      // One-pixel gap between neighbouring bars keeps same-height bars apart.
      cairo_rectangle(cr, x + 0.5, std::min(top, base), std::max(1.0, bar_w - 1.0),
                      std::abs(base - top));
      SetColor(cr, color);
      cairo_fill_preserve(cr);
      SetColor(cr, Mix(color, colors::kBlack, 0.4));
      cairo_set_line_width(cr, 1.0);
      cairo_stroke(cr);
      double label_y = std::min(top, base) - 3.0;
      if (c < static_cast<int>(series.errors.size()) && std::isfinite(series.errors[c])) {
        // Whisker value +- error, capped, black over the bar; the value label goes above it.
        const double e = series.errors[c], xc = x + 0.5 * bar_w, cap = 0.25 * bar_w;
        const double y_lo = to_py(v - e), y_hi = to_py(v + e);
        label_y = std::min(label_y, y_hi - 3.0);
        SetColor(cr, colors::kBlack);
        cairo_set_line_width(cr, 1.5);
        cairo_move_to(cr, xc, y_lo);
        cairo_line_to(cr, xc, y_hi);
        cairo_move_to(cr, xc - cap, y_lo);
        cairo_line_to(cr, xc + cap, y_lo);
        cairo_move_to(cr, xc - cap, y_hi);
        cairo_line_to(cr, xc + cap, y_hi);
        cairo_stroke(cr);
      }
      if (chart.value_labels && bar_w >= 22.0) {
        char buf[32];
        if (chart.percent)
          std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * v);
        else
          std::snprintf(buf, sizeof buf, "%.3g", v);
        DrawText(cr, buf, x + 0.5 * bar_w, label_y,
                 {.size = kFont * 0.72, .h = HAlign::kCenter, .v = VAlign::kBottom});
      }
    }
  }
  DrawFrame(cr, a);
  // Every k-th category label when they would overlap (many objects in a narrow chart).
  double widest = 0.0;
  for (const std::string& c : chart.categories)
    widest = std::max(widest, detail::TextWidth(cr, c, kFont * 0.9) + 6.0);
  const int label_stride = std::max(1, static_cast<int>(std::ceil(widest / slot)));
  for (int c = 0; c < nc; c += label_stride)
    DrawText(cr, chart.categories[c], a.left + slot * (c + 0.5), a.top + a.height + 8.0,
             {.size = kFont * 0.9, .h = HAlign::kCenter, .v = VAlign::kTop});
  DrawAxisLabels(cr, a, chart.x_label, chart.y_label);
  DrawHeader(cr, chart.title, legend, a, chart.width);
  canvas.Save(path);
}

namespace {

std::string Superscript(int e) { return e < 0 ? "\u2212" + std::to_string(-e) : std::to_string(e); }

// "10" with a raised exponent, right-aligned at x.
void DrawPowerOfTen(cairo_t* cr, int e, double x, double y) {
  const std::string exp = Superscript(e);
  const double w_exp = detail::TextWidth(cr, exp, kFont * 0.65);
  const double w_10 = detail::TextWidth(cr, "10", kFont * 0.9);
  DrawText(cr, "10", x - w_exp - w_10, y, {.size = kFont * 0.9, .v = VAlign::kMiddle});
  DrawText(cr, exp, x - w_exp, y - kFont * 0.4, {.size = kFont * 0.65, .v = VAlign::kMiddle});
}

}  // namespace

void RenderLineChart(const LineChart& chart, const std::string& path) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderLineChart: " + error);
  const PlotArea a = ChartPlotArea(chart.width, chart.height);
  detail::Canvas canvas(chart.width, chart.height);
  cairo_t* cr = canvas.cr();

  const auto usable = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!chart.log_y || y > 0.0);
  };
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const LineSeries& s : chart.series)
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (usable(s.x[k], s.y[k])) {
        x_lo = std::min(x_lo, s.x[k]);
        x_hi = std::max(x_hi, s.x[k]);
        y_lo = std::min(y_lo, s.y[k]);
        y_hi = std::max(y_hi, s.y[k]);
      }
  const bool no_data = !(x_hi >= x_lo);
  if (no_data) x_lo = 0.0, x_hi = 1.0, y_lo = chart.log_y ? 0.1 : 0.0, y_hi = 1.0;
  if (!std::isnan(chart.x_min)) x_lo = chart.x_min;
  if (!std::isnan(chart.x_max)) x_hi = chart.x_max;
  if (!std::isnan(chart.y_min)) y_lo = chart.y_min;
  if (!std::isnan(chart.y_max)) y_hi = chart.y_max;
  if (!(x_hi > x_lo)) {  // one point, one x, or a fixed end beyond the data: centre on x_lo
    const double c = std::isnan(chart.x_min) && !std::isnan(chart.x_max) ? x_hi : x_lo;
    x_lo = c - 1.0;
    x_hi = c + 1.0;
  }
  if (chart.log_y && !(y_hi > y_lo)) {
    if (std::isnan(chart.y_max))
      y_hi = 10.0 * y_lo;
    else
      y_lo = 0.1 * y_hi;
  }
  // The x axis is not widened: time series should start and end at the frame.
  const std::vector<double> xt = detail::NiceTicks(x_lo, x_hi, std::max(2, int(a.width / 110)));
  const auto to_px = [&](double x) { return a.left + a.width * (x - x_lo) / (x_hi - x_lo); };

  std::function<double(double)> to_py;
  LinearAxis lin{};
  int e_lo = 0, e_hi = 0;
  if (chart.log_y) {
    e_lo = static_cast<int>(std::floor(std::log10(y_lo) + 1e-9));
    e_hi = static_cast<int>(std::ceil(std::log10(y_hi) - 1e-9));
    if (e_hi <= e_lo) e_hi = e_lo + 1;
    const double l0 = std::isnan(chart.y_min) ? e_lo : std::log10(chart.y_min);
    const double l1 = std::isnan(chart.y_max) ? e_hi : std::log10(chart.y_max);
    to_py = [=](double y) { return a.top + a.height * (l1 - std::log10(y)) / (l1 - l0); };
    // Minor ticks at 2..9 x 10^e; decade labels (every k-th when there are many decades).
    const int stride = std::max(1, (e_hi - e_lo + 7) / 8);
    for (int e = e_lo; e <= e_hi; ++e) {
      for (int m = 1; m <= 9; ++m) {
        const double v = m * std::pow(10.0, e);
        const double lv = std::log10(v);
        if (lv < l0 - 1e-9 || lv > l1 + 1e-9) continue;
        const double py = to_py(v);
        if (m == 1) {
          HorizontalGridLine(cr, a, py);
          if ((e - e_lo) % stride == 0) DrawPowerOfTen(cr, e, a.left - 8.0, py);
        } else {
          cairo_move_to(cr, a.left - 3.0, std::round(py) + 0.5);
          cairo_line_to(cr, a.left, std::round(py) + 0.5);
          SetColor(cr, kAxis);
          cairo_set_line_width(cr, 1.0);
          cairo_stroke(cr);
          if (l1 - l0 <= 2.0 + 1e-9 && (m == 2 || m == 5)) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%g", v);
            DrawText(cr, buf, a.left - 8.0, py,
                     {.size = kFont * 0.75,
                      .color = {0.4, 0.4, 0.4, 1.0},
                      .h = HAlign::kRight,
                      .v = VAlign::kMiddle});
          }
        }
      }
    }
  } else {
    lin = NiceAxis(y_lo, y_hi, !std::isnan(chart.y_min), !std::isnan(chart.y_max), 6);
    to_py = [=](double y) { return a.top + a.height * (lin.hi - y) / (lin.hi - lin.lo); };
    const double step = lin.ticks.size() > 1 ? lin.ticks[1] - lin.ticks[0] : 1.0;
    for (double t : lin.ticks) {
      HorizontalGridLine(cr, a, to_py(t));
      DrawText(cr, detail::FormatTick(t, step), a.left - 8.0, to_py(t),
               {.size = kFont * 0.9, .h = HAlign::kRight, .v = VAlign::kMiddle});
    }
  }

  // Shaded spans under the lines; a span of zero width (one sample) is drawn 2 px wide, reversed
  // ends are read in order, and a span with a non-finite end is skipped.
  for (const XSpan& span : chart.spans) {
    if (!std::isfinite(span.x0) || !std::isfinite(span.x1)) continue;
    double x0 = to_px(std::min(span.x0, span.x1)), x1 = to_px(std::max(span.x0, span.x1));
    if (x1 - x0 < 2.0) x0 -= 1.0, x1 += 1.0;
    x0 = std::max(a.left, x0);
    x1 = std::min(a.left + a.width, x1);
    if (x1 <= x0) continue;
    cairo_rectangle(cr, x0, a.top, x1 - x0, a.height);
    SetColor(cr, {0.5, 0.5, 0.5, 0.15});
    cairo_fill(cr);
    DrawText(cr, span.label, 0.5 * (x0 + x1), a.top + 4.0,
             {.size = kFont * 0.8,
              .color = {0.3, 0.3, 0.3, 1.0},
              .h = HAlign::kCenter,
              .v = VAlign::kTop});
  }

  const double x_step = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  for (double t : xt) {
    const double px = std::round(to_px(t)) + 0.5;
    cairo_move_to(cr, px, a.top + a.height);
    cairo_line_to(cr, px, a.top + a.height + 5.0);
    SetColor(cr, kAxis);
    cairo_set_line_width(cr, 1.0);
    cairo_stroke(cr);
    DrawText(cr, detail::FormatTick(t, x_step), px, a.top + a.height + 8.0,
             {.size = kFont * 0.9, .h = HAlign::kCenter, .v = VAlign::kTop});
  }

  std::vector<LegendItem> legend;
  cairo_save(cr);
  cairo_rectangle(cr, a.left, a.top, a.width, a.height);
  cairo_clip(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const LineSeries& s = chart.series[i];
    const Rgba color = SeriesColor(s.name, s.color, static_cast<int>(i));
    // A series without a name (e.g. the second line of a band) has no legend entry.
    if (!s.name.empty())
      legend.push_back({s.name, color, s.dashed ? Marker::kDashedLine : Marker::kLine});
    cairo_new_path(cr);
    SetColor(cr, color);
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!usable(s.x[k], s.y[k])) continue;
      const double px = to_px(s.x[k]), py = to_py(s.y[k]);
      const bool joined_before = k > 0 && usable(s.x[k - 1], s.y[k - 1]);
      const bool joined_after = k + 1 < s.x.size() && usable(s.x[k + 1], s.y[k + 1]);
      if (joined_before) {
        cairo_line_to(cr, px, py);
      } else if (joined_after) {
        cairo_move_to(cr, px, py);
      } else {  // an isolated point (one sample, or between gaps) would draw nothing: a dot
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, s.line_width, 0.0, 2.0 * kPi);
        cairo_fill(cr);
        cairo_new_path(cr);
      }
    }
    cairo_set_line_width(cr, s.line_width);
    if (s.dashed) {
      const double dash[] = {3.0 * s.line_width, 2.0 * s.line_width};
      cairo_set_dash(cr, dash, 2, 0.0);
    } else {
      cairo_set_dash(cr, nullptr, 0, 0.0);
    }
    cairo_stroke(cr);
  }
  cairo_restore(cr);
  if (no_data) DrawNoData(cr, a, "no data");
  DrawFrame(cr, a);
  DrawAxisLabels(cr, a, chart.x_label, chart.y_label);
  DrawHeader(cr, chart.title, legend, a, chart.width);
  canvas.Save(path);
}

}  // namespace dualgrid::viz
