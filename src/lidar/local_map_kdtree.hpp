#pragma once
// Private helper of LocalMap: a nanoflann (1.4, uint32_t indices) k-d tree over a PointCloud. Included only by
// .cpp files so nanoflann stays out of the public headers.
#include <cstdint>
#include <memory>
#include <nanoflann.hpp>

#include "lidar/feature_set.hpp"

namespace drover::lidar::detail {

// The dataset adaptor nanoflann asks for: a view of a cloud that must outlive the tree.
struct CloudAdaptor {
  const PointCloud* cloud = nullptr;
  std::size_t kdtree_get_point_count() const { return cloud->size(); }
  float kdtree_get_pt(std::uint32_t idx, std::size_t dim) const { return (*cloud)[idx][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox& /*bb*/) const {
    return false;  // let nanoflann compute it
  }
};

class CloudKdTree {
 public:
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>, CloudAdaptor,
                                                   3, std::uint32_t>;

  // Indexes `cloud` (kept by pointer; it must not change or move while the tree lives).
  explicit CloudKdTree(const PointCloud& cloud) : adaptor_{&cloud} {
    tree_ = std::make_unique<Tree>(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  }
  // The tree refers to adaptor_, so the object stays where it was built.
  CloudKdTree(const CloudKdTree&) = delete;
  CloudKdTree& operator=(const CloudKdTree&) = delete;

  std::size_t knn(const Eigen::Vector3f& query, std::size_t k, std::uint32_t* indices, float* sq_dists) const {
    if (adaptor_.cloud->empty() || k == 0) return 0;
    return tree_->knnSearch(query.data(), k, indices, sq_dists);
  }

 private:
  CloudAdaptor adaptor_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace drover::lidar::detail
