#include "sections.hpp"

namespace dualgrid::scenario {

Override ParseOverride(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError("--set '" + text + "': expected KEY=VALUE, e.g. filter.preset=paper");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace detail {

// Sets `o.key` in `doc` to the YAML value `o.value`, creating maps on the way.
void ApplyOverride(YAML::Node doc, const Override& o) {
  const std::string where = "--set " + o.key + "=" + o.value;
  YAML::Node value;
  try {
    value = YAML::Load(o.value);
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + ": the value is not valid YAML: " + e.msg);
  }
  std::vector<std::string> parts;
  for (std::size_t a = 0;;) {
    const std::size_t b = o.key.find('.', a);
    parts.push_back(o.key.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  // yaml-cpp nodes are handles: assigning to `node` would rebind it, so walk with reset().
  YAML::Node node;
  node.reset(doc);
  std::string path;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    if (part.empty()) throw ConfigError(where + ": empty component in the key");
    path += (path.empty() ? "" : ".") + part;
    const bool last = i + 1 == parts.size();
    if (node.IsSequence()) {
      if (part.find_first_not_of("0123456789") != std::string::npos || part.size() > 6 ||
          std::stoul(part) >= node.size())
        throw ConfigError(where + ": '" + path + "' indexes a list of " +
                          std::to_string(node.size()) + " entries; expected an index 0.." +
                          std::to_string(node.size() == 0 ? 0 : node.size() - 1));
      if (last) {
        node[std::stoul(part)] = value;
        return;
      }
      YAML::Node next = node[std::stoul(part)];
      node.reset(next);
      continue;
    }
    if (!node.IsMap() && !node.IsNull())
      throw ConfigError(where + ": '" + path.substr(0, path.size() - part.size() - 1) +
                        "' is not a map in the scenario file");
    if (last) {
      node[part] = value;
      return;
    }
    YAML::Node next = node[part];
    if (!next.IsDefined() || next.IsNull()) {  // a section the file does not have yet
      node[part] = YAML::Node(YAML::NodeType::Map);
      next.reset(node[part]);
    }
    node.reset(next);
  }
}

}  // namespace detail

}  // namespace dualgrid::scenario
