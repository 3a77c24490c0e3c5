#pragma once
// SuperPoint's post-processing (DeTone, Malisiewicz & Rabinovich, "SuperPoint: Self-Supervised Interest Point
// Detection and Description", CVPRW 2018, Sec. 3.2-3.3; MagicLeap's SuperPointPretrainedNetwork demo), on the raw
// network heads, in network pixels:
//   1. softmax over the 65 channels of each 8x8 cell, the 65th ("dustbin", no keypoint in the cell) dropped;
//   2. depth-to-space: channel c of cell (cx, cy) is the pixel (8 cx + c % 8, 8 cy + c / 8);
//   3. pixels with probability >= confidence_threshold and allowed by the mask are candidates;
//   4. grid NMS: strongest first, a candidate survives if no survivor lies within nms_radius (Chebyshev, px);
//   5. survivors closer than `border` px to the image edge are dropped; the strongest max_count are kept;
//      (Drover's floor, off by default: when fewer than min(min_keypoints, max_count) survive, steps 3-5 are run
//      again on every unmasked pixel, and the strongest fill up to that many: the absolute threshold, made for
//      well-exposed images, otherwise leaves a dark frame nearly empty. Points above the threshold are the same
//      either way, since NMS visits them first.)
//      (Drover's spread, off by default: with a grid_cols x grid_rows grid the survivors are taken cell by cell, the
//      strongest of every cell first, then every cell's second, ..., each round by score, for both the floor's
//      fill and the max_count cut. The pretrained network scores a grid of ceiling lights far above a textured
//      floor; by score alone a detection puts its keypoints on the ceiling, and a ground robot's monocular VIS loses
//      the floor, the one surface that holds its scale (bench/RESULTS.md, the lighting course). ORB's FAST cells and
//      VINS-Mono's min-distance mask spread their corners the same way.)
//   6. descriptors: the coarse 256-d map is L2-normalised per cell (as SuperPointNet.forward), sampled bilinearly
//      at the keypoint, the cell centre of cell (cx, cy) being pixel (8 cx + 3.5, 8 cy + 3.5), clamped to the
//      outer cell centres, and L2-normalised again.
// The mask is applied before NMS (as goodFeaturesToTrack applies it), so a keypoint next to a masked live track
// is not suppressed by a masked candidate.
#include <string>
#include <vector>

#include "visual/keypoint_detector.hpp"

namespace drover::visual {

struct SuperPointPostConfig {
  double confidence_threshold = 0.015;  // keypoint probability threshold (paper/demo: 0.015)
  int nms_radius = 4;                   // [network px] NMS half-window (demo: 4)
  int border = 4;                       // [network px] keypoints this close to the edge are dropped (demo: 4)
  int min_keypoints = 0;                // floor (see step 5): below-threshold points fill up to this many; 0 = off
  int grid_cols = 0;                    // spread (see step 5) over this many columns x rows of the image; 0 = off
  int grid_rows = 0;
  std::string validate() const;         // empty = valid
};

class SuperPointPostprocessor {
 public:
  explicit SuperPointPostprocessor(const SuperPointPostConfig& config = {});  // throws std::invalid_argument
  // semi: CV_32F blob 1x65xHcxWc (detector logits); desc: CV_32F blob 1x256xHcxWc (coarse descriptors) or empty
  // (then no descriptors are returned); mask: empty or CV_8UC1 of 8Wc x 8Hc. Returns points in network pixels,
  // strongest first, at most max_count (>= 0). Throws std::invalid_argument on a shape or type mismatch.
  Keypoints run(const cv::Mat& semi, const cv::Mat& desc, const cv::Mat& mask, int max_count);
  const SuperPointPostConfig& config() const { return config_; }

 private:
  struct Candidate {
    float score;
    int x, y;
  };
  void softmax(const cv::Mat& semi);
  void collectCandidates(int hc, int wc, float threshold, const cv::Mat& mask);
  void suppress(int width, int height);
  void spread(int width, int height);
  void sampleDescriptors(const cv::Mat& desc, Keypoints& out);

  SuperPointPostConfig config_;
  // Buffers reused between frames (sized on the first frame of a size).
  cv::Mat max_logit_, sum_exp_, exp_, tmp_, inv_norm_;
  cv::Mat suppressed_;
  struct Ranked {
    int rank;  // within its grid cell, 0 = the cell's strongest
    Candidate candidate;
  };
  std::vector<Candidate> candidates_, kept_;
  std::vector<Ranked> ranked_;
};

}  // namespace drover::visual
