#include "eval/pose_error.hpp"

#include <numbers>

#include "geometry/so3.hpp"

namespace drover::eval {

double poseError(const Eigen::Isometry3d& E, PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation: return E.translation().norm();
    case PoseRelation::kRotation: return (E.linear() - Eigen::Matrix3d::Identity()).norm();
    case PoseRelation::kFull: return (E.matrix() - Eigen::Matrix4d::Identity()).norm();
    case PoseRelation::kAngleDeg: return geometry::rotationAngle(E.linear()) * 180.0 / std::numbers::pi;
  }
  return 0.0;
}

const char* relationName(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation: return "trans";
    case PoseRelation::kRotation: return "rot";
    case PoseRelation::kFull: return "full";
    case PoseRelation::kAngleDeg: return "angle_deg";
  }
  return "?";
}

const char* relationTitle(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation: return "translation part";
    case PoseRelation::kRotation: return "rotation part";
    case PoseRelation::kFull: return "full transformation";
    case PoseRelation::kAngleDeg: return "rotation angle in degrees";
  }
  return "?";
}

const char* relationUnit(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation: return "m";
    case PoseRelation::kRotation: return "unit-less";
    case PoseRelation::kFull: return "unit-less";
    case PoseRelation::kAngleDeg: return "deg";
  }
  return "?";
}

}  // namespace drover::eval
