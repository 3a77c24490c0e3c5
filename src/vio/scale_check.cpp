#include "vio/scale_check.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "geometry/so3.hpp"
#include "vio/initial_alignment.hpp"

namespace drover::vio {

ScaleCheck checkScale(const std::vector<ScaleCheckFrame>& frames, const Eigen::Isometry3d& T_imu_cam,
                      const imu::PreintegrationConfig& imu_config) {
  ScaleCheck out;
  if (frames.size() < 3) {
    out.why = fmt::format("{} keyframes < 3", frames.size());
    return out;
  }
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::Vector3d> c;
  std::vector<imu::Preintegrator> pre;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    R.push_back(frames[k].T_world_imu.linear());
    c.push_back((frames[k].T_world_imu * T_imu_cam).translation());
    if (k == 0) continue;
    const std::vector<ImuSample>& imu = frames[k].imu;
    if (imu.empty() || imu.front().t > frames[k - 1].t || !(frames[k].t > frames[k - 1].t)) {
      throw std::invalid_argument(fmt::format("checkScale: frame {}'s IMU samples do not cover its interval", k));
    }
    // Linearised at the bias the window integrated this interval with (the earlier frame's).
    pre.emplace_back(frames[k - 1].bias, imu_config);
    pre.back().integrateRange(imu, frames[k - 1].t, frames[k].t);
  }
  // The estimate's world is already gravity-aligned to within the error sought: refine from -z directly.
  const double G = imu_config.gravity;
  std::vector<Eigen::Vector3d> acc;  // [m/s^2] world frame: v_k = v_k-1 + g dt + R_k-1 dV
  for (std::size_t k = 0; k < pre.size(); ++k)
    acc.push_back(R[k] * pre[k].deltaV() / pre[k].deltaTime() + Eigen::Vector3d(0, 0, -G));
  out.acc_std = spreadAboutMean(acc);
  const LinearAlignment la = refineGravity(R, c, T_imu_cam.translation(), pre, Eigen::Vector3d(0, 0, -G), G,
                                           AlignmentConfig{}.refine_gravity_iterations, true);
  out.scale = la.scale;
  out.rel_sigma = la.scale_sigma / la.scale;
  if (!std::isfinite(la.scale) || !(la.scale > 0) || !la.g_l.allFinite() || !std::isfinite(out.rel_sigma)) {
    out.why = fmt::format("the alignment gave scale {:.3f} +- {:.3f}", la.scale, la.scale_sigma);
    return out;
  }
  out.R_fix = Eigen::Quaterniond::FromTwoVectors(la.g_l.normalized(), Eigen::Vector3d(0, 0, -1)).toRotationMatrix();
  out.tilt_rad = geometry::rotationAngle(out.R_fix);
  for (std::size_t k = 0; k < frames.size(); ++k) out.v_world.push_back(out.R_fix * R[k] * la.v_imu[k]);
  out.ok = true;
  return out;
}

}  // namespace drover::vio
