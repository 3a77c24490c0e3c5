#pragma once
// Place-recognition evaluation maths (`drover loop eval`): which earlier keyframes a query may be matched to, whether
// a true revisit exists by the ground truth, whether the best candidate is the right place, and precision / recall
// / F1 at a threshold and over a range of thresholds (the precision-recall curve of Kim & Kim, IROS 2018, Fig. 8).
// No IO: the caller streams the dataset and fills PlaceQuery records.
//
// Counting, per query (a keyframe searched, or a listed pair):
//   detected = it has a candidate and the candidate's distance < threshold;
//   TP = detected and the candidate is the right place; FP = detected and it is not;
//   FN = a true revisit exists and the query is not a TP (missed, or matched to the wrong place);
//   TN = no true revisit and nothing detected.
//   precision = TP / (TP + FP) (1 when nothing is detected), recall = TP / (TP + FN) = TP / true revisits (1 when
//   there is none), F1 = their harmonic mean (0 when both are 0).
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "types/time.hpp"

namespace drover::loop {

struct PlaceQuery {
  bool has_candidate = false;     // the database returned an eligible candidate
  double distance = 1.0;          // [-] its Scan Context distance
  bool candidate_correct = false; // the candidate is the right place (ground truth or the pair's label)
  bool has_true_revisit = false;  // an eligible earlier keyframe is within the true distance (or label = 1)
};

struct PrCounts {
  double threshold = 0;  // [-]
  std::size_t queries = 0, true_revisits = 0, tp = 0, fp = 0, fn = 0, tn = 0;
  double precision = 1, recall = 1, f1 = 0;
};

// Throws std::invalid_argument for a non-finite threshold.
PrCounts countAt(const std::vector<PlaceQuery>& queries, double threshold);

// countAt at every threshold of `thresholds` (in the given order).
std::vector<PrCounts> precisionRecallCurve(const std::vector<PlaceQuery>& queries,
                                           const std::vector<double>& thresholds);

// first, first + step, ... up to last (inclusive, within step / 1000 of rounding). Throws std::invalid_argument when
// step <= 0, last < first or a value is not finite.
std::vector<double> thresholdRange(double first, double last, double step);

struct TruthConfig {
  double true_distance = 3.0;     // [m] a query has a true revisit when an eligible keyframe is this close
  double correct_distance = 6.0;  // [m] the best candidate is the right place when this close (tolerance: 2x)
  int exclude_recent = 50;        // [keyframes] the newest ones are never eligible (the database's exclusion)
  double min_age = 30.0;          // [s] eligible keyframes are at least this much older than the query
  std::string validate() const;   // empty when valid
};

// Keyframes [0, returned) are eligible for query `query` (times increase with the index, so eligibility is a
// prefix): at most query - exclude_recent and at least min_age older. Throws std::invalid_argument when query is out
// of range or the config is invalid.
std::size_t eligibleEnd(const std::vector<Time>& times, std::size_t query, const TruthConfig& config);

struct TruthMatch {
  bool has_true_revisit = false;
  double nearest_distance = -1;   // [m] to the nearest eligible keyframe (-1: none eligible)
  std::ptrdiff_t nearest = -1;    // its index
  double candidate_distance = -1; // [m] ground-truth distance of the candidate to the query (-1: no candidate)
  bool candidate_correct = false; // candidate_distance <= correct_distance
};

// positions: ground-truth lidar positions of the keyframes [m] (world frame); candidate < 0 means none. Throws
// std::invalid_argument when sizes differ or an index is out of range.
TruthMatch matchAgainstTruth(const std::vector<Eigen::Vector3d>& positions, const std::vector<Time>& times,
                             std::size_t query, std::ptrdiff_t candidate, const TruthConfig& config);

}  // namespace drover::loop
