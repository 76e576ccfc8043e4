#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

#include "pspslam/map/feature_grid.h"
#include "pspslam/map/frame.h"

namespace pspslam {
namespace {

CameraConfig bonn_like_camera() {
  CameraConfig camera;
  camera.pinhole.fx = 542.822841;
  camera.pinhole.fy = 542.576870;
  camera.pinhole.cx = 315.593520;
  camera.pinhole.cy = 237.756098;
  camera.pinhole.distortion = {0.039903, -0.099343, -0.00073, -0.000144, 0.0};
  return camera;
}

TEST(Frame, UndistortionAndBackProjectionRoundTrip) {
  const CameraConfig config = bonn_like_camera();
  auto camera = std::make_shared<const CameraModel>(CameraModel::from_config(config, 0.08));
  auto pyramid = std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-0.5, 0.5);
  std::uniform_real_distribution<double> z(0.8, 4.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) {
    const double depth = z(rng);
    points.emplace_back(xy(rng) * depth, xy(rng) * depth * 0.75, depth);
  }
  // Distorted pixels as the sensor sees them; depth is stored at the rounded pixel, as in a
  // registered depth image.
  std::vector<cv::Point2d> distorted;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), config.pinhole.K(),
                    config.pinhole.distortion_coeffs(), distorted);
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0));
  std::vector<cv::KeyPoint> keypoints;
  std::vector<cv::Point3d> kept;
  for (size_t i = 0; i < points.size(); ++i) {
    const int u = cvRound(distorted[i].x);
    const int v = cvRound(distorted[i].y);
    if (u < 0 || v < 0 || u >= 640 || v >= 480 || depth.at<float>(v, u) > 0) continue;
    depth.at<float>(v, u) = static_cast<float>(points[i].z);
    keypoints.emplace_back(cv::Point2f(distorted[i].x, distorted[i].y), 31.0f);
    kept.push_back(points[i]);
  }
  ASSERT_GT(kept.size(), 150u);
  cv::Mat descriptors(static_cast<int>(keypoints.size()), 32, CV_8U, cv::Scalar(0));
  Frame frame(0, 1.0, keypoints, descriptors, depth, camera, pyramid);
  frame.set_pose(Pose::Identity());
  ASSERT_EQ(frame.size(), static_cast<int>(kept.size()));
  double max_pixel_error = 0.0;
  double max_point_error = 0.0;
  for (int i = 0; i < frame.size(); ++i) {
    const Eigen::Vector3d truth(kept[i].x, kept[i].y, kept[i].z);
    const Eigen::Vector2d ideal = camera->pinhole.project(truth);
    const cv::Point2f& undistorted = frame.keypoints()[i].pt;
    max_pixel_error =
        std::max(max_pixel_error, (ideal - Eigen::Vector2d(undistorted.x, undistorted.y)).norm());
    ASSERT_NEAR(frame.depth(i), truth.z(), 1e-6);
    EXPECT_NEAR(frame.right_u(i), undistorted.x - camera->bf / truth.z(), 1e-3);
    max_point_error = std::max(max_point_error, (frame.unproject_world(i) - truth).norm());
  }
  // Undistortion is iterative (cv::undistortPoints), float keypoints: sub-0.05 pixel.
  EXPECT_LT(max_pixel_error, 0.05);
  EXPECT_LT(max_point_error, 5e-4);
  EXPECT_NEAR(camera->bf, 542.822841 * 0.08, 1e-9);
}

TEST(Frame, BackProjectionUsesThePose) {
  CameraConfig config;
  auto camera = std::make_shared<const CameraModel>(CameraModel::from_config(config, 0.08));
  auto pyramid = std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  std::vector<cv::KeyPoint> keypoints = {cv::KeyPoint(cv::Point2f(100.0f, 200.0f), 31.0f)};
  Frame frame(0, 0.0, keypoints, cv::Mat(1, 32, CV_8U, cv::Scalar(0)), depth, camera, pyramid);
  Pose T_world_camera = Pose::Identity();
  T_world_camera.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_world_camera.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  frame.set_pose(T_world_camera.inverse());
  const Eigen::Vector3d world = frame.unproject_world(0);
  const Eigen::Vector3d back = frame.T_camera_world() * world;
  EXPECT_NEAR(back.z(), 2.0, 1e-9);
  const Eigen::Vector2d pixel = camera->pinhole.project(back);
  EXPECT_NEAR(pixel.x(), 100.0, 1e-6);
  EXPECT_NEAR(pixel.y(), 200.0, 1e-6);
  EXPECT_TRUE((frame.camera_center() - Eigen::Vector3d(1.0, -2.0, 0.5)).norm() < 1e-12);
}

TEST(FeatureGrid, RadiusQueryEqualsBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(0.0f, 640.0f);
  std::uniform_real_distribution<float> y(0.0f, 480.0f);
  std::uniform_int_distribution<int> level(0, 7);
  std::vector<cv::KeyPoint> keypoints;
  for (int i = 0; i < 2000; ++i) {
    cv::KeyPoint kp(cv::Point2f(x(rng), y(rng)), 31.0f);
    kp.octave = level(rng);
    keypoints.push_back(kp);
  }
  const FeatureGrid grid(keypoints, 0.0, 640.0, 0.0, 480.0);
  std::vector<int> found;
  for (int q = 0; q < 100; ++q) {
    const double qx = x(rng);
    const double qy = y(rng);
    const double radius = 5.0 + q % 40;
    const int min_level = q % 3;
    const int max_level = q % 2 == 0 ? -1 : 5;
    grid.query(keypoints, qx, qy, radius, min_level, max_level, found);
    std::vector<int> expected;
    for (int i = 0; i < static_cast<int>(keypoints.size()); ++i) {
      const cv::KeyPoint& kp = keypoints[i];
      if (kp.octave < min_level || (max_level >= 0 && kp.octave > max_level)) continue;
      if (std::abs(kp.pt.x - qx) < radius && std::abs(kp.pt.y - qy) < radius) expected.push_back(i);
    }
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected) << "query " << q;
  }
}

TEST(ScalePyramid, PredictsLevelFromDistance) {
  const ScalePyramid pyramid = ScalePyramid::from_config(OrbConfig{});
  ASSERT_EQ(pyramid.levels, 8);
  EXPECT_NEAR(pyramid.scale[3], 1.2 * 1.2 * 1.2, 1e-12);
  EXPECT_NEAR(pyramid.inv_sigma2[2], 1.0 / (1.44 * 1.44), 1e-12);
  // Seen at max distance 4.8 m on level 0: at 4.0 m (ratio 1.2) it appears one level up.
  EXPECT_EQ(pyramid.predict_level(4.0, 4.8), 1);
  EXPECT_EQ(pyramid.predict_level(4.8, 4.8), 0);
  EXPECT_EQ(pyramid.predict_level(0.1, 4.8), 7);
}

}  // namespace
}  // namespace pspslam
