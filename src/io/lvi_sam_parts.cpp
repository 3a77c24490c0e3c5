#include "io/lvi_sam_parts.hpp"

#include <algorithm>
#include <limits>

#include "io/error.hpp"
#include "io/text_parsing.hpp"

namespace drover::io::lvisam {
namespace {

// An OpenCV FileStorage matrix (!!opencv-matrix): a map with rows, cols and data. yaml-cpp keeps the tag but
// parses the map as any other, so it is recognised by its keys.
bool isOpenCvMatrix(const YAML::Node& n) { return n.IsMap() && n["rows"] && n["cols"] && n["data"]; }

void collectLeaves(const YAML::Node& n, const std::string& prefix, std::vector<std::string>& out) {
  if (!n.IsMap() || isOpenCvMatrix(n) || n.size() == 0) {
    out.push_back(prefix);
    return;
  }
  for (const auto& kv : n) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    collectLeaves(kv.second, prefix.empty() ? key : prefix + "." + key, out);
  }
}

bool under(const std::string& leaf, const std::string& key) {
  return leaf == key || (leaf.size() > key.size() && leaf.compare(0, key.size(), key) == 0 && leaf[key.size()] == '.');
}

}  // namespace

ParamFile::ParamFile(std::string path, const YAML::Node& params, std::string prefix)
    : path_(std::move(path)), prefix_(std::move(prefix)), params_(params) {
  if (params_.IsMap())
    for (const auto& kv : params_) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
      collectLeaves(kv.second, key, leaves_);
    }
}

YAML::Node ParamFile::find(const std::string& key) const {
  YAML::Node n;
  n.reset(params_);  // reset, not assignment: assigning to a Node would overwrite the tree it refers to
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = key.find('.', begin);
    const std::string part = key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    if (!n.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& parent = n;  // the const operator[] looks up without inserting
    const YAML::Node child = parent[part];
    if (!child) return YAML::Node(YAML::NodeType::Undefined);
    n.reset(child);
    if (dot == std::string::npos) return n;
    begin = dot + 1;
  }
}

ValueSource ParamFile::source(const std::string& key) const {
  const YAML::Node n = find(key);
  const int line = n ? n.Mark().line : -1;
  return {path_, (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key " +
                     echo(dotted(key))};
}

std::string ParamFile::record(const std::string& key) const { return source(key).record; }

void ParamFile::fail(const std::string& key, const std::string& what) const {
  const ValueSource s = source(key);
  io::fail(s.file, s.record, what);
}

std::string ParamFile::scalar(const std::string& key, const YAML::Node& n) const {
  if (!n.IsScalar()) fail(key, "expected a single value");
  return n.Scalar();
}

void ParamFile::use(const std::string& key) { used_.push_back(key); }

std::optional<double> ParamFile::number(const std::string& key, const Range& range) {
  const YAML::Node n = find(key);
  if (!n) return std::nullopt;
  use(key);
  return parseNumber(scalar(key, n), range, source(key));
}

std::optional<int> ParamFile::integer(const std::string& key, int min, int max) {
  const YAML::Node n = find(key);
  if (!n) return std::nullopt;
  use(key);
  return static_cast<int>(parseInteger(scalar(key, n), min, max, source(key)));
}

std::optional<std::string> ParamFile::text(const std::string& key) {
  const YAML::Node n = find(key);
  if (!n) return std::nullopt;
  use(key);
  return scalar(key, n);
}

std::optional<bool> ParamFile::flag(const std::string& key) {
  const YAML::Node n = find(key);
  if (!n) return std::nullopt;
  use(key);
  const std::string v = scalar(key, n);
  if (v == "1") return true;
  if (v == "0") return false;
  bool b = false;
  if (!YAML::convert<bool>::decode(n, b)) fail(key, "expected true, false, 1 or 0, got " + echo(v));
  return b;
}

std::optional<std::vector<double>> ParamFile::numbers(const std::string& key, std::size_t count) {
  const YAML::Node n = find(key);
  if (!n) return std::nullopt;
  use(key);
  const YAML::Node list = isOpenCvMatrix(n) ? n["data"] : n;
  if (!list.IsSequence()) fail(key, "expected a list of " + std::to_string(count) + " numbers");
  if (isOpenCvMatrix(n)) {
    const auto rows = parseInteger(scalar(key, n["rows"]), 1, 1000, source(key));
    const auto cols = parseInteger(scalar(key, n["cols"]), 1, 1000, source(key));
    if (static_cast<std::size_t>(rows * cols) != list.size())
      fail(key, std::to_string(rows) + "x" + std::to_string(cols) + " matrix with " + std::to_string(list.size()) +
                    " numbers in data");
  }
  if (list.size() != count)
    fail(key, "expected " + std::to_string(count) + " numbers, found " + std::to_string(list.size()));
  std::vector<double> v;
  for (const YAML::Node& item : list) v.push_back(parseNumber(scalar(key, item), source(key)));
  return v;
}

std::vector<std::string> ParamFile::unused() const {
  std::vector<std::string> out;
  for (const std::string& leaf : leaves_)
    if (std::none_of(used_.begin(), used_.end(), [&](const std::string& k) { return under(leaf, k); }))
      out.push_back(leaf);
  return out;
}

ConfigTree::Node& ConfigTree::at(const std::string& dotted) {
  Node* n = &root_;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', begin);
    const std::string part = dotted.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    auto it = std::find_if(n->children.begin(), n->children.end(), [&](const Node& c) { return c.key == part; });
    if (it == n->children.end()) {
      n->children.push_back(Node{part, "", "", {}, {}});
      it = std::prev(n->children.end());
    }
    n = &*it;
    if (dot == std::string::npos) return *n;
    begin = dot + 1;
  }
}

