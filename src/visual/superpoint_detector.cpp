#include "visual/superpoint_detector.hpp"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "visual/detector_input.hpp"

namespace drover::visual {

const char* const kSuperPointWeightsHelp =
    "SuperPoint weights are an ONNX file (input 'input' 1x1xHxW; outputs 'semi' 1x65xH/8xW/8 and 'desc' "
    "1x256xH/8xW/8): ../shared/models/superpoint_v1.onnx is MagicLeap's pretrained SuperPoint (non-commercial "
    "research use only), or convert your own SuperPointNet .pth with tools/superpoint_to_onnx.py; point "
    "--weights or the config key visual.detector.superpoint.weights at it, or choose another detector with "
    "--detector shi-tomasi|orb (config key visual.detector.type)";

namespace {

const std::vector<std::string> kOutputNames = {"semi", "desc"};

[[noreturn]] void weightsError(const std::string& path, const std::string& what) {
  throw std::invalid_argument("superpoint: " + path + ": " + what + ". " + kSuperPointWeightsHelp);
}

}  // namespace

std::string SuperPointConfig::validate() const {
  if (weights.empty()) return "superpoint.weights is empty";
  if (input_width < 0 || input_height < 0 || input_width % 8 || input_height % 8 ||
      (input_width == 0) != (input_height == 0))
    return "superpoint.input_width/input_height must both be 0 or both positive multiples of 8, got " +
           std::to_string(input_width) + "x" + std::to_string(input_height);
  if (max_keypoints < 1) return "superpoint.max_keypoints must be >= 1, got " + std::to_string(max_keypoints);
  if (threads < 0) return "superpoint.threads must be >= 0, got " + std::to_string(threads);
  return post.validate();
}

SuperPointDetector::SuperPointDetector(const SuperPointConfig& config) : config_(config), post_(config.post) {
  if (std::string err = config_.validate(); !err.empty()) throw std::invalid_argument(err);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(config_.weights, ec)) weightsError(config_.weights, "file not found");
  try {
    net_ = cv::dnn::readNetFromONNX(config_.weights);
  } catch (const cv::Exception& e) {
    weightsError(config_.weights, "not a readable ONNX network (" + std::string(e.err) + ")");
  }
  if (net_.empty()) weightsError(config_.weights, "not a readable ONNX network");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  if (config_.threads > 0) cv::setNumThreads(config_.threads);
  checkOutputs(cv::Size(32, 24));
}

// One forward pass on a small black image: the graph must take `input` and give `semi` and `desc` of the
// expected shapes, so that a wrong file fails at start-up, not on the first frame.
void SuperPointDetector::checkOutputs(cv::Size net_size) const {
  cv::dnn::Net net = net_;  // shares the graph; forward() is non-const
  std::vector<cv::Mat> outs;
  try {
    const int shape[4] = {1, 1, net_size.height, net_size.width};
    net.setInput(cv::Mat(4, shape, CV_32F, cv::Scalar(0)), "input");
    net.forward(outs, kOutputNames);
  } catch (const cv::Exception& e) {
    weightsError(config_.weights, "the network does not run on a 1x1x" + std::to_string(net_size.height) + "x" +
                                      std::to_string(net_size.width) + " input named 'input' with outputs 'semi' "
                                      "and 'desc' (" + std::string(e.err) + ")");
  }
  const int hc = net_size.height / 8, wc = net_size.width / 8;
  const int channels[2] = {65, 256};
  for (int i = 0; i < 2; ++i) {
    const cv::Mat& m = outs[i];
    if (m.dims != 4 || m.size[0] != 1 || m.size[1] != channels[i] || m.size[2] != hc || m.size[3] != wc ||
        m.type() != CV_32F) {
      weightsError(config_.weights, "output '" + kOutputNames[i] + "' has shape " + blobShape(m) + ", expected 1x" +
                                        std::to_string(channels[i]) + "x" + std::to_string(hc) + "x" +
                                        std::to_string(wc) + " for a " + std::to_string(net_size.width) + "x" +
                                        std::to_string(net_size.height) + " input");
    }
  }
}

cv::Size SuperPointDetector::networkSize(cv::Size image) const {
  if (config_.input_width > 0) return {config_.input_width, config_.input_height};
  auto round8 = [](int v) { return std::max(8, (v + 4) / 8 * 8); };
  return {round8(image.width), round8(image.height)};
}

void SuperPointDetector::forward(const cv::Mat& net_image) {
  if (net_image.type() != CV_8UC1 || net_image.cols % 8 || net_image.rows % 8 || net_image.empty())
    throw std::invalid_argument("superpoint: forward() needs a CV_8UC1 image with sides multiples of 8");
  // blobFromImage would allocate; scaling into the reused 4-D blob does not.
  const int shape[4] = {1, 1, net_image.rows, net_image.cols};
  blob_.create(4, shape, CV_32F);
  cv::Mat blob_plane(net_image.rows, net_image.cols, CV_32F, blob_.ptr<float>());
  net_image.convertTo(blob_plane, CV_32F, 1.0 / 255.0);
  net_.setInput(blob_, "input");
  net_.forward(outputs_, kOutputNames);
}

// The caller's mask at network resolution: network pixel (x, y) takes the mask of the image pixel its centre
// falls in, the same mapping the keypoints are scaled back with.
void SuperPointDetector::netMask(const cv::Mat& mask, cv::Size net_size) {
  if (mask.empty() || mask.size() == net_size) {
    mask_net_ = mask;
    return;
  }
  mask_net_.create(net_size, CV_8U);
  const double sx = static_cast<double>(mask.cols) / net_size.width, sy = static_cast<double>(mask.rows) / net_size.height;
  std::vector<int> xs(net_size.width);
  for (int x = 0; x < net_size.width; ++x) xs[x] = std::min(mask.cols - 1, static_cast<int>((x + 0.5) * sx));
  for (int y = 0; y < net_size.height; ++y) {
    const uchar* src = mask.ptr<uchar>(std::min(mask.rows - 1, static_cast<int>((y + 0.5) * sy)));
    uchar* dst = mask_net_.ptr<uchar>(y);
    for (int x = 0; x < net_size.width; ++x) dst[x] = src[xs[x]];
  }
}

Keypoints SuperPointDetector::detect(const cv::Mat& image, const cv::Mat& mask, int max_count) {
  checkDetectInput("superpoint", image, mask, max_count);
  const int n = std::min(max_count, config_.max_keypoints);
  if (n == 0) return {};
  const cv::Size net_size = networkSize(image.size());
  const bool resize = net_size != image.size();
  if (resize) cv::resize(image, resized_, net_size, 0, 0, cv::INTER_AREA);
  forward(resize ? resized_ : image);
  netMask(mask, net_size);
  Keypoints out = post_.run(outputs_[0], outputs_[1], mask_net_, n);
  if (resize) {
    // Pixel centres map to pixel centres: x_image + 0.5 = (x_net + 0.5) * W_image / W_net.
    const float sx = static_cast<float>(image.cols) / net_size.width, sy = static_cast<float>(image.rows) / net_size.height;
    for (cv::Point2f& p : out.points) p = {(p.x + 0.5f) * sx - 0.5f, (p.y + 0.5f) * sy - 0.5f};
  }
  return out;
}

}  // namespace drover::visual
