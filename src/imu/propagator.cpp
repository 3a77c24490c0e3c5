#include "imu/propagator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "geometry/so3.hpp"

namespace drover::imu {

namespace {

bool finite(const ImuSample& s) {
  return s.omega_imu.allFinite() && s.acc_imu.allFinite() && (!s.q_world_imu || s.q_world_imu->coeffs().allFinite());
}

}  // namespace

const char* toString(SampleStatus status) {
  switch (status) {
    case SampleStatus::kAccepted: return "accepted";
    case SampleStatus::kAcceptedAfterGap: return "accepted_after_gap";
    case SampleStatus::kDroppedNonFinite: return "dropped_nonfinite";
    case SampleStatus::kDroppedOutOfOrder: return "dropped_out_of_order";
    case SampleStatus::kDroppedSpike: return "dropped_spike";
  }
  return "unknown";
}

std::string ImuPropagator::Config::validate() const {
  std::ostringstream out;
  const auto positive = [&out](const char* name, double value) {
    if (!std::isfinite(value) || value <= 0) out << name << " = " << value << " must be finite and > 0; ";
  };
  positive("max_gap_s", max_gap_s);
  positive("max_acc", max_acc);
  positive("max_gyro", max_gyro);
  positive("buffer_s", buffer_s);
  positive("gravity", gravity);
  return out.str();
}

ImuPropagator::ImuPropagator() : ImuPropagator(Config{}) {}

ImuPropagator::ImuPropagator(const Config& config) : config_(config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("ImuPropagator::Config: " + error);
}

SampleStatus ImuPropagator::check(const ImuSample& sample) const {
  if (!finite(sample)) return SampleStatus::kDroppedNonFinite;
  if (!samples_.empty() && sample.t <= samples_.back().t) return SampleStatus::kDroppedOutOfOrder;
  if (sample.acc_imu.norm() > config_.max_acc || sample.omega_imu.norm() > config_.max_gyro) {
    return SampleStatus::kDroppedSpike;
  }
  if (!samples_.empty() && toSeconds(sample.t - samples_.back().t) > config_.max_gap_s) {
    return SampleStatus::kAcceptedAfterGap;
  }
  return SampleStatus::kAccepted;
}

SampleStatus ImuPropagator::addSample(const ImuSample& sample) {
  const SampleStatus status = check(sample);
  switch (status) {
    case SampleStatus::kDroppedNonFinite: ++stats_.dropped_nonfinite; return status;
    case SampleStatus::kDroppedOutOfOrder: ++stats_.dropped_out_of_order; return status;
    case SampleStatus::kDroppedSpike: ++stats_.dropped_spike; return status;
    case SampleStatus::kAcceptedAfterGap: ++stats_.gaps; break;
    case SampleStatus::kAccepted: break;
  }
  ++stats_.accepted;
  if (!samples_.empty()) stats_.largest_gap_s = std::max(stats_.largest_gap_s, toSeconds(sample.t - samples_.back().t));
  samples_.push_back(sample);
  if (initialized_) appendNode(sample);
  trim();
  return status;
}

void ImuPropagator::reset(const NavState& state, const ImuBias& bias) {
  if (!state.T_world_imu.matrix().allFinite() || !state.v_world.allFinite() || !bias.gyro.allFinite() ||
      !bias.acc.allFinite()) {
    throw std::invalid_argument("ImuPropagator::reset: state or bias is not finite");
  }
  bias_ = bias;
  initialized_ = true;
  nodes_.clear();
  Node anchor;
  anchor.t = state.t;
  anchor.R = Eigen::Quaterniond(state.T_world_imu.linear()).normalized().toRotationMatrix();
  anchor.p = state.T_world_imu.translation();
  anchor.v = state.v_world;
  nodes_.push_back(anchor);
  // Zero-order hold: the last sample at or before state.t holds over it (appendNode falls back to the first
  // later sample when none is buffered).
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), state.t,
                                      [](Time t, const ImuSample& s) { return t < s.t; });
  anchor_held_ = false;
  if (after != samples_.begin()) appendNode(*(after - 1));
  for (auto it = after; it != samples_.end(); ++it) appendNode(*it);
}

ImuPropagator::Node ImuPropagator::step(const Node& from, Time t) const {
  const double dt = toSeconds(t - from.t);
  const Eigen::Vector3d a_world = from.R * from.acc + Eigen::Vector3d(0, 0, -config_.gravity);
  Node to = from;
  to.t = t;
  to.R = from.R * geometry::expSO3(from.omega * dt);
  to.v = from.v + a_world * dt;
  to.p = from.p + from.v * dt + 0.5 * a_world * dt * dt;
  return to;
}

void ImuPropagator::appendNode(const ImuSample& sample) {
  const Eigen::Vector3d omega = sample.omega_imu - bias_.gyro, acc = sample.acc_imu - bias_.acc;
  Node& last = nodes_.back();
  if (sample.t <= last.t || !anchor_held_) {
    // A sample at or before the anchor is what the anchor holds (zero-order hold over state.t). With none such,
    // the first sample after the anchor is held back to it.
    last.omega = omega;
    last.acc = acc;
    anchor_held_ = true;
    if (sample.t <= last.t) return;
  }
  Node next = step(last, sample.t);
  next.omega = omega;
  next.acc = acc;
  nodes_.push_back(next);
}

void ImuPropagator::trim() {
  const Time cutoff = samples_.back().t - fromSeconds(config_.buffer_s);
  // Keep the last element at or before the cutoff: it holds over the cutoff.
  while (samples_.size() >= 2 && samples_[1].t <= cutoff) samples_.pop_front();
  while (nodes_.size() >= 2 && nodes_[1].t <= cutoff) nodes_.pop_front();
}

const ImuPropagator::Node* ImuPropagator::nodeAt(Time t) const {
  if (!initialized_ || nodes_.empty() || t < nodes_.front().t || t > nodes_.back().t) return nullptr;
  const auto after = std::upper_bound(nodes_.begin(), nodes_.end(), t, [](Time x, const Node& n) { return x < n.t; });
  return &*(after - 1);
}

std::optional<NavState> ImuPropagator::stateAt(Time t) const {
  const Node* node = nodeAt(t);
  if (node == nullptr) return std::nullopt;
  const Node at = step(*node, t);
  NavState state;
  state.t = t;
  state.T_world_imu.linear() = at.R;
  state.T_world_imu.translation() = at.p;
  state.v_world = at.v;
  return state;
}

std::optional<Eigen::Vector3d> ImuPropagator::omegaAt(Time t) const {
  const Node* node = nodeAt(t);
  if (node == nullptr) return std::nullopt;
  return node->omega;
}

std::vector<ImuSample> ImuPropagator::samplesCovering(Time t0, Time t1) const {
  const auto after = std::upper_bound(samples_.begin(), samples_.end(), t0,
                                      [](Time t, const ImuSample& s) { return t < s.t; });
  if (after == samples_.begin()) return {};
  std::vector<ImuSample> out;
  for (auto it = after - 1; it != samples_.end() && (it->t <= t1 || it == after - 1); ++it) out.push_back(*it);
  return out;
}

Time ImuPropagator::latestTime() const { return samples_.empty() ? 0 : samples_.back().t; }

}  // namespace drover::imu
