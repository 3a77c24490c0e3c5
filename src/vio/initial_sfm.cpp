#include "vio/initial_sfm.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/SVD>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <stdexcept>

#include "vio/solver_log.hpp"

namespace drover::vio {

namespace {

std::string fmt1(double value) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << value;
  return out.str();
}

// Features seen in both frames, in id order.
void correspondences(const FrameFeatures& a, const FrameFeatures& b, std::vector<Eigen::Vector2d>& xa,
                     std::vector<Eigen::Vector2d>& xb) {
  xa.clear();
  xb.clear();
  for (const auto& [id, x] : a) {
    const auto it = b.find(id);
    if (it == b.end()) continue;
    xa.push_back(x);
    xb.push_back(it->second);
  }
}

std::vector<cv::Point2d> toCv(const std::vector<Eigen::Vector2d>& x) {
  std::vector<cv::Point2d> out;
  out.reserve(x.size());
  for (const auto& p : x) out.emplace_back(p.x(), p.y());
  return out;
}

// Reprojection residual in normalised coordinates scaled by the focal length (pixels), camera pose as
// T_cam_world = (q, t): x = pi(q p + t). Autodiff: the adjustment runs once per initialisation.
struct ReprojectionError {
  ReprojectionError(const Eigen::Vector2d& x, double focal) : x_(x), focal_(focal) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cw(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cw(t), p_w(p);
    const Eigen::Matrix<T, 3, 1> p_c = q_cw * p_w + t_cw;
    residual[0] = T(focal_) * (p_c.x() / p_c.z() - T(x_.x()));
    residual[1] = T(focal_) * (p_c.y() / p_c.z() - T(x_.y()));
    return true;
  }
  Eigen::Vector2d x_;
  double focal_;
};

// The incremental reconstruction, VINS-Mono GlobalSFM::construct, with poses kept as T_cam_world (world = c_l).
class Reconstruction {
 public:
  Reconstruction(const std::vector<FrameFeatures>& frames, const SfmConfig& config)
      : frames_(frames), config_(config), T_cw_(frames.size()) {}

  bool run(int l, const Eigen::Isometry3d& T_l_last, SfmResult& result) {
    const int last = static_cast<int>(frames_.size()) - 1;
    setPose(l, Eigen::Isometry3d::Identity());
    setPose(last, T_l_last.inverse());
    for (int i = l; i < last; ++i) {
      if (i > l && !pnp(i, T_cw_[i - 1], result.why)) return false;
      triangulateTwo(i, last);
    }
    for (int i = l + 1; i < last; ++i) triangulateTwo(l, i);
    for (int i = l - 1; i >= 0; --i) {
      if (!pnp(i, T_cw_[i + 1], result.why)) return false;
      triangulateTwo(i, l);
    }
    triangulateRemaining();
    if (!adjust(l, last, result)) return false;
    for (const auto& T : T_cw_) result.T_l_cam.push_back(T.inverse());
    result.points_l = points_;
    return true;
  }

 private:
  void setPose(int k, const Eigen::Isometry3d& T_cw) { T_cw_[k] = T_cw; }

  void triangulateTwo(int i, int j) {
    for (const auto& [id, xi] : frames_[i]) {
      if (points_.count(id)) continue;
      const auto it = frames_[j].find(id);
      if (it == frames_[j].end()) continue;
      Eigen::Vector3d p;
      if (triangulatePoint(T_cw_[i], T_cw_[j], xi, it->second, p)) points_[id] = p;
    }
  }

