#include "dualgrid/core/json_input.hpp"

#include <istream>
#include <set>
#include <stdexcept>
#include <streambuf>
#include <vector>

namespace dualgrid {
namespace {

using Json = nlohmann::json;

// An std::streambuf over an InputStream: JSON is parsed as it is read, so that a file that is
// not JSON (zeros, a binary) is refused at its first bytes, not after reading up to the cap.
class InputBuffer : public std::streambuf {
 public:
  explicit InputBuffer(InputStream& in) : in_(in) {}

 protected:
  int_type underflow() override {
    const std::size_t n = in_.Read(buffer_, sizeof buffer_);
    if (n == 0) return traits_type::eof();
    setg(buffer_, buffer_, buffer_ + n);
    return traits_type::to_int_type(buffer_[0]);
  }

 private:
  InputStream& in_;
  char buffer_[1 << 16];
};

// Refuses a key given twice in one object, naming its path ("scenes.123"; "[]" for a list).
class DuplicateKeys {
 public:
  explicit DuplicateKeys(const std::string& file) : file_(file) {}
  bool operator()(int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        if (levels_.size() >= static_cast<std::size_t>(kMaxJsonDepth))
          throw std::invalid_argument(file_ + ": lists or objects nested more than " +
                                      std::to_string(kMaxJsonDepth) + " deep");
        levels_.push_back(
            {{}, Key() + (event == Json::parse_event_t::array_start ? "[]" : ""), ""});
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

// Parses what `parse(callback)` reads, naming `file` in every error; `size` for the message.
template <class Parse>
Json Parsed(const std::string& file, const std::string& size, Parse&& parse) {
  try {
    return parse(DuplicateKeys(file));
  } catch (const Json::parse_error& e) {
    throw std::invalid_argument(file + ": not valid JSON (at byte " + std::to_string(e.byte) +
                                size + "; truncated or damaged?)");
  } catch (const Json::exception&) {
    throw std::invalid_argument(file + ": not valid JSON (truncated or damaged?)");
  }
}

}  // namespace

Json ParseJsonInput(const std::string& text, const std::string& file) {
  return Parsed(file, " of " + std::to_string(text.size()),
                [&](DuplicateKeys keys) { return Json::parse(text, std::move(keys)); });
}

Json ReadJsonInput(const std::filesystem::path& path, const std::string& what,
                   std::uint64_t max_bytes) {
  return NamingInputOnFailure(path, what, [&] {
    InputStream in(path, what, max_bytes);
    InputBuffer buffer(in);
    std::istream stream(&buffer);
    return Parsed(path.string(), "",
                  [&](DuplicateKeys keys) { return Json::parse(stream, std::move(keys)); });
  });
}

}  // namespace dualgrid
