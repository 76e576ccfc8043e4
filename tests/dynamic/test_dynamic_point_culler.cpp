#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

#include "pspslam/core/error.h"
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
  params.evidence = CullingEvidence::dynamic_pixels;
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

DynamicCullingParams seen_through_params() {
  DynamicCullingParams params;
  params.evidence = CullingEvidence::seen_through;
  params.min_dynamic_hits = 3;
  // Too few points here for the wrong-pose guard, tested on its own below.
  params.min_points_measured = 1000;
  return params;
}

// A person stood at 1.5 m on the left and a point was made on her; she has walked away and the
// frame sees the wall at 3 m through where she stood. A wall point on the right is covered by a
// mask that spills over the background (the mask is not read), and a point behind her old place
// is occluded by a newcomer: neither is ever seen through.
TEST(DynamicPointCuller, APointSeenThroughInThreeFramesIsCulledAStaticOneUnderAMaskIsNot) {
  const PinholeCamera camera = small_camera();
  cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(0, 90, 40, 30)).setTo(1.0f);  // a newcomer in the lower left corner
  const cv::Mat spilled_mask(120, 160, CV_8UC1, cv::Scalar(255));
  auto on_person = std::make_shared<MapPoint>(1, Eigen::Vector3d(-0.5, 0.0, 1.5), nullptr);
  auto wall = std::make_shared<MapPoint>(2, Eigen::Vector3d(0.5, 0.0, 3.0), nullptr);
  // Pixel (20, 105): inside the newcomer, who stands in front of it.
  auto occluded = std::make_shared<MapPoint>(3, Eigen::Vector3d(-1.8, 1.35, 3.0), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {on_person, wall, occluded};

  DynamicPointCuller culler(seen_through_params());
  const Pose identity = Pose::Identity();
  EXPECT_TRUE(culler.observe(points, identity, spilled_mask, depth, camera).empty());
  EXPECT_TRUE(culler.observe(points, identity, cv::Mat(), depth, camera).empty());
  const auto& culled = culler.observe(points, identity, spilled_mask, depth, camera);
  ASSERT_EQ(culled.size(), 1u);
  EXPECT_EQ(culled[0]->id(), on_person->id());
  const std::vector<std::shared_ptr<MapPoint>> kept = {wall, occluded};
  for (int frame = 0; frame < 5; ++frame)
    EXPECT_TRUE(culler.observe(kept, identity, spilled_mask, depth, camera).empty());
}

// A point on the edge of a cupboard (1 m) in front of the wall (3 m): its own pixel, one pixel
// off, sees the wall, but the pixels beside it see the cupboard. An edge is not free space.
TEST(DynamicPointCuller, APointOnADepthEdgeIsNotSeenThrough) {
  const PinholeCamera camera = small_camera();
  cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(3.0f));
  depth(cv::Rect(0, 0, 80, 120)).setTo(1.0f);  // the cupboard fills columns 0..79
  // Projects to column 80: the first wall column, right of the cupboard's edge.
  auto edge = std::make_shared<MapPoint>(1, Eigen::Vector3d(0.0, 0.0, 1.0), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {edge};
  DynamicPointCuller culler(seen_through_params());
  for (int frame = 0; frame < 5; ++frame)
    EXPECT_TRUE(culler.observe(points, Pose::Identity(), cv::Mat(), depth, camera).empty());
}

// A frame that measures a point where the map has it withdraws one frame's doubt: seen through,
// seen through, measured in place, seen through is two frames against it, not three.
TEST(DynamicPointCuller, AFrameThatMeasuresThePointInPlaceWithdrawsOneFramesDoubt) {
  const PinholeCamera camera = small_camera();
  const cv::Mat behind(120, 160, CV_32FC1, cv::Scalar(3.0f));
  const cv::Mat in_place(120, 160, CV_32FC1, cv::Scalar(1.5f));
  auto point = std::make_shared<MapPoint>(1, Eigen::Vector3d(0.0, 0.0, 1.5), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {point};
  DynamicPointCuller culler(seen_through_params());
  const Pose identity = Pose::Identity();
  EXPECT_TRUE(culler.observe(points, identity, {}, behind, camera).empty());
  EXPECT_TRUE(culler.observe(points, identity, {}, behind, camera).empty());
  EXPECT_TRUE(culler.observe(points, identity, {}, in_place, camera).empty());
  EXPECT_TRUE(culler.observe(points, identity, {}, behind, camera).empty());
  EXPECT_EQ(culler.observe(points, identity, {}, behind, camera).size(), 1u);
}

// Ten wall points at 2 m: a frame whose pose is 1 m too far forward sees through all of them.
// That is a wrong pose, not a moved scene: nothing is counted, however often it happens.
TEST(DynamicPointCuller, AFrameThatSeesThroughMostOfTheMapCountsNothing) {
  const PinholeCamera camera = small_camera();
  const cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(2.0f));
  std::vector<std::shared_ptr<MapPoint>> points;
  for (int i = 0; i < 10; ++i)
    points.push_back(
        std::make_shared<MapPoint>(i, Eigen::Vector3d(-0.5 + 0.1 * i, 0.0, 2.0), nullptr));
  DynamicCullingParams params = seen_through_params();
  params.max_seen_through_share = 0.25;
  params.min_points_measured = 5;
  DynamicPointCuller culler(params);
  Pose too_far_forward = Pose::Identity();
  too_far_forward.translation().z() = 1.0;
  for (int frame = 0; frame < 5; ++frame)
    EXPECT_TRUE(culler.observe(points, too_far_forward, {}, depth, camera).empty());
}

