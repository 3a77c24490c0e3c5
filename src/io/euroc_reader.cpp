#include "io/euroc_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/image_file_io.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

// ---- sensor.yaml ---------------------------------------------------------------------------------------------

// EuRoC's sensor.yaml files start with OpenCV's "%YAML:1.0", which readYamlText() neutralises.
YAML::Node loadSensorYaml(const std::string& path) {
  if (!fs::exists(path)) fail(path, "", "sensor calibration file not found");
  const std::string text = readYamlText(path);
  try {
    YAML::Node root = YAML::Load(text);
    if (!root.IsMap()) fail(path, "", "expected a YAML map of sensor properties");
    return root;
  } catch (const YAML::Exception& e) {
    fail(path, lineRecord(static_cast<std::size_t>(e.mark.line + 1)), "invalid YAML: " + e.msg);
  }
}

std::string keyRecord(const YAML::Node& node, const std::string& key) {
  const int line = node.Mark().line;
  return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key '" + key + "'";
}

YAML::Node requireKey(const YAML::Node& map, const std::string& key, const std::string& file) {
  const YAML::Node node = map[key];
  if (!node) fail(file, "key '" + key + "'", "missing");
  return node;
}

std::string scalarText(const YAML::Node& node, const std::string& key, const std::string& file) {
  if (!node.IsScalar()) fail(file, keyRecord(node, key), "expected a single value");
  return node.Scalar();
}

std::vector<double> numberList(const YAML::Node& node, std::size_t expected, const std::string& key,
                               const std::string& file) {
  const std::string record = keyRecord(node, key);
  if (!node.IsSequence()) fail(file, record, "expected a list of " + std::to_string(expected) + " numbers");
  if (node.size() != expected)
    fail(file, record, "expected " + std::to_string(expected) + " numbers, found " + std::to_string(node.size()));
  std::vector<double> values;
  for (const YAML::Node& item : node) values.push_back(parseDouble(scalarText(item, key, file), file, record));
  return values;
}

Eigen::Isometry3d readTBS(const YAML::Node& root, const std::string& file) {
  const YAML::Node tbs = requireKey(root, "T_BS", file);
  if (!tbs.IsMap()) fail(file, keyRecord(tbs, "T_BS"), "expected a map with rows, cols and data");
  for (const char* dim : {"rows", "cols"}) {
    const YAML::Node n = requireKey(tbs, dim, file);
    const std::string key = std::string("T_BS.") + dim;
    if (parseInt64(scalarText(n, key, file), file, keyRecord(n, key)) != 4)
      fail(file, keyRecord(n, key), "expected 4");
  }
  const YAML::Node data = requireKey(tbs, "data", file);
  return rigidTransformFromRowMajor(numberList(data, 16, "T_BS.data", file), file, keyRecord(data, "T_BS.data"));
}

DistortionModel parseDistortionModel(const YAML::Node& node, const std::string& file) {
  const std::string name = scalarText(node, "distortion_model", file);
  if (name == "radial-tangential" || name == "radtan") return DistortionModel::kRadialTangential;
  if (name == "equidistant") return DistortionModel::kEquidistant;
  fail(file, keyRecord(node, "distortion_model"),
       "unknown distortion model '" + name + "' (expected radial-tangential or equidistant)");
}

CameraIntrinsics readIntrinsics(const YAML::Node& root, const std::string& file) {
  if (const YAML::Node model = root["camera_model"]; model && scalarText(model, "camera_model", file) != "pinhole")
    fail(file, keyRecord(model, "camera_model"), "only the pinhole camera model is supported");
  CameraIntrinsics cam;
  const YAML::Node res = requireKey(root, "resolution", file);
  const std::vector<double> wh = numberList(res, 2, "resolution", file);
  if (wh[0] < 1 || wh[1] < 1 || wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1]) || wh[0] > 1e5 ||
      wh[1] > 1e5)
    fail(file, keyRecord(res, "resolution"), "expected two positive integers [width, height]");
  cam.width = static_cast<int>(wh[0]);
  cam.height = static_cast<int>(wh[1]);
  const YAML::Node intr = requireKey(root, "intrinsics", file);
  const std::vector<double> k = numberList(intr, 4, "intrinsics", file);  // fu fv cu cv [px]
  if (!(k[0] > 0) || !(k[1] > 0))
    fail(file, keyRecord(intr, "intrinsics"),
         "focal lengths must be > 0 px, got fx " + formatDouble(k[0]) + ", fy " + formatDouble(k[1]));
  cam.fx = k[0], cam.fy = k[1], cam.cx = k[2], cam.cy = k[3];
  cam.distortion = parseDistortionModel(requireKey(root, "distortion_model", file), file);
  const YAML::Node coeffs = requireKey(root, "distortion_coefficients", file);
  // rad-tan: k1 k2 p1 p2 (EuRoC) or k1 k2 p1 p2 k3; equidistant: k1 k2 k3 k4.
  const std::size_t n = coeffs.IsSequence() ? coeffs.size() : 0;
  const bool radtan = cam.distortion == DistortionModel::kRadialTangential;
  cam.distortion_coeffs = numberList(coeffs, radtan && n == 5 ? 5 : 4, "distortion_coefficients", file);
  return cam;
}

