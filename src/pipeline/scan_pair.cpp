#include "pipeline/scan_pair.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "lidar/feature_extractor.hpp"
#include "lidar/scan_layout.hpp"

namespace drover::pipeline {
lidar::FeatureSet prepareScan(LidarScan& scan, const OdometryConfig& config, const std::string& name) {
  lidar::sanitize(scan, config.layout);
  if (static_cast<int>(scan.points.size()) < config.min_points)
    throw std::invalid_argument(fmt::format("{}: {} valid points, fewer than min_points = {}", name,
                                            scan.points.size(), config.min_points));
  if (!scan.has_time) lidar::inferTimes(scan, config.layout);
  if (!scan.has_ring) lidar::inferRings(scan, config.layout);
  return lidar::FeatureExtractor(config.features).extract(scan).features;
}

ScanPairResult compareScans(LidarScan a, LidarScan b, const OdometryConfig& config, const std::string& name_a,
                            const std::string& name_b) {
  ScanPairResult r;
  const lidar::FeatureSet fa = prepareScan(a, config, name_a);
  const lidar::FeatureSet fb = prepareScan(b, config, name_b);
  r.points_a = a.points.size();
  r.points_b = b.points.size();
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
