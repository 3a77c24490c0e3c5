#pragma once
// Pieces shared by the KITTI odometry and KITTI raw readers: velodyne scans, images, "key: values" calib files.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "types/camera.hpp"
#include "types/lidar.hpp"

namespace drover::io {

// A KITTI velodyne .bin: consecutive float32 (x, y, z, reflectance) records, lidar frame, metres.
// Throws IoError naming the file when its size is not a multiple of 16 bytes; points with a NaN/inf value are
// dropped and counted in LidarScan::dropped_nonfinite.
// The scan has no per-point time or ring (has_time = has_ring = false); t and t_end are set from the arguments.
LidarScan readKittiBin(const std::string& path, Time t, Time t_end);
// KITTI raw "extract" scans: ASCII "x y z reflectance" per line. Same checks, errors name the line.
LidarScan readKittiScanText(const std::string& path, Time t, Time t_end);

// An 8-bit PNG/JPEG as mono8 (grey files) or BGR (colour files; BGRA loses alpha). Throws IoError naming
// the file when it is missing, undecodable or not 8-bit.
Image readImageFile(const std::string& path);
// Width and height from a PNG header without decoding the pixels; {0, 0} when the file is absent or no PNG.
std::pair<int, int> pngSize(const std::string& path);

// A calib file of "key: v1 v2 ..." lines (KITTI odometry calib.txt, raw calib_*.txt). Values that are not
// all numbers (e.g. "calib_time: 09-Jan-2012 13:57:47") are kept out of `numbers` and ignored.
class KittiCalibFile {
 public:
  explicit KittiCalibFile(std::string path);
  const std::string& path() const { return path_; }
  bool has(const std::string& key) const { return numbers_.count(key) > 0; }
  // The values of `key`; throws IoError naming the file and key when it is missing or has another count.
  const std::vector<double>& get(const std::string& key, std::size_t count) const;
  // 3x4 (or 3x3) row-major matrix of `key`.
  Eigen::Matrix<double, 3, 4> matrix34(const std::string& key) const;
  Eigen::Matrix3d matrix33(const std::string& key) const;
  // Rigid transform from a 12-value row-major [R | t] (key) or from separate "R:" (9) and "T:" (3) keys.
  // The rotation is checked and orthonormalised (checkedRotation).
  Eigen::Isometry3d rigid34(const std::string& key) const;
  Eigen::Isometry3d rigidRT(const std::string& r_key, const std::string& t_key) const;
  // A camera matrix (3x4 projection or 3x3 K) whose focal lengths (0,0) and (1,1) are checked to be > 0 [px], so
  // that a zeroed P2 is an error naming the key, not a camera that projects everything to one pixel.
  Eigen::Matrix<double, 3, 4> projection34(const std::string& key) const;
  Eigen::Matrix3d intrinsics33(const std::string& key) const;

 private:
  void requireFocalLengths(const std::string& key, double fx, double fy) const;

  std::string path_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::size_t> lines_;  // key -> line number, for error messages
  // Keys whose values are not all numbers ("calib_time: 09-Jan-2012 13:57:47") -> first such value: an error only
  // when a number is asked for, so a malformed "Tr:" is reported as malformed, not missing.
  std::map<std::string, std::string> text_;
};

// The frame in which a rectified projection P = K [I | p/K] projects with K alone: the camera is displaced
// from the reference (rectified cam0) frame by -K^-1 p4 (p4 = P's last column), so
// T_ref_cam = translation(-K^-1 p4). Camera 2 of KITTI sits ~6 cm to the left (-x) of camera 0.
Eigen::Isometry3d rectifiedCameraOffset(const Eigen::Matrix<double, 3, 4>& P);

}  // namespace drover::io
