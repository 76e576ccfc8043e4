#include <gtest/gtest.h>

#include "pspslam/tracking/keyframe_policy.h"

namespace pspslam {
namespace {

KeyFrameEvidence steady_tracking() {
  KeyFrameEvidence e;
  e.frame_id = 100;
  e.last_keyframe_frame_id = 95;
  e.keyframes_in_map = 10;
  e.tracked_inliers = 420;  // 0.93 of the reference
  e.reference_tracked_points = 450;
  e.tracked_close_points = 300;
  e.untracked_close_points = 50;
  return e;
}

TEST(KeyFramePolicy, NoKeyFrameWhileTrackingTheReferenceWell) {
  EXPECT_EQ(decide_keyframe(steady_tracking(), {}), KeyFrameDecision::kSkip);
}

TEST(KeyFramePolicy, KeyFrameWhenFewerPointsThanTheReference) {
  KeyFrameEvidence e = steady_tracking();
  e.tracked_inliers = 300;  // < 0.9 * 450, mapper idle
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInsert);
  e.mapper_idle = false;
  e.last_keyframe_frame_id = 99;
  // Busy with nothing queued: the keyframe goes in and cuts the mapper's BA short.
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInsertInterruptingMapper);
  KeyFramePolicyOptions orb_slam2;
  orb_slam2.insert_while_mapping = false;
  EXPECT_EQ(decide_keyframe(e, orb_slam2), KeyFrameDecision::kSkip);  // busy and not yet due
  e.mapper_queue = 1;
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kSkip);  // one waits already, not yet due
  e.last_keyframe_frame_id = 60;                               // due: 40 > 30 frames
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInsertInterruptingMapper);
  EXPECT_EQ(decide_keyframe(e, orb_slam2), KeyFrameDecision::kInsertInterruptingMapper);
  e.mapper_queue = 3;
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInterruptMapper);
}

TEST(KeyFramePolicy, DueKeyFrameEvenWhenTheReferenceCountIsLow) {
  // The reference keyframe's points seen by >= 3 keyframes are few (sparse keyframes), so the
  // frame tracks more than 0.9 of them although it has moved on.
  KeyFrameEvidence e = steady_tracking();
  e.reference_tracked_points = 110;
  e.tracked_inliers = 105;
  e.last_keyframe_frame_id = 69;  // 31 frames ago: due (max_frames_between 30)
  KeyFramePolicyOptions when_due;
  when_due.insert_when_due = true;
  EXPECT_EQ(decide_keyframe(e, when_due), KeyFrameDecision::kInsert);
  e.mapper_idle = false;
  EXPECT_EQ(decide_keyframe(e, when_due), KeyFrameDecision::kInsertInterruptingMapper);
  e.mapper_idle = true;
  e.last_keyframe_frame_id = 71;  // 29 frames ago: not yet due
  EXPECT_EQ(decide_keyframe(e, when_due), KeyFrameDecision::kSkip);
  e.last_keyframe_frame_id = 69;
  // The default (ORB-SLAM2): due, but gated on the ratio.
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kSkip);
  e.tracked_inliers = 15;  // too few inliers to make a reliable keyframe
  EXPECT_EQ(decide_keyframe(e, when_due), KeyFrameDecision::kSkip);
}

TEST(KeyFramePolicy, TrackedRatioToReferenceIsTheThreshold) {
  KeyFrameEvidence e = steady_tracking();
  e.tracked_inliers = 400;  // 0.89 of the reference's 450 points
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInsert);
  e.tracked_inliers = 370;  // 0.82
  KeyFramePolicyOptions orb_slam2;
  orb_slam2.tracked_ratio_to_reference = 0.75;
  EXPECT_EQ(decide_keyframe(e, orb_slam2), KeyFrameDecision::kSkip);
  e.tracked_inliers = 330;  // 0.73
  EXPECT_EQ(decide_keyframe(e, orb_slam2), KeyFrameDecision::kInsert);
}

TEST(KeyFramePolicy, KeyFrameWhenCloseStructureIsUntracked) {
  KeyFrameEvidence e = steady_tracking();
  e.tracked_close_points = 90;    // < 100 tracked close points
  e.untracked_close_points = 80;  // > 70 untracked ones
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kInsert);
  e.tracked_inliers = 15;  // too few inliers to make a reliable keyframe
  EXPECT_EQ(decide_keyframe(e, {}), KeyFrameDecision::kSkip);
}

}  // namespace
}  // namespace pspslam
