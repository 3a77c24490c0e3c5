#include "vio/seed_agreement.hpp"

#include <algorithm>

namespace drover::vio {

SeedAgreement seedAgreement(const FeatureManager& features, const std::vector<Eigen::Isometry3d>& T_world_cam,
                            double focal_px) {
  std::vector<double> errors;
  for (const auto& [id, f] : features.features()) {
    if (!f.lidar_anchor || f.depth <= 0) continue;
    const auto anchor = static_cast<std::size_t>(f.start());
    if (anchor >= T_world_cam.size()) continue;
    const Eigen::Vector3d p_world = T_world_cam[anchor] * anchorPoint(f, f.depth);
    for (std::size_t k = 1; k < f.obs.size(); ++k) {
      const auto frame = static_cast<std::size_t>(f.obs[k].frame);
      if (frame >= T_world_cam.size()) continue;
      const Eigen::Vector3d p_cam = T_world_cam[frame].inverse() * p_world;
      if (p_cam.z() <= 0) {
        errors.push_back(1e6);  // behind the camera: as far off as it gets
        continue;
      }
      errors.push_back(focal_px * (p_cam.head<2>() / p_cam.z() - f.obs[k].normalized).norm());
    }
  }
  SeedAgreement a;
  a.observations = errors.size();
  if (errors.empty()) return a;
  const auto mid = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
  std::nth_element(errors.begin(), mid, errors.end());
  a.median_px = *mid;
  return a;
}

}  // namespace drover::vio
