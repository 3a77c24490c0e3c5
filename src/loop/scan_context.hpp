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
#include <Eigen/Core>
#include <optional>
#include <string>

#include "lidar/feature_set.hpp"

namespace drover::loop {

struct ScanContextConfig {
  int rings = 20;                // [-] radial bins (the paper's N_r)
  int sectors = 60;              // [-] azimuthal bins (N_s), 6 deg each by default
  double max_radius = 80.0;      // [m] points farther (in x-y) are ignored (L_max)
  double sensor_height = 2.0;    // [m] added to z so that ground-level heights are about zero (KITTI: ~1.73 m)
  double threshold = 0.13;       // [-] distance below which two scans are the same place (reference value)
  int search_radius = 3;         // [sectors] dh of the prior-narrowed search
  std::string validate() const;  // empty when valid
};

struct ScanContext {
  Eigen::MatrixXf image;      // rings x sectors, max height per bin [m] (0 where empty)
  Eigen::MatrixXf occupied;   // rings x sectors, 1 where a point fell, else 0
  Eigen::VectorXf ring_key;   // rings: mean of each ring's row (rotation invariant)
  Eigen::VectorXf sector_key; // sectors: mean of each sector's column
};

// Descriptor of a cloud in the lidar frame. Non-finite points and points beyond max_radius are ignored. Throws
// std::invalid_argument when config.validate() fails.
ScanContext makeScanContext(const lidar::PointCloud& cloud_lidar, const ScanContextConfig& config);

// Mean over the columns non-empty in both of (1 - cosine similarity) between column j of A and column (j - shift)
// of B (paper Eq. 5); 1.0 when no column pair is non-empty in both. Shapes must match (std::invalid_argument).
double columnDistance(const ScanContext& a, const ScanContext& b, int shift);

struct ShiftMatch {
  double distance = 1.0;  // [-] at the best shift
  int shift = 0;          // [sectors], in [0, sectors)
  double yaw = 0.0;       // [rad] yawFromShift(shift)
  bool narrowed = false;  // found by the prior-narrowed search (false: full search, or fell back to it)
  bool fell_back = false; // a prior was given but its window's best failed the threshold
  int evaluated = 0;      // shifts whose distance was computed
};

// Every shift.
ShiftMatch fullShiftSearch(const ScanContext& a, const ScanContext& b);
// Shifts within config.search_radius of the prior's shift (shiftFromYaw(*yaw_prior)); the full search when there is
// no prior or the best found is not below config.threshold.
ShiftMatch narrowedShiftSearch(const ScanContext& a, const ScanContext& b, std::optional<double> yaw_prior,
                               const ScanContextConfig& config);

double yawFromShift(int shift, int sectors);   // [rad] in (-pi, pi]
int shiftFromYaw(double yaw, int sectors);      // nearest shift in [0, sectors)

}  // namespace drover::loop
