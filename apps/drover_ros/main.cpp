// drover_ros: the live Drover as a ROS1 node (see drover_node.hpp).
//   drover_ros _config:=config/m2dgr.yaml [_save_dir:=out/live _save_on_exit:=true]
// SIGINT/SIGTERM stop it the way drover run stops: the input ends, everything queued is processed (its outputs still
// published), the run folder is written when ~save_on_exit is set, then the node leaves the ROS graph. A second
// signal kills at once. Exit code 0, 1 when the node could not start or the save on exit failed.
#include <ros/ros.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <exception>

#include "apps/drover/heap_tuning.hpp"
#include "apps/drover_ros/drover_node.hpp"

namespace {

std::atomic<int> g_signal{0};

extern "C" void onSignal(int signal) {
  g_signal.store(signal);
  std::signal(SIGINT, SIG_DFL);  // the second signal kills
  std::signal(SIGTERM, SIG_DFL);
}

}  // namespace

int main(int argc, char** argv) {
  ::ros::init(argc, argv, "drover", ::ros::init_options::NoSigintHandler);
  // Started here, not by the first NodeHandle: otherwise the last NodeHandle's end (a node that failed to start)
  // shuts ROS down, and the error line below would go nowhere.
  ::ros::start();
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  int code = 0;
  try {
    drover::ros_node::DroverNode node{::ros::NodeHandle(), ::ros::NodeHandle("~")};
    // The global queue carries the services and the path/map timers; the sensors have their own threads.
    ::ros::CallbackQueue* queue = ::ros::getGlobalCallbackQueue();
    // A node runs for hours: the heap's fragmented free pages go back to the kernel every 30 s of wall time.
    drover::cli::HeapTrimmer heap;
    while (g_signal.load() == 0 && ::ros::ok()) {
      queue->callAvailable(::ros::WallDuration(0.1));
      heap.tick(std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now().time_since_epoch()).count());
    }
    const int s = g_signal.load();
    code = node.finish(s == SIGINT ? "interrupted by SIGINT" : s == SIGTERM ? "interrupted by SIGTERM" : "ROS shut down")
               ? 0
               : 1;
  } catch (const std::exception& e) {
    ROS_FATAL_STREAM("drover: " << e.what());
    code = 1;
  }
  ::ros::shutdown();
  return code;
}
