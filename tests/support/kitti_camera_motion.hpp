#pragma once
// The motion of KITTI camera 2 from frame 0 to frame 9 of a snippet in ../shared, estimated from its images with
// metric depth from the lidar, as an independent check of the reference poses and the lidar odometry (used by
// tests/system/test_kitti_camera_crosscheck.cpp, whose header says why and what it found).
//
// Frames: camera 2, rectified (x right, y down, z forward), K from P2, no distortion. Three estimates:
//  - chained: for each step k -> k+1, Shi-Tomasi corners of image k get depth from scan k by LVI-SAM's ray-plane
//    association (visual::DepthAssociator on that one sweep), are tracked into image k+1 by pyramidal KLT with a
//    forward-backward check, and PnP (EPnP inside RANSAC, then Levenberg-Marquardt on the inliers) gives
//    T_cam(k)_cam(k+1); the nine steps are chained. The point is the pixel's ray times the lidar depth, so an error in
//    the lidar-camera rotation moves which surface point is picked, not the ray.
//  - direct: the frame-0 points tracked through all nine images, one PnP from frame 0 to frame 9. Fewer tracks
//    survive, but nothing is chained: a bias per step (a lidar-camera time offset dt puts every scan's points v * dt
//    off, which the chain adds up nine times and the direct estimate once) would make the two disagree.
//  - rotation: the essential matrix of all tracked corners of each step (five-point RANSAC, then Gauss-Newton on the
//    Sampson distances of all inliers), chained. It uses no depth, so it is the camera's own rotation.
#include <Eigen/Geometry>
#include <algorithm>
#include <climits>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "geometry/so3.hpp"
#include "io/dataset.hpp"
#include "support/shared_data.hpp"
#include "visual/depth_association.hpp"

