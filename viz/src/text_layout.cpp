// Text that wraps (titles, captions) and metre axes around maps: the layout helpers of draw.hpp
// that the figures share beyond single strokes and strings.
#include <algorithm>
#include <sstream>

#include "draw.hpp"

namespace dualgrid::viz::detail {

double LineHeight(double size) { return 1.25 * size; }

namespace {
// A word wider than the line, split after '_', '.', '=', '/' or ',' into pieces that fit where
// it can be (identifiers and paths); a piece without such a break stays whole.
std::vector<std::string> SplitLongWord(cairo_t* cr, const std::string& word, double size,
                                       double max_width, bool bold) {
  std::vector<std::string> pieces;
  std::string piece, run;  // run: the characters since the last break point
  for (const char c : word) {
    run += c;
    if (std::string("_.=/,").find(c) == std::string::npos) continue;
    if (!piece.empty() && TextWidth(cr, piece + run, size, bold) > max_width) {
      pieces.push_back(piece);
      piece.clear();
    }
    piece += run;
    run.clear();
  }
  if (!piece.empty() && TextWidth(cr, piece + run, size, bold) > max_width) {
    pieces.push_back(piece);
    piece.clear();
  }
  pieces.push_back(piece + run);
  return pieces;
}
}  // namespace

std::vector<std::string> WrapText(cairo_t* cr, const std::string& text, double size,
                                  double max_width, bool bold) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t nl = text.find('\n', start);
    const std::string para = text.substr(start, nl == std::string::npos ? nl : nl - start);
    // Words split at spaces; a "%" stays with its number ("95 %" is never broken).
    std::vector<std::string> words;
    std::istringstream in(para);
    for (std::string w; in >> w;) {
      if (w.front() == '%' && !words.empty())
        words.back() += " " + w;
      else
        words.push_back(w);
    }
    std::string line;
    for (const std::string& word : words) {
      const std::vector<std::string> pieces = TextWidth(cr, word, size, bold) > max_width
                                                  ? SplitLongWord(cr, word, size, max_width, bold)
                                                  : std::vector<std::string>{word};
      for (std::size_t i = 0; i < pieces.size(); ++i) {
        // Pieces of one word join without a space.
        const std::string& w = pieces[i];
        const std::string candidate = line.empty() ? w : line + (i == 0 ? " " : "") + w;
        if (!line.empty() && TextWidth(cr, candidate, size, bold) > max_width) {
          lines.push_back(line);
          line = w;
        } else {
          line = candidate;
        }
      }
    }
    lines.push_back(line);
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  return lines;
}

double DrawParagraph(cairo_t* cr, const std::string& text, double x, double y, double max_width,
                     const TextStyle& style, bool draw) {
  if (text.empty()) return 0.0;
  const std::vector<std::string> lines = WrapText(cr, text, style.size, max_width, style.bold);
  if (draw) {
    TextStyle s = style;
    s.v = VAlign::kTop;
    for (std::size_t i = 0; i < lines.size(); ++i)
      DrawText(cr, lines[i], x, y + i * LineHeight(style.size), s);
  }
  return lines.size() * LineHeight(style.size);
}

namespace {
double TickStep(const std::vector<double>& ticks) {
  return ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
}
// About one labelled tick per 5.5 font sizes across and per 3 font sizes up the map.
std::vector<double> XTicks(const MapTransform& t, double fs) {
  return NiceTicks(t.world().min.x(), t.world().max.x(),
                   std::max(2, static_cast<int>(t.pixel_width() / (5.5 * fs))));
}
std::vector<double> YTicks(const MapTransform& t, double fs) {
  return NiceTicks(t.world().min.y(), t.world().max.y(),
                   std::max(2, static_cast<int>(t.pixel_height() / (3.0 * fs))));
}
}  // namespace

double MapAxesLabelWidth(cairo_t* cr, const MapTransform& t, const MapAxesStyle& style) {
  if (!style.label_y) return style.tick_length;
  const std::vector<double> yt = YTicks(t, style.font_size);
  double widest = 0.0;
  for (double v : yt)
    widest = std::max(widest, TextWidth(cr, FormatTick(v, TickStep(yt)), style.font_size));
  return style.tick_length + 0.3 * style.font_size + widest;
}

double DrawMapAxes(cairo_t* cr, const MapTransform& t, const MapAxesStyle& style) {
  const double fs = style.font_size;
  const double x0 = t.pixel_offset().x(), y0 = t.pixel_offset().y();
  const double w = t.pixel_width(), h = t.pixel_height();
  const WorldRect& wr = t.world();
  cairo_save(cr);
  SetColor(cr, colors::kBlack);
  cairo_set_line_width(cr, style.line_width);
  const double half = 0.5 * style.line_width;
  cairo_rectangle(cr, x0 - half, y0 - half, w + style.line_width, h + style.line_width);
  cairo_stroke(cr);
  const std::vector<double> xt = XTicks(t, fs), yt = YTicks(t, fs);
  const double gap = 0.3 * fs;
  for (double v : xt) {
    const double px = t.ToPixel({v, wr.min.y()}).x();
    cairo_move_to(cr, px, y0 + h);
    cairo_line_to(cr, px, y0 + h + style.tick_length);
    cairo_stroke(cr);
    if (!style.label_x) continue;
    const std::string label = FormatTick(v, TickStep(xt));
    const double half = 0.5 * TextWidth(cr, label, fs);
    if (px - half < x0 - style.label_left_room || px + half > x0 + w + style.label_right_room)
      continue;
    DrawText(cr, label, px, y0 + h + style.tick_length + gap,
             {.size = fs, .h = HAlign::kCenter, .v = VAlign::kTop});
  }
  for (double v : yt) {
    const double py = t.ToPixel({wr.min.x(), v}).y();
    cairo_move_to(cr, x0 - style.tick_length, py);
    cairo_line_to(cr, x0, py);
    cairo_stroke(cr);
    if (style.label_y)
      DrawText(cr, FormatTick(v, TickStep(yt)), x0 - style.tick_length - gap, py,
               {.size = fs, .h = HAlign::kRight, .v = VAlign::kMiddle});
  }
  cairo_restore(cr);
  return style.tick_length + (style.label_x ? gap + LineHeight(fs) : 0.0);
}

}  // namespace dualgrid::viz::detail