// The culler reads the depth image at the pixel the camera recorded a point at: undistorting
// that pixel gives back the ideal pinhole's (Bonn's published calibration, over the whole image).
TEST(DynamicPointCuller, TheRecordedPixelUndistortsToTheIdealOne) {
  PinholeCamera camera;
  camera.fx = 542.822841;
  camera.fy = 542.576870;
  camera.cx = 315.593520;
  camera.cy = 237.756098;
  camera.distortion = {0.039903, -0.099343, -0.00073, -0.000144, 0.0};
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(-1.1, -0.85, 2.0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.4, 0.2, 3.0),
        Eigen::Vector3d(1.2, 0.9, 2.0)}) {
    const Eigen::Vector2d ideal = camera.project(point);
    const Eigen::Vector2d recorded = project_distorted(camera, point);
    std::vector<cv::Point2f> pixels = {cv::Point2f(recorded.x(), recorded.y())};
    camera.undistort_points(pixels);
    EXPECT_NEAR(pixels[0].x, ideal.x(), 0.02);
    EXPECT_NEAR(pixels[0].y, ideal.y(), 0.02);
  }
  // Near the corner the two differ by about two pixels: at a depth edge, the ideal pixel's depth
  // can be a neighbouring surface's.
  EXPECT_GT((project_distorted(camera, {1.1, 0.85, 2.0}) - camera.project({1.1, 0.85, 2.0})).norm(),
            1.5);
}

TEST(DynamicPointCuller, CullingEvidenceIsParsedOrRefusedByName) {
  EXPECT_EQ(parse_culling_evidence("off", "--cull-evidence"), CullingEvidence::none);
  EXPECT_EQ(parse_culling_evidence("mask", "--cull-evidence"), CullingEvidence::dynamic_pixels);
  EXPECT_EQ(parse_culling_evidence("seen-through", "--cull-evidence"),
            CullingEvidence::seen_through);
  try {
    parse_culling_evidence("depth", "--cull-evidence");
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "--cull-evidence: 'depth' is not a culling evidence (off, mask, seen-through)");
  }
}

// By default nothing is culled for being dynamic, however often a point lies on the mask.
TEST(DynamicPointCuller, TheDefaultCullsNothing) {
  const PinholeCamera camera = small_camera();
  const cv::Mat mask(120, 160, CV_8UC1, cv::Scalar(255));
  const cv::Mat depth(120, 160, CV_32FC1, cv::Scalar(2.0f));
  auto point = std::make_shared<MapPoint>(1, Eigen::Vector3d(0.0, 0.0, 2.0), nullptr);
  const std::vector<std::shared_ptr<MapPoint>> points = {point};
  DynamicPointCuller culler;
  EXPECT_EQ(culler.params().evidence, CullingEvidence::none);
  for (int frame = 0; frame < 5; ++frame)
    EXPECT_TRUE(culler.observe(points, Pose::Identity(), mask, depth, camera).empty());
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

  DynamicPointCuller stale_culler(
      {.evidence = CullingEvidence::dynamic_pixels, .min_dynamic_hits = 1});
  const auto& culled_by_stale =
      stale_culler.observe(points, Pose::Identity(), mask_of_frame_0, depth_of_frame_12, camera);
  ASSERT_EQ(culled_by_stale.size(), 1u);
  EXPECT_EQ(culled_by_stale[0]->id(), wall->id());

  LateMaskFrames frames;
  frames.remember({12, 0, Pose::Identity(), depth_of_frame_12});
  const auto frame_12 = frames.take(12);  // its mask arrived, say at frame 24
  ASSERT_TRUE(frame_12);
  DynamicPointCuller exact_culler(
      {.evidence = CullingEvidence::dynamic_pixels, .min_dynamic_hits = 1});
  const auto& culled_by_late = exact_culler.observe(points, frame_12->T_world_camera,
                                                    mask_of_frame_12, frame_12->depth, camera);
  ASSERT_EQ(culled_by_late.size(), 1u);
  EXPECT_EQ(culled_by_late[0]->id(), person->id());
}

}  // namespace
}  // namespace pspslam
