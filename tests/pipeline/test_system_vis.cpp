// The VIS inside the live system: in its own thread, fed the IMU, the camera frames and the LIS's deskewed sweeps,
// it starts from the LIS's state (read through the System's board, not the LIS itself) and tracks the truth of a
// simulated course with a camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/system.hpp"
#include "support/live_course.hpp"
#include "visual/detector_factory.hpp"

namespace drover::pipeline {
namespace {

// 14 s of the sharp-turns course with its 15 Hz camera: at rest 2.5 s, 11 m straight, then turning.
const test::LiveCourse& visCourse() {
  static const test::LiveCourse c = test::simulateLiveCourse("sharp-turns", 14.0, 5, true);
  return c;
}

SystemConfig config() {
  SystemConfig c;
  c.odometry = test::simOdometryConfig();
  c.vis = vio::VisConfig{};
  c.live.sweep_queue = 1'000'000;
  c.live.frame_queue = 1'000'000;
  return c;
}

std::shared_ptr<visual::KeypointDetector> shiTomasi() {
  visual::DetectorConfig d;
  d.type = visual::DetectorType::kShiTomasi;
  return visual::makeDetector(d);
}

TEST(SystemVis, TheVisRunsInItsOwnThreadStartsFromTheLisAndTracksTheTruth) {
  std::mutex mutex;
  std::vector<vio::VisFrame> frames;
  std::atomic<bool> on_pusher{false};
  std::atomic<std::size_t> sweeps{0};
  const std::thread::id pusher = std::this_thread::get_id();
  SystemCallbacks cb;
  cb.sweep = [&](const ScanOutcome&) { ++sweeps; };
  cb.vis_frame = [&](const vio::VisFrame& f) {
    if (std::this_thread::get_id() == pusher) on_pusher = true;
    std::lock_guard<std::mutex> lock(mutex);
    frames.push_back(f);
  };
  System system(config(), visCourse().calibration, cb, shiTomasi());
  // Paced as a live stream whose LIS keeps up: a frame goes in once the sweeps before it are fused (the VIS reads
  // the LIS's newest IMU-rate poses, which exist only then).
  std::size_t pushed_sweeps = 0;
  for (const Measurement& m : visCourse().stream) {
    if (const auto* imu = std::get_if<ImuSample>(&m)) {
      system.pushImu(*imu);
    } else if (const auto* scan = std::get_if<LidarScan>(&m)) {
      system.pushSweep(*scan);
      ++pushed_sweeps;
    } else {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
      while (sweeps.load() + 1 < pushed_sweeps && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      system.pushFrame(std::get<CameraFrame>(m));
    }
  }
  system.shutdown();
  ASSERT_NE(system.vis(), nullptr);
  EXPECT_FALSE(on_pusher.load());
  EXPECT_EQ(system.stats().frames_dropped, 0u);
  std::size_t initialized = 0;
  bool from_lis = false;
  double worst = 0;
  // The VIS is seeded in the LIS's world: compare with the truth through the LIS's first pose.
  const Trajectory& lis = system.lis().trajectory();
  const Eigen::Isometry3d T_lidar_imu = visCourse().calibration.T_imu_lidar.inverse();
  const auto truthAt = [](Time t) -> const Eigen::Isometry3d* {
    const Trajectory& truth = visCourse().truth;
    const auto it = std::lower_bound(truth.begin(), truth.end(), t,
                                     [](const StampedPose& p, Time x) { return p.t < x; });
    return it != truth.end() && std::abs(it->t - t) < 3'000'000 ? &it->T_world_body : nullptr;
  };
  const Eigen::Isometry3d T_truth_est = *truthAt(lis.front().t) * (lis.front().T_world_body * T_lidar_imu).inverse();
  for (const vio::VisFrame& f : frames) {
    if (f.estimate.just_initialized && f.estimate.event.find("LIS") != std::string::npos) from_lis = true;
    if (!f.estimate.initialized) continue;
    ++initialized;
    if (const Eigen::Isometry3d* truth = truthAt(f.estimate.t))
      worst = std::max(worst, ((T_truth_est * f.estimate.T_world_imu).translation() - truth->translation()).norm());
  }
  std::printf("VIS in the System: %zu frames, %zu estimated, worst position error %.3f m\n", frames.size(),
              initialized, worst);
  EXPECT_EQ(frames.size(), 210u);  // 14 s at 15 Hz: every frame taken
  EXPECT_TRUE(from_lis);
  EXPECT_GT(initialized, frames.size() / 2);
  EXPECT_LT(worst, 0.3);  // [m] over ~12 m of path
}

}  // namespace
}  // namespace drover::pipeline
