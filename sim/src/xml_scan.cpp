#include "dualgrid/sim/xml_scan.hpp"

#include <expat.h>

#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>

#include "dualgrid/core/input_file.hpp"
#include "dualgrid/core/write_file.hpp"

namespace dualgrid::sim {

const char* XmlElement::Attribute(std::string_view name) const {
  for (const char** a = attributes_; a != nullptr && a[0] != nullptr; a += 2)
    if (name == a[0]) return a[1];
  return nullptr;
}

namespace {

// What the handlers share. No exception may cross expat's C frames: a callback's is kept in
// `error` and rethrown once the parser has stopped.
struct ParseState {
  XML_Parser parser = nullptr;
  const std::function<bool(const XmlElement&)>* element = nullptr;
  int depth = 0;
  bool stopped = false;
  std::exception_ptr error;
  // CopyXml only.
  std::FILE* out = nullptr;
  const XmlEdit* edit = nullptr;
  std::size_t changed = 0;
  bool open_tag = false;  // a start tag written without its '>' yet (an empty element may follow)
};

void Stop(ParseState* s) {
  s->stopped = true;
  XML_StopParser(s->parser, XML_FALSE);
}

long Line(const ParseState& s) { return static_cast<long>(XML_GetCurrentLineNumber(s.parser)); }

void OnStart(void* data, const XML_Char* name, const XML_Char** attributes) {
  auto* s = static_cast<ParseState*>(data);
  const int depth = s->depth++;
  if (s->stopped) return;
  try {
    if (!(*s->element)(XmlElement(name, attributes, Line(*s), depth))) Stop(s);
  } catch (...) {
    s->error = std::current_exception();
    Stop(s);
  }
}

void OnEnd(void* data, const XML_Char*) { --static_cast<ParseState*>(data)->depth; }

// --- CopyXml's writer -----------------------------------------------------------------------

struct WriteFailed {};  // CopyXml names the file

void Put(ParseState* s, std::string_view text) {
  if (!text.empty() && std::fwrite(text.data(), 1, text.size(), s->out) != text.size()) {
    s->error = std::make_exception_ptr(WriteFailed{});
    Stop(s);
  }
}

// XML escapes; in attribute values also the white space that a parser would otherwise
// normalise to blanks, so that values survive the copy exactly.
std::string Escaped(std::string_view text, bool attribute) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += attribute ? "&quot;" : "\"";
        break;
      case '\n':
        out += attribute ? "&#10;" : "\n";
        break;
      case '\r':
        out += "&#13;";
        break;
      case '\t':
        out += attribute ? "&#9;" : "\t";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void CloseOpenTag(ParseState* s) {
  if (s->open_tag) Put(s, ">");
  s->open_tag = false;
}

void OnCopyStart(void* data, const XML_Char* name, const XML_Char** attributes) {
  auto* s = static_cast<ParseState*>(data);
  const int depth = s->depth++;
  if (s->stopped) return;
  try {
    CloseOpenTag(s);
    const XmlElement e(name, attributes, Line(*s), depth);
    std::vector<std::pair<std::string, std::string>> changes;
    (*s->edit)(e, &changes);
    std::string tag = std::string("<") + name;
    for (const char** a = attributes; a[0] != nullptr; a += 2) {
      std::string_view value = a[1];
      for (const auto& [attr, v] : changes)
        if (attr == a[0]) {
          value = v;
          ++s->changed;
        }
      tag += std::string(" ") + a[0] + "=\"" + Escaped(value, true) + "\"";
    }
    Put(s, tag);
    s->open_tag = true;
  } catch (...) {
    s->error = std::current_exception();
    Stop(s);
  }
}

void OnCopyEnd(void* data, const XML_Char* name) {
  auto* s = static_cast<ParseState*>(data);
  --s->depth;
  if (s->stopped) return;
  if (s->open_tag) {
    Put(s, "/>");
    s->open_tag = false;
  } else {
    Put(s, std::string("</") + name + ">");
  }
}

void OnCopyText(void* data, const XML_Char* text, int length) {
  auto* s = static_cast<ParseState*>(data);
  if (s->stopped) return;
  CloseOpenTag(s);
  Put(s, Escaped(std::string_view(text, static_cast<std::size_t>(length)), false));
}

void OnCopyComment(void* data, const XML_Char* text) {
  auto* s = static_cast<ParseState*>(data);
  if (s->stopped) return;
  CloseOpenTag(s);
  Put(s, std::string("<!--") + text + "-->");
}

// Runs `s.parser` over `path`, turning expat's errors into the documented message.
void Parse(ParseState& s, const std::filesystem::path& path, const std::string& what) {
  const auto check = [&](XML_Status status) {
    if (status != XML_STATUS_ERROR || s.stopped) return;
    throw std::invalid_argument(path.string() + ":" + std::to_string(Line(s)) + ": " + what +
                                " is not well-formed XML (" +
                                XML_ErrorString(XML_GetErrorCode(s.parser)) + ")");
  };
  ReadInputChunks(path, what, [&](std::string_view c) {
    if (s.stopped) return;
    check(XML_Parse(s.parser, c.data(), static_cast<int>(c.size()), XML_FALSE));
  });
  if (!s.stopped) check(XML_Parse(s.parser, "", 0, XML_TRUE));  // a truncated document fails
}

struct ParserFree {
  void operator()(XML_ParserStruct* p) const { XML_ParserFree(p); }
};
struct FileClose {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

void ScanXml(const std::filesystem::path& path, const std::string& what,
             const std::function<bool(const XmlElement&)>& element) {
  ParseState s;
  const std::unique_ptr<XML_ParserStruct, ParserFree> parser(XML_ParserCreate(nullptr));
  if (!parser) throw std::runtime_error("out of memory (XML parser)");
  s.parser = parser.get();
  s.element = &element;
  XML_SetUserData(s.parser, &s);
  XML_SetElementHandler(s.parser, OnStart, OnEnd);
  Parse(s, path, what);
  if (s.error) std::rethrow_exception(s.error);
}

std::size_t CopyXml(const std::filesystem::path& path, const std::string& what,
                    const std::filesystem::path& out, const XmlEdit& edit) {
  ParseState s;
  const std::unique_ptr<XML_ParserStruct, ParserFree> parser(XML_ParserCreate(nullptr));
  if (!parser) throw std::runtime_error("out of memory (XML parser)");
  std::unique_ptr<std::FILE, FileClose> file(std::fopen(out.c_str(), "wb"));
  if (!file) throw std::runtime_error("cannot write " + out.string() + ": " + SystemReason());
  s.parser = parser.get();
  s.out = file.get();
  s.edit = &edit;
  XML_SetUserData(s.parser, &s);
  XML_SetElementHandler(s.parser, OnCopyStart, OnCopyEnd);
  XML_SetCharacterDataHandler(s.parser, OnCopyText);
  XML_SetCommentHandler(s.parser, OnCopyComment);
  Put(&s, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  Parse(s, path, what);
  Put(&s, "\n");
  const bool closed = std::fclose(file.release()) == 0;
  try {
    if (s.error) std::rethrow_exception(s.error);
  } catch (const WriteFailed&) {
    throw std::runtime_error("cannot write " + out.string() + ": " + SystemReason());
  }
  if (!closed) throw std::runtime_error("cannot write " + out.string() + ": " + SystemReason());
  return s.changed;
}

}  // namespace dualgrid::sim
