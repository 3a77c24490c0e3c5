#pragma once
// Reads one YAML section of a platform config into typed fields that the caller binds by name, so that every
// module's Config can be filled from a file without the module knowing about YAML. An unknown key, a value of the
// wrong type or a non-finite number is an IoError naming the file, the line and the dotted key
// ("odometry.matcher.max_iterations"): a typo must never fall back to a default silently.
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace drover::io {

struct Range;

// The top level of a platform config file (config/*.yaml): a null node for an empty file, else a map. Throws IoError
// naming the file for a missing file, a folder, invalid YAML (with its line), a key or section written twice in one map
// (with both lines) or a top level that is not a map. Shared by every
// reader of a config section (dataset, sim, odometry, loop, visual).
YAML::Node loadConfigRoot(const std::string& yaml_path);

// A Config::validate() message as an IoError naming the file, the section's line (when the file has the section) and
// the section; nothing when `error` is empty.
void checkSectionValid(const std::string& file, const YAML::Node& section_node, const std::string& section,
                       const std::string& error);

class YamlSection {
 public:
  // `prefix` names the section in messages, e.g. "odometry.matcher".
  YamlSection(std::string file, std::string prefix);
  YamlSection& bind(const std::string& key, double& value);
  YamlSection& bind(const std::string& key, int& value);
  YamlSection& bind(const std::string& key, bool& value);
  YamlSection& bind(const std::string& key, std::string& value);
  // Seconds that the core turns into Time [ns]: within `range` and convertible (io/user_values.hpp).
  YamlSection& bindSeconds(const std::string& key, double& seconds, const Range& range);
  // A string that must be one of `allowed`; otherwise an IoError naming the line, the key and the allowed values.
  YamlSection& bindChoice(const std::string& key, std::string& value, std::vector<std::string> allowed);
  // A nested section, read by `read` (which binds its own keys on the YamlSection it is given).
  YamlSection& nested(const std::string& key, std::function<void(YamlSection&)> read);

  // Applies a map node: every key must have been bound. A null node changes nothing.
  void apply(const YAML::Node& node) const;

  const std::string& file() const { return file_; }
  const std::string& prefix() const { return prefix_; }

 private:
  using Setter = std::function<void(const YAML::Node&, const std::string& record)>;
  std::string file_, prefix_;
  std::map<std::string, Setter> setters_;
  std::map<std::string, std::function<void(YamlSection&)>> nested_;
};

}  // namespace drover::io
