// Physical design of the figures: sizes in points at a paper's column width, PNGs at print
// resolution, and a record of the smallest text of every figure saved (fonts must stay readable
// when a figure is scaled to one column).
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace dualgrid::viz {

/// Figures are laid out in points (1/72 in): SVG and PDF are written in points, PNGs are rasterised
/// at kPngDpi. A figure designed kSingleColumn wide prints at 3.5 in without scaling.
inline constexpr double kPointsPerInch = 72.0;
inline constexpr double kSingleColumn = 252.0;  ///< [pt], 3.5 in
inline constexpr double kDoubleColumn = 516.0;  ///< [pt], 7.16 in
inline constexpr double kPngDpi = 300.0;
/// PNG pixels per point.
inline constexpr double kPngScale = kPngDpi / kPointsPerInch;

/// Readability rule: scaled to one column (3.5 in), a figure's smallest text is at least 7 pt,
/// i.e. (smallest font size) / (figure width) >= 7 / 252 for every figure.
inline constexpr double kMinFontRatio = 7.0 / 252.0;

/// Font sizes of a figure `width` wide (any unit): base text (axis labels) and the smallest text
/// (ticks, legends, captions), 8 pt and 7.2 pt at one column: 3 % above the rule's limit, so
/// rounding never takes a figure under it.
double BaseFontSize(double width);
double SmallFontSize(double width);

/// What Save recorded of one figure: its size in drawing units (points), the PNG scale, the
/// smallest text drawn (in the same units; +inf without text) and every text drawn, in order.
struct FigureRecord {
  std::string path;
  double width = 0.0;
  double height = 0.0;
  double png_scale = 1.0;
  double min_font = std::numeric_limits<double>::infinity();
  int texts = 0;
  std::vector<std::string> strings;
  double MinFontRatio() const { return min_font / width; }
  /// Whether the texts drawn, joined by spaces (wrapped lines), contain `part`.
  bool HasText(const std::string& part) const;
};

/// While alive, collects a FigureRecord of every figure saved on this thread (tests use it to
/// check fonts and words). Outside tests, setting DUALGRID_FIGURE_AUDIT=<file> makes every figure
/// saved by any process append one JSON line {"path", "width", "height", "png_scale",
/// "min_font", "texts", "strings"} to that file: the CLI tests check the figures of real runs
/// with it.
class FigureAudit {
 public:
  FigureAudit();
  ~FigureAudit();
  FigureAudit(const FigureAudit&) = delete;
  FigureAudit& operator=(const FigureAudit&) = delete;
  const std::vector<FigureRecord>& records() const { return records_; }

  /// Called by every Save (internal).
  static void Report(const FigureRecord& record);

 private:
  std::vector<FigureRecord> records_;
  FigureAudit* previous_;
};

}  // namespace dualgrid::viz
