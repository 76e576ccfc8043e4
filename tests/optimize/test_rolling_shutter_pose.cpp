#include "pspslam/optimize/rolling_shutter_pose.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "pspslam/optimize/pose_optimizer.h"

namespace pspslam {
namespace {

// A frame whose keypoints were moved to its instant with a rate 0.15 rad/s (~9 deg/s) off the
// true one: each point appears where the camera, turned by rho dt, saw it. 1 px noise, 300
// points, half of them with depth (RGB-D rows), a 30 ms readout.
struct SkewedFrame {
  PinholeCamera camera;
  double bf = 525.0 * 0.08;
  Pose T_camera_world;
  Eigen::Vector3d rho{0.05, -0.15, 0.03};
  std::vector<PoseObservation> observations;
  std::vector<double> row_times;
};

SkewedFrame make_frame() {
  SkewedFrame frame;
  frame.T_camera_world.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  frame.T_camera_world.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(10.0, 630.0), v(10.0, 470.0), z(1.0, 4.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Pose T_world_camera = frame.T_camera_world.inverse();
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p = frame.camera.unproject({u(rng), v(rng)}, z(rng));
    const double dt = 0.030 * ((frame.camera.project(p).y() + 0.5) / frame.camera.height - 0.5);
    const Eigen::Vector3d seen =
        Eigen::AngleAxisd(-frame.rho.norm() * dt, frame.rho.normalized()) * p;
    const Eigen::Vector2d pixel =
        frame.camera.project(seen) + Eigen::Vector2d(noise(rng), noise(rng));
    const double right_u =
        i % 2 == 0 ? pixel.x() - frame.bf / seen.z() : std::numeric_limits<double>::quiet_NaN();
    frame.observations.push_back({T_world_camera * p, pixel, right_u, 1.0});
    frame.row_times.push_back(dt);
  }
  return frame;
}

TEST(RollingShutterPose, MeasuresTheRateTheKeypointsWereMovedWithout) {
  const SkewedFrame frame = make_frame();
  // Start where a pose-only optimisation that knows no rolling shutter ends.
  const PoseOptimizationResult rigid =
      optimize_pose(frame.camera, frame.bf, frame.T_camera_world, frame.observations);
  const RollingShutterPose refined = refine_pose_and_rotation_rate(
      frame.camera, frame.bf, PoseOptimizerOptions{}.depth_noise, rigid.T_camera_world,
      frame.observations, frame.row_times, /*sigma_rate=*/10.0);
  // The skew is +-1.2 px at the top and bottom rows against 1 px noise on 300 points: the rate is
  // measured to ~0.01 rad/s about the axes that shear or stretch the image.
  EXPECT_LT((refined.rate_correction - frame.rho).norm(), 0.03)
      << refined.rate_correction.transpose();
  const auto rotation_error = [&](const Pose& pose) {
    return Eigen::AngleAxisd(pose.linear() * frame.T_camera_world.linear().transpose()).angle();
  };
  const auto translation_error = [&](const Pose& pose) {
    return (pose.inverse().translation() - frame.T_camera_world.inverse().translation()).norm();
  };
  EXPECT_LT(rotation_error(refined.T_camera_world), 0.5 * rotation_error(rigid.T_camera_world));
  EXPECT_LT(translation_error(refined.T_camera_world), 0.002);
}

TEST(RollingShutterPose, ThePriorHoldsTheRateWhereTheImageCannotTell) {
  SkewedFrame frame = make_frame();
  frame.observations.resize(6);  // six points cannot separate a shear from the pose
  frame.row_times.resize(6);
  const RollingShutterPose refined = refine_pose_and_rotation_rate(
      frame.camera, frame.bf, PoseOptimizerOptions{}.depth_noise, frame.T_camera_world,
      frame.observations, frame.row_times, /*sigma_rate=*/0.001);
  EXPECT_LT(refined.rate_correction.norm(), 0.01);
}

TEST(RollingShutterPose, DegenerateInputReturnsTheStart) {
  const SkewedFrame frame = make_frame();
  const std::vector<PoseObservation> none;
  const RollingShutterPose empty = refine_pose_and_rotation_rate(
      frame.camera, frame.bf, DepthNoiseModel{}, frame.T_camera_world, none, {}, 0.03);
  EXPECT_TRUE(empty.T_camera_world.isApprox(frame.T_camera_world));
  EXPECT_EQ(empty.rate_correction, Eigen::Vector3d::Zero());
  // A point behind the camera: no step is taken.
  std::vector<PoseObservation> behind = frame.observations;
  behind[0].point_world = frame.T_camera_world.inverse() * Eigen::Vector3d(0.0, 0.0, -1.0);
  const RollingShutterPose refused =
      refine_pose_and_rotation_rate(frame.camera, frame.bf, DepthNoiseModel{}, frame.T_camera_world,
                                    behind, frame.row_times, 0.03);
  EXPECT_TRUE(refused.T_camera_world.isApprox(frame.T_camera_world));
  EXPECT_EQ(refused.rate_correction, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace pspslam
