#include "io/config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>

#include "io/error.hpp"
#include "io/yaml_section.hpp"
#include "io/text_parsing.hpp"
#include "io/user_values.hpp"

namespace drover::io {
namespace {

// Reads typed values out of one section, naming file, line and "section.key" in every error.
class SectionReader {
 public:
  SectionReader(const YAML::Node& map, std::string section, std::string file)
      : map_(map), section_(std::move(section)), file_(std::move(file)) {}

  // Every key of the section must be one of `known`.
  void rejectUnknownKeys(std::initializer_list<const char*> known) const {
    for (const auto& kv : map_) {
      const std::string key = kv.first.Scalar();
      if (std::none_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) {
        std::string list;
        for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        fail(file_, record(kv.first, key), "unknown key (expected one of: " + list + ")");
      }
    }
  }
  bool has(const char* key) const { return static_cast<bool>(map_[key]); }
  YAML::Node node(const char* key) const { return map_[key]; }
  std::string record(const YAML::Node& node, const std::string& key) const {
    const int line = node.Mark().line;
    return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key " +
           echo(section_ + "." + key);
  }

  void read(const char* key, std::string& out) const {
    if (const YAML::Node n = map_[key]) {
      if (!n.IsScalar() || n.Scalar().empty()) fail(file_, record(n, key), "expected a non-empty string");
      out = n.Scalar();
    }
  }
  void read(const char* key, bool& out) const {
    if (const YAML::Node n = map_[key]) {
      if (!n.IsScalar() || !YAML::convert<bool>::decode(n, out))
        fail(file_, record(n, key), "expected true or false, found " + describe(n));
    }
  }
  void read(const char* key, int& out, int min, int max) const {
    if (const YAML::Node n = map_[key]) {
      out = static_cast<int>(parseInteger(scalar(n, key), min, max, source(n, key)));
    }
  }
  void read(const char* key, double& out, const Range& range = Range{}) const {
    if (const YAML::Node n = map_[key]) out = parseNumber(scalar(n, key), range, source(n, key));
  }
  // Seconds to Time [ns], checked as an option's seconds are (io/user_values.hpp).
  void readSeconds(const char* key, Time& out, const Range& range) const {
    if (const YAML::Node n = map_[key]) out = parseSecondsValue(scalar(n, key), range, source(n, key));
  }
  std::vector<double> numbers(const char* key) const {
    const YAML::Node n = map_[key];
    if (!n.IsSequence()) fail(file_, record(n, key), "expected a list of numbers, found " + describe(n));
    std::vector<double> values;
    for (const YAML::Node& item : n) values.push_back(parseNumber(scalar(item, key), source(n, key)));
    return values;
  }
  void readTransform(const char* key, Eigen::Isometry3d& out) const {
    if (!has(key)) return;
    const std::vector<double> v = numbers(key);
    if (v.size() != 16)
      fail(file_, record(map_[key], key),
           "expected 16 numbers (row-major 4x4), found " + std::to_string(v.size()));
    out = rigidTransformFromRowMajor(v, file_, record(map_[key], key));
  }
  const std::string& file() const { return file_; }

 private:
  ValueSource source(const YAML::Node& n, const std::string& key) const { return {file_, record(n, key)}; }
  std::string scalar(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(file_, record(n, key), "expected a number, found " + describe(n));
    return n.Scalar();
  }
  static std::string describe(const YAML::Node& n) {
    if (n.IsScalar()) return echo(n.Scalar());
    if (n.IsSequence()) return "a list";
    if (n.IsMap()) return "a map";
    return "nothing";
  }

