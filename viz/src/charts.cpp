#include "dualgrid/viz/charts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "chart_frame.hpp"
#include "draw.hpp"
#include "dualgrid/core/text.hpp"
#include "dualgrid/core/types.hpp"
#include "dualgrid/core/validation.hpp"

namespace dualgrid::viz {

using detail::ChartFrame;
using detail::ChartText;
using detail::DrawText;
using detail::HAlign;
using detail::LegendItem;
using detail::Marker;
using detail::SetColor;
using detail::TextStyle;
using detail::VAlign;

namespace {

std::string Values(std::size_t n) { return std::to_string(n) + (n == 1 ? " value" : " values"); }

void CheckSize(FieldCheck& c, int width, int height, double png_scale) {
  c.InRange("width", width, 100, 5000);
  c.InRange("height", height, 80, 5000);
  c.InRange("png_scale", png_scale, 0.0, 32.0, Interval::kLeftOpen);
}

// Error bars of a series `name` with n values: none, or one per value (NaN: no bar there).
void CheckErrors(FieldCheck& c, const std::vector<double>& errors, std::size_t n,
                 const std::string& name) {
  c.Expect(errors.empty() || errors.size() == n, name + ".errors", Values(errors.size()),
           "none or " + Values(n));
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (!std::isnan(errors[i])) c.NonNegative(Indexed(name + ".errors", i), errors[i]);
}

Rgba SeriesColor(const std::string& name, const std::optional<Rgba>& color, int index) {
  if (color) return *color;
  if (const auto mode = ModeFromName(name)) return ModeColor(*mode);
  return CategoryColor(index);
}

// Linear axis [lo, hi] widened to whole ticks, with the ticks.
struct LinearAxis {
  double lo = 0.0, hi = 1.0;
  std::vector<double> ticks;
  double Step() const { return ticks.size() > 1 ? ticks[1] - ticks[0] : hi - lo; }
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

// A vertical error bar y +- e with caps `cap` wide, in the current colour.
void ErrorBar(cairo_t* cr, double x, double y_lo, double y_hi, double cap, double line_width) {
  cairo_save(cr);
  cairo_set_line_width(cr, line_width);
  cairo_set_dash(cr, nullptr, 0, 0.0);
  cairo_move_to(cr, x, y_lo);
  cairo_line_to(cr, x, y_hi);
  cairo_move_to(cr, x - cap, y_lo);
  cairo_line_to(cr, x + cap, y_lo);
  cairo_move_to(cr, x - cap, y_hi);
  cairo_line_to(cr, x + cap, y_hi);
  cairo_stroke(cr);
  cairo_restore(cr);
}

// ---- bar chart ----

struct BarGeometry {
  LinearAxis axis;
  std::vector<std::string> tick_labels;
  std::vector<LegendItem> legend;
  std::vector<Rgba> colors;
  ChartFrame frame;
  bool value_labels = false;
  detail::CategoryLabels categories;
};

std::string BarValueLabel(const BarChart& chart, double v) {
  char buf[32];
  if (chart.percent)
    std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

BarGeometry BarLayout(cairo_t* m, const BarChart& chart) {
  BarGeometry g;
  double data_max = chart.y_min;
  for (const BarSeries& s : chart.series)
    for (std::size_t c = 0; c < s.values.size(); ++c) {
      const double e = c < s.errors.size() && std::isfinite(s.errors[c]) ? s.errors[c] : 0.0;
      if (std::isfinite(s.values[c])) data_max = std::max(data_max, s.values[c] + e);
    }
  double y_hi = chart.y_max;
  if (std::isnan(y_hi)) y_hi = chart.percent ? std::max(1.0, data_max) : data_max * 1.08;
  g.axis = NiceAxis(chart.y_min, y_hi, true, !std::isnan(chart.y_max), 5);
  for (double t : g.axis.ticks)
    g.tick_labels.push_back(chart.percent
                                ? detail::FormatTick(100.0 * t, 100.0 * g.axis.Step()) + "%"
                                : detail::FormatTick(t, g.axis.Step()));
  for (std::size_t s = 0; s < chart.series.size(); ++s) {
    const Rgba color = SeriesColor(chart.series[s].name, chart.series[s].color, int(s));
    g.colors.push_back(color);
    g.legend.push_back(
        {chart.series[s].name, color, Marker::kSwatch, Mix(color, colors::kBlack, 0.4)});
  }
  const ChartText text{chart.title, chart.x_label, chart.y_label, chart.caption, g.legend};
  const double sm = SmallFontSize(chart.width);
  const int nc = static_cast<int>(chart.categories.size());
  const int ns = static_cast<int>(chart.series.size());
  // Value labels only where every label fits its bar: no overlaps, no thinning.
  const auto labels_fit = [&](double plot_width) {
    if (!chart.value_labels || nc == 0 || ns == 0) return false;
    const double bar_w = 0.8 * plot_width / nc / ns;
    for (const BarSeries& s : chart.series)
      for (double v : s.values)
        if (std::isfinite(v) && detail::TextWidth(m, BarValueLabel(chart, v), sm) > bar_w)
          return false;
    return true;
  };
  g.frame = detail::LayoutChartFrame(
      m, text, chart.width, chart.height, detail::WidestLabel(m, g.tick_labels, sm),
      [&](double plot_width) {
        g.categories = detail::FitCategoryLabels(m, chart.categories, plot_width, sm);
        g.value_labels = labels_fit(plot_width);
        return g.categories.height;
      },
      [&] { return g.value_labels ? detail::LineHeight(sm) : 0.0; });
  return g;
}

}  // namespace

PlotArea ChartPlotArea(int width, int height) {
  cairo_surface_t* s = cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, nullptr);
  cairo_t* m = cairo_create(s);
  const ChartFrame f = detail::LayoutChartFrame(
      m, {}, width, height, detail::TextWidth(m, "100%", SmallFontSize(width)),
      [&](double) { return detail::LineHeight(SmallFontSize(width)); }, [] { return 0.0; });
  cairo_destroy(m);
  cairo_surface_destroy(s);
  return f.layout.plot;
}

bool BarChart::IsValid(std::string* error) const {
  FieldCheck c;
  CheckSize(c, width, height, png_scale);
  for (std::size_t i = 0; i < series.size(); ++i) {
    const std::string name = Indexed("series", i);
    const std::vector<double>& values = series[i].values;
    c.Expect(values.size() == categories.size(), name + ".values", Values(values.size()),
             Values(categories.size()) + " (one per category)");
    for (std::size_t k = 0; k < values.size(); ++k)  // NaN: no bar
      c.Expect(!std::isinf(values[k]), Indexed(name + ".values", k), values[k],
               "finite or nan (no bar)");
    CheckErrors(c, series[i].errors, categories.size(), name);
  }
  c.Finite("y_min", y_min);
  c.Expect(std::isnan(y_max) || y_max > y_min, "y_max", y_max,
           "nan (automatic) or > y_min = " + FormatShort(y_min));
  return c.Done(error);
}

bool LineChart::IsValid(std::string* error) const {
  FieldCheck c;
  CheckSize(c, width, height, png_scale);
  for (std::size_t i = 0; i < series.size(); ++i) {
    const LineSeries& s = series[i];
    const std::string name = Indexed("series", i);
    c.Expect(s.x.size() == s.y.size(), name + ".y", Values(s.y.size()),
             Values(s.x.size()) + " (the size of x)");
    c.InRange(name + ".line_width", s.line_width, 0.0, 20.0, Interval::kLeftOpen, "pt");
    CheckErrors(c, s.errors, s.x.size(), name);
  }
  c.Expect(!log_y || std::isnan(y_min) || y_min > 0.0, "y_min", y_min,
           "nan (automatic) or > 0 with log_y");
  c.Expect(std::isnan(x_min) || std::isnan(x_max) || x_max > x_min, "x_max", x_max,
           "> x_min = " + FormatShort(x_min));
  c.Expect(std::isnan(y_min) || std::isnan(y_max) || y_max > y_min, "y_max", y_max,
           "> y_min = " + FormatShort(y_min));
  return c.Done(error);
}

ChartLayout LayoutBarChart(const BarChart& chart) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderBarChart: " + error);
  detail::Measure m;
  return BarLayout(m.cr(), chart).frame.layout;
}

void RenderBarChart(const BarChart& chart, const std::string& path) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderBarChart: " + error);
  detail::Measure measure;
  const BarGeometry g = BarLayout(measure.cr(), chart);
  const ChartFrame& f = g.frame;
  const PlotArea& a = f.layout.plot;
  detail::Canvas canvas(f.CanvasWidth(), f.CanvasHeight());
  canvas.SetRasterScale(chart.png_scale);
  cairo_t* cr = canvas.cr();
  const double u = f.u, sm = f.small;
  const auto to_py = [&](double v) {
    v = std::clamp(v, g.axis.lo, g.axis.hi);
    return a.top + a.height * (g.axis.hi - v) / (g.axis.hi - g.axis.lo);
  };
  for (std::size_t i = 0; i < g.axis.ticks.size(); ++i)
    detail::HorizontalTick(cr, f, to_py(g.axis.ticks[i]), g.tick_labels[i]);

