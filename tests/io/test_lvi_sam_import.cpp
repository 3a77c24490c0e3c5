// LIO-SAM / LVI-SAM parameter files -> a platform config (io/lvi_sam_import.hpp): known answers for the extrinsic
// conventions (config/lvisam.yaml documents LVI-SAM's own), the IMU noise, topics, camera models and the VINS
// settings; every key of a file is either mapped or listed with a reason; bad input is an IoError naming file,
// line and key. Fixtures: tests/fixtures/lvi_sam/ (LVI-SAM's shipped parameter files' keys and values).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "io/error.hpp"
#include "io/lvi_sam_import.hpp"
#include "io/text_parsing.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

const fs::path kFixtures = fs::path(DROVER_SOURCE_DIR) / "tests" / "fixtures" / "lvi_sam";
const std::string kLidar = (kFixtures / "params_lidar.yaml").string();
const std::string kCamera = (kFixtures / "params_camera.yaml").string();

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The generated config loaded as the platform loaders load it (calibration and dataset).
DatasetOptions datasetOf(const LviSamImport& r) {
  test::TempDir dir;
  test::writeText(dir / "platform.yaml", r.yaml);
  return loadDatasetOptions((dir / "platform.yaml").string());
}

YAML::Node at(const LviSamImport& r, const std::string& dotted) {
  YAML::Node n = YAML::Load(r.yaml);
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', begin);
    const YAML::Node child = n[dotted.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin)];
    n.reset(child);
    if (!n || dot == std::string::npos) return n;
    begin = dot + 1;
  }
}

const LviSamKey* find(const std::vector<LviSamKey>& keys, const std::string& key) {
  const auto it = std::find_if(keys.begin(), keys.end(), [&](const LviSamKey& k) { return k.key == key; });
  return it == keys.end() ? nullptr : &*it;
}

LviSamImport importText(const std::string& text, const std::string& name = "params.yaml") {
  return importLviSam({{name, text}});
}

