// Reader of Drover's simulated-dataset folder (format in io/sim_dataset.hpp).
#include <yaml-cpp/yaml.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/image_file_io.hpp"
#include "io/sim_dataset.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little, "the .bin records are read in host order");

// ---- calibration.yaml ------------------------------------------------------------------------------------------

// Typed access to required keys of one YAML map, naming file, line and "section.key" in every error.
class YamlMap {
 public:
  YamlMap(YAML::Node node, std::string path, std::string file) : node_(node), path_(std::move(path)), file_(file) {}
  YamlMap map(const std::string& key) const {
    const YAML::Node n = get(key);
    if (!n.IsMap()) fail(file_, record(n, key), "expected a map");
    return YamlMap(n, name(key), file_);
  }
  std::string text(const std::string& key) const {
    const YAML::Node n = get(key);
    if (!n.IsScalar()) fail(file_, record(n, key), "expected a single value");
    return n.Scalar();
  }
  double number(const std::string& key) const { return parseDouble(text(key), file_, record(get(key), key)); }
  double positive(const std::string& key) const {
    const double v = number(key);
    if (!(v > 0)) fail(file_, record(get(key), key), "must be positive");
    return v;
  }
  int integer(const std::string& key, int min, int max) const {
    const std::int64_t v = parseInt64(text(key), file_, record(get(key), key));
    if (v < min || v > max)
      fail(file_, record(get(key), key), "expected an integer in [" + std::to_string(min) + ", " +
                                             std::to_string(max) + "], found " + std::to_string(v));
    return static_cast<int>(v);
  }
  bool has(const std::string& key) const { return static_cast<bool>(node_[key]); }
  bool boolean(const std::string& key) const {
    const std::string v = text(key);
    if (v != "true" && v != "false") fail(file_, record(get(key), key), "expected true or false, found " + v);
    return v == "true";
  }
  Time seconds(const std::string& key) const { return parseSeconds(text(key), file_, record(get(key), key)); }
  std::vector<double> numbers(const std::string& key) const {
    const YAML::Node n = get(key);
    if (!n.IsSequence()) fail(file_, record(n, key), "expected a list of numbers");
    std::vector<double> v;
    for (const YAML::Node& item : n) {
      if (!item.IsScalar()) fail(file_, record(n, key), "expected a list of numbers");
      v.push_back(parseDouble(item.Scalar(), file_, record(n, key)));
    }
    return v;
  }
  Eigen::Isometry3d transform(const std::string& key) const {
    return rigidTransformFromRowMajor(numbers(key), file_, record(get(key), key));
  }
  [[noreturn]] void failKey(const std::string& key, const std::string& what) const {
    fail(file_, record(get(key), key), what);
  }
  std::string record(const YAML::Node& n, const std::string& key) const {
    const int line = n.Mark().line;
    return (line >= 0 ? lineRecord(static_cast<std::size_t>(line + 1)) + ", " : std::string()) + "key '" +
           name(key) + "'";
  }