  const int nc = static_cast<int>(chart.categories.size());
  const int ns = static_cast<int>(chart.series.size());
  if (nc > 0 && ns > 0) {
    const double slot = a.width / nc;
    const double bar_w = 0.8 * slot / ns;
    const double base = to_py(std::max(g.axis.lo, 0.0));
    for (int s = 0; s < ns; ++s) {
      const BarSeries& series = chart.series[s];
      for (int c = 0; c < nc; ++c) {
        const double v = series.values[c];
        if (std::isnan(v)) continue;
        const double x = a.left + slot * (c + 0.1) + bar_w * s;
        const double top = to_py(v);
        // A thin gap between neighbouring bars keeps same-height bars apart.
        cairo_rectangle(cr, x + 0.25 * u, std::min(top, base), std::max(0.3 * u, bar_w - 0.5 * u),
                        std::abs(base - top));
        SetColor(cr, g.colors[s]);
        cairo_fill_preserve(cr);
        SetColor(cr, Mix(g.colors[s], colors::kBlack, 0.4));
        cairo_set_line_width(cr, 0.4 * u);
        cairo_stroke(cr);
        double label_y = std::min(top, base) - 1.5 * u;
        if (c < static_cast<int>(series.errors.size()) && std::isfinite(series.errors[c])) {
          // Whisker value +- error, capped, black over the bar; the value label goes above it.
          const double e = series.errors[c];
          const double y_hi = to_py(v + e);
          label_y = std::min(label_y, y_hi - 1.5 * u);
          SetColor(cr, colors::kBlack);
          ErrorBar(cr, x + 0.5 * bar_w, to_py(v - e), y_hi, std::max(0.25 * bar_w, 1.2 * u),
                   0.8 * u);
        }
        if (g.value_labels)
          DrawText(cr, BarValueLabel(chart, v), x + 0.5 * bar_w, label_y,
                   {.size = sm, .h = HAlign::kCenter, .v = VAlign::kBottom});
      }
    }
    detail::DrawCategoryLabels(cr, f, g.categories, chart.categories);
  } else {
    detail::DrawNoData(cr, f);
  }
  detail::DrawChartFrame(cr, f,
                         {chart.title, chart.x_label, chart.y_label, chart.caption,
                          nc > 0 && ns > 0 ? g.legend : std::vector<LegendItem>{}});
  canvas.Save(path);
}