std::string errorOf(const std::vector<LviSamFile>& files) {
  try {
    importLviSam(files);
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an IoError";
  return {};
}

// Leaf keys of a parameter file as the importer counts them (an !!opencv-matrix is one).
std::size_t leafCount(const YAML::Node& n) {
  if (!n.IsMap() || (n["rows"] && n["data"])) return 1;
  std::size_t count = 0;
  for (const auto& kv : n) count += leafCount(kv.second);
  return count;
}

TEST(LviSamImport, LviSamsShippedExtrinsicsGiveExactlyTheTransformsConfigLvisamDocuments) {
  const LviSamImport r = importLviSamFiles({kLidar, kCamera});
  const DatasetOptions got = datasetOf(r);
  const DatasetOptions doc = loadDatasetOptions(std::string(DROVER_SOURCE_DIR) + "/config/lvisam.yaml");
  EXPECT_TRUE(got.calibration.T_imu_lidar.matrix().isApprox(doc.calibration.T_imu_lidar.matrix(), 1e-15))
      << got.calibration.T_imu_lidar.matrix();
  EXPECT_TRUE(got.calibration.T_imu_cam.matrix().isApprox(doc.calibration.T_imu_cam.matrix(), 1e-15))
      << got.calibration.T_imu_cam.matrix();
  EXPECT_EQ(got.lidar_topic, "/points_raw");
  EXPECT_EQ(got.imu_topic, "/imu_raw");
  EXPECT_EQ(got.image_topic, "/camera/image_raw");
  EXPECT_EQ(got.calibration.camera_time_offset, 0);
}

// The shipped platform file for LVI-SAM's bags holds the sensor settings the importer takes from LVI-SAM's files:
// without them its bags ran on the farm robot's IMU noise (imuGyrNoise 1.6e-3 against 1.7e-4) and took the
// MicroStrain's orientation output as the IMU frame's.
TEST(LviSamImport, ConfigLvisamHoldsTheImuNoiseTheOrientationFlagAndTheLayoutLviSamsFilesGive) {
  const LviSamImport r = importLviSamFiles({kLidar, kCamera});
  const YAML::Node doc = YAML::LoadFile(std::string(DROVER_SOURCE_DIR) + "/config/lvisam.yaml");
  for (const char* key : {"acc_noise_density", "gyro_noise_density", "acc_bias_random_walk", "gyro_bias_random_walk",
                          "gravity"}) {
    SCOPED_TRACE(key);
    ASSERT_TRUE(doc["odometry"]["imu"][key]);
    EXPECT_EQ(doc["odometry"]["imu"][key].as<double>(), at(r, std::string("odometry.imu.") + key).as<double>());
  }
  ASSERT_TRUE(doc["odometry"]["use_imu_orientation"]);
  EXPECT_EQ(doc["odometry"]["use_imu_orientation"].as<bool>(), at(r, "odometry.use_imu_orientation").as<bool>());
  EXPECT_EQ(doc["odometry"]["layout"]["n_rings"].as<int>(), at(r, "odometry.layout.n_rings").as<int>());
  EXPECT_EQ(doc["odometry"]["layout"]["columns"].as<int>(), at(r, "odometry.layout.columns").as<int>());
  EXPECT_EQ(doc["odometry"]["features"]["columns"].as<int>(), at(r, "odometry.features.columns").as<int>());
}

TEST(LviSamImport, ExtrinsicRotAndTransAreRLidarImuAndTheImuOriginInTheLidarFrame) {
  // R_lidar_imu = Rz(+90 deg), IMU origin at (1, 2, 3) in the lidar frame.
  const LviSamImport r = importText(
      "lio_sam:\n  extrinsicRot: [0, -1, 0, 1, 0, 0, 0, 0, 1]\n  extrinsicRPY: [0, -1, 0, 1, 0, 0, 0, 0, 1]\n"
      "  extrinsicTrans: [1, 2, 3]\n");
  const Eigen::Isometry3d T_imu_lidar = datasetOf(r).calibration.T_imu_lidar;
  Eigen::Matrix4d expected;
  expected << 0, 1, 0, -2,  //
      -1, 0, 0, 1,          //
      0, 0, 1, -3,          //
      0, 0, 0, 1;
  EXPECT_TRUE(T_imu_lidar.matrix().isApprox(expected, 1e-15)) << T_imu_lidar.matrix();
  // An IMU x-axis vector is the lidar's +y (extrinsicRot), and the IMU origin sits at extrinsicTrans.
  EXPECT_TRUE((T_imu_lidar.inverse().linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE((T_imu_lidar.inverse() * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_FALSE(at(r, "odometry.use_imu_orientation")) << "extrinsicRPY equals extrinsicRot: orientation usable";
}

TEST(LviSamImport, AnOrientationFrameOtherThanTheImusTurnsTheUnitsOrientationOff) {
  // LVI-SAM's MicroStrain: extrinsicRPY differs from extrinsicRot.
  const LviSamImport r = importLviSamFiles({kLidar});
  ASSERT_TRUE(at(r, "odometry.use_imu_orientation"));
  EXPECT_FALSE(at(r, "odometry.use_imu_orientation").as<bool>());
  ASSERT_NE(find(r.mapped, "lvi_sam.extrinsicRPY"), nullptr);
}

TEST(LviSamImport, ImuNoiseLidarLayoutFeaturesKeyframesAndLoopKeysKeepTheirValues) {
  const LviSamImport r = importLviSamFiles({kLidar});
  EXPECT_EQ(at(r, "odometry.imu.acc_noise_density").as<double>(), 3.9939570888238808e-03);
  EXPECT_EQ(at(r, "odometry.imu.gyro_noise_density").as<double>(), 1.5636343949698187e-03);
  EXPECT_EQ(at(r, "odometry.imu.acc_bias_random_walk").as<double>(), 6.4356659353532566e-05);
  EXPECT_EQ(at(r, "odometry.imu.gyro_bias_random_walk").as<double>(), 3.5640318696367613e-05);
  EXPECT_EQ(at(r, "odometry.imu.gravity").as<double>(), 9.80511);
  EXPECT_EQ(at(r, "odometry.layout.n_rings").as<int>(), 16);
  EXPECT_EQ(at(r, "odometry.layout.columns").as<int>(), 1800);
  EXPECT_EQ(at(r, "odometry.features.columns").as<int>(), 1800);
  EXPECT_EQ(at(r, "odometry.features.edge_threshold").as<double>(), 1.0);
  EXPECT_EQ(at(r, "odometry.features.surf_threshold").as<double>(), 0.1);
  EXPECT_EQ(at(r, "odometry.features.surf_leaf").as<double>(), 0.4);
  EXPECT_EQ(at(r, "odometry.local_map.edge_leaf").as<double>(), 0.2);
  EXPECT_EQ(at(r, "odometry.local_map.plane_leaf").as<double>(), 0.4);
  EXPECT_EQ(at(r, "odometry.local_map.keyframe_density").as<double>(), 2.0);
  EXPECT_EQ(at(r, "odometry.local_map.surrounding_radius").as<double>(), 50.0);
  EXPECT_EQ(at(r, "odometry.matcher.min_edge_features").as<int>(), 10);
  EXPECT_EQ(at(r, "odometry.matcher.min_plane_features").as<int>(), 100);
  EXPECT_EQ(at(r, "odometry.keyframes.distance").as<double>(), 1.0);
  EXPECT_EQ(at(r, "odometry.keyframes.angle").as<double>(), 0.2);
  EXPECT_TRUE(at(r, "loop.enabled").as<bool>());
  EXPECT_EQ(at(r, "loop.radius").as<double>(), 20.0);
  EXPECT_EQ(at(r, "loop.min_age").as<double>(), 30.0);
  EXPECT_EQ(at(r, "loop.submap_keyframes").as<int>(), 25);
  EXPECT_TRUE(at(r, "dataset.load_lidar").as<bool>());
  EXPECT_FALSE(at(r, "dataset.load_images").as<bool>()) << "no camera file: LIO-SAM has no camera";
}

TEST(LviSamImport, LioSamsRangeLimitsReachLayoutAndFeaturesAlsoUnderRos2sNamespace) {
  for (const std::string ns : {"lio_sam:\n", "/**:\n  ros__parameters:\n"}) {
    SCOPED_TRACE(ns);
    const std::string indent = ns.size() > 10 ? "    " : "  ";
    const LviSamImport r =
        importText(ns + indent + "lidarMinRange: 0.5\n" + indent + "lidarMaxRange: 12.0\n" + indent + "N_SCAN: 32\n");
    for (const char* section : {"layout", "features"}) {
      EXPECT_EQ(at(r, std::string("odometry.") + section + ".min_range").as<double>(), 0.5);
      EXPECT_EQ(at(r, std::string("odometry.") + section + ".max_range").as<double>(), 12.0);
    }
    EXPECT_EQ(at(r, "odometry.layout.n_rings").as<int>(), 32);
  }
}

TEST(LviSamImport, TheMeiCameraIsListedAsNotRepresentableAndImagesAreNotLoaded) {
  const LviSamImport r = importLviSamFiles({kLidar, kCamera});
  const LviSamKey* model = find(r.ignored, "model_type");
  ASSERT_NE(model, nullptr);
  EXPECT_TRUE(has(model->note, "MEI")) << model->note;
  EXPECT_TRUE(has(model->note, "cannot be represented")) << model->note;
  for (const char* k :
       {"mirror_parameters.xi", "projection_parameters.gamma1", "distortion_parameters.p2", "image_width"})
    EXPECT_NE(find(r.ignored, k), nullptr) << k;
  EXPECT_FALSE(at(r, "dataset.load_images").as<bool>());
  EXPECT_FALSE(at(r, "calibration.camera"));
}

TEST(LviSamImport, PinholeAndKannalaBrandtCamerasMapToRadTanAndEquidistantIntrinsics) {
  const LviSamImport pin = importText(
      "%YAML:1.0\nmodel_type: PINHOLE\nimage_width: 640\nimage_height: 480\ndistortion_parameters:\n"
      "   k1: -0.28\n   k2: 0.07\n   p1: 0.0002\n   p2: 0.00002\nprojection_parameters:\n"
      "   fx: 461.6\n   fy: 460.3\n   cx: 363.0\n   cy: 248.1\n",
      "cam.yaml");
  CameraIntrinsics c = datasetOf(pin).calibration.camera;
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.fx, 461.6);
  EXPECT_EQ(c.fy, 460.3);
  EXPECT_EQ(c.cx, 363.0);
  EXPECT_EQ(c.cy, 248.1);
  EXPECT_EQ(c.distortion, DistortionModel::kRadialTangential);
  EXPECT_EQ(c.distortion_coeffs, (std::vector<double>{-0.28, 0.07, 0.0002, 0.00002}));
  EXPECT_TRUE(at(pin, "dataset.load_images").as<bool>());

  const LviSamImport kb = importText(
      "%YAML:1.0\nmodel_type: KANNALA_BRANDT\nimage_width: 752\nimage_height: 480\nprojection_parameters:\n"
      "   k2: 0.01\n   k3: -0.002\n   k4: 0.0003\n   k5: -0.00004\n   mu: 355.5\n   mv: 354.4\n"
      "   u0: 376.1\n   v0: 240.2\n",
      "cam.yaml");
  c = datasetOf(kb).calibration.camera;
  EXPECT_EQ(c.distortion, DistortionModel::kEquidistant);
  EXPECT_EQ(c.fx, 355.5);
  EXPECT_EQ(c.fy, 354.4);
  EXPECT_EQ(c.cx, 376.1);
  EXPECT_EQ(c.cy, 240.2);
  EXPECT_EQ(c.distortion_coeffs, (std::vector<double>{0.01, -0.002, 0.0003, -0.00004}));
}

TEST(LviSamImport, VinsSettingsReachTheFrontEndTheWindowAndTheTimeOffset) {
  const LviSamImport r = importLviSamFiles({kLidar, kCamera});
  EXPECT_EQ(at(r, "visual.detector.type").as<std::string>(), "shi-tomasi");
  EXPECT_EQ(at(r, "visual.detector.shi_tomasi.max_cnt").as<int>(), 150);
  EXPECT_EQ(at(r, "visual.tracker.max_features").as<int>(), 150);
  EXPECT_EQ(at(r, "visual.tracker.min_distance").as<double>(), 20.0);
  EXPECT_EQ(at(r, "visual.tracker.ransac_threshold_px").as<double>(), 1.0);
  EXPECT_EQ(at(r, "visual.tracker.clahe").as<std::string>(), "always");
  EXPECT_EQ(at(r, "vio.max_solver_ms").as<double>(), 35.0);  // max_solver_time 0.035 s
  EXPECT_EQ(at(r, "vio.max_iterations").as<int>(), 10);
  EXPECT_EQ(at(r, "vio.min_parallax_px").as<double>(), 10.0);
  EXPECT_FALSE(at(r, "vio.estimate_extrinsic").as<bool>());
  EXPECT_FALSE(at(r, "vio.estimate_time_offset").as<bool>());
  EXPECT_EQ(at(r, "vio.depth_mode").as<std::string>(), "fixed");
  const LviSamImport td = importText("%YAML:1.0\nimage_topic: /cam\ntd: -0.012\nestimate_td: 1\n", "cam.yaml");
  EXPECT_EQ(datasetOf(td).calibration.camera_time_offset, -12'000'000);  // [ns] t_imu = t_image + td
  EXPECT_TRUE(at(td, "vio.estimate_time_offset").as<bool>());
}

TEST(LviSamImport, TheLidarFilesImuNoiseWinsAndTheCameraFilesIsListedOtherwiseTheCamerasIsUsed) {
  const LviSamImport both = importLviSamFiles({kCamera, kLidar});  // order of the files does not matter
  EXPECT_EQ(at(both, "odometry.imu.acc_noise_density").as<double>(), 3.9939570888238808e-03);
  const LviSamKey* acc = find(both.ignored, "acc_n");
  ASSERT_NE(acc, nullptr);
  EXPECT_TRUE(has(acc->note, "one IMU noise model")) << acc->note;
  const LviSamImport camera = importLviSamFiles({kCamera});
  EXPECT_EQ(at(camera, "odometry.imu.acc_noise_density").as<double>(), 0.02);
  EXPECT_EQ(at(camera, "odometry.imu.gyro_bias_random_walk").as<double>(), 4.0e-5);
  EXPECT_EQ(at(camera, "odometry.imu.gravity").as<double>(), 9.805);
  EXPECT_EQ(at(camera, "dataset.imu_topic").as<std::string>(), "/imu_raw");
}

TEST(LviSamImport, EveryKeyOfTheShippedFilesIsEitherMappedOrListedWithAReason) {
  const LviSamImport r = importLviSamFiles({kLidar, kCamera});
  const std::size_t leaves =
      leafCount(YAML::Load(readYamlText(kLidar))) + leafCount(YAML::Load(readYamlText(kCamera)));
  EXPECT_EQ(r.mapped.size() + r.ignored.size(), leaves);
  for (const LviSamKey& k : r.ignored) {
    EXPECT_EQ(find(r.mapped, k.key), nullptr) << k.key << " is both mapped and ignored";
    EXPECT_FALSE(k.note.empty()) << k.key;
    EXPECT_FALSE(has(k.note, "not a LIO-SAM / LVI-SAM parameter")) << k.key << ": a shipped key must be known";
    EXPECT_TRUE(has(r.yaml, "#   " + k.file + ": " + k.key + " -- ")) << k.key << " missing from the YAML's list";
  }
  for (const char* k : {"PROJECT_NAME", "lvi_sam.savePCD", "lvi_sam.numberOfCores", "lvi_sam.surroundingKeyframeSize",
                        "lvi_sam.historyKeyframeFitnessScore", "lidar_to_cam_rz", "loop_closure", "point_cloud_topic"})
    EXPECT_NE(find(r.ignored, k), nullptr) << k;
}

TEST(LviSamImport, AnUnknownKeyIsListedAsUnknownAndNotMapped) {
  const LviSamImport r = importText("lvi_sam:\n  N_SCAN: 16\n  myOwnTweak: 3\n");
  const LviSamKey* k = find(r.ignored, "lvi_sam.myOwnTweak");
  ASSERT_NE(k, nullptr);
  EXPECT_TRUE(has(k->note, "not a LIO-SAM / LVI-SAM parameter the importer knows")) << k->note;
  EXPECT_EQ(r.mapped.size(), 1u);
}

TEST(LviSamImport, BadValuesAreErrorsNamingFileLineAndKey) {
  std::string e = errorOf({{"p.yaml", "lvi_sam:\n  imuTopic: /imu\n  N_SCAN: 0\n"}});
  EXPECT_TRUE(has(e, "p.yaml (line 3, key 'lvi_sam.N_SCAN')")) << e;
  e = errorOf({{"p.yaml", "lvi_sam:\n  extrinsicRot: [1, 0, 0, 0, 1, 0, 0, 0, 2]\n"}});
  EXPECT_TRUE(has(e, "'lvi_sam.extrinsicRot'")) << e;
  EXPECT_TRUE(has(e, "not orthonormal")) << e;
  e = errorOf({{"p.yaml", "lvi_sam:\n  extrinsicTrans: [0, 0]\n"}});
  EXPECT_TRUE(has(e, "expected 3 numbers, found 2")) << e;
  e = errorOf({{"c.yaml", "%YAML:1.0\nmodel_type: PINHOLE\nprojection_parameters:\n   fx: 400\n"}});
  EXPECT_TRUE(has(e, "c.yaml")) << e;
  EXPECT_TRUE(has(e, "missing fy")) << e;
  e = errorOf({{"c.yaml", "%YAML:1.0\nimage_topic: /c\nextrinsicTranslation: !!opencv-matrix\n   rows: 3\n"
                          "   cols: 1\n   dt: d\n   data: [1, 2]\n"}});
  EXPECT_TRUE(has(e, "3x1 matrix with 2 numbers")) << e;
}

TEST(LviSamImport, FilesOfNeitherKindTwoOfOneKindInvalidYamlAndDuplicateKeysAreErrors) {
  EXPECT_TRUE(has(errorOf({{"x.yaml", "foo: 1\n"}}), "neither a LIO-SAM/LVI-SAM lidar file"));
  const std::string two = errorOf({{"a.yaml", "lio_sam:\n  N_SCAN: 16\n"}, {"b.yaml", "lio_sam:\n  N_SCAN: 32\n"}});
  EXPECT_TRUE(has(two, "b.yaml")) << two;
  EXPECT_TRUE(has(two, "a second lidar parameter file (the first: a.yaml)")) << two;
  EXPECT_TRUE(has(errorOf({{"bad.yaml", "lio_sam:\n  N_SCAN: [16\n"}}), "bad.yaml (line"));
  const std::string dup = errorOf({{"d.yaml", "lio_sam:\n  N_SCAN: 16\n  N_SCAN: 32\n"}});
  EXPECT_TRUE(has(dup, "d.yaml (line 3, key 'N_SCAN'): duplicate key (first at line 2)")) << dup;
}

TEST(LviSamImport, AMissingFileIsAnErrorNamingIt) {
  try {
    importLviSamFiles({"/nonexistent/params_lidar.yaml"});
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_TRUE(has(e.what(), "/nonexistent/params_lidar.yaml: parameter file not found")) << e.what();
  }
}

}  // namespace
}  // namespace drover::io
