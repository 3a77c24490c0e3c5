#include "pipeline/scan_pair.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "lidar/feature_extractor.hpp"
#include "lidar/scan_layout.hpp"

namespace drover::pipeline {
namespace {

lidar::FeatureSet prepare(LidarScan& scan, const OdometryConfig& config, const char* name, std::size_t& points) {
  lidar::sanitize(scan, config.layout);
  points = scan.points.size();
  if (static_cast<int>(points) < config.min_points)
    throw std::invalid_argument(
        fmt::format("scan {} has {} valid points (fewer than min_points = {})", name, points, config.min_points));
  if (!scan.has_time) lidar::inferTimes(scan, config.layout);
  if (!scan.has_ring) lidar::inferRings(scan, config.layout);
  return lidar::FeatureExtractor(config.features).extract(scan).features;
}

}  // namespace

ScanPairResult compareScans(LidarScan a, LidarScan b, const OdometryConfig& config) {
  ScanPairResult r;
  const lidar::FeatureSet fa = prepare(a, config, "A", r.points_a);
  const lidar::FeatureSet fb = prepare(b, config, "B", r.points_b);
  const loop::ScanContextConfig& sc = config.loop.database.descriptor;
  // The descriptors use every valid point, as the reference implementation does with the raw scan.
  lidar::PointCloud ca, cb;
  for (const LidarPoint& p : a.points) ca.emplace_back(p.x, p.y, p.z);
  for (const LidarPoint& p : b.points) cb.emplace_back(p.x, p.y, p.z);
  const loop::ScanContext da = loop::makeScanContext(ca, sc);
  const loop::AugmentedScanContext db = loop::makeAugmentedScanContext(cb, sc);
  r.plain = loop::fullShiftSearch(da, db.descriptors[0]);
  r.match = loop::augmentedShiftSearch(da, db, std::nullopt, sc);
  r.same_place = r.match.match.distance < sc.threshold;
  r.T_A_B_guess = loop::relativePoseFromMatch(r.match);
  const loop::LoopVerifier verifier(config.loop.verifier);
  const loop::SubmapKeyframe submap[] = {{&fa, Eigen::Isometry3d::Identity()}};
  r.icp = verifier.verify(fb, submap, 0, r.T_A_B_guess);
  return r;
}

}  // namespace drover::pipeline