// ---- line chart ----

namespace {

std::string Superscript(int e) { return e < 0 ? "\u2212" + std::to_string(-e) : std::to_string(e); }

struct LineGeometry {
  double x_lo = 0.0, x_hi = 1.0;
  std::vector<double> x_ticks;
  bool log = false;
  double l0 = 0.0, l1 = 1.0;  // log10 range of a log axis
  int e_lo = 0, e_hi = 1;
  LinearAxis lin;
  std::vector<LegendItem> legend;
  bool no_data = false;
  ChartFrame frame;
  double ToPy(double y) const {
    const PlotArea& a = frame.layout.plot;
    if (log) return a.top + a.height * (l1 - std::log10(y)) / (l1 - l0);
    return a.top + a.height * (lin.hi - y) / (lin.hi - lin.lo);
  }
  double ToPx(double x) const {
    const PlotArea& a = frame.layout.plot;
    return a.left + a.width * (x - x_lo) / (x_hi - x_lo);
  }
};

bool Usable(const LineChart& chart, double x, double y) {
  return std::isfinite(x) && std::isfinite(y) && (!chart.log_y || y > 0.0);
}

// Width of a "10^e" tick label at size `size`.
double PowerOfTenWidth(cairo_t* m, int e, double size) {
  return detail::TextWidth(m, "10", size) + detail::TextWidth(m, Superscript(e), size);
}

LineGeometry LineLayout(cairo_t* m, const LineChart& chart) {
  LineGeometry g;
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const LineSeries& s : chart.series)
    for (std::size_t k = 0; k < s.x.size(); ++k)
      if (Usable(chart, s.x[k], s.y[k])) {
        const double e = k < s.errors.size() && std::isfinite(s.errors[k]) ? s.errors[k] : 0.0;
        x_lo = std::min(x_lo, s.x[k]);
        x_hi = std::max(x_hi, s.x[k]);
        // Error bars belong in the range (not below zero on a log axis).
        y_lo = std::min(y_lo, chart.log_y && s.y[k] - e <= 0.0 ? s.y[k] : s.y[k] - e);
        y_hi = std::max(y_hi, s.y[k] + e);
      }
  g.no_data = !(x_hi >= x_lo);
  if (g.no_data) x_lo = 0.0, x_hi = 1.0, y_lo = chart.log_y ? 0.1 : 0.0, y_hi = 1.0;
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
  g.x_lo = x_lo;
  g.x_hi = x_hi;
  const double sm = SmallFontSize(chart.width);
  std::vector<std::string> y_labels;
  double y_label_w = 0.0;
  if (chart.log_y) {
    g.log = true;
    g.e_lo = static_cast<int>(std::floor(std::log10(y_lo) + 1e-9));
    g.e_hi = static_cast<int>(std::ceil(std::log10(y_hi) - 1e-9));
    if (g.e_hi <= g.e_lo) g.e_hi = g.e_lo + 1;
    g.l0 = std::isnan(chart.y_min) ? g.e_lo : std::log10(chart.y_min);
    g.l1 = std::isnan(chart.y_max) ? g.e_hi : std::log10(chart.y_max);
    for (int e = g.e_lo; e <= g.e_hi; ++e)
      y_label_w = std::max(y_label_w, PowerOfTenWidth(m, e, sm));
    if (g.l1 - g.l0 <= 2.0 + 1e-9)
      y_label_w = std::max(y_label_w, detail::TextWidth(m, "0.005", sm));
  } else {
    g.lin = NiceAxis(y_lo, y_hi, !std::isnan(chart.y_min), !std::isnan(chart.y_max), 5);
    for (double t : g.lin.ticks) y_labels.push_back(detail::FormatTick(t, g.lin.Step()));
    y_label_w = detail::WidestLabel(m, y_labels, sm);
  }
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const LineSeries& s = chart.series[i];
    // A series without a name (e.g. the second line of a band) has no legend entry.
    if (!s.name.empty())
      g.legend.push_back({s.name, SeriesColor(s.name, s.color, static_cast<int>(i)),
                          s.dashed ? Marker::kDashedLine : Marker::kLine});
  }
  const ChartText text{chart.title, chart.x_label, chart.y_label, chart.caption, g.legend};
  g.frame = detail::LayoutChartFrame(
      m, text, chart.width, chart.height, y_label_w,
      [&](double plot_width) {
        // About one labelled tick per 5 small font sizes: tick labels never touch.
        g.x_ticks =
            detail::NiceTicks(x_lo, x_hi, std::max(2, static_cast<int>(plot_width / (5.0 * sm))));
        return detail::LineHeight(sm);
      },
      [] { return 0.0; });
  return g;
}