// ---- csv indexes -----------------------------------------------------------------------------------------------

// Rows whose stamp does not advance are dropped, their warnings appended to `dropped`.
std::vector<ImuSample> readImuCsv(const std::string& path, std::vector<std::string>& dropped) {
  std::vector<ImuSample> samples;
  for (const NumberedLine& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto fields = splitOn(line.text, ',');
    requireColumns(fields, 7, path, record);
    ImuSample s;
    s.t = parseInt64(fields[0], path, record);
    const std::vector<double> v = parseDoubles(fields, 1, 6, path, record);
    if (!samples.empty() && s.t <= samples.back().t) {
      dropped.push_back(staleStampNotice(samples.back().t, s.t, path, record));
      continue;
    }
    s.omega_imu = Eigen::Vector3d(v[0], v[1], v[2]);
    s.acc_imu = Eigen::Vector3d(v[3], v[4], v[5]);
    samples.push_back(s);
  }
  if (samples.empty()) fail(path, "", "no IMU samples");
  return samples;
}

struct ImageEntry {
  Time t = 0;
  std::string path;    // cam0/data/<filename>
  std::string record;  // "mav0/cam0/data.csv line N", for errors raised when the image is read
};

std::vector<ImageEntry> readImageCsv(const std::string& csv, const fs::path& image_dir,
                                     std::vector<std::string>& dropped) {
  std::vector<ImageEntry> entries;
  for (const NumberedLine& line : readDataLines(csv, "#")) {
    const std::string record = lineRecord(line.number);
    const auto fields = splitOn(line.text, ',');
    requireColumns(fields, 2, csv, record);
    const Time t = parseInt64(fields[0], csv, record);
    if (fields[1].empty()) fail(csv, record, "empty image file name");
    constexpr std::size_t kMaxName = 255;  // [bytes] NAME_MAX of Linux file systems
    if (fields[1].size() > kMaxName || fields[1].find('/') != std::string_view::npos)
      fail(csv, record, "image file name " + echo(fields[1]) + " is not a plain file name of at most 255 characters");
    if (!entries.empty() && t <= entries.back().t) {
      dropped.push_back(staleStampNotice(entries.back().t, t, csv, record));
      continue;
    }
    entries.push_back({t, (image_dir / std::string(fields[1])).string(), csv + " " + record});
  }
  return entries;
}

// ---- images ---------------------------------------------------------------------------------------------------

Image decodeImage(const ImageEntry& entry, const CameraIntrinsics& cam) {
  std::error_code ec;  // the error_code form: a name the file system refuses is "not found", never a throw
  if (!fs::exists(entry.path, ec)) fail(entry.path, "listed in " + entry.record, "image file not found");
  cv::Mat mat = decodeImageFile(entry.path);
  if (mat.depth() != CV_8U) fail(entry.path, "", "expected an 8-bit image");
  if (mat.channels() == 4) cv::cvtColor(mat, mat, cv::COLOR_BGRA2BGR);
  if (mat.channels() != 1 && mat.channels() != 3) fail(entry.path, "", "expected a grey or colour image");
  if (mat.cols != cam.width || mat.rows != cam.height)
    fail(entry.path, "",
         "image is " + std::to_string(mat.cols) + "x" + std::to_string(mat.rows) + " but cam0/sensor.yaml says " +
             std::to_string(cam.width) + "x" + std::to_string(cam.height));
  if (!mat.isContinuous()) mat = mat.clone();
  Image img;
  img.width = mat.cols;
  img.height = mat.rows;
  img.channels = mat.channels();
  img.data.resize(mat.total() * mat.elemSize());
  std::memcpy(img.data.data(), mat.data, img.data.size());
  return img;
}

// ---- layout and ground truth -----------------------------------------------------------------------------------

struct Layout {
  fs::path root;  // sequence folder (holds mav0/ and possibly groundtruth_tum.txt)
  fs::path mav0;
};

// Absolute, normalised, without a trailing separator ("seq/." -> "/abs/seq"), so parent_path() is the parent.
fs::path normalFolder(const std::string& dir) {
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (p.filename().empty() && p.has_parent_path()) p = p.parent_path();
  return p;
}

Layout findLayout(const std::string& dir) {
  const fs::path p = normalFolder(dir);
  if (!fs::exists(p)) fail(dir, "", "EuRoC sequence folder not found");
  if (!fs::is_directory(p)) fail(dir, "", "not a folder (expected an EuRoC sequence folder holding mav0/)");
  if (fs::is_directory(p / "mav0")) return {p, p / "mav0"};
  if (fs::is_directory(p / "imu0") || fs::is_directory(p / "cam0")) return {p.parent_path(), p};
  fail(dir, "", "not an EuRoC sequence: no mav0/ folder (nor imu0/ and cam0/ in it)");
}

