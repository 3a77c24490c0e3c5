#pragma once
// SuperPoint keypoints and descriptors (DeTone et al., CVPRW 2018): the network runs through OpenCV DNN from an
// ONNX file (input `input` 1x1xHxW float32 grey in [0, 1]; outputs `semi` 1x65xH/8xW/8 detector logits and `desc`
// 1x256xH/8xW/8 coarse descriptors), post-processing in C++ (superpoint_postprocess.hpp).
//
// Weights: ../shared/models/superpoint_v1.onnx is MagicLeap's pretrained SuperPoint, released for NON-COMMERCIAL
// research use only; users may point `weights` at their own file (tools/superpoint_to_onnx.py converts a
// SuperPointNet state_dict).
#include <opencv2/dnn.hpp>
#include <string>

#include "visual/superpoint_postprocess.hpp"

namespace drover::visual {

struct SuperPointConfig {
  std::string weights = "../shared/models/superpoint_v1.onnx";  // ONNX file (relative = to the working directory)
  // [px] network input; both multiples of 8, or both 0 = the image size rounded to a multiple of 8. The image is
  // resized to it and the keypoints scaled back to image pixels; smaller = faster (cost ~ width x height).
  int input_width = 0;
  int input_height = 0;
  int max_keypoints = 1000;   // at most this many per image; the caller may ask fewer
  SuperPointPostConfig post;  // threshold, NMS radius and border, in network pixels
  // Threads OpenCV uses for the forward pass (cv::setNumThreads, a process-wide setting applied at construction);
  // 0 = leave OpenCV's setting.
  int threads = 0;
  std::string validate() const;  // empty = valid
};

// Where the weights come from and how to do without them: appended to every weights error.
extern const char* const kSuperPointWeightsHelp;

class SuperPointDetector : public KeypointDetector {
 public:
  // Loads and checks the network: a missing or malformed file, or outputs without the expected names and shapes
  // (probed by one forward pass on a small image), throw std::invalid_argument with kSuperPointWeightsHelp.
  explicit SuperPointDetector(const SuperPointConfig& config);
  // Scores are keypoint probabilities in [threshold, 1] (below it only for the post.min_keypoints floor);
  // descriptors CV_32F, 256 per row, unit L2 norm.
  Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) override;
  std::string name() const override { return "superpoint"; }
  bool paced() const override { return true; }
  const SuperPointConfig& config() const { return config_; }

  // The network input size used for an image of this size [px].
  cv::Size networkSize(cv::Size image) const;
  // The forward pass alone on a CV_8UC1 image already of a network size (multiples of 8): fills semi() and desc().
  void forward(const cv::Mat& net_image);
  const cv::Mat& semi() const { return outputs_[0]; }
  const cv::Mat& desc() const { return outputs_[1]; }

 private:
  void checkOutputs(cv::Size net_size) const;
  void netMask(const cv::Mat& mask, cv::Size net_size);

  SuperPointConfig config_;
  cv::dnn::Net net_;
  SuperPointPostprocessor post_;
  std::vector<cv::Mat> outputs_;  // reused between frames: semi, desc
  cv::Mat resized_, blob_, mask_net_;
};

}  // namespace drover::visual
