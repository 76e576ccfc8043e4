#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "pspslam/tracking/mover_guard.h"

namespace pspslam {
namespace {

Pose shifted(double x_m) {
  Pose pose = Pose::Identity();
  pose.translation().x() = x_m;
  return pose;
}

constexpr double kFramePeriod = 1.0 / 30.0;

GuardedFrame frame(int inliers, const Pose& optimised, const Pose& predicted,
                   bool on_stale_mask = false, double seconds = kFramePeriod) {
  return {.inliers = inliers,
          .optimised = optimised,
          .predicted = predicted,
          .seconds = seconds,
          .on_stale_mask = on_stale_mask};
}

MoverGuard enabled_guard() {
  MoverGuardOptions options;
  options.enabled = true;
  options.smoothing = 1.0;  // the average is the last believed frame
  return MoverGuard(options);
}

TEST(MoverGuard, BelievesFramesThatAgreeWithThePredictionOrKeepTheirInliers) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(frame(300, shifted(0.0), shifted(0.0))));
  // Few inliers, but on the prediction: a texture-poor view, not a crowd.
  EXPECT_FALSE(guard.should_hold(frame(100, shifted(0.005), shifted(0.0))));
  EXPECT_FALSE(guard.should_hold(frame(300, shifted(0.0), shifted(0.0))));
  // Off the prediction with as many inliers as usual: the camera really accelerated.
  EXPECT_FALSE(guard.should_hold(frame(290, shifted(0.05), shifted(0.0))));
}

TEST(MoverGuard, HoldsThePredictionForAFewFramesWhenInliersDropAndThePoseJumps) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(frame(300, shifted(0.0), shifted(0.0))));
  for (int i = 0; i < 3; ++i)
    EXPECT_TRUE(guard.should_hold(frame(120, shifted(0.05), shifted(0.0))));
  // Still jumping after three held frames: the measurement is believed again.
  EXPECT_FALSE(guard.should_hold(frame(120, shifted(0.05), shifted(0.0))));
}

TEST(MoverGuard, ARotationJumpCountsAndAResetForgetsTheAverage) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(frame(300, Pose::Identity(), Pose::Identity())));
  Pose turned = Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_TRUE(guard.should_hold(frame(100, turned, Pose::Identity())));
  guard.reset();
  EXPECT_FALSE(guard.should_hold(frame(100, turned, Pose::Identity())));  // no average to drop from
}

TEST(MoverGuard, WithoutAStaleMaskNeverHoldsUnlessEnabled) {
  MoverGuard guard;
  EXPECT_FALSE(guard.watches(/*on_stale_mask=*/false));
  EXPECT_FALSE(guard.should_hold(frame(300, shifted(0.0), shifted(0.0))));
  EXPECT_FALSE(guard.should_hold(frame(10, shifted(1.0), shifted(0.0))));
}

TEST(MoverGuard, OnAStaleMaskHoldsJumpsFasterThanACameraMoves) {
  MoverGuard guard;  // the jump rule's defaults: 6 m/s, 6 rad/s
  EXPECT_TRUE(guard.watches(/*on_stale_mask=*/true));
  // 0.15 m off the prediction in a frame: a hard jolt, but a camera can do it.
  EXPECT_FALSE(guard.should_hold(frame(40, shifted(0.15), shifted(0.0), true)));
  // 0.4 m in a frame is 12 m/s: held for three frames, then believed.
  for (int i = 0; i < 3; ++i)
    EXPECT_TRUE(guard.should_hold(frame(40, shifted(0.4), shifted(0.0), true)));
  EXPECT_FALSE(guard.should_hold(frame(40, shifted(0.4), shifted(0.0), true)));
  // The same 0.4 m after 0.1 s (frames dropped between) is 4 m/s.
  EXPECT_FALSE(guard.should_hold(frame(40, shifted(0.4), shifted(0.0), true, 0.1)));
  // On a fresh mask the tracker's pose is believed.
  EXPECT_FALSE(guard.should_hold(frame(40, shifted(1.0), shifted(0.0), false)));
  Pose turned = Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_TRUE(guard.should_hold(frame(40, turned, Pose::Identity(), true)));
}

TEST(MoverGuard, TheJumpRuleCanBeTurnedOff) {
  MoverGuardOptions options;
  options.hold_jumps_on_stale_masks = false;
  MoverGuard guard(options);
  EXPECT_FALSE(guard.watches(/*on_stale_mask=*/true));
  EXPECT_FALSE(guard.should_hold(frame(40, shifted(1.0), shifted(0.0), true)));
}

}  // namespace
}  // namespace pspslam
