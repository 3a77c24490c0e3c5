#pragma once
// High-rate IMU propagation: keeps a short buffer of checked IMU samples and, from the last optimised state
// (reset()), the navigation state at any time up to the newest sample. As in LIO-SAM's imuPreintegration, the
// state is re-propagated through the buffered samples after every reset. Integration is the same zero-order hold
// as the preintegration (Forster et al. TRO 2017, Eq. 30 discretised): between sample times
//   R(t) = R_k Exp((w_k - bg) dt),  v(t) = v_k + (g + R_k (a_k - ba)) dt,
//   p(t) = p_k + v_k dt + 1/2 (g + R_k (a_k - ba)) dt^2,   dt = t - t_k,
// with the world z axis up and gravity g = (0, 0, -gravity).
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"
#include "types/time.hpp"

namespace drover::imu {

// Outcome of ImuPropagator::addSample.
enum class SampleStatus {
  kAccepted,
  kAcceptedAfterGap,    // accepted, but more than max_gap_s after the previous accepted sample
  kDroppedNonFinite,    // NaN or infinite value
  kDroppedOutOfOrder,   // stamp not strictly after the previous accepted sample (duplicate or backwards)
  kDroppedSpike,        // |acc| > max_acc or |omega| > max_gyro
};
const char* toString(SampleStatus status);

// Counters over the whole stream (never reset by reset()).
struct ImuStreamStats {
  std::uint64_t accepted = 0;          // includes those accepted after a gap
  std::uint64_t gaps = 0;              // accepted after a gap
  std::uint64_t dropped_nonfinite = 0;
  std::uint64_t dropped_out_of_order = 0;
  std::uint64_t dropped_spike = 0;
  double largest_gap_s = 0;            // [s] largest interval between consecutive accepted samples
};

class ImuPropagator {
 public:
  struct Config {
    double max_gap_s = 0.1;    // [s] an interval longer than this between accepted samples is reported as a gap
    double max_acc = 150.0;    // [m/s^2] specific-force norm above this is a spike (~15 g)
    double max_gyro = 35.0;    // [rad/s] rate norm above this is a spike (~2000 deg/s)
    // [s] samples older than the newest minus this are discarded. The smoother bridges a lidar dropout with the IMU
    // factor over these samples; past them it restarts. At 5 s the farm's 5 s lidar dropout fell just outside (the
    // sweep after it starts 5.1 s after the one before), and the restart re-estimated both biases from loose priors.
    // 20 s at 200 Hz is 4,000 samples (~0.4 MB with the propagated states).
    double buffer_s = 20.0;
    double gravity = 9.81;     // [m/s^2] world gravity is (0, 0, -gravity)
    // Empty when valid: all values finite and > 0.
    std::string validate() const;
  };

  // Throws std::invalid_argument when config.validate() fails.
  ImuPropagator();  // default Config
  explicit ImuPropagator(const Config& config);

  // Checks one sample and buffers it when good; if initialised, extends the propagated states by it.
  SampleStatus addSample(const ImuSample& sample);

  // Sets the state valid at state.t and the bias used from then on; the states after state.t are re-propagated
  // through the buffered samples. The sample held over state.t is the last one at or before it (the first
  // buffered one if none is). Throws std::invalid_argument for a non-finite state or bias.
  void reset(const NavState& state, const ImuBias& bias);

  // The propagated state at t in [state.t, latestTime()] (nullopt otherwise, before reset(), or when t is older
  // than the buffer still holds). O(log n) binary search to the sample interval and one exact step inside it;
  // velocity in the world frame.
  std::optional<NavState> stateAt(Time t) const;
  // Angular rate (bias-corrected, IMU frame) held at time t, for the same range as stateAt.
  std::optional<Eigen::Vector3d> omegaAt(Time t) const;

  // The buffered samples that cover [t0, t1] for Preintegrator::integrateRange: the last one at or before t0
  // and all up to t1. Empty when none is at or before t0.
  std::vector<ImuSample> samplesCovering(Time t0, Time t1) const;

  Time latestTime() const;  // stamp of the newest accepted sample [ns]; 0 when none
  bool initialized() const { return initialized_; }
  const ImuBias& bias() const { return bias_; }
  const ImuStreamStats& stats() const { return stats_; }
  const std::deque<ImuSample>& samples() const { return samples_; }
  const Config& config() const { return config_; }

 private:
  // Propagated state at a node time (state.t or a later sample time) and the bias-corrected measurement held
  // from there to the next node.
  struct Node {
    Time t = 0;
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d v = Eigen::Vector3d::Zero(), p = Eigen::Vector3d::Zero();
    Eigen::Vector3d omega = Eigen::Vector3d::Zero(), acc = Eigen::Vector3d::Zero();
  };
  Node step(const Node& from, Time t) const;
  void appendNode(const ImuSample& sample);
  SampleStatus check(const ImuSample& sample) const;
  void trim();
  const Node* nodeAt(Time t) const;

  Config config_;
  std::deque<ImuSample> samples_;
  std::deque<Node> nodes_;
  ImuBias bias_;
  bool initialized_ = false;
  bool anchor_held_ = false;  // the anchor node has its held measurement
  ImuStreamStats stats_;
};

}  // namespace drover::imu