 private:
  std::string name(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  YAML::Node get(const std::string& key) const {
    const YAML::Node n = node_[key];
    if (!n) fail(file_, "key '" + name(key) + "'", "missing");
    return n;
  }
  YAML::Node node_;
  std::string path_, file_;
};

CameraIntrinsics readCamera(const YamlMap& m) {
  CameraIntrinsics k;
  k.width = m.integer("width", 1, 100000);
  k.height = m.integer("height", 1, 100000);
  k.fx = m.positive("fx"), k.fy = m.positive("fy");
  k.cx = m.number("cx"), k.cy = m.number("cy");
  const std::string model = m.text("distortion_model");
  k.distortion_coeffs = m.numbers("distortion_coeffs");
  const std::size_t n = k.distortion_coeffs.size();
  bool ok = false;
  if (model == "none") {
    k.distortion = DistortionModel::kNone, ok = n == 0;
  } else if (model == "radial-tangential") {
    k.distortion = DistortionModel::kRadialTangential, ok = n == 4 || n == 5;
  } else if (model == "equidistant") {
    k.distortion = DistortionModel::kEquidistant, ok = n == 4;
  } else {
    m.failKey("distortion_model", "unknown model '" + model + "' (expected none, radial-tangential or equidistant)");
  }
  if (!ok) m.failKey("distortion_coeffs", std::to_string(n) + " coefficients do not fit " + model);
  return k;
}

Calibration readCalibration(const YamlMap& m) {
  Calibration c;
  c.T_imu_lidar = m.transform("T_imu_lidar");
  c.T_imu_cam = m.transform("T_imu_cam");
  c.lidar_time_offset = m.seconds("lidar_time_offset");
  c.camera_time_offset = m.seconds("camera_time_offset");
  c.camera = readCamera(m.map("camera"));
  return c;
}

SimSensorInfo readSensors(const YamlMap& m) {
  SimSensorInfo s;
  const YamlMap lidar = m.map("lidar");
  s.lidar_model = lidar.text("model");
  s.lidar_rings = lidar.integer("rings", 1, 65535);
  s.lidar_columns = lidar.integer("columns", 1, 1000000);
  s.lidar_rate_hz = lidar.positive("rate_hz");
  const YamlMap camera = m.map("camera");
  s.camera_rate_hz = camera.positive("rate_hz");
  s.camera_channels = camera.integer("channels", 1, 3);
  if (s.camera_channels == 2) camera.failKey("channels", "expected 1 (mono8) or 3 (bgr8)");
  s.camera_exposure_s = camera.number("exposure_s");
  // Datasets written before the key are point-sampled.
  s.camera_pixel_samples = camera.has("pixel_samples") ? camera.integer("pixel_samples", 1, 4) : 1;
  s.camera_texture_filter = camera.has("texture_filter") && camera.boolean("texture_filter");
  s.camera_edge_pixel_samples = camera.has("edge_pixel_samples") ? camera.integer("edge_pixel_samples", 0, 4) : 0;
  const YamlMap imu = m.map("imu");
  s.imu_rate_hz = imu.positive("rate_hz");
  s.gyro_noise_density = imu.number("gyro_noise_density");
  s.accel_noise_density = imu.number("accel_noise_density");
  s.gyro_bias_random_walk = imu.number("gyro_bias_random_walk");
  s.accel_bias_random_walk = imu.number("accel_bias_random_walk");
  const YamlMap gt = m.map("ground_truth");
  s.ground_truth_rate_hz = gt.positive("rate_hz");
  if (gt.text("body_frame") != "imu") gt.failKey("body_frame", "expected 'imu'");
  return s;
}

void readCalibrationYaml(const fs::path& path, SimDatasetDescription& d) {
  const std::string file = path.string();
  if (!fs::exists(path)) fail(file, "", "calibration file not found (not a simulated dataset, or an incomplete one)");
  YAML::Node root;
  try {
    root = YAML::Load(readTextFile(file));
  } catch (const YAML::Exception& e) {
    fail(file, lineRecord(static_cast<std::size_t>(e.mark.line + 1)), "invalid YAML: " + e.msg);
  }
  if (!root.IsMap()) fail(file, "", "expected a YAML map with calibration and sensors");
  const YamlMap top(root, "", file);
  d.calibration = readCalibration(top.map("calibration"));
  d.sensors = readSensors(top.map("sensors"));
}

// ---- scenario.json ---------------------------------------------------------------------------------------------

template <typename T>
T jsonValue(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key)) fail(file, std::string("key '") + key + "'", "missing");
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception& e) {
    fail(file, std::string("key '") + key + "'", std::string("wrong type: ") + e.what());
  }
}

