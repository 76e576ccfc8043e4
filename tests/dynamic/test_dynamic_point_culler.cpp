#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <memory>
#include <vector>

#include "pspslam/dynamic/dynamic_point_culler.h"
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

}  // namespace
}  // namespace pspslam
