#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "pspslam/camera/rolling_shutter.h"
#include "pspslam/map/frame.h"

namespace pspslam {
namespace {

// A camera turning at `rate` about `axis` (its own frame) with a rolling shutter of `readout`
// seconds: where static points are seen, each on the row whose instant saw it.
struct TurningCamera {
  PinholeCamera pinhole;
  double readout = 0.030;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d(0.3, -0.9, 0.2);  // rad/s, ~55 deg/s

  // The point (camera coordinates at the frame's instant, t = 0) in the camera at time t.
  Eigen::Vector3d at(const Eigen::Vector3d& point, double t) const {
    const double rate = angular_velocity.norm();
    return Eigen::AngleAxisd(-rate * t, angular_velocity / rate) * point;
  }
  double row_time(double row) const { return readout * ((row + 0.5) / pinhole.height - 0.5); }
  // The row fixes the instant and the instant the row: a fixed point, reached in a few steps
  // since one readout moves a point by a few pixels.
  Eigen::Vector3d seen(const Eigen::Vector3d& point) const {
    double row = pinhole.project(point).y();
    for (int i = 0; i < 20; ++i) row = pinhole.project(at(point, row_time(row))).y();
    return at(point, row_time(row));
  }
};

std::vector<Eigen::Vector3d> points_in_view(const PinholeCamera& camera, int count) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(20.0, camera.width - 20.0);
  std::uniform_real_distribution<double> v(20.0, camera.height - 20.0);
  std::uniform_real_distribution<double> z(0.8, 4.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.push_back(camera.unproject({u(rng), v(rng)}, z(rng)));
  return points;
}

TEST(RollingShutter, MovesEachKeypointToTheFramesInstant) {
  const TurningCamera camera;
  const RollingShutterCorrection correction(camera.pinhole, camera.readout,
                                            camera.angular_velocity);
  ASSERT_TRUE(correction.active());
  double worst_skew = 0.0, worst_pixel = 0.0, worst_depth = 0.0;
  for (const Eigen::Vector3d& point : points_in_view(camera.pinhole, 300)) {
    const Eigen::Vector3d seen = camera.seen(point);
    const Eigen::Vector2d pixel = camera.pinhole.project(seen);
    cv::Point2f keypoint(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
    float depth = static_cast<float>(seen.z());
    const cv::Point2f without_depth = correction.apply(keypoint, keypoint.y);
    correction.apply(keypoint, keypoint.y, depth);
    EXPECT_NEAR(without_depth.x, keypoint.x, 1e-3);  // a bearing turns alike, depth or not
    EXPECT_NEAR(without_depth.y, keypoint.y, 1e-3);
    const Eigen::Vector2d truth = camera.pinhole.project(point);
    worst_skew = std::max(worst_skew, (pixel - truth).norm());
    worst_pixel = std::max(worst_pixel, (Eigen::Vector2d(keypoint.x, keypoint.y) - truth).norm());
    worst_depth = std::max(worst_depth, std::abs(depth - point.z()));
  }
  // ~55 deg/s over half of a 30 ms readout: the rows farthest from the middle are ~7 px off.
  EXPECT_GT(worst_skew, 5.0);
  EXPECT_LT(worst_pixel, 0.01);  // float keypoints, exact rotation
  EXPECT_LT(worst_depth, 1e-5);
}

TEST(RollingShutter, GlobalShutterOrStillCameraMovesNothing) {
  const PinholeCamera pinhole;
  using Case = std::pair<double, Eigen::Vector3d>;
  for (const auto& [readout, rate] :
       {Case{0.0, Eigen::Vector3d(0.3, 0.1, 0.0)}, Case{0.03, Eigen::Vector3d::Zero()}}) {
    const RollingShutterCorrection correction(pinhole, readout, rate);
    EXPECT_FALSE(correction.active());
    cv::Point2f keypoint(100.25f, 400.5f);
    float depth = 2.0f;
    correction.apply(keypoint, keypoint.y, depth);
    EXPECT_EQ(keypoint, cv::Point2f(100.25f, 400.5f));
    EXPECT_EQ(depth, 2.0f);
  }
}

// The Frame applies it with the camera's readout. The depth image is taken at one instant, the
// frame's (a global-shutter depth camera, as synth/ renders it): each keypoint's depth is read
// where the point lies at that instant, not where the colour rows saw it.
TEST(RollingShutter, FrameReadsDepthWhereTheCorrectedKeypointLies) {
  TurningCamera camera;
  CameraConfig config;
  config.pinhole = camera.pinhole;
  config.rolling_shutter_readout_s = camera.readout;
  auto rgbd = std::make_shared<const CameraModel>(CameraModel::from_config(config, 0.08));
  auto pyramid = std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  cv::Mat depth_image(camera.pinhole.height, camera.pinhole.width, CV_32F, cv::Scalar(0));
  std::vector<cv::KeyPoint> keypoints;
  std::vector<Eigen::Vector3d> truths;
  for (const Eigen::Vector3d& point : points_in_view(camera.pinhole, 100)) {
    // The point's depth on a 3x3 patch around its pixel at the frame's instant.
    const Eigen::Vector2d truth = camera.pinhole.project(point);
    const cv::Rect patch(cvRound(truth.x()) - 1, cvRound(truth.y()) - 1, 3, 3);
    if (cv::countNonZero(depth_image(patch)) > 0) continue;
    depth_image(patch).setTo(point.z());
    const Eigen::Vector2d seen = camera.pinhole.project(camera.seen(point));
    keypoints.emplace_back(cv::Point2f(static_cast<float>(seen.x()), static_cast<float>(seen.y())),
                           31.0f);
    truths.push_back(point);
  }
  const cv::Mat descriptors(static_cast<int>(keypoints.size()), 32, CV_8U, cv::Scalar(0));
  const Frame still(0, 1.0, keypoints, descriptors, depth_image, rgbd, pyramid);
  const Frame turning(0, 1.0, keypoints, descriptors, depth_image, rgbd, pyramid,
                      camera.angular_velocity);
  ASSERT_GT(turning.size(), 80);
  int still_with_right_depth = 0;
  for (int i = 0; i < turning.size(); ++i) {
    EXPECT_EQ(still.keypoints()[i].pt, keypoints[i].pt);  // no rotation rate: untouched
    if (std::abs(still.depth(i) - truths[i].z()) < 1e-6) ++still_with_right_depth;
    const Eigen::Vector2d truth = camera.pinhole.project(truths[i]);
    const cv::Point2f& corrected = turning.keypoints()[i].pt;
    EXPECT_NEAR(corrected.x, truth.x(), 0.01);
    EXPECT_NEAR(corrected.y, truth.y(), 0.01);
    EXPECT_FLOAT_EQ(turning.depth(i), static_cast<float>(truths[i].z()));
    EXPECT_NEAR(turning.right_u(i), truth.x() - rgbd->bf / truths[i].z(), 0.01);
  }
  // Read where the rows saw them, most keypoints miss their patch (skewed by up to ~7 px).
  EXPECT_LT(still_with_right_depth, turning.size() / 2);
}

// A stereo pair's depth is triangulated from rows read at the same instant in both images: the
// point is turned with its keypoint, and its right coordinate follows.
TEST(RollingShutter, StereoFrameTurnsTheTriangulatedPoint) {
  TurningCamera camera;
  CameraConfig config;
  config.type = SensorType::stereo;
  config.baseline = 0.1;
  config.pinhole = camera.pinhole;
  config.rolling_shutter_readout_s = camera.readout;
  auto rgbd = std::make_shared<const CameraModel>(CameraModel::from_config(config, 0.08));
  auto pyramid = std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  std::vector<cv::KeyPoint> keypoints;
  std::vector<float> depths, right_us;
  std::vector<Eigen::Vector3d> truths;
  for (const Eigen::Vector3d& point : points_in_view(camera.pinhole, 50)) {
    const Eigen::Vector3d seen = camera.seen(point);
    const Eigen::Vector2d pixel = camera.pinhole.project(seen);
    keypoints.emplace_back(
        cv::Point2f(static_cast<float>(pixel.x()), static_cast<float>(pixel.y())), 31.0f);
    depths.push_back(static_cast<float>(seen.z()));
    right_us.push_back(static_cast<float>(pixel.x() - rgbd->bf / seen.z()));
    truths.push_back(point);
  }
  const cv::Mat descriptors(static_cast<int>(keypoints.size()), 32, CV_8U, cv::Scalar(0));
  const Frame frame(0, 1.0, keypoints, descriptors, depths, right_us, rgbd, pyramid,
                    camera.angular_velocity);
  for (int i = 0; i < frame.size(); ++i) {
    const Eigen::Vector2d truth = camera.pinhole.project(truths[i]);
    EXPECT_NEAR(frame.keypoints()[i].pt.x, truth.x(), 0.01);
    EXPECT_NEAR(frame.keypoints()[i].pt.y, truth.y(), 0.01);
    EXPECT_NEAR(frame.depth(i), truths[i].z(), 1e-4);
    EXPECT_NEAR(frame.right_u(i), truth.x() - rgbd->bf / truths[i].z(), 0.01);
  }
}

}  // namespace
}  // namespace pspslam
