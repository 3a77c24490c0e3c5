#pragma once
// The `loops` record of drover run's report.json: every verified candidate (accepted or rejected) with its Scan
// Context and scan-matching figures and, when the dataset has ground truth, how right it was; plus precision and
// recall of the accepted loops against the ground truth.
//   correct loop: the accepted relative pose T_candidate_query is within 1 m and 5 deg of the ground truth's;
//   precision = correct / accepted;
//   recall    = keyframes searched (not skipped after a loop) that have a true revisit -- an older keyframe, at
//               least loop.min_age earlier, within 3 m by the ground truth -- and got a correct loop, over those
//               searched keyframes with a true revisit.
#include "apps/drover/eval_report.hpp"
#include "apps/drover/run_output.hpp"

namespace drover::cli {

// loops: the loop search that ran (the LIS's own, or pipeline::System's loop thread's).
Json loopsJson(const RunContext& context, const pipeline::LidarOdometry& odometry, const pipeline::LoopClosure& loops);

}  // namespace drover::cli
