// kitti05-replay: the KITTI 05 ground-truth path, in a z-up world, resampled on the spline's uniform knots and
// driven at its real speeds through a procedural town (scenario_town.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sim/scenario_internal.hpp"

namespace drover::sim {
namespace {

// Camera-0 axes (x right, y down, z forward) expressed in the z-up body axes (x forward, y left, z up).
Eigen::Matrix3d bodyFromCamera() {
  Eigen::Matrix3d A;
  A << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return A;
}

// Rotation that turns the normal of the plane z = a x + b y + c fitted to the positions to +z (identity when the
// positions do not span a plane).
Eigen::Matrix3d levelling(const Trajectory& poses) {
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atz = Eigen::Vector3d::Zero();
  for (const StampedPose& p : poses) {
    const Eigen::Vector3d& t = p.T_world_body.translation();
    const Eigen::Vector3d row(t.x(), t.y(), 1.0);
    AtA += row * row.transpose();
    Atz += row * t.z();
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(AtA);
  if (lu.rank() < 3) return Eigen::Matrix3d::Identity();
  const Eigen::Vector3d abc = lu.solve(Atz);
  const Eigen::Vector3d normal = Eigen::Vector3d(-abc.x(), -abc.y(), 1.0).normalized();
  return Eigen::Quaterniond::FromTwoVectors(normal, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace

Trajectory kittiCameraToZupBody(const Trajectory& camera_poses) {
  const Eigen::Matrix3d A = bodyFromCamera();
  Trajectory out;
  out.reserve(camera_poses.size());
  for (const StampedPose& p : camera_poses) {
    StampedPose q;
    q.t = p.t;
    q.T_world_body.linear() = A * p.T_world_body.linear() * A.transpose();
    q.T_world_body.translation() = A * p.T_world_body.translation();
    out.push_back(q);
  }
  const Eigen::Matrix3d L = levelling(out);
  for (StampedPose& q : out) {
    q.T_world_body.linear() = L * q.T_world_body.linear();
    q.T_world_body.translation() = L * q.T_world_body.translation();
  }
  return out;
}

namespace detail {
namespace {

struct Knot {
  double t;                       // [s] from the first pose
  Eigen::Matrix<double, 6, 1> x;  // position [m], yaw (unwrapped), pitch, roll [rad]
};

std::vector<Knot> knotsOf(const Trajectory& body) {
  std::vector<Knot> knots;
  for (const StampedPose& p : body) {
    const Eigen::Matrix3d& R = p.T_world_body.linear();  // R = Rz(yaw) Ry(pitch) Rx(roll)
    Knot k;
    k.t = toSeconds(p.t - body.front().t);
    k.x.head<3>() = p.T_world_body.translation();
    k.x[3] = std::atan2(R(1, 0), R(0, 0));
    k.x[4] = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    k.x[5] = std::atan2(R(2, 1), R(2, 2));
    if (!knots.empty()) {
      if (!(k.t > knots.back().t))
        throw std::invalid_argument("kitti05-replay: ground-truth times must increase, got " + std::to_string(k.t) +
                                    " s after " + std::to_string(knots.back().t) + " s");
      k.x[3] = knots.back().x[3] + std::remainder(k.x[3] - knots.back().x[3], 2.0 * std::numbers::pi);
    }
    knots.push_back(k);
  }
  return knots;
}

// Cubic Hermite interpolation through the knots with finite-difference tangents (Catmull-Rom on a non-uniform
// time grid); linear extrapolation with the end tangent past the last knot.
Eigen::Matrix<double, 6, 1> interpolate(const std::vector<Knot>& k, double t) {
  const auto tangent = [&](std::size_t i) {
    const std::size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, k.size() - 1);
    return Eigen::Matrix<double, 6, 1>((k[b].x - k[a].x) / (k[b].t - k[a].t));
  };
  if (t >= k.back().t) return k.back().x + (t - k.back().t) * tangent(k.size() - 1);
  const auto it = std::upper_bound(k.begin(), k.end(), t, [](double v, const Knot& q) { return v < q.t; });
  const std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - k.begin(), 1)) - 1;
  const double h = k[i + 1].t - k[i].t, u = (t - k[i].t) / h;
  const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u;
  const double h01 = -2 * u * u * u + 3 * u * u, h11 = u * u * u - u * u;
  return h00 * k[i].x + h10 * h * tangent(i) + h01 * k[i + 1].x + h11 * h * tangent(i + 1);
}

}  // namespace

Scenario makeKittiReplay(const Trajectory& ground_truth, const ScenarioOptions& options) {
  if (ground_truth.size() < 4)
    throw std::invalid_argument("kitti05-replay: need >= 4 ground-truth poses, got " +
                                std::to_string(ground_truth.size()));
  const std::vector<Knot> knots = knotsOf(kittiCameraToZupBody(ground_truth));
  constexpr Time kKnot = 100'000'000;  // [ns] spline knot spacing
  const auto count = static_cast<std::int64_t>(std::ceil(knots.back().t / toSeconds(kKnot) - 1e-9));
  ScenarioParts parts;
  parts.name = "kitti05-replay";
  for (std::int64_t i = 0; i <= count; ++i) {
    const Eigen::Matrix<double, 6, 1> x = interpolate(knots, toSeconds(i * kKnot));
    PathSample s;
    s.t = i * kKnot;
    s.p_world = x.head<3>();
    s.yaw = x[3], s.pitch = x[4], s.roll = x[5];
    parts.samples.push_back(s);
  }
  parts.world = buildTown(parts.samples, options.seed);
  return finishScenario(std::move(parts), options);
}

}  // namespace detail
}  // namespace drover::sim
