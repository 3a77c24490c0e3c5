#pragma once
// Scalar errors of an error pose E (ideally the identity), as evo's PoseRelation:
//   kTranslation: |t(E)| [m]              (evo: translation_part)
//   kRotation:    |R(E) - I|_F [-]        (evo: rotation_part)
//   kFull:        |E - I_4|_F [-]         (evo: full_transformation)
//   kAngleDeg:    |Log R(E)| [deg]        (evo: rotation_angle_deg)
// All four are invariant under E -> E^-1, so evo's E = P_est^-1 P_ref and our E = P_ref^-1 P_est give the same
// numbers.
#include <Eigen/Geometry>

namespace drover::eval {

enum class PoseRelation { kTranslation, kRotation, kFull, kAngleDeg };

double poseError(const Eigen::Isometry3d& E, PoseRelation relation);

const char* relationName(PoseRelation relation);   // "trans" | "rot" | "full" | "angle_deg" (CLI spelling)
const char* relationTitle(PoseRelation relation);  // evo's wording, e.g. "translation part"
const char* relationUnit(PoseRelation relation);   // "m" | "unit-less" | "deg"

}  // namespace drover::eval
