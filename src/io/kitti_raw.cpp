#include "io/kitti_raw.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "io/error.hpp"
#include "io/kitti_common.hpp"
#include "io/kitti_oxts.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {

namespace fs = std::filesystem;

namespace {
std::string frameRecord(std::size_t i) { return "frame " + std::to_string(i); }

std::string numberedFile(std::size_t i, const std::string& ext) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%010zu.", i);
  return buf + ext;
}

std::size_t countFiles(const fs::path& dir, const std::string& ext) {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && e.path().extension() == "." + ext) ++n;
  return n;
}

// KITTI ships the calibration in the date folder; a copy inside the drive folder wins.
std::string findCalib(const fs::path& drive, const std::string& name) {
  if (fs::exists(drive / name)) return (drive / name).string();
  const fs::path p = drive.parent_path() / name;
  if (!fs::exists(p))
    fail((drive / name).string(), "", "calibration file not found, neither here nor in the parent folder " +
                                          drive.parent_path().string());
  return p.string();
}

std::string normalizedFolder(const std::string& dir) {
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.string();
}
}  // namespace

std::string KittiRawReader::FileStream::path(std::size_t i) const {
  return (fs::path(data_dir) / numberedFile(i, ext)).string();
}

KittiRawReader::KittiRawReader(const std::string& drive_dir, const DatasetOptions& options)
    : dir_(normalizedFolder(drive_dir)), options_(options) {
  if (options_.kitti_camera != 0 && options_.kitti_camera != 2)
    throw std::invalid_argument("kitti_camera must be 0 or 2, got " + std::to_string(options_.kitti_camera));
  const fs::path dir(dir_);
  if (!fs::is_directory(dir)) fail(dir_, "", "KITTI raw drive folder not found");
  const fs::path velo_data = dir / "velodyne_points" / "data";
  if (countFiles(velo_data, "bin") > 0)
    sync_ = true;
  else if (countFiles(velo_data, "txt") > 0)
    sync_ = false;
  else
    sync_ = dir.filename().string().find("_extract") == std::string::npos;
  readCalibration(dir_);
  readOxts(dir_);
  if (options_.load_lidar) {
    scans_ = indexStream("velodyne_points", sync_ ? "bin" : "txt", true);
    scans_.enabled = true;
  }
  if (options_.load_images) {
    images_ = indexStream(options_.kitti_camera == 0 ? "image_00" : "image_02", "png", false);
    images_.enabled = true;
  }
}

