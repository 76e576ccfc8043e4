#include <gtest/gtest.h>

#include "pspslam/dynamic/late_mask_frames.h"

namespace pspslam {
namespace {

SegmentedFrame segmented(std::int64_t id, double x = 0.0) {
  Pose pose = Pose::Identity();
  pose.translation().x() = x;
  return {id, 0, pose, {}};
}

TEST(LateMaskFrames, AMaskFindsItsOwnFrameOnceAndOlderFramesAreForgotten) {
  LateMaskFrames frames(4);
  for (std::int64_t id : {3, 5, 8}) frames.remember(segmented(id, static_cast<double>(id)));
  EXPECT_FALSE(frames.take(4));  // never segmented
  const auto five = frames.take(5);
  ASSERT_TRUE(five);
  EXPECT_EQ(five->id, 5);
  EXPECT_DOUBLE_EQ(five->T_world_camera.translation().x(), 5.0);
  EXPECT_FALSE(frames.take(5));  // judged once
  EXPECT_FALSE(frames.take(3));  // skipped by the thread: forgotten when 5 arrived
  EXPECT_TRUE(frames.take(8));
  // Only the newest `capacity` frames wait.
  for (std::int64_t id = 10; id < 16; ++id) frames.remember(segmented(id));
  EXPECT_FALSE(frames.take(11));
  EXPECT_TRUE(frames.take(12));
}

}  // namespace
}  // namespace pspslam
