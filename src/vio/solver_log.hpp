#pragma once
// Ceres reports each rejected trial step or failed factorisation of a trust-region solve through glog at WARNING
// level: normal events (the solver raises its damping and goes on) that would flood a run's terminal, and that a
// quiet run (-q) printed. Errors still print. Private to drover_vio (glog comes with Ceres).
#include <glog/logging.h>

#include <algorithm>

namespace drover::vio {

inline void quietSolverWarnings() {
  static const bool once = [] {
    FLAGS_minloglevel = std::max(FLAGS_minloglevel, 2);  // google::GLOG_ERROR
    return true;
  }();
  (void)once;
}

}  // namespace drover::vio
