#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "pspslam/core/error.h"
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
