#include <gtest/gtest.h>

#include <random>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"
#include "pspslam/tracking/frame_pose_optimization.h"

namespace pspslam {
namespace {

// A crowd that fills the view while the mask is stale: 60 static points made by a keyframe of
// frame 10, which an exact mask has judged, and 150 points made by a keyframe of frame 40 on
// people who have since walked 15 cm to the side. Frame 45 sees both where they are now, with
// depth, from a camera 3 cm off the motion model's prediction.
class JudgedPointsTest : public ::testing::Test {
 protected:
  static constexpr int kStatic = 60;
  static constexpr int kPeople = 150;

  void SetUp() override {
    truth_.linear() =
        Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    truth_.translation() = Eigen::Vector3d(0.04, 0.0, 0.01);
    const auto old_keyframe = keyframe_of_frame(10);
    const auto new_keyframe = keyframe_of_frame(40);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> x(-1.2, 1.2), y(-0.8, 0.8);
    std::normal_distribution<double> noise(0.0, 0.3);
    const Eigen::Vector3d walked(0.15, 0.0, 0.0);
    std::vector<cv::KeyPoint> keypoints;
    std::vector<float> depths, right_u;
    auto observe = [&](const Eigen::Vector3d& world_now, const Eigen::Vector3d& mapped_at,
                       const std::shared_ptr<KeyFrame>& made_by) {
      const Eigen::Vector3d camera_point = truth_ * world_now;
      const Eigen::Vector2d pixel = camera_->pinhole.project(camera_point);
      const float u = static_cast<float>(pixel.x() + noise(rng));
      keypoints.emplace_back(cv::Point2f(u, static_cast<float>(pixel.y() + noise(rng))), 31.0f);
      depths.push_back(static_cast<float>(camera_point.z()));
      right_u.push_back(static_cast<float>(u - camera_->bf / camera_point.z()));
      points_.push_back(std::make_shared<MapPoint>(points_.size(), mapped_at, made_by));
    };
    for (int i = 0; i < kStatic; ++i) {
      const Eigen::Vector3d wall(x(rng) * 2.0, y(rng) * 2.0, 4.0);
      observe(wall, wall, old_keyframe);
    }
    for (int i = 0; i < kPeople; ++i) {
      const Eigen::Vector3d person(x(rng) * 0.6, y(rng), 1.5);
      observe(person + walked, person, new_keyframe);
    }
    frame_.emplace(45, 1.5, keypoints, cv::Mat(static_cast<int>(keypoints.size()), 32, CV_8U),
                   depths, right_u, camera_, pyramid_);
    for (size_t i = 0; i < points_.size(); ++i) frame_->map_points[i] = points_[i];
    predicted_ = truth_;
    predicted_.translation() += Eigen::Vector3d(0.03, 0.0, 0.0);
    frame_->set_pose(predicted_);
  }

  std::shared_ptr<KeyFrame> keyframe_of_frame(std::uint64_t frame_id) {
    Frame frame(frame_id, 0.0, {}, cv::Mat(0, 32, CV_8U), {}, {}, camera_, pyramid_);
    frame.set_pose(Pose::Identity());
    return std::make_shared<KeyFrame>(frame_id, frame);
  }

  double translation_error() const {
    return (frame_->T_camera_world().translation() - truth_.translation()).norm();
  }

  std::shared_ptr<const CameraModel> camera_ =
      std::make_shared<const CameraModel>(CameraModel::from_config(CameraConfig{}, 0.08));
  std::shared_ptr<const ScalePyramid> pyramid_ =
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  Pose truth_ = Pose::Identity();
  Pose predicted_ = Pose::Identity();
  std::vector<std::shared_ptr<MapPoint>> points_;
  std::optional<Frame> frame_;
  FramePoseBuffers buffers_;
};

TEST_F(JudgedPointsTest, EveryMatchAlikeFollowsThePeople) {
  optimize_frame_pose(*frame_, PoseOptimizerOptions{}, buffers_);
  EXPECT_GT(translation_error(), 0.10);  // the crowd's 15 cm walk, seen as the camera's
}

TEST_F(JudgedPointsTest, JudgedPointsFirstKeepTheCameraAndSetThePeopleAside) {
  int set_aside = -1;
  const PoseOptimizationResult result =
      optimize_frame_pose_judged_first(*frame_, PoseOptimizerOptions{}, buffers_, nullptr,
                                       {.judged_through_frame = 30, .min_points = 30}, set_aside);
  EXPECT_LT(translation_error(), 0.005);
  EXPECT_EQ(set_aside, kPeople);
  ASSERT_EQ(result.inlier.size(), points_.size());
  int static_inliers = 0;
  int people_inliers = 0;
  for (size_t k = 0; k < result.inlier.size(); ++k) {
    const bool is_static = buffers_.keypoint_of_observation[k] < kStatic;
    (is_static ? static_inliers : people_inliers) += result.inlier[k];
  }
  EXPECT_GE(static_inliers, kStatic * 9 / 10);
  EXPECT_EQ(people_inliers, 0);
  EXPECT_EQ(result.num_inliers, static_inliers);
}

TEST_F(JudgedPointsTest, TooFewJudgedPointsSolveOnEveryMatchAsUsual) {
  Frame usual = *frame_;
  optimize_frame_pose(usual, PoseOptimizerOptions{}, buffers_);
  int set_aside = -1;
  optimize_frame_pose_judged_first(*frame_, PoseOptimizerOptions{}, buffers_, nullptr,
                                   {.judged_through_frame = 30, .min_points = kStatic + 1},
                                   set_aside);
  EXPECT_EQ(set_aside, 0);
  EXPECT_TRUE(frame_->T_camera_world().isApprox(usual.T_camera_world(), 1e-12));
}

TEST_F(JudgedPointsTest, PointsMadeAfterTheFrameCountAsJudged) {
  // A loaded map's keyframes carry another session's frame ids, which may be higher: nothing
  // says its points were made on people since the mask's frame.
  const auto loaded_keyframe = keyframe_of_frame(900);
  for (int i = 0; i < kStatic; ++i) {
    frame_->map_points[static_cast<size_t>(i)] = std::make_shared<MapPoint>(
        1000 + i, points_[static_cast<size_t>(i)]->position(), loaded_keyframe);
  }
  int set_aside = -1;
  optimize_frame_pose_judged_first(*frame_, PoseOptimizerOptions{}, buffers_, nullptr,
                                   {.judged_through_frame = 5, .min_points = 30}, set_aside);
  EXPECT_EQ(set_aside, kPeople);
  EXPECT_LT(translation_error(), 0.005);
}

}  // namespace
}  // namespace pspslam
