#pragma once
// Scan Context (Kim & Kim, "Scan Context: Egocentric Spatial Descriptor for Place Recognition within 3D Point
// Cloud Map", IROS 2018): a ring x sector image of a scan holding the maximum height per polar bin, its ring key
// (rotation-invariant, for retrieval) and sector key, and the column-shift search that both measures the distance
// of two descriptors (the paper's Eq. 5-6) and estimates their relative yaw. Besides the full search over every
// shift, the prior-narrowed search of Drover's paper: a rough shift A from a yaw prior (odometry or VIS), then only
// A - dh .. A + dh, falling back to the full search when there is no prior or the narrowed best fails the threshold.
//
// Shift and yaw convention: shift n compares column j of A with column (j - n) mod sectors of B. If scan B was taken
// at the same place with the sensor turned by psi about z (R_A_B = Rz(psi)), a point at azimuth theta in A appears
// at theta - psi in B, so the best shift is n = psi / (2 pi / sectors): yawFromShift(n) = n * 2 pi / sectors
// (wrapped to (-pi, pi]) is the yaw that rotates B's cloud onto A's (p_A = Rz(psi) p_B).
//
// Lateral augmentation (Scan Context++, Kim et al., T-RO 2021, "root shifting"): the descriptor is sensitive to the
// sensor's lateral offset between visits (an opposite-direction revisit in another lane). The query's descriptor is
// also made from virtual sensor positions on a small x-y grid around the real one, and the best match over them is
// kept. On the KITTI 08 revisit (3.1 m apart, 148 deg) this takes the distance from 0.22 to 0.12.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "lidar/feature_set.hpp"