void DrawLogTicks(cairo_t* cr, const LineGeometry& g) {
  const ChartFrame& f = g.frame;
  const PlotArea& a = f.layout.plot;
  const double sm = f.small;
  // Minor ticks at 2..9 x 10^e; decade labels (every k-th when there are many decades).
  const int stride = std::max(1, (g.e_hi - g.e_lo + 7) / 8);
  for (int e = g.e_lo; e <= g.e_hi; ++e) {
    for (int m = 1; m <= 9; ++m) {
      const double v = m * std::pow(10.0, e);
      const double lv = std::log10(v);
      if (lv < g.l0 - 1e-9 || lv > g.l1 + 1e-9) continue;
      const double py = g.ToPy(v);
      if (m == 1) {
        detail::HorizontalTick(cr, f, py, "");
        if ((e - g.e_lo) % stride == 0) {
          // "10" with its exponent raised, right-aligned at the tick label column.
          const std::string exp = Superscript(e);
          const double x = a.left - f.tick_length - f.label_gap;
          const double w_exp = detail::TextWidth(cr, exp, sm);
          DrawText(cr, "10", x - w_exp, py,
                   {.size = sm, .h = HAlign::kRight, .v = VAlign::kMiddle});
          DrawText(cr, exp, x - w_exp, py - 0.4 * sm, {.size = sm, .v = VAlign::kMiddle});
        }
      } else {
        cairo_save(cr);
        cairo_move_to(cr, a.left - 0.6 * f.tick_length, py);
        cairo_line_to(cr, a.left, py);
        SetColor(cr, detail::kChartAxis);
        cairo_set_line_width(cr, 0.5 * f.u);
        cairo_stroke(cr);
        cairo_restore(cr);
        if (g.l1 - g.l0 <= 2.0 + 1e-9 && (m == 2 || m == 5)) {
          char buf[32];
          std::snprintf(buf, sizeof buf, "%g", v);
          DrawText(cr, buf, a.left - f.tick_length - f.label_gap, py,
                   {.size = sm,
                    .color = {0.4, 0.4, 0.4, 1.0},
                    .h = HAlign::kRight,
                    .v = VAlign::kMiddle});
        }
      }
    }
  }
}