void readScenarioJson(const fs::path& path, SimDatasetDescription& d) {
  const std::string file = path.string();
  if (!fs::exists(path)) fail(file, "", "scenario file not found");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readTextFile(file));
  } catch (const nlohmann::json::parse_error& e) {
    fail(file, "byte " + std::to_string(e.byte), "invalid JSON");
  }
  if (!j.is_object()) fail(file, "", "expected a JSON object");
  const int version = jsonValue<int>(j, "format_version", file);
  if (version != kSimFormatVersion)
    fail(file, "key 'format_version'", "unsupported version " + std::to_string(version) + " (this Drover reads " +
                                           std::to_string(kSimFormatVersion) + ")");
  SimScenarioInfo& s = d.scenario;
  s.generator = jsonValue<std::string>(j, "generator", file);
  s.name = jsonValue<std::string>(j, "scenario", file);
  s.seed = jsonValue<std::uint64_t>(j, "seed", file);
  s.duration_s = jsonValue<double>(j, "duration_s", file);
  s.path_length_m = jsonValue<double>(j, "path_length_m", file);
  s.closes_loop = jsonValue<bool>(j, "closes_loop", file);
  const auto sensors = jsonValue<nlohmann::json>(j, "sensors", file);
  s.has_imu = jsonValue<bool>(sensors, "imu", file);
  s.has_lidar = jsonValue<bool>(sensors, "lidar", file);
  s.has_camera = jsonValue<bool>(sensors, "camera", file);
  s.segments.clear();
  for (const auto& seg : jsonValue<nlohmann::json>(j, "segments", file))
    s.segments.push_back({jsonValue<std::string>(seg, "condition", file), jsonValue<Time>(seg, "start_ns", file),
                          jsonValue<Time>(seg, "end_ns", file)});
  s.faults.clear();
  if (j.contains("faults"))
    for (const auto& f : jsonValue<nlohmann::json>(j, "faults", file))
      s.faults.push_back({jsonValue<std::string>(f, "kind", file), jsonValue<Time>(f, "start_ns", file),
                          jsonValue<Time>(f, "end_ns", file)});
}

// ---- csv indexes -----------------------------------------------------------------------------------------------

