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

MoverGuard enabled_guard() {
  MoverGuardOptions options;
  options.enabled = true;
  options.smoothing = 1.0;  // the average is the last believed frame
  return MoverGuard(options);
}

TEST(MoverGuard, BelievesFramesThatAgreeWithThePredictionOrKeepTheirInliers) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(300, shifted(0.0), shifted(0.0)));
  // Few inliers, but on the prediction: a texture-poor view, not a crowd.
  EXPECT_FALSE(guard.should_hold(100, shifted(0.005), shifted(0.0)));
  EXPECT_FALSE(guard.should_hold(300, shifted(0.0), shifted(0.0)));
  // Off the prediction with as many inliers as usual: the camera really accelerated.
  EXPECT_FALSE(guard.should_hold(290, shifted(0.05), shifted(0.0)));
}

TEST(MoverGuard, HoldsThePredictionForAFewFramesWhenInliersDropAndThePoseJumps) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(300, shifted(0.0), shifted(0.0)));
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(guard.should_hold(120, shifted(0.05), shifted(0.0)));
  // Still jumping after three held frames: the measurement is believed again.
  EXPECT_FALSE(guard.should_hold(120, shifted(0.05), shifted(0.0)));
}

TEST(MoverGuard, ARotationJumpCountsAndAResetForgetsTheAverage) {
  MoverGuard guard = enabled_guard();
  EXPECT_FALSE(guard.should_hold(300, Pose::Identity(), Pose::Identity()));
  Pose turned = Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_TRUE(guard.should_hold(100, turned, Pose::Identity()));
  guard.reset();
  EXPECT_FALSE(guard.should_hold(100, turned, Pose::Identity()));  // no average to drop from
}

TEST(MoverGuard, NeverHoldsWhenDisabled) {
  MoverGuard guard;
  EXPECT_FALSE(guard.should_hold(300, shifted(0.0), shifted(0.0)));
  EXPECT_FALSE(guard.should_hold(10, shifted(1.0), shifted(0.0)));
}

}  // namespace
}  // namespace pspslam
