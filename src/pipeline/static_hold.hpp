#pragma once
// Holding a static start at rest: a zero-velocity update (as OpenVINS's ZUPT, or the stationary detector of a
// GNSS/INS) from a static start until the IMU says the platform moved.
//
// Why. Standing still, an accelerometer bias b along a direction the lidar leaves open (a start in a degenerate
// corridor) is indistinguishable from motion: the smoother integrates it and the pose creeps by b t^2 / 2 (the
// simulated corridor: 0.02 m/s^2, a creep of 4-6 cm and 0.04 m/s in the 2 s before the pull-away). When the VIS's
// motion then reaches the smoother, the smoother must put the creep somewhere; it took it as a velocity error since
// the start and moved the pose back 12 cm past the truth (bench/RESULTS.md). The static initialiser already judged
// the start at rest from the IMU window; holding that knowledge while the IMU still reads what it read at rest makes
// the bias observable instead: between two states of zero relative motion the IMU factor's measured velocity
// change is the bias (Forster et al., TRO 2017, Eq. 45 with dv = 0).
//
// How the motion is detected. The IMU cannot tell rest from constant velocity, but it sees every change: the hold
// integrates the specific force less the rest's (the window's mean: gravity and bias as they were at rest) into a
// velocity change, and the angular rate less the rest's into a rotation, since the hold began; it ends for good when
// either exceeds its threshold. The noise of those integrals over a few seconds (the simulated IMU's 2e-3 m/s^2/rtHz:
// 0.004 m/s after 4 s) is well under the default 0.02 m/s, and a pull-away at 0.4 m/s^2 crosses it in 0.05 s, within
// the sweep where it begins. A hold that ends too early is the behaviour without it; one that ends too late pins a
// moving pose, so the thresholds are kept near the noise.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "types/imu.hpp"
#include "types/time.hpp"

namespace drover::pipeline {

struct StaticHoldConfig {
  double sigma = 0.0;          // [m and rad] per sweep: the zero-motion factor's sigma while held; 0: off
  double max_velocity = 0.02;  // [m/s] |integrated specific force less the rest's| since the hold began that ends it
  double max_rotation = 0.01;  // [rad] |integrated angular rate less the rest's| that ends it
  std::string validate() const;  // empty when valid
};

class StaticHold {
 public:
  explicit StaticHold(const StaticHoldConfig& config = {}) : config_(config) {}

  // At a static start (time t): the rest's mean specific force [m/s^2] and angular rate [rad/s], IMU frame. Does
  // nothing when the config's sigma is 0.
  void begin(Time t, const Eigen::Vector3d& rest_specific_force, const Eigen::Vector3d& rest_rate);
  // Integrates the samples in (a, b] (time order; samples outside are skipped) and returns whether the platform is
  // still at rest at b. Once it has moved, false for good.
  bool stillAtRest(const std::vector<ImuSample>& samples, Time a, Time b);
  bool holding() const { return holding_; }
  // Why and when the hold ended (empty / 0 while holding or never begun).
  const std::string& endReason() const { return end_reason_; }
  Time endedAt() const { return ended_at_; }

 private:
  void end(Time t, std::string reason);

  StaticHoldConfig config_;
  bool holding_ = false;
  Time last_ = 0;  // [ns] the newest sample integrated (or the hold's start)
  Eigen::Vector3d rest_f_ = Eigen::Vector3d::Zero(), rest_w_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dv_ = Eigen::Vector3d::Zero(), dtheta_ = Eigen::Vector3d::Zero();
  std::string end_reason_;
  Time ended_at_ = 0;
};

}  // namespace drover::pipeline