// Shaded spans under the lines; a span of zero width (one sample) is drawn 0.8 pt wide, reversed
// ends are read in order, and a span with a non-finite end is skipped.
void DrawSpans(cairo_t* cr, const LineChart& chart, const LineGeometry& g) {
  const ChartFrame& f = g.frame;
  const PlotArea& a = f.layout.plot;
  for (const XSpan& span : chart.spans) {
    if (!std::isfinite(span.x0) || !std::isfinite(span.x1)) continue;
    double x0 = g.ToPx(std::min(span.x0, span.x1)), x1 = g.ToPx(std::max(span.x0, span.x1));
    if (x1 - x0 < 0.8 * f.u) x0 -= 0.4 * f.u, x1 += 0.4 * f.u;
    x0 = std::max(a.left, x0);
    x1 = std::min(a.left + a.width, x1);
    if (x1 <= x0) continue;
    cairo_rectangle(cr, x0, a.top, x1 - x0, a.height);
    SetColor(cr, {0.5, 0.5, 0.5, 0.15});
    cairo_fill(cr);
    // The label only where it fits inside its span.
    if (detail::TextWidth(cr, span.label, f.small) <= x1 - x0)
      DrawText(cr, span.label, 0.5 * (x0 + x1), a.top + f.u,
               {.size = f.small,
                .color = {0.3, 0.3, 0.3, 1.0},
                .h = HAlign::kCenter,
                .v = VAlign::kTop});
  }
}