namespace drover::test {

constexpr int kSnippetFrames = 10;

// Camera 2 and the lidar over a snippet.
struct CameraSnippet {
  std::vector<cv::Mat> grey;                        // the images, 8-bit grey
  std::vector<std::vector<Eigen::Vector3d>> scans;  // scan k in the camera-k frame [m]
  cv::Mat K;                                        // 3x3 CV_64F [px]
  Eigen::Isometry3d T_lidar_cam = Eigen::Isometry3d::Identity();
  Trajectory truth;  // official poses, T_world_lidar
};

inline CameraSnippet loadCameraSnippet(const std::string& sequence) {
  io::DatasetOptions options;
  options.load_imu = false;
  options.kitti_camera = 2;
  options.kitti_max_frames = kSnippetFrames;
  auto reader = io::openDataset(sharedData("kitti/sequences/" + sequence).string(), "kitti", options);
  const Calibration& calibration = reader->calibration();
  const CameraIntrinsics& c = calibration.camera;
  CameraSnippet s;
  s.T_lidar_cam = calibration.T_imu_cam;  // KITTI odometry has no IMU: the body frame is the lidar
  s.K = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  const Eigen::Isometry3d T_cam_lidar = s.T_lidar_cam.inverse();
  while (auto m = reader->next()) {
    if (const auto* scan = std::get_if<LidarScan>(&*m)) {
      std::vector<Eigen::Vector3d> points;
      points.reserve(scan->points.size());
      for (const LidarPoint& p : scan->points) points.push_back(T_cam_lidar * Eigen::Vector3d(p.x, p.y, p.z));
      s.scans.push_back(std::move(points));
    } else if (auto* frame = std::get_if<CameraFrame>(&*m)) {
      Image& image = frame->image;
      const cv::Mat wrapped(image.height, image.width, image.channels == 3 ? CV_8UC3 : CV_8UC1, image.data.data());
      cv::Mat grey;
      if (image.channels == 3)
        cv::cvtColor(wrapped, grey, cv::COLOR_BGR2GRAY);
      else
        grey = wrapped.clone();
      s.grey.push_back(grey);
    }
  }
  s.truth = reader->groundTruth().poses;
  return s;
}

// Up to 8000 corners 5 px apart: the lidar covers only the lower half of the 1241 x 376 image, and more corners
// there mean more points with depth.
inline std::vector<cv::Point2f> corners(const cv::Mat& grey) {
  std::vector<cv::Point2f> out;
  cv::goodFeaturesToTrack(grey, out, 8000, 0.001, 5.0);
  return out;
}

// Pyramidal KLT (21 x 21 px window, 3 levels) from image `from` to image `to`. ok[i] stays true only for a point
// that was found, lies in the image and tracks back to within 0.5 px of where it started.
inline std::vector<cv::Point2f> trackKlt(const cv::Mat& from, const cv::Mat& to, const std::vector<cv::Point2f>& in,
                                         std::vector<bool>& ok) {
  std::vector<cv::Point2f> out, back;
  if (in.empty()) return out;
  std::vector<unsigned char> found, found_back;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(from, to, in, out, found, error, cv::Size(21, 21), 3);
  cv::calcOpticalFlowPyrLK(to, from, out, back, found_back, error, cv::Size(21, 21), 3);
  const cv::Rect2f image(0, 0, static_cast<float>(to.cols), static_cast<float>(to.rows));
  for (std::size_t i = 0; i < in.size(); ++i)
    ok[i] = ok[i] && found[i] && found_back[i] && image.contains(out[i]) && cv::norm(back[i] - in[i]) < 0.5;
  return out;
}

// Corners of image k with depth from scan k: pixels [px] and their points in the camera-k frame [m].
struct DepthFeatures {
  std::vector<cv::Point2f> pixels;
  std::vector<cv::Point3f> points;
};

inline DepthFeatures cornersWithDepth(const CameraSnippet& s, int k) {
  // One full-resolution sweep, so no voxel filter. The spherical grid is finer than LVI-SAM's 0.5 deg (the HDL-64E
  // fires every 0.17 deg in azimuth; its rings are ~0.4 deg apart), and the three neighbours' ranges may spread
  // 0.3 m instead of 2 m: a corner often lies on a depth edge, and a plane that bridges the edge is a wrong depth.
  visual::DepthAssociationConfig config;
  config.voxel_size = 0;
  config.grid_resolution_deg = 0.2;
  config.neighbour_cells = 4;
  config.max_depth_spread = 0.3;  // [m]
  config.min_depth = 2.0;         // [m] nearer is the car's own bonnet
  config.max_depth = 60.0;        // [m]
  visual::DepthAssociator associator(config);
  associator.addSweep(0, s.scans[static_cast<std::size_t>(k)]);
  const std::vector<cv::Point2f> pixels = corners(s.grey[static_cast<std::size_t>(k)]);
  const double fx = s.K.at<double>(0, 0), fy = s.K.at<double>(1, 1);
  const double cx = s.K.at<double>(0, 2), cy = s.K.at<double>(1, 2);
  std::vector<Eigen::Vector2d> normalized;
  for (const cv::Point2f& p : pixels) normalized.emplace_back((p.x - cx) / fx, (p.y - cy) / fy);
  const visual::DepthAssociationResult r = associator.associate(0, Eigen::Isometry3d::Identity(), normalized);
  DepthFeatures out;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (r.features[i].status != visual::DepthStatus::kOk) continue;
    const Eigen::Vector3d p = r.features[i].depth * Eigen::Vector3d(normalized[i].x(), normalized[i].y(), 1);
    out.pixels.push_back(pixels[i]);
    out.points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  return out;
}

struct PnpResult {
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  // camera `to` in the camera-`from` frame
  int tracked = 0, inliers = 0;
};

// PnP from the points (camera-`from` frame) with ok[i] to their pixels in image `to`: EPnP in RANSAC with a 2 px
// threshold, then Levenberg-Marquardt on the inliers.
inline PnpResult solvePnp(const std::vector<cv::Point3f>& points, const std::vector<cv::Point2f>& pixels,
                          const std::vector<bool>& ok, const cv::Mat& K) {
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (ok[i]) {
      object.push_back(points[i]);
      image.push_back(pixels[i]);
    }
  PnpResult result;
  result.tracked = static_cast<int>(object.size());
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  if (object.size() < 6 ||
      !cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false, 2000, 2.0, 0.9999, inliers,
                          cv::SOLVEPNP_EPNP) ||
      inliers.size() < 6)
    return result;
  std::vector<cv::Point3f> object_in;
  std::vector<cv::Point2f> image_in;
  for (int i : inliers) {
    object_in.push_back(object[static_cast<std::size_t>(i)]);
    image_in.push_back(image[static_cast<std::size_t>(i)]);
  }
  cv::solvePnPRefineLM(object_in, image_in, K, cv::noArray(), rvec, tvec);
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d R_to_from;
  Eigen::Vector3d t_to_from;
  cv::cv2eigen(R, R_to_from);
  cv::cv2eigen(tvec, t_to_from);
  Eigen::Isometry3d T_to_from = Eigen::Isometry3d::Identity();
  T_to_from.linear() = R_to_from;
  T_to_from.translation() = t_to_from;
  result.T_from_to = T_to_from.inverse();
  result.inliers = static_cast<int>(inliers.size());
  return result;
}