void KittiRawReader::readCalibration(const std::string& drive_dir) {
  const fs::path drive(drive_dir);
  const KittiCalibFile imu_to_velo(findCalib(drive, "calib_imu_to_velo.txt"));
  const KittiCalibFile velo_to_cam(findCalib(drive, "calib_velo_to_cam.txt"));
  const KittiCalibFile cam_to_cam(findCalib(drive, "calib_cam_to_cam.txt"));
  const Eigen::Isometry3d T_velo_imu = imu_to_velo.rigidRT("R", "T");
  const Eigen::Isometry3d T_cam0_velo = velo_to_cam.rigidRT("R", "T");
  const Eigen::Isometry3d T_imu_cam0 = T_velo_imu.inverse() * T_cam0_velo.inverse();
  calibration_.T_imu_lidar = T_velo_imu.inverse();
  const std::string x = options_.kitti_camera == 0 ? "00" : "02";
  CameraIntrinsics& cam = calibration_.camera;
  std::string size_key;
  if (sync_) {
    // Rectified reference frame: X_rect0 = R_rect_00 X_cam0; rectified camera x is offset by K^-1 P(:,3).
    Eigen::Isometry3d T_rect0_cam0 = Eigen::Isometry3d::Identity();
    T_rect0_cam0.linear() = checkedRotation(cam_to_cam.matrix33("R_rect_00"), cam_to_cam.path(), "key 'R_rect_00'");
    const Eigen::Matrix<double, 3, 4> P = cam_to_cam.projection34("P_rect_" + x);
    calibration_.T_imu_cam = T_imu_cam0 * T_rect0_cam0.inverse() * rectifiedCameraOffset(P);
    cam.fx = P(0, 0), cam.fy = P(1, 1), cam.cx = P(0, 2), cam.cy = P(1, 2);
    cam.distortion = DistortionModel::kNone;
    size_key = "S_rect_" + x;
  } else {
    const Eigen::Isometry3d T_camx_cam0 = cam_to_cam.rigidRT("R_" + x, "T_" + x);
    calibration_.T_imu_cam = T_imu_cam0 * T_camx_cam0.inverse();
    const Eigen::Matrix3d K = cam_to_cam.intrinsics33("K_" + x);
    cam.fx = K(0, 0), cam.fy = K(1, 1), cam.cx = K(0, 2), cam.cy = K(1, 2);
    cam.distortion = DistortionModel::kRadialTangential;
    cam.distortion_coeffs = cam_to_cam.get("D_" + x, 5);  // k1 k2 p1 p2 k3
    size_key = "S_" + x;
  }
  if (cam_to_cam.has(size_key)) {
    const auto& s = cam_to_cam.get(size_key, 2);
    for (double v : s)
      if (!(v >= 1 && v <= 100000 && v == std::floor(v)))
        fail(cam_to_cam.path(), "key '" + size_key + "'", "expected a width and a height in whole pixels, got " +
                                                              formatDouble(s[0]) + " " + formatDouble(s[1]));
    cam.width = static_cast<int>(s[0]);
    cam.height = static_cast<int>(s[1]);
  }
}

void KittiRawReader::readOxts(const std::string& drive_dir) {
  const fs::path oxts = fs::path(drive_dir) / "oxts";
  if (!fs::is_directory(oxts)) {
    if (options_.load_imu) fail(oxts.string(), "", "oxts folder missing (or set load_imu: false)");
    return;  // no IMU wanted and no ground truth available
  }
  const std::string stamps = (oxts / "timestamps.txt").string();
  const std::vector<Time> times = readKittiTimestampsAsListed(stamps);
  const std::size_t files = countFiles(oxts / "data", "txt");
  if (files != times.size())
    fail(stamps, "", "has " + std::to_string(times.size()) + " timestamps but " + (oxts / "data").string() + " has " +
                         std::to_string(files) + " .txt files");
  std::vector<OxtsRecord> records;
  std::vector<Time> kept;  // the records' stamps, strictly increasing
  records.reserve(times.size());
  for (std::size_t i = 0; i < times.size(); ++i) {
    const fs::path p = oxts / "data" / numberedFile(i, "txt");
    if (!fs::exists(p)) fail(p.string(), frameRecord(i), "oxts record listed in timestamps.txt is missing");
    OxtsRecord record = readOxtsFile(p.string());
    if (!kept.empty() && times[i] <= kept.back()) {
      dropMeasurement(staleStampNotice(kept.back(), times[i], stamps, frameRecord(i)));
      continue;
    }
    records.push_back(record);
    kept.push_back(times[i]);
  }
  ground_truth_.poses = oxtsToPoses(records, kept);
  ground_truth_.body_frame = "imu";
  if (options_.load_imu) {
    imu_.reserve(records.size());
    for (std::size_t i = 0; i < records.size(); ++i) imu_.push_back(oxtsToImu(records[i], kept[i]));
  }
}