  YAML::Node map_;
  std::string section_;
  std::string file_;
};

// A section is optional; "section:" with nothing under it counts as empty. Anything else must be a map.
YAML::Node section(const YAML::Node& root, const char* name, const std::string& file) {
  const YAML::Node n = root[name];
  if (!n || n.IsNull()) return YAML::Node(YAML::NodeType::Map);
  if (!n.IsMap()) fail(file, "key '" + std::string(name) + "'", "expected a map of settings");
  return n;
}

void readDataset(const SectionReader& s, DatasetOptions& o) {
  s.rejectUnknownKeys(
      {"lidar_topic", "imu_topic", "image_topic", "ground_truth_topic", "kitti_camera", "load_lidar", "load_imu",
       "load_images"});
  s.read("lidar_topic", o.lidar_topic);
  s.read("imu_topic", o.imu_topic);
  s.read("image_topic", o.image_topic);
  s.read("ground_truth_topic", o.ground_truth_topic);
  s.read("kitti_camera", o.kitti_camera, 0, 3);
  s.read("load_lidar", o.load_lidar);
  s.read("load_imu", o.load_imu);
  s.read("load_images", o.load_images);
}

DistortionModel parseDistortionModel(const SectionReader& s) {
  std::string name = "none";
  s.read("distortion_model", name);
  if (name == "none") return DistortionModel::kNone;
  if (name == "radial-tangential" || name == "radtan") return DistortionModel::kRadialTangential;
  if (name == "equidistant") return DistortionModel::kEquidistant;
  fail(s.file(), s.record(s.node("distortion_model"), "distortion_model"),
       "unknown distortion model " + echo(name) + " (expected none, radial-tangential or equidistant)");
}

void readCamera(const SectionReader& s, CameraIntrinsics& cam) {
  s.rejectUnknownKeys({"width", "height", "fx", "fy", "cx", "cy", "distortion_model", "distortion_coeffs"});
  s.read("width", cam.width, 0, 100000);
  s.read("height", cam.height, 0, 100000);
  for (auto [key, value] : {std::pair{"fx", &cam.fx}, {"fy", &cam.fy}, {"cx", &cam.cx}, {"cy", &cam.cy}})
    s.read(key, *value, atLeast(0, "px"));
  cam.distortion = parseDistortionModel(s);
  if (s.has("distortion_coeffs")) cam.distortion_coeffs = s.numbers("distortion_coeffs");
  const std::size_t n = cam.distortion_coeffs.size();
  const bool ok = cam.distortion == DistortionModel::kNone               ? n == 0
                  : cam.distortion == DistortionModel::kRadialTangential ? (n == 4 || n == 5)
                                                                         : n == 4;
  if (!ok)
    fail(s.file(), s.record(s.node("distortion_coeffs"), "distortion_coeffs"),
         std::to_string(n) + " coefficients do not fit the distortion model (none: 0, radial-tangential: 4 or 5, "
                             "equidistant: 4)");
}

void readCalibration(const SectionReader& s, Calibration& c) {
  s.rejectUnknownKeys({"T_imu_lidar", "T_imu_cam", "camera", "lidar_time_offset", "camera_time_offset"});
  s.readTransform("T_imu_lidar", c.T_imu_lidar);
  s.readTransform("T_imu_cam", c.T_imu_cam);
  for (auto [key, value] : {std::pair{"lidar_time_offset", &c.lidar_time_offset},
                            {"camera_time_offset", &c.camera_time_offset}})
    s.readSeconds(key, *value, between(-3600, 3600, "s"));  // one hour either way
  if (s.has("camera")) {
    const YAML::Node cam = s.node("camera");
    if (!cam.IsMap()) fail(s.file(), s.record(cam, "camera"), "expected a map of camera settings");
    readCamera(SectionReader(cam, "calibration.camera", s.file()), c.camera);
  }
}

}  // namespace

std::string readYamlText(const std::string& path) {
  std::string text = readTextFile(path);
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';
  return text;
}

Eigen::Isometry3d rigidTransformFromRowMajor(const std::vector<double>& v, const std::string& file,
                                             const std::string& record) {
  if (v.size() != 16) fail(file, record, "expected 16 numbers (row-major 4x4), found " + std::to_string(v.size()));
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = v[static_cast<std::size_t>(4 * r + c)];
  if (!((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() <= 1e-9))
    fail(file, record, "last row of a rigid transform must be 0 0 0 1");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = checkedRotation(M.topLeftCorner<3, 3>(), file, record);
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

DatasetOptions loadDatasetOptions(const std::string& yaml_path) {
  const YAML::Node root = loadConfigRoot(yaml_path);
  if (root.IsNull()) return {};  // an empty file: all defaults
  // Every module's section is known here, so a misspelt one ("odometri:") cannot be silently ignored.
  static const std::vector<std::string> known = {"dataset", "calibration", "sim", "odometry", "loop", "visual", "vio"};
  for (const auto& kv : root) {
    const std::string name = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), name) == known.end())
      fail(yaml_path, lineRecord(static_cast<std::size_t>(kv.first.Mark().line + 1)) + ", section " + echo(name),
           "unknown section (expected dataset, calibration, sim, odometry, loop, visual or vio)");
  }
  DatasetOptions options;
  readDataset(SectionReader(section(root, "dataset", yaml_path), "dataset", yaml_path), options);
  readCalibration(SectionReader(section(root, "calibration", yaml_path), "calibration", yaml_path),
                  options.calibration);
  return options;
}

}  // namespace drover::io
