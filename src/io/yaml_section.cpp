#include "io/yaml_section.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/text_parsing.hpp"
#include "io/user_values.hpp"

namespace drover::io {
namespace {

std::string lineOf(const YAML::Node& n) { return lineRecord(static_cast<std::size_t>(n.Mark().line + 1)); }

// `dotted` is the section's own path and a bound key's name: Drover's text, printed whole (echo() would cut the longer
// ones, such as odometry.vis_fusion.keyframe_gap_min_distance, at 40 characters). A key the file made up is echoed.
std::string record(const YAML::Node& n, const std::string& dotted, bool known = true) {
  const int line = n.Mark().line;
  return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key " +
         (known ? "'" + dotted + "'" : echo(dotted));
}

// A key written twice in one map: yaml-cpp keeps both pairs, lookups find the first and readers that iterate take
// the last, so either way one of the two values would be dropped silently. Walks every map and list; the count
// bounds the walk when anchors and aliases make a small file a huge tree.
void rejectDuplicateKeys(const YAML::Node& node, const std::string& prefix, const std::string& file,
                         std::size_t& visited) {
  constexpr std::size_t kMaxNodes = 1'000'000;
  if (++visited > kMaxNodes) fail(file, "", "more than 1000000 YAML nodes (aliases?); a config is a small file");
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) rejectDuplicateKeys(item, prefix, file, visited);
    return;
  }
  if (!node.IsMap()) return;
  std::map<std::string, YAML::Node> seen;
  for (const auto& kv : node) {
    if (kv.first.IsScalar()) {
      const std::string key = kv.first.Scalar();
      const std::string dotted = prefix.empty() ? key : prefix + "." + key;
      if (const auto first = seen.find(key); first != seen.end())
        fail(file, lineOf(kv.first) + ", " + (prefix.empty() ? "section " : "key ") + echo(dotted),
             std::string(prefix.empty() ? "duplicate section" : "duplicate key") + " (first at " +
                 lineOf(first->second) + "); write each once");
      seen.emplace(key, kv.first);
      rejectDuplicateKeys(kv.second, dotted, file, visited);
    } else {
      rejectDuplicateKeys(kv.second, prefix, file, visited);
    }
  }
}

std::string scalarOf(const YAML::Node& n, const std::string& file, const std::string& rec) {
  if (!n.IsScalar()) fail(file, rec, "expected a single value");
  return n.Scalar();
}

}  // namespace

YamlSection::YamlSection(std::string file, std::string prefix) : file_(std::move(file)), prefix_(std::move(prefix)) {}

YamlSection& YamlSection::bind(const std::string& key, double& value) {
  setters_[key] = [this, &value](const YAML::Node& n, const std::string& rec) {
    value = parseNumber(scalarOf(n, file_, rec), ValueSource{file_, rec});
  };
  return *this;
}

YamlSection& YamlSection::bind(const std::string& key, int& value) {
  setters_[key] = [this, &value](const YAML::Node& n, const std::string& rec) {
    value = static_cast<int>(parseInteger(scalarOf(n, file_, rec), std::numeric_limits<int>::min(),
                                          std::numeric_limits<int>::max(), ValueSource{file_, rec}));
  };
  return *this;
}

YamlSection& YamlSection::bind(const std::string& key, bool& value) {
  setters_[key] = [this, &value](const YAML::Node& n, const std::string& rec) {
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, value)) fail(file_, rec, "expected true or false");
  };
  return *this;
}

YamlSection& YamlSection::bind(const std::string& key, std::string& value) {
  setters_[key] = [this, &value](const YAML::Node& n, const std::string& rec) { value = scalarOf(n, file_, rec); };
  return *this;
}

YamlSection& YamlSection::bindChoice(const std::string& key, std::string& value, std::vector<std::string> allowed) {
  setters_[key] = [this, &value, allowed = std::move(allowed)](const YAML::Node& n, const std::string& rec) {
    const std::string v = scalarOf(n, file_, rec);
    if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
      std::string list;  // "a, b or c"
      for (std::size_t i = 0; i < allowed.size(); ++i)
        list += (i == 0 ? "" : i + 1 == allowed.size() ? " or " : ", ") + allowed[i];
      fail(file_, rec, "expected " + list + ", got " + echo(v));
    }
    value = v;
  };
  return *this;
}

YamlSection& YamlSection::bindSeconds(const std::string& key, double& seconds, const Range& range) {
  setters_[key] = [this, &seconds, range](const YAML::Node& n, const std::string& rec) {
    const ValueSource source{file_, rec};
    seconds = parseNumber(scalarOf(n, file_, rec), source);
    checkedSeconds(seconds, range, source);  // the core converts it to Time [ns]
  };
  return *this;
}

YamlSection& YamlSection::nested(const std::string& key, std::function<void(YamlSection&)> read) {
  nested_[key] = std::move(read);
  return *this;
}

void YamlSection::apply(const YAML::Node& node) const {
  if (!node || node.IsNull()) return;
  if (!node.IsMap()) fail(file_, record(node, prefix_), "expected a map of settings");
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const std::string dotted = prefix_ + "." + key;
    if (auto s = setters_.find(key); s != setters_.end()) {
      s->second(kv.second, record(kv.first, dotted));
    } else if (auto n = nested_.find(key); n != nested_.end()) {
      YamlSection child(file_, dotted);
      n->second(child);
      child.apply(kv.second);
    } else {
      std::string known;
      for (const auto& [k, _] : setters_) known += (known.empty() ? "" : ", ") + k;
      for (const auto& [k, _] : nested_) known += (known.empty() ? "" : ", ") + k;
      fail(file_, record(kv.first, dotted, false), "unknown key (expected one of: " + known + ")");
    }
  }
}

void checkSectionValid(const std::string& file, const YAML::Node& section_node, const std::string& section,
                       const std::string& error) {
  if (error.empty()) return;
  const int line = section_node ? section_node.Mark().line : -1;
  fail(file,
       (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "section '" + section + "'",
       error);
}

YAML::Node loadConfigRoot(const std::string& yaml_path) {
  if (!std::filesystem::exists(yaml_path)) fail(yaml_path, "", "config file not found");
  if (std::filesystem::is_directory(yaml_path))
    fail(yaml_path, "", "is a folder; expected a config file (config/*.yaml)");
  YAML::Node root;
  try {
    root = YAML::Load(readYamlText(yaml_path));
  } catch (const YAML::Exception& e) {
    fail(yaml_path, lineRecord(static_cast<std::size_t>(e.mark.line + 1)), "invalid YAML: " + e.msg);
  }
  if (!root.IsNull() && !root.IsMap()) fail(yaml_path, "", "expected a YAML map of sections at top level");
  std::size_t visited = 0;
  rejectDuplicateKeys(root, "", yaml_path, visited);
  return root;
}

}  // namespace drover::io