void ConfigTree::set(const std::string& dotted, std::string value, std::string comment) {
  Node& n = at(dotted);
  n.value = std::move(value);
  n.comment = std::move(comment);
}

void ConfigTree::note(const std::string& dotted, std::string comment) {
  at(dotted).notes.push_back(std::move(comment));
}

bool ConfigTree::has(const std::string& dotted) const {
  const Node* n = &root_;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', begin);
    const std::string part = dotted.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    auto it = std::find_if(n->children.begin(), n->children.end(), [&](const Node& c) { return c.key == part; });
    if (it == n->children.end()) return false;
    n = &*it;
    if (dot == std::string::npos) return true;
    begin = dot + 1;
  }
}

void ConfigTree::emit(const Node& n, int depth, std::string& out) {
  if (n.value.empty() && n.children.empty()) return;  // a section nothing was imported into
  const std::string indent(static_cast<std::size_t>(2 * depth), ' ');
  for (const std::string& c : n.notes) out += indent + "# " + c + "\n";
  std::string line = indent + n.key + ":";
  if (!n.value.empty()) {
    // Continuation lines of a multi-line value line up under its first character.
    const std::string pad(line.size() + 1, ' ');
    std::string value;
    for (char ch : n.value) value += ch == '\n' ? "\n" + pad : std::string(1, ch);
    line += " " + value;
  }
  if (!n.comment.empty()) line += "  # " + n.comment;
  out += line + "\n";
  for (const Node& c : n.children) emit(c, depth + 1, out);
}

std::string ConfigTree::emit() const {
  std::string out;
  for (const Node& section : root_.children) emit(section, 0, out);
  return out;
}

std::string yamlNumber(double v) { return formatDouble(v + 0.0); }

std::string yamlString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string yamlList(const std::vector<double>& v, std::size_t per_line) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    out += yamlNumber(v[i]);
    if (i + 1 < v.size()) out += (per_line > 0 && (i + 1) % per_line == 0) ? ",\n " : ", ";
  }
  return out + "]";
}

}  // namespace drover::io::lvisam
