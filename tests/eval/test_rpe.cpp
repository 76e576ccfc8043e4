#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "pspslam/core/error.h"
#include "pspslam/eval/report.h"
#include "pspslam/eval/rpe.h"

namespace pspslam {
namespace {

constexpr double kRate = 30.0;  // Hz
constexpr int kPoses = 301;     // 10 s

// Ground truth: 1 m/s along x, with a slow yaw so rotations are not trivially identity.
// Poses at t = 50 + i / 30.
Trajectory make_trajectory(double speed, double yaw_rate_deg, double extra_yaw_rate_deg = 0.0) {
  Trajectory trajectory;
  for (int i = 0; i < kPoses; ++i) {
    const double t = i / kRate;
    StampedPose p;
    p.timestamp = 50.0 + t;
    p.T_world_camera.linear() =
        Eigen::AngleAxisd((yaw_rate_deg + extra_yaw_rate_deg) * t * std::numbers::pi / 180.0,
                          Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    p.T_world_camera.translation() = Eigen::Vector3d(speed * t, 0.0, 0.0);
    trajectory.push_back(p);
  }
  return trajectory;
}

TEST(Rpe, ConstantTranslationDrift) {
  // Without rotation the estimate's 1.1 m/s against 1.0 m/s is a drift of exactly 0.1 m/s.
  const RpeResult rpe = compute_rpe(make_trajectory(1.0, 0.0), make_trajectory(1.1, 0.0));
  // Pairs (i, i+30) for i = 0..269: evaluate_rpe.py leaves out every pair ending at the last pose.
  EXPECT_EQ(rpe.pairs.size(), 270u);
  EXPECT_NEAR(rpe.translation.rmse, 0.1, 1e-9);
  EXPECT_NEAR(rpe.translation.min, 0.1, 1e-9);
  EXPECT_NEAR(rpe.translation.max, 0.1, 1e-9);
  EXPECT_NEAR(rpe.translation_per_second.mean, 0.1, 1e-9);
  EXPECT_LT(rpe.rotation.max, 1e-6);
}

TEST(Rpe, ConstantRotationDrift) {
  // Same path, estimate yaws 2 deg/s faster than the ground truth's 5 deg/s.
  const RpeResult rpe = compute_rpe(make_trajectory(0.0, 5.0), make_trajectory(0.0, 5.0, 2.0));
  EXPECT_NEAR(rpe.rotation.rmse, 2.0, 1e-6);
  EXPECT_NEAR(rpe.rotation.median, 2.0, 1e-6);
  EXPECT_NEAR(rpe.rotation_per_second.max, 2.0, 1e-6);
  EXPECT_LT(rpe.translation.max, 1e-12);
}

TEST(Rpe, FrameDeltaEqualsSecondsAtKnownRate) {
  RpeOptions frames;
  frames.unit = RpeDeltaUnit::frames;
  frames.delta = 15;  // 0.5 s at 30 Hz
  const RpeResult rpe = compute_rpe(make_trajectory(1.0, 0.0), make_trajectory(1.2, 0.0), frames);
  EXPECT_EQ(rpe.pairs.size(), 285u);
  EXPECT_NEAR(rpe.translation.mean, 0.2 * 0.5, 1e-9);
  EXPECT_NEAR(rpe.translation_per_second.mean, 0.2, 1e-9);
}

TEST(Rpe, IdenticalTrajectoriesHaveZeroError) {
  const Trajectory gt = make_trajectory(0.7, 12.0);
  const RpeResult rpe = compute_rpe(gt, gt);
  EXPECT_LT(rpe.translation.max, 1e-12);
  EXPECT_LT(rpe.rotation.max, 1e-5);  // acos near 1 amplifies rounding: ~1e-6 deg
}

// A hand-held camera: yaw, pitch and roll all vary, so relative rotations turn about many axes.
Trajectory hand_held_trajectory() {
  Trajectory trajectory;
  for (int i = 0; i < kPoses; ++i) {
    const double t = i / kRate;
    const double deg = std::numbers::pi / 180.0;
    StampedPose p;
    p.timestamp = 50.0 + t;
    p.T_world_camera.linear() =
        (Eigen::AngleAxisd(20.0 * t * deg, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(10.0 * std::sin(t) * deg, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(8.0 * std::cos(1.3 * t) * deg, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    p.T_world_camera.translation() = Eigen::Vector3d(0.3 * t, 0.1 * std::sin(t), 0.0);
    trajectory.push_back(p);
  }
  return trajectory;
}

TEST(Rpe, BodyFrameRotationIsZeroForTheSameBody) {
  const Trajectory camera = hand_held_trajectory();
  const RpeResult rpe = compute_rpe(camera, camera);
  EXPECT_LT(rpe.body_frame_rotation_deg, 0.1);
  EXPECT_FALSE(rpe.body_frames_differ());
}

TEST(Rpe, GroundTruthOfAnotherBodyIsDetectedAndReported) {
  // The ground truth tracks a marker body turned 120 deg from the camera (as bonn_crowd_dev's
  // motion capture: 171 deg): same positions, so the ATE would be 0, but RPE compares motions
  // expressed in different frames.
  const Trajectory camera = hand_held_trajectory();
  const Eigen::Matrix3d camera_to_marker =
      Eigen::AngleAxisd(120.0 * std::numbers::pi / 180.0, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  Trajectory marker = camera;
  for (StampedPose& p : marker) p.T_world_camera.linear() *= camera_to_marker;
  const RpeResult rpe = compute_rpe(marker, camera);
  EXPECT_NEAR(rpe.body_frame_rotation_deg, 120.0, 0.5);
  EXPECT_TRUE(rpe.body_frames_differ());
  EXPECT_GT(rpe.translation.rmse, 0.1);  // meaningless: the same positions give 0.1+ m "error"
  const EvalSettings settings;
  EXPECT_NE(format_eval_table(settings, compute_ate(marker, camera), rpe)
                .find("warning: the ground truth's body frame is rotated 120 deg"),
            std::string::npos);
  EXPECT_NE(format_eval_json(settings, compute_ate(marker, camera), rpe)
                .find("\"body_frames_differ\": true"),
            std::string::npos);
}

TEST(Rpe, BodyFrameRotationIsUndeterminedForTurnsAboutOneAxis) {
  const Trajectory yaw_only = make_trajectory(0.7, 12.0);
  const RpeResult rpe = compute_rpe(yaw_only, yaw_only);
  EXPECT_TRUE(std::isnan(rpe.body_frame_rotation_deg));
  EXPECT_FALSE(rpe.body_frames_differ());
  EXPECT_NE(format_eval_json({}, compute_ate(yaw_only, yaw_only), rpe)
                .find("\"body_frame_rotation_deg\": null"),
            std::string::npos);
}

TEST(Rpe, TooShortOrDisjointTrajectoriesAreErrors) {
  const Trajectory gt = make_trajectory(1.0, 0.0);
  Trajectory late = gt;
  for (StampedPose& p : late) p.timestamp += 1000.0;
  try {
    compute_rpe(gt, late);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "RPE: only 0 pose pairs 1 s apart have ground truth at both ends (need at "
                 "least 2); is the trajectory shorter than the delta, or the wrong ground truth?");
  }
  EXPECT_THROW(compute_rpe(gt, Trajectory(gt.begin(), gt.begin() + 1)), Error);
}

}  // namespace
}  // namespace pspslam
