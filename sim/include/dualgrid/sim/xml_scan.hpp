// SUMO's XML inputs (configurations, networks, route and additional files) parsed once, streaming,
// in linear time (expat), through core's bounded reader (dualgrid/core/input_file.hpp).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dualgrid/core/input_file.hpp"

namespace dualgrid::sim {

/// One XML start element: its tag and attributes (valid during the callback only).
class XmlElement {
 public:
  XmlElement(std::string_view tag, const char** attributes, long line, int depth)
      : tag_(tag), attributes_(attributes), line_(line), depth_(depth) {}
  std::string_view tag() const { return tag_; }
  /// The attribute's value, or nullptr when the element has none of that name.
  const char* Attribute(std::string_view name) const;
  /// Name, value, name, value, ..., nullptr (expat's list; valid during the callback only).
  const char* const* attributes() const { return attributes_; }
  long line() const { return line_; }
  /// 0 for the root element.
  int depth() const { return depth_; }

 private:
  std::string_view tag_;
  const char** attributes_;
  long line_;
  int depth_;
};

/// Parses `path` (dualgrid::ReadInputChunks) as XML with expat, in one linear pass, calling
/// `element` for every start element in document order; comments, processing instructions and CDATA
/// are never mistaken for elements. `element` returns false to stop early. Throws
/// std::invalid_argument "<path>:<line>: <what> is not well-formed XML (<expat's reason>)" for
/// a malformed or truncated document; external entities are never fetched.
void ScanXml(const std::filesystem::path& path, const std::string& what,
             const std::function<bool(const XmlElement&)>& element);

/// CopyXml's edit of one start element: appends (attribute name, new value) for each attribute of
/// `element` to change; attributes not named keep their value.
using XmlEdit = std::function<void(const XmlElement& element,
                                   std::vector<std::pair<std::string, std::string>>* changes)>;

/// Writes to `out` an equivalent copy of `path` (parsed as ScanXml does, one pass): elements,
/// attributes, text and comments in document order, UTF-8, with a fresh XML declaration; the
/// DOCTYPE and processing instructions are dropped (SUMO reads neither). `edit` may change
/// attribute values. Returns the number of attribute values changed. Throws
/// std::invalid_argument as ScanXml, std::runtime_error "cannot write <out>" when a write fails
/// (`out` is then incomplete: the caller removes it).
std::size_t CopyXml(const std::filesystem::path& path, const std::string& what,
                    const std::filesystem::path& out, const XmlEdit& edit);

}  // namespace dualgrid::sim
