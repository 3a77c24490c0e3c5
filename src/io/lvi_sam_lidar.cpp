// LIO-SAM's params.yaml / LVI-SAM's params_lidar.yaml -> the dataset, calibration, odometry and loop sections.
// Units are LIO-SAM's own (m, rad, s, the IMU noise as continuous-time densities, as GTSAM's preintegration takes
// them), which are Drover's, so numbers are copied unchanged.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "io/lvi_sam_parts.hpp"
#include "io/text_parsing.hpp"

namespace drover::io::lvisam {
namespace {

// A parameter copied as it is to one or more Drover keys.
struct NumberRule {
  const char* key;
  std::vector<const char*> targets;
  Range range;
  bool integer;
  const char* comment;  // the unit and anything a reader of the output should know
};

const std::vector<NumberRule>& numberRules() {
  static const std::vector<NumberRule> rules = {
      {"N_SCAN", {"odometry.layout.n_rings"}, between(1, 65535, ""), true, "beams"},
      {"Horizon_SCAN",
       {"odometry.layout.columns", "odometry.features.columns"},
       between(1, 1e6, ""),
       true,
       "firings per revolution"},
      {"lidarMinRange", {"odometry.layout.min_range", "odometry.features.min_range"}, atLeast(0, "m"), false, "[m]"},
      {"lidarMaxRange", {"odometry.layout.max_range", "odometry.features.max_range"}, positive("m"), false, "[m]"},
      {"imuAccNoise", {"odometry.imu.acc_noise_density"}, atLeast(0, ""), false, "[m/s^2/sqrt(Hz)]"},
      {"imuGyrNoise", {"odometry.imu.gyro_noise_density"}, atLeast(0, ""), false, "[rad/s/sqrt(Hz)]"},
      {"imuAccBiasN", {"odometry.imu.acc_bias_random_walk"}, atLeast(0, ""), false, "[m/s^3/sqrt(Hz)]"},
      {"imuGyrBiasN", {"odometry.imu.gyro_bias_random_walk"}, atLeast(0, ""), false, "[rad/s^2/sqrt(Hz)]"},
      {"imuGravity", {"odometry.imu.gravity"}, positive("m/s^2"), false, "[m/s^2]"},
      {"edgeThreshold", {"odometry.features.edge_threshold"}, atLeast(0, ""), false, "curvature"},
      {"surfThreshold", {"odometry.features.surf_threshold"}, atLeast(0, ""), false, "curvature"},
      {"edgeFeatureMinValidNum", {"odometry.matcher.min_edge_features"}, between(0, 1e9, ""), true, "edges"},
      {"surfFeatureMinValidNum", {"odometry.matcher.min_plane_features"}, between(0, 1e9, ""), true, "planes"},
      {"odometrySurfLeafSize", {"odometry.features.surf_leaf"}, atLeast(0, "m"), false, "[m]"},
      {"mappingCornerLeafSize", {"odometry.local_map.edge_leaf"}, positive("m"), false, "[m]"},
      {"mappingSurfLeafSize", {"odometry.local_map.plane_leaf"}, positive("m"), false, "[m]"},
      {"surroundingkeyframeAddingDistThreshold", {"odometry.keyframes.distance"}, positive("m"), false, "[m]"},
      {"surroundingkeyframeAddingAngleThreshold",
       {"odometry.keyframes.angle"},
       positive("rad"),
       false,
       "[rad] of the geodesic angle (LIO-SAM: each Euler angle)"},
      {"surroundingKeyframeDensity", {"odometry.local_map.keyframe_density"}, atLeast(0, "m"), false, "[m]"},
      {"surroundingKeyframeSearchRadius", {"odometry.local_map.surrounding_radius"}, positive("m"), false, "[m]"},
      {"historyKeyframeSearchRadius",
       {"loop.radius"},
       positive("m"),
       false,
       "[m] LIO-SAM's radius search; used with loop.source radius or both (default: Scan Context)"},
      {"historyKeyframeSearchTimeDiff", {"loop.min_age"}, between(0, 1e6, "s"), false, "[s]"},
      {"historyKeyframeSearchNum",
       {"loop.submap_keyframes"},
       between(0, 100000, ""),
       true,
       "keyframes on each side of the candidate"},
  };
  return rules;
}

std::string joined(const std::vector<const char*>& v) {
  std::string s;
  for (const char* t : v) s += (s.empty() ? "" : ", ") + std::string(t);
  return s;
}

void copyNumbers(ParamFile& f, Output& o) {
  for (const NumberRule& r : numberRules()) {
    std::optional<double> v;
    if (r.integer) {
      if (const auto i = f.integer(r.key, static_cast<int>(r.range.min), static_cast<int>(r.range.max))) v = *i;
    } else {
      v = f.number(r.key, r.range);
    }
    if (!v) continue;
    for (const char* t : r.targets) o.tree.set(t, yamlNumber(*v), std::string(r.key) + " " + r.comment);
    o.map(f, r.key, joined(r.targets));
  }
}

void copyTopics(ParamFile& f, Output& o) {
  if (const auto t = f.text("pointCloudTopic")) {
    o.tree.set("dataset.lidar_topic", yamlString(*t), "pointCloudTopic");
    o.map(f, "pointCloudTopic", "dataset.lidar_topic");
  }
  if (const auto t = f.text("imuTopic")) {
    o.tree.set("dataset.imu_topic", yamlString(*t), "imuTopic");
    o.imu_topic = *t;
    o.map(f, "imuTopic", "dataset.imu_topic");
  }
}

Eigen::Matrix3d matrix3(const std::vector<double>& v) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = v[static_cast<std::size_t>(3 * r + c)];
  return R;
}

// extrinsicRot = R_lidar_imu and extrinsicTrans = t_lidar_imu (LIO-SAM composes T_world_imu = T_world_lidar *
// (I, extrinsicTrans) after rotating the IMU's vectors by extrinsicRot), so T_imu_lidar = [R^T | -R^T t].
void mapExtrinsics(ParamFile& f, Output& o) {
  const auto rot = f.numbers("extrinsicRot", 9);
  const auto trans = f.numbers("extrinsicTrans", 3);
  if (rot || trans) {
    const Eigen::Matrix3d R = rot ? matrix3(*rot) : Eigen::Matrix3d::Identity();
    if (rot) checkedRotation(R, f.path(), f.record("extrinsicRot"));  // throws unless a rotation
    const Eigen::Vector3d t = trans ? Eigen::Vector3d((*trans)[0], (*trans)[1], (*trans)[2]) : Eigen::Vector3d::Zero();
    const Eigen::Matrix3d Rt = R.transpose();
    const Eigen::Vector3d ti = -Rt * t;
    std::vector<double> m;
    for (int r = 0; r < 3; ++r) m.insert(m.end(), {Rt(r, 0), Rt(r, 1), Rt(r, 2), ti(r)});
    m.insert(m.end(), {0, 0, 0, 1});
    o.tree.note("calibration.T_imu_lidar",
                "LIO-SAM: extrinsicRot = R_lidar_imu, extrinsicTrans = t_lidar_imu; here inv([R | t]) [m]");
    o.tree.set("calibration.T_imu_lidar", yamlList(m, 4));
    if (rot) o.map(f, "extrinsicRot", "calibration.T_imu_lidar (transposed)");
    if (trans) o.map(f, "extrinsicTrans", "calibration.T_imu_lidar (as -R^T t)");
  }
  // extrinsicRPY rotates only the 9-axis unit's orientation output: R_lidar_orientation. When the orientation is
  // not of the IMU's own acc/gyro frame (R_imu_orientation = extrinsicRot^T extrinsicRPY != I), Drover, which
  // takes a unit's orientation as q_world_imu, must not use it.
  if (const auto rpy = f.numbers("extrinsicRPY", 9)) {
    const Eigen::Matrix3d Q = matrix3(*rpy);
    checkedRotation(Q, f.path(), f.record("extrinsicRPY"));
    const Eigen::Matrix3d R = rot ? matrix3(*rot) : Eigen::Matrix3d::Identity();
    const double off = (R.transpose() * Q - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (off <= kRotationTolerance) {
      o.map(f, "extrinsicRPY", "equals extrinsicRot: the unit's orientation is of its IMU frame (no key needed)");
    } else {
      o.tree.set("odometry.use_imu_orientation", "false",
                 "extrinsicRPY != extrinsicRot: the unit's orientation is not of its acc/gyro frame");
      o.map(f, "extrinsicRPY", "odometry.use_imu_orientation: false (differs from extrinsicRot)");
    }
  }
}

// Keys whose value either matches what Drover always does (then understood, no key needed) or asks for something
// Drover does not do (then ignored, saying so).
void mapConditionals(ParamFile& f, Output& o) {
  if (const auto s = f.text("sensor")) {
    if (*s == "livox")
      o.ignore(f, "sensor", "livox: a non-repetitive scan has no rings; Drover's features need a spinning lidar");
    else
      o.map(f, "sensor", *s + ": ring and per-point time come from the PointCloud2 fields (no key needed)");
  }
  if (const auto s = f.text("timeField")) {
    if (*s == "time" || *s == "t" || *s == "timestamp")
      o.map(f, "timeField", "'" + *s + "' is one of the fields Drover reads (time, t, timestamp; no key needed)");
    else
      o.ignore(f, "timeField", "Drover reads per-point time only from a field named time, t or timestamp");
  }
  if (const auto r = f.integer("downsampleRate", 1, 65535)) {
    if (*r == 1)
      o.map(f, "downsampleRate", "1: every ring is used, as Drover does (no key needed)");
    else
      o.ignore(f, "downsampleRate", "Drover uses every ring; dropping rings is not supported");
  }
  for (const char* key : {"z_tollerance", "rotation_tollerance"}) {
    if (const auto v = f.number(key, atLeast(0, ""))) {
      if (*v >= 1000)
        o.map(f, key, "off (1000): Drover has no planar-robot constraint either (no key needed)");
      else
        o.ignore(f, key, "Drover has no planar-robot motion constraint (z and roll/pitch clamps)");
    }
  }
  if (const auto on = f.flag("loopClosureEnableFlag")) {
    o.tree.set("loop.enabled", *on ? "true" : "false", "loopClosureEnableFlag");
    o.map(f, "loopClosureEnableFlag", "loop.enabled");
  }
}

}  // namespace

void mapLidarFile(ParamFile& f, Output& o) {
  copyTopics(f, o);
  mapExtrinsics(f, o);
  copyNumbers(f, o);
  mapConditionals(f, o);
}

}  // namespace drover::io::lvisam
