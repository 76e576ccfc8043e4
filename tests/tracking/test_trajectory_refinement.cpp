#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pspslam/tracking/trajectory_refinement.h"

namespace pspslam {
namespace {

Pose pose(double yaw_deg, const Eigen::Vector3d& translation) {
  Pose p = Pose::Identity();
  p.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = translation;
  return p;
}

double yaw_deg(const Pose& p) {
  return std::atan2(p.linear()(1, 0), p.linear()(0, 0)) * 180.0 / M_PI;
}

// Frames at t = 0..4 s tracked on a straight line, each turned by its own yaw; the keyframes at
// t = 1 and t = 3 were moved by mapping by known world-frame corrections.
std::vector<TrackedFramePose> straight_line() {
  std::vector<TrackedFramePose> frames;
  for (int i = 0; i < 5; ++i) {
    TrackedFramePose& frame = frames.emplace_back();
    frame.timestamp = static_cast<double>(i);
    frame.T_world_camera_tracked = pose(10.0 * i, {0.5 * i, 0.0, 1.0});
    frame.T_world_camera_through_reference = frame.T_world_camera_tracked;
  }
  return frames;
}

const Pose kFirstCorrection = pose(0.0, {0.10, 0.0, 0.0});
const Pose kSecondCorrection = pose(20.0, {0.30, -0.2, 0.0});

TEST(TrajectoryRefinement, WithoutKeyframesFramesGoThroughTheirReferenceKeyframes) {
  std::vector<TrackedFramePose> frames = straight_line();
  for (TrackedFramePose& frame : frames)
    frame.T_world_camera_through_reference = kFirstCorrection * frame.T_world_camera_tracked;
  const Trajectory refined = refine_by_keyframe_corrections(frames);
  ASSERT_EQ(refined.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_DOUBLE_EQ(refined[i].timestamp, frames[i].timestamp);
    EXPECT_TRUE(
        refined[i].T_world_camera.isApprox(frames[i].T_world_camera_through_reference, 1e-12));
  }
}

TEST(TrajectoryRefinement, NeverInterpolatesAcrossAMapCorrection) {
  // A loop correction between t = 2 and t = 3: frames 0-2 were tracked in the uncorrected map,
  // frames 3-4 in the corrected one. Frame 2 takes the keyframe-1 correction alone.
  std::vector<TrackedFramePose> frames = straight_line();
  frames[3].map_epoch = frames[4].map_epoch = 1;
  frames[1].T_world_camera_keyframe_now = kFirstCorrection * frames[1].T_world_camera_tracked;
  frames[3].T_world_camera_keyframe_now = kSecondCorrection * frames[3].T_world_camera_tracked;
  const Trajectory refined = refine_by_keyframe_corrections(frames);
  ASSERT_EQ(refined.size(), 5u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(refined[i].T_world_camera.isApprox(
        kFirstCorrection * frames[i].T_world_camera_tracked, 1e-12))
        << "frame " << i;
  }
  for (size_t i = 3; i < 5; ++i) {
    EXPECT_TRUE(refined[i].T_world_camera.isApprox(
        kSecondCorrection * frames[i].T_world_camera_tracked, 1e-12))
        << "frame " << i;
  }
  // An epoch whose keyframes were all culled: its frames go through their reference keyframes.
  frames[3].T_world_camera_keyframe_now.reset();
  frames[3].T_world_camera_through_reference = kSecondCorrection;
  const Trajectory without = refine_by_keyframe_corrections(frames);
  EXPECT_TRUE(without[3].T_world_camera.isApprox(kSecondCorrection, 1e-12));
  EXPECT_TRUE(without[4].T_world_camera.isApprox(frames[4].T_world_camera_tracked, 1e-12));
}

TEST(TrajectoryRefinement, FramesFollowTheCorrectionsOfTheKeyframesAroundThem) {
  std::vector<TrackedFramePose> frames = straight_line();
  frames[1].T_world_camera_keyframe_now = kFirstCorrection * frames[1].T_world_camera_tracked;
  frames[3].T_world_camera_keyframe_now = kSecondCorrection * frames[3].T_world_camera_tracked;
  const Trajectory refined = refine_by_keyframe_corrections(frames);
  ASSERT_EQ(refined.size(), 5u);

  // Keyframes land exactly on their current poses.
  EXPECT_TRUE(refined[1].T_world_camera.isApprox(*frames[1].T_world_camera_keyframe_now, 1e-12));
  EXPECT_TRUE(refined[3].T_world_camera.isApprox(*frames[3].T_world_camera_keyframe_now, 1e-12));
  // Before the first and after the last keyframe: that keyframe's correction.
  EXPECT_TRUE(refined[0].T_world_camera.isApprox(
      kFirstCorrection * frames[0].T_world_camera_tracked, 1e-12));
  EXPECT_TRUE(refined[4].T_world_camera.isApprox(
      kSecondCorrection * frames[4].T_world_camera_tracked, 1e-12));
  // Halfway between: half of each correction. Tracked frame 2 is at (1, 0, 1) with yaw 20°; the
  // halfway correction turns it by 10° about the world origin's z axis and adds (0.2, -0.1, 0).
  const double c = std::cos(10.0 * M_PI / 180.0), s = std::sin(10.0 * M_PI / 180.0);
  const Eigen::Vector3d expected(c * 1.0 + 0.2, s * 1.0 - 0.1, 1.0);
  EXPECT_NEAR((refined[2].T_world_camera.translation() - expected).norm(), 0.0, 1e-12);
  EXPECT_NEAR(yaw_deg(refined[2].T_world_camera), 30.0, 1e-9);
}

TEST(TrajectoryRefinement, InterpolatesByTimeNotByFrameCount) {
  std::vector<TrackedFramePose> frames = straight_line();
  frames[2].timestamp = 1.25;  // a quarter of the way from the keyframe at 1 s to the one at 2 s
  frames.erase(frames.begin() + 3);
  frames[3].timestamp = 2.0;
  frames[1].T_world_camera_keyframe_now = kFirstCorrection * frames[1].T_world_camera_tracked;
  frames[3].T_world_camera_keyframe_now = kSecondCorrection * frames[3].T_world_camera_tracked;
  const Trajectory refined = refine_by_keyframe_corrections(frames);
  const Eigen::Vector3d tracked = frames[2].T_world_camera_tracked.translation();
  const double angle = 5.0 * M_PI / 180.0;  // a quarter of 20°
  const Eigen::Vector3d expected(
      std::cos(angle) * tracked.x() - std::sin(angle) * tracked.y() + 0.15,
      std::sin(angle) * tracked.x() + std::cos(angle) * tracked.y() - 0.05, tracked.z());
  EXPECT_NEAR((refined[2].T_world_camera.translation() - expected).norm(), 0.0, 1e-12);
  EXPECT_NEAR(yaw_deg(refined[2].T_world_camera), 25.0, 1e-9);
}

}  // namespace
}  // namespace pspslam
