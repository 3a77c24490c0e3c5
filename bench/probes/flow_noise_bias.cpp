// Probe: is LK's flow shrunk by image noise on weak texture (the corner top-up's plain walls)? Two renders of the
// same simulated course, one with the sensors' noise and one without (drover sim --config with sim.noise false): the
// same scene at the same poses, so the clean pair's flow is the noisy pair's true flow up to LK's own error on a
// clean image. Corners are found on each noisy frame as the tracker's top-up finds them (goodFeaturesToTrack,
// quality 0.01, 30 px apart), tracked to the next frame in both renders from the same pixels with the farm
// config's LK (21 px window, 3 levels, 30 iterations, 0.01 px), the noisy track held to the floor and to the
// 0.5 px forward-backward check as the tracker holds it (the backward flow started at the original points). Printed per band of the noisy track's minimum eigenvalue:
// how many, the median clean flow [px], the median of (noisy flow . clean flow) / |clean flow|^2 (1: unbiased,
// < 1: shrunk toward no motion) and the median |noisy - clean| [px].
// Build: g++ -O2 -std=c++17 bench/probes/flow_noise_bias.cpp -I/usr/include/opencv4 -lopencv_video -lopencv_imgcodecs -lopencv_imgproc -lopencv_core -o /tmp/fnb
// Run:   /tmp/fnb NOISY_DIR/camera CLEAN_DIR/camera FIRST LAST [FLOOR=1e-4]
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

