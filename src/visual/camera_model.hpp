#pragma once
// Camera models of the visual front end: pinhole with radial-tangential distortion (OpenCV/Kalibr "radtan") and
// equidistant fisheye (Kannala-Brandt as cv::fisheye and Kalibr "equidistant"), built from the CameraIntrinsics the
// dataset readers fill. The distortion maths is shared with the simulator (types/camera_distortion.hpp).
//
// Pixel convention (as OpenCV / Kalibr): integer pixel coordinates are pixel centres. Camera frame: z forward,
// x right, y down. "Normalised coordinates" are the undistorted pinhole coordinates (x / z, y / z).
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "types/calibration.hpp"

namespace drover::visual {

// Empty when the intrinsics describe a camera this module can use, else names the bad value: positive size and
// focal lengths, finite principal point, rad-tan with 4 or 5 coefficients, equidistant with 4, none with 0.
std::string validateIntrinsics(const CameraIntrinsics& intrinsics);

class CameraModel {
 public:
  // Throws std::invalid_argument naming the bad value when validateIntrinsics() fails.
  explicit CameraModel(const CameraIntrinsics& intrinsics);

  // Pixel [px] of a camera-frame point [m]; J_pixel_point, when given, receives d pixel / d p_cam (2x3).
  // Nothing when the point is not representable: pinhole: z <= 1e-9 m or beyond the radius where the image ends
  // (with margin; radial-tangential models fold beyond it); fisheye: angle from the axis >= the model's limit.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_cam,
                                         Eigen::Matrix<double, 2, 3>* J_pixel_point = nullptr) const;
  // Unit ray in the camera frame through `pixel` [px], undistorted to < 1e-9 px. Nothing when the model cannot be
  // inverted there.
  std::optional<Eigen::Vector3d> unproject(const Eigen::Vector2d& pixel) const;
  // Normalised coordinates (x / z, y / z) of the ray through `pixel`; nothing when unproject() fails or the ray
  // does not point forward (z <= 1e-9, possible for a fisheye).
  std::optional<Eigen::Vector2d> undistort(const Eigen::Vector2d& pixel) const;
  // undistort() for many points; a point that cannot be undistorted becomes (NaN, NaN).
  std::vector<cv::Point2f> undistortPoints(const std::vector<cv::Point2f>& pixels) const;

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }
  // OpenCV's K (3x3, CV_64F) and distortion vector (rad-tan k1 k2 p1 p2 [k3]; fisheye k1..k4), for cross-checks.
  cv::Mat cameraMatrix() const;
  cv::Mat distortionCoefficients() const;

 private:
  CameraIntrinsics intrinsics_;
  double max_r2_ = 0;         // pinhole: largest |xn|^2 project() accepts (image corners' radius with margin)
  double max_theta_ = 0;      // fisheye: largest angle from the optical axis project() accepts [rad]
  double tolerance_ = 1e-12;  // Newton tolerance on normalised coordinates (1e-9 px / focal length)
};

}  // namespace drover::visual
