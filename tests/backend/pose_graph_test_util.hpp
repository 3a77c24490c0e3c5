#pragma once
// Random SE(3) tangents, a helix of poses and diagonal informations for the pose-graph tests.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "geometry/so3.hpp"

namespace drover::backend::test {

// [rho; phi] with independent normal components: sigma_position [m] for rho, sigma_rotation [rad] for phi.
inline Eigen::Matrix<double, 6, 1> randomTangent(std::mt19937& rng, double sigma_position, double sigma_rotation) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 6, 1> xi;
  for (int i = 0; i < 3; ++i) xi(i) = sigma_position * n(rng);
  for (int i = 3; i < 6; ++i) xi(i) = sigma_rotation * n(rng);
  return xi;
}

// n poses on one turn of a helix (radius 10 m, climbing 2 m), heading along the path, with some roll.
inline std::vector<Eigen::Isometry3d> helix(int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << 10 * std::cos(a), 10 * std::sin(a), 2.0 * k / n;
    T.linear() = geometry::expSO3(Eigen::Vector3d(0.1 * std::sin(3 * a), 0.05, a + std::numbers::pi / 2));
    poses.push_back(T);
  }
  return poses;
}

// Diagonal information: 1 / sigma_position^2 [1/m^2] for the translation, 1 / sigma_rotation^2 [1/rad^2].
inline Eigen::Matrix<double, 6, 6> information(double sigma_position, double sigma_rotation) {
  Eigen::Matrix<double, 6, 1> d;
  d << Eigen::Vector3d::Constant(1 / (sigma_position * sigma_position)),
      Eigen::Vector3d::Constant(1 / (sigma_rotation * sigma_rotation));
  return d.asDiagonal();
}

}  // namespace drover::backend::test
