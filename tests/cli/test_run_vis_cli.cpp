// `drover run` with a camera, end to end: the VIS alone (--no-lidar, visual-inertial initialisation) and beside the
// LIS (initialised from it, lidar depth) on a simulated straight course that starts at rest and accelerates; and the
// nearly still EuRoC snippet, on which the visual-inertial initialisation must refuse and say that it needs motion.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/edited_config.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

// A platform config with the Shi-Tomasi detector (SuperPoint costs ~0.4 s a frame on these cores).
std::string shiTomasiConfig(const std::string& name, const fs::path& dir) {
  return editedConfig(name, dir, {{"type: superpoint ", "type: shi-tomasi "}});
}

// Path length of the ground truth between two times [s] and the estimate's displacement over the same span.
struct Displacement {
  double truth = 0, estimate = 0;
};
Displacement displacement(const Trajectory& est, const Trajectory& gt) {
  Displacement d;
  if (est.size() < 2) return d;
  auto at = [&gt](Time t) {
    const StampedPose* best = &gt.front();
    for (const StampedPose& p : gt)
      if (std::abs(p.t - t) < std::abs(best->t - t)) best = &p;
    return best->T_world_body.translation();
  };
  d.truth = (at(est.back().t) - at(est.front().t)).norm();
  d.estimate = (est.back().T_world_body.translation() - est.front().T_world_body.translation()).norm();
  return d;
}

// The simulated straight course (at rest for 2 s, then pulling away at 0.4 m/s^2): 7 s at 15 Hz.
CliResult simulate(const TempDir& dir) {
  return runDrover("sim -q --scenario straight --duration 7 --camera-rate 15 --out " + (dir / "straight").string());
}

std::string runArgs(const TempDir& dir) {
  return "run " + (dir / "straight").string() + " --format sim --config " +
         shiTomasiConfig("farm_sim.yaml", dir.path()) + " --no-loop";
}

// One test per run (each test is its own process under ctest, so a shared fixture would simulate again anyway).
TEST(VisRun, NoLidarRunsTheVisAloneAtMetricScaleAndWritesItsTrajectoryAndReport) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const CliResult vis = runDrover(runArgs(dir) + " --no-lidar --out " + (dir / "vis").string());
  ASSERT_EQ(vis.exit_code, 0) << vis.output;
  const Json r = readJson(dir / "vis" / "report.json");
  EXPECT_EQ(r["mode"], "camera+imu");
  const Json& v = r["vis"];
  EXPECT_TRUE(v["initialized"].get<bool>());
  EXPECT_NE(v["events"][0]["what"].get<std::string>().find("visual-inertial alignment"), std::string::npos);
  // One pose per frame after the start, trajectory.tum the same; no lidar, no map.
  const Trajectory est = io::readTum((dir / "vis" / "trajectory_vis.tum").string());
  EXPECT_EQ(est.size(), io::readTum((dir / "vis" / "trajectory.tum").string()).size());
  EXPECT_EQ(est.size(), v["frames_estimated"].get<std::size_t>());
  EXPECT_GT(est.size(), 40u);
  EXPECT_FALSE(std::filesystem::exists(dir / "vis" / "map.pcd"));
  // The report: ms per stage, tracking and keyframe counts; the frames one line each in vis_frames.jsonl, streamed
  // as they came (report.json holds no per-frame array: an hour's would be ~50,000 entries).
  for (const char* stage : {"track", "depth", "solve", "marginalize", "total"})
    EXPECT_TRUE(v["ms_per_frame"].contains(stage)) << stage;
  EXPECT_FALSE(v.contains("frames"));
  EXPECT_GT(v["mean"]["tracked"].get<double>(), 30.0);
  EXPECT_GT(v["keyframes"].get<int>(), 5);
  const Json frames = readJsonLines(dir / "vis" / "vis_frames.jsonl");
  ASSERT_EQ(frames.size(), v["frames_in"].get<std::size_t>());
  std::size_t initialised = 0, keyframes = 0;
  double tracked = 0;
  for (const Json& f : frames) {
    initialised += f["initialized"].get<bool>() ? 1 : 0;
    keyframes += f["keyframe"].get<bool>() ? 1 : 0;
    tracked += f["tracked"].get<double>();
    EXPECT_TRUE(f["ms"].contains("solve")) << f;
    // the state behind each estimated pose: the simulated IMU's biases are (0.002, -0.001, 0.0015) rad/s and
    // (0.02, -0.03, 0.01) m/s^2, the straight drive's speed at most 1.2 m/s
    EXPECT_EQ(f.contains("acc_bias"), f["initialized"].get<bool>()) << f;
    if (!f["initialized"].get<bool>()) continue;
    EXPECT_EQ(f["acc_bias"].size(), 3u);
    EXPECT_LT(std::abs(f["gyro_bias"][0].get<double>() - 0.002), 0.005) << f;
    EXPECT_LT(f["speed"].get<double>(), 2.0) << f;
  }
  EXPECT_EQ(initialised, est.size()) << "a pose in trajectory_vis.tum for every initialised frame";
  EXPECT_EQ(keyframes, v["keyframes"].get<std::size_t>());
  EXPECT_NEAR(tracked / static_cast<double>(frames.size()), v["mean"]["tracked"].get<double>(), 1e-6);
  EXPECT_LT(frames.front()["t"].get<double>(), frames.back()["t"].get<double>());
  // Metric scale from the IMU alone: the displacement since the start within 5 %.
  const Displacement d = displacement(est, io::readTum((dir / "straight" / "groundtruth.txt").string()));
  ASSERT_GT(d.truth, 2.0);
  EXPECT_NEAR(d.estimate / d.truth, 1.0, 0.05) << d.estimate << " m estimated, " << d.truth << " m true";
}