  // Features with two or more observations in posed frames: first and last observation (VINS-Mono step 5).
  void triangulateRemaining() {
    std::map<std::uint64_t, std::pair<int, int>> span;
    for (int k = 0; k < static_cast<int>(frames_.size()); ++k) {
      for (const auto& [id, x] : frames_[k]) {
        (void)x;
        auto [it, inserted] = span.emplace(id, std::make_pair(k, k));
        if (!inserted) it->second.second = k;
      }
    }
    for (const auto& [id, s] : span) {
      if (points_.count(id) || s.first == s.second) continue;
      Eigen::Vector3d p;
      if (triangulatePoint(T_cw_[s.first], T_cw_[s.second], frames_[s.first].at(id), frames_[s.second].at(id), p)) {
        points_[id] = p;
      }
    }
  }

  bool pnp(int k, const Eigen::Isometry3d& T_init, std::string& why) {
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> image;
    for (const auto& [id, x] : frames_[k]) {
      const auto it = points_.find(id);
      if (it == points_.end()) continue;
      object.emplace_back(it->second.x(), it->second.y(), it->second.z());
      image.emplace_back(x.x(), x.y());
    }
    if (static_cast<int>(object.size()) < config_.min_pnp_points) {
      why = "sfm: frame " + std::to_string(k) + " sees " + std::to_string(object.size()) +
            " triangulated features < " + std::to_string(config_.min_pnp_points) + " needed for PnP";
      return false;
    }
    cv::Mat R_cv, rvec, tvec;
    cv::eigen2cv(Eigen::Matrix3d(T_init.linear()), R_cv);
    cv::Rodrigues(R_cv, rvec);
    cv::eigen2cv(Eigen::Vector3d(T_init.translation()), tvec);
    const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
    if (!cv::solvePnP(object, image, K, cv::Mat(), rvec, tvec, true)) {
      why = "sfm: PnP failed for frame " + std::to_string(k);
      return false;
    }
    cv::Rodrigues(rvec, R_cv);
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    cv::cv2eigen(R_cv, R);
    cv::cv2eigen(tvec, t);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = t;
    setPose(k, T);
    return true;
  }

  bool adjust(int l, int last, SfmResult& result) {
    const std::size_t n = frames_.size();
    std::vector<Eigen::Quaterniond> q(n);
    std::vector<Eigen::Vector3d> t(n);
    ceres::Problem problem;
    for (std::size_t k = 0; k < n; ++k) {
      q[k] = Eigen::Quaterniond(T_cw_[k].linear());
      t[k] = T_cw_[k].translation();
      problem.AddParameterBlock(q[k].coeffs().data(), 4, new ceres::EigenQuaternionManifold);
      problem.AddParameterBlock(t[k].data(), 3);
    }
    int observations = 0;
    for (std::size_t k = 0; k < n; ++k) {
      for (const auto& [id, x] : frames_[k]) {
        const auto it = points_.find(id);
        if (it == points_.end()) continue;
        auto* cost = new ceres::AutoDiffCostFunction<ReprojectionError, 2, 4, 3, 3>(
            new ReprojectionError(x, config_.focal_px));
        problem.AddResidualBlock(cost, nullptr, q[k].coeffs().data(), t[k].data(), it->second.data());
        ++observations;
      }
    }
    // Gauge: c_l is the world, and the l <-> last baseline fixes the scale (VINS-Mono fixes the same blocks).
    problem.SetParameterBlockConstant(q[l].coeffs().data());
    problem.SetParameterBlockConstant(t[l].data());
    problem.SetParameterBlockConstant(t[last].data());
    quietSolverWarnings();
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_SCHUR;
    options.max_num_iterations = 100;
    options.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    result.reprojection_px = observations > 0 ? std::sqrt(2.0 * summary.final_cost / observations) : 0;
    if (summary.termination_type == ceres::FAILURE || !std::isfinite(summary.final_cost)) {
      result.why = "sfm: bundle adjustment failed: " + summary.message;
      return false;
    }
    if (result.reprojection_px > config_.max_reprojection_px) {
      result.why = "sfm: reprojection error after bundle adjustment " + fmt1(result.reprojection_px) + " px > " +
                   fmt1(config_.max_reprojection_px) + " px";
      return false;
    }
    for (std::size_t k = 0; k < n; ++k) {
      T_cw_[k].linear() = q[k].normalized().toRotationMatrix();
      T_cw_[k].translation() = t[k];
    }
    return true;
  }

