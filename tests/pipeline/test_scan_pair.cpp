// Loop closure on the real KITTI pairs in ../shared (issue 5): the sequence-08 revisit driven the other way is the
// same place, at the true yaw, and scan matching recovers the true relative pose; the sequence-00 pair 58 m apart
// is rejected by both Scan Context and the scan match.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "io/kitti_common.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/scan_pair.hpp"
#include "support/shared_data.hpp"

namespace drover::pipeline {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// The KITTI HDL-64E as config/kitti.yaml describes it (what `drover loop pair` uses without --config).
OdometryConfig kittiConfig() { return OdometryConfig::kittiHdl64(); }

Eigen::Isometry3d trueLidarPose(const std::filesystem::path& dir, int frame) {
  const Eigen::Isometry3d Tr = io::KittiCalibFile((dir / "calib.txt").string()).rigid34("Tr");
  return Tr.inverse() * io::readKitti((dir / "poses.txt").string()).at(static_cast<std::size_t>(frame)).T_world_body *
         Tr;
}

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

TEST(ScanPairKitti, RevisitIsTheSamePlaceAndScanMatchingRecoversTheTruePose) {
  const auto dir = test::sharedData("kitti/revisit_08");
  DROVER_REQUIRE_SHARED(dir / "001500.bin");
  const ScanPairResult r = compareScans(io::readKittiBin((dir / "000720.bin").string(), 0, 0),
                                        io::readKittiBin((dir / "001500.bin").string(), 0, 0), kittiConfig());
  const Eigen::Isometry3d T_true = trueLidarPose(dir, 720).inverse() * trueLidarPose(dir, 1500);
  const Eigen::Isometry3d& T = r.icp.T_candidate_query;
  std::printf(
      "revisit_08: distance %.4f (plain %.4f), yaw %.1f deg (true %.2f); scan match %s, t = (%.2f, %.2f, "
      "%.2f) m (true (%.2f, %.2f, %.2f)), yaw %.2f deg\n",
      r.match.match.distance, r.plain.distance, r.match.match.yaw * kDeg, yawOf(T_true.linear()) * kDeg,
      r.icp.reason.c_str(), T.translation().x(), T.translation().y(), T.translation().z(), T_true.translation().x(),
      T_true.translation().y(), T_true.translation().z(), yawOf(T.linear()) * kDeg);
  EXPECT_TRUE(r.same_place);
  EXPECT_LT(std::abs(std::remainder(r.match.match.yaw - yawOf(T_true.linear()), 2 * std::numbers::pi)) * kDeg, 6.0);
  ASSERT_TRUE(r.icp.accepted) << r.icp.reason;
  // Rotation and horizontal position against the ground truth.
  const Eigen::Isometry3d err = T_true.inverse() * T;
  EXPECT_LT(Eigen::AngleAxisd(err.linear()).angle() * kDeg, 2.0);
  EXPECT_LT((T.translation() - T_true.translation()).head<2>().norm(), 0.5);
  // Height: the ground truth puts B 1.06 m below A, but both scans see the road 1.73-1.76 m below the sensor and
  // the road under B's position in A's scan is at -1.73 m, so B's sensor is at A's height to a few centimetres:
  // the sequence-08 ground truth's vertical error between the two passes (GPS/INS), not the match's. The test
  // checks that the reference still has that offset and holds the match to the height the scans show.
  EXPECT_LT(T_true.translation().z(), -0.9);
  EXPECT_LT(std::abs(T.translation().z()), 0.1);
}

TEST(ScanPairKitti, PlacesFiftyEightMetresApartAreRejectedByScanContextAndByTheScanMatch) {
  const auto dir = test::sharedData("kitti/non_revisit_00");
  DROVER_REQUIRE_SHARED(dir / "000198.bin");
  const ScanPairResult r = compareScans(io::readKittiBin((dir / "000094.bin").string(), 0, 0),
                                        io::readKittiBin((dir / "000198.bin").string(), 0, 0), kittiConfig());
  std::printf("non_revisit_00: distance %.4f, scan match %s\n", r.match.match.distance, r.icp.reason.c_str());
  EXPECT_FALSE(r.same_place);
  EXPECT_FALSE(r.icp.accepted);
}

TEST(ScanPair, AScanWithTooFewValidPointsIsAnError) {
  LidarScan empty, one;
  one.points.push_back({1, 2, 3, 0, 0, 0});
  EXPECT_THROW(compareScans(empty, one, kittiConfig()), std::invalid_argument);
}

}  // namespace
}  // namespace drover::pipeline
