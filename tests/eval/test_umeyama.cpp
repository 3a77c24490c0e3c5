// Umeyama alignment (PAMI 1991) as evo's umeyama_alignment / align_trajectory.
#include <gtest/gtest.h>

#include <numbers>
#include <stdexcept>

#include "eval/umeyama.hpp"
#include "eval_fixtures.hpp"

namespace drover::eval {
namespace {

Eigen::Matrix3Xd somePoints() {
  Eigen::Matrix3Xd x(3, 6);
  x << 0, 1, 2, 0.5, -1, 3,  //
      0, 0, 1, 2, 1.5, -1,   //
      0, 0.2, -0.3, 1, 0.1, 2;
  return x;
}

TEST(Umeyama, RecoversAKnownSim3Exactly) {
  const Eigen::Matrix3d R = geometry::expSO3(Eigen::Vector3d(0.3, -1.1, 2.0));
  const Eigen::Vector3d t(4.0, -2.0, 0.5);
  const double s = 2.5;
  const Eigen::Matrix3Xd x = somePoints();
  const Eigen::Matrix3Xd y = ((s * R) * x).colwise() + t;
  const Sim3 a = umeyamaAlignment(x, y, true);
  EXPECT_TRUE(a.R.isApprox(R, 1e-12)) << a.R;
  EXPECT_TRUE(a.t.isApprox(t, 1e-12)) << a.t.transpose();
  EXPECT_NEAR(a.scale, s, 1e-12);
  EXPECT_NEAR(a.R.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, Se3AlignmentKeepsScaleOne) {
  const Eigen::Matrix3d R = geometry::expSO3(Eigen::Vector3d(-0.4, 0.2, 0.9));
  const Eigen::Vector3d t(-1.0, 3.0, 7.0);
  const Eigen::Matrix3Xd x = somePoints();
  const Eigen::Matrix3Xd y = (R * x).colwise() + t;
  const Sim3 a = umeyamaAlignment(x, y, false);
  EXPECT_TRUE(a.R.isApprox(R, 1e-12));
  EXPECT_TRUE(a.t.isApprox(t, 1e-12));
  EXPECT_EQ(a.scale, 1.0);
}

TEST(Umeyama, ScaleFollowsUmeyamasVarianceDefinition) {
  // x_i = (+-1, 0, 0), (0, +-1, 0); y_i = x_i + (0, 0, h_i) with h_i = h, h, -h, -h, so sum x_i h_i = 0.
  // Cross-covariance diag(1/2, 1/2, 0), sigma_x^2 = 1: c = tr(D S) / sigma_x^2 = 1 (Eq. 42).
  // Swapping the roles (align y onto x): same covariance, sigma_y^2 = 1 + h^2, so c = 1 / (1 + h^2).
  const double h = 0.5;
  Eigen::Matrix3Xd x(3, 4), y(3, 4);
  x << 1, -1, 0, 0, 0, 0, 1, -1, 0, 0, 0, 0;
  y = x;
  y.row(2) << h, h, -h, -h;
  EXPECT_NEAR(umeyamaAlignment(x, y, true).scale, 1.0, 1e-12);
  EXPECT_NEAR(umeyamaAlignment(y, x, true).scale, 1.0 / (1.0 + h * h), 1e-12);
}

TEST(Umeyama, ReflectionIsAvoided) {
  // y is a mirror image of x (z flipped): the best proper rotation still has det = +1.
  const Eigen::Matrix3Xd x = somePoints();
  Eigen::Matrix3Xd y = x;
  y.row(2) *= -1.0;
  const Sim3 a = umeyamaAlignment(x, y, false);
  EXPECT_NEAR(a.R.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, RejectsCollinearOrTooFewPoints) {
  Eigen::Matrix3Xd line(3, 5);
  line << 0, 1, 2, 3, 4, 0, 2, 4, 6, 8, 0, -1, -2, -3, -4;
  EXPECT_THROW(umeyamaAlignment(line, line, false), std::invalid_argument);
  EXPECT_THROW(umeyamaAlignment(line, line, true), std::invalid_argument);
  const Eigen::Matrix3Xd two = somePoints().leftCols(2);
  EXPECT_THROW(umeyamaAlignment(two, two, false), std::invalid_argument);
  const Eigen::Matrix3Xd one = somePoints().leftCols(1);
  EXPECT_THROW(umeyamaAlignment(one, one, false), std::invalid_argument);
  EXPECT_THROW(umeyamaAlignment(somePoints(), somePoints().leftCols(5), false), std::invalid_argument);
  // Three non-collinear points are enough.
  const Eigen::Matrix3Xd three = somePoints().leftCols(3);
  EXPECT_NO_THROW(umeyamaAlignment(three, three, false));
}

TEST(Umeyama, ApplyAlignmentScalesTranslationsOnlyThenTransforms) {
  // evo's align_trajectory with scale: t' = s R t + t_a, R' = R_a R; the rotation is not scaled.
  Sim3 a;
  a.R = geometry::expSO3(Eigen::Vector3d(0, 0, std::numbers::pi / 2));
  a.t = Eigen::Vector3d(1, 0, 0);
  a.scale = 2.0;
  const Trajectory in{{5, test::pose(Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(1, 2, 3))}};
  const Trajectory out = applyAlignment(in, a);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].t, 5);
  // 2 * Rz(90) (1, 2, 3) + (1, 0, 0) = 2 * (-2, 1, 3) + (1, 0, 0) = (-3, 2, 6).
  EXPECT_TRUE(out[0].T_world_body.translation().isApprox(Eigen::Vector3d(-3, 2, 6), 1e-12));
  EXPECT_TRUE(out[0].T_world_body.linear().isApprox(a.R * geometry::expSO3(Eigen::Vector3d(0.2, 0, 0)), 1e-12));
}

}  // namespace
}  // namespace drover::eval
