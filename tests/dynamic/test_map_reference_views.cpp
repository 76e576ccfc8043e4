#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/dynamic/map_reference_views.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/scale_pyramid.h"

namespace pspslam {
namespace {

std::shared_ptr<KeyFrame> keyframe_with(std::uint64_t id, const Pose& T_world_camera,
                                        const std::vector<cv::Point2f>& pixels,
                                        const std::vector<float>& depths,
                                        const PinholeCamera& pinhole) {
  CameraConfig camera;
  camera.pinhole = pinhole;
  KeyFrameData data;
  data.T_camera_world = T_world_camera.inverse();
  for (const cv::Point2f& pixel : pixels) data.keypoints.emplace_back(pixel, 31.0f);
  data.descriptors = cv::Mat::zeros(static_cast<int>(pixels.size()), 32, CV_8U);
  data.depth = depths;
  return std::make_shared<KeyFrame>(
      id, std::move(data),
      std::make_shared<const CameraModel>(CameraModel::from_config(camera, 0.08)),
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{})));
}

// A keyframe of a loaded map becomes a reference depth image from its keypoints'
// depths: squares of the splat radius, the nearer surface where two overlap, 0 elsewhere.
TEST(MapReferenceViews, KeypointDepthsAreSplattedNearestFirst) {
  PinholeCamera camera;  // 640x480, no distortion
  const auto keyframe = keyframe_with(0, Pose::Identity(), {{100, 100}, {104, 100}, {300, 200}},
                                      {2.0f, 1.5f, 3.0f}, camera);
  const cv::Mat depth = rebuild_reference_depth(*keyframe, camera, 3);
  ASSERT_EQ(depth.type(), CV_32FC1);
  ASSERT_EQ(depth.size(), cv::Size(640, 480));
  EXPECT_FLOAT_EQ(depth.at<float>(100, 97), 2.0f);   // left edge of the first square
  EXPECT_FLOAT_EQ(depth.at<float>(100, 102), 1.5f);  // overlap: the nearer keypoint wins
  EXPECT_FLOAT_EQ(depth.at<float>(103, 107), 1.5f);
  EXPECT_FLOAT_EQ(depth.at<float>(100, 108), 0.0f);  // outside every square
  EXPECT_FLOAT_EQ(depth.at<float>(197, 303), 3.0f);
  EXPECT_EQ(cv::countNonZero(depth), 7 * 7 + 7 * 7 + 7 * 4);
}

TEST(MapReferenceViews, DistortedCamerasPlaceDepthAtTheRawPixel) {
  PinholeCamera camera;
  camera.distortion = {0.2, 0.0, 0.0, 0.0, 0.0};
  // Undistorted (x, y) = (0.5, 0) in normalised coordinates -> raw x = 0.5 * (1 + 0.2 * 0.25).
  const float undistorted_u = static_cast<float>(camera.cx + 0.5 * camera.fx);
  const auto keyframe =
      keyframe_with(0, Pose::Identity(), {{undistorted_u, 240.0f}}, {2.5f}, camera);
  const cv::Mat depth = rebuild_reference_depth(*keyframe, camera, 0);
  const int raw_u = static_cast<int>(std::lround(camera.cx + 0.5 * 1.05 * camera.fx));
  EXPECT_FLOAT_EQ(depth.at<float>(240, raw_u), 2.5f);
  EXPECT_EQ(cv::countNonZero(depth), 1);
}

TEST(MapReferenceViews, PoolIsTheNearestKeyframesLookingTheSameWay) {
  PinholeCamera camera;
  Map map;
  const auto at = [](double x, double turn_deg) {
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
    pose.translation() = Eigen::Vector3d(x, 0.0, 0.0);
    return pose;
  };
  map.add_keyframe(keyframe_with(0, at(0.0, 0.0), {{10, 10}}, {1.0f}, camera));
  map.add_keyframe(keyframe_with(1, at(1.0, 0.0), {{10, 10}}, {1.0f}, camera));
  map.add_keyframe(keyframe_with(2, at(0.3, 90.0), {{10, 10}}, {1.0f}, camera));  // turned away
  map.add_keyframe(keyframe_with(3, at(0.5, 10.0), {{10, 10}}, {1.0f}, camera));
  const MapReferenceViews views(map, camera);
  EXPECT_EQ(views.size(), 4u);
  std::vector<DepthView> pool;
  views.pool(at(0.45, 0.0), 2, pool);
  ASSERT_EQ(pool.size(), 2u);
  EXPECT_NEAR(pool[0].T_world_camera.translation().x(), 0.5, 1e-12);
  EXPECT_NEAR(pool[1].T_world_camera.translation().x(), 0.0, 1e-12);
  views.pool(at(0.45, 0.0), 10, pool);
  EXPECT_EQ(pool.size(), 3u);  // the keyframe turned by 90 degrees never joins
}

}  // namespace
}  // namespace pspslam