// Rows whose stamp does not advance are dropped (as from a real IMU), their warnings appended to `dropped`.
std::vector<ImuSample> readImuCsv(const std::string& path, std::vector<std::string>& dropped) {
  if (!fs::exists(path)) fail(path, "", "IMU file not found");
  std::vector<ImuSample> samples;
  std::size_t columns = 0;
  for (const NumberedLine& line : readDataLines(path, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitOn(line.text, ',');
    if (columns == 0) {
      if (f.size() != 7 && f.size() != 11)
        fail(path, record, "expected 7 or 11 columns, found " + std::to_string(f.size()));
      columns = f.size();
    }
    requireColumns(f, columns, path, record);
    ImuSample s;
    s.t = parseInt64(f[0], path, record);
    const std::vector<double> v = parseDoubles(f, 1, columns - 1, path, record);
    s.omega_imu = Eigen::Vector3d(v[0], v[1], v[2]);
    s.acc_imu = Eigen::Vector3d(v[3], v[4], v[5]);
    if (columns == 11) s.q_world_imu = checkedQuaternion(v[6], v[7], v[8], v[9], path, record);
    if (!samples.empty() && s.t <= samples.back().t) {
      dropped.push_back(staleStampNotice(samples.back().t, s.t, path, record));
      continue;
    }
    samples.push_back(s);
  }
  return samples;
}

struct IndexEntry {
  Time t = 0, t_end = 0;
  std::string path;    // the data file
  std::string record;  // "DIR/lidar/timestamps.csv line N", for errors raised when the file is read
};

// lidar/timestamps.csv (`index,t_start_ns,t_end_ns`) or camera/timestamps.csv (`index,t_ns`).
// Rows whose stamp does not advance are dropped, their warnings appended to `dropped`.
std::vector<IndexEntry> readIndex(const fs::path& folder, bool has_end, const char* extension,
                                  std::vector<std::string>& dropped) {
  const std::string csv = (folder / "timestamps.csv").string();
  if (!fs::exists(csv)) fail(csv, "", "timestamps file not found");
  std::vector<IndexEntry> entries;
  std::size_t listed = 0;  // rows so far, kept or dropped: the index the next row must carry
  for (const NumberedLine& line : readDataLines(csv, "#")) {
    const std::string record = lineRecord(line.number);
    const auto f = splitOn(line.text, ',');
    requireColumns(f, has_end ? 3 : 2, csv, record);
    const std::int64_t index = parseInt64(f[0], csv, record);
    if (index != static_cast<std::int64_t>(listed))
      fail(csv, record, "expected index " + std::to_string(listed) + ", found " + std::to_string(index));
    IndexEntry e;
    e.t = parseInt64(f[1], csv, record);
    e.t_end = has_end ? parseInt64(f[2], csv, record) : e.t;
    if (e.t_end < e.t) fail(csv, record, "sweep ends before it starts");
    e.path = (folder / simFileName(listed++, extension)).string();
    e.record = "listed in " + csv + " " + record;
    if (!entries.empty() && e.t <= entries.back().t) {
      dropped.push_back(staleStampNotice(entries.back().t, e.t, csv, record));
      continue;
    }
    entries.push_back(std::move(e));
  }
  return entries;
}

// ---- payloads --------------------------------------------------------------------------------------------------

LidarScan readScan(const IndexEntry& e, int rings) {
  if (!fs::exists(e.path)) fail(e.path, e.record, "lidar scan file not found");
  const std::string bytes = readTextFile(e.path);
  if (bytes.size() % kSimPointBytes != 0)
    fail(e.path, "", "size " + std::to_string(bytes.size()) + " bytes is not a multiple of the " +
                         std::to_string(kSimPointBytes) + "-byte point record");
  LidarScan scan;
  scan.t = e.t;
  scan.t_end = e.t_end;
  scan.has_time = scan.has_ring = true;
  const std::size_t n = bytes.size() / kSimPointBytes;
  scan.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const char* r = bytes.data() + i * kSimPointBytes;
    LidarPoint p;
    std::uint32_t offset_ns = 0;
    std::memcpy(&p.x, r + 0, 4);
    std::memcpy(&p.y, r + 4, 4);
    std::memcpy(&p.z, r + 8, 4);
    std::memcpy(&p.intensity, r + 12, 4);
    std::memcpy(&offset_ns, r + 16, 4);
    std::memcpy(&p.ring, r + 20, 2);
    const std::string record = "point " + std::to_string(i);
    // A missing return, as a real lidar gives: dropped and counted, not an error.
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity)) {
      ++scan.dropped_nonfinite;
      continue;
    }
    if (static_cast<Time>(offset_ns) > e.t_end - e.t)
      fail(e.path, record, "time offset " + std::to_string(offset_ns) + " ns is beyond the sweep's end");
    if (p.ring >= rings)
      fail(e.path, record, "ring " + std::to_string(p.ring) + " >= " + std::to_string(rings) + " rings");
    p.time_offset = static_cast<float>(static_cast<double>(offset_ns) * 1e-9);
    scan.points.push_back(p);
  }
  return scan;
}

Image readImage(const IndexEntry& e, const CameraIntrinsics& k, int channels) {
  if (!fs::exists(e.path)) fail(e.path, e.record, "image file not found");
  cv::Mat mat = decodeImageFile(e.path);
  if (mat.depth() != CV_8U || mat.channels() != channels || mat.cols != k.width || mat.rows != k.height)
    fail(e.path, "", "image is " + std::to_string(mat.cols) + "x" + std::to_string(mat.rows) + "x" +
                         std::to_string(mat.channels()) + " (8-bit: " + (mat.depth() == CV_8U ? "yes" : "no") +
                         ") but calibration.yaml says 8-bit " + std::to_string(k.width) + "x" +
                         std::to_string(k.height) + "x" + std::to_string(channels));
  if (!mat.isContinuous()) mat = mat.clone();
  Image img;
  img.width = mat.cols;
  img.height = mat.rows;
  img.channels = mat.channels();
  img.data.assign(mat.data, mat.data + mat.total() * mat.elemSize());
  return img;
}

