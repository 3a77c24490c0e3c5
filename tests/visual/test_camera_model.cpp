// Camera models: round trips over the whole image, OpenCV as the independent reference, analytic Jacobians.
#include "visual/camera_model.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

namespace drover::visual {
namespace {

CameraIntrinsics radTan(std::vector<double> coeffs) {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = 460;
  k.fy = 455;
  k.cx = 319.5;
  k.cy = 239.5;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = std::move(coeffs);
  return k;
}
CameraIntrinsics euroc() { return radTan({-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}); }
// Strong barrel distortion with k3 and tangential terms (corners moved by ~80 px; monotonic over the image).
CameraIntrinsics strongRadTan() { return radTan({-0.35, 0.12, 1.5e-3, -1.2e-3, 0.01}); }
// A 230-degree-diagonal fisheye: image corners at theta_d = 2 rad.
CameraIntrinsics fisheye() {
  CameraIntrinsics k = radTan({});
  k.fx = k.fy = 200;
  k.distortion = DistortionModel::kEquidistant;
  k.distortion_coeffs = {-0.013, 0.021, -0.0085, 0.0012};
  return k;
}

double worstRoundTripPx(const CameraModel& camera, int step) {
  double worst = 0;
  for (int v = 0; v < camera.height(); v += step) {
    for (int u = 0; u < camera.width(); u += step) {
      const Eigen::Vector2d pixel(u + 0.25, v - 0.25);
      const auto ray = camera.unproject(pixel);
      EXPECT_TRUE(ray.has_value()) << "pixel " << pixel.transpose();
      if (!ray) continue;
      EXPECT_NEAR(ray->norm(), 1.0, 1e-12);
      const auto back = camera.project(*ray * 3.7);  // any depth along the ray
      EXPECT_TRUE(back.has_value()) << "pixel " << pixel.transpose();
      if (back) worst = std::max(worst, (*back - pixel).norm());
    }
  }
  return worst;
}

TEST(CameraModel, RadTanProjectUnprojectRoundTripsEveryPixelToMicroPixels) {
  EXPECT_LT(worstRoundTripPx(CameraModel(euroc()), 2), 1e-6);
  EXPECT_LT(worstRoundTripPx(CameraModel(strongRadTan()), 2), 1e-6);
}

TEST(CameraModel, EquidistantProjectUnprojectRoundTripsEveryPixelIncludingRaysBeyond90Degrees) {
  const CameraModel camera(fisheye());
  EXPECT_LT(worstRoundTripPx(camera, 2), 1e-6);
  const auto corner = camera.unproject({-0.5, -0.5});
  ASSERT_TRUE(corner.has_value());
  EXPECT_LT(corner->z(), 0.0) << "a corner of this lens sees behind the image plane";
  EXPECT_FALSE(camera.undistort({-0.5, -0.5}).has_value()) << "no pinhole coordinates behind the camera";
}

std::vector<cv::Point3d> pointsInView(const CameraModel& camera, int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, camera.width() - 1), v(0, camera.height() - 1), depth(0.5, 30);
  std::vector<cv::Point3d> points;
  while (static_cast<int>(points.size()) < n) {
    const auto ray = camera.unproject({u(rng), v(rng)});
    if (!ray || ray->z() < 0.05) continue;  // OpenCV's fisheye model divides by z
    const Eigen::Vector3d p = *ray * depth(rng);
    points.emplace_back(p.x(), p.y(), p.z());
  }
  return points;
}

TEST(CameraModel, RadTanMatchesOpenCvProjectPoints) {
  for (const CameraIntrinsics& k : {euroc(), strongRadTan()}) {
    const CameraModel camera(k);
    const std::vector<cv::Point3d> points = pointsInView(camera, 500, 3);
    std::vector<cv::Point2d> reference;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.cameraMatrix(),
                      camera.distortionCoefficients(), reference);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto pixel = camera.project({points[i].x, points[i].y, points[i].z});
      ASSERT_TRUE(pixel.has_value());
      EXPECT_NEAR(pixel->x(), reference[i].x, 1e-8);
      EXPECT_NEAR(pixel->y(), reference[i].y, 1e-8);
    }
  }
}

