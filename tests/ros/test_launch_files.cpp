// The launch file and the RViz config of drover_ros: roslaunch finds the built node without catkin, and RViz shows
// the topics the node publishes.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>
#include <string>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const fs::path kRos = fs::path(DROVER_SOURCE_DIR) / "apps" / "drover_ros";

TEST(RosLaunchFiles, RoslaunchFindsTheBuiltNodeThroughTheBuildFolderOnRosPackagePath) {
  const TempDir tmp;
  const std::string build = fs::path(DROVER_ROS_BINARY).parent_path().string();
  // --args prints the node's command line without a master: the executable must be the one just built.
  const CliResult r =
      runShell("ROS_HOME=" + tmp.path().string() + " ROS_LOG_DIR=" + tmp.path().string() + " ROS_PACKAGE_PATH=" +
               build + " roslaunch --args /drover " + (kRos / "launch" / "drover.launch").string() +
               " config:=/abs/platform.yaml rviz:=false 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, std::string(DROVER_ROS_BINARY) + " __name:=drover")) << r.output;
}

// The shipped configs' SuperPoint weights path is relative, written for drover run in the repository; the node
// starts in ROS_HOME, so the launch file points ~working_dir at the repository (live::LiveOptions::working_dir).
TEST(RosLaunchFiles, TheNodesWorkingDirIsTheRepositoryThatTheShippedWeightsPathIsWrittenFor) {
  const TempDir tmp;
  const CliResult r = runShell("ROS_HOME=" + tmp.path().string() + " ROS_LOG_DIR=" + tmp.path().string() +
                               " roslaunch --dump-params " + (kRos / "launch" / "drover.launch").string() +
                               " config:=/abs/platform.yaml rviz:=false 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const YAML::Node params = YAML::Load(r.output);
  ASSERT_TRUE(params["/drover/working_dir"]) << r.output;
  EXPECT_TRUE(fs::equivalent(params["/drover/working_dir"].as<std::string>(), DROVER_SOURCE_DIR)) << r.output;
  EXPECT_EQ(YAML::LoadFile(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim_bag.yaml")["visual"]["detector"]["superpoint"]
                ["weights"]
                    .as<std::string>(),
            "../shared/models/superpoint_v1.onnx");
}

TEST(RosLaunchFiles, LaunchFileWithoutTheConfigArgumentIsRefusedByRoslaunch) {
  const TempDir tmp;
  const CliResult r = runShell("ROS_HOME=" + tmp.path().string() + " ROS_LOG_DIR=" + tmp.path().string() +
                               " roslaunch --nodes " + (kRos / "launch" / "drover.launch").string() + " 2>&1");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "config")) << r.output;
}

TEST(RosLaunchFiles, RvizShowsTheMapSweepPathLoopsAndOdometryTheNodePublishes) {
  const YAML::Node rviz = YAML::LoadFile((kRos / "rviz" / "drover.rviz").string());
  std::set<std::string> topics;
  for (const YAML::Node& d : rviz["Visualization Manager"]["Displays"]) {
    if (d["Topic"]) topics.insert(d["Topic"].as<std::string>());
    if (d["Marker Topic"]) topics.insert(d["Marker Topic"].as<std::string>());
  }
  const std::set<std::string> published{"/drover/map", "/drover/cloud", "/drover/path", "/drover/loops",
                                        "/drover/odometry/lidar"};
  EXPECT_EQ(topics, published);
  EXPECT_EQ(rviz["Visualization Manager"]["Global Options"]["Fixed Frame"].as<std::string>(), "map");
}

}  // namespace
}  // namespace drover::test
