#include "dualgrid/outputs/viewer.hpp"

#include <stdexcept>
#include <string>

#include "dualgrid/outputs/output_file.hpp"
#include "dualgrid/outputs/video.hpp"
#include "dualgrid/viz/viewer_template.hpp"

namespace dualgrid::outputs {

namespace fs = std::filesystem;

namespace {

void AppendBase64(const std::vector<std::uint8_t>& in, std::string& out) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8) | in[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = in[i] << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
}

// JSON inside a <script> element: every '<' as \u003c (still the same JSON), so that no text in it
// ("</script>", "<!--") can end the element or change how the HTML parser reads it.
std::string ScriptSafe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

}  // namespace

fs::path WriteViewer(const replay::Reader& reader, const ReplayOptions& o) {
  const fs::path out =
      CheckOutputFile(o.html_out.empty() ? reader.dir().parent_path() / "replay.html" : o.html_out,
                      "--html-out", ".html");
  const auto [first, last] = FrameRange(reader, o);
  // Every frame is decoded and checked first, as the video does: a damaged recording is refused
  // with its file and key named instead of becoming a page that breaks in the browser.
  for (std::size_t i = first; i < last; ++i) (void)reader.Load(i);
  nlohmann::json index = reader.index();
  nlohmann::json frames = nlohmann::json::array();
  for (std::size_t i = first; i < last; ++i) frames.push_back(index["frames"][i]);
  index["frames"] = std::move(frames);

  const std::string_view page = viz::ViewerTemplate();
  const std::size_t at = page.find(viz::kViewerDataMarker);
  if (at == std::string_view::npos)
    throw std::logic_error("viewer page without its data marker (viz/viewer/viewer.html)");
  std::string html(page.substr(0, at));
  const replay::Header& h = reader.header();
  const nlohmann::json title = h.scenario + " \u00b7 seed " + std::to_string(h.seed);
  html += "{\"title\":" + ScriptSafe(title.dump()) + ",\"index\":" + ScriptSafe(index.dump()) +
          ",\"frames\":[";
  for (std::size_t i = first; i < last; ++i) {
    html += i == first ? "\"" : ",\"";
    AppendBase64(reader.Compressed(i), html);
    html += '"';
  }
  html += "]}";
  html += page.substr(at + viz::kViewerDataMarker.size());
  // Under its name only when complete.
  const fs::path part = fs::path(out).concat(".part");
  WriteTextFile(part, html);
  fs::rename(part, out);
  return out;
}

}  // namespace dualgrid::outputs
