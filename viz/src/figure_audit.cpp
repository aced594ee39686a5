#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "dualgrid/viz/figure.hpp"

namespace dualgrid::viz {

double BaseFontSize(double width) { return width * 8.0 / kSingleColumn; }
double SmallFontSize(double width) { return width * 7.2 / kSingleColumn; }

namespace {

thread_local FigureAudit* current = nullptr;

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;  // no control characters
    out += c;
  }
  return out + "\"";
}

std::string JsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// One write() of one line on an O_APPEND descriptor: lines of concurrent processes (the seeds of
// an experiment) do not interleave.
void AppendLine(const char* file, const std::string& line) {
  const int fd = ::open(file, O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) return;  // an audit hook never fails a figure
  const ssize_t written = ::write(fd, line.data(), line.size());
  (void)written;
  ::close(fd);
}

}  // namespace

bool FigureRecord::HasText(const std::string& part) const {
  // Joined with spaces: a phrase of a caption that wrapped across lines is found too.
  std::string all;
  for (const std::string& s : strings) all += s + " ";
  return all.find(part) != std::string::npos;
}

FigureAudit::FigureAudit() : previous_(current) { current = this; }

FigureAudit::~FigureAudit() { current = previous_; }

void FigureAudit::Report(const FigureRecord& r) {
  for (FigureAudit* a = current; a; a = a->previous_) a->records_.push_back(r);
  if (const char* file = std::getenv("DUALGRID_FIGURE_AUDIT"); file && *file) {
    std::string strings;
    for (const std::string& s : r.strings) strings += (strings.empty() ? "" : ", ") + JsonString(s);
    AppendLine(file, "{\"path\": " + JsonString(r.path) + ", \"width\": " + JsonNumber(r.width) +
                         ", \"height\": " + JsonNumber(r.height) + ", \"png_scale\": " +
                         JsonNumber(r.png_scale) + ", \"min_font\": " + JsonNumber(r.min_font) +
                         ", \"texts\": " + std::to_string(r.texts) + ", \"strings\": [" + strings +
                         "]}\n");
  }
}

}  // namespace dualgrid::viz
