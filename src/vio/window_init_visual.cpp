// Visual-inertial initialisation of the window (VINS-Mono Sec. V) when no LIS state is available.
#include <fmt/format.h>

#include <cmath>

#include "vio/initial_alignment.hpp"
#include "vio/window_frame.hpp"

namespace drover::vio {

bool SlidingWindowEstimator::initializeVisually(std::string& why) {
  std::vector<InitFrame> frames;
  for (const auto& f : frames_) frames.push_back(InitFrame{f->t, f->seen, f->imu});
  AlignmentConfig ac;
  ac.sfm.focal_px = config_.focal_px;
  ac.sfm.min_parallax_px = config_.init_min_parallax_px;
  ac.min_acc_excitation = config_.init_min_acc_excitation;
  ac.max_scale_rel_sigma = config_.init_max_scale_rel_sigma;
  const AlignmentResult a = alignVisualInertial(frames, T_imu_cam(), imu_config_, ac);
  if (!a.ok) {
    why = a.why;
    return false;
  }
  imu::ImuBias bias;
  bias.gyro = a.gyro_bias;
  for (std::size_t k = 0; k < frames_.size(); ++k) {
    frames_[k]->setPose(a.T_world_imu[k]);
    frames_[k]->setVelocity(a.v_world[k]);
    frames_[k]->setBias(bias);
    if (k > 0) integrate(*frames_[k], *frames_[k - 1]);
  }
  // Depths from the alignment's metric points where it has them, else triangulated from the aligned poses.
  const std::vector<Eigen::Isometry3d> T_wc = cameraPoses();
  for (auto& [id, f] : features_.features()) {
    auto p = a.points_world.find(id);
    if (p == a.points_world.end()) continue;
    const double z = (T_wc[static_cast<std::size_t>(f.start())].inverse() * p->second).z();
    f.depth = z > 0.1 ? z : 0;
  }
  features_.initializeDepths(T_wc, config_.depth_mode != DepthMode::kOff);
  // The alignment's gravity and gyro bias are good to about a degree and 1e-3 rad/s on real data; it does not
  // estimate the accelerometer bias (zero, as VINS-Mono). Its velocities carry the scale's error: at 10 m/s a
  // 5 % scale is 0.5 m/s, so the prior on the oldest velocity must not hold it tighter than that.
  const double speed_error = a.scale_rel_sigma * a.v_world.front().norm();
  setInitPrior(config_.align_sigma_rotation_rad, std::hypot(config_.align_sigma_velocity, speed_error),
               config_.align_sigma_gyro_bias, config_.align_sigma_acc_bias);
  aligned_visually_ = true;
  last_scale_check_ = frames_.back()->t;
  why = fmt::format("scale {:.3f} +- {:.1f} %, gyro bias ({:.4f}, {:.4f}, {:.4f}) rad/s", a.scale,
                    100 * a.scale_rel_sigma, a.gyro_bias.x(), a.gyro_bias.y(), a.gyro_bias.z());
  return true;
}

}  // namespace drover::vio
