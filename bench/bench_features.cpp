// Keypoint detector costs (issue 6): the real SuperPoint forward pass (OpenCV DNN, CPU) at 640x480 and at KITTI's
// 1241x376 (network 1240x376), its C++ post-processing alone, and Shi-Tomasi and ORB at 640x480, all on a real
// EuRoC frame (752x480, resized) or KITTI 00/000000. OpenCV uses its default thread count (all cores).
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>

#include "io/image_file_io.hpp"
#include "support/shared_data.hpp"
#include "visual/orb_detector.hpp"
#include "visual/shi_tomasi_detector.hpp"
#include "visual/superpoint_detector.hpp"

namespace {

namespace visual = drover::visual;
namespace fs = std::filesystem;

const fs::path kModel = drover::test::sharedDir() / "models" / "superpoint_v1.onnx";
const fs::path kKitti = drover::test::sharedData("kitti/sequences/00/image_2/000000.png");
const fs::path kEuroc = drover::test::sharedData("euroc/V1_01_easy_micro/mav0/cam0/data/1403715273262142976.png");

// The image at `size` (resized), or empty when the shared file is missing.
cv::Mat image(const fs::path& p, cv::Size size) {
  if (!fs::exists(p)) return {};
  cv::Mat img = drover::io::readGreyImage(p.string());
  if (img.size() != size) cv::resize(img, img, size, 0, 0, cv::INTER_AREA);
  return img;
}

visual::SuperPointDetector* superpoint() {
  static std::unique_ptr<visual::SuperPointDetector> det;
  if (!det && fs::exists(kModel)) {
    visual::SuperPointConfig c;
    c.weights = kModel.string();
    det = std::make_unique<visual::SuperPointDetector>(c);
  }
  return det.get();
}

void forward(benchmark::State& state, const fs::path& path, cv::Size image_size) {
  visual::SuperPointDetector* det = superpoint();
  if (!det) return state.SkipWithError("../shared/models/superpoint_v1.onnx not found");
  cv::Mat img = image(path, image_size);
  if (img.empty()) return state.SkipWithError("shared image not found");
  cv::Mat net_img;
  cv::resize(img, net_img, det->networkSize(img.size()), 0, 0, cv::INTER_AREA);
  det->forward(net_img);  // the first pass allocates
  for (auto _ : state) {
    det->forward(net_img);
    benchmark::DoNotOptimize(det->semi().data);
  }
  state.counters["net_w"] = net_img.cols;
  state.counters["net_h"] = net_img.rows;
}

void BM_SuperPointForward640x480(benchmark::State& state) { forward(state, kEuroc, {640, 480}); }
BENCHMARK(BM_SuperPointForward640x480)->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_SuperPointForwardKitti1241x376(benchmark::State& state) { forward(state, kKitti, {1241, 376}); }
BENCHMARK(BM_SuperPointForwardKitti1241x376)->Unit(benchmark::kMillisecond)->Iterations(5);

// Softmax, depth-to-space, threshold, NMS, border, top-500 and descriptor sampling on the real heads.
void BM_SuperPointPostprocess640x480(benchmark::State& state) {
  visual::SuperPointDetector* det = superpoint();
  if (!det) return state.SkipWithError("../shared/models/superpoint_v1.onnx not found");
  const cv::Mat img = image(kEuroc, {640, 480});
  if (img.empty()) return state.SkipWithError("shared image not found");
  det->forward(img);
  const cv::Mat semi = det->semi().clone(), desc = det->desc().clone();
  visual::SuperPointPostprocessor post;
  std::size_t n = 0;
  for (auto _ : state) n = post.run(semi, desc, cv::Mat(), 500).points.size();
  state.counters["keypoints"] = static_cast<double>(n);
}
BENCHMARK(BM_SuperPointPostprocess640x480)->Unit(benchmark::kMillisecond);

// The whole detect() (resize, forward, post-processing) at 640x480 for the record.
void BM_SuperPointDetect640x480(benchmark::State& state) {
  visual::SuperPointDetector* det = superpoint();
  if (!det) return state.SkipWithError("../shared/models/superpoint_v1.onnx not found");
  const cv::Mat img = image(kEuroc, {640, 480});
  if (img.empty()) return state.SkipWithError("shared image not found");
  std::size_t n = 0;
  for (auto _ : state) n = det->detect(img, cv::Mat(), 500).points.size();
  state.counters["keypoints"] = static_cast<double>(n);
}
BENCHMARK(BM_SuperPointDetect640x480)->Unit(benchmark::kMillisecond)->Iterations(5);

template <typename Detector>
void classic(benchmark::State& state) {
  const cv::Mat img = image(kEuroc, {640, 480});
  if (img.empty()) return state.SkipWithError("shared image not found");
  Detector det;
  std::size_t n = 0;
  for (auto _ : state) n = det.detect(img, cv::Mat(), 500).points.size();
  state.counters["keypoints"] = static_cast<double>(n);
}

// VINS settings (150 corners, 30 px apart, quality 0.01).
void BM_ShiTomasi640x480(benchmark::State& state) { classic<visual::ShiTomasiDetector>(state); }
BENCHMARK(BM_ShiTomasi640x480)->Unit(benchmark::kMillisecond);

// 500 features, 8 levels, scale 1.2, FAST 20, with descriptors.
void BM_Orb640x480(benchmark::State& state) { classic<visual::OrbDetector>(state); }
BENCHMARK(BM_Orb640x480)->Unit(benchmark::kMillisecond);

}  // namespace
BENCHMARK_MAIN();
