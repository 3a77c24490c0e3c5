#include "io/lvi_sam_import.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>

#include "io/error.hpp"
#include "io/lvi_sam_parts.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {
namespace lvisam {

std::string whyIgnored(const std::string& key) {
  static const std::string kGps = "GPS: Drover fuses no GPS";
  static const std::string kVisualLoop =
      "LVI-SAM's visual loop closure (DBoW2, BRIEF): Drover closes loops with the lidar (Scan Context, loop.enabled)";
  static const std::string kDisplay = "display (rviz) only";
  static const std::string kLidarToCam =
      "Drover composes the lidar-camera transform from T_imu_lidar and T_imu_cam; LVI-SAM uses this separate one "
      "only to project lidar points for feature depth (check that the two agree)";
  static const std::map<std::string, std::string> reasons = {
      {"PROJECT_NAME", "ROS package name"},
      {"project_name", "ROS package name"},
      {"odomTopic", "LIO-SAM's IMU-rate odometry output: drover run writes it to trajectory_imu_rate.tum"},
      {"gpsTopic", kGps},
      {"useGpsElevation", kGps},
      {"gpsCovThreshold", kGps},
      {"poseCovThreshold", kGps},
      {"useImuHeadingInitialization", "aligns the map's heading for GPS: Drover fuses no GPS"},
      {"lidarFrame", "ROS tf frame name: drover run writes files, no tf"},
      {"baselinkFrame", "ROS tf frame name: drover run writes files, no tf"},
      {"odometryFrame", "ROS tf frame name: drover run writes files, no tf"},
      {"mapFrame", "ROS tf frame name: drover run writes files, no tf"},
      {"savePCD", "drover run always writes map.pcd and map.ply into its run folder (--out)"},
      {"savePCDDirectory", "drover run always writes map.pcd and map.ply into its run folder (--out)"},
      {"imuRPYWeight",
       "Drover takes roll and pitch from its smoother's gravity (odometry.gravity_roll_pitch), not by blending "
       "in the IMU's orientation"},
      {"numberOfCores", "drover run is a single-threaded, deterministic replay"},
      {"mappingProcessInterval", "LIO-SAM skips sweeps that arrive sooner; Drover matches every sweep"},
      {"loopClosureFrequency", "Drover looks for a loop at every keyframe"},
      {"surroundingKeyframeSize",
       "LVI-SAM's local map is the newest N keyframes while loop closure is on; Drover's is the keyframes within "
       "odometry.local_map.surrounding_radius plus the last recent_window seconds (recent_count adds the newest N)"},
      {"historyKeyframeFitnessScore",
       "PCL ICP's mean squared point distance [m^2]; Drover accepts a loop by the RMS point-to-feature distance "
       "(loop.verifier.max_fitness [m], default 0.25), a different measure"},
      {"globalMapVisualizationSearchRadius", kDisplay},
      {"globalMapVisualizationPoseDensity", kDisplay},
      {"globalMapVisualizationLeafSize", kDisplay},
      {"camera_name", "a name only"},
      {"point_cloud_topic", "LVI-SAM's internal topic of deskewed sweeps: Drover hands them to the VIS internally"},
      {"lidar_skip", "Drover gives features depth from the deskewed sweeps of the last visual.depth.window_s seconds"},
      {"align_camera_lidar_estimation", kDisplay},
      {"lidar_to_cam_tx", kLidarToCam},
      {"lidar_to_cam_ty", kLidarToCam},
      {"lidar_to_cam_tz", kLidarToCam},
      {"lidar_to_cam_rx", kLidarToCam},
      {"lidar_to_cam_ry", kLidarToCam},
      {"lidar_to_cam_rz", kLidarToCam},
      {"fisheye_mask", "Drover applies no image mask"},
      {"freq", "VINS publishes tracks at most this often; Drover's VIS uses every frame"},
      {"show_track", kDisplay},
      {"output_path", "drover run writes into its run folder (--out)"},
      {"loop_closure", kVisualLoop},
      {"skip_time", kVisualLoop},
      {"skip_dist", kVisualLoop},
      {"debug_image", kVisualLoop},
      {"match_image_scale", kVisualLoop},
      {"vocabulary_file", kVisualLoop},
      {"brief_pattern_file", kVisualLoop},
  };
  const auto it = reasons.find(key);
  return it == reasons.end() ? std::string() : it->second;
}

}  // namespace lvisam

