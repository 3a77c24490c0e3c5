#include "eval/umeyama.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace drover::eval {

namespace {

// Umeyama on n point pairs given by accessors x(i), y(i) (so matched trajectories need no copies).
template <typename X, typename Y>
Sim3 umeyamaCore(Eigen::Index n, const X& x, const Y& y, bool with_scale) {
  if (n == 0) throw std::invalid_argument("no matched positions");
  const double inv_n = 1.0 / static_cast<double>(n);
  // Means (Eqs. 34, 35).
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_y = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    mean_x += x(i);
    mean_y += y(i);
  }
  mean_x *= inv_n;
  mean_y *= inv_n;
  // Variance of x (Eq. 36) and covariance (Eq. 38).
  double sigma_x = 0.0;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d dx = x(i) - mean_x;
    sigma_x += dx.squaredNorm();
    cov.noalias() += (y(i) - mean_y) * dx.transpose();
  }
  sigma_x *= inv_n;
  cov *= inv_n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();  // descending
  // evo rejects a covariance rank below m - 1 = 2 (singular values <= machine epsilon). A relative test as well,
  // so that collinear points carrying rounding noise are still reported as degenerate.
  const double eps = std::numeric_limits<double>::epsilon();
  if (!(d(1) > eps) || d(1) <= 1e-13 * d(0))
    throw std::invalid_argument("the " + std::to_string(n) +
                                " matched positions are all equal or on one line (need at least 3 that are not)");
  // S (Eq. 43): reflect the last axis when det(U) det(V) < 0 so that R is a proper rotation.
  Eigen::Vector3d s = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s(2) = -1.0;
  Sim3 out;
  out.R = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();  // Eq. 40
  out.scale = with_scale ? d.dot(s) / sigma_x : 1.0;                    // Eq. 42
  out.t = mean_y - out.scale * (out.R * mean_x);                        // Eq. 41
  return out;
}

void alignPose(Eigen::Isometry3d& T, const Sim3& a) {
  const Eigen::Matrix3d R = a.R * T.linear();
  const Eigen::Vector3d t = a.scale * (a.R * T.translation()) + a.t;
  T.linear() = R;
  T.translation() = t;
}

}  // namespace

Sim3 umeyamaAlignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, bool with_scale) {
  if (x.cols() != y.cols())
    throw std::invalid_argument("Umeyama alignment: " + std::to_string(x.cols()) + " source points but " +
                                std::to_string(y.cols()) + " target points");
  return umeyamaCore(
      x.cols(), [&](Eigen::Index i) { return Eigen::Vector3d(x.col(i)); },
      [&](Eigen::Index i) { return Eigen::Vector3d(y.col(i)); }, with_scale);
}

Sim3 umeyamaAlignment(const Trajectory& est, const std::vector<std::size_t>& est_index, const Trajectory& ref,
                      const std::vector<std::size_t>& ref_index, bool with_scale) {
  if (est_index.size() != ref_index.size())
    throw std::invalid_argument("Umeyama alignment: " + std::to_string(est_index.size()) + " source points but " +
                                std::to_string(ref_index.size()) + " target points");
  return umeyamaCore(
      static_cast<Eigen::Index>(est_index.size()),
      [&](Eigen::Index i) { return Eigen::Vector3d(est.at(est_index[i]).T_world_body.translation()); },
      [&](Eigen::Index i) { return Eigen::Vector3d(ref.at(ref_index[i]).T_world_body.translation()); }, with_scale);
}

Eigen::Matrix3Xd positionsOf(const Trajectory& trajectory) {
  Eigen::Matrix3Xd p(3, static_cast<Eigen::Index>(trajectory.size()));
  for (std::size_t i = 0; i < trajectory.size(); ++i)
    p.col(static_cast<Eigen::Index>(i)) = trajectory[i].T_world_body.translation();
  return p;
}

Trajectory applyAlignment(const Trajectory& trajectory, const Sim3& a) {
  Trajectory out = trajectory;
  for (StampedPose& p : out) alignPose(p.T_world_body, a);
  return out;
}

Trajectory applyAlignment(const Trajectory& trajectory, const std::vector<std::size_t>& indices, const Sim3& a) {
  Trajectory out;
  out.reserve(indices.size());
  for (const std::size_t i : indices) {
    out.push_back(trajectory.at(i));
    alignPose(out.back().T_world_body, a);
  }
  return out;
}

Sim3 alignTrajectory(const Trajectory& est, const std::vector<std::size_t>& est_index, const Trajectory& ref,
                     const std::vector<std::size_t>& ref_index, Alignment alignment, Trajectory& est_aligned) {
  Sim3 a;
  if (alignment != Alignment::kNone) {
    try {
      a = umeyamaAlignment(est, est_index, ref, ref_index, alignment == Alignment::kSim3);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("cannot align (") + alignmentName(alignment) + "): " + e.what());
    }
  }
  est_aligned = applyAlignment(est, est_index, a);
  return a;
}

const char* alignmentName(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone: return "none";
    case Alignment::kSe3: return "se3";
    case Alignment::kSim3: return "sim3";
  }
  return "?";
}

}  // namespace drover::eval
