#include "io/kitti_odometry.hpp"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "io/error.hpp"
#include "io/kitti_common.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {

namespace fs = std::filesystem;

namespace {
std::string frameName(std::size_t frame, const char* ext) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06zu.%s", frame, ext);
  return buf;
}

std::string frameRecord(std::size_t frame) { return "frame " + std::to_string(frame); }

// "a/b/", "a/./b" and relative paths -> absolute "/.../a/b", so parent_path() and filename() mean what they say.
std::string normalizedFolder(const std::string& dir) {
  fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.string();
}

void requireFolder(const fs::path& p, const std::string& what) {
  if (!fs::is_directory(p)) fail(p.string(), "", what);
}
}  // namespace

KittiOdometryReader::KittiOdometryReader(const std::string& sequence_dir, const DatasetOptions& options)
    : dir_(normalizedFolder(sequence_dir)), options_(options) {
  if (options_.kitti_camera != 0 && options_.kitti_camera != 2)
    throw std::invalid_argument("kitti_camera must be 0 or 2, got " + std::to_string(options_.kitti_camera));
  const fs::path dir(dir_);
  requireFolder(dir, "KITTI odometry sequence folder not found");
  times_ = readTimesFile((dir / "times.txt").string());
  if (times_.empty()) fail((dir / "times.txt").string(), "", "no frames listed");
  if (options_.kitti_max_frames > 0 && options_.kitti_max_frames < times_.size())
    times_.resize(options_.kitti_max_frames);
  if (options_.load_lidar) requireFolder(dir / "velodyne", "velodyne folder missing (or set load_lidar: false)");
  if (options_.load_images)
    requireFolder(dir / imageFolder(),
                  "image folder missing (or set load_images: false, or choose the other kitti_camera)");
  readCalibration();
  readGroundTruth();
}

void KittiOdometryReader::readCalibration() {
  const KittiCalibFile calib((fs::path(dir_) / "calib.txt").string());
  for (const char* key : {"P0", "P1", "P2", "P3"}) calib.get(key, 12);  // all four are part of the format
  const Eigen::Matrix<double, 3, 4> P = calib.projection34(options_.kitti_camera == 0 ? "P0" : "P2");
  T_cam0_lidar_ = calib.rigid34("Tr");
  // No IMU: the body frame is the lidar.
  calibration_.T_imu_lidar = Eigen::Isometry3d::Identity();
  calibration_.T_imu_cam = T_cam0_lidar_.inverse() * rectifiedCameraOffset(P);
  CameraIntrinsics& cam = calibration_.camera;
  cam.fx = P(0, 0);
  cam.fy = P(1, 1);
  cam.cx = P(0, 2);
  cam.cy = P(1, 2);
  cam.distortion = DistortionModel::kNone;  // KITTI odometry images are rectified
  // Image size is not in calib.txt; the first PNG's header has it (0 x 0 when images are absent).
  const auto [w, h] = pngSize(imagePath(0));
  cam.width = w;
  cam.height = h;
}

void KittiOdometryReader::readGroundTruth() {
  const fs::path dir(dir_);
  // Our layout keeps poses.txt in the sequence; the official one has dataset/poses/NN.txt beside sequences/.
  fs::path poses = dir / "poses.txt";
  if (!fs::exists(poses)) poses = dir.parent_path().parent_path() / "poses" / (dir.filename().string() + ".txt");
  if (!fs::exists(poses)) return;  // sequences 11-21: no ground truth, not an error
  ground_truth_cam0_ = readKitti(poses.string(), (dir / "times.txt").string());
  const Eigen::Isometry3d T_lidar_cam0 = T_cam0_lidar_.inverse();
  ground_truth_.body_frame = "lidar";
  ground_truth_.poses.reserve(ground_truth_cam0_.size());
  for (const auto& p : ground_truth_cam0_)
    ground_truth_.poses.push_back({p.t, T_lidar_cam0 * p.T_world_body * T_cam0_lidar_});
}

std::string KittiOdometryReader::imageFolder() const { return options_.kitti_camera == 0 ? "image_0" : "image_2"; }

std::string KittiOdometryReader::scanPath(std::size_t frame) const {
  return (fs::path(dir_) / "velodyne" / frameName(frame, "bin")).string();
}

std::string KittiOdometryReader::imagePath(std::size_t frame) const {
  return (fs::path(dir_) / imageFolder() / frameName(frame, "png")).string();
}

std::optional<Measurement> KittiOdometryReader::next() {
  while (frame_ < times_.size()) {
    const std::size_t frame = frame_;
    if (!scan_done_ && options_.load_lidar) {
      const std::string path = scanPath(frame);
      if (!fs::exists(path)) fail(path, frameRecord(frame), "velodyne scan listed in times.txt is missing");
      LidarScan scan = readKittiBin(path, times_[frame], times_[frame]);
      scan_done_ = true;
      return scan;
    }
    if (options_.load_images) {
      const std::string path = imagePath(frame);
      if (!fs::exists(path)) fail(path, frameRecord(frame), "image listed in times.txt is missing");
      CameraFrame cam;
      cam.t = times_[frame];
      cam.camera_id = options_.kitti_camera;
      cam.image = readImageFile(path);
      // The calibrated size is image 0's (calib.txt has none); a sequence's images all share it.
      const CameraIntrinsics& k = calibration_.camera;
      if (cam.image.width != k.width || cam.image.height != k.height)
        fail(path, frameRecord(frame),
             "image is " + std::to_string(cam.image.width) + "x" + std::to_string(cam.image.height) +
                 " px, frame 0's is " + std::to_string(k.width) + "x" + std::to_string(k.height));
      cam.source = path;
      ++frame_;
      scan_done_ = false;
      return cam;
    }
    ++frame_;
    scan_done_ = false;
  }
  return std::nullopt;
}

std::string KittiOdometryReader::describe() const {
  return "KITTI odometry " + fs::path(dir_).filename().string() + " (" +
         std::to_string(times_.size()) + " frames, camera " + std::to_string(options_.kitti_camera) + ")";
}

std::unique_ptr<Reader> openKittiOdometry(const std::string& sequence_dir, const DatasetOptions& options) {
  return std::make_unique<KittiOdometryReader>(sequence_dir, options);
}

}  // namespace drover::io