cv::Mat load(const std::string& dir, int i) {
  char name[32];
  std::snprintf(name, sizeof name, "/%06d.png", i);
  cv::Mat m = cv::imread(dir + name, cv::IMREAD_GRAYSCALE);
  if (m.empty()) {
    std::fprintf(stderr, "cannot read %s%s\n", dir.c_str(), name);
    std::exit(1);
  }
  return m;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct Band {
  double lo, hi;
  std::vector<double> clean_px, ratio, error_px, ncc, aperture;
};

// lambda_min / lambda_max of the 21 x 21 window's gradient matrix around p in the clean image (0: an edge or a flat
// window, 1: a corner): what the scene offers there without the noise.
double apertureRatio(const cv::Mat& image, cv::Point2f p) {
  cv::Mat patch, gx, gy;
  cv::getRectSubPix(image, cv::Size(23, 23), p, patch, CV_32F);
  cv::Sobel(patch, gx, CV_32F, 1, 0);
  cv::Sobel(patch, gy, CV_32F, 0, 1);
  const cv::Rect inner(1, 1, 21, 21);
  const double a = cv::sum(gx(inner).mul(gx(inner)))[0], b = cv::sum(gx(inner).mul(gy(inner)))[0],
               c = cv::sum(gy(inner).mul(gy(inner)))[0];
  const double tr = a + c, det = a * c - b * b, disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  return tr > 0 ? (tr / 2 - disc) / (tr / 2 + disc) : 0.0;
}

// Zero-mean normalised cross-correlation of the 21 x 21 windows around a in A and b in B (sub-pixel, bilinear): the
// share of a window's variance that is the scene's (signal / (signal + noise) for two exposures of one window).
double zncc(const cv::Mat& A, cv::Point2f a, const cv::Mat& B, cv::Point2f b) {
  cv::Mat pa, pb;
  cv::getRectSubPix(A, cv::Size(21, 21), a, pa, CV_32F);
  cv::getRectSubPix(B, cv::Size(21, 21), b, pb, CV_32F);
  cv::Scalar ma, sa, mb, sb;
  cv::meanStdDev(pa, ma, sa);
  cv::meanStdDev(pb, mb, sb);
  if (sa[0] <= 0 || sb[0] <= 0) return 0;
  return cv::mean((pa - ma[0]).mul(pb - mb[0]))[0] / (sa[0] * sb[0]);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s NOISY_CAMERA_DIR CLEAN_CAMERA_DIR FIRST LAST [FLOOR=1e-4]\n", argv[0]);
    return 2;
  }
  const std::string noisy_dir = argv[1], clean_dir = argv[2];
  const int first = std::stoi(argv[3]), last = std::stoi(argv[4]);
  const double floor = argc > 5 ? std::stod(argv[5]) : 1e-4;
  const cv::Size window(21, 21);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<Band> bands{{1e-4, 3e-4, {}, {}, {}}, {3e-4, 1e-3, {}, {}, {}}, {1e-3, 2e-3, {}, {}, {}},
                          {2e-3, 1e9, {}, {}, {}}};
  // The scene's own change: pixels of the clean render identical one second (15 frames) later.
  double same = 0;
  for (int i = first; i + 15 <= last; i += 15) {
    const cv::Mat d = load(clean_dir, i) != load(clean_dir, i + 15);
    same += 1.0 - cv::countNonZero(d) / static_cast<double>(d.total());
  }
  std::printf("clean render: %.1f %% of the pixels the same 1 s later\n", 100 * same / std::max(1, (last - first) / 15));
  std::size_t found = 0, failed_noisy = 0, failed_fb = 0, failed_clean = 0;
  for (int i = first; i < last; ++i) {
    const cv::Mat n0 = load(noisy_dir, i), n1 = load(noisy_dir, i + 1);
    const cv::Mat c0 = load(clean_dir, i), c1 = load(clean_dir, i + 1);
    std::vector<cv::Point2f> p0;
    cv::goodFeaturesToTrack(n0, p0, 150, 0.01, 30, cv::noArray(), 3, false, 0.04);
    found += p0.size();
    if (p0.empty()) continue;
    std::vector<cv::Point2f> pn, pc, pb;
    std::vector<unsigned char> sn, sc, sb;
    std::vector<float> eig, err;
    cv::calcOpticalFlowPyrLK(n0, n1, p0, pn, sn, eig, window, 3, criteria, cv::OPTFLOW_LK_GET_MIN_EIGENVALS, floor);
    pb = p0;  // as the tracker: the backward flow starts at the original points (OPTFLOW_USE_INITIAL_FLOW)
    cv::calcOpticalFlowPyrLK(n1, n0, pn, pb, sb, err, window, 3, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
    cv::calcOpticalFlowPyrLK(c0, c1, p0, pc, sc, err, window, 3, criteria, 0, 1e-6);
    for (std::size_t k = 0; k < p0.size(); ++k) {
      if (!sn[k] || eig[k] < floor) {
        ++failed_noisy;
        continue;
      }
      if (!sb[k] || cv::norm(pb[k] - p0[k]) > 0.5) {
        ++failed_fb;
        continue;
      }
      if (!sc[k]) {
        ++failed_clean;
        continue;
      }
      const cv::Point2f dn = pn[k] - p0[k], dc = pc[k] - p0[k];
      const double dc2 = dc.dot(dc);
      for (Band& b : bands) {
        if (eig[k] < b.lo || eig[k] >= b.hi) continue;
        b.clean_px.push_back(std::sqrt(dc2));
        if (dc2 > 0.25) b.ratio.push_back(dn.dot(dc) / dc2);  // flows under 0.5 px: the ratio is noise
        b.error_px.push_back(cv::norm(dn - dc));
        b.ncc.push_back(zncc(n0, p0[k], n1, pn[k]));
        b.aperture.push_back(apertureRatio(c0, p0[k]));
      }
    }
  }
  std::printf("frames %d..%d: %zu corners; lost: %zu at the floor %.0e, %zu by forward-backward, %zu clean\n", first,
              last, found, failed_noisy, floor, failed_fb, failed_clean);
  std::printf("min eigenvalue band     tracks  clean flow px  (noisy.clean)/|clean|^2 (n)  |noisy-clean| px  "
              "ZNCC p10 / p50  ZNCC < 0.5  clean lmin/lmax p50\n");
  for (const Band& b : bands) {
    std::vector<double> ncc = b.ncc;
    std::sort(ncc.begin(), ncc.end());
    const double low = static_cast<double>(std::lower_bound(ncc.begin(), ncc.end(), 0.5) - ncc.begin());
    std::printf("[%.0e, %.0e)  %8zu  %13.2f  %14.3f (%zu)  %16.3f  %6.2f / %5.2f  %9.1f %%  %.3f\n", b.lo,
                b.hi,
                b.error_px.size(), median(b.clean_px), median(b.ratio), b.ratio.size(), median(b.error_px),
                ncc.empty() ? NAN : ncc[ncc.size() / 10], median(b.ncc), ncc.empty() ? NAN : 100 * low / ncc.size(),
                median(b.aperture));
  }
  return 0;
}
