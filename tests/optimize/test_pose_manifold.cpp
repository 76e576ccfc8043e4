#include "pspslam/optimize/pose_manifold.h"

#include <gtest/gtest.h>

#include "optimize/synthetic_views.h"
#include "pspslam/optimize/reprojection_error.h"

namespace pspslam {
namespace {

TEST(PoseManifold, PlusThenMinusRoundTrips) {
  const PoseManifold manifold;
  const PoseParameters x =
      PoseParameters::from_pose(testing::make_pose({0.3, -0.2, 0.1}, {1.0, -2.0, 0.5}));
  const Eigen::Matrix<double, 6, 1> delta =
      (Eigen::Matrix<double, 6, 1>() << 0.05, -0.02, 0.03, 0.1, 0.2, -0.3).finished();
  PoseParameters y;
  ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
  Eigen::Matrix<double, 6, 1> recovered;
  ASSERT_TRUE(manifold.Minus(y.data(), x.data(), recovered.data()));
  EXPECT_LT((recovered - delta).norm(), 1e-12);
}

TEST(PoseManifold, PlusIsLeftMultiplication) {
  const PoseManifold manifold;
  const Pose pose = testing::make_pose({0.3, -0.2, 0.1}, {1.0, -2.0, 0.5});
  const PoseParameters x = PoseParameters::from_pose(pose);
  const Eigen::Vector3d omega(0.1, 0.0, -0.2);
  const Eigen::Vector3d v(0.3, -0.1, 0.2);
  const Eigen::Matrix<double, 6, 1> delta = (Eigen::Matrix<double, 6, 1>() << omega, v).finished();
  PoseParameters y;
  ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
  const Pose expected = testing::make_pose(omega, v) * pose;
  EXPECT_TRUE(y.to_pose().isApprox(expected, 1e-12));
}

// The analytic tangent Jacobians of both residual kinds against central differences through Plus.
// `disparity_row`: the depth row is the disparity weighed by the sensor model (DepthNoiseModel),
// else ORB-SLAM2's u_r weighed like a pixel.
template <int kDof, ObservationRows kRows>
void check_bundle_jacobians(double huber_delta, bool disparity_row = false) {
  const PinholeCamera camera = testing::test_camera();
  DepthNoiseModel depth_noise;
  depth_noise.enabled = disparity_row;
  const StereoProjection model =
      StereoProjection::from(camera, testing::test_bf(camera), depth_noise);
  const PoseManifold manifold;
  const PoseParameters pose =
      PoseParameters::from_pose(testing::make_pose({0.2, 0.1, -0.1}, {0.1, 0.2, 0.3}));
  Eigen::Vector3d point = pose.to_pose().inverse() * Eigen::Vector3d(0.4, -0.3, 2.0);
  Measurement<kDof> measured;
  measured.setConstant(300.0);
  if constexpr (kDof == 3) measured(2) = 280.0;  // a 20 px disparity (≈2 m): u_r = u − 20
  const BundleReprojectionCost<kDof, kRows> cost(model, measured, 1.0 / 1.2, huber_delta);
  constexpr int kResiduals = 2;

  Eigen::Matrix<double, kResiduals, 1> residual;
  Eigen::Matrix<double, kResiduals, 7, Eigen::RowMajor> pose_jacobian;
  Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor> point_jacobian;
  const double* parameters[] = {pose.data(), point.data()};
  double* jacobians[] = {pose_jacobian.data(), point_jacobian.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residual.data(), jacobians));
  EXPECT_EQ(pose_jacobian.col(6).norm(), 0.0);
  if (kRows == ObservationRows::kRightPadded) {
    EXPECT_EQ(residual(1), 0.0);
    EXPECT_EQ(pose_jacobian.row(1).norm() + point_jacobian.row(1).norm(), 0.0);
  }
  // With a kernel (IRLS) the Jacobian is the plain residual's derivative weighted by √ρ'(s), not
  // the derivative of the scaled residual: differentiate the kernel-free cost and weight it.
  const BundleReprojectionCost<kDof, kRows> plain_cost(model, measured, 1.0 / 1.2, 0.0);
  const double jacobian_weight = [&] {
    if (huber_delta <= 0.0) return 1.0;
    const Eigen::Vector3d p_c = pose.to_pose() * point;
    Measurement<kDof> r = Measurement<kDof>::Zero();
    EXPECT_TRUE(whitened_residual<kDof>(model, measured, 1.0 / 1.2, p_c, r, nullptr));
    const RobustScaling s = huber_scaling(r.squaredNorm(), huber_delta);
    EXPECT_LT(s.jacobian, 1.0);  // the kernel is active at this residual
    return s.jacobian;
  }();

