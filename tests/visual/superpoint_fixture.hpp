#pragma once
// Runs tests/visual/make_superpoint_onnx.py into a temporary folder at test time (so the build needs no Python and
// a missing python3-onnx skips the test with a message instead of failing the build) and reads what it wrote.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"

namespace drover::test {

// 0 = written; 77 = python3-onnx missing; other = failure (the output is printed by the shell).
inline int makeSuperPointOnnx(const std::filesystem::path& dir, const std::string& variant = "ok") {
  if (!std::filesystem::exists("/usr/bin/python3")) return 77;
  const std::string cmd = "/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) +
                          "/tests/visual/make_superpoint_onnx.py " + dir.string() + " --variant " + variant;
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

#define DROVER_MAKE_SUPERPOINT_ONNX(dir, variant)                                                              \
  do {                                                                                                         \
    const int rc_ = drover::test::makeSuperPointOnnx(dir, variant);                                            \
    if (rc_ == 77) GTEST_SKIP() << "python3-onnx not installed (scripts/install_deps.sh installs it): the "  \
                                   "SuperPoint reference test needs /usr/bin/python3 with onnx and numpy"; \
    ASSERT_EQ(rc_, 0) << "tests/visual/make_superpoint_onnx.py failed";                                       \
  } while (0)

template <typename T>
std::vector<T> readRaw(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  EXPECT_TRUE(in.good()) << p;
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<T> v(bytes.size() / sizeof(T));
  std::memcpy(v.data(), bytes.data(), v.size() * sizeof(T));
  return v;
}

struct SuperPointReference {
  cv::Mat image;
  std::vector<float> points, scores, desc;  // N x 2, N, N x 256
  int count = 0;
};

inline SuperPointReference readSuperPointReference(const std::filesystem::path& dir) {
  SuperPointReference r;
  std::ifstream meta(dir / "meta.txt");
  int h = 0, w = 0, max_count = 0;
  meta >> h >> w >> r.count >> max_count;
  std::vector<unsigned char> pixels = readRaw<unsigned char>(dir / "image.u8");
  EXPECT_EQ(pixels.size(), static_cast<std::size_t>(h * w));
  r.image = cv::Mat(h, w, CV_8UC1, pixels.data()).clone();
  r.points = readRaw<float>(dir / "points.f32");
  r.scores = readRaw<float>(dir / "scores.f32");
  r.desc = readRaw<float>(dir / "desc.f32");
  return r;
}

}  // namespace drover::test
