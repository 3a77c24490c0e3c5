#pragma once
// Internals of the LIO-SAM / LVI-SAM importer (io/lvi_sam_import.hpp): one parsed parameter file whose keys are
// marked as they are consumed, so that every key left over can be listed, and the output config as an ordered
// tree of keys with a comment each.
#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "io/lvi_sam_import.hpp"
#include "io/user_values.hpp"

namespace drover::io::lvisam {

class ParamFile {
 public:
  // `params` is the map that holds the parameters (the namespace's content, or the root); `prefix` names it in
  // messages ("lvi_sam." or "").
  ParamFile(std::string path, const YAML::Node& params, std::string prefix);

  const std::string& path() const { return path_; }
  std::string dotted(const std::string& key) const { return prefix_ + key; }
  bool has(const std::string& key) const { return static_cast<bool>(find(key)); }

  // Typed values of a key given dotted within the parameters ("projection_parameters.fx"): nullopt when absent.
  // Each marks the key used and throws IoError naming the file, the line and the key on a bad value.
  std::optional<double> number(const std::string& key, const Range& range);
  std::optional<int> integer(const std::string& key, int min, int max);
  std::optional<std::string> text(const std::string& key);
  std::optional<bool> flag(const std::string& key);  // true/false, or 1/0 as VINS-Mono writes them
  // A ROS list of numbers or an !!opencv-matrix (rows, cols, data) of exactly `count` numbers.
  std::optional<std::vector<double>> numbers(const std::string& key, std::size_t count);

  void use(const std::string& key);  // marks a key (or every key under a map) consumed
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  std::string record(const std::string& key) const;  // "line N, key 'ns.key'" for messages
  // Leaf keys not consumed yet, in file order (an !!opencv-matrix or a list counts as one leaf).
  std::vector<std::string> unused() const;

 private:
  YAML::Node find(const std::string& key) const;
  ValueSource source(const std::string& key) const;
  std::string scalar(const std::string& key, const YAML::Node& n) const;

  std::string path_, prefix_;
  YAML::Node params_;
  std::vector<std::string> leaves_;  // dotted, in file order
  std::vector<std::string> used_;
};

// The generated config: sections and keys in the order they are first set.
class ConfigTree {
 public:
  // `dotted` = "odometry.layout.n_rings"; parents are created as needed. `value` is YAML text (a continuation
  // line of a multi-line value is indented under the first). Setting a key again replaces its value.
  void set(const std::string& dotted, std::string value, std::string comment = "");
  // A comment line written just above a section or key (created if needed).
  void note(const std::string& dotted, std::string comment);
  bool has(const std::string& dotted) const;
  std::string emit() const;

 private:
  struct Node {
    std::string key, value, comment;
    std::vector<std::string> notes;
    std::vector<Node> children;
  };
  Node& at(const std::string& dotted);
  static void emit(const Node& n, int depth, std::string& out);
  Node root_;
};

// YAML text of values.
std::string yamlNumber(double v);  // shortest round-trip text; -0 printed as 0
std::string yamlString(const std::string& s);  // double-quoted, escaped
std::string yamlList(const std::vector<double>& v, std::size_t per_line);  // flow list, `per_line` numbers a line

// The importer's result under construction.
struct Output {
  ConfigTree tree;
  std::vector<LviSamKey> mapped, ignored;
  std::string imu_topic;  // the lidar file's imuTopic, to compare with the camera file's imu_topic
  void map(ParamFile& f, const std::string& key, const std::string& note) {
    f.use(key);
    mapped.push_back({f.path(), f.dotted(key), note});
  }
  void ignore(ParamFile& f, const std::string& key, const std::string& why) {
    f.use(key);
    ignored.push_back({f.path(), f.dotted(key), why});
  }
};

// The two kinds of file (lvi_sam_lidar.cpp, lvi_sam_camera.cpp).
void mapLidarFile(ParamFile& f, Output& o);
void mapCameraFile(ParamFile& f, Output& o, bool have_lidar_file);
// Why a known LIO-SAM / LVI-SAM key has no Drover counterpart; empty for a key the importer does not know.
std::string whyIgnored(const std::string& key);

}  // namespace drover::io::lvisam
