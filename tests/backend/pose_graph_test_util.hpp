#pragma once
// Random SE(3) tangents for the pose-graph tests.
#include <Eigen/Core>
#include <random>

namespace drover::backend::test {

// [rho; phi] with independent normal components: sigma_position [m] for rho, sigma_rotation [rad] for phi.
inline Eigen::Matrix<double, 6, 1> randomTangent(std::mt19937& rng, double sigma_position, double sigma_rotation) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 6, 1> xi;
  for (int i = 0; i < 3; ++i) xi(i) = sigma_position * n(rng);
  for (int i = 3; i < 6; ++i) xi(i) = sigma_rotation * n(rng);
  return xi;
}

}  // namespace drover::backend::test
