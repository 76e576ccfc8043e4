#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

#include "pspslam/dynamic/dynamic_point_culler.h"
#include "pspslam/dynamic/late_mask_frames.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

PinholeCamera small_camera() {
  PinholeCamera camera;
  camera.width = 160;
  camera.height = 120;
  camera.fx = camera.fy = 100.0;
  camera.cx = 80.0;
  camera.cy = 60.0;
  return camera;
}

TEST(DynamicPointCuller, PointsRepeatedlyOnDynamicPixelsAreCulledOccludedOnesAreNot) {
  const PinholeCamera camera = small_camera();
  // Dynamic region: the left half. Measured depth 2 m everywhere.
  cv::Mat mask = cv::Mat::zeros(120, 160, CV_8UC1);
  mask(cv::Rect(0, 0, 80, 120)).setTo(255);
  const cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(2.0f));

  auto on_person = std::make_shared<MapPoint>(1, Eigen::Vector3d(-0.5, 0.0, 2.0), nullptr);
  // Behind the person (4 m): occluded by it, still a valid static point.
  auto occluded = std::make_shared<MapPoint>(2, Eigen::Vector3d(-1.0, 0.0, 4.0), nullptr);
  auto static_side = std::make_shared<MapPoint>(3, Eigen::Vector3d(0.5, 0.0, 2.0), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {on_person, occluded, static_side};

  DynamicCullingParams params;
  params.min_dynamic_hits = 3;
  DynamicPointCuller culler(params);
  const Pose identity = Pose::Identity();
  EXPECT_TRUE(culler.observe(points, identity, mask, depth, camera).empty());
  EXPECT_TRUE(culler.observe(points, identity, mask, depth, camera).empty());
  const auto& culled = culler.observe(points, identity, mask, depth, camera);
  ASSERT_EQ(culled.size(), 1u);
  EXPECT_EQ(culled[0]->id(), 1u);
  // Counting starts again for a point that was reported (the caller erases it from the map).
  EXPECT_TRUE(culler.observe(points, identity, mask, depth, camera).empty());
  // With an empty mask nothing is counted.
  EXPECT_TRUE(culler.observe(points, identity, cv::Mat(), depth, camera).empty());
}

// A person stood on the left of a still camera when frame 0 was segmented, and by frame 12 has
// walked to the right, uncovering the wall. Frame 0's mask, still the newest at frame 12, lies on
// the wall: culling with it erases the static wall point and never the point made on the person.
// Frame 12's own mask, arriving frames later, judged at frame 12's pose and depth, culls only the
// person's point.
TEST(LateMaskFrames, TheLateMaskJudgedAtItsOwnFrameCullsThePersonNotTheWall) {
  const PinholeCamera camera = small_camera();
  const cv::Rect left(0, 0, 80, 120), right(80, 0, 80, 120);
  cv::Mat mask_of_frame_0 = cv::Mat::zeros(120, 160, CV_8UC1);
  mask_of_frame_0(left).setTo(255);
  cv::Mat mask_of_frame_12 = cv::Mat::zeros(120, 160, CV_8UC1);
  mask_of_frame_12(right).setTo(255);
  // Frame 12: the wall at 2 m on the left, the person at 1.5 m on the right.
  cv::Mat depth_of_frame_12(120, 160, CV_32FC1, cv::Scalar(2.0f));
  depth_of_frame_12(right).setTo(1.5f);
  auto wall = std::make_shared<MapPoint>(1, Eigen::Vector3d(-0.5, 0.0, 2.0), nullptr);
  auto person = std::make_shared<MapPoint>(2, Eigen::Vector3d(0.4, 0.0, 1.5), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {wall, person};

  DynamicPointCuller stale_culler({.min_dynamic_hits = 1});
  const auto& culled_by_stale =
      stale_culler.observe(points, Pose::Identity(), mask_of_frame_0, depth_of_frame_12, camera);
  ASSERT_EQ(culled_by_stale.size(), 1u);
  EXPECT_EQ(culled_by_stale[0]->id(), wall->id());

  LateMaskFrames frames;
  frames.remember({12, 0, Pose::Identity(), depth_of_frame_12});
  const auto frame_12 = frames.take(12);  // its mask arrived, say at frame 24
  ASSERT_TRUE(frame_12);
  DynamicPointCuller exact_culler({.min_dynamic_hits = 1});
  const auto& culled_by_late = exact_culler.observe(points, frame_12->T_world_camera,
                                                    mask_of_frame_12, frame_12->depth, camera);
  ASSERT_EQ(culled_by_late.size(), 1u);
  EXPECT_EQ(culled_by_late[0]->id(), person->id());
}

}  // namespace
}  // namespace pspslam