  const std::vector<FrameFeatures>& frames_;
  const SfmConfig& config_;
  std::vector<Eigen::Isometry3d> T_cw_;  // camera k from c_l
  std::map<std::uint64_t, Eigen::Vector3d> points_;  // in c_l
};

}  // namespace

std::string SfmConfig::validate() const {
  std::ostringstream out;
  if (!(focal_px > 0) || !std::isfinite(focal_px)) out << "focal_px = " << focal_px << " must be > 0; ";
  if (!(min_parallax_px >= 0)) out << "min_parallax_px = " << min_parallax_px << " must be >= 0; ";
  if (!(min_translation_parallax_px >= 0)) {
    out << "min_translation_parallax_px = " << min_translation_parallax_px << " must be >= 0; ";
  }
  if (min_correspondences < 5) out << "min_correspondences = " << min_correspondences << " must be >= 5; ";
  if (min_essential_inliers < 5) out << "min_essential_inliers = " << min_essential_inliers << " must be >= 5; ";
  if (!(ransac_threshold_px > 0)) out << "ransac_threshold_px = " << ransac_threshold_px << " must be > 0; ";
  if (min_pnp_points < 6) out << "min_pnp_points = " << min_pnp_points << " must be >= 6; ";
  if (!(max_reprojection_px > 0)) out << "max_reprojection_px = " << max_reprojection_px << " must be > 0; ";
  return out.str();
}

double meanParallaxPx(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double focal_px) {
  if (a.empty()) return 0;
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).norm();
  return focal_px * sum / static_cast<double>(a.size());
}

double rotationCompensatedParallaxPx(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                                     double focal_px) {
  if (a.size() < 3) return 0;
  // Kabsch: R = argmin sum |f_b - R f_a|^2 over unit bearings.
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) H += b[i].homogeneous().normalized() * a[i].homogeneous().normalized().transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  std::vector<Eigen::Vector2d> rotated;
  rotated.reserve(a.size());
  for (const auto& x : a) {
    const Eigen::Vector3d r = R * x.homogeneous();
    rotated.push_back(r.z() > 1e-9 ? Eigen::Vector2d(r.hnormalized()) : Eigen::Vector2d(1e3, 1e3));
  }
  return meanParallaxPx(rotated, b, focal_px);
}

bool relativePose(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                  const SfmConfig& config, Eigen::Isometry3d& T_a_b, std::string& why) {
  if (static_cast<int>(a.size()) <= config.min_correspondences) {
    why = "relative pose: " + std::to_string(a.size()) + " correspondences <= " +
          std::to_string(config.min_correspondences);
    return false;
  }
  const std::vector<cv::Point2d> pa = toCv(a), pb = toCv(b);
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  cv::Mat mask;
  // Five-point RANSAC on normalised coordinates (VINS-Mono solve_5pts.cpp: threshold 0.3 / 460, p = 0.99).
  const cv::Mat E = cv::findEssentialMat(pa, pb, K, cv::RANSAC, 0.99, config.ransac_threshold_px / config.focal_px, mask);
  if (E.rows != 3 || E.cols != 3) {
    why = "relative pose: no essential matrix from " + std::to_string(a.size()) + " correspondences";
    return false;
  }
  cv::Mat R_cv, t_cv;
  const int inliers = cv::recoverPose(E, pa, pb, K, R_cv, t_cv, mask);
  if (inliers <= config.min_essential_inliers) {
    why = "relative pose: " + std::to_string(inliers) + " essential-matrix inliers <= " +
          std::to_string(config.min_essential_inliers);
    return false;
  }
  // recoverPose: x_b = R x_a + t, i.e. T_b_a = [R | t]; we return its inverse, the pose of b in a.
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(t_cv, t);
  T_a_b = Eigen::Isometry3d::Identity();
  T_a_b.linear() = R.transpose();
  T_a_b.translation() = -R.transpose() * t.normalized();
  return true;
}