namespace drover::loop {

struct ScanContextConfig {
  int rings = 20;                // [-] radial bins (the paper's N_r)
  int sectors = 60;              // [-] azimuthal bins (N_s), 6 deg each by default
  double max_radius = 80.0;      // [m] points farther (in x-y) are ignored (L_max)
  double sensor_height = 2.0;    // [m] added to z so that ground-level heights are slightly positive (the reference's
                                 // 2.0 for KITTI's 1.73 m mount: ground-only bins must not be zero or negative)
  // Instead of sensor_height, estimate the ground per scan: lift = ground_lift - (5th percentile of z of the points
  // 2-20 m away in x-y). For datasets whose platforms differ (one config for a 0.7 m crawler and a 1.8 m car).
  bool auto_height = false;
  double ground_lift = 0.3;      // [m] height given to the estimated ground with auto_height
  double threshold = 0.13;       // [-] distance below which two scans are the same place (reference value)
  int search_radius = 3;         // [sectors] dh of the prior-narrowed search
  double lateral_step = 2.0;     // [m] spacing of the virtual sensor positions of the lateral augmentation
  int lateral_steps = 1;         // [-] grid half-width: (2 k + 1)^2 virtual positions; 0 = no augmentation
  std::string validate() const;  // empty when valid
};

struct ScanContext {
  Eigen::MatrixXf image;      // rings x sectors, max height per bin [m] (0 where empty)
  Eigen::MatrixXf occupied;   // rings x sectors, 1 where a point fell, else 0
  Eigen::VectorXf ring_key;   // rings: mean of each ring's row (rotation invariant)
  Eigen::VectorXf sector_key; // sectors: mean of each sector's column
  // Each column of `image` divided by its norm (zero columns stay zero) and the norms, so that a shift's distance
  // is a sum of dot products; filled by makeScanContext. columnDistance computes them when absent.
  Eigen::MatrixXf unit_columns;
  Eigen::VectorXf column_norms;
};

// Descriptor of a cloud in the lidar frame. Non-finite points and points beyond max_radius are ignored. Throws
// std::invalid_argument when config.validate() fails.
// The height added to z: sensor_height, or with auto_height the estimate described in the config.
double heightLift(const lidar::PointCloud& cloud_lidar, const ScanContextConfig& config);
ScanContext makeScanContext(const lidar::PointCloud& cloud_lidar, const ScanContextConfig& config);

// Mean over the columns non-empty in both of (1 - cosine similarity) between column j of A and column (j - shift)
// of B (paper Eq. 5); 1.0 when no column pair is non-empty in both. Shapes must match (std::invalid_argument).
double columnDistance(const ScanContext& a, const ScanContext& b, int shift);

struct ShiftMatch {
  double distance = 1.0;  // [-] at the best shift
  int shift = 0;          // [sectors], in [0, sectors)
  double yaw = 0.0;       // [rad] yawFromShift(shift)
  bool narrowed = false;  // found by the prior-narrowed search (false: full search, or fell back to it)
  bool fell_back = false; // a prior was given, its window's best failed the threshold and more shifts were searched
  int evaluated = 0;      // shifts whose distance was computed
};

// A yaw prior [rad] (as narrowedShiftSearch's) and how far its fall-back may reach: when the best of the narrowed
// window (+-config.search_radius sectors) fails the threshold, the search goes on over the shifts within
// +-fallback_radius sectors of the prior's shift; every shift once that covers them all (the default: the paper's
// fall-back to the full search), none when fallback_radius <= search_radius. A caller that knows how far the prior
// can be off (the loop closure's rotation drift budget) so skips the shifts no acceptable loop could have.
// Implicit from a yaw, so callers that only have a yaw keep the full fall-back.
struct YawPrior {
  static constexpr int kFullFallback = 1 << 20;  // [sectors] more than any descriptor has
  YawPrior(double yaw_ = 0.0, int fallback_radius_ = kFullFallback) : yaw(yaw_), fallback_radius(fallback_radius_) {}
  double yaw;           // [rad]
  int fallback_radius;  // [sectors]
};

// Every shift.
ShiftMatch fullShiftSearch(const ScanContext& a, const ScanContext& b);
// Shifts within config.search_radius of the prior's shift (shiftFromYaw(prior->yaw)); when there is no prior the
// full search, and when the best found is not below config.threshold the fall-back of YawPrior (fell_back = true
// when it searched any further shift; a partial fall-back does not evaluate the window's shifts again).
ShiftMatch narrowedShiftSearch(const ScanContext& a, const ScanContext& b, std::optional<YawPrior> prior,
                               const ScanContextConfig& config);

// The reference implementation's coarse alignment: argmin over shifts n of the L1 distance between A's sector key
// and B's sector key shifted by n (same shift convention as columnDistance), in [0, sectors).
int sectorKeyShift(const ScanContext& a, const ScanContext& b);
// The reference implementation's search: shifts within config.search_radius of sectorKeyShift (no prior needed,
// no fallback; narrowed = true).
ShiftMatch sectorKeyShiftSearch(const ScanContext& a, const ScanContext& b, const ScanContextConfig& config);

// Lateral augmentation: one descriptor per virtual sensor position o = (i, j) * lateral_step, i, j in
// [-lateral_steps, lateral_steps] (x-y of the lidar frame, [m]), made from the points p - o. Index 0 is the real
// position (o = 0); offsets[i] is the position of descriptors[i].
struct AugmentedScanContext {
  std::vector<ScanContext> descriptors;
  std::vector<Eigen::Vector2f> offsets;  // [m] virtual sensor position in the cloud's frame
};
AugmentedScanContext makeAugmentedScanContext(const lidar::PointCloud& cloud_lidar, const ScanContextConfig& config);

struct AugmentedMatch {
  ShiftMatch match;             // the best over the query's virtual positions (by distance)
  int index = 0;                // which of b.descriptors
  Eigen::Vector2f offset{0, 0};  // [m] its virtual position in B's frame
};
// Full (no prior) or prior-narrowed search (narrowedShiftSearch) of descriptor A against every descriptor of B.
AugmentedMatch augmentedShiftSearch(const ScanContext& a, const AugmentedScanContext& b,
                                    std::optional<YawPrior> yaw_prior, const ScanContextConfig& config);

// The relative pose of the query (B) in the candidate's (A) lidar frame that a match implies: yaw about z from
// the shift, applied to R_candidate_query_tilt's roll and pitch (e.g. the estimate's relative rotation; identity
// when there is none), and the translation that puts B's sensor where the chosen virtual position says A's sensor
// is seen from B (t = -Rz(yaw) [offset; 0]; z = 0: same ground height).
Eigen::Isometry3d relativePoseFromMatch(const AugmentedMatch& match,
                                        const Eigen::Matrix3d& R_candidate_query_tilt = Eigen::Matrix3d::Identity());

double yawFromShift(int shift, int sectors);   // [rad] in (-pi, pi]
int shiftFromYaw(double yaw, int sectors);      // nearest shift in [0, sectors)

}  // namespace drover::loop