// The corner top-up's record: ORB topped up below 200 tracks (more than max_features, so at every frame after the
// first): vis_frames.jsonl's corners_added, and report.json's corner_top_up sums of them.
TEST(VisRun, TheCornerTopUpIsRecordedPerFrameAndSummedInTheReport) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string config = editedConfig(
      "farm_sim.yaml", dir.path(), {{"type: superpoint ", "type: orb "}, {"top_up_below: 0 ", "top_up_below: 200 "}});
  const CliResult run = runDrover("run " + (dir / "straight").string() + " --format sim --config " + config +
                                  " --no-loop -q --out " + (dir / "run").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const Json v = readJson(dir / "run" / "report.json")["vis"];
  ASSERT_TRUE(v.contains("corner_top_up")) << v;
  EXPECT_EQ(v["corner_top_up"]["below"], 200);
  std::size_t frames = 0, corners = 0;
  for (const Json& f : readJsonLines(dir / "run" / "vis_frames.jsonl")) {
    frames += f["corners_added"].get<int>() > 0 ? 1 : 0;
    corners += f["corners_added"].get<std::size_t>();
  }
  EXPECT_GT(frames, 50u) << "the straight course has ~100 frames; the top-up acts wherever ORB leaves room";
  EXPECT_EQ(v["corner_top_up"]["frames"].get<std::size_t>(), frames);
  EXPECT_EQ(v["corner_top_up"]["corners"].get<std::size_t>(), corners);
}

TEST(VisRun, BesideTheLisTheVisStartsFromItAndUsesLidarDepth) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const CliResult lvi = runDrover(runArgs(dir) + " --out " + (dir / "lvi").string());
  ASSERT_EQ(lvi.exit_code, 0) << lvi.output;
  const Json r = readJson(dir / "lvi" / "report.json");
  EXPECT_EQ(r["mode"], "lidar+imu+camera");
  EXPECT_EQ(r["vis"]["events"][0]["what"].get<std::string>().rfind("initialised from the LIS (", 0), 0u)
      << r["vis"]["events"][0]["what"];
  EXPECT_GT(r["vis"]["mean"]["features_with_lidar_depth"].get<double>(), 20.0);
  const Displacement d = displacement(io::readTum((dir / "lvi" / "trajectory_vis.tum").string()),
                                      io::readTum((dir / "straight" / "groundtruth.txt").string()));
  EXPECT_NEAR(d.estimate / d.truth, 1.0, 0.03) << d.estimate << " m estimated, " << d.truth << " m true";
  EXPECT_TRUE(std::filesystem::exists(dir / "lvi" / "trajectory.tum"));  // the LIS's, as without a camera
  EXPECT_EQ(readJsonLines(dir / "lvi" / "vis_frames.jsonl").size(), r["vis"]["frames_in"].get<std::size_t>());
}

