// The VIS's events in report.json (apps/drover/run_vis.hpp): a VIS that stays out after a reset says why, and how
// long it was out when it comes back; a short wait, or the first initialisation's, adds nothing.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/drover/run_vis.hpp"

namespace drover::cli {
namespace {

vio::VisFrame frameAt(double t_s) {
  vio::VisFrame f;
  f.estimate.t = fromSeconds(t_s);
  return f;
}

vio::VisFrame initialised(double t_s, bool just) {
  vio::VisFrame f = frameAt(t_s);
  f.estimate.initialized = true;
  f.estimate.just_initialized = just;
  if (just) f.estimate.event = "initialised from the LIS";
  return f;
}

vio::VisFrame waiting(double t_s, const std::string& why) {
  vio::VisFrame f = frameAt(t_s);
  f.estimate.event = "not initialised: " + why;
  return f;
}

vio::VisFrame reset(double t_s) {
  vio::VisFrame f = frameAt(t_s);
  f.estimate.reset = true;
  f.estimate.event = "only 4 features tracked into the frame (< 8): window cleared, re-initialising";
  return f;
}

std::vector<std::string> kinds(const nlohmann::json& report) {
  std::vector<std::string> out;
  for (const auto& e : report["events"]) out.push_back(e["kind"].get<std::string>());
  return out;
}

TEST(VisEvents, AVisOutForSecondsAfterAResetSaysWhyAndHowLongWhenItComesBack) {
  RunVis vis(loadVisSetup(""));
  for (double t = 0.0; t < 3.0; t += 0.1) vis.record(waiting(t, "waiting for parallax"));  // the first start
  vis.record(initialised(3.0, true));
  vis.record(initialised(3.1, false));
  vis.record(reset(3.2));
  for (double t = 3.3; t < 8.0; t += 0.1) vis.record(waiting(t, t < 6 ? "the LIS's seed disagrees" : "no LIS state"));
  vis.record(initialised(8.0, true));
  const nlohmann::json r = vis.report();
  ASSERT_EQ(kinds(r), (std::vector<std::string>{"initialized", "reset", "waiting", "waited", "initialized"})) << r;
  const auto& events = r["events"];
  EXPECT_NEAR(events[2]["t"].get<double>(), 5.2, 0.05) << "reported once the wait reaches 2 s";
  EXPECT_EQ(events[2]["what"], "not initialised: the LIS's seed disagrees");
  EXPECT_EQ(events[3]["what"], "4.8 s since the reset; the last reason: not initialised: no LIS state");
}

TEST(VisEvents, AShortWaitAfterAResetAddsNoEvent) {
  RunVis vis(loadVisSetup(""));
  vis.record(initialised(1.0, true));
  vis.record(reset(2.0));
  for (double t = 2.1; t < 3.5; t += 0.1) vis.record(waiting(t, "no LIS state"));
  vis.record(initialised(3.5, true));
  EXPECT_EQ(kinds(vis.report()), (std::vector<std::string>{"initialized", "reset", "initialized"}));
}

}  // namespace
}  // namespace drover::cli