bool triangulatePoint(const Eigen::Isometry3d& T_c0_w, const Eigen::Isometry3d& T_c1_w, const Eigen::Vector2d& x0,
                      const Eigen::Vector2d& x1, Eigen::Vector3d& p_w) {
  // DLT (Hartley & Zisserman Sec. 12.2): x cross (P X) = 0, two rows per view.
  const Eigen::Matrix<double, 3, 4> P0 = T_c0_w.matrix().topRows<3>(), P1 = T_c1_w.matrix().topRows<3>();
  Eigen::Matrix4d A;
  A.row(0) = x0.x() * P0.row(2) - P0.row(0);
  A.row(1) = x0.y() * P0.row(2) - P0.row(1);
  A.row(2) = x1.x() * P1.row(2) - P1.row(0);
  A.row(3) = x1.y() * P1.row(2) - P1.row(1);
  const Eigen::Vector4d X = Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return false;
  p_w = X.hnormalized();
  return p_w.allFinite() && (T_c0_w * p_w).z() > 0 && (T_c1_w * p_w).z() > 0;
}

SfmResult globalSfm(const std::vector<FrameFeatures>& frames, const SfmConfig& config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("SfmConfig: " + error);
  SfmResult result;
  if (frames.size() < 3) {
    result.why = "sfm: " + std::to_string(frames.size()) + " frames < 3";
    return result;
  }
  const int last = static_cast<int>(frames.size()) - 1;
  // Frame l: the oldest frame with enough correspondences, parallax and a relative pose to the last frame
  // (VINS-Mono Estimator::relativePose). `why` keeps the best reason seen, to say what was missing.
  std::vector<Eigen::Vector2d> xa, xb;
  std::string why = "sfm: no frame has more than " + std::to_string(config.min_correspondences) +
                    " features in common with the last frame (too few features)";
  int stage = 0;  // how far the best candidate got: 1 parallax, 2 rotation-compensated parallax, 3 relative pose
  double best_parallax = -1;
  const auto refuse = [&](int at, const std::string& reason) {
    if (at >= stage) why = reason;
    stage = std::max(stage, at);
  };
  for (int i = 0; i < last; ++i) {
    correspondences(frames[i], frames[last], xa, xb);
    if (static_cast<int>(xa.size()) <= config.min_correspondences) continue;
    const double parallax = meanParallaxPx(xa, xb, config.focal_px);
    if (parallax <= config.min_parallax_px) {
      if (parallax > best_parallax) {
        refuse(1, "waiting: parallax " + fmt1(parallax) + " px < " + fmt1(config.min_parallax_px) +
                      " px over the window (need motion)");
      }
      best_parallax = std::max(best_parallax, parallax);
      continue;
    }
    const double translation_parallax = rotationCompensatedParallaxPx(xa, xb, config.focal_px);
    if (translation_parallax <= config.min_translation_parallax_px) {
      refuse(2, "waiting: parallax after removing rotation " + fmt1(translation_parallax) + " px < " +
                    fmt1(config.min_translation_parallax_px) + " px (rotation without translation)");
      continue;
    }
    Eigen::Isometry3d T_l_last;
    std::string pose_why;
    if (!relativePose(xa, xb, config, T_l_last, pose_why)) {
      refuse(3, pose_why);
      continue;
    }
    result.l = i;
    result.raw_parallax_px = parallax;
    result.translation_parallax_px = translation_parallax;
    Reconstruction reconstruction(frames, config);
    if (!reconstruction.run(i, T_l_last, result)) return result;
    result.ok = true;
    result.why.clear();
    return result;
  }
  result.why = why;
  return result;
}

}  // namespace drover::vio
