// Simple clean charts: grouped bars (paper Fig. 6) and lines over time (paper Fig. 4).
// Laid out in points at a column width (dualgrid/viz/figure.hpp): every font size follows from
// the width, so a chart stays readable at one column whatever width it is drawn at.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/figure.hpp"

namespace dualgrid::viz {

struct BarSeries {
  std::string name;  ///< legend label; a mode name ("dual", ...) picks ModeColor by default
  std::vector<double> values;  ///< one per category; NaN = no bar
  std::optional<Rgba> color;
  /// Empty, or one half-width per category drawn as a whisker value +- error with caps (e.g. the
  /// 95 % confidence interval over seeds); NaN = no whisker. Must be >= 0.
  std::vector<double> errors;
};

struct BarChart {
  std::string title;
  std::string x_label;
  std::string y_label;
  /// Wrapped under the chart when not empty: what the bars, whiskers and colours mean.
  std::string caption;
  std::vector<std::string> categories;  ///< e.g. object ids
  std::vector<BarSeries> series;        ///< e.g. one per mode
  /// Values are fractions in [0, 1] shown as percent (axis and value labels).
  bool percent = false;
  /// y axis range; y_max NaN = automatic (1 for percent).
  double y_min = 0.0;
  double y_max = std::numeric_limits<double>::quiet_NaN();
  bool value_labels = true;  ///< print each value above its bar where the label fits the bar
  /// [pt]; fonts follow from the width (BaseFontSize). `height` is the chart's height with a
  /// one-line title, one legend row and horizontal category names; more lines and the caption
  /// make the image taller, never the plot smaller.
  int width = static_cast<int>(kSingleColumn);
  int height = 180;
  double png_scale = kPngScale;  ///< PNG pixels per point
  bool IsValid(std::string* error) const;
};

struct LineSeries {
  std::string name;  ///< legend label; empty: no legend entry
  std::vector<double> x;
  std::vector<double> y;  ///< same size as x; NaN (or <= 0 on a log axis) breaks the line
  std::optional<Rgba> color;
  double line_width = 1.0;  ///< [pt] at one column width (scaled with the chart's width)
  bool dashed = false;
  /// Empty, or one half-width per point drawn as a vertical error bar y +- error with caps (e.g.
  /// the 95 % confidence interval over seeds); NaN = none. Must be >= 0.
  std::vector<double> errors;
};

/// Shaded x interval with an optional label (e.g. "radial speed differs").
struct XSpan {
  double x0 = 0.0;
  double x1 = 0.0;
  std::string label;
};

struct LineChart {
  std::string title;
  std::string x_label = "time [s]";
  std::string y_label;
  /// Wrapped under the chart when not empty: what the lines, bands and colours mean.
  std::string caption;
  std::vector<LineSeries> series;
  std::vector<XSpan> spans;
  bool log_y = false;
  /// Axis ranges; NaN = from the data.
  double x_min = std::numeric_limits<double>::quiet_NaN();
  double x_max = std::numeric_limits<double>::quiet_NaN();
  double y_min = std::numeric_limits<double>::quiet_NaN();
  double y_max = std::numeric_limits<double>::quiet_NaN();
  /// As BarChart's.
  int width = static_cast<int>(kSingleColumn);
  int height = 180;
  double png_scale = kPngScale;
  bool IsValid(std::string* error) const;
};

/// Throw std::invalid_argument (naming the field) for bad input, std::runtime_error if the PNG
/// cannot be written.
/// `path` ends in .png, .svg or .pdf (raster or vector; see BirdsEyeView::Save).
void RenderBarChart(const BarChart& chart, const std::string& path);
void RenderLineChart(const LineChart& chart, const std::string& path);

/// Plot-area rectangle in points (left, top, width, height); exposed for tests.
struct PlotArea {
  double left = 0.0;
  double top = 0.0;
  double width = 0.0;
  double height = 0.0;
};
/// Where a chart's plot lands and the image's size [pt] (PNG: times png_scale).
struct ChartLayout {
  double width = 0.0;
  double height = 0.0;
  PlotArea plot;
};
/// Throw std::invalid_argument like the Render functions.
ChartLayout LayoutBarChart(const BarChart& chart);
ChartLayout LayoutLineChart(const LineChart& chart);
/// The plot area of a chart with an empty title, legend and caption (the nominal layout).
PlotArea ChartPlotArea(int width, int height);

}  // namespace dualgrid::viz