// Gauss-Newton on the Sampson distances of the inliers over R and the direction of t (x_to = R x_from + t, x in
// normalised coordinates): RANSAC's model fits five points, this one all of them. Without it the chained rotation
// moved by up to 0.2 deg with the RANSAC threshold; with it, by 0.03 deg.
inline void refineRelativePose(const std::vector<Eigen::Vector3d>& x_from, const std::vector<Eigen::Vector3d>& x_to,
                               Eigen::Matrix3d& R, Eigen::Vector3d& t) {
  using Vector5d = Eigen::Matrix<double, 5, 1>;
  const auto residuals = [&](const Eigen::Matrix3d& Rm, const Eigen::Vector3d& tm) {
    const Eigen::Matrix3d E = geometry::hat(tm) * Rm;
    Eigen::VectorXd r(static_cast<Eigen::Index>(x_from.size()));
    for (std::size_t i = 0; i < x_from.size(); ++i) {
      const Eigen::Vector3d Ex = E * x_from[i], Etx = E.transpose() * x_to[i];
      r[static_cast<Eigen::Index>(i)] =
          x_to[i].dot(Ex) / std::sqrt(Ex.head<2>().squaredNorm() + Etx.head<2>().squaredNorm());
    }
    return r;
  };
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::Vector3d b1 = t.unitOrthogonal(), b2 = t.cross(b1);  // t's tangent plane on the unit sphere
    const auto moved = [&](const Vector5d& d) {
      return std::pair<Eigen::Matrix3d, Eigen::Vector3d>(geometry::expSO3(d.head<3>()) * R,
                                                         (t + d[3] * b1 + d[4] * b2).normalized());
    };
    const Eigen::VectorXd r = residuals(R, t);
    Eigen::MatrixXd J(r.size(), 5);
    constexpr double h = 1e-7;
    for (int k = 0; k < 5; ++k) {
      const auto [Rp, tp] = moved(Vector5d::Unit(k) * h);
      const auto [Rm, tm] = moved(-Vector5d::Unit(k) * h);
      J.col(k) = (residuals(Rp, tp) - residuals(Rm, tm)) / (2 * h);
    }
    const Vector5d step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    const auto [R_new, t_new] = moved(step);
    if (!(residuals(R_new, t_new).squaredNorm() < r.squaredNorm())) break;
    R = R_new;
    t = t_new;
  }
}

struct RotationResult {
  Eigen::Matrix3d R_from_to = Eigen::Matrix3d::Identity();
  int inliers = 0;
};

