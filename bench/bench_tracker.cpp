// Visual front end speed (issue 6): the KLT tracker alone (detections precomputed, so only flow, checks, RANSAC,
// mask and bookkeeping are timed) must sustain >= 30 Hz at 640x480; and detect + track per frame for each detector.
// Frames: 60 images of the simulator's `straight` course at 15 Hz (640x480 mono, rendered once in-process).
// CPU time is the process's (all of OpenCV's worker threads), the figure to compare with the frame period when
// the machine is shared; wall time is the figure on an idle machine.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "sim/camera_model.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"
#include "support/shared_data.hpp"
#include "visual/detector_factory.hpp"
#include "visual/feature_tracker.hpp"

namespace {

namespace visual = drover::visual;
using drover::Time;

struct Frames {
  std::vector<cv::Mat> images;
  std::vector<Time> times;
  drover::CameraIntrinsics intrinsics;
};

const Frames& frames() {
  static const Frames f = [] {
    Frames out;
    drover::sim::ScenarioOptions options;
    options.duration_s = 8;
    const auto scenario = drover::sim::makeScenario("straight", options);
    const auto config = drover::sim::SimulatorConfig::defaults();
    const drover::sim::CameraRenderer renderer(config.camera);
    out.intrinsics = config.camera.intrinsics;
    for (int k = 0; k < 60; ++k) {
      const Time t = 3'000'000'000 + k * 1'000'000'000LL / 15;
      const auto frame = renderer.render(scenario.world, *scenario.trajectory, config.T_imu_cam, scenario.illumination,
                                         t, 1, static_cast<std::uint64_t>(k));
      out.images.push_back(visual::imageView(frame.image).clone());
      out.times.push_back(t);
    }
    return out;
  }();
  return f;
}

// Returns Shi-Tomasi corners computed beforehand for each frame (filtered by the mask), so the tracker's own
// work is what is timed.
class PrecomputedDetector : public visual::KeypointDetector {
 public:
  explicit PrecomputedDetector(const Frames& f) {
    for (const cv::Mat& image : f.images) {
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(image, corners, 400, 0.01, 10);
      table_.push_back({key(image), corners});
    }
  }
  visual::Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) override {
    visual::Keypoints k;
    const std::uint64_t k_image = key(image);
    for (const auto& [k_table, corners] : table_) {
      if (k_table != k_image) continue;
      for (const cv::Point2f& p : corners)
        if (static_cast<int>(k.points.size()) < max_count && mask.at<unsigned char>(cv::Point(p)) != 0)
          k.points.push_back(p);
      break;
    }
    k.scores.assign(k.points.size(), 1.0f);
    return k;
  }
  std::string name() const override { return "precomputed"; }

 private:
  // Identifies a frame by a sample of its pixels (the tracker hands the detector its own copy of the image).
  static std::uint64_t key(const cv::Mat& image) {
    std::uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < image.rows * image.cols; i += 97) h = (h ^ image.data[i]) * 1099511628211ull;
    return h;
  }
  std::vector<std::pair<std::uint64_t, std::vector<cv::Point2f>>> table_;
};

void trackFrames(benchmark::State& state, const std::function<std::shared_ptr<visual::KeypointDetector>()>& make) {
  const Frames& f = frames();
  visual::FeatureTrackerConfig config;
  config.clahe = visual::ClaheMode::kOff;
  auto tracker = std::make_unique<visual::FeatureTracker>(visual::CameraModel(f.intrinsics), make(), config);
  std::size_t k = 0, features = 0, frames_done = 0;
  for (auto _ : state) {
    if (k == f.images.size()) {  // start over: a new tracker, not a jump back to the first frame
      state.PauseTiming();
      tracker = std::make_unique<visual::FeatureTracker>(visual::CameraModel(f.intrinsics), make(), config);
      k = 0;
      state.ResumeTiming();
    }
    features += tracker->track(f.times[k], f.images[k]).features.size();
    ++k;
    ++frames_done;
  }
  state.counters["features"] = static_cast<double>(features) / static_cast<double>(frames_done);
  state.counters["Hz"] = benchmark::Counter(static_cast<double>(frames_done), benchmark::Counter::kIsRate);
}

void BM_TrackerAlone640x480(benchmark::State& state) {
  const auto detector = std::make_shared<PrecomputedDetector>(frames());
  trackFrames(state, [&] { return detector; });
}
BENCHMARK(BM_TrackerAlone640x480)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_DetectAndTrack640x480(benchmark::State& state, visual::DetectorType type) {
  visual::DetectorConfig config;
  config.type = type;
  config.superpoint.weights = (drover::test::sharedDir() / "models/superpoint_v1.onnx").string();
  if (type == visual::DetectorType::kSuperPoint && !std::filesystem::exists(config.superpoint.weights))
    return state.SkipWithError("../shared/models/superpoint_v1.onnx not found");
  trackFrames(state, [&] { return std::shared_ptr<visual::KeypointDetector>(visual::makeDetector(config)); });
}
BENCHMARK_CAPTURE(BM_DetectAndTrack640x480, shi_tomasi, visual::DetectorType::kShiTomasi)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_DetectAndTrack640x480, orb, visual::DetectorType::kOrb)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_DetectAndTrack640x480, superpoint, visual::DetectorType::kSuperPoint)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Iterations(60);

}  // namespace

BENCHMARK_MAIN();