  const double step = 1e-6;
  for (int j = 0; j < 6; ++j) {
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    delta(j) = step;
    PoseParameters plus, minus;
    manifold.Plus(pose.data(), delta.data(), plus.data());
    delta(j) = -step;
    manifold.Plus(pose.data(), delta.data(), minus.data());
    Eigen::Matrix<double, kResiduals, 1> r_plus, r_minus;
    const double* p_plus[] = {plus.data(), point.data()};
    const double* p_minus[] = {minus.data(), point.data()};
    plain_cost.Evaluate(p_plus, r_plus.data(), nullptr);
    plain_cost.Evaluate(p_minus, r_minus.data(), nullptr);
    const Eigen::Matrix<double, kResiduals, 1> numeric = (r_plus - r_minus) / (2.0 * step);
    EXPECT_LT((jacobian_weight * numeric - pose_jacobian.col(j)).norm(), 1e-4)
        << "pose tangent column " << j;
  }
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d plus = point, minus = point;
    plus(j) += step;
    minus(j) -= step;
    Eigen::Matrix<double, kResiduals, 1> r_plus, r_minus;
    const double* p_plus[] = {pose.data(), plus.data()};
    const double* p_minus[] = {pose.data(), minus.data()};
    plain_cost.Evaluate(p_plus, r_plus.data(), nullptr);
    plain_cost.Evaluate(p_minus, r_minus.data(), nullptr);
    const Eigen::Matrix<double, kResiduals, 1> numeric = (r_plus - r_minus) / (2.0 * step);
    EXPECT_LT((jacobian_weight * numeric - point_jacobian.col(j)).norm(), 1e-4)
        << "point column " << j;
  }
}

TEST(ReprojectionError, MonocularJacobiansMatchFiniteDifferences) {
  check_bundle_jacobians<2, ObservationRows::kPixel>(0.0);
}

TEST(ReprojectionError, RgbdJacobiansMatchFiniteDifferences) {
  check_bundle_jacobians<3, ObservationRows::kPixel>(0.0);
  check_bundle_jacobians<3, ObservationRows::kRightPadded>(0.0);
  check_bundle_jacobians<3, ObservationRows::kPixel>(0.0, /*disparity_row=*/true);
  check_bundle_jacobians<3, ObservationRows::kRightPadded>(0.0, /*disparity_row=*/true);
}

// The disparity row is whitened by the sensor's σ_d = bf σ_z(z) / z², not by the pixel σ.
TEST(ReprojectionError, DisparityRowUsesTheDepthNoiseModel) {
  const PinholeCamera camera = testing::test_camera();
  const double bf = testing::test_bf(camera);
  const DepthNoiseModel depth_noise{.enabled = true};
  const StereoProjection model = StereoProjection::from(camera, bf, depth_noise);
  const Eigen::Vector3d point(0.1, -0.2, 2.0);
  const double u = camera.fx * point.x() / point.z() + camera.cx;
  const double v = camera.fy * point.y() / point.z() + camera.cy;
  // Measured 5 mm further than the point; σ_z at the measured depth.
  const double z_measured = 2.005;
  const double sigma_z = 0.0012 + 0.0019 * (z_measured - 0.4) * (z_measured - 0.4);
  const Measurement<3> measured(u, v, u - bf / z_measured);
  Eigen::Vector3d r;
  ASSERT_TRUE(whitened_residual<3>(model, measured, 1.0, point, r, nullptr));
  EXPECT_NEAR(r(0), 0.0, 1e-9);
  EXPECT_NEAR(r(1), 0.0, 1e-9);
  const double sigma_d = bf * sigma_z / (z_measured * z_measured);
  EXPECT_NEAR(r(2), (bf / z_measured - bf / point.z()) / sigma_d, 1e-9);
  // ≈ the depth error in σ_z units (−0.82), where the u_r row would say −0.026 σ.
  EXPECT_NEAR(r(2), -0.005 * z_measured / (point.z() * sigma_z), 1e-9);
}

TEST(ReprojectionError, HuberWeightedJacobiansAreScaledDerivatives) {
  // The test residuals (measurement 300 px everywhere) are far outside δ: the kernel is active.
  check_bundle_jacobians<2, ObservationRows::kPixel>(std::sqrt(5.991));
  check_bundle_jacobians<3, ObservationRows::kRightPadded>(std::sqrt(7.815));
}

TEST(ReprojectionError, HuberScalingGivesTheRobustCost) {
  const double delta = 2.0;
  EXPECT_EQ(huber_scaling(3.0, delta).residual, 1.0);  // inside: untouched
  EXPECT_EQ(huber_scaling(3.0, delta).jacobian, 1.0);
  const double s = 25.0;  // |r| = 5
  const RobustScaling scaling = huber_scaling(s, delta);
  EXPECT_NEAR(scaling.residual * scaling.residual * s, 2.0 * delta * 5.0 - delta * delta, 1e-12);
  EXPECT_NEAR(scaling.jacobian * scaling.jacobian, delta / 5.0, 1e-12);
  EXPECT_EQ(huber_scaling(s, 0.0).residual, 1.0);  // disabled
}

TEST(ReprojectionError, PointBehindCameraIsRejected) {
  const PinholeCamera camera = testing::test_camera();
  const StereoProjection model =
      StereoProjection::from(camera, testing::test_bf(camera), DepthNoiseModel{});
  EXPECT_TRUE(std::isinf(
      chi_squared<2>(model, Eigen::Vector2d(320.0, 240.0), 1.0, Eigen::Vector3d(0.0, 0.0, -1.0))));
}

}  // namespace
}  // namespace pspslam
