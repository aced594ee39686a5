// Private: the frame shared by the charts (title, legend, axes, caption) laid out from the
// chart's width, so that every font size is a fixed fraction of the width.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "draw.hpp"
#include "dualgrid/viz/charts.hpp"

namespace dualgrid::viz::detail {

inline constexpr Rgba kChartAxis{0.2, 0.2, 0.2, 1.0};

/// The words around a plot.
struct ChartText {
  std::string title, x_label, y_label, caption;
  std::vector<LegendItem> legend;
};

/// Where everything around the plot goes [pt]; u is one point at one column width.
struct ChartFrame {
  ChartLayout layout;
  double u = 1.0, base = 8.0, small = 7.2, title_size = 8.4;
  double pad = 5.0, tick_length = 3.0, label_gap = 1.5;
  double title_top = 0.0, legend_top = 0.0, legend_x = 0.0;
  double x_ticks_top = 0.0, x_label_top = 0.0, caption_top = 0.0;
  std::vector<std::string> y_label_lines;
  int CanvasWidth() const;
  int CanvasHeight() const;
};

/// Lays the frame out around a plot whose y tick labels are `y_tick_width` wide;
/// `x_tick_height(plot_width)` says how tall the x tick labels are (it may choose them from the
/// plot's width); `headroom()`, asked after it, is extra space above the plot (value labels over
/// full bars, when they are drawn).
ChartFrame LayoutChartFrame(cairo_t* m, const ChartText& text, int width, int height,
                            double y_tick_width, const std::function<double(double)>& x_tick_height,
                            const std::function<double()>& headroom);

double WidestLabel(cairo_t* m, const std::vector<std::string>& labels, double size);

/// Category names under bars: level when they fit their slot, else turned 45 degrees, and every
/// `stride`-th one only when even turned they would touch.
struct CategoryLabels {
  double height = 0.0;
  bool rotated = false;
  int stride = 1;
};
CategoryLabels FitCategoryLabels(cairo_t* m, const std::vector<std::string>& names,
                                 double plot_width, double size);
void DrawCategoryLabels(cairo_t* cr, const ChartFrame& f, const CategoryLabels& fit,
                        const std::vector<std::string>& names);

/// A y tick at py: grid line across the plot, tick mark and (non-empty) label.
void HorizontalTick(cairo_t* cr, const ChartFrame& f, double py, const std::string& label);
/// An x tick at px under the plot with its label.
void VerticalTick(cairo_t* cr, const ChartFrame& f, double px, const std::string& label);
/// "no data" in the middle of the plot: a chart of an empty run says so instead of failing.
void DrawNoData(cairo_t* cr, const ChartFrame& f);
/// The plot's frame, title, legend, axis labels and caption.
void DrawChartFrame(cairo_t* cr, const ChartFrame& f, const ChartText& text);

}  // namespace dualgrid::viz::detail