GroundTruth readGroundTruth(const Layout& layout, const Eigen::Isometry3d& T_B_imu) {
  const fs::path csv = layout.mav0 / "state_groundtruth_estimate0" / "data.csv";
  const fs::path tum = layout.root / "groundtruth_tum.txt";
  GroundTruth gt;
  if (fs::exists(csv))
    gt.poses = readEurocCsv(csv.string());
  else if (fs::exists(tum))
    gt.poses = readTum(tum.string());
  else
    return gt;
  for (StampedPose& p : gt.poses) p.T_world_body = p.T_world_body * T_B_imu;  // T_world_imu
  gt.body_frame = "imu";
  return gt;
}

// ---- the reader -----------------------------------------------------------------------------------------------

class EurocReader final : public Reader {
 public:
  EurocReader(std::string name, Calibration calib, GroundTruth gt, std::vector<ImuSample> imu,
              std::vector<ImageEntry> images, const std::vector<std::string>& dropped)
      : name_(std::move(name)),
        calib_(std::move(calib)),
        gt_(std::move(gt)),
        imu_(std::move(imu)),
        images_(std::move(images)) {
    for (const std::string& notice : dropped) dropMeasurement(notice);
  }

  std::optional<Measurement> next() override {
    const bool has_imu = next_imu_ < imu_.size();
    const bool has_image = next_image_ < images_.size();
    if (!has_imu && !has_image) return std::nullopt;
    if (has_imu && (!has_image || imu_[next_imu_].t <= images_[next_image_].t)) return imu_[next_imu_++];
    const ImageEntry& entry = images_[next_image_++];
    CameraFrame frame;
    frame.t = entry.t;
    frame.camera_id = 0;
    frame.image = decodeImage(entry, calib_.camera);
    frame.source = entry.path;
    return frame;
  }
  const Calibration& calibration() const override { return calib_; }
  const GroundTruth& groundTruth() const override { return gt_; }
  std::string describe() const override { return "EuRoC " + name_; }

 private:
  std::string name_;
  Calibration calib_;
  GroundTruth gt_;
  std::vector<ImuSample> imu_;
  std::vector<ImageEntry> images_;
  std::size_t next_imu_ = 0;
  std::size_t next_image_ = 0;
};

}  // namespace

Eigen::Isometry3d readEurocSensorExtrinsics(const std::string& sensor_yaml) {
  return readTBS(loadSensorYaml(sensor_yaml), sensor_yaml);
}

Calibration readEurocCalibration(const std::string& mav0_dir) {
  const std::string imu_yaml = (fs::path(mav0_dir) / "imu0" / "sensor.yaml").string();
  const std::string cam_yaml = (fs::path(mav0_dir) / "cam0" / "sensor.yaml").string();
  const Eigen::Isometry3d T_B_imu = readEurocSensorExtrinsics(imu_yaml);
  const YAML::Node cam_root = loadSensorYaml(cam_yaml);
  const Eigen::Isometry3d T_B_cam = readTBS(cam_root, cam_yaml);
  Calibration calib;
  calib.T_imu_cam = T_B_imu.inverse() * T_B_cam;
  calib.camera = readIntrinsics(cam_root, cam_yaml);
  return calib;
}

EurocImuNoise readEurocImuNoise(const std::string& dir) {
  EurocImuNoise noise;
  noise.file = (findLayout(dir).mav0 / "imu0" / "sensor.yaml").string();
  const YAML::Node root = loadSensorYaml(noise.file);
  const auto figure = [&](const char* key) -> std::optional<double> {
    const YAML::Node node = root[key];
    if (!node) return std::nullopt;
    const double value = parseDouble(scalarText(node, key, noise.file), noise.file, keyRecord(node, key));
    if (!std::isfinite(value) || value < 0)
      fail(noise.file, keyRecord(node, key), "expected a noise density >= 0, got " + formatDouble(value));
    return value;
  };
  noise.gyroscope_noise_density = figure("gyroscope_noise_density");
  noise.gyroscope_random_walk = figure("gyroscope_random_walk");
  noise.accelerometer_noise_density = figure("accelerometer_noise_density");
  noise.accelerometer_random_walk = figure("accelerometer_random_walk");
  return noise;
}

std::unique_ptr<Reader> openEuroc(const std::string& dir, const DatasetOptions& options) {
  const Layout layout = findLayout(dir);
  Calibration calib = readEurocCalibration(layout.mav0.string());
  const Eigen::Isometry3d T_B_imu = readEurocSensorExtrinsics((layout.mav0 / "imu0" / "sensor.yaml").string());
  GroundTruth gt = readGroundTruth(layout, T_B_imu);
  std::vector<std::string> dropped;  // rows whose stamp does not advance
  std::vector<ImuSample> imu;
  if (options.load_imu) imu = readImuCsv((layout.mav0 / "imu0" / "data.csv").string(), dropped);
  std::vector<ImageEntry> images;
  if (options.load_images)
    images = readImageCsv((layout.mav0 / "cam0" / "data.csv").string(), layout.mav0 / "cam0" / "data", dropped);
  return std::make_unique<EurocReader>(layout.root.filename().string(), std::move(calib), std::move(gt), std::move(imu),
                                       std::move(images), dropped);
}

}  // namespace drover::io
