// LVI-SAM's params_camera.yaml (VINS-Mono's format, camodocs camera models) -> the image topic, the camera
// intrinsics and T_imu_cam, the visual front end (`visual:`) and the sliding window (`vio:`).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "io/error.hpp"
#include "io/lvi_sam_parts.hpp"
#include "io/text_parsing.hpp"

namespace drover::io::lvisam {
namespace {

// The numbers `keys` (source key under `section`, Drover key it sets) of a camera model, each recorded as mapped.
std::vector<double> values(ParamFile& f, Output& o, const std::string& section,
                           const std::vector<std::pair<const char*, const char*>>& keys, const Range& range) {
  std::vector<double> v;
  for (const auto& [k, target] : keys) {
    const std::string key = section + "." + k;
    const auto x = f.number(key, range);
    if (!x) f.fail(section, "missing " + std::string(k) + " (the camera model needs it)");
    v.push_back(*x);
    o.map(f, key, std::string("calibration.camera.") + target);
  }
  return v;
}

void setIntrinsics(Output& o, const std::vector<double>& k, const char* model, const std::vector<double>& d,
                   const std::string& source) {
  const char* names[] = {"fx", "fy", "cx", "cy"};
  for (std::size_t i = 0; i < 4; ++i)
    o.tree.set(std::string("calibration.camera.") + names[i], yamlNumber(k[i]), "[px]");
  o.tree.set("calibration.camera.distortion_model", model, source);
  o.tree.set("calibration.camera.distortion_coeffs", yamlList(d, 0));
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

// PINHOLE (rad-tan) and KANNALA_BRANDT (equidistant: theta_d = theta + k2 theta^3 + ... + k5 theta^9, which is
// OpenCV's fisheye k1..k4) map to calibration.camera; MEI (unified omnidirectional, xi) and SCARAMUZZA have no
// counterpart, and a pinhole stand-in would be wrong at their fields of view: the images are then not loaded.
// Returns why the camera cannot be used, empty when it can.
std::string mapCameraModel(ParamFile& f, Output& o) {
  if (!f.has("model_type") && !f.has("projection_parameters")) return "the camera file gives no camera model";
  const std::string model = f.text("model_type").value_or("PINHOLE");  // camodocs' default
  const bool supported = model == "PINHOLE" || model == "KANNALA_BRANDT";
  for (const char* key : {"image_width", "image_height"}) {
    const auto v = f.integer(key, 1, 100000);
    if (!v) continue;
    const std::string target = std::string("calibration.camera.") + (key[6] == 'w' ? "width" : "height");
    if (supported) {
      o.tree.set(target, std::to_string(*v), std::string("[px] ") + key);
      o.map(f, key, target);
    } else {
      o.ignore(f, key, "belongs to the " + model + " camera model, which Drover cannot represent");
    }
  }
  if (model == "PINHOLE") {
    const auto k = values(f, o, "projection_parameters", {{"fx", "fx"}, {"fy", "fy"}, {"cx", "cx"}, {"cy", "cy"}},
                          positive("px"));
    const auto d = values(f, o, "distortion_parameters",
                          {{"k1", "distortion_coeffs[0]"}, {"k2", "distortion_coeffs[1]"},
                           {"p1", "distortion_coeffs[2]"}, {"p2", "distortion_coeffs[3]"}},
                          Range{});
    setIntrinsics(o, k, "radial-tangential", d, "model_type PINHOLE");
    if (f.has("model_type")) o.map(f, "model_type", "calibration.camera.distortion_model: radial-tangential");
    return "";
  }
  if (model == "KANNALA_BRANDT") {
    const auto p = values(f, o, "projection_parameters", {{"mu", "fx"}, {"mv", "fy"}, {"u0", "cx"}, {"v0", "cy"}},
                          positive("px"));
    const auto d = values(f, o, "projection_parameters",
                          {{"k2", "distortion_coeffs[0]"}, {"k3", "distortion_coeffs[1]"},
                           {"k4", "distortion_coeffs[2]"}, {"k5", "distortion_coeffs[3]"}},
                          Range{});
    setIntrinsics(o, p, "equidistant", d, "model_type KANNALA_BRANDT");
    o.map(f, "model_type", "calibration.camera.distortion_model: equidistant");
    return "";
  }
  o.ignore(f, "model_type",
           "model_type " + model +
               ": Drover's cameras are pinhole (rad-tan) or equidistant; this model cannot be represented, so "
               "images are not loaded (load_images: false) and the run is lidar-inertial");
  for (const std::string& key : f.unused())
    if (startsWith(key, "mirror_parameters") || startsWith(key, "distortion_parameters") ||
        startsWith(key, "projection_parameters"))
      o.ignore(f, key, "belongs to the " + model + " camera model, which Drover cannot represent");
  return "the " + model + " camera model cannot be represented (see the parameters not imported)";
}

// extrinsicRotation = imu^R_cam, extrinsicTranslation = imu^t_cam: T_imu_cam directly.
void mapExtrinsics(ParamFile& f, Output& o) {
  const auto rot = f.numbers("extrinsicRotation", 9);
  const auto trans = f.numbers("extrinsicTranslation", 3);
  if (!rot && !trans) return;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (rot) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = (*rot)[static_cast<std::size_t>(3 * r + c)];
    checkedRotation(R, f.path(), f.record("extrinsicRotation"));
  }
  const std::vector<double> t = trans ? *trans : std::vector<double>{0, 0, 0};
  std::vector<double> m;
  for (int r = 0; r < 3; ++r) m.insert(m.end(), {R(r, 0), R(r, 1), R(r, 2), t[static_cast<std::size_t>(r)]});
  m.insert(m.end(), {0, 0, 0, 1});
  o.tree.note("calibration.T_imu_cam", "VINS: extrinsicRotation = imu^R_cam, extrinsicTranslation = imu^t_cam [m]");
  o.tree.set("calibration.T_imu_cam", yamlList(m, 4));
  if (rot) o.map(f, "extrinsicRotation", "calibration.T_imu_cam (rotation)");
  if (trans) o.map(f, "extrinsicTranslation", "calibration.T_imu_cam (translation)");
}

// acc_n ... g_norm: Drover has one IMU noise model for the LIS and the VIS (odometry.imu); the lidar file's
// values, which LIO-SAM's preintegration uses, take precedence.
void mapImuNoise(ParamFile& f, Output& o, bool have_lidar_noise) {
  const std::pair<const char*, const char*> keys[] = {{"acc_n", "acc_noise_density"},
                                                      {"gyr_n", "gyro_noise_density"},
                                                      {"acc_w", "acc_bias_random_walk"},
                                                      {"gyr_w", "gyro_bias_random_walk"},
                                                      {"g_norm", "gravity"}};
  for (const auto& [key, target] : keys) {
    if (!f.has(key)) continue;
    const std::string path = std::string("odometry.imu.") + target;
    if (have_lidar_noise && o.tree.has(path)) {
      o.ignore(f, key, "Drover has one IMU noise model for the LIS and the VIS: " + path +
                           " comes from the lidar file (LIO-SAM's)");
      continue;
    }
    const double v = *f.number(key, std::string(key) == "g_norm" ? positive("m/s^2") : atLeast(0, ""));
    o.tree.set(path, yamlNumber(v), std::string(key) + " (VINS)");
    o.map(f, key, path);
  }
}

void mapFrontEnd(ParamFile& f, Output& o) {
  if (const auto n = f.integer("max_cnt", 1, 100000)) {
    o.tree.set("visual.detector.type", "shi-tomasi", "as LVI-SAM (cv::goodFeaturesToTrack); superpoint needs weights");
    o.tree.set("visual.detector.shi_tomasi.max_cnt", std::to_string(*n), "max_cnt");
    o.tree.set("visual.tracker.max_features", std::to_string(*n), "max_cnt");
    o.map(f, "max_cnt", "visual.detector.shi_tomasi.max_cnt, visual.tracker.max_features");
  }
  if (const auto d = f.number("min_dist", atLeast(0, "px"))) {
    o.tree.set("visual.detector.shi_tomasi.min_dist", yamlNumber(*d), "[px] min_dist");
    o.tree.set("visual.tracker.min_distance", yamlNumber(*d), "[px] min_dist");
    o.map(f, "min_dist", "visual.detector.shi_tomasi.min_dist, visual.tracker.min_distance");
  }
  if (const auto t = f.number("F_threshold", positive("px"))) {
    o.tree.set("visual.tracker.ransac_threshold_px", yamlNumber(*t), "[px at virtual_focal_px 460] F_threshold");
    o.map(f, "F_threshold", "visual.tracker.ransac_threshold_px");
  }
  if (const auto eq = f.flag("equalize")) {
    o.tree.set("visual.tracker.clahe", *eq ? "always" : "off", "equalize (CLAHE on every frame)");
    o.map(f, "equalize", std::string("visual.tracker.clahe: ") + (*eq ? "always" : "off"));
  }
  if (const auto fe = f.flag("fisheye")) {
    if (*fe)
      o.ignore(f, "fisheye", "Drover applies no image mask (fisheye_mask); tracks near the border are dropped "
                             "by visual.tracker.border_px");
    else
      o.map(f, "fisheye", "0: no mask, as Drover (no key needed)");
  }
}

void mapWindow(ParamFile& f, Output& o) {
  if (const auto s = f.number("max_solver_time", positive("s"))) {
    o.tree.set("vio.max_solver_ms", yamlNumber(*s * 1000.0), "[ms] max_solver_time (VINS takes it in seconds)");
    o.map(f, "max_solver_time", "vio.max_solver_ms (x 1000)");
  }
  if (const auto n = f.integer("max_num_iterations", 1, 100000)) {
    o.tree.set("vio.max_iterations", std::to_string(*n), "max_num_iterations");
    o.map(f, "max_num_iterations", "vio.max_iterations");
  }
  if (const auto p = f.number("keyframe_parallax", positive("px"))) {
    o.tree.set("vio.min_parallax_px", yamlNumber(*p), "[px at focal 460] keyframe_parallax");
    o.map(f, "keyframe_parallax", "vio.min_parallax_px");
  }
  if (const auto e = f.integer("estimate_extrinsic", 0, 2)) {
    o.tree.set("vio.estimate_extrinsic", *e ? "true" : "false", "estimate_extrinsic " + std::to_string(*e));
    o.map(f, "estimate_extrinsic", *e == 2 ? "vio.estimate_extrinsic: true (2, calibration from nothing, is not "
                                             "supported: refined from T_imu_cam)"
                                           : "vio.estimate_extrinsic");
  }
  if (const auto e = f.flag("estimate_td")) {
    o.tree.set("vio.estimate_time_offset", *e ? "true" : "false", "estimate_td");
    o.map(f, "estimate_td", "vio.estimate_time_offset");
  }
  if (const auto td = f.number("td", between(-3600, 3600, "s"))) {
    o.tree.set("calibration.camera_time_offset", yamlNumber(*td), "[s] td: t_imu = t_image + td");
    o.map(f, "td", "calibration.camera_time_offset");
  }
  if (const auto l = f.flag("use_lidar")) {
    o.tree.set("vio.depth_mode", *l ? "fixed" : "off", "use_lidar (LVI-SAM holds a lidar depth fixed)");
    o.map(f, "use_lidar", std::string("vio.depth_mode: ") + (*l ? "fixed" : "off"));
  }
  if (const auto rs = f.flag("rolling_shutter")) {
    if (*rs) {
      o.ignore(f, "rolling_shutter", "Drover models a global shutter");
    } else {
      o.map(f, "rolling_shutter", "0: global shutter, as Drover (no key needed)");
      if (f.has("rolling_shutter_tr")) o.map(f, "rolling_shutter_tr", "unused with rolling_shutter 0");
    }
  }
}

}  // namespace

void mapCameraFile(ParamFile& f, Output& o, bool have_lidar_file) {
  if (const auto t = f.text("image_topic")) {
    o.tree.set("dataset.image_topic", yamlString(*t), "image_topic");
    o.map(f, "image_topic", "dataset.image_topic");
  }
  if (const auto t = f.text("imu_topic")) {
    if (o.imu_topic.empty()) {
      o.tree.set("dataset.imu_topic", yamlString(*t), "imu_topic");
      o.map(f, "imu_topic", "dataset.imu_topic");
    } else if (*t == o.imu_topic) {
      o.map(f, "imu_topic", "dataset.imu_topic (the same as the lidar file's imuTopic)");
    } else {
      o.ignore(f, "imu_topic", "differs from the lidar file's imuTopic " + echo(o.imu_topic) +
                                   ", which dataset.imu_topic took: Drover reads one IMU topic");
    }
  }
  const std::string unusable = mapCameraModel(f, o);
  o.tree.set("dataset.load_images", unusable.empty() ? "true" : "false", unusable);
  mapExtrinsics(f, o);
  mapImuNoise(f, o, have_lidar_file);
  mapFrontEnd(f, o);
  mapWindow(f, o);
}

}  // namespace drover::io::lvisam
