#pragma once
// Umeyama alignment (S. Umeyama, "Least-squares estimation of transformation parameters between two point
// patterns", IEEE PAMI 1991, Eqs. 34-43), defined as evo's geometry.umeyama_alignment and
// trajectory.align_trajectory: find R, t, c minimising sum_i |y_i - (c R x_i + t)|^2.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "types/trajectory.hpp"

namespace drover::eval {

enum class Alignment { kNone, kSe3, kSim3 };

// y = scale * R * x + t. For SE(3) alignment scale is 1.
struct Sim3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double scale = 1.0;
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return scale * (R * x) + t; }
};

// x: source points (the estimate), y: target points (the reference), both 3xN with matching columns.
// The variance of x is (1/n) sum |x_i - mean_x|^2 (Eq. 36) and the scale c = tr(D S) / sigma_x^2 (Eq. 42).
// Throws std::invalid_argument when the shapes differ or the cross-covariance has rank < 2 (fewer than three
// non-collinear points: the rotation is not determined).
Sim3 umeyamaAlignment(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y, bool with_scale);

// The same on the positions of matched poses, x_k = est[est_index[k]], y_k = ref[ref_index[k]], without copying
// them out (10^6 poses are hundreds of MB).
Sim3 umeyamaAlignment(const Trajectory& est, const std::vector<std::size_t>& est_index, const Trajectory& ref,
                      const std::vector<std::size_t>& ref_index, bool with_scale);

// Positions of a trajectory as a 3xN matrix.
Eigen::Matrix3Xd positionsOf(const Trajectory& trajectory);

// Applies an alignment to an estimate as evo does: the translations are scaled first (rotations untouched),
// then every pose is left-multiplied by [R | t]:  R_i' = R R_i,  t_i' = scale R t_i + t.
Trajectory applyAlignment(const Trajectory& trajectory, const Sim3& alignment);
// The poses at `indices`, aligned.
Trajectory applyAlignment(const Trajectory& trajectory, const std::vector<std::size_t>& indices, const Sim3& alignment);

// Umeyama of the matched estimate poses onto the matched reference poses; kNone gives the identity. The
// estimate's matched poses after alignment are returned through `est_aligned`. Throws std::invalid_argument
// (naming the alignment and the number of poses) for degenerate positions.
Sim3 alignTrajectory(const Trajectory& est, const std::vector<std::size_t>& est_index, const Trajectory& ref,
                     const std::vector<std::size_t>& ref_index, Alignment alignment, Trajectory& est_aligned);

const char* alignmentName(Alignment alignment);  // "none" | "se3" | "sim3"

}  // namespace drover::eval