// The paper's comparison: --preset lvi-sam runs LVI-SAM's methods over the platform file (radius loops, no VO factor,
// fixed lidar depth, Shi-Tomasi) and says so in report.json; --without takes one part out after a preset.
TEST(VisRun, PresetLviSamRunsLviSamsMethodsAndReportJsonNamesThePresetAndThePartsTakenOut) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string base = "run " + (dir / "straight").string() + " --format sim --config " +
                           shiTomasiConfig("farm_sim.yaml", dir.path());
  const CliResult lvi = runDrover(base + " -q --preset lvi-sam --out " + (dir / "lvi").string());
  ASSERT_EQ(lvi.exit_code, 0) << lvi.output;
  const Json r = readJson(dir / "lvi" / "report.json");
  EXPECT_EQ(r["preset"], "lvi-sam");
  EXPECT_EQ(r["loops"]["source"], "radius");
  EXPECT_EQ(r["loops"]["graph_dof"], 6) << "LIO-SAM's keyframe graph corrects all six degrees of freedom";
  EXPECT_EQ(r["loops"]["sigma_fitness_reference_m"], 0.0);
  EXPECT_EQ(r["vis"]["depth_mode"], "fixed");
  EXPECT_EQ(r["vis"]["detector"], "shi-tomasi");
  EXPECT_EQ(r["vis"]["lk_min_eigenvalue"], 1e-4) << "OpenCV's default, as LVI-SAM's tracker";
  EXPECT_FALSE(r["vis"].contains("corner_top_up")) << "Shi-Tomasi is the corners already";
  EXPECT_EQ(r["counts"]["vis_factor_scans"], 0) << "LVI-SAM's released code has no visual odometry factor";
  EXPECT_GT(r["counts"]["vis_guess_scans"].get<int>(), 20);
  const CliResult nf = runDrover(base + " -q --no-loop --preset drover --without superpoint --without vo-factor "
                                 "--out " + (dir / "nf").string());
  ASSERT_EQ(nf.exit_code, 0) << nf.output;
  const Json n = readJson(dir / "nf" / "report.json");
  EXPECT_EQ(n["preset"], "drover without superpoint, vo-factor");
  EXPECT_EQ(n["vis"]["depth_mode"], "factor");
  EXPECT_EQ(n["vis"]["lk_min_eigenvalue"], 1e-4) << "Shi-Tomasi's tracks keep the platform's LK threshold";
  EXPECT_EQ(n["counts"]["vis_factor_scans"], 0);
  EXPECT_EQ(n["loops"]["graph_dof"], 4) << "the drover preset's pose graph leaves roll and pitch to the IMU";
  const CliResult bad = runDrover(base + " --preset vins --out " + (dir / "bad").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--preset"), std::string::npos) << bad.output;
  const CliResult part = runDrover(base + " --without loops --out " + (dir / "bad").string());
  EXPECT_EQ(part.exit_code, 2) << part.output;
  EXPECT_NE(part.output.find("--without"), std::string::npos) << part.output;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

// The drover preset searches both loop sources (Scan Context and the 15 m radius search) whatever the platform file
// names, in a 4-DoF graph; --without radius-search leaves Scan Context alone, --without scan-context the radius
// search alone, --without four-dof the 6-DoF graph. Its loops' covariances widen with their fits' residuals
// (--without loop-fitness-sigma: the fit and the floors alone); its edges yield by the VIS's sigma where the VIS
// carried a degenerate sweep (--without vis-carried-sigma: as tight as the lidar's).
TEST(VisRun, PresetDroverSearchesBothLoopSourcesInAFourDofGraphAndTheAblationTakesEachOut) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  std::ifstream in(shiTomasiConfig("farm_sim.yaml", dir.path()));
  std::stringstream text;
  text << in.rdbuf();
  const std::string yaml = text.str();
  const std::string from = "source: scancontext";
  const auto at = yaml.find(from);
  ASSERT_NE(at, std::string::npos) << "farm_sim.yaml no longer names its loop source";
  std::string radius_yaml = yaml;
  radius_yaml.replace(at, from.size(), "source: radius");
  writeText(dir / "radius.yaml", radius_yaml);
  struct Case {
    std::string name, config, without, source;
    int dof;
    double fitness_reference = 0.05;  // [m]
    double vis_carried_sigma = 0.1;   // [m or rad a sweep]
  };
  const std::vector<Case> cases = {
      {"sc_file", shiTomasiConfig("farm_sim.yaml", dir.path()), "", "both", 4},
      {"radius_file", (dir / "radius.yaml").string(), "", "both", 4},
      {"no_radius", (dir / "radius.yaml").string(), "--without radius-search", "scancontext", 4},
      {"no_sc", (dir / "radius.yaml").string(), "--without scan-context", "radius", 4},
      {"six_dof", (dir / "radius.yaml").string(), "--without four-dof", "both", 6},
      {"no_fitness", (dir / "radius.yaml").string(), "--without loop-fitness-sigma", "both", 4, 0.0},
      {"no_vis_sigma", (dir / "radius.yaml").string(), "--without vis-carried-sigma", "both", 4, 0.05, 0.0}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const CliResult r = runDrover("run " + (dir / "straight").string() + " --format sim --config " + c.config +
                                  " --no-camera -q --preset drover " + c.without + " --out " + (dir / c.name).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Json loops = readJson(dir / c.name / "report.json")["loops"];
    EXPECT_EQ(loops["source"], c.source);
    EXPECT_EQ(loops["graph_dof"], c.dof);
    EXPECT_EQ(loops["radius_m"], 15.0) << "LIO-SAM's historyKeyframeSearchRadius (Drover's own default is 10 m)";
    EXPECT_EQ(loops["sigma_fitness_reference_m"], c.fitness_reference) << "a loop's covariance widens with its fit";
    EXPECT_EQ(loops["vis_carried_sigma"], c.vis_carried_sigma);
  }
}

// SuperPoint's weights are a separate download: a run whose weights are missing goes on with Shi-Tomasi, and says so
// even under -q (a run that quietly used another detector would be misread), and report.json names the detector.
TEST(VisRun, MissingSuperPointWeightsFallBackToShiTomasiAndSayItEvenWhenQuiet) {
  TempDir dir;
  const CliResult sim = simulate(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  std::ifstream in(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string from = "weights: ../shared/models/superpoint_v1.onnx";
  const auto at = yaml.find(from);
  ASSERT_NE(at, std::string::npos) << "farm_sim.yaml no longer names the shared weights";
  yaml.replace(at, from.size(), "weights: no_such_weights.onnx");
  writeText(dir / "missing_weights.yaml", yaml);
  const CliResult r = runDrover("run " + (dir / "straight").string() + " --format sim --config " +
                                (dir / "missing_weights.yaml").string() + " --no-lidar --no-loop -q --out " +
                                (dir / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("SuperPoint cannot start"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no_such_weights.onnx"), std::string::npos) << r.output;
  EXPECT_EQ(readJson(dir / "run" / "report.json")["vis"]["detector"], "shi-tomasi (SuperPoint unavailable)");
}

TEST(VisRunRefuses, NoLidarWithNoCameraIsAnErrorBeforeAnyWork) {
  TempDir dir;
  const CliResult r = runDrover("run " + dir.path().string() + " --format sim --no-lidar --no-camera --out " +
                                (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "--no-lidar with --no-camera")) << r.output;
}

TEST(VisRunRefuses, NoLidarWithNoImuIsAnErrorBeforeAnyWork) {
  TempDir dir;
  const CliResult r = runDrover("run " + dir.path().string() + " --format sim --no-lidar --no-imu --out " +
                                (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "--no-lidar with --no-imu")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(VisRunRefuses, TheStillEurocSnippetIsNotInitialisedAndTheRunSaysItNeedsMotion) {
  const fs::path seq = sharedData("euroc/V1_01_easy_micro");
  if (!fs::exists(seq)) GTEST_SKIP() << "needs ../shared/data/euroc/V1_01_easy_micro (not present)";
  TempDir dir;
  const std::string config = shiTomasiConfig("euroc.yaml", dir.path());
  const CliResult r = runDrover("run " + seq.string() + " --format euroc --config " + config + " --no-lidar --out " +
                                (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "did not initialise")) << r.output;
  EXPECT_TRUE(contains(r.output, "need motion") || contains(r.output, "not enough motion")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));  // no run folder for a run that produced no pose
}

}  // namespace
}  // namespace drover::test
