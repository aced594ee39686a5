#include "dualgrid/core/json_input.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <vector>

namespace dualgrid {
namespace {

using Json = nlohmann::json;

// The deepest nesting of `text` (strings skipped), found before parsing.
std::size_t MaxDepth(const std::string& text) {
  std::size_t depth = 0, max_depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      max_depth = std::max(max_depth, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return max_depth;
}

// Refuses a key given twice in one object, naming its path ("scenes.123"; "[]" for a list).
class DuplicateKeys {
 public:
  explicit DuplicateKeys(const std::string& file) : file_(file) {}
  bool operator()(int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
        levels_.push_back({{}, Key(), ""});
        break;
      case Json::parse_event_t::array_start:
        levels_.push_back({{}, Key() + "[]", ""});
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!levels_.empty()) levels_.pop_back();
        break;
      case Json::parse_event_t::key: {
        Level& top = levels_.back();
        const std::string name = parsed.get<std::string>();
        top.key = name;
        if (!top.seen.insert(name).second)
          throw std::invalid_argument(file_ + ": key '" + Path() + "' given twice");
        break;
      }
      case Json::parse_event_t::value:
        break;
    }
    return true;
  }

 private:
  struct Level {
    std::set<std::string> seen;
    std::string prefix, key;
  };
  // The path of the key being read at the innermost level.
  std::string Path() const {
    const Level& top = levels_.back();
    return top.prefix.empty() ? top.key : top.prefix + "." + top.key;
  }
  // The prefix for a level opened now (the path of the key it is the value of).
  std::string Key() const {
    if (levels_.empty()) return "";
    const Level& top = levels_.back();
    if (top.key.empty()) return top.prefix;
    return top.prefix.empty() ? top.key : top.prefix + "." + top.key;
  }

  std::string file_;
  std::vector<Level> levels_;
};

}  // namespace

Json ParseJsonInput(const std::string& text, const std::string& file) {
  const std::size_t depth = MaxDepth(text);
  if (depth > static_cast<std::size_t>(kMaxJsonDepth))
    throw std::invalid_argument(file + ": lists or objects nested " + std::to_string(depth) +
                                " deep, expected at most " + std::to_string(kMaxJsonDepth));
  try {
    return Json::parse(text, DuplicateKeys(file));
  } catch (const Json::parse_error& e) {
    throw std::invalid_argument(file + ": not valid JSON (at byte " + std::to_string(e.byte) +
                                " of " + std::to_string(text.size()) + "; truncated or damaged?)");
  } catch (const Json::exception&) {
    throw std::invalid_argument(file + ": not valid JSON (truncated or damaged?)");
  }
}

Json ReadJsonInput(const std::filesystem::path& path, const std::string& what,
                   std::uint64_t max_bytes) {
  return NamingInputOnFailure(path, what, [&] {
    return ParseJsonInput(ReadInputText(path, what, max_bytes), path.string());
  });
}

}  // namespace dualgrid