KittiRawReader::FileStream KittiRawReader::indexStream(const std::string& folder, const std::string& ext,
                                                       bool with_start_end) const {
  const fs::path base = fs::path(dir_) / folder;
  FileStream s;
  s.data_dir = (base / "data").string();
  s.ext = ext;
  const std::string stamps = (base / "timestamps.txt").string();
  s.stamps = stamps;
  s.t = readKittiTimestampsAsListed(stamps);
  s.t_end = s.t;
  if (with_start_end && fs::exists(base / "timestamps_start.txt")) {
    const std::string start_path = (base / "timestamps_start.txt").string();
    const std::string end_path = (base / "timestamps_end.txt").string();
    s.stamps = start_path;
    s.t = readKittiTimestampsAsListed(start_path);
    s.t_end = readKittiTimestampsAsListed(end_path);
    if (s.t.size() != s.t_end.size())
      fail(end_path, "", "has " + std::to_string(s.t_end.size()) + " timestamps but timestamps_start.txt has " +
                             std::to_string(s.t.size()));
    for (std::size_t i = 0; i < s.t.size(); ++i)
      if (s.t_end[i] < s.t[i]) fail(end_path, lineRecord(i + 1), "sweep ends before it starts");
  }
  const std::size_t files = countFiles(s.data_dir, ext);
  if (files != s.t.size())
    fail(stamps, "", "has " + std::to_string(s.t.size()) + " timestamps but " + s.data_dir + " has " +
                         std::to_string(files) + " ." + ext + " files");
  return s;
}

LidarScan KittiRawReader::loadScan() {
  const std::size_t i = scans_.next;
  const std::string path = scans_.path(i);
  if (!fs::exists(path)) fail(path, frameRecord(i), "velodyne scan listed in timestamps.txt is missing");
  LidarScan scan = sync_ ? readKittiBin(path, scans_.t[i], scans_.t_end[i])
                         : readKittiScanText(path, scans_.t[i], scans_.t_end[i]);
  scans_.last = scans_.t[i];
  ++scans_.next;
  return scan;
}

CameraFrame KittiRawReader::loadImage() {
  const std::size_t i = images_.next;
  const std::string path = images_.path(i);
  if (!fs::exists(path)) fail(path, frameRecord(i), "image listed in timestamps.txt is missing");
  CameraFrame frame;
  frame.t = images_.t[i];
  frame.camera_id = options_.kitti_camera;
  frame.image = readImageFile(path);
  frame.source = path;
  images_.last = images_.t[i];
  ++images_.next;
  return frame;
}

void KittiRawReader::skipStale(FileStream& stream) {
  for (; stream.hasNext() && stream.last && stream.t[stream.next] <= *stream.last; ++stream.next)
    dropMeasurement(staleStampNotice(*stream.last, stream.t[stream.next], stream.stamps, frameRecord(stream.next)));
}

std::optional<Measurement> KittiRawReader::next() {
  skipStale(scans_);
  skipStale(images_);
  // Earliest of the three streams; at equal stamps IMU before lidar before camera.
  const bool has_imu = next_imu_ < imu_.size();
  const bool has_scan = scans_.hasNext();
  const bool has_image = images_.hasNext();
  const Time t_imu = has_imu ? imu_[next_imu_].t : 0;
  const Time t_scan = has_scan ? scans_.t[scans_.next] : 0;
  const Time t_image = has_image ? images_.t[images_.next] : 0;
  if (has_imu && (!has_scan || t_imu <= t_scan) && (!has_image || t_imu <= t_image)) return imu_[next_imu_++];
  if (has_scan && (!has_image || t_scan <= t_image)) return loadScan();
  if (has_image) return loadImage();
  return std::nullopt;
}

std::string KittiRawReader::describe() const {
  return "KITTI raw " + fs::path(dir_).filename().string() + (sync_ ? " (sync" : " (extract") + ", " +
         std::to_string(imu_.size()) + " oxts, " + std::to_string(scans_.t.size()) + " scans, " +
         std::to_string(images_.t.size()) + " images)";
}

std::unique_ptr<Reader> openKittiRaw(const std::string& drive_dir, const DatasetOptions& options) {
  return std::make_unique<KittiRawReader>(drive_dir, options);
}

}  // namespace drover::io