void DrawSeries(cairo_t* cr, const LineChart& chart, const LineGeometry& g) {
  const ChartFrame& f = g.frame;
  const PlotArea& a = f.layout.plot;
  cairo_save(cr);
  cairo_rectangle(cr, a.left, a.top, a.width, a.height);
  cairo_clip(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  // Rank of each series among those with error bars.
  std::vector<int> rank(chart.series.size(), 0);
  int with_errors = 0;
  for (std::size_t i = 0; i < chart.series.size(); ++i)
    if (std::any_of(chart.series[i].errors.begin(), chart.series[i].errors.end(),
                    [](double e) { return std::isfinite(e); }))
      rank[i] = with_errors++;
  for (std::size_t i = 0; i < chart.series.size(); ++i) {
    const LineSeries& s = chart.series[i];
    const Rgba color = SeriesColor(s.name, s.color, static_cast<int>(i));
    const double lw = s.line_width * f.u;
    SetColor(cr, color);
    // Error bars first, under the line; the series' bars side by side around their x (dodged)
    // where several series have them, so that bars at one x do not hide each other.
    const double dodge = (rank[i] - 0.5 * (with_errors - 1)) * 1.6 * f.u;
    for (std::size_t k = 0; k < s.errors.size(); ++k) {
      if (!Usable(chart, s.x[k], s.y[k]) || !std::isfinite(s.errors[k])) continue;
      const double lo = s.y[k] - s.errors[k];
      const double y_lo = chart.log_y && lo <= 0.0 ? a.top + a.height : g.ToPy(lo);
      ErrorBar(cr, g.ToPx(s.x[k]) + dodge, y_lo, g.ToPy(s.y[k] + s.errors[k]), 1.6 * f.u,
               0.7 * f.u);
    }
    cairo_new_path(cr);
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!Usable(chart, s.x[k], s.y[k])) continue;
      const double px = g.ToPx(s.x[k]), py = g.ToPy(s.y[k]);
      const bool joined_before = k > 0 && Usable(chart, s.x[k - 1], s.y[k - 1]);
      const bool joined_after = k + 1 < s.x.size() && Usable(chart, s.x[k + 1], s.y[k + 1]);
      if (joined_before) {
        cairo_line_to(cr, px, py);
      } else if (joined_after) {
        cairo_move_to(cr, px, py);
      } else {  // an isolated point (one sample, or between gaps) would draw nothing: a dot
        cairo_new_sub_path(cr);
        cairo_arc(cr, px, py, std::max(lw, 1.2 * f.u), 0.0, 2.0 * kPi);
        cairo_fill(cr);
        cairo_new_path(cr);
      }
    }
    cairo_set_line_width(cr, lw);
    if (s.dashed) {
      const double dash[] = {3.0 * lw, 2.0 * lw};
      cairo_set_dash(cr, dash, 2, 0.0);
    } else {
      cairo_set_dash(cr, nullptr, 0, 0.0);
    }
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

}  // namespace

ChartLayout LayoutLineChart(const LineChart& chart) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderLineChart: " + error);
  detail::Measure m;
  return LineLayout(m.cr(), chart).frame.layout;
}

void RenderLineChart(const LineChart& chart, const std::string& path) {
  std::string error;
  if (!chart.IsValid(&error)) throw std::invalid_argument("RenderLineChart: " + error);
  detail::Measure measure;
  const LineGeometry g = LineLayout(measure.cr(), chart);
  const ChartFrame& f = g.frame;
  const PlotArea& a = f.layout.plot;
  detail::Canvas canvas(f.CanvasWidth(), f.CanvasHeight());
  canvas.SetRasterScale(chart.png_scale);
  cairo_t* cr = canvas.cr();
  if (g.log) {
    DrawLogTicks(cr, g);
  } else {
    for (double t : g.lin.ticks)
      detail::HorizontalTick(cr, f, g.ToPy(t), detail::FormatTick(t, g.lin.Step()));
  }
  DrawSpans(cr, chart, g);
  const double x_step = g.x_ticks.size() > 1 ? g.x_ticks[1] - g.x_ticks[0] : 1.0;
  for (double t : g.x_ticks) detail::VerticalTick(cr, f, g.ToPx(t), detail::FormatTick(t, x_step));
  DrawSeries(cr, chart, g);
  if (g.no_data) detail::DrawNoData(cr, f);
  detail::DrawChartFrame(cr, f,
                         {chart.title, chart.x_label, chart.y_label, chart.caption, g.legend});
  (void)a;
  canvas.Save(path);
}

}  // namespace dualgrid::viz
