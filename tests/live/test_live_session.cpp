// live::LiveSession (apps/drover_ros/live_session.hpp), the ROS node's core without ROS: pipeline::System built from
// a platform config, its outputs, the map and path read while it runs, drover run's run folder, reset.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include "apps/drover/run_folder.hpp"
#include "apps/drover_ros/live_session.hpp"
#include "io/dataset.hpp"
#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A short simulated course (turns, no loop) and a platform config for it: config/farm_sim.yaml with the simulated
// robot's calibration (the `calibration:` block of the course's calibration.yaml).
struct Course {
  fs::path dir, config;
};

Course makeCourse(const TempDir& tmp) {
  Course c{tmp / "course", tmp / "platform.yaml"};
  const CliResult r = runDrover("sim --scenario sharp-turns --duration 6 --no-camera -q --out " + c.dir.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string calibration = readFile(c.dir / "calibration.yaml");
  const std::size_t begin = calibration.find("calibration:"), end = calibration.find("\nsensors:");
  EXPECT_NE(begin, std::string::npos);
  writeText(c.config, readFile(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml") + "\n" +
                          calibration.substr(begin, end - begin) + "\n");
  return c;
}

// Every measurement of the course pushed from one thread in time order, as fast as the reader gives them (the
// sweep queue holds them all: nothing is dropped).
void pushCourse(live::LiveSession& session, const fs::path& course, double until_s = 1e9) {
  io::DatasetOptions options;
  options.load_images = false;
  std::unique_ptr<io::Reader> reader = io::openDataset(course.string(), "sim", options);
  while (std::optional<Measurement> m = reader->next()) {
    if (toSeconds(measurementTime(*m)) > until_s) break;
    if (auto* s = std::get_if<ImuSample>(&*m)) session.pushImu(*s);
    else if (auto* l = std::get_if<LidarScan>(&*m)) session.pushSweep(std::move(*l));
  }
}

live::LiveOptions optionsFor(const Course& c) {
  live::LiveOptions o;
  o.config = c.config.string();
  o.use_camera = false;
  o.sweep_queue = 100'000;
  return o;
}

// drover run on the course (the reference the live session is held to); false, with the output, when it failed.
::testing::AssertionResult runOffline(const Course& course, const fs::path& out) {
  const CliResult r = runDrover("run " + course.dir.string() + " --format sim --config " + course.config.string() +
                                " --no-camera -q --out " + out.string());
  if (r.exit_code == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << r.output;
}

TEST(LiveSession, FedInTimeOrderItPublishesAndSavesTheTrajectoryOfDroverRun) {
  const TempDir tmp;
  const Course course = makeCourse(tmp);
  ASSERT_TRUE(runOffline(course, tmp / "offline"));

  std::atomic<std::size_t> sweeps{0}, keyframes{0}, deskewed{0}, paired{0};
  std::mutex mutex;
  std::set<Time> deskewed_t;  // both callbacks come from the LIS thread; the lock is for the reads at the end
  live::LiveCallbacks cb;
  cb.deskewed_sweep = [&](Time t, const Eigen::Isometry3d&, const std::vector<Eigen::Vector3f>& points) {
    deskewed += points.size() > 1000 ? 1 : 0;  // a VLP-16 sweep, downsampled
    std::lock_guard<std::mutex> lock(mutex);
    deskewed_t.insert(t);
  };
  cb.sweep = [&](const live::SweepResult& s) {
    ++sweeps;
    keyframes += s.keyframe ? 1 : 0;
    std::lock_guard<std::mutex> lock(mutex);
    paired += deskewed_t.count(s.pose.t);  // its deskewed points came before it, with its stamp
  };
  live::LiveSession session(optionsFor(course), cb);
  EXPECT_EQ(session.bodyFrame(), "imu");
  EXPECT_FALSE(session.visRuns());
  pushCourse(session, course.dir);
  session.shutdown();
  const live::LiveView view = session.view(0.4f);
  EXPECT_EQ(view.keyframes.size(), keyframes.load());
  EXPECT_EQ(deskewed.load(), sweeps.load());  // the node's ~cloud
  EXPECT_EQ(paired.load(), sweeps.load());
  EXPECT_GT(view.map.size(), 1000u);
  EXPECT_TRUE(view.loops.empty());
  // (IMU-rate odometry starts once the LIS has fused a sweep; pushed this fast, the IMU is all in before that: the
  // end-to-end test in tests/ros checks it at real time.)

  const std::string line = session.save((tmp / "live").string(), "end of test");
  EXPECT_TRUE(contains(line, std::to_string(sweeps.load()) + " sweeps")) << line;
  EXPECT_EQ(cli::runFolderProblem(tmp / "live"), "");
  EXPECT_EQ(readJson(tmp / "live" / "report.json")["end"]["reason"], "end of test");
  EXPECT_EQ(readJson(tmp / "live" / "report.json")["format"], "ros");
  // The same LIS on the same measurements: the live threads change nothing without a loop closure.
  const Trajectory live = io::readTum((tmp / "live" / "trajectory.tum").string());
  const Trajectory replay = io::readTum((tmp / "offline" / "trajectory.tum").string());
  ASSERT_EQ(live.size(), replay.size());
  ASSERT_EQ(live.size(), sweeps.load());
  double worst = 0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    EXPECT_EQ(live[i].t, replay[i].t);
    worst = std::max(worst, (live[i].T_world_body.translation() - replay[i].T_world_body.translation()).norm());
  }
  EXPECT_LT(worst, 1e-6) << "[m] largest position difference, live against drover run";
}

TEST(LiveSession, ResetStartsAnEmptyMapAfterWhichSaveHasNothingToWriteUntilNewSweepsCome) {
  const TempDir tmp;
  const Course course = makeCourse(tmp);
  live::LiveSession session(optionsFor(course), {});
  pushCourse(session, course.dir, 3.0);
  const auto hasKeyframes = [&] { return !session.view(0).keyframes.empty(); };
  for (int i = 0; i < 200 && !hasKeyframes(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(hasKeyframes());
  session.reset();
  EXPECT_TRUE(session.view(0.4f).keyframes.empty());
  EXPECT_TRUE(session.view(0.4f).map.empty());
  try {
    session.save((tmp / "empty").string(), "test");
    FAIL() << "a save without a processed sweep must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "nothing to save yet")) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp / "empty")) << "a refused save leaves no folder";
  pushCourse(session, course.dir);  // the same course again, from its start: a fresh system takes it
  session.shutdown();
  EXPECT_FALSE(session.view(0).keyframes.empty());
  EXPECT_NO_THROW(session.save((tmp / "after_reset").string(), "test"));
}

// `rosbag play --loop`: after 3 s the course starts over, its clock 3 s back. The session restarts by itself (a
// warning, the restarted callback) before the first measurement of the second pass, and maps that pass as a fresh
// run: drover run's trajectory again.
TEST(LiveSession, AClockThatJumpsBackRestartsTheSessionWhichThenMapsTheNewPassAsAFreshRun) {
  const TempDir tmp;
  const Course course = makeCourse(tmp);
  ASSERT_TRUE(runOffline(course, tmp / "offline"));
  std::atomic<std::size_t> restarts{0}, warned{0};
  live::LiveCallbacks cb;
  cb.restarted = [&](const std::string&) { ++restarts; };
  cb.warning = [&](const std::string& w) { warned += contains(w, "clock jumped back") ? 1 : 0; };
  live::LiveSession session(optionsFor(course), cb);
  pushCourse(session, course.dir, 3.0);
  pushCourse(session, course.dir);
  session.shutdown();
  EXPECT_EQ(restarts.load(), 1u);
  EXPECT_EQ(warned.load(), 1u);
  session.save((tmp / "live").string(), "end of test");
  const Trajectory live = io::readTum((tmp / "live" / "trajectory.tum").string());
  const Trajectory replay = io::readTum((tmp / "offline" / "trajectory.tum").string());
  ASSERT_EQ(live.size(), replay.size());
  double worst = 0;
  for (std::size_t i = 0; i < live.size(); ++i)
    worst = std::max(worst, (live[i].T_world_body.translation() - replay[i].T_world_body.translation()).norm());
  EXPECT_LT(worst, 1e-6) << "[m] largest position difference, the second pass against drover run";
}

TEST(LiveSession, SavesAndViewsWhileSweepsAreProcessedEachLeaveAValidRunFolder) {
  const TempDir tmp;
  const Course course = makeCourse(tmp);
  live::LiveOptions options = optionsFor(course);
  live::LiveSession session(options, {});
  std::atomic<bool> pushed{false};
  std::thread feeder([&] {
    pushCourse(session, course.dir);
    pushed = true;
  });
  std::vector<std::size_t> saved_poses;  // trajectory.tum's length at each save
  std::size_t last_keyframes = 0;
  while (saved_poses.size() < 5) {  // the LIS works meanwhile: every save pauses it between two sweeps
    const live::LiveView v = session.view(0.4f);
    EXPECT_GE(v.keyframes.size(), last_keyframes) << "keyframes only come";
    last_keyframes = v.keyframes.size();
    try {
      session.save((tmp / "running").string(), "saved while running");
      EXPECT_EQ(cli::runFolderProblem(tmp / "running"), "");
      saved_poses.push_back(io::readTum((tmp / "running" / "trajectory.tum").string()).size());
    } catch (const std::invalid_argument& e) {  // before the first sweep's pose
      EXPECT_TRUE(contains(e.what(), "nothing to save yet")) << e.what();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  feeder.join();
  session.shutdown();
  session.save((tmp / "running").string(), "end");
  const std::size_t all = io::readTum((tmp / "running" / "trajectory.tum").string()).size();
  EXPECT_EQ(all, 60u) << "6 s of 10 Hz sweeps";
  EXPECT_LT(saved_poses.front(), all) << "the first save came while sweeps were still being processed";
}

TEST(LiveSession, PlatformWithoutLidarIsRefusedNamingTheConfig) {
  const TempDir tmp;
  writeText(tmp / "no_lidar.yaml", "dataset:\n  load_lidar: false\n");
  live::LiveOptions o;
  o.config = (tmp / "no_lidar.yaml").string();
  try {
    live::LiveSession session(o, {});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "no_lidar.yaml")) << e.what();
    EXPECT_TRUE(contains(e.what(), "load_lidar")) << e.what();
  }
}

// roslaunch starts the node in ROS_HOME, where the shipped configs' relative SuperPoint weights path (written for
// drover run in the repository) finds nothing, nor does it beside the config: the session then says Shi-Tomasi. The
// launch file's ~working_dir (the repository by default) is where the path is looked for next.
TEST(LiveSession, TheShippedConfigsSuperPointWeightsAreFoundFromTheWorkingDirWhereverTheNodeStarts) {
  DROVER_REQUIRE_SHARED(sharedDir() / "models" / "superpoint_v1.onnx");
  const fs::path config = fs::path(DROVER_SOURCE_DIR) / "config" / "farm_sim_bag.yaml";
  ASSERT_FALSE(fs::exists("../shared/models/superpoint_v1.onnx")) << "the test needs a working directory ("
                                                                    << fs::current_path() << ") without the weights";
  live::LiveOptions o;
  o.config = config.string();
  {
    const live::LiveSession session(o, {});
    ASSERT_TRUE(session.visRuns());
    EXPECT_EQ(session.visDetector(), "shi-tomasi (SuperPoint unavailable)");
  }
  o.working_dir = DROVER_SOURCE_DIR;
  const live::LiveSession session(o, {});
  ASSERT_TRUE(session.visRuns());
  EXPECT_EQ(session.visDetector(), "superpoint");
}

}  // namespace
}  // namespace drover::test