namespace {

using lvisam::Output;
using lvisam::ParamFile;

// A key written twice in one map would lose one of its values silently (yaml-cpp keeps both pairs).
void rejectDuplicates(const YAML::Node& n, const std::string& path) {
  if (n.IsSequence())
    for (const YAML::Node& item : n) rejectDuplicates(item, path);
  if (!n.IsMap()) return;
  std::map<std::string, int> seen;
  for (const auto& kv : n) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
    const int line = kv.first.Mark().line + 1;
    if (const auto first = seen.find(key); first != seen.end())
      fail(path, lineRecord(static_cast<std::size_t>(line)) + ", key " + echo(key),
           "duplicate key (first at " + lineRecord(static_cast<std::size_t>(first->second)) + ")");
    seen.emplace(key, line);
    rejectDuplicates(kv.second, path);
  }
}

YAML::Node parse(const LviSamFile& f) {
  std::string text = f.text;
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';  // OpenCV's header, which yaml-cpp rejects; lines stay put
  YAML::Node root;
  try {
    root = YAML::Load(text);  // !!opencv-matrix is kept as a tag on an ordinary map
  } catch (const YAML::Exception& e) {
    fail(f.path, lineRecord(static_cast<std::size_t>(e.mark.line + 1)), "invalid YAML: " + e.msg);
  }
  if (!root.IsMap()) fail(f.path, "", "expected a map of parameters at top level");
  rejectDuplicates(root, f.path);
  return root;
}

// LIO-SAM's files hold their parameters under one namespace key (lio_sam:, lvi_sam:, ROS 2's /**:
// ros__parameters:); LVI-SAM's camera file (VINS-Mono's format) holds them at top level.
struct Located {
  bool camera = false;
  YAML::Node params;
  std::string prefix;     // "lvi_sam." or ""
  std::string namespace_; // the root key holding the parameters, "" for a camera file
};

Located locate(const YAML::Node& root, const std::string& path) {
  Located l;
  if (root["model_type"] || root["image_topic"] || root["projection_parameters"]) {
    l.camera = true;
    l.params.reset(root);
    return l;
  }
  std::optional<std::string> ns;
  for (const auto& kv : root)
    if (kv.second.IsMap()) {
      if (ns) fail(path, "", "two parameter namespaces, '" + *ns + "' and '" + kv.first.Scalar() + "'; expected one");
      ns = kv.first.Scalar();
    }
  if (!ns) {
    if (root["N_SCAN"] || root["pointCloudTopic"]) {  // parameters at top level (a rosparam dump)
      l.params.reset(root);
      return l;
    }
    fail(path, "",
         "neither a LIO-SAM/LVI-SAM lidar file (parameters under lio_sam: or lvi_sam:) nor an LVI-SAM camera file "
         "(model_type, image_topic)");
  }
  l.namespace_ = *ns;
  l.prefix = *ns + ".";
  const YAML::Node params = root[*ns];
  const YAML::Node inner = params["ros__parameters"];
  if (inner && inner.IsMap()) {  // ROS 2
    l.params.reset(inner);
    l.prefix += "ros__parameters.";
  } else {
    l.params.reset(params);
  }
  return l;
}

void listLeftovers(ParamFile& f, Output& o) {
  for (const std::string& key : f.unused()) {
    std::string why = lvisam::whyIgnored(key);
    if (why.empty()) why = lvisam::whyIgnored(key.substr(0, key.find('.')));
    o.ignore(f, key, why.empty() ? "not a LIO-SAM / LVI-SAM parameter the importer knows" : why);
  }
}