// ---- the reader ------------------------------------------------------------------------------------------------

class SimReader final : public Reader {
 public:
  SimReader(fs::path dir, SimDatasetDescription d, GroundTruth gt, std::vector<ImuSample> imu,
            std::vector<IndexEntry> scans, std::vector<IndexEntry> frames, const std::vector<std::string>& dropped)
      : dir_(std::move(dir)), d_(std::move(d)), gt_(std::move(gt)), imu_(std::move(imu)), scans_(std::move(scans)),
        frames_(std::move(frames)) {
    for (const std::string& notice : dropped) dropMeasurement(notice);
  }

  std::optional<Measurement> next() override {
    constexpr Time kEnd = std::numeric_limits<Time>::max();
    const Time ti = next_imu_ < imu_.size() ? imu_[next_imu_].t : kEnd;
    const Time tl = next_scan_ < scans_.size() ? scans_[next_scan_].t : kEnd;
    const Time tc = next_frame_ < frames_.size() ? frames_[next_frame_].t : kEnd;
    if (ti == kEnd && tl == kEnd && tc == kEnd) return std::nullopt;
    if (ti <= tl && ti <= tc) return imu_[next_imu_++];
    if (tl <= tc) return readScan(scans_[next_scan_++], d_.sensors.lidar_rings);
    const IndexEntry& e = frames_[next_frame_++];
    CameraFrame frame;
    frame.t = e.t;
    frame.image = readImage(e, d_.calibration.camera, d_.sensors.camera_channels);
    frame.source = e.path;
    return frame;
  }
  const Calibration& calibration() const override { return d_.calibration; }
  const GroundTruth& groundTruth() const override { return gt_; }
  std::string describe() const override {
    return "simulated " + d_.scenario.name + " (seed " + std::to_string(d_.scenario.seed) + ", " +
           dir_.filename().string() + ")";
  }

 private:
  fs::path dir_;
  SimDatasetDescription d_;
  GroundTruth gt_;
  std::vector<ImuSample> imu_;
  std::vector<IndexEntry> scans_, frames_;
  std::size_t next_imu_ = 0, next_scan_ = 0, next_frame_ = 0;
};

}  // namespace

SimDatasetDescription readSimDescription(const std::string& dir) {
  if (!fs::is_directory(dir)) fail(dir, "", "not a folder (expected a simulated dataset folder)");
  SimDatasetDescription d;
  readCalibrationYaml(fs::path(dir) / "calibration.yaml", d);
  readScenarioJson(fs::path(dir) / "scenario.json", d);
  return d;
}

std::unique_ptr<Reader> openSimDataset(const std::string& dir, const DatasetOptions& options) {
  fs::path root = fs::absolute(fs::path(dir)).lexically_normal();
  if (root.filename().empty()) root = root.parent_path();
  SimDatasetDescription d = readSimDescription(root.string());
  const std::string gt_path = (root / "groundtruth.txt").string();
  if (!fs::exists(gt_path)) fail(gt_path, "", "ground truth file not found");
  GroundTruth gt{readTum(gt_path), "imu"};
  std::vector<std::string> dropped;  // rows whose stamp does not advance
  std::vector<ImuSample> imu;
  if (options.load_imu) imu = readImuCsv((root / "imu.csv").string(), dropped);
  std::vector<IndexEntry> scans, frames;
  if (options.load_lidar) scans = readIndex(root / "lidar", true, ".bin", dropped);
  if (options.load_images) frames = readIndex(root / "camera", false, ".png", dropped);
  return std::make_unique<SimReader>(root, std::move(d), std::move(gt), std::move(imu), std::move(scans),
                                     std::move(frames), dropped);
}

}  // namespace drover::io
