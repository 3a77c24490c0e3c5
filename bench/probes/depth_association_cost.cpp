// Standalone cost probe of visual::DepthAssociator (not built by CMake; bench/RESULTS.md gives the two g++ lines).
// Depth association cost: 5 s of VLP-16-like sweeps (50 x ~12k points in a 30 m box around the camera), 150 features.
#include <chrono>
#include <cstdio>
#include <random>
#include HEADER
using namespace drover;
int main() {
  visual::DepthAssociator a{visual::DepthAssociationConfig{}};
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-15, 15), h(-1, 3);
  for (int s = 0; s < 50; ++s) {
    std::vector<Eigen::Vector3d> pts;
    for (int k = 0; k < 12000; ++k) {  // walls of a 30 m box and a floor
      const int w = k % 5; const double x = u(rng), y = h(rng);
      if (w == 0) pts.emplace_back(15, x, y); else if (w == 1) pts.emplace_back(-15, x, y);
      else if (w == 2) pts.emplace_back(x, 15, y); else if (w == 3) pts.emplace_back(x, -15, y);
      else pts.emplace_back(x, u(rng), -1.0);
    }
    a.addSweep(s * 100'000'000LL, pts);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // camera looking along world x
  std::vector<Eigen::Vector2d> f;
  std::uniform_real_distribution<double> nx(-0.65, 0.65), ny(-0.5, 0.5);
  for (int k = 0; k < 150; ++k) f.emplace_back(nx(rng), ny(rng));
  int ok = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < 20; ++r) ok += a.associate(4'900'000'000LL, T, f).associated;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / 20;
  std::printf("%.2f ms per frame, %d of 150 associated\n", ms, ok / 20);
}