void describeSections(lvisam::ConfigTree& t) {
  t.note("dataset", "What to read (ROS1 bag topics).");
  t.note("calibration", "Row-major 4x4 rigid transforms [m]; t_imu = t_sensor + offset [s].");
  t.note("odometry", "Lidar-inertial odometry (keys: src/io/odometry/odometry_config_io.hpp).");
  t.note("loop", "Loop closure (keys: src/io/odometry/loop_config_io.hpp).");
  t.note("visual", "Visual front end (keys: src/io/visual/visual_config_io.hpp).");
  t.note("vio", "Sliding-window VIO (keys: src/io/visual/vio_config_io.hpp).");
}

std::string header(const std::vector<LviSamFile>& files) {
  std::string s = "# Drover platform config imported by `drover config import-lvi-sam` from:\n";
  for (const LviSamFile& f : files) s += "#   " + f.path + "\n";
  return s + "# Each value names the parameter it came from; keys not written here take Drover's defaults.\n";
}

std::string footer(const std::vector<LviSamKey>& ignored) {
  std::string s = "\n# Not imported (" + std::to_string(ignored.size()) + " parameters):\n";
  for (const LviSamKey& k : ignored) s += "#   " + k.file + ": " + k.key + " -- " + k.note + "\n";
  return s;
}

}  // namespace

LviSamImport importLviSam(const std::vector<LviSamFile>& files) {
  if (files.empty()) throw std::invalid_argument("no parameter file given");
  Output o;
  describeSections(o.tree);
  std::vector<std::pair<ParamFile, bool>> parsed;  // (parameters, is the camera file)
  std::vector<ParamFile> roots;                    // the namespaced files' other top-level keys (PROJECT_NAME)
  std::string lidar_path, camera_path;
  for (const LviSamFile& f : files) {
    const YAML::Node root = parse(f);
    const Located l = locate(root, f.path);
    std::string& seen = l.camera ? camera_path : lidar_path;
    if (!seen.empty())
      fail(f.path, "", std::string("a second ") + (l.camera ? "camera" : "lidar") + " parameter file (the first: " +
                           seen + "); give one of each");
    seen = f.path;
    parsed.emplace_back(ParamFile(f.path, l.params, l.prefix), l.camera);
    if (!l.namespace_.empty()) {
      roots.emplace_back(f.path, root, "");
      roots.back().use(l.namespace_);
    }
  }
  // The lidar file first: its IMU topic and noise take precedence over the camera file's.
  for (auto& [f, camera] : parsed)
    if (!camera) lvisam::mapLidarFile(f, o);
  o.tree.set("dataset.load_lidar", lidar_path.empty() ? "false" : "true");
  o.tree.set("dataset.load_imu", "true");
  for (auto& [f, camera] : parsed)
    if (camera) lvisam::mapCameraFile(f, o, !lidar_path.empty());
  if (camera_path.empty()) o.tree.set("dataset.load_images", "false", "no camera parameter file given");
  for (ParamFile& r : roots) listLeftovers(r, o);
  for (auto& [f, camera] : parsed) listLeftovers(f, o);
  LviSamImport result;
  result.yaml = header(files) + o.tree.emit() + footer(o.ignored);
  result.mapped = std::move(o.mapped);
  result.ignored = std::move(o.ignored);
  return result;
}

LviSamImport importLviSamFiles(const std::vector<std::string>& paths) {
  std::vector<LviSamFile> files;
  for (const std::string& p : paths) {
    if (std::filesystem::is_directory(p)) fail(p, "", "is a folder; expected a parameter file");
    if (!std::filesystem::exists(p)) fail(p, "", "parameter file not found");
    files.push_back({p, readTextFile(p)});
  }
  return importLviSam(files);
}

}  // namespace drover::io