// Rotation between two images from the essential matrix of all tracked corners (RANSAC threshold 0.5 px).
inline RotationResult essentialRotation(const cv::Mat& from, const cv::Mat& to, const cv::Mat& K) {
  const std::vector<cv::Point2f> start = corners(from);
  std::vector<bool> ok(start.size(), true);
  const std::vector<cv::Point2f> end = trackKlt(from, to, start, ok);
  std::vector<cv::Point2f> p, q;
  for (std::size_t i = 0; i < start.size(); ++i)
    if (ok[i]) {
      p.push_back(start[i]);
      q.push_back(end[i]);
    }
  RotationResult result;
  if (p.size() < 8) return result;
  cv::Mat mask, R, t;
  const cv::Mat E = cv::findEssentialMat(p, q, K, cv::RANSAC, 0.9999, 0.5, mask);
  // Several stacked solutions mean a degenerate set.
  if (E.rows != 3) return result;
  result.inliers = cv::recoverPose(E, p, q, K, R, t, mask);  // x_to = R x_from + t
  Eigen::Matrix3d R_to_from, K_inverse;
  Eigen::Vector3d t_to_from;
  cv::cv2eigen(R, R_to_from);
  cv::cv2eigen(t, t_to_from);
  cv::cv2eigen(K, K_inverse);
  K_inverse = K_inverse.inverse().eval();
  std::vector<Eigen::Vector3d> x_from, x_to;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (mask.at<unsigned char>(static_cast<int>(i))) {
      x_from.push_back(K_inverse * Eigen::Vector3d(p[i].x, p[i].y, 1));
      x_to.push_back(K_inverse * Eigen::Vector3d(q[i].x, q[i].y, 1));
    }
  refineRelativePose(x_from, x_to, R_to_from, t_to_from);
  result.R_from_to = R_to_from.transpose();
  return result;
}

// The camera's estimates of the motion from frame 0 to frame 9, camera-2 frame.
struct CameraMotion {
  Eigen::Isometry3d chained = Eigen::Isometry3d::Identity();  // T_cam0_cam9 from nine PnP steps
  Eigen::Isometry3d direct = Eigen::Isometry3d::Identity();   // T_cam0_cam9 from one PnP, frame-0 points in image 9
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();     // R_cam0_cam9 from nine essential matrices
  double travelled = 0;                                       // [m] sum of the chained steps' lengths
  int fewest_depth_features = INT_MAX, fewest_step_inliers = INT_MAX;  // over the nine steps
  int fewest_essential_inliers = INT_MAX;
  int direct_tracked = 0, direct_inliers = 0;
};

inline CameraMotion estimateCameraMotion(const CameraSnippet& s) {
  CameraMotion m;
  const DepthFeatures first = cornersWithDepth(s, 0);
  std::vector<cv::Point2f> first_now = first.pixels;  // where the frame-0 points are in the current image
  std::vector<bool> first_ok(first.pixels.size(), true);
  for (int k = 0; k + 1 < kSnippetFrames; ++k) {
    const cv::Mat& image = s.grey[static_cast<std::size_t>(k)];
    const cv::Mat& next_image = s.grey[static_cast<std::size_t>(k) + 1];
    const DepthFeatures f = k == 0 ? first : cornersWithDepth(s, k);
    std::vector<bool> ok(f.pixels.size(), true);
    const PnpResult step = solvePnp(f.points, trackKlt(image, next_image, f.pixels, ok), ok, s.K);
    m.chained = m.chained * step.T_from_to;
    m.travelled += step.T_from_to.translation().norm();
    m.fewest_depth_features = std::min(m.fewest_depth_features, static_cast<int>(f.pixels.size()));
    m.fewest_step_inliers = std::min(m.fewest_step_inliers, step.inliers);
    first_now = trackKlt(image, next_image, first_now, first_ok);
    const RotationResult rotation = essentialRotation(image, next_image, s.K);
    m.rotation = m.rotation * rotation.R_from_to;
    m.fewest_essential_inliers = std::min(m.fewest_essential_inliers, rotation.inliers);
  }
  const PnpResult direct = solvePnp(first.points, first_now, first_ok, s.K);
  m.direct = direct.T_from_to;
  m.direct_tracked = direct.tracked;
  m.direct_inliers = direct.inliers;
  return m;
}

}  // namespace drover::test