TEST(CameraModel, EquidistantMatchesOpenCvFisheyeProjectPoints) {
  const CameraModel camera(fisheye());
  const std::vector<cv::Point3d> points = pointsInView(camera, 500, 4);
  std::vector<cv::Point2d> reference;
  cv::fisheye::projectPoints(points, reference, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.cameraMatrix(),
                             camera.distortionCoefficients());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto pixel = camera.project({points[i].x, points[i].y, points[i].z});
    ASSERT_TRUE(pixel.has_value());
    EXPECT_NEAR(pixel->x(), reference[i].x, 1e-8);
    EXPECT_NEAR(pixel->y(), reference[i].y, 1e-8);
  }
}

TEST(CameraModel, UndistortMatchesOpenCvIterativeUndistortPoints) {
  const CameraModel camera(euroc());
  std::vector<cv::Point2d> pixels = {{10, 10}, {600, 30}, {320, 240}, {50, 470}, {630, 470}};
  std::vector<cv::Point2d> reference;
  cv::undistortPoints(pixels, reference, camera.cameraMatrix(), camera.distortionCoefficients(), cv::noArray(),
                      cv::noArray(), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const auto xn = camera.undistort({pixels[i].x, pixels[i].y});
    ASSERT_TRUE(xn.has_value());
    EXPECT_NEAR(xn->x(), reference[i].x, 1e-7);
    EXPECT_NEAR(xn->y(), reference[i].y, 1e-7);
  }
}

TEST(CameraModel, ProjectionJacobianMatchesCentralDifferences) {
  for (const CameraIntrinsics& k : {euroc(), strongRadTan(), fisheye()}) {
    const CameraModel camera(k);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.2, 1.5), Eigen::Vector3d(-1.0, 0.7, 2.0),
                                     Eigen::Vector3d(0, 0, 4), Eigen::Vector3d(0.01, 0.02, 0.5)}) {
      Eigen::Matrix<double, 2, 3> J;
      ASSERT_TRUE(camera.project(p, &J).has_value());
      constexpr double h = 1e-6;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d e = Eigen::Vector3d::Unit(i) * h;
        const Eigen::Vector2d numeric = (*camera.project(p + e) - *camera.project(p - e)) / (2 * h);
        EXPECT_LT((J.col(i) - numeric).norm(), 1e-4 * (1 + numeric.norm())) << "p = " << p.transpose() << " col " << i;
      }
    }
  }
}

TEST(CameraModel, PointsBehindOrFarOutsideThePinholeViewDoNotProject) {
  const CameraModel camera(strongRadTan());
  EXPECT_FALSE(camera.project({0, 0, -1}).has_value());
  EXPECT_FALSE(camera.project({0, 0, 0}).has_value());
  // Far outside the image a rad-tan lens folds back: such a point must not land on a wrong, in-image pixel.
  EXPECT_FALSE(camera.project({50, 0, 1}).has_value());
}

TEST(CameraModel, BadIntrinsicsAreRejectedNamingTheValue) {
  CameraIntrinsics k = euroc();
  k.fx = 0;
  EXPECT_THROW(CameraModel{k}, std::invalid_argument);
  k = euroc();
  k.distortion_coeffs.resize(3);
  EXPECT_NE(validateIntrinsics(k).find("4 or 5"), std::string::npos);
  k = fisheye();
  k.distortion_coeffs.push_back(0);
  EXPECT_THROW(CameraModel{k}, std::invalid_argument);
  k.width = 0;
  EXPECT_NE(validateIntrinsics(k).find("size"), std::string::npos);
}

}  // namespace
}  // namespace drover::visual
